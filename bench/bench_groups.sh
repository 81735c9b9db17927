#!/usr/bin/env bash
# Sweeps on groups of ranks (issue 19, item 4): the wall time of an 8-point sweep (the cantilever of
# input/sweep_cantilever.cfg at L = 10 .. 17 with 8L + 1 by 17 particles, about 2 800 to 4 700 dofs a point)
# run serially and with `mpirun -np 2` on one-rank groups (sweep.ranks_per_point = 1: points 1, 3, 5, 7 on
# rank 0, 2, 4, 6, 8 on rank 1), alternating, GROUPS_REPEAT times each (default 3); the minimum of each and
# their ratio (serial / groups: > 1 is a speed-up). The parallel wall time includes mpirun's start-up; the
# launch alone (`mpirun -np 2 mica --version`, which starts no MPI) is printed too. One BLAS thread per process.
# Figures only: never passes or fails on time. About 40 s. The machine's load average is printed with them.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
out=${OUT_DIR:-build/bench-out}/groups
REPEAT=${GROUPS_REPEAT:-3}
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
MPIRUN=(mpirun --oversubscribe -x OPENBLAS_NUM_THREADS -x OMP_NUM_THREADS)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
if ! "${MPIRUN[@]}" -np 2 "$MICA" --version > /dev/null 2>&1; then
  echo "bench_groups: mpirun cannot start processes here; no figures"
  exit 0
fi
sweep=(sweep input/sweep_cantilever.cfg --set sweep.chart=false --set 'particles.count=["8*L+1","17"]'
       --set 'sweep.parameters=({ path = "parameters.L"; values = [10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0, 17.0]; })')
# wall COMMAND...: seconds the command takes (it must succeed)
wall() {
  local start end
  start=$(date +%s.%N)
  "$@" > "$out/last.log" 2>&1 || { echo "bench_groups: failed: $*"; tail -n 3 "$out/last.log"; exit 1; }
  end=$(date +%s.%N)
  awk -v s="$start" -v e="$end" 'BEGIN { printf "%.3f", e - s }'
}
min() { awk -v a="$1" -v b="$2" 'BEGIN { print (a == "" || b + 0 < a + 0) ? b : a }'; }
echo "cores: $(nproc --all), load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
serial="" groups="" startup=""
for r in $(seq 1 "$REPEAT"); do
  s=$(wall "$MICA" "${sweep[@]}" -o "$out/serial")
  g=$(wall "${MPIRUN[@]}" -np 2 "$MICA" "${sweep[@]}" -o "$out/groups")
  u=$(wall "${MPIRUN[@]}" -np 2 "$MICA" --version)
  echo "  repeat $r: serial $s s, -np 2 one-rank groups $g s, mpirun launch $u s"
  serial=$(min "$serial" "$s") groups=$(min "$groups" "$g") startup=$(min "$startup" "$u")
done
# the tables must be the same: the figure compares equal work
diff <(cut -d, -f1-4 "$out/serial/sweep.csv") <(cut -d, -f1-4 "$out/groups/sweep.csv") > /dev/null \
  || { echo "bench_groups: the -np 2 table differs from the serial one"; exit 1; }
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
awk -v s="$serial" -v g="$groups" -v u="$startup" -v n="$REPEAT" 'BEGIN {
  printf "sweep of 8 points, minimum of %d: serial %.2f s, mpirun -np 2 (one rank per point) %.2f s: ratio %.2f", n, s, g, s / g
  printf " (less the launch of mpirun -np 2 mica --version, %.2f s: %.2f)\n", u, s / (g - u) }'
