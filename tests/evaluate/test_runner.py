"""The runner: every method on every instance through the public ``complete``, rows in spec order, failures
recorded; and the summary statistics."""

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from symfruit import InputError, Settings
from symfruit.evaluate.metrics import score_completion
from symfruit.evaluate.protocols import Spec, build
from symfruit.evaluate.runner import COLUMNS, Row, average_ranks, run, spearman, summarise
from symfruit.methods import register

SPECS = [Spec("paper", "strawberry", 0, 9), Spec("paper", "strawberry", 1, 0)]


def test_rows_come_in_spec_then_method_order_with_the_metrics_of_complete():
    from symfruit import complete

    rows = run(SPECS, ("raw", "sphere"), jobs=1, progress=False)
    assert [(r.fruit_index, r.pose, r.method) for r in rows] == [(0, 9, "raw"), (0, 9, "sphere"), (1, 0, "raw"),
                                                                  (1, 0, "sphere")]  # fmt: skip
    inst = build(SPECS[1])
    result = complete(inst.visible, camera=inst.camera, method="sphere")
    expected = score_completion(result.box, result.points, inst.truth_box, inst.truth_surface)
    row = rows[3]
    assert (row.iou, row.centre_mm, row.chamfer_mm, row.f1) == (expected.iou, expected.centre_mm,
                                                                expected.chamfer_mm, expected.f1)  # fmt: skip
    assert row.n_visible == len(inst.visible) and row.angle_x == -45.0 and row.distance_m == 0.3 and row.error == ""
    assert math.isnan(row.confidence) and row.reliable is False  # sphere estimates no confidence
    assert list(row.to_dict()) == list(COLUMNS)


def test_settings_reach_every_method():
    few = Settings().replace(paper={"translations": 1, "rotations_x": 1, "rotations_y": 1})
    rows = run(SPECS[:1], ("paper",), few, jobs=1, progress=False)
    default = run(SPECS[:1], ("paper",), jobs=1, progress=False)
    assert rows[0].iou != default[0].iou


def test_a_failing_method_is_recorded_and_the_others_go_on(isolated_registry):
    @register("test-fails")
    def fails(points, camera, settings):
        """Always refuses."""
        raise InputError("cannot do this one")

    rows = run(SPECS[:1], ("test-fails", "raw"), jobs=1, progress=False)
    assert [r.method for r in rows] == ["test-fails", "raw"]
    assert rows[0].error == "cannot do this one" and math.isnan(rows[0].iou) and math.isnan(rows[0].seconds)
    assert rows[1].error == "" and 0 < rows[1].iou < 1


def test_a_bad_instance_or_a_method_fault_in_a_worker_pool_is_recorded_and_the_run_goes_on(isolated_registry,
                                                                                        monkeypatch):  # fmt: skip
    # with --jobs N one exception in a worker (an instance that could not be built, a method's fault that is no
    # refusal) ended the whole evaluation through pool.map, every finished instance lost
    from symfruit.evaluate import runner

    @register("test-fault")
    def fault(points, camera, settings):
        """Fails like a bug on the second instance."""
        if len(points) == len(build(SPECS[1]).visible):
            raise ValueError("a fault")
        raise InputError("refused")

    real = runner.build

    def build_or_fail(spec, *args):
        if spec.index == 2:
            raise OSError("scan unreadable")
        return real(spec, *args)

    monkeypatch.setattr(runner, "build", build_or_fail)  # workers are forked: they see it
    specs = [*SPECS, Spec("paper", "strawberry", 2, 0)]
    rows = run(specs, ("test-fault", "raw"), jobs=2, progress=False)
    assert [(r.fruit_index, r.method) for r in rows] == [(i, m) for i in (0, 1, 2) for m in ("test-fault", "raw")]
    lost = "the instance: internal error (OSError: scan unreadable)"
    assert [r.error for r in rows] == ["refused", "", "internal error (ValueError: a fault)", "", lost, lost]
    assert 0 < rows[1].iou < 1 and 0 < rows[3].iou < 1 and math.isnan(rows[4].iou)


def test_a_worker_that_dies_fails_its_instance_and_the_others_go_on(monkeypatch):
    """Stop 48 (robust48): a worker process killed (out of memory, a crash in compiled code) ended the evaluation
    with a BrokenProcessPool traceback, every finished batch lost. The batches not back are evaluated again, each
    instance in a process of its own: the one that dies again is a row saying so."""
    import os

    from symfruit.evaluate import runner

    parent, real = os.getpid(), runner._evaluate

    def dies_on_the_second(spec, methods, settings):
        if spec.index == 1 and os.getpid() != parent:
            os._exit(9)  # as the kernel's OOM killer ends a process: no exception, no cleanup
        return real(spec, methods, settings)

    monkeypatch.setattr(runner, "_evaluate", dies_on_the_second)  # workers are forked: they see it
    specs = [*SPECS, Spec("paper", "strawberry", 2, 0)]
    rows = run(specs, ("raw",), jobs=2, progress=False)
    assert [(r.fruit_index, r.method) for r in rows] == [(0, "raw"), (1, "raw"), (2, "raw")]
    assert [r.error for r in rows] == ["", f"the instance: {runner.WORKER_DIED}", ""]
    assert 0 < rows[0].iou < 1 and math.isnan(rows[1].iou) and 0 < rows[2].iou < 1


def row(method="raw", iou=0.5, centre_mm=2.0, confidence=float("nan"), error="", occlusion=0.0, **kw):
    base = dict(protocol="paper", fruit="apple", kind="apple", fruit_index=0, pose=0, angle_x=0.0, angle_y=0.0,
                angle_z=0.0, distance_m=0.3, occlusion=occlusion, hidden=0.1, n_visible=100, method=method, iou=iou,
                centre_mm=centre_mm, chamfer_mm=1.0, f1=0.9, precision=0.9, recall=0.9, seconds=0.002,
                confidence=confidence, error=error)  # fmt: skip
    return Row(**{**base, **kw})


def test_summary_known_answers():
    rows = [row(iou=0.2, centre_mm=1.0), row(iou=0.4, centre_mm=5.0), row(iou=0.9, centre_mm=3.0),
            row(error="failed", iou=float("nan")), row(method="paper", iou=0.8)]  # fmt: skip
    by = {s["method"]: s for s in summarise(rows)}
    raw = by["raw"]
    assert (raw["fruit"], raw["occlusion"], raw["n"], raw["failed"]) == ("apple", 0.0, 4, 1)
    assert raw["iou_mean"] == pytest.approx(0.5) and raw["iou_median"] == pytest.approx(0.4)
    assert raw["centre_mm_mean"] == pytest.approx(3.0) and raw["centre_mm_median"] == pytest.approx(3.0)
    assert raw["ms_median"] == pytest.approx(2.0) and raw["hidden_mean"] == pytest.approx(0.1)
    assert math.isnan(raw["spearman"])  # no confidence: no statistics of it
    assert by["paper"]["n"] == 1 and by["paper"]["iou_mean"] == pytest.approx(0.8)
    grouped = summarise(rows, by=("method",))
    assert [s["method"] for s in grouped] == ["raw", "paper"] and set(grouped[0]) >= {"n", "iou_mean"}


def test_summary_of_groups_that_all_failed_is_nan():
    (only,) = summarise([row(error="x", iou=float("nan"))])
    assert only["n"] == 1 and only["failed"] == 1 and math.isnan(only["iou_mean"]) and math.isnan(only["ms_median"])


def test_confidence_statistics():
    # Confidence falls exactly as the error grows: Spearman -1; the 80 % most confident skip the worst.
    pairs = zip(np.linspace(1, 0.1, 10), np.arange(1.0, 11.0), strict=True)
    rows = [row(confidence=c, centre_mm=e, reliable=c > 0.45) for c, e in pairs]
    (s,) = summarise(rows)
    assert s["spearman"] == pytest.approx(-1.0)
    assert s["centre_mm_top80"] == pytest.approx(np.mean(np.arange(1.0, 9.0)))
    assert s["reliable_share"] == pytest.approx(0.6)
    flat = [replace(r, confidence=0.5) for r in rows]
    assert math.isnan(summarise(flat)[0]["spearman"])  # no spread in confidence: no correlation


def test_spearman_known_answers_with_ties():
    assert average_ranks(np.array([10.0, 30.0, 20.0, 30.0, 10.0, 10.0])).tolist() == [2.0, 5.5, 4.0, 5.5, 2.0, 2.0]
    assert spearman(np.array([1.0, 2.0, 3.0, 4.0]), np.array([8.0, 6.0, 4.0, 2.0])) == pytest.approx(-1.0)
    # ranks (1.5, 1.5, 3, 4) and (1, 3, 2, 4), both about 2.5: Pearson 3 / sqrt(4.5 * 5)
    got = spearman(np.array([5.0, 5.0, 7.0, 9.0]), np.array([1.0, 3.0, 2.0, 4.0]))
    assert got == pytest.approx(3.0 / math.sqrt(4.5 * 5.0))
    constant, nan = ([1.0, 1.0, 1.0], [1.0, 2.0, 3.0]), ([1.0, math.nan, 3.0], [1.0, 2.0, 3.0])
    for x, y in (constant, constant[::-1], nan, nan[::-1]):
        assert math.isnan(spearman(np.array(x), np.array(y)))  # a constant or a NaN: no correlation


def _defined_ranks(v: np.ndarray) -> np.ndarray:
    """Ranks as the definition counts them: 1 + the values below + half the others equal."""
    return np.array([1 + np.sum(v < e) + (np.sum(v == e) - 1) / 2 for e in v])


@given(st.lists(st.tuples(st.integers(0, 6), st.floats(-1e3, 1e3)), min_size=3, max_size=40))
def test_spearman_is_pearson_of_the_ranks_by_their_definition(pairs):
    """Ties drawn often (x takes seven values); y any finite numbers."""
    x = np.array([float(a) for a, _ in pairs])
    y = np.array([b for _, b in pairs])
    rx, ry = _defined_ranks(x), _defined_ranks(y)
    np.testing.assert_array_equal(average_ranks(x), rx)
    np.testing.assert_array_equal(average_ranks(y), ry)
    if np.ptp(x) > 0 and np.ptp(y) > 0:
        dx, dy = rx - rx.mean(), ry - ry.mean()
        assert spearman(x, y) == pytest.approx(np.sum(dx * dy) / math.sqrt(np.sum(dx**2) * np.sum(dy**2)), abs=1e-12)
    else:
        assert math.isnan(spearman(x, y))


def test_worst_case_statistics():
    rows = [row(pose=0, iou=0.5, centre_mm=12.0), row(pose=1, iou=0.6, centre_mm=8.0),
            row("fit", pose=0, iou=0.4, centre_mm=11.0, confidence=0.1), row("fit", pose=1, iou=0.9, centre_mm=1.0,
                                                                           confidence=0.9, reliable=True)]  # fmt: skip
    by = {s["method"]: s for s in summarise(rows)}
    assert (by["raw"]["centre_mm_max"], by["raw"]["over_10mm"], by["raw"]["below_raw"]) == (12.0, 1, 0)
    assert (by["fit"]["centre_mm_max"], by["fit"]["over_10mm"], by["fit"]["below_raw"]) == (11.0, 1, 1)
    assert by["fit"]["bad_flagged"] == 1.0  # the one view off by more than 10 mm is flagged unreliable
    alone = summarise([r for r in rows if r.method == "fit"])
    assert math.isnan(alone[0]["below_raw"])  # no raw run: nothing to compare with


def test_scans_are_grouped_by_scan():
    rows = [row(fruit="/data/scans", kind="scan/pear", pose=0), row(fruit="/data/scans", kind="scan/banana", pose=1)]
    assert {s["fruit"] for s in summarise(rows)} == {"scan/pear", "scan/banana"}
    assert rows[0].label == "scan/pear" and row().label == "apple"


def _blas_threads() -> list[int]:
    from threadpoolctl import threadpool_info

    return sorted({info["num_threads"] for info in threadpool_info() if info["user_api"] == "blas"})


def test_a_worker_runs_numpys_blas_on_one_thread():
    """Stop 52: a forked worker inherits the BLAS threads numpy's OpenBLAS started with (OPENBLAS_NUM_THREADS set
    after the fork no longer reaches it); the workers' initializer limits them by threadpoolctl. The parent is
    given two threads here (the test processes run with one), so a worker that kept them would say 2."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from symfruit.threads import one_blas_thread

    fork = multiprocessing.get_context("fork")  # the runner's workers on Linux (Python's default there before 3.14)

    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        if _blas_threads() != [2]:
            pytest.skip(f"numpy's BLAS here cannot run two threads ({_blas_threads()})")
        with ProcessPoolExecutor(max_workers=1, mp_context=fork) as pool:
            assert pool.submit(_blas_threads).result(timeout=600) == [2]  # what a worker inherits
        with ProcessPoolExecutor(max_workers=1, mp_context=fork, initializer=one_blas_thread) as pool:
            assert pool.submit(_blas_threads).result(timeout=600) == [1]
