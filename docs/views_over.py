"""Which of `evidence`'s views are off by more than a threshold, and why (docs/ablation.md, "The real scans' views
off by more than 10 mm"): the evaluation's own instances (`symfruit evaluate`'s protocol, sensor, poses and seed,
the same extraction), and per view over the threshold its centre error, the signed error of the centre along the
line of sight, how far the fruit recedes (``extras["recede"]``), whether it was flagged reliable, the candidate of
largest weight and the candidate whose own box centre was nearest the truth's, each with its centre error.

    python docs/views_over.py --fruit examples/scans --n 190 --pose upright [--protocol camera] [--sensor heldback]
                              [--seed 0] [--over 10]

Each view gets one of three causes: ``hidden`` (no candidate's own box within the threshold: what the view shows
leaves the hidden part to a guess no candidate makes), ``weights`` (a candidate within the threshold and at least
3 mm better than the one of largest weight), ``fusion`` (the winner was about as good as the best candidate: the
weighted median and the depth prior moved the box past the threshold).
"""

import argparse
import collections
import sys

import numpy as np

from symfruit.evaluate import runner
from symfruit.evaluate.protocols import specs
from symfruit.settings import Settings


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--protocol", default="camera", choices=("camera", "paper"))
    ap.add_argument("--fruit", default="examples/scans")
    ap.add_argument("--n", type=int, default=190)
    ap.add_argument("--pose", default="hanging")
    ap.add_argument("--sensor", default="heldback")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--over", type=float, default=10.0, help="threshold, mm")
    a = ap.parse_args()
    caught: dict = {}
    complete, score = runner.complete, runner.score_completion

    def keep_result(*args, **kwargs):
        caught["result"] = complete(*args, **kwargs)
        return caught["result"]

    def keep_truth(box, points, truth_box, *args, **kwargs):
        caught["truth"] = truth_box
        return score(box, points, truth_box, *args, **kwargs)

    runner.complete, runner.score_completion = keep_result, keep_truth
    settings = Settings()
    causes: collections.Counter = collections.Counter()
    n = 0
    out = sys.stdout
    out.write("| view | fruit | centre (mm) | along sight (mm) | recede (mm) | reliable | largest weight | nearest "
              "candidate | cause |\n|---|---|---|---|---|---|---|---|---|\n")  # fmt: skip
    for spec in specs(a.protocol, a.fruit, n=a.n, seed=a.seed, sensor=a.sensor, poses=a.pose):
        caught.clear()
        row = runner._evaluate_instance(spec, ["evidence"], settings)[0]
        n += 1
        if row.error or not row.centre_mm > a.over:
            continue
        e, truth = caught["result"].extras, caught["truth"]
        errs = {name: 1000 * float(np.linalg.norm(0.5 * (np.array(c["min"]) + np.array(c["max"])) - truth.centre))
                for name, c in e["candidates"].items()}  # fmt: skip
        win = max(e["weights"], key=e["weights"].get)
        best = min(errs, key=errs.get)
        cause = "hidden" if errs[best] > a.over else "weights" if errs[win] - errs[best] >= 3.0 else "fusion"
        causes[cause] += 1
        along = 1000 * float(caught["result"].box.centre[2] - truth.centre[2])
        out.write(f"| {spec.pose} | {row.kind.split('/')[-1]} | {row.centre_mm:.1f} | {along:+.1f} | "
                  f"{1000 * e['recede']:.0f} | {'yes' if e['reliable'] else 'no'} | `{win}` {e['weights'][win]:.2f}: "
                  f"{errs[win]:.1f} | `{best}`: {errs[best]:.1f} | {cause} |\n")  # fmt: skip
    found = ", ".join(f"{k} {v}" for k, v in causes.most_common())
    out.write(f"\n{sum(causes.values())} of {n} views over {a.over:g} mm: {found}\n")


if __name__ == "__main__":
    main()
