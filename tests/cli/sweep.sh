# mica sweep: the demo deck against the beam formula, the outputs (CSV, points, chart, summary), a failing
# point that the sweep records and survives, the comparison of models, and bad sweep decks (exit 2, line).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/sweep"
rm -rf "$work" && mkdir -p "$work"

"$MICA" help sweep | grep -q "sweep.parameters.\[\].path" || fail "help sweep does not list sweep.parameters.[].path"
"$MICA" help sweep | grep -q "material.model" || fail "help sweep does not list the run deck's settings"
ok "help sweep"

# ---- the demo: tip deflection against L = 4, 8, 16, 32 (H = 2) --------------------------------------------
"$MICA" sweep input/sweep_cantilever.cfg -o "$work/demo" > "$work/demo.log" 2>&1 || fail "demo sweep failed: $(tail -n 3 "$work/demo.log")"
for n in 1 2 3 4; do
  grep -Eq "^point $n/4  L=[0-9]+  tip_uy=[-0-9.e]+  elapsed [0-9.]+ s  remaining ~[0-9]+ s$" "$work/demo.log" \
    || fail "no progress line for point $n: $(cat "$work/demo.log")"
done
ok "progress lines"
csv="$work/demo/sweep.csv"
[ "$(head -n 1 "$csv")" = "index,parameters.L,tip_uy,root_sxx,time_total,status,message" ] || fail "sweep.csv header: $(head -n 1 "$csv")"
[ "$(wc -l < "$csv")" -eq 5 ] || fail "sweep.csv should have a header and 4 rows: $(cat "$csv")"
[ "$(grep -c ',ok,$' "$csv")" -eq 4 ] || fail "sweep.csv: every point should be ok: $(cat "$csv")"
ok "sweep.csv: header and 4 rows"

# Euler-Bernoulli + shear: P L^3/(3 E I) + P L/(kappa G A), E = 2e5, nu = 0.3, H = 2, P = 10 (plane stress)
beam() { awk -v L="$1" 'BEGIN { E = 2e5; nu = 0.3; H = 2; P = 10; I = H^3/12; G = E/(2*(1 + nu));
                                printf "%.10g", P*L^3/(3*E*I) + P*L/(5/6*G*H) }'; }
for L in 8 16 32; do  # L/H >= 4
  tip=$(awk -F, -v L=$L '$2 == L { print $3 }' "$csv")
  within "$tip" "$(beam $L)" 0.03 "tip deflection at L = $L against the beam formula"
done
# the chart's analytic curve is the same formula: its last sample is at L = 32
last=$(awk 'NF == 2 && $1 == 32 { print $2 }' "$work/demo/sweep_analytic.dat" | tail -n 1)
within "$last" "$(beam 32)" 1e-8 "analytic curve at L = 32"
for f in sweep.png sweep.svg summary.json resolved.cfg; do [ -s "$work/demo/$f" ] || fail "demo: $f missing or empty"; done
for n in 1 2 3 4; do
  [ "$(json_value status "$work/demo/points/$n/summary.json")" = ok ] || fail "points/$n/summary.json status is not ok"
done
ls "$work"/demo/points/*/*.vtu > /dev/null 2>&1 && fail "points wrote VTU files (output.vtu should be off)"
s="$work/demo/summary.json"
[ "$(json_value points_total "$s")/$(json_value points_ok "$s")/$(json_value points_failed "$s")" = 4/4/0 ] \
  || fail "summary counts: $(grep points_ "$s")"
[ "$(json_value chart "$s")" = sweep.png ] || fail "summary: chart is $(json_value chart "$s")"
ok "outputs: chart, summaries per point, no VTU, counts 4/4/0"

# a second sweep into the same directory replaces the points; the user's --set comes before the sweep's
"$MICA" sweep input/sweep_cantilever.cfg -o "$work/demo" --set output.vtu=true \
  --set 'sweep.parameters=({ path = "parameters.L"; values = [8.0, 16.0]; })' > "$work/demo2.log" 2>&1 \
  || fail "second sweep into the same directory failed: $(tail -n 3 "$work/demo2.log")"
[ "$(ls "$work/demo/points" | wc -l)" -eq 2 ] || fail "the second sweep should leave 2 points: $(ls "$work/demo/points")"
[ -f "$work/demo/points/2/step_0001.vtu" ] || fail "--set output.vtu=true did not reach the points"
ok "re-run into the same directory; --set output.vtu=true wins over the sweep's default"

# ---- a deck without its own sweep, for the rest ------------------------------------------------------------
base='parameters = { L = 10.0; H = 2.0; E = 200.0e3; nu = 0.3; P = 10.0; };
geometry = { shape = "box"; lower = ["0", "-H/2"]; upper = ["L", "H/2"]; };
particles = { count = [21, 5]; };
mls = { order = 2; dilation = 3.0; };
material = { model = "linear"; E = "E"; nu = "nu"; plane = "strain"; };
bcs = { dirichlet = ( { set = "left"; ux = "0"; uy = "0"; } ); traction = ( { set = "right"; ty = "P/H"; } ); };
solver = { steps = 4; };
output = { probes = ( { name = "tip_uy"; point = ["L", "0"]; field = "uy"; } ); };'
deck() { printf '%s\n%s\n' "$base" "$2" > "$work/$1.cfg"; }   # the sweep group is on line 9

# ---- a point that fails: dilation 0.5 leaves a singular moment matrix --------------------------------------
deck failing 'sweep = { parameters = ( { path = "mls.dilation"; values = [3.0, 0.5]; } ); };'
"$MICA" sweep "$work/failing.cfg" -o "$work/failing" > "$work/failing.log" 2>&1 \
  || fail "a sweep with one good point should succeed: $(tail -n 3 "$work/failing.log")"
csv="$work/failing/sweep.csv"
awk -F, '$1 == 1 && $2 == 3 && $(NF-1) == "ok"' "$csv" | grep -q . || fail "point 1 should be ok: $(cat "$csv")"
awk -F, '$1 == 2 && $2 == 0.5' "$csv" | grep -q ',error,".*singular' || fail "point 2 should be an error: $(cat "$csv")"
[ "$(json_value points_failed "$work/failing/summary.json")" = 1 ] || fail "summary: points_failed should be 1"
[ "$(json_value status "$work/failing/points/2/summary.json")" = error ] || fail "points/2/summary.json should say error"
grep -q "1 of 2 points ok, 1 failed" "$work/failing.log" || fail "stdout does not say how many failed"
grep -q "^point 2/2  mls.dilation=0.5  failed: .*singular" "$work/failing.log" || fail "no failure in the progress line"
ok "a failing point is recorded (status error, message) and the sweep goes on"

deck allfail 'sweep = { parameters = ( { path = "mls.dilation"; values = [0.5, 0.6]; } ); };'
expect_failure 2 "every point of the sweep failed (2); point 1: " -- "$MICA" sweep "$work/allfail.cfg" -o "$work/allfail"
[ -e "$work/allfail" ] && fail "a sweep whose every point failed left $work/allfail behind"
ok "every point failing is an error and leaves nothing"

# ---- models: svk against linear (classical) ---------------------------------------------------------------
# small rotations everywhere: svk agrees from the smallest L on
deck models 'sweep = { parameters = ( { path = "material.model"; words = "linear, svk"; },
                                      { path = "parameters.L"; values = [4.0, 8.0, 16.0]; } ); };'
"$MICA" sweep "$work/models.cfg" -o "$work/models" > "$work/models.log" 2>&1 || fail "models sweep failed: $(tail -n 3 "$work/models.log")"
[ "$(json_value svk "$work/models/summary.json")" = 4 ] || fail "svk should agree with linear above L = 4: $(grep -A2 agrees "$work/models/summary.json")"
grep -q "svk agrees with linear (|tip_uy / tip_uy_linear - 1| <= 0.01) for L >= 4" "$work/models.log" || fail "no comparison statement"
[ "$(wc -l < "$work/models/sweep.csv")" -eq 7 ] || fail "models: 6 points expected"
ok "svk agrees with linear for L >= 4 (tolerance 1 %)"
# stiffness: the rotations shrink as E grows, and svk comes closer to linear (differences 2e-3 at E = 1e4, 2e-5 at 1e5)
deck stiff 'sweep = { tolerance = 1e-3; parameters = ( { path = "material.model"; words = "linear, svk"; },
                                      { path = "parameters.E"; values = [1e3, 1e4, 1e5]; } ); };'
"$MICA" sweep "$work/stiff.cfg" -o "$work/stiff" > "$work/stiff.log" 2>&1 || fail "stiffness sweep failed: $(tail -n 3 "$work/stiff.log")"
# the sampled points agree from E = 1e5 on (1e4 does not); bisection narrows the threshold between them
# (sweep_threshold.c): the bracket [lo, hi] is checked by independent runs — at lo the two models differ by more
# than the tolerance, at hi by no more — and the estimate lies inside it
read -r lo hi < <(awk '/"bracket"/ { f = 1; next } f && /\]/ { exit } f { gsub(/[ ,]/, ""); printf "%s ", $0 }' \
  "$work/stiff/summary.json")
above=$(json_value svk "$work/stiff/summary.json")
estimate=$(awk '/"model_thresholds"/ { f = 1 } f && /"threshold"/ { gsub(/[ ,]/, ""); split($0, a, ":"); print a[2]; exit }' \
  "$work/stiff/summary.json")
awk -v lo="$lo" -v hi="$hi" -v a="$above" -v e="$estimate" \
  'BEGIN { exit !(lo >= 1e4 && hi <= 1e5 && lo < hi && a == hi && e >= lo && e <= hi && (hi - lo) / hi < 0.03) }' \
  || fail "stiff: bracket [$lo, $hi], agrees above $above, estimate $estimate: not a bracket inside [1e4, 1e5]"
[ "$(json_value bisection_steps "$work/stiff/summary.json")" = 8 ] || fail "stiff: 8 bisection steps expected"
for end in lo hi; do
  for model in linear svk; do
    "$MICA" run "$work/stiff.cfg" -o "$work/stiff_${end}_$model" --set material.model=\"$model\" \
      --set parameters.E="${!end}" > /dev/null 2>&1 || fail "stiff: the run at E = ${!end} ($model) failed"
  done
  d=$(awk -v a="$(json_value tip_uy "$work/stiff_${end}_svk/summary.json")" \
          -v b="$(json_value tip_uy "$work/stiff_${end}_linear/summary.json")" 'BEGIN { d = a / b - 1; print d < 0 ? -d : d }')
  if [ "$end" = lo ]; then less_than 1e-3 "$d" || fail "stiff: at the bracket's lower end E = $lo svk agrees ($d)"
  else less_than "$d" 1.0000001e-3 || fail "stiff: at the bracket's upper end E = $hi svk differs by $d"; fi
  ok "stiff: at E = ${!end} (bracket $end) |svk / linear - 1| = $d"
done
grep -q "svk agrees with linear (|tip_uy / tip_uy_linear - 1| <= 0.001) for E >= $(printf %g "$above"); the threshold lies in" \
  "$work/stiff.log" || fail "stiff: the statement does not give the bracket: $(grep agrees "$work/stiff.log")"
awk -v e="$estimate" 'NF == 2 && $1 == e { n++ } END { exit n != 2 }' "$work/stiff/sweep_thresholds.dat" \
  || fail "stiff: the chart's threshold line is not at the estimate $estimate"
grep -q "sweep_thresholds.dat" "$work/stiff/sweep_chart.gp" || fail "stiff: the chart does not draw the threshold"
ok "svk's threshold between the sampled E = 1e4 and 1e5: in [$lo, $hi], estimate $estimate, drawn on the chart"
"$MICA" sweep "$work/stiff.cfg" -o "$work/stiff_never" --set sweep.tolerance=1e-6 > /dev/null 2>&1 || fail "stiffness sweep failed"
[ "$(json_value svk "$work/stiff_never/summary.json")" = never ] || fail "svk should never agree within 1e-6"
ok "svk never agrees with linear within 1e-6"

# ---- reuse: a point that changes only the model, its constants or the loads builds no discretization, MLS
# or shape function; it shares the previous point's, and gives exactly what a run of its own gives ------------
s="$work/stiff/summary.json"
[ "$(json_value points_sharing_shape_functions "$s")" = 5 ] \
  || fail "stiff: 5 of 6 points should share shape functions, not $(json_value points_sharing_shape_functions "$s")"
at_least "$(json_value shape_caches_built "$work/stiff/points/1/summary.json")" 1 "stiff: point 1 computes its shape functions"
for n in 2 3 4 5 6; do
  p="$work/stiff/points/$n/summary.json"
  [ "$(json_value reused_discretization "$p")/$(json_value shape_caches_built "$p")" = true/0 ] \
    || fail "stiff point $n should reuse the discretization and build no cache: $(grep -E 'reused|caches' "$p")"
done
grep -q "^reuse: 5 of 6 points computed no shape function; setup [0-9.e-]* s on the first point" "$work/stiff.log" \
  || fail "no reuse line in the sweep log: $(tail -n 4 "$work/stiff.log")"
for n in 2 6; do  # the second point (same model as the first) and the last (svk after linear)
  row=$(awk -F, -v n=$n '$1 == n' "$work/stiff/sweep.csv")
  model=$(echo "$row" | cut -d, -f2 | tr -d '"'); E=$(echo "$row" | cut -d, -f3); swept=$(echo "$row" | cut -d, -f4)
  "$MICA" run "$work/stiff.cfg" -o "$work/stiff_alone_$n" --set material.model=$model --set parameters.E=$E \
    > /dev/null 2>&1 || fail "stiff point $n alone failed"
  alone=$(json_value tip_uy "$work/stiff_alone_$n/summary.json")
  awk -v a="$alone" -v b="$swept" 'BEGIN { exit !(a == b) }' \
    || fail "stiff point $n: swept tip_uy $swept differs from the run alone $alone"
done
ok "sharing points give the digits of a run alone"
# every point of the demo changes L: nothing is shared
[ "$(json_value points_sharing_shape_functions "$work/demo/summary.json")" = 0 ] || fail "demo: no point may share"
for n in 1 2; do
  [ "$(json_value reused_discretization "$work/demo/points/$n/summary.json")" = false ] || fail "demo point $n reused"
done
# a model that needs Hessians (strain gradient) does not take a first-order model's caches, nor lends its own
deck orders 'sweep = { parameters = ( { path = "material.model"; words = "strain-gradient, linear, strain-gradient"; } ); };'
"$MICA" sweep "$work/orders.cfg" -o "$work/orders" --set material.l=0.2 --set bc.method=penalty > "$work/orders.log" 2>&1 \
  || fail "orders sweep failed: $(tail -n 3 "$work/orders.log")"
for n in 1 2 3; do
  p="$work/orders/points/$n/summary.json"
  [ "$(json_value reused_discretization "$p")" = $([ $n = 1 ] && echo false || echo true) ] || fail "orders point $n: reuse flag"
  at_least "$(json_value shape_caches_built "$p")" 2 "orders point $n computes the caches of its derivative order"
done
"$MICA" run "$work/orders.cfg" -o "$work/orders_alone" --set material.l=0.2 --set bc.method=penalty \
  --set material.model=strain-gradient > /dev/null 2>&1 || fail "strain-gradient run alone failed"
[ "$(json_value tip_uy "$work/orders_alone/summary.json")" = "$(json_value tip_uy "$work/orders/points/3/summary.json")" ] \
  || fail "orders point 3 differs from the run alone"
ok "reuse follows the derivative order: strain gradient after linear rebuilds, and matches a run alone"

# ---- bad sweep decks: exit 2 with the line ----------------------------------------------------------------
bad() {  # bad NAME SWEEP_GROUP MESSAGE: exit 2, a message that starts with the sweep group's line
  deck "$1" "$2"
  local err rc
  err=$("$MICA" sweep "$work/$1.cfg" -o "$work/$1" 2>&1 >/dev/null); rc=$?
  [ "$rc" -eq 2 ] || fail "$1: exit $rc, expected 2: $err"
  grep -qF -- "mica: $work/$1.cfg:9: " <<<"$err" || fail "$1: the message does not start with the line: $err"
  grep -qF -- "$3" <<<"$err" || fail "$1: the message lacks '$3': $err"
  ok "$1: exit 2, line 9, '$3'"
}
bad unknown 'sweep = { parameters = ( { path = "mls.dilatation"; values = [1.0]; } ); };' \
  "sweep.parameters.[0]: --set mls.dilatation=1: unknown setting 'mls.dilatation'; did you mean 'mls.dilation'?"
bad noparam 'sweep = { parameters = ( { path = "parameters.LL"; values = [1.0]; } ); };' "the deck has no parameter 'LL'"
bad empty 'sweep = { parameters = ( { path = "parameters.L"; values = []; } ); };' "values has 0 values"
bad nopoints 'sweep = { parameters = ( { path = "parameters.L"; range = [1.0, 2.0]; } ); };' "a range needs points"
bad zip 'sweep = { mode = "zip"; parameters = ( { path = "parameters.L"; values = [1.0, 2.0]; },
                                                 { path = "parameters.H"; values = [1.0]; } ); };' 'mode = "zip" takes'
bad probe 'sweep = { probe = "tip_ux"; parameters = ( { path = "parameters.L"; values = [1.0]; } ); };' \
  'probe = "tip_ux" is not a probe of this deck'
bad range 'sweep = { parameters = ( { path = "mls.order"; values = [1, 7]; } ); };' "mls.order = 7 is out of range"
bad word 'sweep = { parameters = ( { path = "material.model"; words = "linear, svkk"; } ); };' 'did you mean "svk"?'
bad threshold 'sweep = { threshold_steps = 4; parameters = ( { path = "parameters.L"; values = [1.0, 2.0]; } ); };' \
  'sweep.threshold_steps narrows the size at which a model agrees with sweep.classical'
bad array 'sweep = { parameters = ( { path = "geometry.lower"; values = [1.0]; } ); };' "only single values can be swept"
[ -e "$work/unknown" ] && fail "a bad sweep deck left an output directory"
ok "bad sweep decks"
