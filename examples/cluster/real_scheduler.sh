#!/usr/bin/env bash
# The check of issue 21 by hand: a real Dask scheduler and two workers on 127.0.0.1, `detect --scheduler` over
# 40 rendered frames, one worker killed mid-run and another started, compared with a serial run frame for
# frame and row for row; then `symfruit report`.
#
#   pip install -e '.[cluster,plot]'
#   bash examples/cluster/real_scheduler.sh /tmp/season      # a work folder (made, emptied)
set -u
HERE=$(cd "$(dirname "$0")/../.." && pwd)
WORK=${1:-/tmp/symfruit-cluster-check}
PORT=${PORT:-8786}
mkdir -p "$WORK" && cd "$WORK" && rm -rf frames serial dist logs && mkdir logs
. "$HERE/examples/cluster/lib.sh"

symfruit scenes frames --n 40
symfruit detect frames --output serial > logs/serial.txt 2>&1
start_cluster
symfruit detect frames --output dist --scheduler "tcp://127.0.0.1:$PORT" > logs/dist.txt 2>&1 &
RUN=$!
kill_and_replace 8 "dist/*/detections.json"
wait "$RUN"; echo "detect exit status: $?"
cat logs/dist.txt
symfruit report dist
stop_cluster
python "$HERE/examples/cluster/compare.py" serial dist
ls dist/report
