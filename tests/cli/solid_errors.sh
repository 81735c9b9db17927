# Bad input to `mica run`: each a clear error naming the deck line (or the file), with exit status 2 and no
# output directory left behind.
source "$(dirname "$0")/common.bash"
D=tests/decks/solid
work="$OUT_DIR/solid_errors"
rm -rf "$work" && mkdir -p "$work"
"$MICA" run $D/base.cfg -o "$work/base" > /dev/null || fail "the base deck does not run"
expect_failure 2 "unknown_set.cfg:6: there is no boundary set 'lefft'" -- "$MICA" run $D/unknown_set.cfg -o "$work/x"
expect_failure 2 "this body has: left, right, bottom, top" -- "$MICA" run $D/unknown_set.cfg -o "$work/x"
expect_failure 2 "missing_load_set.cfg:6: there is no boundary set 'hole'" -- "$MICA" run $D/missing_load_set.cfg -o "$work/x"
expect_failure 2 "bad_modulus.cfg:" -- "$MICA" run $D/bad_modulus.cfg -o "$work/x"
expect_failure 2 "must be positive" -- "$MICA" run $D/bad_modulus.cfg -o "$work/x"
expect_failure 2 "bad_poisson.cfg:" -- "$MICA" run $D/bad_poisson.cfg -o "$work/x"
expect_failure 2 "use ν < 0.5" -- "$MICA" run $D/bad_poisson.cfg -o "$work/x"
expect_failure 2 "supporting particles" -- "$MICA" run $D/too_sparse.cfg -o "$work/x"
expect_failure 2 "plate_hole_truncated.msh:" -- "$MICA" run $D/truncated_mesh.cfg -o "$work/x"
expect_failure 2 "unknown setting" -- "$MICA" run $D/base.cfg -o "$work/x" --set material.youngs=3
# a traction that divides by zero on its set: the setting, the expression, where it was given, the point and
# the load factor
expect_failure 2 '--set bcs.traction.[0].ty="1/(x-4)": bcs.traction.[0].ty "1/(x-4)" is inf at (x, y) = (4, ' \
  -- "$MICA" run $D/base.cfg -o "$work/x" --set 'bcs.traction.[0].ty="1/(x-4)"'
expect_failure 2 '), load factor 1; write an expression that is finite on the whole set' \
  -- "$MICA" run $D/base.cfg -o "$work/x" --set 'bcs.traction.[0].ty="1/(x-4)"'
# the same for a prescribed displacement, a body force and an exact solution's derivative, each with its deck line
# (the first point: the 4-point Gauss rule on a cell of height 0.5, y = 0.25 (1 - 0.861136), as printed)
expect_failure 2 'nonfinite_dirichlet.cfg:7: bcs.dirichlet.[0].uy "1/x" is inf at (x, y) = (0, 0.0347159), load factor 1; write an expression that is finite on the whole set' \
  -- "$MICA" run $D/nonfinite_dirichlet.cfg -o "$work/x"
for method in penalty lagrange; do
  expect_failure 2 'nonfinite_dirichlet.cfg:7: bcs.dirichlet.[0].uy "1/x" is inf at (x, y) = (0, ' \
    -- "$MICA" run $D/nonfinite_dirichlet.cfg -o "$work/x" --set bc.method=$method
done
expect_failure 2 'nonfinite_body.cfg:8: loads.by "sqrt(x - 5)" is NaN at (x, y) = (0.0347159, 0.0347159), load factor 1; write an expression that is finite in the whole body' \
  -- "$MICA" run $D/nonfinite_body.cfg -o "$work/x"
expect_failure 2 'nonfinite_exact.cfg:9: the x-derivative of exact.ux "d(sqrt(x))/dx" is inf at (x, y) = (0, 0), load factor 1' \
  -- "$MICA" run $D/nonfinite_exact.cfg -o "$work/x"
[ ! -e "$work/x" ] || fail "a failed run left $work/x"
ok "no output directory after failed runs"
