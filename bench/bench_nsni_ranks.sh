#!/usr/bin/env bash
# The production nodal mode on distributed data (issues 19 and 20; figures only, never pass/fail): the 3-D
# manufactured solution (input/manufactured3d.cfg: products of sines, no element or basis is exact) on jittered
# particles, NSNI_N³ particles (default 15: 10 125 dofs; at 25 NSNI's symmetric VCI alone took 71 s serially and did
# not finish in 10 minutes at P = 2: docs/performance.md), linear basis of dilation 2, parallel.data =
# "distributed", CG / GMRES with solver.petsc = NSNI_PETSC (default gmg), at P = 1 and P = 2, two integrations:
#   gauss  2 × 2 × 2 Gauss points per cell and VCI (auto: on for jittered particles; Petrov–Galerkin, GMRES);
#   nsni   one point per particle, NSNI's stabilization, its symmetric VCI (MUMPS over the ranks; CG).
# Alternating (gauss 1, nsni 1, gauss 2, nsni 2, ...), NSNI_REPEAT times (default 3), the minimum of each column.
# Columns: quadrature points, relative L2 and energy errors (the same at P = 1 and 2: the runs are checked to agree
# within 1e-9 — a distributed run that differed would be a fault, not a figure), shape functions and pattern,
# VCI, assembly, linear solver, Newton and the wall clock (seconds), and the larger rank's peak memory (MB).
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
REPEAT=${NSNI_REPEAT:-3}
N=${NSNI_N:-15} PETSC=${NSNI_PETSC:-gmg}
out=${OUT_DIR:-build/bench-out}/nsni_ranks
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
MPIRUN=(mpirun)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
if ! "${MPIRUN[@]}" -np 2 "$MICA" --version > /dev/null 2>&1; then
  echo "bench_nsni_ranks: mpirun cannot start 2 processes here; no figures"
  exit 0
fi
v() { sed -n "s/^ *\"$1\": *\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2" | head -n 1; }
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
common=(--set "particles.count=[$N,$N,$N]" --set particles.layout=\"jittered\" --set mls.order=1
        --set mls.dilation=2.0 --set parallel.data=\"distributed\" --set solver.linear=\"petsc\"
        --set solver.petsc=\"$PETSC\" --set output.monitor=false --set output.vtu=false --set output.mesh=false)
declare -A mode=([gauss]='--set quadrature.mode="gauss" --set quadrature.order=2'
                 [nsni]='--set quadrature.mode="nsni"')

# one NAME NP: a run; prints "points l2 energy cache vci assemble solver newton wall peak", or nothing on failure
one() {
  local name=$1 np=$2 d="$out/$1_$2" launch=("${MPIRUN[@]}" -np "$2") start end
  [ "$np" = 1 ] && launch=()
  local extra; read -r -a extra <<<"${mode[$name]}"
  start=$(date +%s.%N)
  "${launch[@]}" "$MICA" run input/manufactured3d.cfg -o "$d" "${common[@]}" "${extra[@]}" > "$d.log" 2>&1 \
    || { echo "bench_nsni_ranks: $name np $np failed: $(tail -n 2 "$d.log")" >&2; return; }
  end=$(date +%s.%N)
  local s="$d/summary.json" peak
  peak=$(v peak_memory_rank_max "$s"); [ -n "$peak" ] || peak=$(v peak_memory "$s")
  awk -v q="$(v quadrature_points "$s")" -v l="$(v error_l2 "$s")" -v e="$(v error_energy "$s")" \
      -v c="$(v time_cache_and_pattern "$s")" -v vc="$(v time_vci "$s")" -v a="$(v time_assemble "$s")" \
      -v an="$(v time_analyze "$s")" -v f="$(v time_factor "$s")" -v so="$(v time_solve "$s")" \
      -v n="$(v time_newton "$s")" -v s0="$start" -v e0="$end" -v p="${peak:-0}" \
      'BEGIN { printf "%d %.4e %.4e %.3f %.3f %.3f %.3f %.3f %.3f %.0f\n", q, l, e, c, vc, a, an + f + so, n, e0 - s0, p / 1e6 }'
}

declare -A best
for ((r = 0; r < REPEAT; r++)); do
  for np in 1 2; do
    for name in gauss nsni; do
      t=$(one "$name" "$np")
      [ -n "$t" ] || exit 0
      key="$name $np"
      best[$key]=$(printf '%s\n%s\n' "${best[$key]:-}" "$t" | awk 'NF { for (i = 1; i <= NF; i++) if (!(i in m) || $i < m[i]) m[i] = $i }
        END { for (i = 1; i <= 10; i++) printf "%s ", m[i]; print "" }')
    done
  done
done
for name in gauss nsni; do # P = 1 and 2 must give the same answer
  a=$(v error_l2 "$out/${name}_1/summary.json") b=$(v error_l2 "$out/${name}_2/summary.json")
  awk -v a="$a" -v b="$b" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 1e-9 * a) }' \
    || echo "bench_nsni_ranks: $name: error_l2 $a at P = 1, $b at P = 2 — the distributed run differs" >&2
done
echo "-- manufactured 3-D, jittered, ${N}³ particles ($((3 * N * N * N)) dofs), linear basis, solver.petsc = $PETSC, minimum of $REPEAT"
printf '%-6s %-3s %9s %10s %10s %8s %7s %8s %8s %8s %8s %8s\n' mode P points L2 energy cache vci assemble solver newton wall peakMB
for name in gauss nsni; do
  for np in 1 2; do
    read -r -a c <<<"${best[$name $np]}"
    printf '%-6s %-3s %9s %10s %10s %8s %7s %8s %8s %8s %8s %8s\n' "$name" "$np" "${c[@]}"
  done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
