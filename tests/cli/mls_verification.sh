# The MLS accuracy study against references:
#  - Table 3.1 of seed 001: supporting particles along the line (-5,0,0)-(5,0,0) for nine box radii
#    on the 11^3 grid (min at the ends, max inside); exact integers.
#  - exact reproduction: a quadratic is reproduced by a second-order basis, with its derivatives, to
#    rounding (relative error < 1e-10), on regular and jittered particles, through the whole pipeline
#    (deck, libmatheval's symbolic derivatives, MLS, summary).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/mls_verification"
rm -rf "$work" && mkdir -p "$work"

"$MICA" mls examples/mls-accuracy/support_table.cfg -o "$work/table" --set output.chart=false > /dev/null \
  || fail "support_table.cfg failed"
expected_min="1 18 18 75 75 75 196 196 405"
expected_max="2 27 36 125 150 150 343 392 729"
got_min=$(json_values support_min "$work/table/summary.json" | tr '\n' ' ' | sed 's/ $//')
got_max=$(json_values support_max "$work/table/summary.json" | tr '\n' ' ' | sed 's/ $//')
[ "$got_min" = "$expected_min" ] || fail "Table 3.1 minimum support: got '$got_min', seed has '$expected_min'"
[ "$got_max" = "$expected_max" ] || fail "Table 3.1 maximum support: got '$got_max', seed has '$expected_max'"
ok "Table 3.1 supports: min $got_min; max $got_max"

quadratic='"1 + x - 2*y + 0.5*x^2 - x*z + 3*y^2 + 0.25*z^2"'
for jitter in 0.0 0.3; do
  "$MICA" mls input/mls_skatulla.cfg -o "$work/quad$jitter" --set "function.f=$quadratic" \
    --set particles.jitter=$jitter --set mls.radius=2.6 --set sample.volume.points=200 \
    --set output.chart=false > /dev/null || fail "quadratic run failed (jitter $jitter)"
  for key in err_f_max err_dx_max err_dxx_max volume_err_f_max volume_err_dx_max volume_err_dxx_max; do
    v=$(json_value $key "$work/quad$jitter/summary.json")
    less_than "$v" 1e-10 || fail "quadratic, jitter $jitter: $key = $v, expected < 1e-10"
  done
  ok "quadratic reproduced to rounding, jitter $jitter (err_dxx_max $(json_value err_dxx_max "$work/quad$jitter/summary.json"))"
done
