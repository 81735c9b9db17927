#!/usr/bin/env bash
# The measured inputs of docs/performance.md's scaling model for 10⁸ unknowns on 256 ranks (issue 19; figures
# only, never pass/fail). input/cube3d_million.cfg's lean cube (linear basis, ball supports of dilation 1.5,
# 8 Gauss points per cell), PETSc CG with SCALING_PETSC (default gmg: geometric multigrid on lattices; gamg: GAMG
# with the rigid motions), parallel.data = "distributed":
#  1. the ghost layer and the halo at P = 1, 2, 3, 4 on N³ particles (N = SCALING_N, default 29: 73 167 dofs):
#     per rank the particles owned and held, the ghost layer's depth δ in particle spacings (the block's held
#     box (b + 2δ)^dim − b^dim solved for δ), the halo of one Newton iteration (the residual sum and the solution
#     scatter: 2 × ghost dofs; the Krylov products: iterations × PETSc's off-rank columns, halo_dofs) in bytes,
#     and the peak memory of the largest rank with its bytes per held particle;
#  2. the multigrid's iteration growth over three sizes (SCALING_SIZES, default "17 25 37": 1.5·10⁴ to 1.5·10⁵ dofs), one
#     process: iterations to linear_rtol 1e-10 and their power-law exponent in the number of unknowns;
#  3. a small run (N = 5) for the fixed memory of the program and its libraries.
# P = 3 and 4 oversubscribe a 2-core machine: the times printed are not speeds. About 3–5 minutes.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
N=${SCALING_N:-29}
PETSC=${SCALING_PETSC:-gmg}
SIZES=${SCALING_SIZES:-17 25 37}
out=${OUT_DIR:-build/bench-out}/scaling
mkdir -p "$out"
source bench/mpi_common.bash
if ! "${MPIRUN[@]}" -np 2 "$MICA" --version > /dev/null 2>&1; then
  echo "bench_scaling: mpirun cannot start processes here; no figures"
  exit 0
fi
# arr KEY FILE: a summary array's numbers, one per line
arr() { sed -n "/\"$1\"/,/]/p" "$2" | sed 1d | grep -o '[-0-9.e+]*[0-9]'; }
deck="$out/cube.cfg"
{ grep -v '^output\|^solver\|^                                  {' input/cube3d_million.cfg
  echo "solver = { linear = \"petsc\"; petsc = \"$PETSC\"; linear_rtol = 1e-10; linear_max_iterations = 2000; rtol = 1e-8; };"
  echo 'output = { vtu = false; mesh = false; monitor = false; };'
} > "$deck"
echo "cube, CG + $PETSC, parallel.data = distributed; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"

# run DIR NP N: the summary, or a message on stderr
run() {
  local dir=$1 np=$2 n=$3 launch=("${MPIRUN[@]}" -np "$2")
  "${launch[@]}" "$MICA" run "$deck" -o "$dir" --set "parameters.n=$n" --set 'parallel.data="distributed"' \
    > "$dir.log" 2>&1 || { echo "bench_scaling: $dir failed: $(tail -n 3 "$dir.log")" >&2; return 1; }
}

run "$out/fixed" 1 5 && fixed=$(v peak_memory "$out/fixed/summary.json") || fixed=0
echo "-- 1. ghost layer and halo, ${N}³ particles ($((3 * N * N * N)) dofs); fixed memory (N = 5): $((fixed / 1000000)) MB"
printf '%3s %8s %9s %9s %7s %6s %10s %10s %6s %12s %9s %12s\n' P blocks owned_max held_max ghost% delta \
  resid_dofs halo_dofs its MB/Newton peak_MB bytes/held
for np in 1 2 3 4; do
  d="$out/ghosts_$np"
  run "$d" "$np" "$N" || continue
  s="$d/summary.json"
  if [ "$np" = 1 ]; then # one process: no per-rank arrays
    blocks=1x1x1 owned=$(v particles "$s") held=$(v particles "$s") ghosts_sum=0
  else
    blocks=$(arr parallel_blocks "$s" | paste -sd x)
    # the rank that holds the most particles: its owned and held counts
    read -r owned held < <(paste <(arr rank_particles_owned "$s") <(arr rank_particles_local "$s") |
                             sort -k2,2g | tail -n 1)
    ghosts_sum=$(paste <(arr rank_particles_owned "$s") <(arr rank_particles_local "$s") |
                 awk '{ g += $2 - $1 } END { print g + 0 }')
  fi
  halo=$(v halo_dofs_max "$s"); halo=${halo:-0}
  its=$(v krylov_iterations "$s"); newton=$(v newton_iterations "$s")
  peak=$(v peak_memory_rank_max "$s"); [ -z "$peak" ] && peak=$(v peak_memory "$s")
  # δ: the ghosts of all ranks over the cut faces' area, both sides (Σ_k (p_k − 1) N² faces of N² particles);
  # the edges' δ² terms are left out (a few per cent here)
  delta=$(echo "$blocks" | awk -v n="$N" -v g="$ghosts_sum" -F x '{
    a = ($1 - 1 + $2 - 1 + $3 - 1) * n * n; printf "%.2f", (a > 0) ? g / (2 * a) : 0 }')
  # bytes per Newton iteration, the largest rank: the residual sum and the scatter of the solution
  # (2 × its ghosts × 3 dofs), and every Krylov product's halo
  mb=$(awk -v g="$((held - owned))" -v h="$halo" -v i="$its" -v k="$newton" \
       'BEGIN { printf "%.2f", (k > 0 ? (2 * g * 3 + i / k * h) * 8 / 1e6 : 0) }')
  printf '%3s %8s %9s %9s %7s %6s %10s %10s %6s %12s %9s %12s\n' "$np" "$blocks" "$owned" "$held" \
    "$(awk -v a="$held" -v b="$owned" 'BEGIN { printf "%.1f", 100 * (a - b) / b }')" "$delta" "$((2 * ghosts_sum * 3))" \
    "$halo" "$its" "$mb" "$((peak / 1000000))" \
    "$(awk -v p="$peak" -v f="$fixed" -v h="$held" 'BEGIN { printf "%.0f", (p - f) / h }')"
done

echo "-- 2. $PETSC iterations over sizes (one process)"
printf '%6s %10s %6s %8s\n' N dofs its newton
prev_n=0 prev_its=0
for n in $SIZES; do
  d="$out/amg_$n"
  "$MICA" run "$deck" -o "$d" --set "parameters.n=$n" > "$d.log" 2>&1 ||
    { echo "bench_scaling: amg $n failed: $(tail -n 3 "$d.log")" >&2; continue; }
  its=$(v krylov_iterations_max "$d/summary.json")
  printf '%6s %10s %6s %8s\n' "$n" "$((3 * n * n * n))" "$its" "$(v newton_iterations "$d/summary.json")"
  echo "$((3 * n * n * n)) $its" >> "$out/amg.dat.$$"
done
[ -f "$out/amg.dat.$$" ] && awk '{ x = log($1); y = log($2); sx += x; sy += y; sxx += x * x; sxy += x * y; c++ }
  END { if (c > 1) { a = (c * sxy - sx * sy) / (c * sxx - sx * sx); b = exp((sy - a * sx) / c)
        printf "iterations ~ %.3g n^%.3f: %.0f at 10^8 unknowns\n", b, a, b * exp(a * log(1e8)) } }' "$out/amg.dat.$$"
rm -f "$out/amg.dat.$$"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
