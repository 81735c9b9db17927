# The docs stay true to the code: every setting that `mica help <command>` lists is in docs/input.md.
source "$(dirname "$0")/common.bash"
for command in run sweep study mls stability; do
  # a setting's line starts at column 0; its description and a wrapped choice list are indented
  settings=$("$MICA" help $command | awk 'f && /^[^ ]/ {print $1} /^setting +type +default +range$/ {f=1}')
  [ -n "$settings" ] || fail "mica help $command lists no settings"
  for s in $settings; do
    grep -qF "\`$s\`" docs/input.md || fail "docs/input.md does not document $s (mica help $command lists it)"
  done
  ok "$command: $(wc -w <<<"$settings") settings documented"
done
