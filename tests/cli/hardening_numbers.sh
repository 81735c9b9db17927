# Numbers and counts the deck reader used to cut silently (issue 17, items 3 and 5): integers past 32 bits
# (libconfig 1.5 wraps them: [21, 4294967301] ran with 5 particles, order 4294967298 at order 2,
# E = 200000000000000000000 was "-1"), more than 1024 load steps (only 1024 VTU files, the final state lost)
# and more than 256 --sets (refused).
source "$(dirname "$0")/common.bash"
D=input/cantilever.cfg
work="$OUT_DIR/hardening_numbers"
rm -rf "$work" && mkdir -p "$work"

# A count past 32 bits is out of range with its true value, from --set and from the deck's line.
expect_failure 2 "--set particles.count=[21,4294967301]: particles.count.[1] = 4294967301 is out of range [2, 1000000]" \
  -- "$MICA" run $D -o "$work/x" --set 'particles.count=[21,4294967301]'
sed 's/count = \[21, 5\]/count = [21, 4294967301]/' $D > "$work/count.cfg"
expect_failure 2 "count.cfg:9: particles.count.[1] = 4294967301 is out of range [2, 1000000]" \
  -- "$MICA" run "$work/count.cfg" -o "$work/x"
sed 's/order = 2;/order = 4294967298;/' $D > "$work/order.cfg"
expect_failure 2 "order.cfg:10: mls.order = 4294967298 is out of range [0, 3]" -- "$MICA" run "$work/order.cfg" -o "$work/x"
expect_failure 2 "--set mls.order=0x100000002: mls.order = 4294967298 is out of range [0, 3]" \
  -- "$MICA" run $D -o "$work/x" --set mls.order=0x100000002
expect_failure 2 "--set mls.order=99999999999999999999L: 99999999999999999999 does not fit in a 64-bit integer" \
  -- "$MICA" run $D -o "$work/x" --set mls.order=99999999999999999999L
[ ! -e "$work/x" ] || fail "a deck error created the output directory $work/x"
ok "no output for the refused decks"

# A float setting written as a long integer is that real number: the same tip deflection as 2e20 written as
# a float (the deflection scales as 1/E, so a wrapped E would show).
tip() { json_value tip_uy "$1/summary.json"; }
run_deck "$work/float" $D --set material.E=2e20
run_deck "$work/int_set" $D --set material.E=200000000000000000000
sed 's/E = 200.0e3;/E = 200000000000000000000;/' $D > "$work/young.cfg"
run_deck "$work/int_deck" "$work/young.cfg"
[ "$(tip "$work/float")" = "$(tip "$work/int_set")" ] || fail "--set E=200000000000000000000: tip $(tip "$work/int_set") != $(tip "$work/float")"
[ "$(tip "$work/float")" = "$(tip "$work/int_deck")" ] || fail "E = 200000000000000000000: tip $(tip "$work/int_deck") != $(tip "$work/float")"
ok "E = 200000000000000000000 (integer literal, --set and deck) is 2e20: tip_uy $(tip "$work/float")"
# aluminium in Pa, 7e10 (< 2^63, > 2^32): libconfig alone read 1280523264, a plausible but wrong modulus
run_deck "$work/al_float" $D --set material.E=7e10
run_deck "$work/al_int" $D --set material.E=70000000000
[ "$(tip "$work/al_float")" = "$(tip "$work/al_int")" ] || fail "E=70000000000: tip $(tip "$work/al_int") != $(tip "$work/al_float")"
ok "E = 70000000000 is 7e10: tip_uy $(tip "$work/al_int")"
# the resolved deck holds the number the run used
grep -q "E = 2e+20;" "$work/int_set/resolved.cfg" || fail "resolved.cfg of --set E=200000000000000000000 lacks E = 2e+20"
ok "resolved.cfg: E = 2e+20"

# 1100 load steps: 1100 VTU files, all in the PVD, the last at t = 1 (the cap was 1024 files).
"$MICA" run $D -o "$work/steps" --set solver.steps=1100 --set output.mesh=false --set output.monitor=false \
  > "$work/steps.log" 2>&1 || fail "1100 steps: $(tail -n 3 "$work/steps.log")"
files=$(ls "$work/steps" | grep -c '^step_[0-9]*\.vtu$')
[ "$files" -eq 1100 ] || fail "1100 steps wrote $files VTU files"
entries=$(grep -c '<DataSet ' "$work/steps/solution.pvd")
[ "$entries" -eq 1100 ] || fail "solution.pvd lists $entries steps, not 1100"
last=$(grep '<DataSet ' "$work/steps/solution.pvd" | tail -n 1)
grep -q 'timestep="1" .*file="step_1100.vtu"' <<<"$last" || fail "the PVD's last step is not t = 1 in step_1100.vtu: $last"
[ -s "$work/steps/step_1100.vtu" ] || fail "step_1100.vtu is missing or empty"
ok "1100 steps: $files VTU files and $entries PVD entries, the last t = 1 (step_1100.vtu)"

# 300 --sets (the cap was 256): all applied in order, the last wins.
args=()
for i in $(seq 300); do args+=(--set mls.order=2); done
"$MICA" check $D -o "$work/many" "${args[@]}" --set mls.order=1 > "$work/many.log" 2>&1 \
  || fail "301 --sets: $(tail -n 3 "$work/many.log")"
grep -q "order = 1;" "$work/many/resolved.cfg" || fail "301 --sets: the last (mls.order=1) did not win"
ok "301 --sets taken, the last wins"

# A long probe list (was quadratic: libconfig's config_setting_index per element, a linear search of the
# JSON members per probe) is read and reported whole: 20000 probes along y = 0, u_y of the last one equals
# the one-probe run's at the same point. Scaling in docs/performance.md.
python3 - "$D" "$work/probes.cfg" <<'PY'
import sys
src = open(sys.argv[1]).read(); n = 20000
cut = src.index('output = {')
probes = ",\n".join('{ name = "p%d"; point = [%r, 0.0]; field = "uy"; }' % (k, 10.0 * (k + 1) / n) for k in range(n))
open(sys.argv[2], 'w').write(src[:cut] + "output = { probes = (\n" + probes + "\n); };\n")
PY
run_deck "$work/probes" "$work/probes.cfg"
[ "$(grep -c '"p[0-9]*":' "$work/probes/summary.json")" -eq 20000 ] || fail "summary.json lacks some of the 20000 probes"
run_deck "$work/plain" $D
within "$(json_value p19999 "$work/probes/summary.json")" "$(tip "$work/plain")" 1e-12 "probe 20000 of 20000 (x = L) = tip_uy"
