#!/usr/bin/env bash
# Rewrites the generated settings tables of docs/input.md (or FILE) in place: the lines between
#   <!-- generated: mica help --markdown [--group GROUP] COMMAND -->
#   <!-- end generated -->
# become what that command prints, run by $MICA_BIN (default bin/mica): the settings table made from the
# command's schema and registries (src/io/deck.c, mica_deck_print_schema_markdown), the prose around the
# blocks untouched. `make docs` runs it; tests/cli/docs.sh runs it on a copy and fails on any difference.
# Usage: bash docs/gen_input_tables.sh [FILE]
set -euf -o pipefail
file=${1:-docs/input.md}
mica=${MICA_BIN:-bin/mica}
die() { echo "gen_input_tables.sh: $*" >&2; exit 1; }
[ -f "$file" ] || die "no file $file"
[ -x "$mica" ] || die "no mica binary $mica (make, or set MICA_BIN)"
tmp=$(mktemp "$file.XXXXXX")
trap 'rm -f "$tmp"' EXIT
begin='^<!-- generated: mica (help --markdown [^>]*[^ >]) -->$'
n=0 start=0 blocks=0
while IFS= read -r line || [ -n "$line" ]; do
  n=$((n + 1))
  if [[ $line =~ $begin ]]; then
    [ "$start" = 0 ] || die "$file:$n: a generated block inside the one of line $start"
    printf '%s\n\n' "$line"
    $mica ${BASH_REMATCH[1]} || die "$file:$n: mica ${BASH_REMATCH[1]} failed"
    printf '\n'
    start=$n
  elif [[ $line == '<!-- end generated -->' ]]; then
    [ "$start" != 0 ] || die "$file:$n: an end marker with no begin marker before it"
    printf '%s\n' "$line"
    start=0 blocks=$((blocks + 1))
  elif [[ $line == '<!-- generated'* || $line == '<!-- end generated'* ]]; then
    die "$file:$n: a marker in neither form: '$line' (<!-- generated: mica help --markdown ... --> and <!-- end generated -->)"
  elif [ "$start" = 0 ]; then
    printf '%s\n' "$line"
  fi
done < "$file" > "$tmp"
[ "$start" = 0 ] || die "$file:$start: the generated block has no end marker"
[ "$blocks" -gt 0 ] || die "$file: no generated block"
cat "$tmp" > "$file"
