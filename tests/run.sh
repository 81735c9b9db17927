#!/usr/bin/env bash
# Runs every unit test executable and every CLI/verification script; prints one closing line
# "tests: N passed, N failed". Called by `make test` with MICA_BIN, TEST_DIR, OUT_DIR (and SAN) set.
set -u
cd "$(dirname "$0")/.."
: "${MICA_BIN:=bin/mica}" "${TEST_DIR:=build/tests}" "${OUT_DIR:=build/test-out}"
export MICA_BIN OUT_DIR
[ -z "${MICA_EXT_BIN:-}" ] || export MICA_EXT_BIN
# OpenMPI's own one-time allocations are not ours to fix (tests/lsan.supp says which and why, and the MPI
# tests add the slow unwinder its entries need); everything else must be leak-free (tests/cli/lsan_active.sh
# proves the check is live).
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export OMPI_MCA_plm_rsh_agent=false OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$OUT_DIR"
passed=0 failed=0 failures=()
for t in "$TEST_DIR"/test_*; do
  [ -x "$t" ] || continue
  name=$(basename "$t")
  # test_linear starts PETSc, hence MPI: OpenMPI's one-time allocations need the slow unwinder to match
  # tests/lsan.supp, as under mpirun (mpi_leak_checks, tests/cli/common.bash)
  lsan=$LSAN_OPTIONS
  [ "$name" = test_linear ] && lsan="$LSAN_OPTIONS:fast_unwind_on_malloc=0"
  if LSAN_OPTIONS=$lsan "$t" > "$OUT_DIR/$name.log" 2>&1; then
    passed=$((passed + 1)); echo "PASS  $name"
  else
    failed=$((failed + 1)); failures+=("$name"); echo "FAIL  $name (log: $OUT_DIR/$name.log)"
    tail -n 30 "$OUT_DIR/$name.log" | sed 's/^/      /'
  fi
done
for s in tests/cli/*.sh; do
  [ -f "$s" ] || continue
  name=$(basename "$s" .sh)
  if bash "$s" > "$OUT_DIR/$name.log" 2>&1; then
    passed=$((passed + 1)); echo "PASS  $name"
  else
    failed=$((failed + 1)); failures+=("$name"); echo "FAIL  $name (log: $OUT_DIR/$name.log)"
    tail -n 30 "$OUT_DIR/$name.log" | sed 's/^/      /'
  fi
done
echo
[ "$failed" -eq 0 ] || echo "failed: ${failures[*]}"
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
