# Adding a type is one file (issue 18, docs/architecture.md §registries): build/tests/mica-ext is the CLI linked
# with tests/extensions/*.c, a weight (bump, (1 − r²)³), a classical model (linear-scaled, linear elasticity
# with E doubled) and an output (displacements_csv: the particles' displacements after the solve, with its own
# setting output.displacements_csv) that register themselves; nothing else names them. mica-ext must offer them
# in help and in the Markdown tables docs/input.md is generated from (mica help --markdown), run decks that choose them and give numbers known
# independently, and plain mica must refuse them as bad input.
source "$(dirname "$0")/common.bash"
case "$MICA_BIN" in build-san/*) : "${MICA_EXT_BIN:=build-san/tests/mica-ext}" ;; *) : "${MICA_EXT_BIN:=build/tests/mica-ext}" ;; esac
EXT="$PWD/$MICA_EXT_BIN"
[ -x "$EXT" ] || EXT="$MICA_EXT_BIN"
[ -x "$EXT" ] || fail "no $MICA_EXT_BIN: build it with make $MICA_EXT_BIN"
work="$OUT_DIR/extensions"
rm -rf "$work" && mkdir -p "$work"

# ---- help: the choice lists come from the registries ----
"$EXT" help run > "$work/help.txt" || fail "mica-ext help run failed"
# the choices of a setting: its line and the indented continuation lines of the choice column, joined
choices() {
  awk -v key="$1" '$1 == key {f = 1; s = $NF; next} f && index($0, $1) > 40 {s = s $1; next} f {print s; exit}' "$2"
}
for key in mls.weight:bump material.model:linear-scaled material.micro_model:linear-scaled; do
  path=${key%%:*} type=${key#*:}
  grep -qE "(^|\|)$type(\||$)" <<<"$(choices "$path" "$work/help.txt")" \
    || fail "mica-ext help run: $path does not offer $type: $(choices "$path" "$work/help.txt")"
  "$MICA" help run > "$work/help-plain.txt"
  grep -qE "(^|\|)$type(\||$)" <<<"$(choices "$path" "$work/help-plain.txt")" \
    && fail "plain mica help run offers $type for $path"
  ok "$path offers $type with the extensions only"
done
# each type's description follows its chooser's help
grep -qF "bump: test extension: the bump (1 - r^2)^3, C2" "$work/help.txt" || fail "mica-ext help run lacks the bump's description"
grep -qF "linear-scaled: test extension: linear elasticity with E doubled" "$work/help.txt" \
  || fail "mica-ext help run lacks linear-scaled's description"
ok "mica-ext help run describes bump and linear-scaled"
# the docs check against mica-ext: the weight and the model add types, not settings; the output type adds its
# own setting, output.displacements_csv, the one setting of mica-ext's help (any command) docs/input.md lacks
settings() { "$1" help "$2" | awk 'f && /^[^ ]/ {print $1} /^setting +type +default +range$/ {f=1}'; }
undocumented=$(for command in run sweep study mls stability; do
  for s in $(settings "$EXT" $command); do grep -qF "\`$s\`" docs/input.md || echo "$s"; done
done | sort -u)
[ "$undocumented" = output.displacements_csv ] \
  || fail "mica-ext's settings that docs/input.md lacks: '$undocumented', expected output.displacements_csv only"
settings "$MICA" run | grep -qx output.displacements_csv && fail "plain mica help run lists output.displacements_csv"
grep -qF "output type displacements_csv: test extension: the particles' displacements" "$work/help.txt" \
  || fail "mica-ext help run does not describe the output type displacements_csv"
ok "docs/input.md covers every setting of mica-ext but the output extension's own, which help describes"
# docs/input.md's tables (mica help --markdown, docs/gen_input_tables.sh): a row's choices are its range column
"$EXT" help --markdown run > "$work/ext.md" || fail "mica-ext help --markdown run failed"
"$MICA" help --markdown run > "$work/plain.md" || fail "mica help --markdown run failed"
row() { awk -F' [|] ' -v key="| \`$1\`" '$1 == key' "$2"; }
md_choices() { row "$1" "$2" | awk -F' [|] ' '{ gsub(/\\[|]/, " ", $4); print $4 }'; }
for key in mls.weight:bump material.model:linear-scaled material.micro_model:linear-scaled; do
  path=${key%%:*} type=${key#*:}
  md_choices "$path" "$work/ext.md" | tr ' ' '\n' | grep -qx -- "$type" \
    || fail "mica-ext help --markdown run: $path's choices lack $type: $(md_choices "$path" "$work/ext.md")"
  row "$path" "$work/ext.md" | grep -qF -- "<br>\`$type\`: test extension: " \
    || fail "mica-ext help --markdown run: $path's row does not describe $type"
  [ -n "$(md_choices "$path" "$work/plain.md")" ] || fail "mica help --markdown run has no row $path"
  md_choices "$path" "$work/plain.md" | tr ' ' '\n' | grep -qx -- "$type" && fail "plain mica's $path offers $type"
  ok "Markdown: $path offers and describes $type with the extensions only"
done
[ "$(row output.displacements_csv "$work/ext.md" | cut -d'|' -f3-4)" = ' bool | false ' ] \
  || fail "mica-ext help --markdown run: no row output.displacements_csv (bool, false): $(row output.displacements_csv "$work/ext.md")"
row output.displacements_csv "$work/ext.md" | grep -qF '<br>output type `displacements_csv`: test extension: ' \
  || fail "mica-ext help --markdown run: output.displacements_csv's row does not describe its output type"
[ -z "$(row output.displacements_csv "$work/plain.md")" ] || fail "plain mica help --markdown run has output.displacements_csv"
ok "Markdown: the output extension's own setting is a row of mica-ext's table only"
# the registry loop over the output types, with the extension's among them
MICA_BIN="$MICA_EXT_BIN" bash "$(dirname "$0")/outputs.sh" > "$work/outputs.log" 2>&1 \
  || fail "outputs.sh with mica-ext: $(tail -3 "$work/outputs.log")"
grep -q "^ok: output.displacements_csv = true (default false) has an effect" "$work/outputs.log" \
  || fail "outputs.sh with mica-ext did not flip output.displacements_csv: $(cat "$work/outputs.log")"
ok "outputs.sh with mica-ext covers displacements_csv"

# ---- the bump weight: the linear patch test reproduces the exact linear field (VCI quadrature) ----
MICA="$EXT" run_deck "$work/patch" input/patch_linear.cfg --set mls.weight=bump --set quadrature.vci=true
err=$(json_value error_l2 "$work/patch/summary.json")
less_than "$err" 1e-10 || fail "bump weight: linear patch error_l2 = $err, not at round-off (< 1e-10)"
ok "bump weight reproduces the linear patch: error_l2 = $err"
# and it is the bump that ran: with Gauss cells its error differs from the default weight's
MICA="$EXT" run_deck "$work/patch-gauss" input/patch_linear.cfg --set mls.weight=bump
MICA="$EXT" run_deck "$work/patch-default" input/patch_linear.cfg
e_bump=$(json_value error_l2 "$work/patch-gauss/summary.json") e_def=$(json_value error_l2 "$work/patch-default/summary.json")
[ "$e_bump" != "$e_def" ] || fail "mls.weight = bump gives the default weight's error $e_def"
ok "Gauss-cell errors differ: bump $e_bump, quartic-c3 $e_def"

# ---- the linear-scaled model: twice the stiffness, half the tip deflection (Dirichlet by multipliers) ----
for model in linear linear-scaled; do
  MICA="$EXT" run_deck "$work/$model" input/cantilever.cfg --set material.model=$model --set bc.method=lagrange
done
[ "$(json_value model "$work/linear-scaled/summary.json")" = linear-scaled ] || fail "the summary does not name linear-scaled"
u1=$(json_value tip_uy "$work/linear/summary.json") u2=$(json_value tip_uy "$work/linear-scaled/summary.json")
within "$u2" "$(awk -v u="$u1" 'BEGIN { printf "%.17g", u / 2 }')" 1e-9 "linear-scaled tip_uy, against linear's $u1 / 2"

# ---- the displacements_csv output: its rows are the last step's VTU displacements, and the probe at (L, 0) ----
"$EXT" run input/cantilever.cfg -o "$work/csv" --set output.displacements_csv=true --set output.monitor=false \
  > "$work/csv.log" 2>&1 || fail "mica-ext run with output.displacements_csv failed: $(tail -3 "$work/csv.log")"
python3 - "$work/csv" "$(json_value tip_uy "$work/csv/summary.json")" <<'PY' || fail "displacements.csv does not match"
import csv, os, sys
sys.path.insert(0, "tests/cli")
import vtu_readback
out, tip_uy = sys.argv[1], float(sys.argv[2])
steps = sorted(f for f in os.listdir(out) if f.startswith("step_") and f.endswith(".vtu"))
vtu = vtu_readback.read_vtu(os.path.join(out, steps[-1]))
rows = list(csv.DictReader(open(os.path.join(out, "displacements.csv"))))
disp = vtu["arrays"]["displacement"][2]
if len(rows) != len(vtu["points"]):
    sys.exit("FAIL: %d rows, %d particles in %s" % (len(rows), len(vtu["points"]), steps[-1]))
worst = 0.0
for i, row in enumerate(rows):
    if [float(row["x"]), float(row["y"]), 0.0] != list(vtu["points"][i]):
        sys.exit("FAIL: row %d at (%s, %s), particle %d at %s" % (i, row["x"], row["y"], i, vtu["points"][i]))
    worst = max(worst, max(abs(float(row[c]) - disp[3 * i + k]) for k, c in enumerate(("ux", "uy", "uz"))))
if worst != 0.0:
    sys.exit("FAIL: the CSV's displacements differ from %s's by up to %g" % (steps[-1], worst))
tip = [r for r in rows if float(r["x"]) == 10.0 and float(r["y"]) == 0.0]
if len(tip) != 1 or abs(float(tip[0]["uy"]) - tip_uy) > 1e-12 * abs(tip_uy):
    sys.exit("FAIL: uy at (10, 0) is %s, the probe tip_uy %.17g" % (tip and tip[0]["uy"], tip_uy))
print("ok: %d rows equal %s's displacements exactly; uy at (L, 0) = %s, the probe tip_uy %.17g (to 1e-12)"
      % (len(rows), steps[-1], tip[0]["uy"], tip_uy))
PY
[ -f "$work/patch-default/displacements.csv" ] && fail "displacements.csv written without output.displacements_csv"
ok "no displacements.csv unless output.displacements_csv = true"

# ---- plain mica: the names are bad input (exit 2), the choice list names the built-in types ----
expect_failure 2 'mls.weight = "bump" is not one of cubic|quartic|quartic-c3|gauss|exponential' -- \
  "$MICA" run input/patch_linear.cfg -o "$work/plain" --set mls.weight=bump
expect_failure 2 'material.model = "linear-scaled" is not one of linear|svk' -- \
  "$MICA" run input/cantilever.cfg -o "$work/plain" --set material.model=linear-scaled
expect_failure 2 "unknown setting 'output.displacements_csv'" -- \
  "$MICA" run input/cantilever.cfg -o "$work/plain" --set output.displacements_csv=true
