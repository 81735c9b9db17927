# MicaFieldModel.param is read and written through the names each model gives its slots (MICA_COSSERAT_* in
# mica/cosserat.h, MICRO_* in src/models/micromorph_private.h, GRADIENT_* in src/models/strain_gradient.c),
# never by a bare number (issue 18): a literal index in src/ or include/ is a slot whose meaning is written
# nowhere. The check is first shown to catch one (a line with param[3]), then run on the sources.
source "$(dirname "$0")/common.bash"

literal_slots() { grep -nE '(->|\.)param\[[0-9]+\]' "$@"; }

work="$OUT_DIR/model_params"; rm -rf "$work" && mkdir -p "$work"
printf '  m->param[3] = c.alpha;\n' > "$work/probe.c"
literal_slots "$work/probe.c" >/dev/null || fail "the check misses a literal slot index (param[3])"
ok "the check catches a literal slot index"

found=$(literal_slots -r src include)
[ -z "$found" ] || fail "MicaFieldModel.param indexed by a number (name the slot in the model's header):"$'\n'"$found"
ok "no MicaFieldModel.param slot in src/ or include/ is indexed by a number"
