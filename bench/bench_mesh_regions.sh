#!/usr/bin/env bash
# A Gmsh mesh on distributed data (figures only, never pass/fail): what building the discretization costs each rank
# when a .msh file is read in passes — its groups and a sample of its nodes, then each rank its region around its
# box (src/geom/mesh_part.c, src/parallel/own_mesh.c) — against one process reading it whole. The mesh: the unit
# cube in N³ × 6 tetrahedra (bench/gmsh_cube_mesh.py, a 2.2 file; N = 40 by default: 68 921 nodes, 384 000
# tetrahedra, 19 MB), the 3-D tension deck tests/decks/parallel/cube_gmsh.cfg on it with one Gauss point per
# tetrahedron; `mica check` builds the discretization, MLS approximation, shape-function cache and pattern and
# solves nothing. Printed per P (1: serial, the whole mesh; 2 and 4: parallel.data = "distributed"): the time of
# the first pass (time_discretize: at P = 1 the whole read and discretization), of the distribution (regions,
# supports, ghosts: time_partition), and the largest rank's peak resident memory once the discretization, MLS
# approximation and distribution are built, before the solid's caches (peak_memory_build_max), with its ratio to
# the serial one. Alternating P = 1, 2, 4, REPEATS times (default 3), the minimum kept. P = 4 oversubscribes a
# 2-core machine: its times are not speeds.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
N=${N:-40}
REPEATS=${REPEATS:-3}
out=${OUT_DIR:-build/bench-out}/mesh_regions
mkdir -p "$out"
source bench/mpi_common.bash
mesh="$out/cube$N.msh"
[ -s "$mesh" ] || python3 bench/gmsh_cube_mesh.py "$N" > "$mesh" || { echo "cannot write $mesh"; exit 1; }
deck="$out/cube.cfg"
abs_mesh=$mesh; [ "${mesh#/}" != "$mesh" ] || abs_mesh=$PWD/$mesh # OUT_DIR may be absolute
sed "s|\"../../../input/meshes/cube.geo\"; mesh_size_factor = 0.5;|\"$abs_mesh\";|" tests/decks/parallel/cube_gmsh.cfg \
  > "$deck"
grep -q "cube$N.msh" "$deck" || { echo "$deck: the mesh path was not rewritten"; exit 1; }
SET=(--set quadrature.order=1 --set quadrature.vci=false --set output.monitor=false --set solver.linear=\"petsc\"
     --set solver.petsc=\"gmg\")
echo "cube of $((6 * N * N * N)) tetrahedra, $(((N + 1) * (N + 1) * (N + 1))) nodes, $(du -m "$mesh" | cut -f1) MB" \
     "(2.2 ASCII); load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
declare -A first part peak
for ((r = 0; r < REPEATS; r++)); do
  for np in 1 2 4; do
    dir="$out/p$np"
    rm -rf "$dir"
    if [ "$np" = 1 ]; then
      "$MICA" check "$deck" -o "$dir" "${SET[@]}" > "$dir.log" 2>&1 || { echo "P = 1 failed: $(tail -n 2 "$dir.log")"; exit 1; }
      m=$(v peak_memory_build "$dir/summary.json")
    else
      "${MPIRUN[@]}" -np "$np" "$MICA" check "$deck" -o "$dir" "${SET[@]}" --set parallel.data=\"distributed\" \
        > "$dir.log" 2>&1 || { echo "P = $np failed: $(tail -n 2 "$dir.log")"; exit 1; }
      m=$(v peak_memory_build_max "$dir/summary.json")
    fi
    a=$(v time_discretize "$dir/summary.json"); b=$(v time_partition "$dir/summary.json"); b=${b:-0}
    first[$np]=$(awk -v x="$a" -v y="${first[$np]:-1e30}" 'BEGIN { print (x < y ? x : y) }')
    part[$np]=$(awk -v x="$b" -v y="${part[$np]:-1e30}" 'BEGIN { print (x < y ? x : y) }')
    peak[$np]=$m
  done
done
printf '%4s  %14s  %14s  %16s  %8s\n' P "first pass s" "distribute s" "peak (build) MB" "/ serial"
for np in 1 2 4; do
  awk -v p="$np" -v a="${first[$np]}" -v b="${part[$np]}" -v m="${peak[$np]}" -v s="${peak[1]}" \
    'BEGIN { printf "%4d  %14.3f  %14.3f  %16.1f  %8.3f\n", p, a, b, m / 1e6, m / s }'
done
