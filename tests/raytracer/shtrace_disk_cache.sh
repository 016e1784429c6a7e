#!/usr/bin/env bash
# A render's kernels compiled into an emptied disk cache by one shtrace
# process, then loaded from it by the next, which says so beside its
# compile time.
set -eu
shtrace=$1
dir=$2
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir"
render() { SH_CACHE_DIR="$dir/cache" "$shtrace" render --scene cornell --size 8x6 --backend cpu -o "$1.png" > "$1.txt"; }

render first
grep -q "^rendered 8x6 on cpu: compile [0-9.]* ms, render" first.txt
echo "an empty cache: $(grep -o 'compile [0-9.]* ms' first.txt), compiled"

render second
grep -q "^rendered 8x6 on cpu: compile [0-9.]* ms (loaded from the disk cache), render" second.txt
echo "a full cache: $(grep -o 'compile [0-9.]* ms (loaded from the disk cache)' second.txt)"
