# solver.linear = "cg" (src/solve/linear_cg.c): preconditioned conjugate gradients give the direct solver's
# answer to the Krylov tolerance, and reproduce an exact solution the discretization reproduces.
# - 3-D cube in tension (input/cube3d.cfg, 8³ particles, 2 Gauss points): cg with block Jacobi and with
#   symmetric block Gauss–Seidel against CHOLMOD: corner displacement to 1e-8 relative, L2 error to 1e-6
#   relative (the error is itself ~1e-5 of the solution, so 1e-6 of it is ~1e-11 of u); iterations reported,
#   true residual ≤ linear_rtol; Gauss–Seidel needs fewer iterations than Jacobi (measured 41 vs 88 at 12³).
# - the same cube with SCNI on jittered particles (the linear field is reproduced exactly, CHOLMOD 6.6e-16):
#   cg's L2 error ≤ 1e-8 (measured 5.4e-12 at linear_rtol 1e-10).
# - 2-D Timoshenko beam (input/timoshenko.cfg): tip deflection as CHOLMOD to 1e-8.
# - bad settings: cg with Lagrange multipliers (indefinite) → exit 2 naming cg; too few iterations → exit 3.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/krylov"
rm -rf "$work" && mkdir -p "$work"

cube=(--set "particles.count=[8,8,8]" --set quadrature.order=2)
run_deck "$work/cube_cholmod" input/cube3d.cfg "${cube[@]}" --set solver.linear='"cholmod"'
ref_ux=$(json_value corner_ux "$work/cube_cholmod/summary.json")
ref_l2=$(json_value error_l2 "$work/cube_cholmod/summary.json")
for pc in jacobi sgs; do
  d="$work/cube_cg_$pc"
  run_deck "$d" input/cube3d.cfg "${cube[@]}" --set solver.linear='"cg"' --set solver.preconditioner="\"$pc\""
  [ "$(json_value linear_solver "$d/summary.json")" = cg ] || fail "$pc: linear_solver is not cg"
  within "$(json_value corner_ux "$d/summary.json")" "$ref_ux" 1e-8 "cg ($pc) corner_ux against CHOLMOD"
  within "$(json_value error_l2 "$d/summary.json")" "$ref_l2" 1e-6 "cg ($pc) L2 error against CHOLMOD's"
  at_least "$(json_value krylov_iterations "$d/summary.json")" 2 "cg ($pc) iterations reported"
  less_than "$(json_value krylov_last_residual "$d/summary.json")" 1e-10 || fail "cg ($pc): true residual above 1e-10"
  ok "cg ($pc): |b - Ax| / |b| = $(json_value krylov_last_residual "$d/summary.json") <= 1e-10"
done
it_j=$(json_value krylov_iterations "$work/cube_cg_jacobi/summary.json")
it_s=$(json_value krylov_iterations "$work/cube_cg_sgs/summary.json")
less_than "$it_s" "$it_j" || fail "Gauss-Seidel ($it_s iterations) not below Jacobi ($it_j)"
ok "iterations: sgs $it_s < jacobi $it_j"

run_deck "$work/scni" input/cube3d.cfg --set quadrature.mode='"scni"' --set particles.layout='"jittered"' \
  --set solver.linear='"cg"'
e=$(json_value error_l2 "$work/scni/summary.json")
less_than "$e" 1e-8 || fail "cg, SCNI patch: L2 $e > 1e-8"
ok "cg reproduces the exact tension field with SCNI: L2 $e <= 1e-8"

run_deck "$work/timo_cholmod" input/timoshenko.cfg --set solver.linear='"cholmod"'
run_deck "$work/timo_cg" input/timoshenko.cfg --set solver.linear='"cg"' --set solver.preconditioner='"sgs"' \
  --set solver.linear_max_iterations=20000
within "$(json_value tip_uy "$work/timo_cg/summary.json")" "$(json_value tip_uy "$work/timo_cholmod/summary.json")" 1e-8 \
  "Timoshenko tip_uy, cg against CHOLMOD"

expect_failure 2 'cg needs a symmetric positive definite tangent' -- \
  "$MICA" run input/cube3d.cfg -o "$work/bad" --set bc.method='"lagrange"' --set solver.linear='"cg"'
expect_failure 3 'did not converge in 3 iterations' -- \
  "$MICA" run input/cube3d.cfg -o "$work/bad" --set solver.linear='"cg"' --set solver.linear_max_iterations=3 \
  --set solver.max_cuts=0 --set output.vtu=false
# a linear problem's tangent does not depend on the load: a failed solve is not retried with load cuts (the
# monitor would print "cut back" before each retry; max_cuts is left at its default 8)
set +e
"$MICA" run input/cube3d.cfg -o "$work/bad" --set solver.linear='"cg"' --set solver.linear_max_iterations=3 \
  --set output.vtu=false > "$work/nocut.log" 2>&1
status=$?
set -e
[ "$status" = 3 ] || { echo "FAIL: linear cg failure exit $status, expected 3"; exit 1; }
if grep -q "cut back" "$work/nocut.log"; then echo "FAIL: a linear problem's failed solve was retried with load cuts"; exit 1; fi
echo "ok: linear problem, failed cg: exit 3 without load cuts"
