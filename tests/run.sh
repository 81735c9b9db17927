#!/usr/bin/env bash
# Runs every unit test executable and every CLI/verification script, MICA_TEST_JOBS at a time (default: the
# cores), and prints one line per test as it ends (PASS/FAIL, its wall seconds), the slowest, and one closing line
# "tests: N passed, N failed". Called by `make test` with MICA_BIN, TEST_DIR, OUT_DIR (and SAN) set.
# Each test owns $OUT_DIR/<name>/ (and its log $OUT_DIR/<name>.log), so tests can run side by side; no check
# depends on time. The suite is mostly one process per run, so two at a time on two cores nearly halve its wall
# time, which `.ci/run` (make test, then make test SAN=1) needs to stay inside CI's limit.
set -u
cd "$(dirname "$0")/.."
: "${MICA_BIN:=bin/mica}" "${TEST_DIR:=build/tests}" "${OUT_DIR:=build/test-out}"
: "${MICA_TEST_JOBS:=$(nproc 2> /dev/null || echo 1)}"
export MICA_BIN OUT_DIR
[ -z "${MICA_EXT_BIN:-}" ] || export MICA_EXT_BIN
# OpenMPI's own one-time allocations are not ours to fix (tests/lsan.supp says which and why, and the MPI
# tests add the slow unwinder its entries need); everything else must be leak-free (tests/cli/lsan_active.sh
# proves the check is live).
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export OMPI_MCA_plm_rsh_agent=false OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Side by side, one BLAS thread a process: OpenBLAS's threads spin while they wait, so two runs of two threads each on
# two cores took twice their time alone (vci_rates 387 s alone, over 1100 s beside mpi_distributed).
if [ "$MICA_TEST_JOBS" -gt 1 ]; then export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1; fi
mkdir -p "$OUT_DIR"

# The longest first (minutes on the 2-core machine, 2026-12-07: vci_rates 6.5, mpi_distributed 5, nsni 2, petsc,
# publish and incompressible 1.2 each), so that no core is left alone with one of them at the end. Only the order:
# every test runs; the closing lines name the slowest, to keep this list right.
first="vci_rates mpi_distributed vci_rates_cosserat3d nsni petsc publish incompressible mpi mpi_groups deck_references"

# run_test PATH: runs one unit executable (build/tests/test_*) or script (tests/cli/*.sh), its output into
# $OUT_DIR/NAME.log; writes "STATUS SECONDS" to $OUT_DIR/NAME.status
run_test() {
  local path=$1 name start rc
  name=$(basename "$path" .sh)
  start=$(date +%s.%N)
  case "$path" in
    *.sh) bash "$path" > "$OUT_DIR/$name.log" 2>&1 ;;
    # test_linear starts PETSc, hence MPI: OpenMPI's one-time allocations need the slow unwinder to match
    # tests/lsan.supp, as under mpirun (mpi_leak_checks, tests/cli/common.bash)
    */test_linear) LSAN_OPTIONS="$LSAN_OPTIONS:fast_unwind_on_malloc=0" "$path" > "$OUT_DIR/$name.log" 2>&1 ;;
    *) "$path" > "$OUT_DIR/$name.log" 2>&1 ;;
  esac
  rc=$?
  echo "$rc $(awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN { printf "%.0f", e - s }')" > "$OUT_DIR/$name.status"
}

tests=()
for name in $first; do [ -f "tests/cli/$name.sh" ] && tests+=("tests/cli/$name.sh"); done
for t in "$TEST_DIR"/test_*; do [ -x "$t" ] && tests+=("$t"); done
for s in tests/cli/*.sh; do
  case " $first " in *" $(basename "$s" .sh) "*) continue ;; esac
  tests+=("$s")
done

passed=0 failed=0 failures=() times=()
declare -A running=() # pid -> test name
# report: waits for one test to end and prints its line (its log's last lines if it failed)
report() {
  local pid name status seconds
  wait -n -p pid
  name=${running[$pid]}
  unset "running[$pid]"
  read -r status seconds < "$OUT_DIR/$name.status" || { status=1 seconds=?; }
  times+=("$seconds $name")
  if [ "$status" = 0 ]; then
    passed=$((passed + 1)); printf 'PASS  %-28s %5s s\n' "$name" "$seconds"
  else
    failed=$((failed + 1)); failures+=("$name")
    printf 'FAIL  %-28s %5s s (log: %s)\n' "$name" "$seconds" "$OUT_DIR/$name.log"
    tail -n 30 "$OUT_DIR/$name.log" | sed 's/^/      /'
  fi
}
start=$(date +%s)
for t in "${tests[@]}"; do
  while [ "${#running[@]}" -ge "$MICA_TEST_JOBS" ]; do report; done
  name=$(basename "$t" .sh)
  rm -f "$OUT_DIR/$name.status"
  run_test "$t" &
  running[$!]=$name
done
while [ "${#running[@]}" -gt 0 ]; do report; done
echo
echo "slowest (s): $(printf '%s\n' "${times[@]}" | sort -rn | head -n 6 | awk '{ printf "%s %s  ", $2, $1 }')"
echo "wall: $(($(date +%s) - start)) s with $MICA_TEST_JOBS at a time"
[ "$failed" -eq 0 ] || echo "failed: ${failures[*]}"
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
