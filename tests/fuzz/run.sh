#!/bin/bash
# Runs each named libFuzzer harness ($FUZZ_OUT/fuzz_NAME, built by `make fuzz-build`) for FUZZ_SECONDS, all at
# once, one process each, and prints per harness: executions, exec/s (their mean, and the last job's), final cov
# and ft, corpus size, crashes, leaks, timeouts (hangs longer than FUZZ_TIMEOUT s) and OOMs (over FUZZ_RSS_MB).
# Called by `make fuzz`.
#
# Fork mode (-fork=1 with -ignore_*) goes on after a crash, so one run finds more than the first bug; each
# finding is saved as $FUZZ_OUT/artifacts/NAME/{crash,timeout,oom,leak}-SHA1 (reproduce: $FUZZ_OUT/fuzz_NAME
# FILE). The corpus grows in $FUZZ_OUT/corpus/NAME, seeded from tests/fuzz/corpus/NAME (never written).
# Exit status: 1 if any harness found anything.
set -u
out=${FUZZ_OUT:-build-fuzz}
seconds=${FUZZ_SECONDS:-1800}
timeout=${FUZZ_TIMEOUT:-10}
rss=${FUZZ_RSS_MB:-2048}
here=$(cd "$(dirname "$0")" && pwd)

run_one() {
  local name=$1 dict=()
  [ -f "$here/$name.dict" ] && dict=(-dict="$here/$name.dict")
  mkdir -p "$out/corpus/$name" "$out/artifacts/$name"
  # the suite's suppressions (tests/lsan.supp: libmatheval's parser on a malformed expression, OpenMPI)
  LSAN_OPTIONS="suppressions=$here/../lsan.supp:print_suppressions=0" \
    nice -n 10 "$out/fuzz_$name" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb="$rss" -print_final_stats=1 \
    -artifact_prefix="$out/artifacts/$name/" "${dict[@]}" "$out/corpus/$name" "$here/corpus/$name" \
    >"$out/$name.log" 2>&1
}

# The last fork-mode status line: "#EXECS: cov: C ft: F corp: N exec/s R oom/timeout/crash: O/T/X time: Ss".
summarize() {
  local name=$1 line
  line=$(grep -E '^#[0-9]+: cov: ' "$out/$name.log" | tail -n 1)
  local execs cov ft corp rate time
  execs=$(sed -E 's/^#([0-9]+):.*/\1/' <<<"$line")
  cov=$(sed -E 's/.* cov: ([0-9]+).*/\1/' <<<"$line")
  ft=$(sed -E 's/.* ft: ([0-9]+).*/\1/' <<<"$line")
  corp=$(sed -E 's/.* corp: ([0-9]+).*/\1/' <<<"$line")
  rate=$(sed -E 's/.* exec\/s:? ([0-9]+).*/\1/' <<<"$line")
  time=$(sed -E 's/.* time: ([0-9]+)s.*/\1/' <<<"$line")
  local crashes timeouts ooms leaks
  crashes=$(find "$out/artifacts/$name" -name 'crash-*' | wc -l)
  leaks=$(find "$out/artifacts/$name" -name 'leak-*' | wc -l)
  timeouts=$(find "$out/artifacts/$name" -name 'timeout-*' | wc -l)
  ooms=$(find "$out/artifacts/$name" -name 'oom-*' | wc -l)
  local mean=?
  [ -n "$execs" ] && [ "${time:-0}" -gt 0 ] && mean=$((execs / time))
  printf '%-5s %6ss  executions %10s  exec/s %6s (last job %s)  cov %5s  ft %6s  corpus %5s  crashes %s  leaks %s  timeouts %s  ooms %s\n' \
    "$name" "${time:-?}" "${execs:-?}" "$mean" "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" "$crashes" "$leaks" \
    "$timeouts" "$ooms"
  [ $((crashes + leaks + timeouts + ooms)) -eq 0 ]
}

echo "fuzzing $* for ${seconds}s each ($(${FUZZ_CC:-clang} --version | head -n 1)); logs in $out/NAME.log"
pids=()
for name in "$@"; do run_one "$name" & pids+=($!); done
for pid in "${pids[@]}"; do wait "$pid"; done
status=0
for name in "$@"; do summarize "$name" || status=1; done
[ $status -eq 0 ] || echo "findings in $out/artifacts/: reproduce with $out/fuzz_NAME FILE"
exit $status
