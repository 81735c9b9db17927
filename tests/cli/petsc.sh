# solver.linear = "petsc" (issue 19, item 2): PETSc's KSP on the tangent distributed by rows over the ranks.
# Serially and under `mpirun -np 2, 3, 4` (oversubscribed) the probes agree with the serial run of the default
# solver (CHOLMOD, or UMFPACK where the tangent is not SPD) — to 1e-10 relative with solver.petsc = "mumps"
# (distributed Cholesky/LU), to 1e-7 with the Krylov presets (solver.linear_rtol = 1e-10: the probes carry the
# residual times the condition number) — on Cook's membrane with Neo-Hooke (Newton over 4 load steps), the 3-D
# cube in tension, the Cosserat glide layer with Lagrange multipliers (a saddle point: MUMPS's LU), the Cosserat
# manufactured solution with Nitsche's method (GAMG with the rigid motions incl. the micro-rotation as near-null
# space) and the linear patch test with VCI (unsymmetric: MUMPS's LU, GMRES with GAMG). The iterative presets
# refuse the saddle point, the Cholesky ones an unsymmetric tangent, and PETSc options it did not use: input
# errors (exit 2) with the remedy. `timeout` only keeps a hang from
# blocking the suite: no check here depends on time.
source "$(dirname "$0")/common.bash"
work="$(cd "$(dirname "$OUT_DIR")" 2>/dev/null && pwd)/$(basename "$OUT_DIR")/petsc" # absolute: mpirun's TMPDIR
rm -rf "$work" && mkdir -p "$work/tmp"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export TMPDIR="$work/tmp"
MPIRUN=(timeout 300 mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
mpi_leak_checks
# a serial petsc run starts MPI too (PetscInitialize), so its leak check needs the slow unwinder for
# tests/lsan.supp to recognize OpenMPI's allocations, as the ranks do (mpi_leak_checks)
[ "${SAN:-}" = 1 ] && export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PWD/tests/lsan.supp:print_suppressions=0}:fast_unwind_on_malloc=0"

# compare SERIAL OTHER TOL KEY...: each key of OTHER's summary within TOL (relative) of SERIAL's
compare() {
  local serial=$1 other=$2 tol=$3; shift 3
  for key in "$@"; do
    local a b
    a=$(json_value "$key" "$serial/summary.json"); b=$(json_value "$key" "$other/summary.json")
    [ -n "$a" ] && [ -n "$b" ] || fail "$key missing in $serial or $other"
    awk -v a="$a" -v b="$b" -v t="$tol" 'BEGIN { d = a - b; if (d < 0) d = -d; s = a < 0 ? -a : a; exit !(d <= t * s) }' \
      || fail "$other: $key = $b, serial $a: not within $tol"
  done
  ok "$(basename "$other"): $* within $tol of the serial run"
}

# prun NP DIR DECK [--set ...]: mica run under mpirun (NP = 1: a plain serial run), quietly
prun() {
  local np=$1 dir=$2 deck=$3; shift 3
  local launch=("${MPIRUN[@]}" -np "$np"); [ "$np" = 1 ] && launch=()
  "${launch[@]}" "$MICA" run "$deck" -o "$dir" --set output.monitor=false --set output.vtu=false "$@" \
    > "$dir.log" 2>&1 || fail "np $np: mica run $deck $* failed: $(tail -n 5 "$dir.log")"
  [ "$(json_value linear_solver "$dir/summary.json")" = petsc ] || fail "$dir: not solved by petsc"
}

probe() { echo "output.probes=({ name = \"$1\"; point = [$2]; field = \"$3\"; })"; }
cook=(--set "particles.count=[9,9]" --set solver.steps=4)
cube=(--set "particles.count=[6,6,6]" --set quadrature.order=3)
nitsche=(--set "$(probe p_phi "0.2, -0.3" phiz)")
vci=(--set quadrature.vci=true --set "$(probe p_ux "0.3, 0.7" ux)")
run_deck "$work/cook" input/cook_neohooke.cfg "${cook[@]}"
run_deck "$work/cube" input/cube3d.cfg "${cube[@]}"
run_deck "$work/glide" input/cosserat_glide.cfg
run_deck "$work/nitsche" tests/decks/cosserat/nitsche.cfg "${nitsche[@]}"
run_deck "$work/vci" input/patch_linear.cfg "${vci[@]}"
[ "$(json_value linear_solver "$work/cook/summary.json")" = cholmod ] || fail "the serial default is not CHOLMOD"
# VCI with Nitsche: CHOLMOD on the symmetric part and refinement (issue 21; UMFPACK before)
[ "$(json_value linear_solver "$work/vci/summary.json")" = cholmod-sym ] || fail "VCI's serial default is not cholmod-sym"

P=(--set solver.linear=petsc)
# The shipped Cook Neo-Hooke deck (21 x 21, 10 load steps) with GAMG, one process: its tangents change over the
# steps while GAMG's prolongators are reused; with the first tangent's eigenvalue estimate in the Chebyshev
# smoothers CG stopped at load factor 0.73 with DIVERGED_INDEFINITE_PC (linear_petsc.c, the gamg preset).
run_deck "$work/cook_full" input/cook_neohooke.cfg
prun 1 "$work/cook_full_gamg" input/cook_neohooke.cfg "${P[@]}" --set solver.petsc=gamg
compare "$work/cook_full" "$work/cook_full_gamg" 1e-7 tip_uy
for np in 1 2 3 4; do
  prun $np "$work/cook_mumps_$np" input/cook_neohooke.cfg "${cook[@]}" "${P[@]}"
  compare "$work/cook" "$work/cook_mumps_$np" 1e-10 tip_uy
  prun $np "$work/cook_gamg_$np" input/cook_neohooke.cfg "${cook[@]}" "${P[@]}" --set solver.petsc=gamg
  compare "$work/cook" "$work/cook_gamg_$np" 1e-7 tip_uy
  prun $np "$work/cube_mumps_$np" input/cube3d.cfg "${cube[@]}" "${P[@]}"
  compare "$work/cube" "$work/cube_mumps_$np" 1e-10 corner_ux
  prun $np "$work/cube_gamg_$np" input/cube3d.cfg "${cube[@]}" "${P[@]}" --set solver.petsc=gamg
  compare "$work/cube" "$work/cube_gamg_$np" 1e-7 corner_ux
  for deck in cook cube; do # geometric multigrid: Cook's trapezoid leaves lattice nodes inactive
    args=("${cook[@]}"); file=input/cook_neohooke.cfg key=tip_uy
    [ $deck = cube ] && args=("${cube[@]}") file=input/cube3d.cfg key=corner_ux
    prun $np "$work/${deck}_gmg_$np" $file "${args[@]}" "${P[@]}" --set solver.petsc=gmg
    compare "$work/$deck" "$work/${deck}_gmg_$np" 1e-7 $key
  done
  prun $np "$work/glide_mumps_$np" input/cosserat_glide.cfg "${P[@]}"
  compare "$work/glide" "$work/glide_mumps_$np" 1e-10 phi_top ux_top phi_mid ux_mid
  prun $np "$work/nitsche_mumps_$np" tests/decks/cosserat/nitsche.cfg "${nitsche[@]}" "${P[@]}"
  compare "$work/nitsche" "$work/nitsche_mumps_$np" 1e-10 p_phi
  prun $np "$work/nitsche_gamg_$np" tests/decks/cosserat/nitsche.cfg "${nitsche[@]}" "${P[@]}" --set solver.petsc=gamg
  compare "$work/nitsche" "$work/nitsche_gamg_$np" 1e-7 p_phi
  prun $np "$work/nitsche_gmg_$np" tests/decks/cosserat/nitsche.cfg "${nitsche[@]}" "${P[@]}" --set solver.petsc=gmg
  compare "$work/nitsche" "$work/nitsche_gmg_$np" 1e-7 p_phi
done
# VCI runs on one process only (its correction sums over every particle's support: run_check_serial_only)
prun 1 "$work/vci_mumps" input/patch_linear.cfg "${vci[@]}" "${P[@]}"
compare "$work/vci" "$work/vci_mumps" 1e-10 p_ux
for preset in gamg gmg asm-umfpack; do
  prun 1 "$work/vci_$preset" input/patch_linear.cfg "${vci[@]}" "${P[@]}" --set solver.petsc=$preset
  compare "$work/vci" "$work/vci_$preset" 1e-7 p_ux
done
# the other presets, serially and on 3 ranks, on the cube
for preset in hypre asm-cholmod asm-umfpack bjacobi-cholmod; do
  for np in 1 3; do
    prun $np "$work/cube_${preset}_$np" input/cube3d.cfg "${cube[@]}" "${P[@]}" --set solver.petsc=$preset
    compare "$work/cube" "$work/cube_${preset}_$np" 1e-7 corner_ux
  done
done
# the Krylov presets solve to solver.linear_rtol: the true residual PETSc reached is in the summary
res=$(json_value krylov_last_residual "$work/cube_gamg_3/summary.json")
less_than "$res" 1e-10 || fail "cube, gamg on 3 ranks: |b - Ax| / |b| = $res, not below solver.linear_rtol = 1e-10"
ok "cube, gamg on 3 ranks: |b - Ax| / |b| = $res < 1e-10 in $(json_value krylov_iterations "$work/cube_gamg_3/summary.json") iterations"

# gmg on Cook's membrane, linear elasticity with the linear basis at 150² (4 levels): with PETSc's default GMRES
# estimate of the Chebyshev smoothers' largest eigenvalue the preconditioner was indefinite (CG stopped after 3
# iterations; -mg_levels_esteig_ksp_type gmres still shows it); the preset estimates by CG (Lanczos)
lean_cook=(--set "particles.count=[150,150]" --set mls.order=1 --set mls.dilation=2.0 --set quadrature.order=3
           --set solver.steps=1 --set 'material.model="linear"' --set "$(probe tip "48, 60" uy)")
run_deck "$work/lean_cook" tests/decks/parallel/cook.cfg "${lean_cook[@]}"
for np in 1 2; do
  prun $np "$work/lean_cook_gmg_$np" tests/decks/parallel/cook.cfg "${lean_cook[@]}" "${P[@]}" --set solver.petsc=gmg
  compare "$work/lean_cook" "$work/lean_cook_gmg_$np" 1e-7 tip
done

# gmg: the lattices' multilinear interpolation reproduces linear fields (the rigid motions among them), so its
# iterations do not grow with the particles per side; GAMG's do (measured when written: gmg 10 at 9³, 15³ and 21³,
# GAMG 28 to 36 over 9³-27³)
for n in 9 15 21; do
  prun 1 "$work/mg_$n" input/cube3d_million.cfg "${P[@]}" --set parameters.n=$n --set solver.petsc=gmg
  its=$(json_value krylov_iterations "$work/mg_$n/summary.json")
  at_most "$its" 14 "gmg CG iterations on the ${n}³ cube"
  within "$(json_value corner_ux "$work/mg_$n/summary.json")" 0.01 5e-4 "gmg, ${n}³ cube: corner_ux against the exact p/E (the Gauss rule's patch error: 1.1e-4 at 9³)"
done
levels=$(json_value multigrid_levels "$work/mg_21/summary.json")
at_least "${levels:-0}" 3 "gmg levels on the 21³ cube (particles and lattices)"
prun 1 "$work/mg_21_gamg" input/cube3d_million.cfg "${P[@]}" --set parameters.n=21 --set solver.petsc=gamg
gamg_its=$(json_value krylov_iterations "$work/mg_21_gamg/summary.json")
less_than "$(( 2 * $(json_value krylov_iterations "$work/mg_21/summary.json") ))" "$gamg_its" \
  || fail "gmg needs $(json_value krylov_iterations "$work/mg_21/summary.json") iterations on the 21³ cube, GAMG $gamg_its: not half"
ok "21³ cube: gmg $(json_value krylov_iterations "$work/mg_21/summary.json") CG iterations ($levels levels), GAMG $gamg_its"

# gmg's first coarse operator is mica's (petsc_lattice.c: Σ over the ranks of Pᵀ K_r P from each rank's own tangent
# and its ghosts' interpolation rows): -mica_gmg_check_galerkin compares it with PETSc's PᵀAP of the assembled
# tangent at every factorization and fails the run beyond 1e-12 relative — on a cube with two lattices, Cook at
# finite strain (Newton: a new tangent each iteration) and the VCI patch test (a Petrov–Galerkin, unsymmetric tangent),
# serially and on 2 and 3 ranks with distributed data
check=(--set solver.petsc=gmg --set 'solver.petsc_options="-mica_gmg_check_galerkin"')
for np in 1 2 3; do
  dist=(); [ "$np" = 1 ] || dist=(--set 'parallel.data="distributed"')
  prun $np "$work/galerkin_cube_$np" input/cube3d_million.cfg "${P[@]}" "${dist[@]}" --set parameters.n=21 "${check[@]}"
  prun $np "$work/galerkin_cook_$np" input/cook_neohooke.cfg "${cook[@]}" "${P[@]}" "${dist[@]}" "${check[@]}"
  prun $np "$work/galerkin_vci_$np" input/patch_linear.cfg "${vci[@]}" "${P[@]}" "${dist[@]}" "${check[@]}"
  for run in cube cook vci; do
    n=$(grep -c "mica's against PETSc's PᵀAP: relative difference" "$work/galerkin_${run}_$np.log")
    [ "$n" -ge 1 ] || fail "np $np, $run: no check of the first coarse operator in the log"
  done
  ok "gmg's first coarse operator equals PETSc's PᵀAP to 1e-12 at every factorization (np $np: cube $(grep -c "relative difference" "$work/galerkin_cube_$np.log"), Cook $(grep -c "relative difference" "$work/galerkin_cook_$np.log"), VCI $(grep -c "relative difference" "$work/galerkin_vci_$np.log") checks)"
done

# what cannot work is refused, with the remedy
expect_failure 2 'solver.petsc = "gmg" builds its coarse spaces from the coordinates of the particles' -- \
  "$MICA" run input/cook_linear.cfg -o "$work/bad" --set problem.method=\"fe\" "${P[@]}" --set solver.petsc=gmg
for preset in gamg gmg hypre asm-umfpack; do
  expect_failure 2 "the Lagrange multipliers make the tangent a saddle point" -- \
    "$MICA" run input/cosserat_glide.cfg -o "$work/bad" "${P[@]}" --set solver.petsc=$preset
done
expect_failure 2 'solver.petsc = "asm-cholmod" needs a symmetric positive definite tangent' -- \
  "$MICA" run input/patch_linear.cfg -o "$work/bad" --set quadrature.vci=true "${P[@]}" --set solver.petsc=asm-cholmod
expect_failure 2 "PETSc did not use -ksp_typo" -- \
  "$MICA" run input/cube3d.cfg -o "$work/bad" "${P[@]}" --set 'solver.petsc_options="-ksp_typo 3"'
expect_failure 2 "PETSc did not use -pc_gamg_threshold" -- \
  "$MICA" run input/cube3d.cfg -o "$work/bad" "${P[@]}" --set solver.petsc=mumps \
  --set 'solver.petsc_options="-pc_gamg_threshold 0.1"'
expect_failure 2 'solver.petsc = "none" takes the method from solver.petsc_options alone' -- \
  "$MICA" run input/cube3d.cfg -o "$work/bad" "${P[@]}" --set solver.petsc=none
expect_failure 2 'solver.petsc is a setting of solver.linear = "petsc" only' -- \
  "$MICA" run input/cube3d.cfg -o "$work/bad" --set solver.petsc=gamg
[ ! -e "$work/bad" ] || fail "a refused run wrote $work/bad"
# solver.petsc = none: the method from the options alone (here CG with block Jacobi/ICC, to the tolerance)
prun 2 "$work/cube_none_2" input/cube3d.cfg "${cube[@]}" "${P[@]}" --set solver.petsc=none \
  --set 'solver.petsc_options="-ksp_type cg -pc_type bjacobi -sub_pc_type icc"'
compare "$work/cube" "$work/cube_none_2" 1e-7 corner_ux

# reuse across Newton iterations (Cook: 4 load steps, 20 factorizations): PETSc's own event counts (-log_view,
# through PETSC_OPTIONS, PETSc's global debugging aid) — one symbolic factorization (MUMPS; CHOLMOD in each ASM
# subdomain) and one GAMG graph (coarsening) and prolongator, numeric work at every Newton iteration
# count_event LOG EVENT: the event's count (the column after its name)
count_event() { awk -v e="$2" '$1 == e { print $2; exit }' "$1"; }
for preset in mumps asm-cholmod gamg gmg; do
  log="$work/log_$preset.txt"
  PETSC_OPTIONS="-log_view :$log" prun 2 "$work/reuse_$preset" input/cook_neohooke.cfg "${cook[@]}" "${P[@]}" \
    --set solver.petsc=$preset
  factorizations=$(json_value factorizations "$work/reuse_$preset/summary.json")
  at_least "$factorizations" 10 "$preset: Newton factorizations"
  case $preset in
    gamg) [ "$(count_event "$log" PCGAMGProl)" = 1 ] && [ "$(count_event "$log" PCGAMGCreateG)" = 1 ] \
            || fail "$preset: prolongator built $(count_event "$log" PCGAMGProl) times for $factorizations setups"
          ok "$preset, 2 ranks: one graph and prolongator for $factorizations setups" ;;
    gmg) [ "$(count_event "$log" MicaGalerkinSym)" = 1 ] && [ "$(count_event "$log" MicaGalerkinNum)" = "$factorizations" ] \
           || fail "$preset: $(count_event "$log" MicaGalerkinSym) symbolic, $(count_event "$log" MicaGalerkinNum) numeric Galerkin products for $factorizations setups of one lattice"
         ok "$preset, 2 ranks: one symbolic Galerkin product (mica's PᵀKP), $factorizations numeric ones" ;;
    *) [ "$(count_event "$log" MatCholFctrSym)" = 1 ] && [ "$(count_event "$log" MatCholFctrNum)" = "$factorizations" ] \
         || fail "$preset: $(count_event "$log" MatCholFctrSym) symbolic, $(count_event "$log" MatCholFctrNum) numeric factorizations for $factorizations"
       ok "$preset, 2 ranks: one symbolic factorization, $factorizations numeric ones" ;;
  esac
done
