# What `mica stability` shows for each integration rule, kept in step with the docs: reads the table of
# docs/verification.md §"What `mica stability` shows for each rule" and runs every row (the deck with the row's
# settings, eigen-analysis only); the zero, rigid, spurious zero and low-energy mode counts must equal the
# table's. A row that no longer holds fails here, so the docs cannot promise what the code does not show.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/stability_rules"
rm -rf "$work" && mkdir -p "$work"
rows=$(awk '/^### What `mica stability` shows for each rule/ { on = 1; next } on && /^#/ { exit }
            on && /^\| input\// { print }' docs/verification.md)
[ "$(wc -l <<<"$rows")" -ge 8 ] || fail "the table in docs/verification.md has $(wc -l <<<"$rows") rows, expected at least 8"
n=0
while IFS='|' read -r _ deck settings zero rigid spurious low _; do
  deck=$(xargs <<<"$deck") settings=$(tr -d '`' <<<"$settings" | sed 's/^ *//; s/ *$//')
  args=()
  for s in $settings; do args+=(--set "$s"); done
  n=$((n + 1))
  d="$work/row$n"
  "$MICA" stability "$deck" -o "$d" "${args[@]}" --set stability.patch=false --set stability.inf_sup=false \
    > "$d.log" 2>&1 || fail "mica stability $deck $settings failed: $(tail -n 3 "$d.log")"
  got="$(json_value zero_modes "$d/summary.json") $(json_value rigid_modes "$d/summary.json")"
  got="$got $(json_value spurious_zero_modes "$d/summary.json") $(json_value low_energy_modes "$d/summary.json")"
  want="$(xargs <<<"$zero") $(xargs <<<"$rigid") $(xargs <<<"$spurious") $(xargs <<<"$low")"
  [ "$got" = "$want" ] || fail "$deck $settings: zero/rigid/spurious zero/low-energy = $got, the docs say $want"
  ok "$deck $settings: $got"
done <<<"$rows"
ok "$n rows of the table hold"
