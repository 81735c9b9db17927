# Long deck strings and long lists (hardening issue 17, items 5 and 8): a name, title or label longer than
# MICA_DECK_TEXT_MAX (200 bytes) and an expression longer than MICA_EXPR_TEXT_MAX (4096 bytes) are refused
# with their deck line and exit 2 before anything runs; strings within the cap reach the outputs whole
# (not cut at some buffer inside); stability.inf_sup_counts takes more than 16 refinement levels.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/long_strings"
rm -rf "$work" && mkdir -p "$work"
repeat() { python3 -c "import sys; sys.stdout.write(sys.argv[1] * int(sys.argv[2]))" "$1" "$2"; }
# expression FILE PIECE COUNT: the deck's traction tx = "1" becomes "1" followed by COUNT times PIECE (built
# in python: a megabyte is beyond the length of one command-line argument)
expression() {
  python3 -c "import sys; p = sys.argv[1]; t = open(p).read().replace('tx = \"1\"', 'tx = \"1' + sys.argv[2] * int(sys.argv[3]) + '\"'); open(p, 'w').write(t)" "$@"
}

box() {  # box FILE [EXTRA LINE]: a small plate with one probe
  cat > "$1" <<EOF
geometry = { shape = "box"; lower = [0.0, 0.0]; upper = [1.0, 1.0]; };
particles = { count = [5, 5]; };
material = { model = "linear"; E = 1.0; nu = 0.3; };
bcs = { dirichlet = ( { set = "left"; ux = "0"; uy = "0"; } ); traction = ( { set = "right"; tx = "1"; } ); };
output = { vtu = false; monitor = false; probes = ( { name = "tip_ux"; point = [1.0, 0.5]; field = "ux"; } ); };
${2:-}
EOF
}

# ---- names and titles beyond the cap: refused with the line ----------------------------------------------
long=$(repeat t 5000)
box "$work/title.cfg" "problem = { title = \"$long\"; };"
for command in check run sweep study stability; do
  expect_failure 2 "title.cfg:6: problem.title is 5000 bytes long; at most 200 are allowed" \
    -- "$MICA" $command "$work/title.cfg" -o "$work/x"
done
box "$work/probe.cfg"
sed -i "s/name = \"tip_ux\"/name = \"$long\"/" "$work/probe.cfg"
expect_failure 2 "probe.cfg:5: output.probes.[0].name is 5000 bytes long; at most 200" \
  -- "$MICA" run "$work/probe.cfg" -o "$work/x"
expect_failure 2 "problem.title is 5000 bytes long" \
  -- "$MICA" check "$work/title.cfg" --set "problem.title=\"$long\"" -o "$work/x"
mls_deck="examples/mls-accuracy/order1_radii.cfg"
sed "s/name = \"rho 1.51\"/name = \"$long\"/" "$mls_deck" > "$work/variant.cfg"
expect_failure 2 "variant.cfg:16: study.variants.[1].name is 5000 bytes long; at most 200" \
  -- "$MICA" mls "$work/variant.cfg" -o "$work/x"
[ ! -e "$work/x" ] || fail "a refused deck left $work/x behind"

# ---- strings within the cap reach the outputs whole ------------------------------------------------------
# A sweep over problem.title with a 150-byte word: the chart's curve title is "problem.title = <word>"
# (cut at 63 bytes of the word before: a 64-byte buffer), and sweep.csv has the word.
word=$(repeat w 150)
box "$work/words.cfg" "sweep = { parameters = ( { path = \"material.E\"; values = [1.0, 2.0]; },
  { path = \"problem.title\"; words = \"$word, short\"; } ); };"
"$MICA" sweep "$work/words.cfg" -o "$work/words" > "$work/words.log" 2>&1 || fail "sweep: $(tail -n 3 "$work/words.log")"
grep -qF "problem.title = $word'" "$work/words/sweep_chart.gp" \
  || fail "sweep_chart.gp lacks the whole 150-byte word: $(grep -o 'problem.title = w*' "$work/words/sweep_chart.gp" | head -n 1 | wc -c) bytes"
ok "a 150-byte word stands whole in the chart's curve title"
# An MLS variant of a 200-byte name (the cap): whole in summary.json (cut at 127 bytes before).
name=$(repeat v 200)
sed "s/name = \"rho 1.51\"/name = \"$name\"/; s/samples = 201/samples = 11/" "$mls_deck" > "$work/name.cfg"
"$MICA" mls "$work/name.cfg" -o "$work/name" --set mls.order=1 > "$work/name.log" 2>&1 \
  || fail "mls: $(tail -n 3 "$work/name.log")"
grep -qF "\"$name\"" "$work/name/summary.json" || fail "summary.json lacks the 200-byte variant name whole"
ok "a 200-byte variant name stands whole in summary.json"

# A study measured by a probe of a 200-byte name: its first line says "relative error of <name>" whole (cut
# at 127 bytes of the line's title before).
box "$work/probe200.cfg" "study = { choices = ( { path = \"material.E\"; values = [1.0, 2.0]; } ); error = \"$name\"; reference = 1.0; };"
sed -i "s/name = \"tip_ux\"/name = \"$name\"/" "$work/probe200.cfg"
"$MICA" study "$work/probe200.cfg" -o "$work/probe200" > "$work/probe200.log" 2>&1 \
  || fail "study: $(tail -n 3 "$work/probe200.log")"
grep -qF "relative error of $name against" "$work/probe200.log" \
  || fail "the study's first line lacks the 200-byte probe name whole: $(head -n 1 "$work/probe200.log" | cut -c1-80)"
ok "a 200-byte probe name stands whole in the study's title"

# ---- expressions beyond MICA_EXPR_TEXT_MAX: refused before libmatheval parses them --------------------------
# libmatheval takes time quadratic in a run of blanks (1 MB: about a second, 50 MB: most of an hour) and
# overflows its stack on a chain of 2 * 10^5 terms (a crash before): both refused at once.
box "$work/blank.cfg"
expression "$work/blank.cfg" ' ' 1000000
start=$(date +%s.%N)
expect_failure 2 "blank.cfg:4: bcs.traction.[0].tx: the expression is longer than 4096 bytes" \
  -- "$MICA" run "$work/blank.cfg" -o "$work/x"
elapsed=$(echo "$(date +%s.%N) - $start" | bc)
less_than "$elapsed" 5 || fail "refusing a 1 MB expression took $elapsed s"
ok "a 1 MB expression refused in $elapsed s"
box "$work/chain.cfg"
expression "$work/chain.cfg" '+1' 200000
expect_failure 2 "chain.cfg:4: bcs.traction.[0].tx: the expression is longer than 4096 bytes" \
  -- "$MICA" run "$work/chain.cfg" -o "$work/x"
box "$work/edge.cfg"
expression "$work/edge.cfg" ' ' 4095
run_deck "$work/edge" "$work/edge.cfg"
ok "an expression of exactly 4096 bytes is taken"

# ---- more than 16 inf-sup refinement levels ----------------------------------------------------------------
# 17 levels (refused before: "has 17 values; it needs 1 to 16"): 17 rows in inf_sup.csv, and the 17th row's
# beta equal to the one of a run of that level alone (the levels are independent).
free_block="examples/stability/free_block.cfg"
only_inf_sup=(--set stability.eigen=false --set stability.patch=false --set stability.conditioning=false
              --set stability.chart=false)
"$MICA" stability "$free_block" -o "$work/levels" "${only_inf_sup[@]}" \
  --set 'stability.inf_sup_counts=[5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21]' > "$work/levels.log" 2>&1 \
  || fail "stability with 17 levels: $(tail -n 3 "$work/levels.log")"
rows=$(($(wc -l < "$work/levels/inf_sup.csv") - 1))
[ "$rows" -eq 17 ] || fail "inf_sup.csv has $rows rows, expected 17"
ok "17 inf-sup levels: 17 rows"
"$MICA" stability "$free_block" -o "$work/level21" "${only_inf_sup[@]}" --set 'stability.inf_sup_counts=[21]' \
  > "$work/level21.log" 2>&1 || fail "stability at N = 21: $(tail -n 3 "$work/level21.log")"
within "$(json_value inf_sup_beta_N21 "$work/levels/summary.json")" \
  "$(json_value inf_sup_beta_N21 "$work/level21/summary.json")" 1e-12 "beta at N = 21, 17th level against alone"
echo "all long-string checks passed"
