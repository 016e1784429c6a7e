#!/usr/bin/env bash
# A rank killed mid-run ends the whole job, non-zero, with a message that
# names it: never a hang (CTest's timeout stops a job that does not end).
set -u
mpirun=$1
helper=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$mpirun" --oversubscribe -np 3 "$helper" "$dir" > "$dir/out.txt" 2>&1 &
job=$!
# Killed once rank 0's first run has come back: every rank serves by then,
# however slowly the job started.
until [ -s "$dir/running" ]; do
  kill -0 "$job" 2>/dev/null || { cat "$dir/out.txt"; echo "FAIL: the job ended before its first run came back"; exit 1; }
  sleep 0.1
done
kill -9 "$(cat "$dir/rank1.pid")"
wait "$job"
status=$?
cat "$dir/out.txt"
[ "$status" -ne 0 ] || { echo "FAIL: the job exited 0"; exit 1; }
grep -q "rank 1" "$dir/out.txt" || { echo "FAIL: no message names rank 1"; exit 1; }
echo "PASS: job ended with status $status after rank 1 was killed mid-run"
