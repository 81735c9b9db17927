# The suite's leak checking is live (hardening issue 17, item 9): under SAN=1, a tiny program built like
# mica (mpicc, the SAN flags, linked with build-san/lib/libmica.a) that initializes MPI as mica does and then
# leaks 4242 bytes on purpose must be reported by LeakSanitizer, with its own frame, under exactly the
# LSAN_OPTIONS / ASAN_OPTIONS the suite runs with (tests/run.sh) and its suppression file (tests/lsan.supp,
# which must hide only OpenMPI's own allocations, never a leak of ours made after MPI_Init). Without SAN the
# binaries are not instrumented and there is nothing to check: the test says so and passes.
source "$(dirname "$0")/common.bash"
if [ "${SAN:-}" != 1 ]; then
  echo "SKIPPED: SAN is not 1, so LeakSanitizer is not built in (run make test SAN=1)"
  exit 0
fi
work="$OUT_DIR/lsan_active"
rm -rf "$work" && mkdir -p "$work"
lib="$(dirname "$(dirname "$MICA")")/lib/libmica.a"
[ -f "$lib" ] || fail "no $lib next to $MICA (SAN=1 builds build-san/lib/libmica.a)"
# the suite's settings (tests/run.sh exports them; set here too when the script runs alone)
: "${LSAN_OPTIONS:=suppressions=$PWD/tests/lsan.supp:print_suppressions=0}"
: "${ASAN_OPTIONS:=detect_leaks=1:abort_on_error=0}"
export LSAN_OPTIONS ASAN_OPTIONS
grep -q 'suppressions=' <<<"$LSAN_OPTIONS" || fail "LSAN_OPTIONS has no suppression file: $LSAN_OPTIONS"

cat > "$work/leak.c" <<'EOF'
#include <stdlib.h>
#include <string.h>
#include <mpi.h>
/* Holds the block until exit, then drops it: the pointer is gone, so LeakSanitizer must see a leak. */
static void *volatile kept;
static void leak_on_purpose(void) {
  kept = malloc(4242);
  memset(kept, 1, 4242);
  kept = NULL;
}
int main(int argc, char **argv) {
  MPI_Init(&argc, &argv); /* OpenMPI's one-time allocations: the suppressions' business */
  leak_on_purpose();
  MPI_Finalize();
  return 0;
}
EOF
sanflags=(-fsanitize=address,undefined -fno-sanitize-recover=undefined -O1 -g -fno-omit-frame-pointer)
mpicc -Iinclude "${sanflags[@]}" "$work/leak.c" "$lib" -lmetis -lconfig -lmatheval -lcholmod -lumfpack \
  -lsuitesparseconfig -llapacke -llapack -lblas -lm -o "$work/leak" > "$work/build.log" 2>&1 \
  || fail "cannot build the leaking program: $(tail -n 5 "$work/build.log")"
"$work/leak" > "$work/leak.out" 2> "$work/leak.err"; rc=$?
[ "$rc" -ne 0 ] || fail "the program that leaks exited 0: leak checking is off (ASAN_OPTIONS=$ASAN_OPTIONS)"
grep -q "ERROR: LeakSanitizer: detected memory leaks" "$work/leak.err" \
  || fail "LeakSanitizer did not report the leak (exit $rc): $(head -n 5 "$work/leak.err")"
grep -q "Direct leak of 4242 byte(s) in 1 object(s)" "$work/leak.err" \
  || fail "the report lacks the 4242-byte leak: $(grep -m 3 'leak of' "$work/leak.err")"
grep -A 4 "Direct leak of 4242" "$work/leak.err" | grep -q "leak_on_purpose" \
  || fail "the 4242-byte leak is not traced to leak_on_purpose: $(grep -A 4 'Direct leak of 4242' "$work/leak.err")"
ok "LeakSanitizer reports the 4242-byte leak after MPI_Init (exit $rc), traced to leak_on_purpose, suppressions on"
# mica itself, serially, under the same settings: no leak report (the suppressions hide OpenMPI's, none of ours)
"$MICA" run tests/decks/solid/base.cfg -o "$work/run" --set output.monitor=false > "$work/run.log" 2>&1 \
  || fail "mica run under LeakSanitizer failed: $(grep -m 3 -A 6 'ERROR' "$work/run.log")"
ok "mica run is leak-free under the same settings"
# Under mpirun, as the MPI tests run (mpi_leak_checks: the slow unwinder): each of 2 ranks reports its leak.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
MPIRUN=(timeout 300 mpirun --oversubscribe -np 2)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
mpi_leak_checks # under SAN=1: the ranks leak-checked with the slow unwinder (common.bash)
if ! out=$("${MPIRUN[@]}" "$MICA" --version 2>&1) || ! grep -q '^mica ' <<<"$out"; then
  echo "SKIPPED: mpirun cannot start 2 processes here, so leak checks under mpirun are untested: $out"
  exit 0
fi
"${MPIRUN[@]}" "$work/leak" > "$work/mpi.out" 2> "$work/mpi.err"
reports=$(cat "$work/mpi.out" "$work/mpi.err" | grep -c "Direct leak of 4242 byte(s)")
others=$(cat "$work/mpi.out" "$work/mpi.err" | grep "leak of" | grep -vc "of 4242 byte(s)")
[ "$reports" -eq 2 ] || fail "mpirun -np 2: $reports reports of the 4242-byte leak, expected one per rank"
[ "$others" -eq 0 ] || fail "mpirun -np 2: $others leak reports besides ours (OpenMPI's, unsuppressed): $(grep -m 1 -A 8 'leak of' "$work/mpi.err")"
ok "mpirun -np 2: each rank's 4242-byte leak reported, nothing of OpenMPI's"
"${MPIRUN[@]}" "$MICA" run tests/decks/solid/base.cfg -o "$work/mpirun" --set output.monitor=false > "$work/mpirun.log" 2>&1 \
  || fail "mpirun -np 2 mica run under LeakSanitizer failed: $(grep -m 1 -A 8 'ERROR' "$work/mpirun.log")"
ok "mpirun -np 2 mica run is leak-free under the same settings"
