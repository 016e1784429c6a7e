#!/usr/bin/env bash
# `shtrace tradeoff` writes its CSV, its gnuplot script and the plot, under
# an --out whose directory holds a quote and a space, and leaves no
# temporary file.
set -eu
shtrace=$1
dir=$2
rm -rf "$dir"
out="$dir/it's a plot/tradeoff"
mkdir -p "$(dirname "$out")"
"$shtrace" tradeoff --size 32x24 --backends cpu --out "$out" > "$dir/said.txt" 2> "$dir/progress.txt"
grep -q "^16 settings; csv: .*tradeoff.csv, plot: .*tradeoff.png$" "$dir/said.txt"
test "$(head -n 1 "$out.csv" | cut -c 1-7)" = backend
test "$(head -c 4 "$out.png" | tail -c 3)" = PNG
if grep -q "gnuplot failed" "$dir/progress.txt"; then cat "$dir/progress.txt"; exit 1; fi
leftovers=$(find "$dir" -name "*.tmp")
test -z "$leftovers" || { echo "temporary files left: $leftovers"; exit 1; }
echo "csv, script and plot under a quoted directory; no temporary files"
