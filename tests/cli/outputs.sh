# The outputs registry seen from outside (docs/architecture.md §outputs): a loop over the output types that
# `mica help run` describes, so that a type an extension registers is covered without editing this file
# (tests/cli/extensions.sh runs it with MICA_BIN=build/tests/mica-ext).
# - every output type with settings is described in the help ("output type NAME: ...") right under its first
#   key, which is output.NAME..., and the built-in ones are there: vtu, mesh, monitor, probes, quadrature_fields;
# - every output type's switch (its bool key output.NAME) has an effect: flipped from its default, the run of
#   input/patch_linear.cfg writes other files, other summary members or other lines than the default run (a
#   setting without effect would be an error of the deck's design). With output.vtu = false the mesh key is
#   flipped too where it has to be (output.mesh = true needs output.vtu: refused, checked in vtu_mesh.sh).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/outputs/$(basename "$MICA_BIN")"
rm -rf "$work" && mkdir -p "$work"

help=$("$MICA" help run)
types=$(awk '$1 == "output" && $2 == "type" { sub(":", "", $3); print $3 }' <<<"$help")
for builtin in vtu mesh monitor probes quadrature_fields; do
  grep -qx "$builtin" <<<"$types" || fail "mica help run does not describe the output type $builtin: $types"
done
# the line before the type's description is its first key's help, and the key before it is output.NAME*
awk '/^[^ ]/ { key = $1 } $1 == "output" && $2 == "type" { sub(":", "", $3); if (index(key, "output." $3) != 1)
       { print "output type " $3 " follows " key; bad = 1 } } END { exit bad }' <<<"$help" \
  || fail "an output type's description does not follow its own key"
ok "$(wc -l <<<"$types") output types described under their keys: $(tr '\n' ' ' <<<"$types")"

# What a run shows of its outputs: the files it wrote, its summary's members, its printed lines (no numbers)
signature() {
  (cd "$1" && ls | grep -v '^resolved.cfg$')
  sed -n 's/^ *"\([a-z_0-9]*\)":.*/member \1/p' "$1/summary.json"
  sed 's/[-0-9.e+]\+/N/g' "$1.log" | sort -u | grep -v "results in"
}
deck=input/patch_linear.cfg
"$MICA" run $deck -o "$work/default" > "$work/default.log" 2>&1 || fail "the default run failed: $(tail -3 "$work/default.log")"
signature "$work/default" > "$work/default.sig"
switches=$(awk '$1 ~ /^output\.[a-z_0-9]+$/ && $2 == "bool" { print $1 " " $3 }' <<<"$help")
n=0
while read -r key def; do
  name=${key#output.}
  grep -qx "$name" <<<"$types" || fail "$key is a switch of no described output type"
  flipped=$([ "$def" = true ] && echo false || echo true)
  extra=()
  [ "$key" = output.vtu ] && [ "$flipped" = false ] && extra=(--set output.mesh=false)
  "$MICA" run $deck -o "$work/$name" --set "$key=$flipped" "${extra[@]}" > "$work/$name.log" 2>&1 \
    || fail "$key = $flipped: the run failed: $(tail -3 "$work/$name.log")"
  signature "$work/$name" > "$work/$name.sig"
  diffs=$(diff "$work/default.sig" "$work/$name.sig" | grep -c '^[<>]')
  [ "$diffs" -gt 0 ] || fail "$key = $flipped changes no file, summary member or printed line: it has no effect"
  ok "$key = $flipped (default $def) has an effect: $diffs lines of the signature differ"
  n=$((n + 1))
done <<<"$switches"
at_least "$n" 4 "output switches flipped"
