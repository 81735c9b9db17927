# Patch tests (seed 000, 7.2.2) with each boundary method on regular and jittered particles. A linear basis
# with enough Gauss points (6 per direction) on regular particles must reach 1e-6 relative (L2). Penalty is
# not consistent (its error falls as 1/α: 3.4e-4 at its default α = 1e3) and reaches 1e-6 only from
# α = 1e7, so it is checked there, and reported at its default; the
# jittered results and the quadratic patch are reported (Gauss-integrated EFG is not exact there: the
# shape functions' derivatives are rational; docs/verification.md).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/solid_patch"
rm -rf "$work" && mkdir -p "$work"
for method in nitsche penalty lagrange; do
  alpha=(); [ $method = penalty ] && alpha=(--set bc.alpha=1e7)
  run_deck "$work/lin_$method" input/patch_linear.cfg --set bc.method=$method --set quadrature.order=6 "${alpha[@]}"
  e=$(json_value error_l2 "$work/lin_$method/summary.json")
  less_than "$e" 1e-6 || fail "linear patch, $method, regular: L2 $e > 1e-6"
  ok "linear patch, $method ${alpha[*]}, regular particles, 6 Gauss points: L2 $e"
  if [ $method = penalty ]; then
    run_deck "$work/lin_default_$method" input/patch_linear.cfg --set bc.method=$method --set quadrature.order=6
    echo "report: linear patch, penalty at its default alpha: L2 $(json_value error_l2 "$work/lin_default_$method/summary.json")"
  fi
  run_deck "$work/jit_$method" input/patch_linear.cfg --set bc.method=$method --set quadrature.order=6 \
    --set particles.layout=jittered
  echo "report: linear patch, $method, jittered 0.2: L2 $(json_value error_l2 "$work/jit_$method/summary.json")"
  run_deck "$work/quad_$method" input/patch_quadratic.cfg --set bc.method=$method
  echo "report: quadratic patch, $method, regular: L2 $(json_value error_l2 "$work/quad_$method/summary.json")"
done
