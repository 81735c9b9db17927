#!/usr/bin/env bash
# Parallel runs (src/parallel): figures only, never pass/fail on time.
#  1. Distributed work with 1 and 2 ranks on Cook's membrane (Neo-Hooke, 2 load steps): shape functions and
#     pattern (time_cache_and_pattern) and the Newton assemblies (time_assemble, which under MPI includes the
#     residual reduction), their speed-up, the gather time, and peak memory per rank.
#  2. Schwarz (CG, CHOLMOD subdomains) on a 3-D linear cube: Krylov iterations against the number of
#     subdomains (ranks) and the overlap (layers of particles).
# The ranks share the machine's cores with whatever else runs: the load average is printed with the figures.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
out=${OUT_DIR:-build/bench-out}/mpi
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
MPIRUN=(mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
v() { sed -n "s/^ *\"$1\": *\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2" | head -n 1; }
if ! "${MPIRUN[@]}" -np 2 "$MICA" --version > /dev/null 2>&1; then
  echo "bench_mpi: mpirun cannot start processes here; no parallel figures"
  exit 0
fi
echo "cores: $(nproc), load average before: $(cut -d' ' -f1-3 /proc/loadavg)"

echo "-- Cook's membrane, Neo-Hooke, ${COOK_N:=31}x$COOK_N particles, 2 load steps (gather)"
printf '%5s %8s %9s %10s %10s %9s %9s %11s %13s\n' ranks dofs cache+pat assemble dist.work gather newton peak_MB/rank tip_uy
for np in 1 2; do
  d="$out/cook_$np"
  "${MPIRUN[@]}" -np $np "$MICA" run input/cook_neohooke.cfg -o "$d" --set "particles.count=[$COOK_N,$COOK_N]" \
    --set solver.steps=2 --set output.monitor=false --set output.vtu=false > "$d.log" 2>&1 || { echo "np $np failed"; continue; }
  s="$d/summary.json"
  work=$(awk -v a="$(v time_cache_and_pattern "$s")" -v b="$(v time_assemble "$s")" 'BEGIN { printf "%.3f", a + b }')
  eval "work_$np=$work"
  peak=$(v peak_memory_rank_max "$s"); peak=$([ -n "$peak" ] && awk -v p="$peak" 'BEGIN { printf "%.1f", p / 1e6 }' || echo -)
  gather=$(v time_gather "$s"); [ -n "$gather" ] || gather=0
  printf '%5s %8s %9.3f %10.3f %10.3f %9.3f %9.3f %11s %13.10f\n' $np "$(v dofs "$s")" "$(v time_cache_and_pattern "$s")" \
    "$(v time_assemble "$s")" "$work" "$gather" "$(v time_newton "$s")" "$peak" "$(v tip_uy "$s")"
done
awk -v a="${work_1:-0}" -v b="${work_2:-0}" 'BEGIN { if (b > 0) printf "speed-up of the distributed work (cache+pattern + assemble), 1 -> 2 ranks: %.2f\n", a / b }'
echo "(peak_MB/rank: getrusage's peak resident memory, largest rank; reported under MPI only)"

echo "-- Schwarz-CG on a 3-D cube, linear elasticity, ${CUBE_N:=14}^3 particles, linear basis"
printf '%5s %7s %8s %10s %10s %12s %9s\n' ranks overlap dofs sub_dofs iterations residual newton
for np in 2 3 4; do
  for overlap in 0 1 2; do
    d="$out/cube_${np}_$overlap"
    "${MPIRUN[@]}" -np $np "$MICA" run input/cube3d.cfg -o "$d" --set "particles.count=[$CUBE_N,$CUBE_N,$CUBE_N]" \
      --set quadrature.order=2 --set solver.parallel=schwarz --set solver.overlap=$overlap --set output.monitor=false \
      --set output.vtu=false > "$d.log" 2>&1 || { echo "np $np overlap $overlap failed: $(tail -n 2 "$d.log")"; continue; }
    s="$d/summary.json"
    printf '%5s %7s %8s %10s %10s %12.3e %9.3f\n' $np $overlap "$(v dofs "$s")" \
      "$(v subdomain_dofs_min "$s")-$(v subdomain_dofs_max "$s")" "$(v krylov_iterations "$s")" \
      "$(v krylov_last_residual "$s")" "$(v time_newton "$s")"
  done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
