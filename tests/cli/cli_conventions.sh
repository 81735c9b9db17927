# The command line's conventions: --help and -h for every command (the same text as `mica help <command>`),
# every help line at most 100 columns (code points), long choice lists wrapped without losing a choice,
# --output=DIR / --output DIR / -o DIR / -oDIR, '--' before a deck named -x.cfg, --set=PATH=VALUE, and the
# usage errors: "did you mean", the command named, exit status 2, nothing written.
source "$(dirname "$0")/common.bash"
D=tests/decks/cli
work="$OUT_DIR/cli_conventions"
rm -rf "$work" && mkdir -p "$work"
commands="run check mls sweep study stability"

# the program's help: mica --help, -h and mica help are one text on stdout, exit 0, listing every command
"$MICA" --help > "$work/help.txt" || fail "mica --help exited $?"
for form in "-h" "help"; do
  "$MICA" $form > "$work/help_form.txt" || fail "mica $form exited $?"
  cmp -s "$work/help.txt" "$work/help_form.txt" || fail "mica $form differs from mica --help"
done
for c in $commands; do grep -q "^  $c " "$work/help.txt" || fail "mica --help does not list $c"; done
grep -q -- "-o, --output DIR" "$work/help.txt" || fail "mica --help does not show -o, --output DIR"
expect_failure 2 "usage: mica <command>" -- "$MICA"
ok "mica --help, -h, help"

# each command's help: --help and -h, before or after a deck, equal `mica help <command>`
for c in $commands; do
  "$MICA" help $c > "$work/help_$c.txt" || fail "mica help $c exited $?"
  head -n 1 "$work/help_$c.txt" | grep -q "^usage: mica $c \[-o DIR\] \[--set PATH=VALUE\]\.\.\. \[--\] DECK$" \
    || fail "mica help $c does not start with its usage: $(head -n 1 "$work/help_$c.txt")"
  for form in "--help" "-h" "$D/small.cfg --help" "-o $work/nowhere -h"; do
    "$MICA" $c $form > "$work/form.txt" || fail "mica $c $form exited $?"
    cmp -s "$work/help_$c.txt" "$work/form.txt" || fail "mica $c $form differs from mica help $c"
  done
done
[ ! -e "$work/nowhere" ] || fail "mica run -o DIR -h created DIR"
ok "mica <command> --help and -h equal mica help <command>, exit 0"

# every help text fits 100 columns, counted in code points (the settings' help has ±, ×, λ, §, ...)
for f in "$work"/help*.txt; do
  python3 - "$f" <<'PY' || fail "$(basename "$f"): a line is wider than 100 columns or ends in a space"
import sys
lines = open(sys.argv[1], encoding='utf-8').read().splitlines()
wide = [(k + 1, len(line)) for k, line in enumerate(lines) if len(line) > 100 or line.endswith(' ')]
print('%s: %d lines, widest %d%s' % (sys.argv[1].split('/')[-1], len(lines), max(map(len, lines)),
      '; too wide or trailing space at line:width %s' % wide if wide else ''))
sys.exit(1 if wide else 0)
PY
done
# the limit binds: help run has lines of 100 columns, and some of them are longer than 100 bytes (≥, −, θ),
# which a count of bytes would call too wide
[ "$(LC_ALL=C.UTF-8 wc -L < "$work/help_run.txt")" = 100 ] || fail "wc -L: help run's widest line is not 100 columns"
multibyte=$(LC_ALL=C awk 'length > 100' "$work/help_run.txt" | wc -l)
[ "$multibyte" -gt 0 ] || fail "help run has no line over 100 bytes: the code-point count is not tested"
ok "every help line fits 100 columns ($multibyte lines of help run are longer than 100 bytes)"

# a long choice list wraps under its range column without losing a choice: material.model's choices in
# mica help run, joined again, are the list the deck checker gives for a wrong one
pieces=$(awk '/^material\.model / {f=1; print $NF; next} f && match($0, /[^ ]/) > 20 {print $1; next} {f=0}' \
  "$work/help_run.txt")
choices=$(tr -d '\n' <<<"$pieces")
checker=$("$MICA" check input/cantilever.cfg -o "$work/x" --set material.model=nosuch 2>&1 | sed -n 's/.*is not one of //p')
[ -n "$checker" ] && [ "$choices" = "$checker" ] || fail "help run's material.model choices '$choices' != '$checker'"
[ "$(wc -l <<<"$pieces")" -ge 2 ] || fail "material.model's choices did not wrap"
ok "material.model's choices wrapped on $(wc -l <<<"$pieces") lines and complete: $checker"

# --output=DIR, --output DIR, -o DIR, -oDIR, an unambiguous prefix (--out), options before or after the deck
n=0
for form in "--output=$work/o1" "--output $work/o2" "-o $work/o3" "-o$work/o4" "--out $work/o5"; do
  n=$((n + 1))
  "$MICA" mls $form $D/small.cfg > /dev/null || fail "mica mls $form DECK failed"
  [ -f "$work/o$n/summary.json" ] || fail "mica mls $form did not write $work/o$n/summary.json"
done
"$MICA" mls $D/small.cfg -o "$work/o6" --set=mls.order=1 --set "particles.count=[5,7]" > /dev/null \
  || fail "mica mls DECK -o DIR --set=PATH=VALUE --set PATH=VALUE failed"
[ "$(json_value particles "$work/o6/summary.json")" = 35 ] || fail "--set particles.count=[5,7] did not give 35 particles"
grep -q "order = 1" "$work/o6/resolved.cfg" || fail "--set=mls.order=1 did not reach the resolved deck"
ok "--output=DIR, --output DIR, -o DIR, -oDIR, --out DIR; --set=PATH=VALUE and --set PATH=VALUE"

# '--' ends the options: a deck named -weird.cfg after it is the deck; without it, a hint
cp $D/small.cfg "$work/-weird.cfg"
(cd "$work" && "$MICA" mls -o weird -- -weird.cfg > /dev/null) || fail "mica mls -o DIR -- -weird.cfg failed"
[ "$(json_value deck "$work/weird/summary.json")" = "-weird.cfg" ] || fail "the deck after -- was not -weird.cfg"
(cd "$work" && expect_failure 2 "goes after '--': mica mls -- -weird.cfg" -- "$MICA" mls -weird.cfg)
(cd "$work" && expect_failure 2 "one deck at a time: '-weird.cfg' and '--help'" -- "$MICA" mls -- -weird.cfg --help)
ok "-- ends the options"

# usage errors: exit 2, the command named, "did you mean", and nothing written
expect_failure 2 "mica mls: unknown option '--outptu'; did you mean '--output'?" -- \
  "$MICA" mls $D/small.cfg --outptu "$work/e"
expect_failure 2 "mica run: unknown option '-s' (in '-set'); did you mean '--set'?" -- \
  "$MICA" run input/cantilever.cfg -set mls.order=2
expect_failure 2 "mica run: '-output' is -o with the value 'utput'; did you mean '--output'?" -- \
  "$MICA" run input/cantilever.cfg -output "$work/e"
expect_failure 2 "mica: unknown option '--hlep'; did you mean '--help'?" -- "$MICA" --hlep
expect_failure 2 "mica: unknown command 'rnu'; did you mean 'run'?" -- "$MICA" rnu input/cantilever.cfg
expect_failure 2 "mica help: unknown command 'stabilty'; did you mean 'stability'?" -- "$MICA" help stabilty
expect_failure 2 "mica study: option '--help' takes no value" -- "$MICA" study --help=all
expect_failure 2 "mica mls: which deck? usage: mica mls [-o DIR]" -- "$MICA" mls -o "$work/e"
expect_failure 2 "mica mls: one deck at a time" -- "$MICA" mls $D/small.cfg $D/small.cfg -o "$work/e"
expect_failure 2 "mica mls: --output given twice" -- "$MICA" mls $D/small.cfg -o "$work/e" -o "$work/f"
[ ! -e "$work/e" ] && [ ! -e "$work/f" ] || fail "a command-line error created an output directory"
ok "unknown options and commands: did you mean, exit 2, nothing written"

# an option missing its value: at the end, empty, or followed by another option
for o in "-o" "--output" "--set"; do
  expect_failure 2 "needs a value" -- "$MICA" mls $D/small.cfg $o
done
expect_failure 2 "mica sweep: option '--output' needs a value: --output DIR, --output=DIR or -o DIR" -- \
  "$MICA" sweep input/sweep_cantilever.cfg -o
expect_failure 2 "option '--output' needs a value, not an empty one" -- "$MICA" mls $D/small.cfg --output=
expect_failure 2 "option '--output' needs a value (it is followed by the option '--set')" -- \
  "$MICA" mls $D/small.cfg -o --set mls.order=1
expect_failure 2 "option '--set' needs a value: --set PATH=VALUE or --set=PATH=VALUE" -- "$MICA" check --set
ok "missing values"

# mica help --markdown: the settings table alone, on stdout (tests/cli/docs.sh checks its rows); its options
# refused where they would have no effect
"$MICA" help --markdown --group mls mls > "$work/md.txt" || fail "mica help --markdown --group mls mls exited $?"
[ "$(head -n 2 "$work/md.txt")" = $'| setting | type | default | range | meaning |\n|---|---|---|---|---|' ] \
  || fail "mica help --markdown does not start with the table's head: $(head -n 2 "$work/md.txt")"
[ "$(tail -n +3 "$work/md.txt" | grep -vc '^| `mls\.[a-z_]*` | ')" = 0 ] || fail "mica help --markdown --group mls has other lines"
[ "$(tail -n +3 "$work/md.txt" | wc -l)" = "$("$MICA" help mls | grep -c '^mls\.')" ] \
  || fail "mica help --markdown --group mls mls has not one row per mls.* setting of mica help mls"
ok "mica help --markdown --group mls mls: $(tail -n +3 "$work/md.txt" | wc -l) rows, the mls.* settings"
expect_failure 2 "mica help: --group mls needs --markdown" -- "$MICA" help --group mls run
expect_failure 2 "mica help: --markdown prints one command's settings: which command?" -- "$MICA" help --markdown
expect_failure 2 "mica help: one command at a time ('run' and 'mls')" -- "$MICA" help --markdown run mls
expect_failure 2 "mica help: --group given twice" -- "$MICA" help --markdown --group mls --group bc run
expect_failure 2 "mica help: no setting is in the group 'mlsx'" -- "$MICA" help --markdown --group mlsx run
expect_failure 2 "mica help: unknown option '--markdwn'; did you mean '--markdown'?" -- "$MICA" help --markdwn run

"$MICA" --version | grep -qx "mica [0-9.]*" || fail "mica --version does not print the version"
ok "mica --version"
