# Helpers for the command-line tests: each test script sources this, runs bin/mica, and exits non-zero
# with a message on the first failed check.
set -u
: "${MICA_BIN:=bin/mica}" "${OUT_DIR:=build/test-out}"
MICA="$PWD/$MICA_BIN"
[ -x "$MICA" ] || MICA="$MICA_BIN"
export OMPI_MCA_plm_rsh_agent=false

fail() { echo "FAIL: $*" >&2; exit 1; }
ok() { echo "ok: $*"; }

# All values of "key" in a summary.json, in file order (our writer puts one member per line).
json_values() { sed -n "s/^ *\"$1\": *\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2"; }
json_value() { json_values "$1" "$2" | head -n 1; }

# expect_failure STATUS PATTERN -- command...: runs it, checks the exit status and that stderr matches.
expect_failure() {
  local status=$1 pattern=$2; shift 3
  local err rc
  err=$("$@" 2>&1 >/dev/null); rc=$?
  [ "$rc" -eq "$status" ] || fail "'$*' exited $rc, expected $status; stderr: $err"
  grep -qF -- "$pattern" <<<"$err" || fail "'$*' stderr lacks '$pattern': $err"
  ok "exit $status with '$pattern'"
}

# less_than A B: floating-point A < B
less_than() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a + 0 < b + 0) }'; }
