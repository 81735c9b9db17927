#!/usr/bin/env bash
# Where the time goes (issue 7, item 2): seconds per phase from each run's summary.json, for a 2-D problem
# (Timoshenko beam, quadratic basis, 5 x 5 Gauss points per cell, Nitsche, CHOLMOD) and a 3-D problem
# (bench/peers/block3d.cfg, linear elasticity, linear basis, 4 x 4 x 4 Gauss points per cell), three sizes
# each, at two or three support radii (mls.dilation). After each size the growth exponent of every phase
# against the number of particles, log(t2/t1) / log(N2/N1): 1 is linear. One BLAS thread. Prints figures
# only; never fails on time.
#   search   neighbor queries of the quadrature points      shape    MLS shape functions (without search)
#   pattern  sparsity pattern of the tangent                 assemble residual and tangent (all passes)
#   analyze  symbolic factorization (once)                  factor   numeric factorization
#   solve    triangular solves                              output   fields, error norms, probes
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
out=${OUT_DIR:-build/bench-out}/phases
mkdir -p "$out"
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
v() { sed -n "s/^ *\"$1\": *\([^,]*\),\{0,1\}$/\1/p" "$2" | head -n 1; }
phases="search shape pattern assemble analyze factor solve output"

# One run; prints its row and leaves "N t_search ... t_output" in $row for the exponents.
run_one() { # label deck count dilation extra-sets...
  local label=$1 deck=$2 count=$3 dil=$4
  shift 4
  local d="$out/$label-$dil-${count//,/x}"
  local sets=(--set "particles.count=[$count]" --set "mls.dilation=$dil" --set output.monitor=false --set output.vtu=false)
  for s in "$@"; do sets+=(--set "$s"); done
  if ! "$MICA" run "$deck" -o "$d" "${sets[@]}" > "$d.log" 2>&1; then
    echo "run $label $count dilation $dil failed (see $d.log)"
    row=""
    return
  fi
  local s="$d/summary.json"
  row=$(awk -v n="$(v particles "$s")" -v se="$(v time_search "$s")" -v sh="$(v time_shape_functions "$s")" \
    -v pa="$(v time_pattern "$s")" -v as="$(v time_assemble "$s")" -v an="$(v time_analyze "$s")" \
    -v fa="$(v time_factor "$s")" -v so="$(v time_solve "$s")" -v ou="$(v time_output "$s")" \
    'BEGIN { printf "%d %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f", n, se, sh, pa, as, an, fa - an, so, ou }')
  printf '%-6s %4s %8s %7s %6.1f %s\n' "$label" "$dil" "$(v particles "$s")" "$(v dofs "$s")" "$(v support_mean "$s")" \
    "$(echo "$row" | awk '{ for (i = 2; i <= NF; i++) printf "%9.4f", $i; t = 0; for (i = 2; i <= NF; i++) t += $i; printf "%9.4f", t }')"
}

exponents() { # previous row, this row
  [ -n "$1" ] && [ -n "$2" ] || return
  printf '%-6s %4s %8s %7s %6s ' "" "" "growth" "" ""
  awk -v a="$1" -v b="$2" 'BEGIN { n = split(a, x, " "); split(b, y, " "); ta = 0; tb = 0
    for (i = 2; i <= n; i++) { ta += x[i]; tb += y[i]
      if (x[i] > 2e-4 && y[i] > 2e-4) printf "%9.2f", log(y[i] / x[i]) / log(y[1] / x[1]); else printf "%9s", "-" }
    printf "%9.2f\n", log(tb / ta) / log(y[1] / x[1]) }'
}

series() { # label deck "counts" "dilations" extra-sets...
  local label=$1 deck=$2 counts=$3 dils=$4
  shift 4
  for dil in $dils; do
    local prev=""
    for count in $counts; do
      run_one "$label" "$deck" "$count" "$dil" "$@"
      [ -n "$prev" ] && exponents "$prev" "$row"
      prev=$row
    done
  done
}

echo "seconds per phase (summary.json), one BLAS thread; growth = d log t / d log particles between sizes"
printf '%-6s %4s %8s %7s %6s' problem dil particles dofs supp
for p in $phases total; do printf '%9s' "$p"; done
echo
series 2d-tim input/timoshenko.cfg "33,9 65,17 129,33" "2.5 3.0 3.5" mls.order=2 quadrature.order=5
series 3d-blk bench/peers/block3d.cfg "9,3,3 17,5,5 25,7,7" "2.0 2.5" mls.order=1 quadrature.order=4
echo "(2d-tim: input/timoshenko.cfg, quadratic basis, 5 x 5 Gauss points per cell; 3d-blk: bench/peers/block3d.cfg,"
echo " linear basis, 4 x 4 x 4 per cell; supp = mean supporting particles per quadrature point)"
