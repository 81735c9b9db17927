# The command line: help, overrides of scalars and arrays, the resolved deck, the default output directory.
source "$(dirname "$0")/common.bash"
D=tests/decks/cli
work="$OUT_DIR/cli_basics"
rm -rf "$work" && mkdir -p "$work"

"$MICA" --help | grep -q "mls" || fail "--help does not list the mls command"
"$MICA" help mls | grep -q "mls.dilation" || fail "help mls does not list mls.dilation"
"$MICA" help mls | grep -q "particles.count" || fail "help mls does not list particles.count"
ok "help"

"$MICA" mls $D/small.cfg -o "$work/a" --set "particles.count=[5,7]" --set mls.order=1 \
  --set 'function.f="2*x - y"' > /dev/null || fail "overrides rejected"
[ "$(json_value particles "$work/a/summary.json")" = 35 ] || fail "particles.count=[5,7] did not give 35 particles"
grep -q "2\*x - y" "$work/a/resolved.cfg" || fail "the resolved deck lacks the overridden function"
grep -Eq "count = \[ *5, *7 *\]" "$work/a/resolved.cfg" || fail "the resolved deck lacks count = [5, 7]"
grep -q "weight" "$work/a/resolved.cfg" || fail "the resolved deck lacks the defaults (mls.weight)"
ok "overrides and resolved deck"

# parameters are overridable, and every setting that uses them follows
"$MICA" mls $D/small.cfg -o "$work/b" --set parameters.L=4 > /dev/null || fail "parameter override rejected"
grep -q "L = 4" "$work/b/resolved.cfg" || fail "the resolved deck lacks L = 4"
ok "parameter override"

# default output directory: out/<deck name>, relative to the working directory
(cd "$work" && "$MICA" mls "$OLDPWD/$D/small.cfg" > /dev/null) || fail "run without -o failed"
[ -f "$work/out/small/summary.json" ] || fail "default output directory out/small not used"
[ "$(json_value status "$work/out/small/summary.json")" = ok ] || fail "summary status is not ok"
ok "default output directory"

# mica check: validates a run deck and reports its cost without solving
"$MICA" check input/timoshenko.cfg -o "$work/check" > "$work/check.log" || fail "mica check failed"
grep -q "dofs" "$work/check.log" || fail "mica check does not print the dofs"
for key in particles quadrature_points dofs nnz cache_bytes matrix_bytes cost_class; do
  [ -n "$(json_value $key "$work/check/summary.json")" ] || fail "mica check summary lacks $key"
done
[ -z "$(json_value newton_iterations "$work/check/summary.json")" ] || fail "mica check solved the problem"
[ "$(json_value dofs "$work/check/summary.json")" = 594 ] || fail "check: 33x9 particles should give 594 dofs"
ok "mica check"

# the quickstart: one solve of its base deck (the Cosserat hole at a/l = 1, N = 0.93) is a run deck with a
# sweep group; its SCF is Kaloni & Ariman's 2.118 within 1 % (a coarser plate than cosserat_hole.cfg)
"$MICA" run input/quickstart.cfg -o "$work/quick" > /dev/null || fail "mica run input/quickstart.cfg failed"
within "$(json_value scf "$work/quick/summary.json")" 2.1180615267 0.01 "quickstart: Cosserat SCF at a/l = 1"
"$MICA" run input/cantilever.cfg -o "$work/cantilever" > /dev/null || fail "mica run input/cantilever.cfg failed"
ok "cantilever deck runs"
