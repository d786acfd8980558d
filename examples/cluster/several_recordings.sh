#!/usr/bin/env bash
# Several recordings in one `detect` run on a real Dask scheduler with two workers on 127.0.0.1: two folders of
# 12 rendered frames that share the name `frames`, the shipped RealSense bag and a file that is no recording; one
# worker killed mid-run and another started; compared with a serial run of the same inputs frame for frame and
# row for row; then `symfruit report` (per recording). `detect` exits 1: the file that is no recording is reported.
#
#   pip install -e '.[cluster,plot,ros]'
#   bash examples/cluster/several_recordings.sh /tmp/season-many      # a work folder (made, emptied)
set -u
HERE=$(cd "$(dirname "$0")/../.." && pwd)
WORK=${1:-/tmp/symfruit-several-recordings}
PORT=${PORT:-8797}
mkdir -p "$WORK" && cd "$WORK" && rm -rf a b serial dist logs notes.txt && mkdir logs
export DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False
worker() { dask worker "tcp://127.0.0.1:$PORT" --host 127.0.0.1 --nthreads 1 --no-nanny --no-dashboard --name "$1" \
             > "logs/$1.log" 2>&1 & }

symfruit scenes a/frames --n 12 --seed 0
symfruit scenes b/frames --n 12 --seed 100
echo "not a recording" > notes.txt
INPUTS="a/frames b/frames $HERE/examples/realsense/fruit.bag notes.txt"
symfruit detect $INPUTS --output serial > logs/serial.txt 2>&1; echo "serial detect exit status: $?"
dask scheduler --host 127.0.0.1 --port "$PORT" --no-dashboard > logs/scheduler.log 2>&1 &
SCHED=$!
sleep 3
worker w1; W1=$!
worker w2; W2=$!
sleep 4
symfruit detect $INPUTS --output dist --scheduler "tcp://127.0.0.1:$PORT" > logs/dist.txt 2>&1 &
RUN=$!
for _ in $(seq 1 3000); do  # until 6 frames are written (at most 300 s)
  [ "$(ls dist/*/*/detections.json 2>/dev/null | wc -l)" -ge 6 ] && break
  sleep 0.1
done
kill -9 "$W1" && echo "killed w1 at $(ls dist/*/*/detections.json | wc -l) frames written"
sleep 2
worker w3; W3=$!
echo "started w3"
wait "$RUN"; echo "detect exit status: $?"
cat logs/dist.txt
symfruit report dist
kill "$W2" "$W3"; wait "$W2" "$W3" 2>/dev/null   # the workers first: they close while their scheduler is up
kill "$SCHED"; wait "$SCHED" 2>/dev/null
python - <<'PY'
import json, pathlib
import pyarrow.parquet as pq

def fruits(out):
    return {str(p.parent.relative_to(out)): [{k: v for k, v in f.items() if k != "seconds"}
                                             for f in json.loads(p.read_text())["fruits"]]
            for p in sorted(pathlib.Path(out).glob("*/*/detections.json"))}

a, b = fruits("serial"), fruits("dist")
print("frames serial / dist:", len(a), len(b), "; equal frame for frame:", a == b)
serial, dist = pq.read_table("serial/detections.parquet"), pq.read_table("dist/detections.parquet")
keys = set(zip(dist["recording"].to_pylist(), dist["frame"].to_pylist(), dist["id"].to_pylist()))
print("table rows:", dist.num_rows, "; fruit in detections.json:", sum(map(len, b.values())),
      "; distinct (recording, frame, id):", len(keys), "; same table as serial:", dist.equals(serial))
errors = json.loads(pathlib.Path("dist/errors.json").read_text())
print("errors.json:", errors, "; as serial:", errors == json.loads(pathlib.Path("serial/errors.json").read_text()))
print("temporary files left:", list(pathlib.Path("dist").rglob("*.tmp")))
PY
ls dist dist/report
