# Dependencies point one way (docs/architecture.md §Layers): the folders of src/ are stages in the order below,
# and no object of a stage may use a symbol defined by a higher stage. Measured from nm: the undefined symbols of
# each folder's objects, resolved against the defined symbols of every higher folder. The check is first run on a
# reversed pair (util above mls: mls's calls of the error functions must be flagged), so it is shown to catch a
# violation, then on the real order.
source "$(dirname "$0")/common.bash"
out_root=$(dirname "$(dirname "$MICA_BIN")")           # bin/mica -> . ; build-san/bin/mica -> build-san
obj="$out_root/obj"; [ "$out_root" = . ] && obj=build/obj
STAGES=(util mls io geom models solve parallel assemble bc fe app cli)
work="$OUT_DIR/layering"; rm -rf "$work" && mkdir -p "$work"

for d in src/*/; do
  d=$(basename "$d")
  [[ " ${STAGES[*]} " == *" $d "* ]] || fail "src/$d has no place in the stage order of tests/cli/layering.sh"
  ls "$obj/src/$d/"*.o >/dev/null 2>&1 || fail "no objects in $obj/src/$d (build first)"
  nm -g --defined-only "$obj/src/$d/"*.o | awk 'NF == 3 { print $3 }' | sort -u > "$work/$d.def"
  # "object symbol" for every undefined symbol of the folder's objects
  for o in "$obj/src/$d/"*.o; do nm -u "$o" | awk -v o="$(basename "$o")" '{ print o, $NF }'; done > "$work/$d.und"
done

# violations STAGE...: "lower -> higher: symbol (object)" for every call of a later stage by an earlier one
violations() {
  local stages=("$@") i j
  for ((i = 0; i < ${#stages[@]}; i++)); do
    for ((j = i + 1; j < ${#stages[@]}; j++)); do
      awk -v lo="src/${stages[i]}" -v hi="src/${stages[j]}" 'NR == FNR { def[$1] = 1; next }
          ($2 in def) { print lo " -> " hi ": " $2 " (" $1 ")" }' "$work/${stages[j]}.def" "$work/${stages[i]}.und"
    done
  done
}

caught=$(violations mls util)
grep -q "src/mls -> src/util: mica_error_set" <<<"$caught" || fail "a reversed order was not caught: $caught"
ok "the check catches a lower stage calling a higher one (util placed above mls: $(wc -l <<<"$caught") calls)"

bad=$(violations "${STAGES[@]}")
[ -z "$bad" ] || fail "lower stages call higher ones (order ${STAGES[*]}):"$'\n'"$bad"
ok "no folder calls a higher one: ${STAGES[*]}"
