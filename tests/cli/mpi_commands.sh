# Every command under mpirun (issue 6, item 4): `mica mls`, `mica sweep` and `mica study` with -np 2 give the
# serial numbers — MLS errors to 1e-12 relative (each rank evaluates, rank 0 writes), sweep probes and study
# error norms to 1e-9 relative (with ranks_per_point = 2 every point is a distributed run with MUMPS,
# which matches the serial factorization to 1e-10; groups of one rank per point: tests/cli/mpi_groups.sh) — and write their files once: the same set of files as the serial run,
# the closing line printed once, no rank's scratch directory left behind. `timeout` only keeps a hang from
# blocking the suite.
source "$(dirname "$0")/common.bash"
work="$(cd "$(dirname "$OUT_DIR")" 2>/dev/null && pwd)/$(basename "$OUT_DIR")/mpi_commands"
rm -rf "$work" && mkdir -p "$work/tmp"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export TMPDIR="$work/tmp"
MPIRUN=(timeout 300 mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
mpi_leak_checks # under SAN=1: the ranks leak-checked with the slow unwinder (common.bash)
if ! out=$("${MPIRUN[@]}" -np 2 "$MICA" --version 2>&1) || [ "$(grep -c '^mica ' <<<"$out")" -lt 1 ]; then
  echo "### SKIPPED: mpirun cannot start 2 processes here, so the commands under mpirun are untested ###"
  echo "### mpirun said: $out"
  exit 0
fi

# same_numbers A B TOL [ABS]: two lists of numbers (one per line) of equal length, equal within TOL relative
# (or within ABS absolute)
same_numbers() {
  paste -d' ' "$1" "$2" | awk -v t="$3" -v a="${4:-0}" '
    NF != 2 { bad = 1; exit }
    { d = $1 - $2; if (d < 0) d = -d; s = $1 < 0 ? -$1 : $1; if (d > t * s && d > a) { bad = 1; exit } ; n++ }
    END { exit bad || n == 0 }'
}
# column NAME CSV: the values of one named column, one per line (no quoted commas in these files' numbers)
column() { awk -F, -v name="$1" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next } { print $c }' "$2"; }
# once DIR LOG: the files of the parallel run are those of the serial one, and "results in" was printed once
once() {
  local serial=$1 parallel=$2 log=$3
  diff <(cd "$serial" && find . -type f | grep -v gnuplot.log | sort) \
       <(cd "$parallel" && find . -type f | grep -v gnuplot.log | sort) > /dev/null \
    || fail "$parallel: files differ from the serial run's"
  [ "$(grep -c '^results in' "$log")" -eq 1 ] || fail "$log: 'results in' printed $(grep -c '^results in' "$log") times"
}

# -- mls: two variants, 601 samples each, Hessians
"$MICA" mls input/mls_quickstart.cfg -o "$work/mls_1" > "$work/mls_1.log" 2>&1 || fail "serial mls failed"
"${MPIRUN[@]}" -np 2 "$MICA" mls input/mls_quickstart.cfg -o "$work/mls_2" > "$work/mls_2.log" 2>&1 \
  || fail "mls under mpirun failed: $(tail -n 3 "$work/mls_2.log")"
for key in err_f_max err_dx_max err_dxx_max volume_err_dxx_rms; do
  json_values "$key" "$work/mls_1/summary.json" > "$work/a" && json_values "$key" "$work/mls_2/summary.json" > "$work/b"
  same_numbers "$work/a" "$work/b" 1e-12 || fail "mls: $key differs under mpirun: $(paste -d' ' "$work/a" "$work/b")"
done
[ "$(json_value ranks "$work/mls_2/summary.json")" = 2 ] || fail "mls summary does not say ranks = 2"
once "$work/mls_1" "$work/mls_2" "$work/mls_2.log"
ok "mls -np 2: the serial errors to 1e-12, files written once"

# -- sweep: the cantilever over four lengths
"$MICA" sweep input/sweep_cantilever.cfg -o "$work/sweep_1" > "$work/sweep_1.log" 2>&1 || fail "serial sweep failed"
"${MPIRUN[@]}" -np 2 "$MICA" sweep input/sweep_cantilever.cfg -o "$work/sweep_2" --set sweep.ranks_per_point=2 \
  > "$work/sweep_2.log" 2>&1 \
  || fail "sweep under mpirun failed: $(tail -n 3 "$work/sweep_2.log")"
column tip_uy "$work/sweep_1/sweep.csv" > "$work/a" && column tip_uy "$work/sweep_2/sweep.csv" > "$work/b"
same_numbers "$work/a" "$work/b" 1e-9 || fail "sweep: tip_uy differs under mpirun: $(paste -d' ' "$work/a" "$work/b")"
[ -n "$(json_value edge_cut "$work/sweep_2/points/1/summary.json")" ] || fail "sweep points did not run distributed"
[ "$(grep -c 'points ok' "$work/sweep_2.log")" -eq 1 ] || fail "sweep's closing line not printed once"
once "$work/sweep_1" "$work/sweep_2" "$work/sweep_2.log"
ok "sweep -np 2: tip_uy of every point to 1e-9 of the serial sweep, each point distributed, files once"

# -- study: linear and quadratic bases at three resolutions
"$MICA" study input/study_timoshenko.cfg -o "$work/study_1" > "$work/study_1.log" 2>&1 || fail "serial study failed"
"${MPIRUN[@]}" -np 2 "$MICA" study input/study_timoshenko.cfg -o "$work/study_2" --set study.ranks_per_point=2 \
  > "$work/study_2.log" 2>&1 \
  || fail "study under mpirun failed: $(tail -n 3 "$work/study_2.log")"
# The error norms are relative to the exact solution's norm, so by the triangle inequality they move by at most
# |u_parallel − u_serial| / |u|, about 1e-10: an absolute 1e-9 on them (a relative bound would demand more of
# an error of 1e-5 than of the solution it measures).
for key in error_l2 error_energy; do
  column "$key" "$work/study_1/study.csv" > "$work/a" && column "$key" "$work/study_2/study.csv" > "$work/b"
  same_numbers "$work/a" "$work/b" 0 1e-9 || fail "study: $key differs under mpirun: $(paste -d' ' "$work/a" "$work/b")"
done
column tip_uy "$work/study_1/study.csv" > "$work/a" && column tip_uy "$work/study_2/study.csv" > "$work/b"
same_numbers "$work/a" "$work/b" 1e-9 || fail "study: tip_uy differs under mpirun: $(paste -d' ' "$work/a" "$work/b")"
[ "$(json_value ranks "$work/study_2/summary.json")" = 2 ] || fail "study summary does not say ranks = 2"
once "$work/study_1" "$work/study_2" "$work/study_2.log"
ok "study -np 2: L2 and energy errors (absolute) and tip deflection (relative) of every combination to 1e-9, files once"

leftover=$(find "$work/tmp" -mindepth 1 -maxdepth 1 | head -n 3)
[ -z "$leftover" ] || fail "scratch left behind by the ranks: $leftover"
ok "no rank's scratch directory left behind"
