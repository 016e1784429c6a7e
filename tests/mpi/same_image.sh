#!/usr/bin/env bash
# `mpirun -np 2 shtrace render --backend mpi` gives the image `cpu` gives,
# with the accelerator auto builds (a BVH on spheres), with the grid, and
# with a lazy octree that each rank builds for itself.
set -eu
mpirun=$1
shtrace=$2
dir=$3
mkdir -p "$dir"
"$shtrace" render --scene spheres --size 160x120 --backend cpu --output "$dir/cpu.png"
"$mpirun" -np 2 "$shtrace" render --scene spheres --size 160x120 --backend mpi --output "$dir/mpi.png"
cmp "$dir/cpu.png" "$dir/mpi.png"
echo "the mpi image is identical to the cpu image"
"$mpirun" -np 2 "$shtrace" render --scene spheres --size 160x120 --backend mpi --accel grid --output "$dir/mpi_grid.png"
cmp "$dir/cpu.png" "$dir/mpi_grid.png"
echo "the mpi image over the grid is the cpu image over the BVH"
"$mpirun" -np 2 "$shtrace" render --scene spheres --size 160x120 --backend mpi --accel lazy-octree \
  --output "$dir/mpi_lazy.png" | tee "$dir/mpi_lazy.txt"
cmp "$dir/cpu.png" "$dir/mpi_lazy.png"
grep -q "rank 0: [1-9][0-9]* nodes built" "$dir/mpi_lazy.txt"
grep -q "rank 1: [1-9][0-9]* nodes built" "$dir/mpi_lazy.txt"
grep -q "overlap: [1-9][0-9]* distinct nodes built" "$dir/mpi_lazy.txt"
echo "the lazy octree built on each rank gives the same image; both ranks built nodes"
# Bidirectional: the light pass's elements are handed out in chunks to both
# ranks, each adding into its own sums that rank 0 adds up; the sums differ
# from cpu's only in the order of the additions, which depends on which
# rank (and thread) took which chunk, so the energy that arrived agrees to
# the digits printed, give or take one in the last (a sum near a rounding
# boundary may print either way).
same_energy() {
  test -s "$1" && test -s "$2"
  paste "$1" "$2" | awk '{ for (i = 4; i <= 6; ++i) { a = $i; b = $(i + 6); d = a > b ? a - b : b - a;
    m = a < 0 ? -a : a; if (d > 1.5e-3 * m) { print "energy differs: " $0; exit 1 } } }'
}
"$shtrace" render --scene magg-glass --size 100x100 --backend cpu --bidirectional --output "$dir/bidir_cpu.png" \
  | grep "energy arrived" | sed 's/.*energy arrived/energy arrived/' > "$dir/bidir_cpu.txt"
"$mpirun" -np 2 "$shtrace" render --scene magg-glass --size 100x100 --backend mpi --bidirectional \
  --output "$dir/bidir_mpi.png" | grep "energy arrived" | sed 's/.*energy arrived/energy arrived/' > "$dir/bidir_mpi.txt"
same_energy "$dir/bidir_cpu.txt" "$dir/bidir_mpi.txt"
echo "the light pass on 2 ranks delivers the energy it delivers on cpu: $(cat "$dir/bidir_mpi.txt")"
# Split tables: every scene table in blocks spread over the 2 ranks, read
# through caches of 8 blocks filled by one-sided reads; the image and the
# light pass's energy are what whole tables give.
"$mpirun" -np 2 "$shtrace" render --scene spheres --size 160x120 --backend mpi --accel grid --set split_tables=0 \
  --set cache_blocks=8 --output "$dir/mpi_split.png" | tee "$dir/mpi_split.txt"
cmp "$dir/cpu.png" "$dir/mpi_split.png"
grep -q "render: split table cell_start .* [1-9][0-9]* from other ranks" "$dir/mpi_split.txt"
# With a lazy octree each rank's tree is its own and read whole; the rest split.
"$mpirun" -np 2 "$shtrace" render --scene spheres --size 160x120 --backend mpi --accel lazy-octree --set split_tables=0 \
  --set cache_blocks=8 --output "$dir/mpi_lazy_split.png" > /dev/null
cmp "$dir/cpu.png" "$dir/mpi_lazy_split.png"
"$mpirun" -np 2 "$shtrace" render --scene magg-glass --size 100x100 --backend mpi --bidirectional --set split_tables=0 \
  --set cache_blocks=8 --output "$dir/bidir_split.png" | grep "energy arrived" | sed 's/.*energy arrived/energy arrived/' \
  > "$dir/bidir_split.txt"
same_energy "$dir/bidir_cpu.txt" "$dir/bidir_split.txt"
echo "split tables read through caches give the same image and the same light-pass energy"
