# Adding a type is one file (issue 18, docs/architecture.md §registries): build/tests/mica-ext is the CLI linked
# with tests/extensions/*.c, a weight (bump, (1 − r²)³) and a classical model (linear-scaled, linear elasticity
# with E doubled) that register themselves; nothing else names them. mica-ext must offer them in help (whose
# text docs/input.md's tables follow), run decks that choose them and give numbers known independently, and
# plain mica must refuse them as bad input.
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
# the docs check, run against mica-ext: the extensions add types, not settings, so docs/input.md still covers
# every setting mica-ext lists
MICA_BIN="$MICA_EXT_BIN" bash "$(dirname "$0")/docs.sh" > "$work/docs.log" 2>&1 || fail "docs.sh with mica-ext: $(cat "$work/docs.log")"
ok "docs.sh passes with mica-ext"

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

# ---- plain mica: the names are bad input (exit 2), the choice list names the built-in types ----
expect_failure 2 'mls.weight = "bump" is not one of cubic|quartic|quartic-c3|gauss|exponential' -- \
  "$MICA" run input/patch_linear.cfg -o "$work/plain" --set mls.weight=bump
expect_failure 2 'material.model = "linear-scaled" is not one of linear|svk' -- \
  "$MICA" run input/cantilever.cfg -o "$work/plain" --set material.model=linear-scaled
