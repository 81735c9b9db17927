# A Newton solve that fails after its cut-backs writes what it reached (issue 17, item 7): exit 3 with the
# reason on stderr; in DIR the fields of the converged load steps only (solution.pvd lists them with their
# load factors) and summary.json with "status": "failed", "load_factor_reached", "load_factor_failed",
# "step_cuts" and "reason", replacing an earlier run's results whole; no NaN in any file. The reproducer is
# Cook's membrane with Neo-Hooke at F = 1000 N (input/cook_neohooke.cfg; 9 x 9 particles, 6 cut-backs of
# 12 iterations, so that it fails within seconds). References, independent of the failing run:
#   - load factors are k / (steps 2^cuts) = k / 640: the reached one is an integer over 640, the failed one the
#     next, and the last file of the PVD is the reached one;
#   - the last step's fields are the state at load factor t: a separate run to the load F t = 28.125 N in the
#     same increments (18 steps) has the same tip displacement u_y(48, 60) (probe tip_uy) to 1e-8 relative;
#   - no step converged (3 cut-backs): load factor 0, no field files.
# Then mpirun -np 2 (the same summary, the message once, files once), and a sweep and a study with such a
# point: the row says "failed", the point's summary keeps how far it got with exit_status 3.
source "$(dirname "$0")/common.bash"
work="$(cd "$(dirname "$OUT_DIR")" 2>/dev/null && pwd)/$(basename "$OUT_DIR")/newton_failure" # absolute: mpirun
rm -rf "$work" && mkdir -p "$work/tmp"
deck=input/cook_neohooke.cfg
small=(--set 'particles.count=[9,9]' --set solver.max_iterations=12 --set output.monitor=false)
failing=(--set parameters.F=1000 --set solver.max_cuts=6)
command -v python3 > /dev/null || fail "python3 is needed to read the VTU files back"
# json_get KEY FILE: a member of summary.json as python3 prints it (the reason holds commas and quotes)
json_get() {
  python3 -c 'import json, sys; print(json.load(open(sys.argv[2])).get(sys.argv[1], "(absent)"))' "$1" "$2"
}

# the checks on a failed run's directory: check_failed DIR EXPECTED_STEPS [RANKS] (under mpirun the steps' files
# are a piece per rank and a .pvtu, which the PVD lists: tests/cli/mpi_output.sh)
check_failed() {
  python3 - "$1" "$2" "${3:-1}" <<'PY' || fail "$1: the failed run's results (above)"
import json, math, os, re, sys
sys.path.insert(0, "tests/cli")
import vtu_readback as v  # read_vtu checks the block layout and that every value is finite
d, steps, ranks = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
ext = "pvtu" if ranks > 1 else "vtu"
def check(cond, what):
    if not cond:
        print("FAIL: " + what); sys.exit(1)
s = json.load(open(os.path.join(d, "summary.json")))
check(s["status"] == "failed", "status %r" % s["status"])
check(s["load_steps"] == steps, "load_steps %d, expected %d" % (s["load_steps"], steps))
check(s["step_cuts"] == 6 or steps == 0, "step_cuts %d, expected 6" % s["step_cuts"])
reached, failed = s["load_factor_reached"], s["load_factor_failed"]
den = 10 * 2 ** s["step_cuts"]
check(reached * den == steps, "load_factor_reached %.17g is not %d/%d" % (reached, steps, den))
check(abs(failed - (steps + 1) / den) <= 1e-15, "load_factor_failed %.17g is not %d/%d" % (failed, steps + 1, den))
check(re.search(r"did not converge|det F", s["reason"]) and "cut-backs" in s["reason"], "reason: " + s["reason"])
for key in ("tip_uy", "error_l2"):
    check(key not in s, "a failed run reports %s, which belongs to the full load" % key)
files = sorted(f for f in os.listdir(d) if f.endswith(".vtu"))
expect = sorted(["step_%04d.vtu" % k for k in range(1, steps + 1)] + ["mesh_%04d.vtu" % k for k in range(1, steps + 1)])
if ranks > 1:
    expect = sorted("%s_%04d_%d.vtu" % (part, k, r) for part in ("step", "mesh") for k in range(1, steps + 1)
                    for r in range(ranks))
    pvtu = sorted(f for f in os.listdir(d) if f.endswith(".pvtu"))
    check(pvtu == sorted("%s_%04d.pvtu" % (part, k) for part in ("step", "mesh") for k in range(1, steps + 1)),
          ".pvtu files %s, expected steps 1..%d" % (pvtu[-4:], steps))
check(files == expect, "VTU files %s, expected steps 1..%d" % (files[-4:], steps))
pvd = os.path.join(d, "solution.pvd")
if steps == 0:
    check(not os.path.exists(pvd), "solution.pvd written with no converged step")
else:
    sets = v.read_pvd(pvd)
    check(len(sets) == 2 * steps, "solution.pvd lists %d data sets, expected %d" % (len(sets), 2 * steps))
    for i, (t, part, name, f) in enumerate(sets):
        k = i // 2 + 1
        check(abs(float(t) - k / den) <= 1e-12 * k / den, "%s at %s, expected %d/%d" % (f, t, k, den))
    check(float(sets[-1][0]) == reached and sets[-1][3] == "mesh_%04d.%s" % (steps, ext), "the PVD ends at %s" % (sets[-1],))
for f in files:
    v.read_vtu(os.path.join(d, f))  # exits with FAIL on a non-finite value
for f in os.listdir(d):
    if not f.endswith("vtu"):
        text = open(os.path.join(d, f)).read().lower()
        check(not re.search(r"\b(nan|inf|infinity)\b", text), "%s holds NaN or Inf" % f)
print("ok: %s: status failed, %d steps to load factor %.6g = %d/%d, failed at %d/%d, files and PVD agree, all finite"
      % (os.path.basename(d), steps, reached, steps, den, steps + 1, den))
PY
}

# ---- serial: an earlier run's results (20 steps), then the failing run into the same directory ----
r="$work/cook"
"$MICA" run $deck -o "$r" "${small[@]}" --set solver.steps=20 --set parameters.F=0.5 > "$r.first.log" 2>&1 \
  || fail "the earlier run failed: $(tail -3 "$r.first.log")"
[ -f "$r/step_0020.vtu" ] || fail "the earlier run wrote no step_0020.vtu"
"$MICA" run $deck -o "$r" "${small[@]}" "${failing[@]}" > "$r.log" 2> "$r.err"
rc=$?
[ $rc -eq 3 ] || fail "the failing run exited $rc, expected 3: $(cat "$r.err")"
reason="^mica: Newton did not converge in 12 iterations at load factor 0.0296875 .*after 6 cut-backs (the most"
reason+=" allowed); the last converged load factor is 0.028125 (load step 18)"
grep -q "$reason" "$r.err" || fail "stderr does not give the reason: $(cat "$r.err")"
[ "$(wc -l < "$r.err")" -eq 1 ] || fail "stderr has more than the one message: $(cat "$r.err")"
ok "exit 3, the reason on stderr"
[ "$(json_get reason "$r/summary.json")" = "$(sed 's/^mica: //' "$r.err")" ] \
  || fail "summary's reason is not stderr's message"
grep -q "^partial results (the converged load steps) in $r/" "$r.log" || fail "stdout does not say where"
[ ! -e "$r/step_0019.vtu" ] && [ ! -e "$r/step_0020.vtu" ] || fail "the earlier run's step files 19, 20 are left"
[ -z "$(ls -A "$work" | grep -e staging -e '\.old-')" ] || fail "a staging directory is left: $(ls -A "$work")"
ok "the failed run's results replaced the earlier run's whole"
check_failed "$r" 18

# the last step's fields are the state at the reached load: a run to F t = 1000 * 18/640 N in the same 18 steps
"$MICA" run $deck -o "$work/ref" "${small[@]}" --set parameters.F=28.125 --set solver.steps=18 --set output.vtu=false \
  > "$work/ref.log" 2>&1 || fail "the reference run failed: $(tail -3 "$work/ref.log")"
ref=$(json_value tip_uy "$work/ref/summary.json")
last=$(python3 - "$r/step_0018.vtu" <<'PY'
import sys
sys.path.insert(0, "tests/cli")
import vtu_readback as v
d = v.read_vtu(sys.argv[1])
i = min(range(len(d["points"])), key=lambda i: (d["points"][i][0] - 48) ** 2 + (d["points"][i][1] - 60) ** 2)
assert abs(d["points"][i][0] - 48) + abs(d["points"][i][1] - 60) < 1e-12, "no particle at (48, 60)"
print("%.17g" % d["arrays"]["displacement"][2][3 * i + 1])
PY
) || fail "cannot read u_y(48, 60) from step_0018.vtu"
within "$last" "$ref" 1e-8 "u_y(48, 60) of the last written step against a run to F = 28.125 N"

# ---- no step converged: 3 cut-backs end at the first step (det F < 0) ----
z="$work/none"
expect_failure 3 "no load step converged (load factor 0 reached)" -- "$MICA" run $deck -o "$z" "${small[@]}" \
  --set parameters.F=1000 --set solver.max_cuts=3
check_failed "$z" 0

# ---- mpirun -np 2: every rank agrees, the message once, the files once, the serial run's summary ----
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
[ "${SAN:-}" = 1 ] && export ASAN_OPTIONS="detect_leaks=0:abort_on_error=0" # as in mpi.sh
MPIRUN=(timeout 300 mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
if TMPDIR="$work/tmp" "${MPIRUN[@]}" -np 2 "$MICA" --version > /dev/null 2>&1; then
  p="$work/cook_np2"
  TMPDIR="$work/tmp" "${MPIRUN[@]}" -np 2 "$MICA" run $deck -o "$p" "${small[@]}" "${failing[@]}" > "$p.log" 2> "$p.err"
  rc=$?
  [ $rc -eq 3 ] || fail "mpirun -np 2: exit $rc, expected 3: $(cat "$p.err")"
  [ "$(grep -c '^mica: ' "$p.err")" -eq 1 ] || fail "mpirun -np 2: the message is not printed once: $(cat "$p.err")"
  grep -q "^mica: Newton did not converge .*the last converged load factor is 0.028125 (load step 18)" "$p.err" \
    || fail "mpirun -np 2: stderr lacks the reason: $(cat "$p.err")"
  [ "$(json_value ranks "$p/summary.json")" = 2 ] || fail "mpirun -np 2: summary.json is not the parallel run's"
  for key in status load_steps load_factor_reached load_factor_failed step_cuts reason; do
    [ "$(json_get $key "$p/summary.json")" = "$(json_get $key "$r/summary.json")" ] \
      || fail "mpirun -np 2: $key = $(json_get $key "$p/summary.json"), serial $(json_get $key "$r/summary.json")"
  done
  [ -z "$(ls -A "$work/tmp")" ] || fail "mpirun -np 2: rank scratch directories left: $(ls -A "$work/tmp")"
  ok "mpirun -np 2: exit 3, the message once, the serial run's status, steps, load factors and reason"
  check_failed "$p" 18 2
else
  echo "### SKIPPED: mpirun cannot start 2 processes here; the parallel failed run is untested ###"
fi

# ---- a sweep and a study with a point that fails this way: they go on; its row says failed ----
{ cat $deck; echo 'sweep = { parameters = ( { path = "parameters.F"; values = [1.0, 1000.0]; } );'
  echo '          probe = "tip_uy"; chart = false; };'; } > "$work/sweep.cfg"
"$MICA" sweep "$work/sweep.cfg" -o "$work/sweep" "${small[@]}" --set solver.max_cuts=3 > "$work/sweep.log" 2>&1 \
  || fail "the sweep failed: $(tail -3 "$work/sweep.log")"
csv="$work/sweep/sweep.csv"
awk -F, '$1 == 1 && $5 == "ok"' "$csv" | grep -q . || fail "sweep point 1 should be ok: $(cat "$csv")"
awk -F, '$1 == 2 && $5 == "failed"' "$csv" | grep -q 'no load step converged' \
  || fail "sweep point 2 should say failed: $(cat "$csv")"
s="$work/sweep/points/2/summary.json"
[ "$(json_value status "$s")/$(json_value exit_status "$s")/$(json_value load_factor_reached "$s")" = failed/3/0 ] \
  || fail "points/2/summary.json: status $(json_value status "$s"), exit_status $(json_value exit_status "$s")"
[ "$(json_value points_failed "$work/sweep/summary.json")" = 1 ] || fail "sweep summary: points_failed should be 1"
ok "sweep: the failing point's row says failed, its summary status failed, exit_status 3, load factor 0"

{ cat $deck; echo 'study = { choices = ( { path = "parameters.F"; values = [1.0, 1000.0]; } );'
  echo '          error = "tip_uy"; reference = 13.77; chart = false; };'; } > "$work/study.cfg"
"$MICA" study "$work/study.cfg" -o "$work/study" "${small[@]}" --set solver.max_cuts=3 > "$work/study.log" 2>&1 \
  || fail "the study failed: $(tail -3 "$work/study.log")"
awk -F, '$1 == 2 && $3 == "failed"' "$work/study/study.csv" | grep -q 'no load step converged' \
  || fail "study row 2 should say failed: $(cat "$work/study/study.csv")"
s="$work/study/points/2/summary.json"
[ "$(json_value status "$s")/$(json_value exit_status "$s")/$(json_value step_cuts "$s")" = failed/3/3 ] \
  || fail "study points/2/summary.json: status $(json_value status "$s"), exit_status $(json_value exit_status "$s")"
ok "study: the failing combination's row says failed, its summary status failed, exit_status 3"
