# Sweeps and studies on groups of ranks (issue 19, items 4 and 5): `mpirun -np P mica sweep|study` deals the
# points to P / ranks_per_point groups (point i to group i mod groups) and gathers the table on rank 0.
#  - one rank per point (the default), -np 2 and -np 3 (oversubscribed): each point IS the serial run (a group
#    of one rank takes the serial path), so every probe, error norm and count in sweep.csv / study.csv is
#    bit-identical to the serial table (one BLAS thread everywhere: CHOLMOD's BLAS may otherwise take another
#    thread count under mpirun's binding, which moves the last bits); each point is solved by exactly one
#    group: its summary names group (i-1) mod G + 1, the summary counts the points per group, the log has one
#    line per point naming that group; the same files as the serial run, the closing line once;
#  - ranks_per_point = 2 with -np 2: every point distributed (its summary has the partition's edge cut), the
#    serial probes to 1e-9 relative (MUMPS matches the serial factorization to 1e-10);
#  - a failing point (dilation 0.5: a singular moment matrix) is recorded as an error with its message, as
#    serially, and the other groups' points succeed; a failure injected in the points of rank 1 fails exactly
#    those points; a crash of rank 1 (exit without MPI_Finalize) ends the job with a non-zero status, before
#    `timeout` kills it; a bad ranks_per_point exits 2 on every rank with one message naming the deck line;
#  - no rank's scratch directory and no staging directory left behind (but that of a rank that crashed: it
#    never ran its cleanup).
# `timeout` only keeps a hang from blocking the suite: no check depends on time.
source "$(dirname "$0")/common.bash"
work="$(cd "$(dirname "$OUT_DIR")" 2>/dev/null && pwd)/$(basename "$OUT_DIR")/mpi_groups"
rm -rf "$work" && mkdir -p "$work/tmp"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export TMPDIR="$work/tmp" OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
MPIRUN=(timeout 300 mpirun --oversubscribe -x OPENBLAS_NUM_THREADS -x OMP_NUM_THREADS)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
mpi_leak_checks # under SAN=1: the ranks leak-checked with the slow unwinder (common.bash)
if ! out=$("${MPIRUN[@]}" -np 2 "$MICA" --version 2>&1) || [ "$(grep -c '^mica ' <<<"$out")" -lt 1 ]; then
  echo "### SKIPPED: mpirun cannot start 2 processes here, so groups of ranks are untested ###"
  echo "### mpirun said: $out"
  exit 0
fi

# column NAME CSV: the values of one named column, one per line (these files' numbers hold no quoted commas)
column() { awk -F, -v name="$1" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next } { print $c }' "$2"; }
# identical NAME A B: the column is the same text in both tables (numbers printed with %.17g: bit-identical)
identical() {
  diff <(column "$1" "$2") <(column "$1" "$3") > /dev/null || fail "$3: column $1 differs from $2: $(column "$1" "$3" | tr '\n' ' ') vs $(column "$1" "$2" | tr '\n' ' ')"
  [ -n "$(column "$1" "$2" | head -n 1)" ] || fail "$2 has no column $1"
}
# same_numbers A B TOL: two lists of numbers (one per line) of equal length, equal within TOL relative
same_numbers() {
  paste -d' ' "$1" "$2" | awk -v t="$3" '
    NF != 2 { bad = 1; exit }
    { d = $1 - $2; if (d < 0) d = -d; s = $1 < 0 ? -$1 : $1; if (d > t * s) { bad = 1; exit } ; n++ }
    END { exit bad || n == 0 }'
}
# same_files SERIAL PARALLEL LOG: the files of the serial run, and "results in" printed once
same_files() {
  diff <(cd "$1" && find . -type f | grep -v gnuplot.log | sort) <(cd "$2" && find . -type f | grep -v gnuplot.log | sort) \
    > /dev/null || fail "$2: files differ from the serial run's"
  [ "$(grep -c '^results in' "$3")" -eq 1 ] || fail "$3: 'results in' printed $(grep -c '^results in' "$3") times"
}
# dealt DIR LOG WORD N G KEY: each of the N points (WORD: point, combination) solved by group (i-1) mod G + 1:
# its summary says so, the log has exactly one line for it naming that group, and the summary's KEY array counts
dealt() {
  local dir=$1 log=$2 word=$3 n=$4 g=$5 key=$6 i
  for i in $(seq 1 "$n"); do
    local want=$(( (i - 1) % g + 1 ))
    [ "$(json_value group "$dir/points/$i/summary.json")" = $want ] \
      || fail "$dir: $word $i solved by group $(json_value group "$dir/points/$i/summary.json"), expected $want"
    [ "$(grep -c "^$word $i/$n " "$log")" -eq 1 ] || fail "$log: not one line for $word $i"
    grep "^$word $i/$n " "$log" | grep -q "(group $want of $g)" || fail "$log: $word $i's line does not name group $want"
  done
  local counts expected=""
  counts=$(sed -n "/\"$key\"/,/]/p" "$dir/summary.json" | grep -o '^ *[0-9]*,\{0,1\}$' | tr -d ' ,' | tr '\n' ' ')
  for i in $(seq 1 "$g"); do expected+="$(( (n - i) / g + 1 )) "; done
  [ "$counts" = "$expected" ] || fail "$dir/summary.json: $key is '$counts', expected '$expected'"
}

# ---- sweep: the cantilever over four lengths, serially and on groups of one rank ----------------------------
sweep=input/sweep_cantilever.cfg
"$MICA" sweep $sweep -o "$work/sweep_1" > "$work/sweep_1.log" 2>&1 || fail "serial sweep failed"
for np in 2 3; do
  d="$work/sweep_np$np"
  "${MPIRUN[@]}" -np $np "$MICA" sweep $sweep -o "$d" > "$d.log" 2>&1 || fail "sweep -np $np failed: $(tail -n 3 "$d.log")"
  for c in index parameters.L tip_uy root_sxx status; do identical $c "$work/sweep_1/sweep.csv" "$d/sweep.csv"; done
  [ -z "$(json_value edge_cut "$d/points/1/summary.json")" ] || fail "sweep -np $np: a point of a one-rank group was partitioned"
  [ "$(json_value groups "$d/summary.json")" = $np ] || fail "sweep -np $np: summary does not say $np groups"
  dealt "$d" "$d.log" point 4 $np points_per_group
  same_files "$work/sweep_1" "$d" "$d.log"
  ok "sweep -np $np, one rank per point: every probe bit-identical to the serial sweep, point i by group (i-1) mod $np + 1, files once"
done

# ranks_per_point = 2 on 2 ranks: one group, every point distributed
d="$work/sweep_rpp2"
"${MPIRUN[@]}" -np 2 "$MICA" sweep $sweep -o "$d" --set sweep.ranks_per_point=2 > "$d.log" 2>&1 \
  || fail "sweep -np 2 ranks_per_point=2 failed: $(tail -n 3 "$d.log")"
for c in tip_uy root_sxx; do
  column $c "$work/sweep_1/sweep.csv" > "$work/a" && column $c "$d/sweep.csv" > "$work/b"
  same_numbers "$work/a" "$work/b" 1e-9 || fail "sweep ranks_per_point=2: $c differs: $(paste -d' ' "$work/a" "$work/b")"
done
for i in 1 2 3 4; do
  [ -n "$(json_value edge_cut "$d/points/$i/summary.json")" ] || fail "ranks_per_point=2: point $i did not run distributed"
  [ "$(json_value group_ranks "$d/points/$i/summary.json")" = 2 ] || fail "ranks_per_point=2: point $i's group is not 2 ranks"
done
same_files "$work/sweep_1" "$d" "$d.log"
ok "sweep -np 2, ranks_per_point = 2: every point distributed over both ranks, probes to 1e-9 of the serial sweep"

# ---- study: two bases at three resolutions --------------------------------------------------------------------
study=input/study_timoshenko.cfg
"$MICA" study $study -o "$work/study_1" > "$work/study_1.log" 2>&1 || fail "serial study failed"
for np in 2 3; do
  d="$work/study_np$np"
  "${MPIRUN[@]}" -np $np "$MICA" study $study -o "$d" > "$d.log" 2>&1 || fail "study -np $np failed: $(tail -n 3 "$d.log")"
  for c in index status dofs nnz nnz_factor cache_bytes error_l2 error_h1 error_energy tip_uy error; do
    identical $c "$work/study_1/study.csv" "$d/study.csv"
  done
  dealt "$d" "$d.log" combination 6 $np combinations_per_group
  same_files "$work/study_1" "$d" "$d.log"
  ok "study -np $np, one rank per combination: error norms, probe and counts bit-identical to the serial study, dealt round robin"
done
d="$work/study_rpp2"
"${MPIRUN[@]}" -np 2 "$MICA" study $study -o "$d" --set study.ranks_per_point=2 > "$d.log" 2>&1 \
  || fail "study -np 2 ranks_per_point=2 failed: $(tail -n 3 "$d.log")"
column tip_uy "$work/study_1/study.csv" > "$work/a" && column tip_uy "$d/study.csv" > "$work/b"
same_numbers "$work/a" "$work/b" 1e-9 || fail "study ranks_per_point=2: tip_uy differs: $(paste -d' ' "$work/a" "$work/b")"
[ -n "$(json_value edge_cut "$d/points/6/summary.json")" ] || fail "study ranks_per_point=2: combination 6 not distributed"
ok "study -np 2, ranks_per_point = 2: combinations distributed, tip_uy to 1e-9 of the serial study"

# ---- a failing point: dilation 0.5 leaves a singular moment matrix ----------------------------------------------
sed 's/^sweep = {$/sweep = { mode = "zip";/; s/parameters = ( { path = "parameters.L"; values = \[4.0, 8.0, 16.0, 32.0\]; } );/parameters = ( { path = "parameters.L"; values = [4.0, 8.0, 16.0, 32.0]; }, { path = "mls.dilation"; values = [3.0, 0.5, 3.0, 3.0]; } );/' \
  $sweep > "$work/failing.cfg"
grep -q 'values = \[3.0, 0.5' "$work/failing.cfg" || fail "could not write the failing deck"
"$MICA" sweep "$work/failing.cfg" -o "$work/failing_1" > "$work/failing_1.log" 2>&1 || fail "serial failing sweep failed"
[ "$(column status "$work/failing_1/sweep.csv" | tr '\n' ' ')" = "ok error ok ok " ] \
  || fail "serial failing sweep: statuses $(column status "$work/failing_1/sweep.csv" | tr '\n' ' ')"
for run in "2 1" "3 1" "2 2"; do
  set -- $run
  d="$work/failing_np$1_rpp$2"
  "${MPIRUN[@]}" -np $1 "$MICA" sweep "$work/failing.cfg" -o "$d" --set sweep.ranks_per_point=$2 > "$d.log" 2>&1 \
    || fail "failing sweep -np $1 ranks_per_point=$2 failed: $(tail -n 3 "$d.log")"
  identical status "$work/failing_1/sweep.csv" "$d/sweep.csv"
  [ "$2" = 2 ] || identical tip_uy "$work/failing_1/sweep.csv" "$d/sweep.csv"
  awk -F, '$1 == 2' "$d/sweep.csv" | grep -q ',error,".*singular' || fail "$d: point 2 not recorded with its message: $(cat "$d/sweep.csv")"
  [ "$(json_value status "$d/points/2/summary.json")" = error ] || fail "$d: points/2/summary.json does not say error"
  [ "$(json_value points_failed "$d/summary.json")" = 1 ] || fail "$d: points_failed is not 1"
  grep -q "3 of 4 points ok, 1 failed" "$d.log" || fail "$d: the closing line does not count the failure"
  ok "a failing point on -np $1, ranks_per_point = $2: recorded as serially (error, message), the other points ok"
done

# a failure injected at the start of every point rank 1 solves: exactly its points (2 and 4) fail
d="$work/inject_point"
MICA_INJECT_FAILURE=1:point "${MPIRUN[@]}" -np 2 "$MICA" sweep $sweep -o "$d" > "$d.log" 2>&1 \
  || fail "a sweep with points failing on rank 1 failed: $(tail -n 3 "$d.log")"
[ "$(column status "$d/sweep.csv" | tr '\n' ' ')" = "ok error ok error " ] || fail "injected point failures: $(cat "$d/sweep.csv")"
grep -q 'failure injected at phase .point.' "$d/points/2/summary.json" || fail "points/2/summary.json lacks the injected message"
[ "$(column tip_uy "$d/sweep.csv" | sed -n '1p;3p' | tr '\n' ' ')" = "$(column tip_uy "$work/sweep_1/sweep.csv" | sed -n '1p;3p' | tr '\n' ' ')" ] \
  || fail "injected point failures: group 1's points do not have the serial probes"
ok "failures injected in rank 1's points: those points recorded as errors, group 1's points as serially"

# a crash of rank 1 in its first point ends every rank (mpirun ends the job when a process exits without
# MPI_Finalize: SIGTERM to the others, SIGKILL odls_base_sigkill_timeout seconds later), with a non-zero status,
# before timeout's 300 s. The survivors remove their directories on SIGTERM; mpirun's default second before
# SIGKILL was too short for that on this loaded machine (rank 0's staging directory stayed in 4 of 10 crashes
# with the 2 cores oversubscribed fivefold), so the test gives them 5 s (mpirun then waits them out).
for command in "sweep $sweep" "study $study"; do
  set -- $command
  d="$work/crash_$1"
  MICA_INJECT_FAILURE=1:point:exit "${MPIRUN[@]}" --mca odls_base_sigkill_timeout 5 -np 3 "$MICA" $1 $2 -o "$d" \
    > "$d.out" 2> "$d.err"
  rc=$?
  [ $rc -ne 0 ] || fail "$1: a crash of rank 1: exit status 0"
  [ $rc -ne 124 ] || fail "$1: a crash of rank 1: the job hung (killed by timeout)"
  [ "$(grep -c 'rank 1: MICA_INJECT_FAILURE=1:point:exit' "$d.err")" -eq 1 ] || fail "$1: crash not reported once: $(cat "$d.err")"
  [ ! -e "$d" ] || fail "$1: a crashed job published $d"
  [ -z "$(ls -A "$work" | grep staging)" ] || fail "$1: a staging directory was left behind: $(ls -A "$work")"
  leftover=$(ls -A "$work/tmp" | grep -v '^mica-rank1-' | head -n 3)
  [ -z "$leftover" ] || fail "$1: scratch of ranks other than the crashed one left behind: $leftover"
  rm -rf "$work"/tmp/mica-rank1-* # the crashed rank never ran its cleanup
  ok "$1 -np 3: a crash of rank 1 ends the job (exit $rc), reported once, nothing published, no other rank's files"
done

# ---- bad ranks_per_point: exit 2 on every rank, one message with the deck line -----------------------------------
sed 's/^sweep = {$/sweep = { ranks_per_point = 2;/' $sweep > "$work/rpp.cfg"
line=$(grep -n 'ranks_per_point = 2' "$work/rpp.cfg" | cut -d: -f1)
[ -n "$line" ] || fail "could not write the ranks_per_point deck"
"${MPIRUN[@]}" -np 3 "$MICA" sweep "$work/rpp.cfg" -o "$work/rpp" > "$work/rpp.out" 2> "$work/rpp.err"
rc=$?
[ $rc -eq 2 ] || fail "ranks_per_point = 2 on 3 ranks: exit $rc, expected 2: $(cat "$work/rpp.err")"
[ "$(grep -c "rpp.cfg:$line: sweep.ranks_per_point = 2 does not divide the 3 ranks" "$work/rpp.err")" -eq 1 ] \
  || fail "ranks_per_point = 2 on 3 ranks: not one message with the line: $(cat "$work/rpp.err")"
"${MPIRUN[@]}" -np 2 "$MICA" study $study -o "$work/rpp_study" --set study.ranks_per_point=3 > /dev/null 2> "$work/rpp_study.err"
rc=$?
[ $rc -eq 2 ] || fail "study.ranks_per_point = 3 on 2 ranks: exit $rc: $(cat "$work/rpp_study.err")"
[ "$(grep -c 'study.ranks_per_point = 3: more ranks than the run has (2)' "$work/rpp_study.err")" -eq 1 ] \
  || fail "study.ranks_per_point = 3 on 2 ranks: not one message: $(cat "$work/rpp_study.err")"
expect_failure 2 "rpp.cfg:$line: sweep.ranks_per_point = 2: more ranks than the run has (1: a serial run" -- \
  "$MICA" sweep "$work/rpp.cfg" -o "$work/rpp_serial"
[ ! -e "$work/rpp" ] && [ ! -e "$work/rpp_study" ] && [ ! -e "$work/rpp_serial" ] || fail "a refused deck left results"
ok "ranks_per_point not dividing or exceeding the ranks: exit 2, one message with the deck line, no results"

leftover=$(find "$work/tmp" -mindepth 1 -maxdepth 1 | head -n 3)
[ -z "$leftover" ] || fail "scratch left behind by the ranks: $leftover"
[ -z "$(find "$work" -maxdepth 1 -name '*staging*' | head -n 1)" ] || fail "a staging directory was left behind"
ok "no rank's scratch directory, no staging directory left behind"
