"""Compare a distributed `detect` run with a serial one: python compare.py SERIAL DIST.

Frame for frame (every detections.json under each folder, `seconds` left out), the Parquet tables row for
row, the (recording, frame, id) keys distinct, errors.json equal, no temporary file left.
"""

import json
import pathlib
import sys

import pyarrow.parquet as pq


def fruits(out: pathlib.Path) -> dict:
    return {
        str(p.parent.relative_to(out)): [
            {k: v for k, v in f.items() if k != "seconds"} for f in json.loads(p.read_text())["fruits"]
        ]
        for p in sorted(out.rglob("detections.json"))
    }


serial, dist = map(pathlib.Path, sys.argv[1:3])
a, b = fruits(serial), fruits(dist)
print("frames serial / dist:", len(a), len(b), "; equal frame for frame:", a == b)
ts, td = pq.read_table(serial / "detections.parquet"), pq.read_table(dist / "detections.parquet")
cols = [c for c in ("recording", "frame", "id") if c in td.column_names]
keys = set(zip(*(td[c].to_pylist() for c in cols), strict=True))
print(
    f"table rows: {td.num_rows}; fruit in detections.json: {sum(map(len, b.values()))}; "
    f"distinct ({', '.join(cols)}): {len(keys)}; same table as serial: {td.equals(ts)}"
)
errors = json.loads((dist / "errors.json").read_text())
print("errors.json:", errors, "; as serial:", errors == json.loads((serial / "errors.json").read_text()))
print("temporary files left:", list(dist.rglob("*.tmp")))
