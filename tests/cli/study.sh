# mica study: speed against accuracy. The small Timoshenko study (input/study_timoshenko.cfg: order 1, 2 x
# m = 2, 4, 8): its rows, its errors against the same combinations run by `mica run --set`, the Pareto
# flags and the fastest combination recomputed here from study.csv, the energy error's convergence rate for
# the linear basis; a combination that fails (recorded, the study goes on); bad study decks (exit 2, line).
# Nothing here depends on the timings' values, only on their order as study.csv reports them.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/study"
rm -rf "$work" && mkdir -p "$work"
deck=input/study_timoshenko.cfg

"$MICA" help study | grep -q "study.choices.\[\].path" || fail "help study does not list study.choices.[].path"
"$MICA" --help | grep -q "^  study " || fail "mica --help does not list the study command"
ok "help study"

# col NAME FILE: the column number of NAME in a CSV header
col() { head -n 1 "$2" | tr ',' '\n' | grep -nx -- "$1" | cut -d: -f1; }
# field ROW NAME FILE: the value of column NAME in the row whose index is ROW
field() { awk -F, -v r="$1" -v c="$(col "$2" "$3")" 'NR > 1 && $1 == r { print $c }' "$3"; }

# ---- the small study ---------------------------------------------------------------------------------------
"$MICA" study "$deck" -o "$work/small" > "$work/small.log" 2>&1 || fail "study failed: $(tail -n 3 "$work/small.log")"
for n in 1 2 3 4 5 6; do
  grep -Eq "^combination $n/6  order=[12] m=[248]  energy [0-9.e+-]+  time [0-9.e+-]+ s  elapsed [0-9.]+ s  remaining ~[0-9]+ s$" \
    "$work/small.log" || fail "no progress line for combination $n: $(cat "$work/small.log")"
done
ok "progress lines"
csv="$work/small/study.csv"
[ "$(wc -l < "$csv")" -eq 7 ] || fail "study.csv should have a header and 6 rows: $(cat "$csv")"
[ "$(awk -F, -v c="$(col status "$csv")" 'NR > 1 && $c == "ok"' "$csv" | wc -l)" -eq 6 ] || fail "every row should be ok"
for c in index parameters.k parameters.m dofs nnz cache_bytes memory_bytes time_discretize time_mls time_cache_pattern \
         time_assemble time_factor time_solve time_solve_total time_total error_l2 error_h1 error_energy tip_uy error \
         time pareto message; do
  [ -n "$(col "$c" "$csv")" ] || fail "study.csv has no column $c: $(head -n 1 "$csv")"
done
ok "study.csv: 6 rows, every column"
s="$work/small/summary.json"
[ "$(json_value combinations "$s")/$(json_value ok "$s")/$(json_value failed "$s")" = 6/6/0 ] || fail "summary counts"
for f in study_time.png study_time.svg study_dofs.png study_dofs.svg study_chart.gp resolved.cfg; do
  [ -s "$work/small/$f" ] || fail "$f missing or empty"
done
for n in 1 2 3 4 5 6; do
  [ "$(json_value status "$work/small/points/$n/summary.json")" = ok ] || fail "points/$n/summary.json is not ok"
done
ok "summary counts 6/6/0, charts, a summary per combination"

# every row's errors and probe are those of `mica run` with the same overrides (to 1e-12 relative)
for n in 1 2 3 4 5 6; do
  k=$(field $n parameters.k "$csv"); m=$(field $n parameters.m "$csv")
  run_deck "$work/direct_$n" "$deck" --set parameters.k=$k --set parameters.m=$m
  for e in error_l2 error_h1 error_energy tip_uy; do
    awk -v a="$(field $n $e "$csv")" -v b="$(json_value $e "$work/direct_$n/summary.json")" \
      'BEGIN { d = (a - b) / b; if (d < 0) d = -d; exit !(d <= 1e-12) }' \
      || fail "combination $n ($k, $m): $e in study.csv $(field $n $e "$csv") != mica run's $(json_value $e "$work/direct_$n/summary.json")"
  done
  [ "$(field $n dofs "$csv")" = "$(json_value dofs "$work/direct_$n/summary.json")" ] || fail "combination $n: dofs differ"
done
ok "errors, probe and dofs of all 6 rows equal mica run --set's (1e-12 relative)"

# the Pareto flags: on the front iff no other ok row has both a smaller time and a smaller error
check_pareto() {
  awk -F, -v ce="$(col error "$1")" -v ct="$(col time "$1")" -v cp="$(col pareto "$1")" -v cs="$(col status "$1")" '
    NR > 1 { n++; e[n] = $ce; t[n] = $ct; p[n] = $cp; st[n] = $cs }
    END {
      for (i = 1; i <= n; i++) {
        front = st[i] == "ok"
        for (j = 1; j <= n && front; j++) if (st[j] == "ok" && t[j] + 0 < t[i] + 0 && e[j] + 0 < e[i] + 0) front = 0
        if (p[i] != front) { printf "row %d: pareto %s, expected %d\n", i, p[i], front; bad = 1 }
        fronts += front
      }
      if (fronts < 1) { print "nothing on the front"; bad = 1 }
      exit bad
    }' "$1" || fail "Pareto flags in $1 are wrong"
  [ "$(awk -F, -v c="$(col pareto "$1")" 'NR > 1 && $c == 1' "$1" | wc -l)" = "$(json_value pareto_points "$2")" ] \
    || fail "summary pareto_points differs from study.csv"
}
check_pareto "$csv" "$s"
ok "Pareto flags recomputed from study.csv ($(json_value pareto_points "$s") on the front)"

# fastest_for_target: its row's error is <= target, and no ok row with error <= target is faster
check_fastest() {  # check_fastest CSV SUMMARY TARGET
  local expect
  expect=$(awk -F, -v ce="$(col error "$1")" -v ct="$(col time "$1")" -v cs="$(col status "$1")" -v T="$3" '
    NR > 1 && $cs == "ok" && $ce + 0 <= T + 0 && (best == "" || $ct + 0 < bt + 0) { best = $1; bt = $ct }
    END { print best }' "$1")
  [ -n "$expect" ] || fail "no row reaches $3 in $1: the test needs one"
  [ "$(json_value combination "$2")" = "$expect" ] || fail "fastest_for_target is combination $(json_value combination "$2"), expected $expect"
  less_than "$(field "$expect" error "$1")" "$3" || [ "$(field "$expect" error "$1")" = "$3" ] || fail "fastest row's error exceeds $3"
}
check_fastest "$csv" "$s" 5e-3
grep -q "^fastest to energy error <= 0.005: order=2 m=8 in " "$work/small.log" || fail "stdout does not name the fastest: $(tail -n 4 "$work/small.log")"
ok "fastest_for_target (5e-3): combination $(json_value combination "$s") = $(json_value choice "$s")"

# a target nobody reaches is not an error
"$MICA" study "$deck" -o "$work/unreached" --set study.target=1e-9 > "$work/unreached.log" 2>&1 || fail "study with an unreachable target failed"
grep -q "^no combination reaches energy error <= 1e-09; the smallest, " "$work/unreached.log" || fail "stdout does not say the target is not reached"
grep -q '"fastest_for_target": "none: no combination reaches energy error <= 1e-09"' "$work/unreached/summary.json" \
  || fail "summary does not say the target is not reached"
ok "an unreached target: said on stdout and in summary.json, exit 0"

# the energy error of the linear basis (order 1, dilation 2) against the spacing h = D/m: theory O(h); on these
# regular grids the coarse rates are higher (measured 1.39 on m = 2, 4, 8). Accepted: 0.9 <= rate <= 1.6 (the
# L2 error, rate ~2.7, or a broken norm would fall outside).
rate=$(awk -F, -v ck="$(col parameters.k "$csv")" -v cm="$(col parameters.m "$csv")" -v ce="$(col error_energy "$csv")" \
  'NR > 1 && $ck == 1 { print 12 / $cm, $ce }' "$csv" | ls_rate)
at_least "$rate" 0.9 "energy-error rate of the linear basis"
less_than "$rate" 1.6 || fail "energy-error rate of the linear basis $rate > 1.6"
ok "energy-error rate of the linear basis: $rate (0.9 to 1.6)"

# repeat: each combination solved 3 times; the errors do not change. A target that 4 rows reach.
"$MICA" study "$deck" -o "$work/repeat" --set study.repeat=3 --set 'study.time="total"' --set study.target=0.06 \
  > "$work/repeat.log" 2>&1 || fail "repeat study failed"
[ "$(json_value repeat "$work/repeat/summary.json")/$(json_value time_measure "$work/repeat/summary.json")" = 3/total ] || fail "repeat/time not in summary"
diff <(cut -d, -f"$(col error_energy "$csv")" "$csv") <(cut -d, -f"$(col error_energy "$work/repeat/study.csv")" "$work/repeat/study.csv") > /dev/null \
  || fail "repeated solves changed the errors"
awk -F, -v ct="$(col time "$work/repeat/study.csv")" -v cT="$(col time_total "$work/repeat/study.csv")" \
  'NR > 1 { d = $ct - $cT; if (d < 0) d = -d; if (d > 1e-6 * $cT) exit 1 }' "$work/repeat/study.csv" || fail "time is not time_total with study.time = total"
check_pareto "$work/repeat/study.csv" "$work/repeat/summary.json"
check_fastest "$work/repeat/study.csv" "$work/repeat/summary.json" 0.06
ok "repeat = 3, time = total: same errors, time = time_total, Pareto flags right, fastest for 0.06 right"

# ---- combinations that fail: a deck error for that combination (CHOLMOD with Lagrange multipliers, which
# ---- give an indefinite matrix) and a numerical one (quadratic basis on a support of 1.2 spacings) --------
"$MICA" study "$deck" -o "$work/invalid" --set parameters.m=4 --set 'study.choices=(
    { path = "bc.method"; words = "nitsche, lagrange"; }, { path = "solver.linear"; words = "cholmod, umfpack"; })' \
    > "$work/invalid.log" 2>&1 || fail "a study with failing combinations should succeed: $(tail -n 3 "$work/invalid.log")"
csv2="$work/invalid/study.csv"
[ "$(wc -l < "$csv2")" -eq 5 ] || fail "invalid: 4 rows expected: $(cat "$csv2")"
grep -q '^3,"lagrange","cholmod",error,.*CHOLMOD needs a symmetric positive definite' "$csv2" || fail "row 3 should be a deck error: $(cat "$csv2")"
[ "$(awk -F, -v c="$(col status "$csv2")" 'NR > 1 && $c == "ok"' "$csv2" | wc -l)" -eq 3 ] || fail "3 rows should be ok"
[ "$(field 3 pareto "$csv2")" = 0 ] || fail "a failed row is on the front"
[ "$(json_value failed "$work/invalid/summary.json")" = 1 ] || fail "summary: failed should be 1"
[ "$(json_value exit_status "$work/invalid/points/3/summary.json")" = 2 ] || fail "points/3: exit_status should be 2"
grep -q "^combination 3/4  bc.method=lagrange solver.linear=cholmod  failed: .*CHOLMOD" "$work/invalid.log" || fail "no failure in the progress line"
grep -q "^study: 3 of 4 combinations ok, 1 failed" "$work/invalid.log" || fail "stdout does not count the failure"
check_pareto "$csv2" "$work/invalid/summary.json"
ok "a deck error of one combination is recorded (status error, message) and the study goes on"

"$MICA" study "$deck" -o "$work/singular" --set parameters.m=4 --set 'study.choices=(
    { path = "parameters.k"; name = "order"; values = [1, 2]; }, { path = "mls.dilation"; values = [1.2, 3.0]; })' \
    > "$work/singular.log" 2>&1 || fail "singular study should succeed: $(tail -n 3 "$work/singular.log")"
grep -q '^3,2,1.2,error,.*singular' "$work/singular/study.csv" || fail "order 2 with dilation 1.2 should fail: $(cat "$work/singular/study.csv")"
[ "$(json_value failed "$work/singular/summary.json")" = 1 ] || fail "singular: failed should be 1"
check_pareto "$work/singular/study.csv" "$work/singular/summary.json"
ok "a singular moment matrix in one combination is recorded and the study goes on"

expect_failure 2 "every combination of the study failed (2); combination 1: " -- "$MICA" study "$deck" -o "$work/allfail" \
  --set 'study.choices=({ path = "mls.dilation"; values = [0.5, 0.6]; })'
[ -e "$work/allfail" ] && fail "a study whose every combination failed left $work/allfail behind"
ok "every combination failing is an error and leaves nothing"

# ---- bad study decks: exit 2 with the line -----------------------------------------------------------------
sed '/^study = {/,$d' "$deck" > "$work/base.cfg"
sed '/^exact = {/,/^};/d' "$work/base.cfg" > "$work/noexact_base.cfg"
bad() {  # bad NAME BASE STUDY_GROUP MESSAGE: exit 2, a message that starts with the study group's line
  cp "$work/$2.cfg" "$work/$1.cfg"
  printf '%s\n' "$3" >> "$work/$1.cfg"
  local line=$(( $(wc -l < "$work/$2.cfg") + 1 )) err rc
  err=$("$MICA" study "$work/$1.cfg" -o "$work/$1" 2>&1 >/dev/null); rc=$?
  [ "$rc" -eq 2 ] || fail "$1: exit $rc, expected 2: $err"
  grep -qF -- "mica: $work/$1.cfg:$line: " <<<"$err" || fail "$1: the message does not start with line $line: $err"
  grep -qF -- "$4" <<<"$err" || fail "$1: the message lacks '$4': $err"
  [ -e "$work/$1" ] && fail "$1: a bad study deck left an output directory"
  ok "$1: exit 2, line $line, '$4'"
}
bad unknown base 'study = { choices = ( { path = "mls.dilatation"; values = [1.0]; } ); };' \
  "study.choices.[0]: --set mls.dilatation=1: unknown setting 'mls.dilatation'; did you mean 'mls.dilation'?"
bad empty base 'study = { choices = ( { path = "parameters.m"; values = []; } ); };' "values has 0 values"
bad noexact noexact_base 'study = { choices = ( { path = "parameters.m"; values = [2, 4]; } ); };' \
  'error = "energy" is measured against an exact solution, and this deck has none'
bad noexact_l2 noexact_base 'study = { choices = ( { path = "parameters.m"; values = [2, 4]; } ); error = "l2"; };' \
  'error = "l2" is measured against an exact solution, and this deck has none'
bad noreference noexact_base 'study = { choices = ( { path = "parameters.m"; values = [2, 4]; } ); error = "tip_uy"; };' \
  'error = "tip_uy" is a probe: give its exact (or overkill) value as reference'
bad noprobe base 'study = { choices = ( { path = "parameters.m"; values = [2, 4]; } ); error = "tip_ux"; };' \
  'error = "tip_ux" is neither l2, h1, energy nor a probe of this deck (output.probes: tip_uy)'
bad own base 'study = { choices = ( { path = "study.repeat"; values = [1, 2]; } ); };' "a study cannot vary its own settings"
bad range base 'study = { choices = ( { path = "mls.order"; values = [1, 7]; } ); };' "mls.order = 7 is out of range"
bad twice base 'study = { choices = ( { path = "parameters.m"; values = [2]; }, { path = "parameters.m"; values = [4]; } ); };' \
  "parameters.m is varied twice"
bad time base 'study = { choices = ( { path = "parameters.m"; values = [2]; } ); time = "wall"; };' '"wall"'

# a probe with its reference: the error is |tip_uy - reference| / |reference| (reference: the exact tip deflection)
cp "$work/noexact_base.cfg" "$work/probe.cfg"
echo 'study = { choices = ( { path = "parameters.m"; values = [2, 4, 8]; } ); error = "tip_uy";
            reference = "P/(6*E*I) * ((4 + 5*nu)*D^2*L/4 + 2*L^3)"; target = 1e-3; };' >> "$work/probe.cfg"
"$MICA" study "$work/probe.cfg" -o "$work/probe" > "$work/probe.log" 2>&1 || fail "probe study failed: $(tail -n 3 "$work/probe.log")"
ref=$(awk 'BEGIN { P = 1000; E = 3e7; nu = 0.3; L = 48; D = 12; I = D^3/12; printf "%.17g", P/(6*E*I) * ((4 + 5*nu)*D^2*L/4 + 2*L^3) }')
for n in 1 2 3; do
  expect=$(awk -v p="$(field $n tip_uy "$work/probe/study.csv")" -v r="$ref" 'BEGIN { d = (p - r) / r; printf "%.17g", d < 0 ? -d : d }')
  within "$(field $n error "$work/probe/study.csv")" "$expect" 1e-9 "probe error of combination $n"
done
[ -z "$(field 1 error_energy "$work/probe/study.csv")" ] || fail "a deck without exact solution has no energy error"
ok "error = a probe against its reference (an expression of the parameters)"
