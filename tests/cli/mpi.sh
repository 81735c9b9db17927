# Parallel runs (issue 6): `mpirun -np 2` and `-np 3` give the serial probes and error norms — to 1e-10
# relative with solver.parallel = gather, to the Krylov tolerance with schwarz — on the Timoshenko beam
# (CHOLMOD / CG), Cook's membrane with Neo-Hooke (Newton over load steps) and the Cosserat glide layer
# (Lagrange multipliers: UMFPACK / GMRES). summary.json carries the partition's edge cut and imbalance;
# files are written once (the fields in pieces, one per rank: mpi_output.sh); a failure injected on rank 1 (MICA_INJECT_FAILURE) or a deck error
# ends every rank with the right exit status, reported once. `timeout` only keeps a hang from blocking
# the suite: no check here depends on time.
source "$(dirname "$0")/common.bash"
work="$(cd "$(dirname "$OUT_DIR")" 2>/dev/null && pwd)/$(basename "$OUT_DIR")/mpi" # absolute: mpirun's TMPDIR
rm -rf "$work" && mkdir -p "$work/tmp"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export TMPDIR="$work/tmp" # ranks other than 0 run in scratch directories here, which must be gone afterwards
# Under SAN=1 the runs under mpirun are leak-checked too (common.bash: the slow unwinder, tests/lsan.supp).
MPIRUN=(timeout 300 mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
mpi_leak_checks # under SAN=1: the ranks leak-checked with the slow unwinder (common.bash)

if ! out=$("${MPIRUN[@]}" -np 2 "$MICA" --version 2>&1) || [ "$(grep -c '^mica ' <<<"$out")" -lt 1 ]; then
  echo "#####################################################################################"
  echo "### SKIPPED: mpirun cannot start 2 processes here, so the parallel runs are untested ###"
  echo "### mpirun said: $out"
  echo "#####################################################################################"
  exit 0
fi

# compare SERIAL PARALLEL TOL KEY...: each key's value in the parallel summary within TOL (relative) of the serial
compare() {
  local serial=$1 parallel=$2 tol=$3; shift 3
  for key in "$@"; do
    local a b
    a=$(json_value "$key" "$serial/summary.json"); b=$(json_value "$key" "$parallel/summary.json")
    [ -n "$a" ] && [ -n "$b" ] || fail "$key missing in $serial or $parallel"
    awk -v a="$a" -v b="$b" -v t="$tol" 'BEGIN { d = a - b; if (d < 0) d = -d; s = a < 0 ? -a : a; exit !(d <= t * s) }' \
      || fail "$parallel: $key = $b, serial $a: not within $tol"
  done
  ok "$(basename "$parallel"): $* within $tol of the serial run"
}

# prun NP DIR DECK [--set ...]: mica run under mpirun, quietly
prun() {
  local np=$1 dir=$2 deck=$3; shift 3
  "${MPIRUN[@]}" -np "$np" "$MICA" run "$deck" -o "$dir" --set output.monitor=false --set output.vtu=false "$@" \
    > "$dir.log" 2>&1 || fail "mpirun -np $np mica run $deck $* failed: $(tail -n 5 "$dir.log")"
}

cook=(--set "particles.count=[9,9]" --set solver.steps=4)
run_deck "$work/timo" input/timoshenko.cfg
run_deck "$work/cook" input/cook_neohooke.cfg "${cook[@]}"
run_deck "$work/glide" input/cosserat_glide.cfg
for np in 2 3; do
  prun $np "$work/timo_$np" input/timoshenko.cfg
  compare "$work/timo" "$work/timo_$np" 1e-10 tip_uy
  # an error norm is a small difference: it carries the round-off of the solution divided by the error
  compare "$work/timo" "$work/timo_$np" 1e-6 error_l2 error_h1 error_energy
  prun $np "$work/cook_$np" input/cook_neohooke.cfg "${cook[@]}"
  compare "$work/cook" "$work/cook_$np" 1e-10 tip_uy
  prun $np "$work/glide_$np" input/cosserat_glide.cfg
  compare "$work/glide" "$work/glide_$np" 1e-10 phi_top ux_top phi_mid ux_mid
  compare "$work/glide" "$work/glide_$np" 1e-6 error_l2 error_energy
  for key in edge_cut imbalance; do
    v=$(json_value $key "$work/timo_$np/summary.json")
    [ -n "$v" ] || fail "summary.json of -np $np lacks $key"
  done
  at_least "$(json_value edge_cut "$work/timo_$np/summary.json")" 1 "-np $np: edge cut"
  less_than "$(json_value imbalance "$work/timo_$np/summary.json")" 1.2 || fail "-np $np: imbalance above 1.2"
  [ "$(json_value ranks "$work/timo_$np/summary.json")" = $np ] || fail "-np $np: ranks in summary.json"
  [ "$(json_value nnz "$work/timo_$np/summary.json")" = "$(json_value nnz "$work/timo/summary.json")" ] \
    || fail "-np $np: nnz of the whole tangent differs from the serial one"
  ok "-np $np: partition in summary.json, nnz as serial"

  # Schwarz: CG (SPD) and GMRES (Lagrange multipliers), to the Krylov tolerance 1e-10 (results to ~1e-8)
  prun $np "$work/timo_schwarz_$np" input/timoshenko.cfg --set solver.parallel=schwarz --set solver.overlap=1
  compare "$work/timo" "$work/timo_schwarz_$np" 1e-7 tip_uy
  at_least "$(json_value krylov_iterations "$work/timo_schwarz_$np/summary.json")" 2 "-np $np: CG iterations"
  prun $np "$work/cook_schwarz_$np" input/cook_neohooke.cfg "${cook[@]}" --set solver.parallel=schwarz
  compare "$work/cook" "$work/cook_schwarz_$np" 1e-7 tip_uy
  prun $np "$work/glide_schwarz_$np" input/cosserat_glide.cfg --set solver.parallel=schwarz --set solver.overlap=1
  compare "$work/glide" "$work/glide_schwarz_$np" 1e-7 phi_top ux_top phi_mid ux_mid
  at_least "$(json_value krylov_iterations "$work/glide_schwarz_$np/summary.json")" 2 "-np $np: GMRES iterations"
done

# solver.linear = cg under MPI: gather runs CG on rank 0 (the serial answer to the Krylov tolerance, iterations
# in the summary); schwarz is itself CG and factors its subdomains (CHOLMOD) when cg is asked for
run_deck "$work/cube_cg" input/cube3d.cfg --set "particles.count=[7,7,7]" --set quadrature.order=2 --set solver.linear='"cg"'
prun 2 "$work/cube_cg_2" input/cube3d.cfg --set "particles.count=[7,7,7]" --set quadrature.order=2 --set solver.linear='"cg"'
compare "$work/cube_cg" "$work/cube_cg_2" 1e-8 corner_ux error_l2
[ "$(json_value krylov_iterations "$work/cube_cg_2/summary.json")" = "$(json_value krylov_iterations "$work/cube_cg/summary.json")" ] \
  || fail "-np 2 gather + cg: iterations differ from the serial cg run"
prun 2 "$work/cube_cg_schwarz" input/cube3d.cfg --set "particles.count=[7,7,7]" --set quadrature.order=2 \
  --set solver.linear='"cg"' --set solver.parallel='"schwarz"' --set solver.overlap=1
compare "$work/cube_cg" "$work/cube_cg_schwarz" 1e-7 corner_ux
[ -n "$(json_value rank_cpu_assemble "$work/cube_cg_2/summary.json")" ] || fail "-np 2: no per-rank CPU times"
ok "-np 2: cg with gather and schwarz as serial; per-rank figures in the summary"

# -np 1 under mpirun takes the serial path (no partition); only the BLAS under CHOLMOD may run with another
# thread count when mpirun binds the process to a core, which changes the last bits
prun 1 "$work/timo_1" input/timoshenko.cfg
compare "$work/timo" "$work/timo_1" 1e-13 tip_uy
[ -z "$(json_value edge_cut "$work/timo_1/summary.json")" ] || fail "-np 1 partitioned"

# files written once: the fields in a piece per rank with rank 0's .pvtu (tests/cli/mpi_output.sh checks their
# numbers), the PVD and the summary by rank 0; no staging directory left, no scratch directory of other ranks
prun 3 "$work/files" input/timoshenko.cfg --set output.vtu=true
[ -f "$work/files/step_0001.pvtu" ] && [ -f "$work/files/mesh_0001.pvtu" ] && [ -f "$work/files/step_0001_2.vtu" ] \
  && [ -f "$work/files/mesh_0001_2.vtu" ] && [ -f "$work/files/solution.pvd" ] \
  && [ -f "$work/files/summary.json" ] || fail "-np 3: result files missing"
[ -z "$(ls -A "$work/files" | grep staging)" ] || fail "a staging directory was left behind"
[ -z "$(ls -A "$work/tmp" | grep mica-rank)" ] || fail "scratch directories of ranks 1, 2 left in TMPDIR: $(ls "$work/tmp")"
[ "$(grep -c '^results in' "$work/files.log")" -eq 1 ] || fail "the log is not written once: $(cat "$work/files.log")"
[ "$(grep -c '^probe tip_uy' "$work/files.log")" -eq 1 ] || fail "probes printed more than once"
ok "-np 3: files and log lines written once"

# a failure on rank 1 ends every rank: an error at a phase, and a crash (exit without MPI_Finalize)
for phase in deck build assemble solve output assemble:exit; do
  d="$work/inject_$(tr : _ <<<"$phase")"
  MICA_INJECT_FAILURE=1:$phase "${MPIRUN[@]}" -np 3 "$MICA" run input/timoshenko.cfg -o "$d" \
    --set output.vtu=false > "$d.out" 2> "$d.err"
  rc=$?
  [ $rc -ne 0 ] || fail "injected failure at $phase: exit status 0"
  [ $rc -ne 124 ] || fail "injected failure at $phase: the run hung (killed by timeout)"
  [ "$(grep -c "rank 1: .*MICA_INJECT_FAILURE=1:$phase" "$d.err")" -eq 1 ] \
    || fail "injected failure at $phase: not reported once: $(cat "$d.err")"
  [ ! -f "$d/summary.json" ] || fail "injected failure at $phase: results were published"
  ok "failure injected on rank 1 at $phase: every rank stopped (exit $rc), reported once"
done

# a deck error: every rank exits 2, the message once
"${MPIRUN[@]}" -np 3 "$MICA" run input/timoshenko.cfg -o "$work/bad" --set mls.order=x > "$work/bad.out" 2> "$work/bad.err"
rc=$?
[ $rc -eq 2 ] || fail "deck error under mpirun: exit $rc, expected 2: $(cat "$work/bad.err")"
[ "$(grep -c 'mls.order must be an integer' "$work/bad.err")" -eq 1 ] || fail "deck error not reported once: $(cat "$work/bad.err")"
ok "deck error under mpirun: exit 2, reported once"

# the measuring sticks of issue 5 (FE baseline, nodal integration) run on one process: refused with the line
for set in problem.method=fe quadrature.mode=scni; do
  "${MPIRUN[@]}" -np 2 "$MICA" run input/timoshenko.cfg -o "$work/serial_only" --set $set > /dev/null 2> "$work/serial_only.err"
  rc=$?
  [ $rc -eq 2 ] || fail "--set $set under mpirun: exit $rc, expected 2: $(cat "$work/serial_only.err")"
  [ "$(grep -c -- "--set $set: .* runs on one process" "$work/serial_only.err")" -eq 1 ] \
    || fail "--set $set under mpirun: no single clear message: $(cat "$work/serial_only.err")"
done
ok "FE and nodal modes under mpirun: exit 2, one message naming the setting"
