# Shared by the cluster examples (sourced, not run): a Dask scheduler and workers on 127.0.0.1, one worker
# killed mid-run and another started, everything stopped in order. Needs PORT and a logs/ folder.
export DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False

worker() {  # worker NAME: a one-thread worker in the background; its pid in $!
  dask worker "tcp://127.0.0.1:$PORT" --host 127.0.0.1 --nthreads 1 --no-nanny --no-dashboard --name "$1" \
    > "logs/$1.log" 2>&1 &
}

start_cluster() {  # the scheduler and workers w1, w2: pids in SCHED, W1, W2
  dask scheduler --host 127.0.0.1 --port "$PORT" --no-dashboard > logs/scheduler.log 2>&1 &
  SCHED=$!
  sleep 3
  worker w1; W1=$!
  worker w2; W2=$!
  sleep 4
}

kill_and_replace() {  # kill_and_replace N GLOB: once N files match GLOB (at most 300 s), kill w1, start w3
  for _ in $(seq 1 3000); do
    [ "$(ls $2 2>/dev/null | wc -l)" -ge "$1" ] && break
    sleep 0.1
  done
  kill -9 "$W1" && echo "killed w1 at $(ls $2 2>/dev/null | wc -l) frames written"
  sleep 2
  worker w3; W3=$!
  echo "started w3"
}

stop_cluster() {  # the workers first: they close while their scheduler is up
  kill "$W2" "$W3"; wait "$W2" "$W3" 2>/dev/null
  kill "$SCHED"; wait "$SCHED" 2>/dev/null
}
