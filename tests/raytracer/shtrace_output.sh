#!/usr/bin/env bash
# `shtrace render` without -o names the image after the scene and never
# replaces a file; with -o it replaces the file named and says so.
set -eu
shtrace=$1
data=$2   # tests/raytracer/data
dir=$3
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir"
render() { "$shtrace" render --backend interp "$@"; }
is_png() { test "$(head -c 4 "$1" | tail -c 3)" = PNG; }

render --scene cornell --size 8x6 > first.txt
is_png out/cornell.png
grep -q "^image: .*/out/cornell.png$" first.txt
cp out/cornell.png cornell-first.png
echo "default name: out/cornell.png"

render --scene cornell --size 10x6 > second.txt
is_png out/cornell-2.png
cmp out/cornell.png cornell-first.png
grep -q "out/cornell.png exists and is kept; this image is out/cornell-2.png" second.txt
grep -q "^image: .*/out/cornell-2.png$" second.txt
render --scene cornell --size 8x6 > third.txt
grep -q "^image: .*/out/cornell-3.png$" third.txt
echo "a second and a third render: out/cornell-2.png, out/cornell-3.png; out/cornell.png kept"

render --scene "$data/flat_box.json" --size 8x6 > file.txt
grep -q "^image: .*/out/flat_box.png$" file.txt
echo "a scene file: out/flat_box.png"

echo "not an image" > mine.png
render --scene cornell --size 8x6 -o mine.png > replaced.txt
grep -q "^replacing mine.png$" replaced.txt
is_png mine.png
render --scene cornell --size 8x6 -o fresh.png > fresh.txt
if grep -q "replacing" fresh.txt; then echo "a new file reported as replaced"; exit 1; fi
echo "-o: an existing file is replaced with a line saying so; a new one without"

render --scene cornell --size 8x6 -o aov.png --aov maps/cornell > aov.txt
test -s maps/cornell_distance.pfm && test -s maps/cornell_triangle.pfm
grep -q "^aov: maps/cornell_distance.pfm, maps/cornell_triangle.pfm$" aov.txt
echo "--aov: its directory made, both maps written"

refused() {  # the command fails, with a message naming the option, and writes no image
  local option=$1; shift
  if render --scene cornell -o refused.png "$@" > refused.txt 2>&1; then echo "accepted: $*"; exit 1; fi
  grep -q -- "$option" refused.txt || { echo "no word of $option for: $*"; cat refused.txt; exit 1; }
  test ! -e refused.png
}
refused --size --size 8x6x3
refused --size --size 8x6abc
refused fov --size 8x6 --fov 0
refused fov --size 8x6 --fov -30
refused fov --size 8x6 --fov 180
echo "bad --size and --fov are errors naming them"

leftovers=$(find . -name "*.tmp" -o -name ".*.png.*")
test -z "$leftovers" || { echo "temporary files left: $leftovers"; exit 1; }
echo "no temporary files left"
