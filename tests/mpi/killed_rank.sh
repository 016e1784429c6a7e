#!/usr/bin/env bash
# A rank killed mid-run ends the whole job, non-zero, with a message that
# names it, within seconds: never a hang.
set -u
mpirun=$1
helper=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$mpirun" --oversubscribe -np 3 "$helper" "$dir" > "$dir/out.txt" 2>&1 &
job=$!
# Rank 1 may be slow to start on a loaded machine: wait up to a minute.
for _ in $(seq 600); do [ -s "$dir/rank1.pid" ] && break; sleep 0.1; done
[ -s "$dir/rank1.pid" ] || { echo "FAIL: rank 1 did not start within 60 s"; kill -9 "$job"; exit 1; }
sleep 2
kill -9 "$(cat "$dir/rank1.pid")"
killed_at=$(date +%s)
for _ in $(seq 300); do kill -0 "$job" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$job" 2>/dev/null; then
  echo "FAIL: the job still runs 30 s after rank 1 was killed"
  kill -9 "$job"
  exit 1
fi
wait "$job"
status=$?
took=$(( $(date +%s) - killed_at ))
cat "$dir/out.txt"
[ "$status" -ne 0 ] || { echo "FAIL: the job exited 0"; exit 1; }
grep -q "rank 1" "$dir/out.txt" || { echo "FAIL: no message names rank 1"; exit 1; }
echo "PASS: job ended with status $status ${took}s after rank 1 was killed"
