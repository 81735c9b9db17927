# lib/libmica.a exports only its public API: every defined global symbol is mica_* or mls_* (the MLS library's
# documented prefix); a folder's cross-file helpers (deck_*, gmsh_*, bc_point, redistribution_*, ...) are local to
# its relocatable object (Makefile: ld -r + objcopy --keep-global-symbol). Under SAN=1 the sanitizers' own
# globals (__asan*, __odr_asan*) are allowed. The same check on the folders' plain objects must find the helpers,
# so the check itself is shown to catch what it looks for.
source "$(dirname "$0")/common.bash"
out_root=$(dirname "$(dirname "$MICA_BIN")")           # bin/mica -> . ; build-san/bin/mica -> build-san
lib="$out_root/lib/libmica.a"
obj="$out_root/obj"; [ "$out_root" = . ] && obj=build/obj
[ -f "$lib" ] || fail "no $lib (build first)"

# foreign FILE...: the defined globals that are neither mica_* nor mls_* (nor a sanitizer's under SAN=1)
foreign() {
  nm -g --defined-only "$@" 2>/dev/null | awk 'NF == 3 { print $3 }' | grep -v '^mica_\|^mls_' |
    { if [ "${SAN:-}" = 1 ]; then grep -v '^__asan\|^__odr_asan'; else cat; fi; } | sort -u
}

n=$(nm -g --defined-only "$lib" | awk 'NF == 3' | wc -l)
[ "$n" -gt 100 ] || fail "$lib defines only $n global symbols"
for api in mica_nonlinear_solve mica_newton_solve mica_deck_load mls_eval mls_create; do
  nm -g --defined-only "$lib" | awk '{ print $3 }' | grep -qx "$api" || fail "$lib does not export $api"
done
bad=$(foreign "$lib")
[ -z "$bad" ] || fail "$lib exports symbols outside mica_*/mls_*: $(tr '\n' ' ' <<<"$bad")"
ok "$lib: $n global symbols, all mica_* or mls_*"

# the check on the objects before localization: the helpers shared between a folder's files are found
raw=$(foreign "$obj"/src/io/*.o "$obj"/src/geom/*.o)
grep -qx deck_text_read <<<"$raw" && grep -qx gmsh_read <<<"$raw" ||
  fail "the check finds no helper in the plain objects of src/io and src/geom: $raw"
ok "the same check flags $(wc -l <<<"$raw") helpers (deck_text_read, gmsh_read, ...) in the plain objects"
