#!/usr/bin/env bash
# Peak memory per rank, replicated against distributed data (issue 19 item 1; figures only, never pass/fail).
# input/cube3d_million.cfg's lean 3-D tension deck at N³ particles (N = 47: 311 469 dofs), solved by PETSc
# (CG with MEMORY_PETSC, default gamg: GAMG with the rigid motions as near-null space; gmg: geometric multigrid on
# lattices: 0.345 at P = 4 as GAMG's 0.345 on 2026-12-07, since its first Galerkin product is mica's — 0.431 before,
# when PETSc's parallel products held their intermediates; docs/performance.md) in every
# run, so that the runs differ in how the data is
# held, not in the solver: serially (P = 1, the baseline), and at P = 2 and 4 with parallel.data = "replicated"
# (every rank builds every particle, METIS on rank 0, replicated vectors) and "distributed" (each rank its block
# and ghosts). Printed per run: the largest rank's peak resident memory (getrusage's ru_maxrss, as
# mica_parallel_peak_memory reports it: the process's high-water mark, VmHWM) and its ratio to the serial peak;
# the issue's target is ≤ 0.35 at P = 4 with distributed data. The runs follow one another (serial, then for each
# P replicated and distributed), REPEATS times (default 1: memory does not depend on the load; raise it to see
# the spread), the minimum kept. P = 4 oversubscribes a 2-core machine: the times are not speeds. MEMORY_PETSC_OPTIONS
# (default none) goes to solver.petsc_options in every run, serial included, e.g. "-pc_gamg_agg_nsmooths 0"
# (unsmoothed aggregation: a smaller hierarchy, more iterations); the CG iterations are printed with the peaks.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
N=${N:-47}
REPEATS=${REPEATS:-1}
OPTIONS=${MEMORY_PETSC_OPTIONS:-}
PETSC=${MEMORY_PETSC:-gamg}
out=${OUT_DIR:-build/bench-out}/memory_ranks
mkdir -p "$out"
source bench/mpi_common.bash
deck="$out/cube.cfg"
{ grep -v '^output\|^solver\|^                                  {' input/cube3d_million.cfg
  echo "solver = { linear = \"petsc\"; petsc = \"$PETSC\"; linear_rtol = 1e-10; linear_max_iterations = 2000; rtol = 1e-8; };"
  echo 'output = { vtu = false; mesh = false; };'
} > "$deck"
echo "cube ${N}³ particles ($((3 * N * N * N)) dofs), PETSc CG + $PETSC${OPTIONS:+ ($OPTIONS)}; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"

# run NAME NP DATA: the largest rank's peak memory in bytes (serial: the process's), or empty on failure
run() {
  local name=$1 np=$2 data=$3 dir="$out/$1"
  local launch=("${MPIRUN[@]}" -np "$np"); [ "$np" = 1 ] && launch=()
  if ! "${launch[@]}" "$MICA" run "$deck" -o "$dir" --set "parameters.n=$N" --set "parallel.data=\"$data\"" \
    --set output.monitor=false --set "solver.petsc_options=\"$OPTIONS\"" > "$dir.log" 2>&1; then
    echo "bench_memory_ranks: $name failed: $(tail -n 3 "$dir.log")" >&2
    return
  fi
  if [ "$np" = 1 ]; then v peak_memory "$dir/summary.json"; else v peak_memory_rank_max "$dir/summary.json"; fi
}

declare -A best
keep() { [ -n "$2" ] && { [ -z "${best[$1]:-}" ] || [ "$2" -lt "${best[$1]}" ]; } && best[$1]=$2; }
for ((r = 0; r < REPEATS; r++)); do
  keep serial "$(run serial 1 replicated)"
  for np in 2 4; do
    keep "replicated-$np" "$(run "replicated-$np" "$np" replicated)"
    keep "distributed-$np" "$(run "distributed-$np" "$np" distributed)"
  done
done
serial=${best[serial]:-}
printf '%-16s %6s %14s %14s %10s %18s %10s  %s\n' run ranks peak_MB_rank_max ratio_serial ghosts_max particles_held_max cg_its \
  peak_MB_per_rank
for name in serial replicated-2 distributed-2 replicated-4 distributed-4; do
  peak=${best[$name]:-}
  np=1; [ "$name" != serial ] && np=${name##*-}
  ratio=-; [ -n "$peak" ] && [ -n "$serial" ] && ratio=$(awk -v a="$peak" -v b="$serial" 'BEGIN { printf "%.3f", a / b }')
  mbv=-; [ -n "$peak" ] && mbv=$(awk -v p="$peak" 'BEGIN { printf "%.0f", p / 1e6 }')
  ghosts=$(v ghost_particles_max "$out/$name/summary.json" 2>/dev/null); held=-
  [ -f "$out/$name/summary.json" ] && held=$(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(max(d.get('rank_particles_local',[d['particles']])))" "$out/$name/summary.json")
  its=$(v krylov_iterations "$out/$name/summary.json" 2>/dev/null)
  ranks=-; [ -f "$out/$name/summary.json" ] && ranks=$(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(' '.join('%.0f' % (p / 1e6) for p in d.get('rank_peak_memory', [])) or '-')" "$out/$name/summary.json")
  printf '%-16s %6s %14s %14s %10s %18s %10s  %s\n' "$name" "$np" "$mbv" "$ratio" "${ghosts:--}" "$held" "${its:--}" "$ranks"
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
