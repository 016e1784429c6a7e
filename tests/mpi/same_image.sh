#!/usr/bin/env bash
# `mpirun -np 2 shtrace render --backend mpi` gives the image `cpu` gives.
set -eu
mpirun=$1
shtrace=$2
dir=$3
mkdir -p "$dir"
"$shtrace" render --scene spheres --size 160x120 --backend cpu --output "$dir/cpu.png"
"$mpirun" -np 2 "$shtrace" render --scene spheres --size 160x120 --backend mpi --output "$dir/mpi.png"
cmp "$dir/cpu.png" "$dir/mpi.png"
echo "the mpi image is identical to the cpu image"
