#!/bin/bash
# The cost of material.pressure = cell-linear against the displacement form on the same discretization:
# input/cook_incompressible.cfg, linear, N x N uniform particles (default 65), cells of 2 spacings, penalty (so that
# both factor with CHOLMOD). The two are run alternately, REPEAT times each (default 3); the minimum of each
# timing is printed with the ratio mixed / displacement. Usage: bash bench/bench_pressure.sh [N] [REPEAT]
N=${1:-65} REPEAT=${2:-3} MICA=${MICA_BIN:-bin/mica}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
c=$(( (N - 1) / 2 ))
keys="time_assemble time_factor time_newton time_total nnz"
declare -A best
for r in $(seq "$REPEAT"); do
  for p in none cell-linear; do
    "$MICA" run input/cook_incompressible.cfg -o "$out/$p" --set material.pressure=$p --set bc.method=penalty \
      --set particles.layout=regular --set "particles.count=[$N, $N]" --set "quadrature.cells=[$c, $c]" \
      --set output.monitor=false > "$out/$p.log" 2>&1 || { echo "run failed: $(tail -n 2 "$out/$p.log")"; exit 1; }
    for k in $keys; do
      v=$(sed -n "s/^ *\"$k\": *\([0-9.eE+-]*\),*$/\1/p" "$out/$p/summary.json" | head -n 1)
      cur=${best[$p.$k]}
      if [ -z "$cur" ] || awk -v a="$v" -v b="$cur" 'BEGIN { exit !(a < b) }'; then best[$p.$k]=$v; fi
    done
  done
done
printf "%-14s %14s %14s %8s\n" "N = $N" none cell-linear ratio
for k in $keys; do
  printf "%-14s %14.4g %14.4g %8.2f\n" "$k" "${best[none.$k]}" "${best[cell-linear.$k]}" \
    "$(awk -v a="${best[cell-linear.$k]}" -v b="${best[none.$k]}" 'BEGIN { print a / b }')"
done
