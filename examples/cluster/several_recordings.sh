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
. "$HERE/examples/cluster/lib.sh"

symfruit scenes a/frames --n 12 --seed 0
symfruit scenes b/frames --n 12 --seed 100
echo "not a recording" > notes.txt
INPUTS="a/frames b/frames $HERE/examples/realsense/fruit.bag notes.txt"
symfruit detect $INPUTS --output serial > logs/serial.txt 2>&1; echo "serial detect exit status: $?"
start_cluster
symfruit detect $INPUTS --output dist --scheduler "tcp://127.0.0.1:$PORT" > logs/dist.txt 2>&1 &
RUN=$!
kill_and_replace 6 "dist/*/*/detections.json"
wait "$RUN"; echo "detect exit status: $?"
cat logs/dist.txt
symfruit report dist
stop_cluster
python "$HERE/examples/cluster/compare.py" serial dist
ls dist dist/report
