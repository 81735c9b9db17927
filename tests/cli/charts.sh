# Charts that need no explaining, checked on the gnuplot scripts mica keeps beside its charts
# (sweep_chart.gp, study_chart.gp, spectrum.gp, inf_sup.gp, mls_chart.gp): the key outside the plot area,
# every analytic reference drawn and inside the y range with a margin, labels in words, the references'
# values those of an independent program, and deck strings that cannot reach gnuplot as commands.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/charts"
rm -rf "$work" && mkdir -p "$work"

# every `set key` is the one below the plot (set key at screen ... bottom, with its own bottom margin) or
# outside to the right; none inside the frame; gnuplot said nothing (no warning, no error)
key_outside() {
  local gp=$1 dir
  dir=$(dirname "$gp")
  grep -q '^set key' "$gp" || fail "$gp: no set key"
  grep '^set key' "$gp" | grep -Ev '^set key (at screen 0\.5, screen 0\.01 center bottom |outside right)' \
    && fail "$gp: a key inside the plot area"
  if grep -q '^set key at screen' "$gp"; then grep -q '^set bmargin [0-9]' "$gp" || fail "$gp: no margin for the key"; fi
  [ ! -s "$dir/gnuplot.log" ] || fail "$gp: gnuplot: $(head -n 3 "$dir/gnuplot.log")"
}
# every x/y label has a space (words, not a bare identifier such as scf or a_over_l)
labels_words() {
  local gp=$1 bare
  bare=$(grep -E "^set [xy]label '[^ ']*'$" "$gp") && fail "$gp: bare label: $bare"
  grep -q "^set xlabel '" "$gp" && grep -q "^set ylabel '" "$gp" || fail "$gp: a label is missing"
}

# ---- the quickstart sweep, two sizes: N = 0 and 0.93 against the classical 3 and Kaloni-Ariman -------------
q="$work/quickstart"
"$MICA" sweep input/quickstart.cfg -o "$q" \
  --set 'sweep.parameters=( { path = "parameters.a_over_l"; values = [0.5, 4.0]; }, { path = "parameters.N"; values = [0.0, 0.93]; } )' \
  > "$q.log" 2>&1 || fail "quickstart sweep failed: $(tail -n 3 "$q.log")"
gp="$q/sweep_chart.gp"
[ -s "$gp" ] && [ -s "$q/sweep.png" ] || fail "sweep_chart.gp or sweep.png missing"
key_outside "$gp"
labels_words "$gp"
grep -q "^set xlabel 'hole radius / length scale a/ℓ'$" "$gp" || fail "the deck's xlabel is not used: $(grep xlabel "$gp")"
ok "quickstart chart: key below the plot, labels in words"
# both references are plotted (the N = 0 curve has no Kaloni-Ariman line: K0, K1 are undefined at 0)
for title in "'classical elasticity (infinite plate): 3'" "'Kaloni-Ariman (infinite plate), N = 0.93'" "'mica, N = 0'" "'mica, N = 0.93'"; do
  [ "$(grep -c "title $title" "$gp")" -eq 2 ] || fail "quickstart chart: no $title in both passes"
done
ok "quickstart chart: mica's N = 0 and 0.93 beside the classical 3 and Kaloni-Ariman"
# Kaloni-Ariman as mica evaluates it (besselk0, besselk1 in the deck) against tests/reference/kaloni_ariman.c
cc -O2 tests/reference/kaloni_ariman.c -lm -o "$work/kaloni_ariman" || fail "cannot build the reference program"
index=$(sed -n "s/.*'sweep_analytic.dat' index \([0-9]*\) .*title 'Kaloni-Ariman (infinite plate), N = 0.93'.*/\1/p" "$gp" | head -n 1)
block() { awk -v b="$1" 'BEGIN { blk = 0; blank = 0 } /^#/ { next } /^$/ { if (++blank == 2) blk++; next } { blank = 0; if (blk == b) print }' "$2"; }
block "$index" "$q/sweep_analytic.dat" > "$work/ka.dat"
[ "$(wc -l < "$work/ka.dat")" -eq 201 ] || fail "the Kaloni-Ariman curve has $(wc -l < "$work/ka.dat") samples, not 201"
for row in 1 67 134 201; do
  read -r x y < <(sed -n "${row}p" "$work/ka.dat")
  within "$y" "$("$work/kaloni_ariman" 0.3 0.93 "$x")" 1e-8 "Kaloni-Ariman at a/l = $x (mica's besselk against the reference program)"
done
# the y range holds every point and every reference value, with a margin of at least 3 % of the span
read -r lo hi < <(sed -n 's/^set yrange \[\(.*\):\(.*\)\]$/\1 \2/p' "$gp" | head -n 1)
[ -n "$lo" ] || fail "quickstart chart: no set yrange"
cat "$q/sweep_analytic.dat" "$q/sweep_points.dat" | awk -v lo="$lo" -v hi="$hi" '
  !/^#/ && NF == 2 && $2 != "NaN" { if (n++ == 0 || $2 < a) a = $2; if (n == 1 || $2 > b) b = $2 }
  END { m = 0.03 * (b - a); if (!(lo <= a - m && hi >= b + m)) { printf "y range [%g, %g] against values [%g, %g]\n", lo, hi, a, b; exit 1 } }' \
  || fail "quickstart chart: the y range does not hold every value with a margin"
less_than 3.0 "$hi" && less_than "$(awk -v h="$hi" 'BEGIN { print h - 3 }')" 1 || fail "the classical 3 is not inside the range [$lo, $hi]"
ok "quickstart chart: y range [$lo, $hi] holds every point and reference (the classical 3 inside)"

# ---- default labels are words; deck strings cannot become gnuplot commands ---------------------------------
d="$work/defaults"
evil='sweep.analytic=( { name = "beam`touch PWNED`'"'"'\"\\\\\nset print \"INJECTED\"\nprint 1 #"; f = "P*x^3/(3*E*I) + P*x/(5/6*G*H)"; } )'
"$MICA" sweep input/sweep_cantilever.cfg -o "$d" --set 'sweep.xlabel=""' --set 'sweep.ylabel=""' --set "$evil" \
  > "$d.log" 2>&1 || fail "cantilever sweep failed: $(tail -n 3 "$d.log")"
gp="$d/sweep_chart.gp"
grep -q "^set xlabel 'parameter L'$" "$gp" || fail "default x label: $(grep xlabel "$gp")"
grep -q "^set ylabel 'tip uy (probe of uy)'$" "$gp" || fail "default y label: $(grep ylabel "$gp")"
labels_words "$gp"
key_outside "$gp"
[ ! -e "$d/PWNED" ] && [ ! -e "$d/INJECTED" ] && [ ! -e PWNED ] || fail "a deck string ran as a gnuplot command"
# gnuplot runs backquotes only outside single-quoted literals (and never in comments): none may be left there.
sed -e "s/'[^']*'//g" -e 's/^[[:space:]]*#.*//' "$gp" | grep -q '`' && fail "a backquote reached the gnuplot script outside a quoted literal"
grep -q '^set print' "$gp" && fail "a line break in a deck string started a gnuplot command"
grep -qF "title 'beam\`touch PWNED\`''\"" "$gp" || fail "the escaped title is missing: $(grep -o "title '[^']*'" "$gp")"
ok "default labels 'parameter L', 'tip uy (probe of uy)'; a title with \`, ', \", \\\\ and line breaks stays a title"
# on log axes too, the beam formula's values lie strictly inside the y range
read -r lo hi < <(sed -n 's/^set yrange \[\(.*\):\(.*\)\]$/\1 \2/p' "$gp" | head -n 1)
awk -v lo="$lo" -v hi="$hi" '!/^#/ && NF == 2 { if (!($2 > lo && $2 < hi)) { print $2; exit 1 } }' "$d/sweep_analytic.dat" \
  || fail "cantilever chart: an analytic value outside [$lo, $hi]"
ok "cantilever chart (log-log): every analytic value inside [$lo, $hi]"

# ---- study, stability and mls charts: keys outside, labels in words ---------------------------------------
"$MICA" study input/study_timoshenko.cfg -o "$work/study" > "$work/study.log" 2>&1 || fail "study failed: $(tail -n 3 "$work/study.log")"
key_outside "$work/study/study_chart.gp"
labels_words "$work/study/study_chart.gp"
# one style per curve: no two curves share colour and dash
styles=$(grep -o "'study_points.dat' index [0-9]* .* lc rgb '#[0-9A-F]*' dt [0-9]*" "$work/study/study_chart.gp" | sed 's/.* lc rgb/lc rgb/' | sort | uniq -d)
[ -z "$styles" ] || [ "$(grep -c "'study_points.dat' index 0 " "$work/study/study_chart.gp")" -gt 1 ] || fail "study: curves share a style"
ok "study charts: key below, labels in words"
"$MICA" stability input/free_block.cfg -o "$work/stability" > "$work/stability.log" 2>&1 \
  || fail "stability failed: $(tail -n 3 "$work/stability.log")"
for gp in spectrum.gp inf_sup.gp; do key_outside "$work/stability/$gp"; labels_words "$work/stability/$gp"; done
# the zero tolerance (a reference line) lies inside the spectrum's y range
read -r lo hi < <(sed -n 's/^set yrange \[\(.*\):\(.*\)\]$/\1 \2/p' "$work/stability/spectrum.gp" | head -n 1)
tol=$(sed -n "s/.*, \([-0-9.e+]*\) with lines dt 2 lc rgb 'black' title 'zero tolerance.*/\1/p" "$work/stability/spectrum.gp" | head -n 1)
less_than "$lo" "$tol" && less_than "$tol" "$hi" && less_than 1 "$hi" || fail "spectrum: zero tolerance $tol or 1 outside [$lo, $hi]"
ok "stability charts: keys below, labels in words, the zero tolerance and the largest eigenvalue inside the y range"
"$MICA" mls examples/mls-accuracy/order2_radii.cfg -o "$work/mls" > "$work/mls.log" 2>&1 || fail "mls failed: $(tail -n 3 "$work/mls.log")"
key_outside "$work/mls/mls_chart.gp"
labels_words "$work/mls/mls_chart.gp"
ok "mls chart: keys outside right, labels in words"
