#!/usr/bin/env bash
# Time per phase and sizes for the Timoshenko beam (input/timoshenko.cfg, quadratic basis, Nitsche) at
# three sizes, from each run's summary.json. Prints figures only; never fails on time.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
out=${OUT_DIR:-build/bench-out}/timoshenko
mkdir -p "$out"
v() { sed -n "s/^ *\"$1\": *\([^,]*\),\{0,1\}$/\1/p" "$2" | head -n 1; }
printf '%-9s %7s %9s %9s %8s %8s %8s %8s %8s %8s %10s\n' particles dofs nnz nnz_L discret mls+cache assemble analyze factor solve 'tip_uy'
for n in "65,17" "129,33" "257,65"; do
  d="$out/$n"
  "$MICA" run input/timoshenko.cfg -o "$d" --set "particles.count=[$n]" --set mls.order=2 --set mls.dilation=3.0 \
    --set quadrature.order=5 --set output.monitor=false --set output.vtu=false > "$d.log" 2>&1 || { echo "run $n failed"; continue; }
  s="$d/summary.json"
  mls_cache=$(awk -v a="$(v time_mls_setup "$s")" -v b="$(v time_cache_and_pattern "$s")" 'BEGIN { printf "%.3f", a + b }')
  printf '%-9s %7s %9s %9s %8.3f %8s %8.3f %8.3f %8.3f %8.3f %10.7f\n' "$(v particles "$s")" "$(v dofs "$s")" "$(v nnz "$s")" \
    "$(v nnz_factor "$s")" "$(v time_discretize "$s")" "$mls_cache" "$(v time_assemble "$s")" "$(v time_analyze "$s")" \
    "$(v time_factor "$s")" "$(v time_solve "$s")" "$(v tip_uy "$s")"
done
echo "(seconds; mls+cache = MLS setup + shape-function cache + sparsity pattern; assemble: one pass, residual and tangent)"
