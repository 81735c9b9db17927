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
# a traction that divides by zero on its set: the expression, its deck line, the point and the load factor
expect_failure 2 'base.cfg:6: the traction'"'"'s component 2 "1/(x-4)" is inf at (x, y) = (4, ' \
  -- "$MICA" run $D/base.cfg -o "$work/x" --set 'bcs.traction.[0].ty="1/(x-4)"'
expect_failure 2 '), load factor 1; write an expression that is finite on the whole set' \
  -- "$MICA" run $D/base.cfg -o "$work/x" --set 'bcs.traction.[0].ty="1/(x-4)"'
[ ! -e "$work/x" ] || fail "a failed run left $work/x"
ok "no output directory after failed runs"
