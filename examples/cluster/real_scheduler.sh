#!/usr/bin/env bash
# The check of issue 21 by hand: a real Dask scheduler and two workers on 127.0.0.1, `detect --scheduler` over
# 40 rendered frames, one worker killed mid-run and another started, compared with a serial run frame for
# frame and row for row; then `symfruit report`.
#
#   pip install -e '.[cluster,plot]'
#   bash examples/cluster/real_scheduler.sh /tmp/season      # a work folder (made, emptied)
set -u
WORK=${1:-/tmp/symfruit-cluster-check}
PORT=${PORT:-8786}
mkdir -p "$WORK" && cd "$WORK" && rm -rf frames serial dist logs && mkdir logs
export DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False
worker() { dask worker "tcp://127.0.0.1:$PORT" --host 127.0.0.1 --nthreads 1 --no-nanny --no-dashboard --name "$1" \
             > "logs/$1.log" 2>&1 & }

symfruit scenes frames --n 40
symfruit detect frames --output serial > logs/serial.txt 2>&1
dask scheduler --host 127.0.0.1 --port "$PORT" --no-dashboard > logs/scheduler.log 2>&1 &
SCHED=$!
sleep 3
worker w1; W1=$!
worker w2; W2=$!
sleep 4
symfruit detect frames --output dist --scheduler "tcp://127.0.0.1:$PORT" > logs/dist.txt 2>&1 &
RUN=$!
for _ in $(seq 1 3000); do  # until 8 frames are written (at most 300 s)
  [ "$(ls dist/*/detections.json 2>/dev/null | wc -l)" -ge 8 ] && break
  sleep 0.1
done
kill -9 "$W1" && echo "killed w1 at $(ls dist/*/detections.json | wc -l) frames written"
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
    return {p.parent.name: [{k: v for k, v in f.items() if k != "seconds"} for f in json.loads(p.read_text())["fruits"]]
            for p in sorted(pathlib.Path(out).glob("*/detections.json"))}

a, b = fruits("serial"), fruits("dist")
print("frames serial / dist:", len(a), len(b), "; equal frame for frame:", a == b)
rows, serial = pq.read_table("dist/detections.parquet").to_pylist(), pq.read_table("serial/detections.parquet").to_pylist()
print("table rows:", len(rows), "; fruit in detections.json:", sum(map(len, b.values())),
      "; distinct (frame, id):", len({(r["frame"], r["id"]) for r in rows}), "; same rows as serial:", rows == serial)
print("errors.json:", json.loads(pathlib.Path("dist/errors.json").read_text()))
print("temporary files left:", list(pathlib.Path("dist").rglob("*.tmp")))
PY
ls dist/report
