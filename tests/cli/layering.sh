# Dependencies point one way (docs/architecture.md §Layers): the folders of src/ are stages in the order below,
# and no object of a stage may use a symbol defined by a higher stage. Measured from nm: the undefined symbols of
# each folder's objects, resolved against the defined symbols of every higher folder. The check is first run on a
# reversed pair (util above mls: mls's calls of the error functions must be flagged), so it is shown to catch a
# violation, then on the real order.
# The headers too: every public header include/mica/NAME.h belongs to the stage that defines its symbols
# (HEADER_STAGE below), and a folder's sources and private headers, and a public header itself, may include only
# public headers of their own stage or lower ones; a quoted include without a path must be a file of the same
# folder. Checked the same way: first with util placed above mls (mls.h includes error.h: must be flagged).
source "$(dirname "$0")/common.bash"
out_root=$(dirname "$(dirname "$MICA_BIN")")           # bin/mica -> . ; build-san/bin/mica -> build-san
obj="$out_root/obj"; [ "$out_root" = . ] && obj=build/obj
STAGES=(util mls io geom models solve parallel assemble bc fe app cli)
# The stage of each public header: the folder that defines what it declares (a header of inline functions and
# types only: the folder of the code it serves). A new header must be added here.
declare -A HEADER_STAGE=(
  [error]=util [registry]=util [sort]=util [schema]=util [text]=util [timer]=util [random]=util
  [mls]=mls
  [deck]=io [expr]=io [files]=io [json]=io [plot]=io [publish]=io [vtk]=io
  [geom]=geom
  [model]=models [cosserat]=models [micromorph]=models [rotation]=models
  [sparse]=solve [newton]=solve [eigen]=solve
  [parallel]=parallel
  [solid]=assemble [kernel]=assemble
  [bc]=bc
  [fe]=fe
  [command]=app [output]=app
  [command_registry]=cli
)
work="$OUT_DIR/layering"; rm -rf "$work" && mkdir -p "$work"

for d in src/*/; do
  d=$(basename "$d")
  [[ " ${STAGES[*]} " == *" $d "* ]] || fail "src/$d has no place in the stage order of tests/cli/layering.sh"
  ls "$obj/src/$d/"*.o >/dev/null 2>&1 || fail "no objects in $obj/src/$d (build first)"
  # the Makefile puts every folder but app and cli into lib/libmica.a, one part each (LIB_DIRS)
  [[ $d == app || $d == cli || -f "$obj/lib/$d.o" ]] || fail "src/$d is a library stage without a part $obj/lib/$d.o"
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

# ---- headers ----
for h in include/mica/*.h; do
  n=$(basename "$h" .h)
  [ -n "${HEADER_STAGE[$n]:-}" ] || fail "include/mica/$n.h has no stage in HEADER_STAGE of tests/cli/layering.sh"
done
for f in src/*/*.[ch]; do
  while read -r inc; do
    [ -f "$(dirname "$f")/$inc" ] || fail "$f includes \"$inc\", which is not a file of its folder (public headers are mica/NAME.h)"
  done < <(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^/"]*\)".*/\1/p' "$f")
done

# "file STAGE header" for every #include "mica/NAME.h": of the folders' files (their folder's stage) and of the
# public headers (their own)
for f in src/*/*.[ch]; do
  d=$(basename "$(dirname "$f")")
  sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"mica\/\([a-z0-9_]*\)\.h".*/\1/p' "$f" | sed "s|^|$f $d |"
done > "$work/includes"
for h in include/mica/*.h; do
  sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"mica\/\([a-z0-9_]*\)\.h".*/\1/p' "$h" |
    sed "s|^|$h ${HEADER_STAGE[$(basename "$h" .h)]} |"
done >> "$work/includes"

# header_violations STAGE...: "file (stage) includes mica/NAME.h (stage)" where NAME's stage comes later in the
# order than the including file's
header_violations() {
  local -A rank=()
  local i file stage name args=("$@")
  for ((i = 0; i < ${#args[@]}; i++)); do rank[${args[i]}]=$i; done
  while read -r file stage name; do
    local hs=${HEADER_STAGE[$name]:-}
    [ -n "$hs" ] || { echo "$file includes mica/$name.h, which is not a public header"; continue; }
    [ -n "${rank[$stage]:-}" ] && [ -n "${rank[$hs]:-}" ] || continue
    ((rank[$hs] <= rank[$stage])) || echo "$file ($stage) includes mica/$name.h ($hs)"
  done < "$work/includes"
}

caught=$(header_violations mls util)
grep -q "include/mica/mls.h (mls) includes mica/error.h (util)" <<<"$caught" || fail "a reversed order was not caught in the headers: $caught"
ok "the header check catches a lower stage including a higher one's header (util placed above mls: $(wc -l <<<"$caught") includes)"

bad=$(header_violations "${STAGES[@]}")
[ -z "$bad" ] || fail "lower stages include higher stages' headers (order ${STAGES[*]}):"$'\n'"$bad"
ok "no folder or public header includes a higher stage's header ($(wc -l < "$work/includes") includes of ${#HEADER_STAGE[@]} headers)"
