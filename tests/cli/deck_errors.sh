# Bad input: every deck error gives exit status 2 and names the file and line; a failed run (bad deck,
# bad override, singular moment matrix) leaves an earlier run's results complete and untouched.
source "$(dirname "$0")/common.bash"
D=tests/decks/cli
work="$OUT_DIR/deck_errors"
rm -rf "$work" && mkdir -p "$work"

expect_failure 2 "unknown_key.cfg:5: unknown setting 'mls.oder'" -- "$MICA" mls $D/unknown_key.cfg -o "$work/x"
expect_failure 2 "did you mean 'mls.order'" -- "$MICA" mls $D/unknown_key.cfg -o "$work/x"
expect_failure 2 "unknown_group.cfg:8:" -- "$MICA" mls $D/unknown_group.cfg -o "$work/x"
expect_failure 2 "wrong_type.cfg:5: mls.order must be an integer" -- "$MICA" mls $D/wrong_type.cfg -o "$work/x"
expect_failure 2 "out_of_range.cfg:5: mls.order = 7 is out of range [0, 3]" -- "$MICA" mls $D/out_of_range.cfg -o "$work/x"
expect_failure 2 "bad_expression.cfg:6:" -- "$MICA" mls $D/bad_expression.cfg -o "$work/x"
expect_failure 2 "unknown name 'q'" -- "$MICA" mls $D/bad_expression.cfg -o "$work/x"
expect_failure 2 "bad_choice.cfg:5:" -- "$MICA" mls $D/bad_choice.cfg -o "$work/x"
expect_failure 2 'did you mean "cubic"' -- "$MICA" mls $D/bad_choice.cfg -o "$work/x"
expect_failure 2 "syntax_error.cfg:4:" -- "$MICA" mls $D/syntax_error.cfg -o "$work/x"
expect_failure 2 "count_mismatch.cfg:4: particles.count needs 2 entries" -- "$MICA" mls $D/count_mismatch.cfg -o "$work/x"
expect_failure 2 "--set mls.weight=cubik" -- "$MICA" mls $D/small.cfg -o "$work/x" --set mls.weight=cubik
expect_failure 2 "--set mls.ordre=2" -- "$MICA" mls $D/small.cfg -o "$work/x" --set mls.ordre=2
expect_failure 2 "no_such_deck.cfg" -- "$MICA" mls $D/no_such_deck.cfg -o "$work/x"
expect_failure 2 "unknown command" -- "$MICA" mlss $D/small.cfg
[ ! -e "$work/x" ] || fail "a deck error created the output directory $work/x"
ok "no output for bad decks"

# An earlier result survives failed runs (a bad override; a radius too small for the basis, which is bad
# input too: exit 2), byte for byte, and no staging directory is left behind.
"$MICA" mls $D/small.cfg -o "$work/keep" > /dev/null || fail "the small deck does not run"
before=$(cat "$work/keep/summary.json" "$work/keep/mls.csv" | cksum)
expect_failure 2 "--set mls.order=9" -- "$MICA" mls $D/small.cfg -o "$work/keep" --set mls.order=9
expect_failure 2 "supporting particles" -- "$MICA" mls $D/small.cfg -o "$work/keep" --set mls.dilation=1.01
after=$(cat "$work/keep/summary.json" "$work/keep/mls.csv" | cksum)
[ "$before" = "$after" ] || fail "a failed run changed the earlier results"
[ -z "$(ls -A "$work/keep" | grep staging)" ] || fail "a failed run left its staging directory"
ok "earlier results intact after failed runs"

# a sample line outside the box is a deck error (2), not a numerical failure
expect_failure 2 '--set sample.line.to=["3","1"]: sample.line.to lies outside the box' -- "$MICA" mls $D/small.cfg -o "$work/y" --set 'sample.line.to=["3","1"]'
