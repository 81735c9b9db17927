#!/usr/bin/env bash
# The 10⁶-dof run (issues 7 and 19): input/cube3d_million.cfg — 3-D linear elastic cube in tension, 70³ particles =
# 1 029 000 dofs, PETSc's CG with geometric multigrid on lattices (gmg; MILLION_PETSC=gamg: GAMG with the rigid
# motions as near-null space) — with its time per phase, Krylov
# iterations, peak memory (getrusage) and error against the exact solution. NOT part of `make test` or `make bench`:
# about 10–20 minutes and ≈ 11 GB of memory at the default size. Figures only: never passes or fails on time.
#   bash bench/bench_million.sh run     (without "run", as `make bench` calls it, it only says how to run it)
#   MILLION_N=70       particles per side (33: 1.1·10⁵ dofs, about a minute)
#   MILLION_NP=1       MPI ranks (> 1: mpirun; PETSc distributes the matrix)
#   MILLION_DATA=distributed  with MILLION_NP > 1: parallel.data (distributed: each rank its block; replicated)
#   MILLION_PETSC=gmg  a solver.petsc preset (gmg, gamg, hypre, asm-cholmod, ..., none), with MILLION_PETSC_OPTIONS as
#                      solver.petsc_options; the block-Jacobi CG that mica once had of its own is
#                      MILLION_PETSC=none MILLION_PETSC_OPTIONS="-ksp_type cg -pc_type pbjacobi" (point-block Jacobi:
#                      the 3 × 3 blocks of the particles)
set -u
cd "$(dirname "$0")/.."
if [ "${1:-}" != run ]; then
  echo "bench_million: not part of make bench (10-20 minutes, 6.5 GB); run: bash bench/bench_million.sh run"
  exit 0
fi
MICA=${MICA_BIN:-bin/mica}
N=${MILLION_N:-70} NP=${MILLION_NP:-1} PETSC=${MILLION_PETSC:-gmg} DATA=${MILLION_DATA:-distributed}
PETSC_OPTIONS=${MILLION_PETSC_OPTIONS:-}
out=${OUT_DIR:-build/bench-out}/million_${N}_${PETSC}_np$NP
mkdir -p "$out"
need_gb=$(awk -v n="$N" 'BEGIN { printf "%.1f", n * n * n * 33e3 / 1e9 * 1.1 }') # measured 11.2 GB at 70^3 with GAMG (docs/performance.md)
avail_gb=$(awk '/MemAvailable/ { printf "%.1f", $2 / 1e6 }' /proc/meminfo)
echo "million: ${N}^3 particles ($((3 * N * N * N)) dofs), needs about $need_gb GB; available $avail_gb GB;" \
  "load average $(cut -d' ' -f1-3 /proc/loadavg)"
if awk -v a="$avail_gb" -v b="$need_gb" 'BEGIN { exit !(a < b) }'; then
  echo "million: not enough free memory for this size; set MILLION_N lower"; exit 1
fi
cmd=("$MICA" run input/cube3d_million.cfg -o "$out/results" --set parameters.n="$N" --set solver.petsc=\""$PETSC"\"
     --set solver.petsc_options=\""$PETSC_OPTIONS"\")
if [ "$NP" -gt 1 ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
  mpi=(mpirun --oversubscribe -np "$NP"); [ "$(id -u)" = 0 ] && mpi+=(--allow-run-as-root)
  cmd=("${mpi[@]}" "${cmd[@]}" --set parallel.data=\""$DATA"\")
  [ "$DATA" = distributed ] && cmd+=(--set output.mesh=false) # the cell mesh is not written from distributed data
fi
echo "command: ${cmd[*]}"
start=$(date +%s.%N)
"${cmd[@]}" > "$out/log" 2>&1 || { echo "million: the run failed:"; tail -n 5 "$out/log"; exit 1; }
wall=$(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN { printf "%.1f", e - s }')
s="$out/results/summary.json" # beside the log: mica replaces its output directory whole
v() { sed -n "s/^ *\"$1\": *\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$s" | head -n 1; }
grep -E "particles,|petsc \(|relative errors|peak memory" "$out/log"
printf '%-24s %s\n' dofs "$(v dofs)" nnz "$(v nnz)" "matrix MB" "$(awk -v b="$(v matrix_bytes)" 'BEGIN { printf "%.0f", b / 1e6 }')" \
  "cache MB" "$(awk -v b="$(v cache_bytes)" 'BEGIN { printf "%.0f", b / 1e6 }')"
for k in time_discretize time_mls_setup time_cache_and_pattern time_assemble time_analyze time_factor time_solve time_newton; do
  printf '%-24s %8.1f s\n' "$k" "$(v $k)"
done
for k in cpu_cache_and_pattern cpu_assemble cpu_krylov; do printf '%-24s %8.1f s\n' "$k" "$(v $k)"; done
printf '%-24s %8s\n' krylov_iterations "$(v krylov_iterations)" krylov_last_residual "$(v krylov_last_residual)"
printf '%-24s %8.0f MB\n' peak_memory "$(awk -v b="$(v peak_memory)" 'BEGIN { print b / 1e6 }')"
[ "$NP" -gt 1 ] && printf '%-24s %8.0f MB\n' peak_memory_rank_max "$(awk -v b="$(v peak_memory_rank_max)" 'BEGIN { print b / 1e6 }')"
printf '%-24s %s\n' error_l2 "$(v error_l2)" error_energy "$(v error_energy)" corner_ux "$(v corner_ux) (exact 0.01)" \
  corner_uy "$(v corner_uy) (exact -0.0025)" "wall clock" "$wall s"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
