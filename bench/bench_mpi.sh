#!/usr/bin/env bash
# Parallel runs (src/parallel): figures only, never pass/fail on time.
#  1. Distributed work with 1 and 2 ranks on Cook's membrane (Neo-Hooke, 2 load steps, MUMPS), at COOK_SIZES
#     particles per side: shape functions and pattern (time_cache_and_pattern) and the Newton assemblies
#     (time_assemble, which under MPI includes the wait for the residual sum). Two speed-ups: wall clock (what
#     a user sees; needs two idle cores) and CPU (serial CPU time of the work / the largest rank's, thread CPU
#     time without the wait: whether the work itself divides, whatever else runs on the machine). Per-rank
#     points, own matrix entries, CPU times and waits are printed from the log. About 80 s.
#  2. PETSc's additive Schwarz (CG, CHOLMOD subdomains: solver.petsc = asm-cholmod) on a 3-D linear elastic cube
#     of CUBE_N³ particles (33: 107 811 dofs) with the lean settings of input/cube3d_million.cfg: Krylov
#     iterations against subdomains (ranks 2, 3, 4, oversubscribed beyond 2) and overlap (0, 1, 2), times and
#     peak memory per rank. Slow (the subdomain factorizations: minutes per run at 33³); CUBE_N=0 skips it.
# One command for part 1 only:  MPI_BENCH=speedup bash bench/bench_mpi.sh
# The ranks share the machine's cores with whatever else runs: the load average is printed with the figures.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
out=${OUT_DIR:-build/bench-out}/mpi
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
cores=$(nproc)
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 # one thread per rank: the ranks are the parallelism
MPIRUN=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
v() { sed -n "s/^ *\"$1\": *\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2" | head -n 1; }
add() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", a + b }'; }
mb() { [ -n "$1" ] && awk -v p="$1" 'BEGIN { printf "%.0f", p / 1e6 }' || echo -; }
if ! "${MPIRUN[@]}" -np 2 "$MICA" --version > /dev/null 2>&1; then
  echo "bench_mpi: mpirun cannot start processes here; no parallel figures"
  exit 0
fi
echo "cores: $cores, load average before: $(cut -d' ' -f1-3 /proc/loadavg)"

speedup() {
  local n=$1
  echo "-- Cook's membrane, Neo-Hooke, ${n}x$n particles, 2 load steps (MUMPS under mpirun)"
  printf '%5s %8s %7s %10s %10s %10s %9s %9s %9s %9s\n' ranks dofs points cache+pat assemble dist.work cpu.work \
    newton peak_MB tip_uy
  local np
  for np in 1 2; do
    local d="$out/cook_${n}_$np"
    "${MPIRUN[@]}" -np $np "$MICA" run input/cook_neohooke.cfg -o "$d" --set "particles.count=[$n,$n]" \
      --set solver.steps=2 --set output.monitor=false --set output.vtu=false > "$d.log" 2>&1 \
      || { echo "np $np failed: $(tail -n 2 "$d.log")"; return; }
    local s="$d/summary.json" work cpu
    work=$(add "$(v time_cache_and_pattern "$s")" "$(v time_assemble "$s")")
    if [ $np = 1 ]; then
      cpu=$(add "$(v cpu_cache_and_pattern "$s")" "$(v cpu_assemble "$s")")
    else # the largest rank's CPU time of the work, without its wait in the residual sum
      cpu=$(paste <(sed -n '/"rank_cpu_cache_and_pattern"/,/]/p' "$s" | grep -o '[0-9.e+-]*[0-9]') \
                  <(sed -n '/"rank_cpu_assemble"/,/]/p' "$s" | grep -o '[0-9.e+-]*[0-9]') |
            awk '{ t = $1 + $2; if (t > m) m = t } END { printf "%.3f", m }')
    fi
    eval "work_$np=$work cpu_$np=$cpu"
    printf '%5s %8s %7s %10.3f %10.3f %10.3f %9.3f %9.3f %9s %9.6f\n' $np "$(v dofs "$s")" "$(v quadrature_points "$s")" \
      "$(v time_cache_and_pattern "$s")" "$(v time_assemble "$s")" "$work" "$cpu" "$(v time_newton "$s")" \
      "$(mb "$(v peak_memory "$s")")" "$(v tip_uy "$s")"
    [ $np = 2 ] && grep -E '^  rank [0-9]+:' "$d.log"
  done
  awk -v a="$work_1" -v b="$work_2" -v c="$cpu_1" -v d="$cpu_2" -v load="$(cut -d' ' -f1-3 /proc/loadavg)" \
    'BEGIN { if (b > 0 && d > 0)
      printf "speed-up of the distributed work, 1 -> 2 ranks: wall %.2f, CPU %.2f   (load average %s)\n", a / b, c / d, load }'
}
for n in ${COOK_SIZES-41 61}; do speedup "$n"; done
echo "(dist.work: wall seconds of cache+pattern + assemble; cpu.work: their thread CPU seconds, the largest rank's"
echo " without its wait in the residual sum; peak_MB: getrusage of rank 0; rank lines: CPU of the assembly net of the wait)"
[ "${MPI_BENCH:-all}" = speedup ] && exit 0

N=${CUBE_N:-33}
[ "$N" -gt 0 ] || exit 0
echo "-- CG with additive Schwarz, CHOLMOD subdomains (solver.petsc = asm-cholmod), on a 3-D cube, linear elasticity,"
echo "   ${N}^3 particles ($((3 * N * N * N)) dofs), linear basis, ball supports of dilation 1.5, 2x2x2 Gauss points"
echo "   per cell; solver.linear_rtol 1e-10; the overlap is PETSc's -pc_asm_overlap (layers of matrix couplings)"
printf '%5s %7s %8s %10s %12s %9s %9s %9s %11s\n' ranks overlap dofs iterations residual factor solve newton \
  peak_MB/rank
for np in ${CUBE_RANKS:-2 3 4}; do
  for overlap in ${CUBE_OVERLAPS:-0 1 2}; do
    d="$out/cube_${N}_${np}_$overlap"
    sed 's/^solver = .*/solver = { linear = "petsc"; petsc = "asm-cholmod"; linear_rtol = 1e-10; rtol = 1e-8; };/' \
      input/cube3d_million.cfg > "$d.cfg"
    "${MPIRUN[@]}" -np $np "$MICA" run "$d.cfg" -o "$d" --set parameters.n=$N \
      --set solver.petsc_options="\"-pc_asm_overlap $overlap\"" --set output.monitor=false \
      > "$d.log" 2>&1 || { echo "np $np overlap $overlap failed: $(tail -n 2 "$d.log")"; continue; }
    s="$d/summary.json"
    printf '%5s %7s %8s %10s %12.3e %9.2f %9.2f %9.2f %11s\n' $np $overlap "$(v dofs "$s")" \
      "$(v krylov_iterations "$s")" "$(v krylov_last_residual "$s")" "$(v time_factor "$s")" "$(v time_solve "$s")" \
      "$(v time_newton "$s")" "$(mb "$(v peak_memory_rank_max "$s")")"
  done
done
echo "(residual: |b - Ax| / |b| after the last CG iteration, tolerance 1e-10)"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
