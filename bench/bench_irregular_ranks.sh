#!/usr/bin/env bash
# The irregular layout on distributed data (figures only, never pass/fail): what building it costs each rank now
# that each rank draws only the Poisson-disk tiles around its box (src/geom/layout.c geom_layout_irregular_box,
# src/parallel/own.c source_build_irregular), against the regular layout of the same counts built the same way (the
# baseline: a rank builds its box of the grid and nothing else). The deck: the 3-D tension cube
# tests/decks/parallel/cube.cfg at N³ particles (N = 41 by default: 68 921 particles), linear basis, one Gauss point
# per cell, VCI off; `mica check` builds the discretization, MLS approximation, shape-function cache and pattern and
# solves nothing. Printed per P (1 serial, 2 and 4 with parallel.data = "distributed") and layout: the
# distribution's time (time_partition; serially the discretization's, time_discretize) and the largest rank's peak
# resident memory once the discretization, MLS approximation and distribution are built (peak_memory_build_max),
# its ratio to the serial peak and the irregular peak over the regular one. Alternating P = 1, 2, 4 and the two
# layouts, REPEATS times (default 3), the minimum kept. P = 4 oversubscribes a 2-core machine: its times are not
# speeds.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
N=${N:-41}
REPEATS=${REPEATS:-3}
out=${OUT_DIR:-build/bench-out}/irregular_ranks
mkdir -p "$out"
source bench/mpi_common.bash
min() { awk -v x="$1" -v y="${2:-1e30}" 'BEGIN { print (x < y ? x : y) }'; }
SET=(--set "particles.count=[$N,$N,$N]" --set quadrature.order=1 --set quadrature.vci=false --set output.monitor=false
     --set solver.linear=\"petsc\" --set solver.petsc=\"gmg\")
echo "cube of $N³ = $((N * N * N)) particles (regular count); load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
declare -A time peak count
for ((r = 0; r < REPEATS; r++)); do
  for np in 1 2 4; do
    for layout in regular irregular; do
      dir="$out/$layout-p$np"
      rm -rf "$dir"
      if [ "$np" = 1 ]; then
        "$MICA" check tests/decks/parallel/cube.cfg -o "$dir" "${SET[@]}" --set particles.layout=\"$layout\" \
          > "$dir.log" 2>&1 || { echo "$layout P = 1 failed: $(tail -n 2 "$dir.log")"; exit 1; }
        m=$(v peak_memory_build "$dir/summary.json"); t=$(v time_discretize "$dir/summary.json")
      else
        "${MPIRUN[@]}" -np "$np" "$MICA" check tests/decks/parallel/cube.cfg -o "$dir" "${SET[@]}" \
          --set particles.layout=\"$layout\" --set parallel.data=\"distributed\" > "$dir.log" 2>&1 \
          || { echo "$layout P = $np failed: $(tail -n 2 "$dir.log")"; exit 1; }
        m=$(v peak_memory_build_max "$dir/summary.json"); t=$(v time_partition "$dir/summary.json")
      fi
      time[$layout$np]=$(min "$t" "${time[$layout$np]:-}")
      peak[$layout$np]=$(min "$m" "${peak[$layout$np]:-}")
      count[$layout]=$(v particles "$dir/summary.json")
    done
  done
done
echo "particles: regular ${count[regular]}, irregular ${count[irregular]}"
printf '%4s  %10s  %14s  %16s  %8s  %14s\n' P layout "build s" "peak (build) MB" "/ serial" "irregular/regular"
for np in 1 2 4; do
  for layout in regular irregular; do
    awk -v p="$np" -v l="$layout" -v t="${time[$layout$np]}" -v m="${peak[$layout$np]}" -v s="${peak[${layout}1]}" \
      -v g="${peak[regular$np]}" 'BEGIN { printf "%4d  %10s  %14.3f  %16.1f  %8.3f  %14.3f\n", p, l, t, m / 1e6, m / s, m / g }'
  done
done
