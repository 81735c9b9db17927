# The reference values quoted in the shipped decks are the ones the tests assert (docs/verification.md
# §Reference values). Every deck in input/ and examples/ that quotes a reference carries one
# machine-readable line per value,
#   # reference: KEY = VALUE (rel|abs TOL)[ at PATH=VALUE ...][ by COMMAND] — docs/verification.md
# (KEY a summary.json member, "at" the --set overrides of the run, "by" the command, default run). This test
#  - checks that each such line is a row of the table in docs/verification.md with the same deck, key and
#    overrides, value and tolerance, and that each row of the table is such a line (a typo in either fails);
#  - checks that the tests named in the row's last column exist and run that deck;
#  - runs each deck once per set of overrides (the decks as shipped; cosserat_roll.cfg with 10 load steps,
#    which give its 20 steps' answer to 1e-14), two at a time, and asserts every value within its tolerance.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/deck_references"
rm -rf "$work" && mkdir -p "$work"
table=docs/verification.md
section='## Reference values of the shipped decks'
grep -qxF "$section" $table || fail "$table has no section '$section'"

# The table's rows (| deck | quantity | reference | source | tolerance | asserted by |) as
# "deck<TAB>quantity<TAB>reference<TAB>tolerance<TAB>asserted by", cells trimmed.
rows=$(awk -v s="$section" -F'|' '
  $0 == s { f = 1; next } f && /^## / { exit }
  f && /^\| `/ { out = ""; for (i = 2; i <= 7; i++) if (i != 5) { c = $i; gsub(/^ +| +$/, "", c); out = out (i > 2 ? "\t" : "") c }
                 print out }' $table)
[ -n "$rows" ] || fail "the table of $section is empty"

re='^# reference: ([A-Za-z_][A-Za-z0-9_]*) = (-?[0-9][0-9.eE+-]*) \((rel|abs) ([0-9][0-9.eE+-]*)\)( at ([^ ]+=[^ ]+( [^ ]+=[^ ]+)*))?( by ([a-z]+))? — docs/verification\.md$'
declare -A runs=()   # run key (deck|command|overrides) -> "key value kind tol;..."
declare -A listed=() # table rows matched by a deck line
count=0
for deck in $(find input examples -name '*.cfg' | sort); do
  while IFS= read -r line; do
    [[ $line =~ $re ]] || fail "$deck: not a reference line: '$line'"
    key=${BASH_REMATCH[1]} value=${BASH_REMATCH[2]} kind=${BASH_REMATCH[3]} tol=${BASH_REMATCH[4]}
    at=${BASH_REMATCH[6]} by=${BASH_REMATCH[9]:-run}
    quantity="\`$key\`"
    [ -n "$at" ] && quantity+=" at $(sed 's/[^ ]*/`&`/g' <<<"$at")"
    [ "$by" != run ] && quantity+=" by \`mica $by\`"
    row=$(awk -F'\t' -v d="\`$deck\`" -v q="$quantity" -v v="$value" -v t="$kind $tol" \
      '$1 == d && index($2, q) == 1 && (length($2) == length(q) || substr($2, length(q) + 1, 1) == ":") &&
       $3 == v && $4 == t { print NR "\t" $5 }' <<<"$rows")
    [ -n "$row" ] || fail "$deck: '$line' is not in $table §Reference values (deck \`$deck\`, quantity $quantity, reference $value, tolerance $kind $tol)"
    [ "$(wc -l <<<"$row")" = 1 ] || fail "$deck: '$line' matches several rows of the table"
    listed[${row%%$'\t'*}]=1
    for t in ${row#*$'\t'}; do
      t=${t%,}
      [ -f "$t" ] || fail "$deck, $key: the table names $t, which does not exist"
      [ "$t" = tests/cli/deck_references.sh ] || grep -qF "$deck" "$t" \
        || fail "$deck, $key: the table says $t asserts it, but $t does not run $deck"
    done
    runs["$deck|$by|$at"]+="$key $value $kind $tol;"
    count=$((count + 1))
  done < <(grep '^# reference' "$deck")
done
nrows=$(wc -l <<<"$rows")
for ((i = 1; i <= nrows; i++)); do
  [ -n "${listed[$i]:-}" ] || fail "the table's row '$(sed -n "${i}p" <<<"$rows" | cut -f1-4)' has no reference line in its deck"
done
ok "$count reference lines in the decks, $nrows rows in the table, in step"

# Each deck once per set of overrides (two at a time: the machine has two cores), then every value against its
# reference.
declare -A dirs=()
n=0
for run in "${!runs[@]}"; do
  IFS='|' read -r deck by at <<<"$run"
  n=$((n + 1)); dirs[$run]="$work/$n"
  args=(-o "$work/$n" --set output.vtu=false)
  [ "$by" = run ] && args+=(--set output.monitor=false)
  for o in $at; do args+=(--set "$o"); done
  [ "$(jobs -rp | wc -l)" -lt 2 ] || wait -n
  ( "$MICA" $by "$deck" "${args[@]}" > "$work/$n.log" 2>&1; echo $? > "$work/$n.status" ) &
done
wait
for run in "${!runs[@]}"; do
  IFS='|' read -r deck by at <<<"$run"
  dir=${dirs[$run]}
  [ "$(cat "$dir.status")" = 0 ] || fail "mica $by $deck ${at:+(at $at) }failed: $(tail -n 3 "$dir.log")"
  IFS=';' read -ra checks <<<"${runs[$run]}"
  for c in "${checks[@]}"; do
    read -r key value kind tol <<<"$c"
    got=$(json_value "$key" "$dir/summary.json")
    [ -n "$got" ] || fail "$deck${at:+ at $at}: summary.json has no $key"
    awk -v g="$got" -v r="$value" -v k="$kind" -v t="$tol" \
      'BEGIN { d = g - r; if (d < 0) d = -d; a = r < 0 ? -r : r; exit !(d <= (k == "rel" ? t * a : t)) }' \
      || fail "$deck${at:+ at $at}: $key = $got is not within $kind $tol of the quoted $value"
    ok "$deck${at:+ at $at}: $key = $got within $kind $tol of $value"
  done
done
