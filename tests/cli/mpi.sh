# Parallel runs (issues 6 and 19): `mpirun -np 2` and `-np 3` with the defaults (solver.linear = "auto", which under
# mpirun is PETSc with MUMPS on the tangent distributed by the ranks' particles) give the serial probes and error
# norms to 1e-10 relative — on the Timoshenko beam (CHOLMOD serially), Cook's membrane with Neo-Hooke (Newton over
# load steps) and the Cosserat glide layer (Lagrange multipliers: UMFPACK serially, MUMPS's LU here); additive
# Schwarz with CHOLMOD subdomains (solver.petsc = "asm-cholmod", CG) to the Krylov tolerance. A one-process solver
# (cholmod, umfpack) under mpirun is a deck error with the remedy. summary.json carries the partition's edge cut and
# imbalance; files are written once (the fields in pieces, one per rank: mpi_output.sh); a failure injected on
# rank 1 (MICA_INJECT_FAILURE) at any phase or a deck error ends every rank with the right exit status, reported
# once, with nothing published and no scratch directory left — with replicated and with distributed data (a built-in
# shape's blocks and a Gmsh mesh's regions).
# `timeout` only keeps a hang from blocking the suite: no check here depends on time.
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

  [ "$(json_value linear_solver "$work/timo_$np/summary.json")" = petsc ] || fail "-np $np: the default is not petsc"
  [ "$(json_value petsc_method "$work/glide_$np/summary.json")" = mumps ] || fail "-np $np: the default is not MUMPS"

  # CHOLMOD under MPI domain decomposition: CG with additive Schwarz, CHOLMOD factoring each rank's subdomain,
  # to the Krylov tolerance 1e-10 (results to ~1e-8)
  prun $np "$work/timo_asm_$np" input/timoshenko.cfg --set solver.linear=petsc --set solver.petsc=asm-cholmod
  compare "$work/timo" "$work/timo_asm_$np" 1e-7 tip_uy
  at_least "$(json_value krylov_iterations "$work/timo_asm_$np/summary.json")" 2 "-np $np: CG iterations"
  prun $np "$work/cook_asm_$np" input/cook_neohooke.cfg "${cook[@]}" --set solver.linear=petsc --set solver.petsc=asm-cholmod
  compare "$work/cook" "$work/cook_asm_$np" 1e-7 tip_uy
done

# a one-process solver under mpirun: refused with the line and the remedy, by every rank, reported once
for linear in cholmod umfpack; do
  "${MPIRUN[@]}" -np 2 "$MICA" run input/timoshenko.cfg -o "$work/one_process" --set solver.linear=$linear \
    > /dev/null 2> "$work/one_process.err"
  rc=$?
  [ $rc -eq 2 ] || fail "solver.linear = $linear under mpirun: exit $rc, expected 2: $(cat "$work/one_process.err")"
  [ "$(grep -c -- "--set solver.linear=$linear: solver.linear = \"$linear\" solves in one process, but this run has 2 ranks; use \"auto\" or \"petsc\"" "$work/one_process.err")" -eq 1 ] \
    || fail "solver.linear = $linear under mpirun: no single clear message: $(cat "$work/one_process.err")"
  [ ! -e "$work/one_process" ] || fail "a refused run wrote its directory"
done
[ -n "$(json_value rank_cpu_assemble "$work/timo_2/summary.json")" ] || fail "-np 2: no per-rank CPU times"
ok "one-process solvers under mpirun: exit 2 with the remedy; per-rank figures in the summary"

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

# a failure on rank 1 ends every rank: an error at a phase, and a crash (exit without MPI_Finalize); with replicated
# data (the beam) and with distributed data (the cube: each rank its own block, its ghost exchange and PETSc's rows)
distributed=(tests/decks/parallel/cube.cfg --set "particles.count=[6,6,6]" --set quadrature.order=3
             --set 'parallel.data="distributed"' --set output.mesh=false)
# and a Gmsh mesh on distributed data (each rank its region of the file, its ghosts' numbers asked of their owners)
gmsh=(input/plate_hole_gmsh.cfg --set 'parallel.data="distributed"' --set 'solver.linear="petsc"')
for data in replicated distributed gmsh; do
  for phase in deck build assemble solve output assemble:exit; do
    d="$work/inject_${data}_$(tr : _ <<<"$phase")"
    rm -rf "$work/tmp" && mkdir -p "$work/tmp"
    case $data in
      replicated) args=(input/timoshenko.cfg) ;;
      distributed) args=("${distributed[@]}") ;;
      gmsh) args=("${gmsh[@]}") ;;
    esac
    MICA_INJECT_FAILURE=1:$phase "${MPIRUN[@]}" -np 3 "$MICA" run "${args[@]}" -o "$d" \
      --set output.vtu=true > "$d.out" 2> "$d.err"
    rc=$?
    [ $rc -ne 0 ] || fail "$data: injected failure at $phase: exit status 0"
    [ $rc -ne 124 ] || fail "$data: injected failure at $phase: the run hung (killed by timeout)"
    [ "$(grep -c "rank 1: .*MICA_INJECT_FAILURE=1:$phase" "$d.err")" -eq 1 ] \
      || fail "$data: injected failure at $phase: not reported once: $(cat "$d.err")"
    [ ! -e "$d" ] || fail "$data: injected failure at $phase: the results directory was published: $(ls "$d")"
    # an error unwinds every rank, which remove their scratch directories (a crashed rank cannot)
    [ "$phase" = assemble:exit ] || [ -z "$(ls -A "$work/tmp" | grep mica-rank)" ] \
      || fail "$data: injected failure at $phase: scratch directories left in TMPDIR: $(ls "$work/tmp")"
    ok "$data: failure injected on rank 1 at $phase: every rank stopped (exit $rc), reported once, nothing left"
  done
done

# a deck error: every rank exits 2, the message once
"${MPIRUN[@]}" -np 3 "$MICA" run input/timoshenko.cfg -o "$work/bad" --set mls.order=x > "$work/bad.out" 2> "$work/bad.err"
rc=$?
[ $rc -eq 2 ] || fail "deck error under mpirun: exit $rc, expected 2: $(cat "$work/bad.err")"
[ "$(grep -c 'mls.order must be an integer' "$work/bad.err")" -eq 1 ] || fail "deck error not reported once: $(cat "$work/bad.err")"
"${MPIRUN[@]}" -np 3 "$MICA" run "${distributed[@]}" -o "$work/bad" --set mls.order=x > "$work/bad.out" 2> "$work/bad.err"
rc=$?
[ $rc -eq 2 ] || fail "deck error under mpirun, distributed data: exit $rc, expected 2: $(cat "$work/bad.err")"
[ "$(grep -c 'mls.order must be an integer' "$work/bad.err")" -eq 1 ] \
  || fail "deck error under mpirun, distributed data: not reported once: $(cat "$work/bad.err")"
[ ! -e "$work/bad" ] || fail "a deck error wrote $work/bad"
ok "deck error under mpirun: exit 2, reported once (replicated and distributed data)"

# the FE measuring stick runs on one process, and the nodal modes need distributed data (each rank builds its
# particles' nodal cells; replicated data spreads Gauss points): refused with the line and the remedy
for case in "problem.method=fe|runs on one process" "quadrature.mode=scni|needs parallel.data = \"distributed\""; do
  set=${case%%|*} why=${case#*|}
  "${MPIRUN[@]}" -np 2 "$MICA" run input/timoshenko.cfg -o "$work/serial_only" --set $set > /dev/null 2> "$work/serial_only.err"
  rc=$?
  [ $rc -eq 2 ] || fail "--set $set under mpirun: exit $rc, expected 2: $(cat "$work/serial_only.err")"
  [ "$(grep -c -- "--set $set: .* $why" "$work/serial_only.err")" -eq 1 ] \
    || fail "--set $set under mpirun: no single clear message: $(cat "$work/serial_only.err")"
done
ok "FE and nodal modes (replicated data) under mpirun: exit 2, one message naming the setting"
