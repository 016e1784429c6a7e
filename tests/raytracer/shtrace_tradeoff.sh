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
# The script, run by itself, draws the plot under the plot's own name.
rm "$out.png"
gnuplot "$out.gp"
test "$(head -c 4 "$out.png" | tail -c 3)" = PNG
# The front: of settings whose errors lie within 1 % of each other, one at
# most (the fastest) is on it.
awk -F, 'NR > 1 && $1 !~ /^#/ { ms[NR] = $8; e[NR] = $9; p[NR] = $12 }
         END { for (i in e) for (j in e) if (i != j && p[i] && p[j] && e[j] <= e[i] * 1.01 && e[j] >= e[i] * 0.99) {
                 print "both on the front though their errors differ by under 1 %: rows " i ", " j; exit 1 } }' "$out.csv"
# Every setting runs on the backends asked for, the ones varied one at a
# time around 16 samples too (they ran on cpu whatever was asked).
"$shtrace" tradeoff --size 8x6 --backends interp --out "$dir/interp/tradeoff" > /dev/null 2>&1
awk -F, 'NR > 1 && $1 !~ /^#/ && $1 != "interp" { print "a setting on " $1 ": " $0; bad = 1 } END { exit bad }' \
  "$dir/interp/tradeoff.csv"
test "$(grep -c '^interp,' "$dir/interp/tradeoff.csv")" = 16
# An output that cannot be put in place (its name is a directory) is an
# error that says why, and leaves no temporary file.
blocked="$dir/blocked/tradeoff"
mkdir -p "$blocked.csv"
if "$shtrace" tradeoff --size 32x24 --backends cpu --out "$blocked" > /dev/null 2> "$dir/blocked.txt"; then
  echo "an --out whose CSV is a directory was accepted"; exit 1
fi
grep -q "tradeoff.csv: exists and is not a regular file" "$dir/blocked.txt" || { cat "$dir/blocked.txt"; exit 1; }
# A scene file's name goes into the plot's title: a newline in it, which
# would end gnuplot's string and run the rest as a command, is shown as '?'.
data=$(cd "$(dirname "$0")/data" && pwd)
evil="x
system \"touch ran\"
#.json"
(cd "$dir" && cp "$data/flat_box.json" "$evil" &&
 "$shtrace" tradeoff --scene "$evil" --size 8x6 --backends cpu --out evil/tradeoff > /dev/null 2>&1)
test ! -e "$dir/ran" || { echo "a scene file's name ran as gnuplot's command"; exit 1; }
grep -q "set title 'Error against render time, scene .*x?system" "$dir/evil/tradeoff.gp"
# An --out that gnuplot's script cannot name is refused before any render.
if "$shtrace" tradeoff --size 8x6 --backends cpu --out "$dir/new
line" > /dev/null 2> "$dir/newline.txt"; then echo "an --out with a newline was accepted"; exit 1; fi
grep -q "an empty name, or one with a control character" "$dir/newline.txt" || { cat "$dir/newline.txt"; exit 1; }
leftovers=$(find "$dir" -name "*.tmp")
test -z "$leftovers" || { echo "temporary files left: $leftovers"; exit 1; }
echo "csv, script and plot under a quoted directory; one setting per error on the front; no temporary files"
