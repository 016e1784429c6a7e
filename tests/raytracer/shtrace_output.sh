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
refused fov --size 8x6 --fov nan
refused size --size 32768x32768
refused eye --size 8x6 --eye 1,2,3,4
refused threads --size 8x6 --threads 10000000
refused grid-density --size 8x6 --grid-density nan
echo "bad --size, --fov, --eye, --threads and --grid-density are errors naming them"

# Every output named is checked before the render: a bad one leaves no
# image behind, and a device or a pipe in an output's place is refused,
# never replaced by a file.
mkfifo pipe
refused "pipe/maps_distance.pfm: cannot make its directory pipe" --size 8x6 --aov pipe/maps
refused "not a regular file" --size 8x6 --dump-ir-bytes "$dir"
if render --scene cornell --size 8x6 -o pipe > pipe.txt 2>&1; then echo "a pipe replaced by an image"; exit 1; fi
test -p pipe
grep -q "pipe: exists and is not a regular file" pipe.txt
echo "outputs checked before the render; a pipe is not replaced"

# An output that is an input, or that another output also names, is
# refused before the render; so is a name too long for its temporary.
cp "$data/flat_box.json" scene.json
if render --scene scene.json --size 8x6 -o scene.json > input.txt 2>&1; then echo "the scene replaced"; exit 1; fi
grep -q "scene.json: is an input of this command" input.txt
cmp scene.json "$data/flat_box.json"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > tri.obj
cp tri.obj tri-before.obj
printf '{"lights": [{"position": [0, 3, 2]}], "objects": [{"type": "mesh", "file": "tri.obj"}]}' > names-model.json
if render --scene names-model.json --size 8x6 -o tri.obj > model.txt 2>&1; then echo "the model replaced"; exit 1; fi
grep -q "tri.obj: is an input of this command" model.txt
cmp tri.obj tri-before.obj
refused "named for two outputs" --size 8x6 --dump-ir-bytes ./refused.png
if render --scene cornell --size 8x6 -o p_distance.pfm --aov p > twice.txt 2>&1; then echo "one file, two outputs"; exit 1; fi
grep -q "p_distance.pfm: named for two outputs" twice.txt
test ! -e p_distance.pfm
long=$(printf 'a%.0s' $(seq 246)).png
if render --scene cornell --size 8x6 -o "$long" > long.txt 2>&1; then echo "a name too long for its temporary"; exit 1; fi
grep -q "a file name of 250 bytes: at most" long.txt
render --scene cornell --size 8x6 -o cornell > builtin.txt
is_png cornell
echo "an input (a scene file, a model it names), one file named twice and a name too long are refused before the" \
  "render; a built-in scene's name is no file"

# A file-size limit (ulimit -f) fails the write, as a full disk would, and
# leaves nothing behind, where its signal would end the process.
if (ulimit -f 1; SH_CACHE_DIR=off render --scene cornell --size 64x48 -o limited.png > limited.txt 2>&1); then
  echo "an image past the file-size limit reported as written"; exit 1
fi
grep -q "limited.png: cannot write the image" limited.txt
test ! -e limited.png
echo "past the file-size limit: an error, no file"

# Other subcommands' inputs and outputs.
if "$shtrace" ir /dev/zero > ir.txt 2>&1; then echo "ir read /dev/zero"; exit 1; fi
grep -q "/dev/zero: not a regular file" ir.txt
if "$shtrace" info > /dev/full 2> full.txt; then echo "info wrote to a full disk and exited 0"; exit 1; fi
grep -q "cannot write standard output" full.txt
if "$shtrace" compare --scene cornell --size 8x6 --runs 1 --backends no-such > compare.txt 2>&1; then
  echo "compare exited 0 with a failed row"; exit 1
fi
grep -q "1 rows, 1 failed" compare.txt
echo "ir refuses a device, a full standard output fails the command, compare fails with its rows"
for cmd in bench compare; do
  if "$shtrace" $cmd --scene cornell --size 8x6 --backends , --threads 1 > stray.txt 2>&1; then
    echo "$cmd took --threads for a backend"; exit 1
  fi
  grep -q "'--threads' is an option, not a backend name" stray.txt
done
echo "an empty --backends list is an error, not the next option read as a backend"

leftovers=$(find . -name "*.tmp" -o -name ".*.png.*")
test -z "$leftovers" || { echo "temporary files left: $leftovers"; exit 1; }
echo "no temporary files left"
