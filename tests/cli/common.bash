# Helpers for the command-line tests: each test script sources this, runs bin/mica, and exits non-zero
# with a message on the first failed check.
set -u
: "${MICA_BIN:=bin/mica}" "${OUT_DIR:=build/test-out}"
MICA="$PWD/$MICA_BIN"
[ -x "$MICA" ] || MICA="$MICA_BIN"
export OMPI_MCA_plm_rsh_agent=false

fail() { echo "FAIL: $*" >&2; exit 1; }

# mpi_leak_checks: call after MPIRUN=(... mpirun ...). Under SAN=1, runs under mpirun keep their leak check,
# with the slow unwinder for the ranks only (mpirun -x): OpenMPI has no frame pointers, so the fast one stops
# inside a plugin unloaded by exit and tests/lsan.supp could name nothing; the full stack reaches
# ompi_mpi_init (the file's comments say why each entry is there). Slow (about 3x): the ranks only.
mpi_leak_checks() {
  [ "${SAN:-}" = 1 ] || return 0
  MPIRUN+=(-x "LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/lsan.supp:print_suppressions=0}:fast_unwind_on_malloc=0")
}
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

# run_deck DIR DECK [--set ...]: mica run quietly into DIR (fails the test if mica fails)
run_deck() {
  local dir=$1 deck=$2; shift 2
  "$MICA" run "$deck" -o "$dir" --set output.monitor=false --set output.vtu=false "$@" > "$dir.log" 2>&1 \
    || fail "mica run $deck $* failed: $(tail -n 3 "$dir.log")"
}
# Least-squares slope of log(error) against log(1/h) for "h error" pairs on stdin (the convergence rate).
ls_rate() { awk '{ x = log($1); y = log($2); n++; sx += x; sy += y; sxx += x*x; sxy += x*y }
                 END { printf "%.3f", (n*sxy - sx*sy) / (n*sxx - sx*sx) }'; }
# within VALUE REFERENCE RELTOL WHAT
within() {
  awk -v v="$1" -v r="$2" -v t="$3" 'BEGIN { d = (v - r) / r; if (d < 0) d = -d; exit !(d <= t) }' \
    || fail "$4: $1 is not within $3 (relative) of $2"
  ok "$4: $1 within $3 of $2"
}
# at_most VALUE MAX WHAT
at_most() {
  awk -v v="$1" -v m="$2" 'BEGIN { exit !(v <= m) }' || fail "$3: $1 > $2"
  ok "$3: $1 <= $2"
}
# at_least VALUE MIN WHAT
at_least() {
  awk -v v="$1" -v m="$2" 'BEGIN { exit !(v >= m) }' || fail "$3: $1 < $2"
  ok "$3: $1 >= $2"
}
