# parallel.data = "distributed" (issue 19 item 1): each rank owns a block of the particle and cell index grids and
# holds only its block, its cells' points and the ghosts their supports reach. Checked against the serial run of
# the default solver (CHOLMOD), which shares no code with the distributed path past the discretization:
#   - parallel equals serial: for P = 1 (the one-block case, serially), 2, 3, 4 (oversubscribed), the particle
#     VTU pieces hold every serial particle once with every field within 1e-10 of the serial value (relative to
#     the field's largest magnitude; tests/cli/pvtu_compare.py) with MUMPS, within 1e-7 with GAMG (solver.linear_rtol
#     1e-12 times the conditioning), and the relative L2 error norm within the same tolerances (absolute): Cook's membrane with
#     Neo-Hooke (4 load steps), the 3-D cube in tension (linear) — both with Nitsche's method, the default —, the
#     Cosserat manufactured solution with penalty and with Nitsche, the cube with penalty; and with MUMPS at P = 2, 3, 4 on a jittered and a graded layout;
#   - VCI (auto: on for jittered particles): Cook's membrane jittered at P = 1-4 with MUMPS (LU) within 1e-10 of the
#     serial cholmod-sym run, with GAMG and gmg (GMRES) at P = 2, 4 within 1e-7, the jittered 3-D cube at P = 2, 4 (MUMPS);
#   - probes (each evaluated by the lowest rank holding the point's whole support): Cook's tip, a stress and the
#     strain energy, the cube's corner and centre, the glide layer's four, a jittered VCI run's, at P = 2-4 within
#     1e-10 (relative) of the serial run;
#   - the error norms on quadrature.error_order's points (each rank's cells) within 1e-10 at P = 2, 4;
#   - Lagrange multipliers: the Cosserat glide layer at P = 1-4 with MUMPS (LU) within 1e-10 of the serial UMFPACK
#     run, with the serial dofs and nnz; GAMG refused;
#   - no rank holds the whole problem: on a 12³ cube at P = 4, the ranks' owned particles, volume points and
#     boundary points sum to the serial run's counts, the summed tangent has the serial nnz, and each rank holds
#     (owned + ghosts) fewer than 0.6 of the particles;
#   - the rigid motions the Dirichlet conditions leave free, found from the ranks' shares of the sets (no rank builds
#     a whole set): the serial message, once, exit 2, at P = 2, 3;
#   - nodal quadrature (NSNI, SCNI, direct nodal) with each rank's own nodal cells: as serially at P = 1-4 (below);
#   - axisymmetric sections (each rank revolves its points): the Lamé cylinder as serially at P = 2, 4;
#   - the exponential weight (its per-particle shape parameters from the rank's box) as serially at P = 2, 4;
#   - the output mesh (a piece per rank of its cells) and quadrature_fields.csv (the ranks' rows in rank order) as
#     serially at P = 2, 4 (tests/cli/mesh_pieces_compare.py, quadrature_rows_compare.py);
#   - collocation (a ghost's rows emptied, a shared vertex's row written in shares) as serially at P = 2-4;
#   - Gmsh meshes (coordinate boxes of equal particle counts, elements by their centroids): Kirsch's plate from
#     plate_hole.msh (VCI on) at P = 1-4 within 1e-10 with MUMPS, its mesh pieces and SCF probe (a probe outside
#     every rank's part refused as serially; the cost guard's estimate the serial one), with Lagrange
#     multipliers at P = 2, 3; the cube of cube.geo (meshed once, by rank 0) at P = 2-4 with MUMPS and 2, 4 with GAMG
#     (1e-7), error norms on quadrature.error_order's points; the ranks' counts sum to the serial ones, each rank
#     holds fewer than 0.6 of the particles at P = 4; the region reads of cube.msh and of a 2.2 file at P = 2-4;
#     NSNI (cells from the Gauss points) on Kirsch (quadratic) at P = 2-4 and on the cube (linear: symmetric VCI);
#   - the irregular layout (each rank draws the tiles around its box, each particle owned by the block of its nearest
#     grid point): Cook at P = 1-4 and at 50² (several tiles) at P = 3, 4, the 3-D cube (error norms) and the plate
#     with a hole at P = 2, 4, with VCI, within 1e-10;
#   - NSNI on the irregular layout (cells from the Gauss points): Cook at finite strain at P = 2-4 and the 3-D cube
#     (symmetric VCI) at P = 2, 4, within 1e-10; the other nodal modes refused there as serially (exit 2, the line).
# `timeout` only keeps a hang from blocking the suite: no check depends on time. Under SAN=1, P = 4 runs only where
# a check needs four ranks (ranks() below says why).
source "$(dirname "$0")/common.bash"
work="$(cd "$(dirname "$OUT_DIR")" 2>/dev/null && pwd)/$(basename "$OUT_DIR")/mpi_distributed"
rm -rf "$work" && mkdir -p "$work/tmp"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export TMPDIR="$work/tmp"
MPIRUN=(timeout 300 mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
mpi_leak_checks
# under SAN=1 the slow unwinder for the runs that start MPI (mpirun's ranks, and PETSc in one process:
# distributed 1); the serial references (CHOLMOD, UMFPACK) never do, and keep the fast one
serial_lsan=${LSAN_OPTIONS:-}
[ "${SAN:-}" = 1 ] && export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PWD/tests/lsan.supp:print_suppressions=0}:fast_unwind_on_malloc=0"

# ranks N...: the rank counts a check runs. Under SAN=1 four ranks are left to the plain run where two run too:
# under the sanitizers each rank is 2-3x slower and the leak check's slow unwinder walks every allocation, four ranks
# oversubscribe the two cores, and the whole script took 40 of CI's 90 minutes (2026-12-07); one rank (PETSc in one
# process), two and three (an even and an odd split) still run under the sanitizers, and four wherever a check
# needs four (the 2 x 2 blocks' counts: medium-4, cube_gmsh-4-gamg).
ranks() {
  local np out=()
  for np; do
    [ "${SAN:-}" = 1 ] && [ "$np" = 4 ] && [[ " $* " == *" 2 "* ]] && continue
    out+=("$np")
  done
  echo "${out[*]}"
}

Q=(--set output.monitor=false --set output.mesh=false)
D=(--set solver.linear=petsc --set parallel.data=distributed)

# serial DIR DECK [--set ...]: the reference, CHOLMOD (REFERENCE=umfpack where the tangent is a saddle point)
serial() {
  local dir=$1 deck=$2; shift 2
  LSAN_OPTIONS=$serial_lsan "$MICA" run "$deck" -o "$dir" "${Q[@]}" "$@" > "$dir.log" 2>&1 \
    || fail "serial $deck $*: $(tail -n 3 "$dir.log")"
  [ "$(json_value linear_solver "$dir/summary.json")" = "${REFERENCE:-cholmod}" ] \
    || fail "$dir: the reference is not ${REFERENCE:-cholmod}"
}

# distributed NP DIR DECK [--set ...] (NP = 1: serially)
distributed() {
  local np=$1 dir=$2 deck=$3; shift 3
  local launch=("${MPIRUN[@]}" -np "$np"); [ "$np" = 1 ] && launch=()
  "${launch[@]}" "$MICA" run "$deck" -o "$dir" "${Q[@]}" "${D[@]}" "$@" > "$dir.log" 2>&1 \
    || fail "np $np: $deck $*: $(tail -n 5 "$dir.log")"
  [ "$np" = 1 ] || [ "$(json_value parallel_data "$dir/summary.json")" = distributed ] || fail "$dir: not distributed"
}

# same SERIAL DIR NP TOL: the fields (VTU pieces or the serial file) and error_l2 within TOL of the serial run
same() {
  local ref=$1 dir=$2 np=$3 tol=$4
  if [ "$np" = 1 ]; then
    python3 - "$ref" "$dir" "$tol" <<'EOF' > "$dir.check" 2>&1 || fail "$dir: $(cat "$dir.check")"
import sys, os
sys.path.insert(0, "tests/cli")
from vtu_readback import read_vtu
ref, out, tol = sys.argv[1], sys.argv[2], float(sys.argv[3])
for name in sorted(f for f in os.listdir(ref) if f.startswith("step_") and f.endswith(".vtu")):
    a, b = read_vtu(os.path.join(ref, name)), read_vtu(os.path.join(out, name))
    if a["points"] != b["points"]:
        sys.exit(f"{name}: the particles differ")
    for key, (_, _, va) in a["arrays"].items():
        vb = b["arrays"][key][2]
        # as pvtu_compare.py: the error (computed minus exact) against the displacement's magnitude
        scale = max(abs(v) for v in (a["arrays"]["displacement"][2] if key == "error" else va)) or 1.0
        worst = max(abs(x - y) for x, y in zip(va, vb)) / scale
        if worst > tol:
            sys.exit(f"{name}: {key} differs by {worst:.3g} > {tol}")
EOF
  else
    python3 tests/cli/pvtu_compare.py "$ref" "$dir" "$np" --tol "$tol" > "$dir.check" 2>&1 || fail "$dir: $(tail -n 2 "$dir.check")"
  fi
  local a b
  a=$(json_value error_l2 "$ref/summary.json"); b=$(json_value error_l2 "$dir/summary.json")
  # error_l2 is |u_h − u| / |u|: two solutions within TOL of each other (relative) give error norms within TOL
  [ -z "$a" ] || awk -v a="$a" -v b="$b" -v t="$tol" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= t) }' \
    || fail "$dir: error_l2 $b, serial $a: not within $tol"
  ok "$(basename "$dir"): fields${a:+ and error_l2} within $tol of the serial run"
}

# equal_keys SERIAL DIR KEY...: each summary key of DIR's run equal to SERIAL's (counts: exact)
equal_keys() {
  local ref=$1 dir=$2; shift 2
  for key in "$@"; do
    local a b
    a=$(json_value "$key" "$ref/summary.json"); b=$(json_value "$key" "$dir/summary.json")
    [ "$a" = "$b" ] || fail "$(basename "$dir"): $key $b, serial $a"
  done
}

# check_deck NAME TOL KTOL DECK [--set ...]: MUMPS within TOL, GAMG (|r| ≤ 1e-12 |b|) within KTOL
check_deck() {
  local name=$1 tol=$2 ktol=$3 deck=$4; shift 4
  serial "$work/$name" "$deck" "$@"
  for np in $(ranks 1 2 3 4); do
    distributed "$np" "$work/$name-$np-mumps" "$deck" "$@" --set solver.petsc=\"mumps\"
    same "$work/$name" "$work/$name-$np-mumps" "$np" "$tol"
    distributed "$np" "$work/$name-$np-gamg" "$deck" "$@" --set solver.petsc=\"gamg\" --set solver.linear_rtol=1e-12
    same "$work/$name" "$work/$name-$np-gamg" "$np" "$ktol"
  done
}

check_deck cook 1e-10 1e-7 tests/decks/parallel/cook.cfg --set "particles.count=[9,9]" --set solver.steps=4
check_deck cube 1e-10 1e-7 tests/decks/parallel/cube.cfg --set "particles.count=[6,6,6]" --set quadrature.order=3
# the penalty (β ∝ (L/h)/h for the quadratic basis) conditions the Cosserat tangent so that MUMPS and CHOLMOD differ
# by 1.3e-10 in the couple stress on one process (with the replicated data too), and MUMPS on 1 and on 2 processes
# by 2.3e-10: 1e-9 there, and GAMG 1e-6 (a wrong spacing or body volume on a rank's ghosts, both seen while this
# was written, moved the fields by 1e-5)
check_deck cosserat 1e-9 1e-6 tests/decks/cosserat/nitsche.cfg --set bc.method=\"penalty\"
check_deck nitsche 1e-10 1e-7 tests/decks/cosserat/nitsche.cfg
check_deck cube_penalty 1e-10 1e-7 tests/decks/parallel/cube.cfg --set "particles.count=[6,6,6]" --set quadrature.order=3 \
  --set bc.method=\"penalty\"

# Lagrange multipliers (a saddle point: MUMPS's LU against the serial UMFPACK): the Cosserat glide layer widened so
# that the blocks of 2, 3 and 4 ranks cut its constrained bottom (split along x, or 2 × 2): a multiplier node on
# two ranks' faces is owned by the lower one; the summed dofs (multipliers included) and nnz are the serial ones
REFERENCE=umfpack serial "$work/glide" tests/decks/parallel/glide.cfg
for np in $(ranks 1 2 3 4); do
  distributed "$np" "$work/glide-$np" tests/decks/parallel/glide.cfg --set solver.petsc=\"mumps\"
  same "$work/glide" "$work/glide-$np" "$np" 1e-10
  equal_keys "$work/glide" "$work/glide-$np" dofs nnz
done
ok "glide: dofs and nnz (multiplier nodes included) as serially at P = 1-4"
# GAMG cannot precondition the saddle point: refused (exit 2) with the remedy
expect_failure 2 'the Lagrange multipliers make the tangent a saddle point' -- "${MPIRUN[@]}" -np 2 "$MICA" run \
  tests/decks/parallel/glide.cfg -o "$work/glide-gamg" "${Q[@]}" "${D[@]}" --set solver.petsc=\"gamg\"

# a rank lays out its own block: jittered particles from their own draws of the counter-based stream, graded ones
# with the whole layout's spacings and radii near the block's edge (MUMPS at P = 2, 3, 4)
check_layout() {
  local name=$1 deck=$2; shift 2
  serial "$work/$name" "$deck" "$@"
  for np in $(ranks 2 3 4); do
    distributed "$np" "$work/$name-$np" "$deck" "$@"
    same "$work/$name" "$work/$name-$np" "$np" 1e-10
  done
}
# (the supports of both are sized on the grid; quadrature.vci = false: the uncorrected Gauss rule)
check_layout jittered tests/decks/parallel/cook.cfg --set "particles.count=[9,9]" --set solver.steps=2 \
  --set particles.layout=\"jittered\" --set particles.seed=7 --set quadrature.vci=false

# VCI (quadrature.vci = auto: on for jittered particles, serially and distributed): each particle's Gram matrix and
# right-hand sides summed at its owner over the ranks its support reaches, solved there, ξ sent to the ghosts. The
# tangent is unsymmetric: MUMPS's LU at P = 1-4 within 1e-10 of the serial cholmod-sym run (refined to round-off),
# GMRES with GAMG and with gmg within 1e-7; and the 3-D jittered cube (boundary faces' sums) with MUMPS at P = 2, 4
check_vci() {
  local name=$1 ranks=$2 deck=$3; shift 3
  REFERENCE=cholmod-sym serial "$work/$name" "$deck" "$@"
  [ "$(json_value vci "$work/$name/summary.json")" = true ] || fail "$name: VCI is not on serially"
  for np in $ranks; do
    distributed "$np" "$work/$name-$np" "$deck" "$@" --set solver.petsc=\"mumps\"
    [ "$(json_value vci "$work/$name-$np/summary.json")" = true ] || fail "$name-$np: VCI is not on"
    same "$work/$name" "$work/$name-$np" "$np" 1e-10
  done
}
jittered=(--set "particles.count=[9,9]" --set solver.steps=2 --set particles.layout=\"jittered\" --set particles.seed=7)
check_vci vci "$(ranks 1 2 3 4)" tests/decks/parallel/cook.cfg "${jittered[@]}"
for np in $(ranks 2 4); do
  for preset in gamg gmg; do # gmg: GMRES, its coarse operators the "backend" PᵀAP of the unsymmetric tangent
    distributed "$np" "$work/vci-$np-$preset" tests/decks/parallel/cook.cfg "${jittered[@]}" \
      --set solver.petsc=\"$preset\" --set solver.linear_rtol=1e-12
    same "$work/vci" "$work/vci-$np-$preset" "$np" 1e-7
    # the Krylov solves reach their tolerance in truth (GMRES smoothers need flexible GMRES outside: with plain
    # GMRES the true residual stayed at 2e-2 and Newton took 29 iterations), so Newton takes the direct run's steps
    at_most "$(json_value krylov_last_residual "$work/vci-$np-$preset/summary.json")" 1e-10 "vci-$np-$preset: true residual"
    [ "$(json_value newton_iterations "$work/vci-$np-$preset/summary.json")" = "$(json_value newton_iterations "$work/vci/summary.json")" ] \
      || fail "vci-$np-$preset: $(json_value newton_iterations "$work/vci-$np-$preset/summary.json") Newton iterations, the direct run $(json_value newton_iterations "$work/vci/summary.json")"
  done
done
check_vci vci_cube "$(ranks 2 4)" tests/decks/parallel/cube.cfg --set "particles.count=[6,6,6]" --set quadrature.order=3 \
  --set particles.layout=\"jittered\" --set particles.seed=3
check_layout graded tests/decks/parallel/cube.cfg --set "particles.count=[7,6,6]" --set quadrature.order=3 \
  --set particles.layout=\"graded\" --set "particles.grading=[4.0]" --set mls.spacing=\"far\"
# the irregular layout (VCI on): every rank draws the Poisson-disk tiles around its source box (the particles whose
# nearest grid point lies in the box, as the whole layout has them), sized on those grid points as serially, its
# ghosts numbered by their owners — Cook (with its output mesh) at P = 1-4 and at 50 × 50 (3 × 3 tiles of 16: the
# ranks draw different tiles; the serial count) at P = 3, 4, the 3-D cube with the error norms' own points and the
# plate with a hole (a curved map) at P = 2, 4
check_vci irregular "$(ranks 1 2 3 4)" tests/decks/parallel/cook.cfg --set "particles.count=[9,9]" --set solver.steps=2 \
  --set particles.layout=\"irregular\" --set particles.seed=5 --set output.mesh=true
# NSNI on the irregular layout (each owned particle's cell the Gauss points nearest to it, from the cells within 3 of
# the rank's block): Cook at finite strain (the frame-invariant stabilization, Petrov–Galerkin VCI; serial UMFPACK)
# at P = 2-4, and the 3-D cube (linear basis: symmetric VCI, the Hessians' wider supports; serial CHOLMOD) at P = 2, 4
nsni_irregular=(--set "particles.count=[17,17]" --set solver.steps=2 --set particles.layout=\"irregular\"
                --set particles.seed=3 --set quadrature.mode=\"nsni\")
REFERENCE=umfpack serial "$work/irregular_nsni" tests/decks/parallel/cook.cfg "${nsni_irregular[@]}" \
  --set solver.linear=\"umfpack\"
for np in $(ranks 2 3 4); do
  distributed "$np" "$work/irregular_nsni-$np" tests/decks/parallel/cook.cfg "${nsni_irregular[@]}" --set solver.petsc=\"mumps\"
  same "$work/irregular_nsni" "$work/irregular_nsni-$np" "$np" 1e-10
  equal_keys "$work/irregular_nsni" "$work/irregular_nsni-$np" particles quadrature_points dofs nnz
done
nsni_cube=(--set "particles.count=[7,6,6]" --set particles.layout=\"irregular\" --set particles.seed=3
           --set quadrature.mode=\"nsni\" --set quadrature.order=4)
serial "$work/irregular_nsni_cube" tests/decks/parallel/cube.cfg "${nsni_cube[@]}"
[ "$(json_value vci_symmetric "$work/irregular_nsni_cube/summary.json")" = true ] || fail "irregular_nsni_cube: not symmetric"
for np in $(ranks 2 4); do
  distributed "$np" "$work/irregular_nsni_cube-$np" tests/decks/parallel/cube.cfg "${nsni_cube[@]}" --set solver.petsc=\"mumps\"
  same "$work/irregular_nsni_cube" "$work/irregular_nsni_cube-$np" "$np" 1e-10
done
tiles=(--set "particles.count=[50,50]" --set solver.steps=1 --set particles.layout=\"irregular\" --set particles.seed=2)
REFERENCE=umfpack serial "$work/irregular_tiles" tests/decks/parallel/cook.cfg "${tiles[@]}" --set solver.linear=\"umfpack\"
for np in $(ranks 3 4); do
  distributed "$np" "$work/irregular_tiles-$np" tests/decks/parallel/cook.cfg "${tiles[@]}" --set solver.petsc=\"mumps\"
  same "$work/irregular_tiles" "$work/irregular_tiles-$np" "$np" 1e-10
  equal_keys "$work/irregular_tiles" "$work/irregular_tiles-$np" particles dofs nnz
done
check_vci irregular_cube "$(ranks 2 4)" tests/decks/parallel/cube.cfg --set "particles.count=[7,6,6]" --set quadrature.order=3 \
  --set particles.layout=\"irregular\" --set particles.seed=3 --set quadrature.error_order=3
check_vci irregular_hole "$(ranks 2 4)" input/plate_hole.cfg --set particles.layout=\"irregular\" --set particles.seed=2 \
  --set "particles.count=[17,11]" --set 'output.probes=()'

# ---- probes: evaluated by the lowest rank holding the point's whole support, broadcast ----------------------------
# probe_same SERIAL OTHER KEY...: each probe of OTHER's summary within 1e-10 (relative) of SERIAL's
probe_same() {
  local ref=$1 dir=$2; shift 2
  for key in "$@"; do
    local a b
    a=$(json_value "$key" "$ref/summary.json"); b=$(json_value "$key" "$dir/summary.json")
    [ -n "$a" ] && [ -n "$b" ] || fail "probe $key missing in $ref or $dir"
    awk -v a="$a" -v b="$b" 'BEGIN { d = a - b; if (d < 0) d = -d; s = a < 0 ? -a : a; exit !(d <= 1e-10 * s) }' \
      || fail "$dir: probe $key = $b, serial $a: not within 1e-10"
  done
  ok "$(basename "$dir"): probes $* within 1e-10 of the serial run"
}
# check_probes NAME RANKS DECK KEYS [--set ...]
check_probes() {
  local name=$1 ranks=$2 deck=$3 keys=$4; shift 4
  serial "$work/$name" "$deck" "$@"
  for np in $ranks; do
    distributed "$np" "$work/$name-$np" "$deck" "$@" --set solver.petsc=\"mumps\"
    probe_same "$work/$name" "$work/$name-$np" $keys
  done
}
# Cook's tip (a corner of the body), a stress inside, the strain energy (a sum over the ranks' points)
check_probes probe_cook "$(ranks 2 3 4)" input/cook_neohooke.cfg "tip_uy mid_sxx energy" --set "particles.count=[9,9]" \
  --set solver.steps=4 --set output.vtu=false --set 'output.probes=({ name = "tip_uy"; point = [48.0, 60.0]; field = "uy"; },
  { name = "mid_sxx"; point = [30.0, 40.0]; field = "sxx"; }, { name = "energy"; field = "energy"; })'
# the cube's corner and its centre (on the interfaces of the 2 × 2 blocks at P = 4)
check_probes probe_cube "$(ranks 2 4)" input/cube3d.cfg "corner_ux centre_uy" --set "particles.count=[6,6,6]" \
  --set quadrature.order=3 --set output.vtu=false --set 'output.probes=({ name = "corner_ux"; point = [1.0, 1.0, 1.0];
  field = "ux"; }, { name = "centre_uy"; point = [0.5, 0.5, 0.5]; field = "uy"; })'
# the glide layer's own probes (blocks along y: the top and the middle on different ranks; multipliers on rank 0)
REFERENCE=umfpack check_probes probe_glide "$(ranks 2 3 4)" input/cosserat_glide.cfg "phi_top ux_top phi_mid ux_mid" \
  --set output.vtu=false
# with VCI (jittered)
REFERENCE=cholmod-sym check_probes probe_vci "$(ranks 2 4)" tests/decks/parallel/cook.cfg "p_ux" "${jittered[@]}" --set output.vtu=false \
  --set 'output.probes=({ name = "p_ux"; point = [24.0, 50.0]; field = "ux"; })'

# ---- error norms on quadrature.error_order's own points: each rank's in its cells (their supports in its ghosts) --
serial "$work/error_order" tests/decks/cosserat/nitsche.cfg --set quadrature.error_order=8
for np in $(ranks 2 4); do
  distributed "$np" "$work/error_order-$np" tests/decks/cosserat/nitsche.cfg --set quadrature.error_order=8 \
    --set solver.petsc=\"mumps\"
  same "$work/error_order" "$work/error_order-$np" "$np" 1e-10
  equal_keys "$work/error_order" "$work/error_order-$np" error_points multiplier_nodes
  for key in error_h1 error_energy; do
    awk -v a="$(json_value $key "$work/error_order/summary.json")" -v b="$(json_value $key "$work/error_order-$np/summary.json")" \
      'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 1e-10) }' || fail "error_order-$np: $key not within 1e-10"
  done
done
ok "error norms with quadrature.error_order = 8 as serially at P = 2, 4"

# ---- nodal quadrature on distributed data ------------------------------------------------------------------
# Each rank builds the nodal cells of its own particles (mica_discretization_nodal_block): NSNI's points at their
# centroids, SCNI's boundary points, the boundary sets on the cells' faces (multiplier vertices named by the dual
# grid's corners). Against the plain serial run where both take the same VCI form (a quadratic basis:
# Petrov–Galerkin): NSNI on jittered Cook (Neo-Hooke, 2 steps) at P = 1-4 with MUMPS within 1e-10 and with gmg
# (GMRES) at P = 2, 4 within 1e-7, and the 3-D cube at P = 2, 4; SCNI (linear basis, jittered) on Cook and the cube
# and direct nodal integration on Cook at P = 2, 4; NSNI with Lagrange multipliers on the glide layer at P = 2, 4
# against serial UMFPACK. A linear basis's NSNI takes the symmetric VCI (one correction of trial and test gradients,
# a global system: CHOLMOD serially, MUMPS over the ranks): jittered Cook at P = 2, 3, 4 and the jittered cube at
# P = 2, 4 within 1e-10 of the serial CHOLMOD run, the cube with gmg (CG: the tangent is symmetric) within 1e-7,
# each run saying "VCI: symmetric"; on the regular cube the symmetric system has no solution and every rank falls
# back to the Petrov–Galerkin form as serially (1e-10, no "VCI: symmetric"). The counts at P = 4 sum to the serial
# ones.
NS=(--set quadrature.mode=\"nsni\" --set particles.layout=\"jittered\")
COOK9=(--set "particles.count=[9,9]" --set solver.steps=2)
REFERENCE=umfpack serial "$work/nsni" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${NS[@]}"
for np in $(ranks 1 2 3 4); do
  distributed "$np" "$work/nsni-$np" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${NS[@]}" --set solver.petsc=\"mumps\"
  same "$work/nsni" "$work/nsni-$np" "$np" 1e-10
done
for np in $(ranks 2 4); do
  distributed "$np" "$work/nsni-gmg-$np" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${NS[@]}" --set solver.petsc=\"gmg\" \
    --set solver.linear_rtol=1e-12
  same "$work/nsni" "$work/nsni-gmg-$np" "$np" 1e-7
done
CUBE=(--set "particles.count=[6,6,6]")
CUBE2=("${CUBE[@]}" --set mls.order=2) # a quadratic basis: Petrov–Galerkin VCI serially too (cholmod-sym stalls on it)
SC=(--set quadrature.mode=\"scni\" --set particles.layout=\"jittered\" --set mls.order=1 --set mls.dilation=2.0)
REFERENCE=umfpack serial "$work/nsni-cube" tests/decks/parallel/cube.cfg "${CUBE2[@]}" "${NS[@]}" --set solver.linear=\"umfpack\"
serial "$work/scni" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${SC[@]}"
serial "$work/scni-cube" tests/decks/parallel/cube.cfg "${CUBE[@]}" "${SC[@]}"
serial "$work/dni" tests/decks/parallel/cook.cfg "${COOK9[@]}" --set quadrature.mode=\"nodal\"
REFERENCE=umfpack serial "$work/nsni-glide" tests/decks/parallel/glide.cfg --set quadrature.mode=\"nsni\"
for np in $(ranks 2 4); do
  distributed "$np" "$work/nsni-cube-$np" tests/decks/parallel/cube.cfg "${CUBE2[@]}" "${NS[@]}" --set solver.petsc=\"mumps\"
  same "$work/nsni-cube" "$work/nsni-cube-$np" "$np" 1e-10
  distributed "$np" "$work/scni-$np" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${SC[@]}" --set solver.petsc=\"mumps\"
  same "$work/scni" "$work/scni-$np" "$np" 1e-10
  distributed "$np" "$work/scni-cube-$np" tests/decks/parallel/cube.cfg "${CUBE[@]}" "${SC[@]}" --set solver.petsc=\"mumps\"
  same "$work/scni-cube" "$work/scni-cube-$np" "$np" 1e-10
  distributed "$np" "$work/dni-$np" tests/decks/parallel/cook.cfg "${COOK9[@]}" --set quadrature.mode=\"nodal\" \
    --set solver.petsc=\"mumps\"
  same "$work/dni" "$work/dni-$np" "$np" 1e-10
  distributed "$np" "$work/nsni-glide-$np" tests/decks/parallel/glide.cfg --set quadrature.mode=\"nsni\" --set solver.petsc=\"mumps\"
  same "$work/nsni-glide" "$work/nsni-glide-$np" "$np" 1e-10
done
L1=(--set mls.order=1 --set mls.dilation=2.0)
symmetric() { # symmetric DIR YES: the run's log says "VCI: symmetric" (YES = 1) or not (0)
  local n; n=$(grep -c "VCI: symmetric" "$1.log")
  [ "$n" = "$2" ] || fail "$1: \"VCI: symmetric\" printed $n times, expected $2"
}
serial "$work/nsni1" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${NS[@]}" "${L1[@]}"
symmetric "$work/nsni1" 1
for np in $(ranks 2 3 4); do
  distributed "$np" "$work/nsni1-$np" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${NS[@]}" "${L1[@]}" --set solver.petsc=\"mumps\"
  symmetric "$work/nsni1-$np" 1
  same "$work/nsni1" "$work/nsni1-$np" "$np" 1e-10
done
serial "$work/nsni1-cube" tests/decks/parallel/cube.cfg "${CUBE[@]}" "${NS[@]}"
REFERENCE=cholmod-sym serial "$work/nsni1-regular" tests/decks/parallel/cube.cfg "${CUBE[@]}" --set quadrature.mode=\"nsni\"
symmetric "$work/nsni1-cube" 1
symmetric "$work/nsni1-regular" 0
for np in $(ranks 2 4); do
  distributed "$np" "$work/nsni1-cube-$np" tests/decks/parallel/cube.cfg "${CUBE[@]}" "${NS[@]}" --set solver.petsc=\"mumps\"
  symmetric "$work/nsni1-cube-$np" 1
  same "$work/nsni1-cube" "$work/nsni1-cube-$np" "$np" 1e-10
  distributed "$np" "$work/nsni1-regular-$np" tests/decks/parallel/cube.cfg "${CUBE[@]}" --set quadrature.mode=\"nsni\" \
    --set solver.petsc=\"mumps\"
  symmetric "$work/nsni1-regular-$np" 0
  same "$work/nsni1-regular" "$work/nsni1-regular-$np" "$np" 1e-10
done
distributed 2 "$work/nsni1-cube-gmg" tests/decks/parallel/cube.cfg "${CUBE[@]}" "${NS[@]}" --set solver.petsc=\"gmg\" \
  --set solver.linear_rtol=1e-12
same "$work/nsni1-cube" "$work/nsni1-cube-gmg" 2 1e-7
python3 - "$work/nsni-1/summary.json" "$work/nsni-$(ranks 1 2 3 4 | awk '{ print $NF }')/summary.json" <<'EOF' || fail "NSNI counts per rank: see above"
import json, sys
s, p = (json.load(open(f)) for f in sys.argv[1:3])
for key, total in (("rank_particles_owned", "particles"), ("rank_points", "quadrature_points"),
                   ("rank_boundary_points", "boundary_points")):
    ok = sum(p[key]) == s[total] and max(p[key]) < s[total]
    print(("ok: " if ok else "FAIL: ") + f"NSNI {key} {p[key]} sum to the one-process {total} {s[total]}, each below")
    if not ok: sys.exit(1)
EOF
ok "nodal quadrature (NSNI, SCNI, direct) on distributed data: as serially at P = 1-4"

# ---- axisymmetric sections on distributed data ----------------------------------------------------------------
# each rank revolves its own points (weights × 2πr: volume, boundary and error points): the Lamé cylinder (Lagrange
# multipliers, a probe at the bore) at P = 2, 4 with MUMPS within 1e-10 of the serial UMFPACK run, its error norm
# on quadrature.error_order's points (each rank's cells, revolved) within 1e-10
AX=(--set "particles.count=[17,8]" --set quadrature.error_order=7)
REFERENCE=umfpack serial "$work/lame" input/lame_axisymmetric.cfg "${AX[@]}"
for np in $(ranks 2 4); do
  distributed "$np" "$work/lame-$np" input/lame_axisymmetric.cfg "${AX[@]}" --set solver.petsc=\"mumps\"
  same "$work/lame" "$work/lame-$np" "$np" 1e-10
  awk -v a="$(json_value ur_inner "$work/lame/summary.json")" -v b="$(json_value ur_inner "$work/lame-$np/summary.json")" \
    'BEGIN { d = (a - b) / a; if (d < 0) d = -d; exit !(d <= 1e-10) }' || fail "lame-$np: probe ur_inner differs"
done
ok "axisymmetric Lamé cylinder on distributed data: fields, error norm and probe as serially at P = 2, 4"

# ---- an adaptive weight on distributed data ---------------------------------------------------------------------
# the exponential weight's shape parameter at a particle comes from the particles whose supports cover it: each
# rank takes its box's (mls_set_weight_params), which the box's margin covers, not its own truncated neighborhood's
# (that moved the fields by 7e-8 at P = 4): jittered Cook at P = 2, 4 with MUMPS within 1e-10 of serial UMFPACK
EX=(--set "particles.count=[11,11]" --set solver.steps=2 --set mls.weight=\"exponential\" --set mls.alpha=0.3
    --set particles.layout=\"jittered\")
REFERENCE=umfpack serial "$work/exponential" tests/decks/parallel/cook.cfg "${EX[@]}" --set solver.linear=\"umfpack\"
for np in $(ranks 2 4); do
  distributed "$np" "$work/exponential-$np" tests/decks/parallel/cook.cfg "${EX[@]}" --set solver.petsc=\"mumps\"
  same "$work/exponential" "$work/exponential-$np" "$np" 1e-10
done
ok "the exponential (adaptive) weight on distributed data: as serially at P = 2, 4"

# ---- the output mesh and the quadrature fields on distributed data ----------------------------------------------
# each rank writes the mesh of its block of cells (mesh_NNNN_R.vtu; its points' supports are in its ghosts) and rank
# 0 the .pvtu of all P pieces; quadrature_fields.csv gets the ranks' rows in rank order. Cook (Neo-Hooke, 2 steps,
# bent edges: biquadratic cells) and the cube (hexahedra) at P = 2, 4 with MUMPS against the serial run: every mesh
# point and row within 1e-10, the pieces' cells summing to the serial mesh's
MO=(--set output.mesh=true --set output.quadrature_fields=true --set quadrature.error_order=4)
serial "$work/mesh" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${MO[@]}"
serial "$work/mesh-cube" tests/decks/parallel/cube.cfg "${CUBE[@]}" "${MO[@]}"
for np in $(ranks 2 4); do
  for deck in mesh:cook mesh-cube:cube; do
    name=${deck%%:*} file=tests/decks/parallel/${deck#*:}.cfg
    [ "$name" = mesh ] && size=("${COOK9[@]}") || size=("${CUBE[@]}")
    distributed "$np" "$work/$name-$np" "$file" "${size[@]}" "${MO[@]}" --set solver.petsc=\"mumps\"
    python3 tests/cli/mesh_pieces_compare.py "$work/$name" "$work/$name-$np" "$np" --tol 1e-10 > "$work/$name-$np.mesh" 2>&1 \
      || fail "$name-$np: $(tail -n 2 "$work/$name-$np.mesh")"
    python3 tests/cli/quadrature_rows_compare.py "$work/$name" "$work/$name-$np" --tol 1e-10 > "$work/$name-$np.rows" 2>&1 \
      || fail "$name-$np: $(tail -n 2 "$work/$name-$np.rows")"
    ok "$name-$np: $(tail -n 1 "$work/$name-$np.mesh" | cut -c5-); quadrature fields: $(cut -c5- "$work/$name-$np.rows")"
  done
done

# ---- collocation on distributed data ---------------------------------------------------------------------------
# the rows of a particle at a constrained vertex are emptied on every rank that holds it (its volume terms there)
# and written by the ranks whose faces have the vertex, each its share; the last condition at a particle writes its
# rows, as serially. Cook (Neo-Hooke, 2 steps) and the cube at P = 2, 3, 4 with MUMPS against serial UMFPACK
COL=(--set bc.method=\"collocation\")
REFERENCE=umfpack serial "$work/collocation" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${COL[@]}"
REFERENCE=umfpack serial "$work/collocation-cube" tests/decks/parallel/cube.cfg "${CUBE[@]}" "${COL[@]}"
for np in $(ranks 2 3 4); do
  distributed "$np" "$work/collocation-$np" tests/decks/parallel/cook.cfg "${COOK9[@]}" "${COL[@]}" --set solver.petsc=\"mumps\"
  same "$work/collocation" "$work/collocation-$np" "$np" 1e-10
  distributed "$np" "$work/collocation-cube-$np" tests/decks/parallel/cube.cfg "${CUBE[@]}" "${COL[@]}" --set solver.petsc=\"mumps\"
  same "$work/collocation-cube" "$work/collocation-cube-$np" "$np" 1e-10
done
ok "collocation on distributed data: as serially at P = 2-4"

# ---- no rank holds the whole problem -----------------------------------------------------------------------
medium=(--set "particles.count=[12,12,12]" --set quadrature.order=2 --set output.vtu=false)
serial "$work/medium" tests/decks/parallel/cube.cfg "${medium[@]}"
distributed 4 "$work/medium-4" tests/decks/parallel/cube.cfg "${medium[@]}"
# rank_counts SERIAL DIST [BLOCKS]: the 4 ranks' counts (owned particles, volume and boundary points) sum to the serial
# run's, each below 0.3 of it; the summed nnz and dofs are the serial ones; each rank holds (owned + ghosts) fewer than
# 0.6 of the particles; BLOCKS (sorted, e.g. 1,2,2): the split's blocks per axis
rank_counts() {
  python3 - "$1/summary.json" "$2/summary.json" "${3:-}" <<'EOF' || fail "counts per rank of $2: see above"
import json, sys
s, p = (json.load(open(f)) for f in sys.argv[1:3])
def check(cond, what):
    print(("ok: " if cond else "FAIL: ") + what)
    if not cond: sys.exit(1)
for key in ("particles", "quadrature_points", "boundary_points", "nnz", "dofs"):
    check(p[key] == s[key], f"{key}: {p[key]} in the distributed run, {s[key]} serially")
for key, total in (("rank_particles_owned", "particles"), ("rank_points", "quadrature_points"),
                   ("rank_boundary_points", "boundary_points")):
    check(sum(p[key]) == s[total], f"{key} {p[key]} sum to the serial {total} {s[total]}")
    check(max(p[key]) < 0.3 * s[total], f"{key}: each rank below 0.3 of the whole {s[total]}")
if sys.argv[3]:
    check(sorted(p["parallel_blocks"]) == [int(b) for b in sys.argv[3].split(",")], f"blocks {p['parallel_blocks']}")
held = p["rank_particles_local"]
check(len(held) == 4 and max(held) < 0.6 * s["particles"],
      f"particles held per rank (owned + ghosts) {held}: each below 0.6 of {s['particles']}")
EOF
}
# the split of 4 ranks over 11³ cells: two axes halved has 2 · 121 interface faces, one axis in 4 has 3 · 121
rank_counts "$work/medium" "$work/medium-4" 1,2,2

# ---- Gmsh meshes: coordinate boxes of equal particle counts, elements by their centroids ---------------------
# Kirsch's plate from plate_hole.msh (VCI on: Gauss cells off a grid; MUMPS's LU) at P = 1-4, its output mesh in
# pieces, the SCF probe; with Lagrange multipliers (named by their nodes' indices in the whole mesh) at P = 2, 3
# against UMFPACK with the serial dofs and nnz; the 3-D cube of cube.geo (meshed by the Gmsh library on rank 0 into a
# .msh file, whose regions the ranks read) at P = 2-4 with MUMPS and at P = 2, 4 with GAMG, with the error norms' own points (quadrature.error_order)
REFERENCE=cholmod-sym serial "$work/kirsch" input/plate_hole_gmsh.cfg --set output.mesh=true
for np in $(ranks 1 2 3 4); do
  distributed "$np" "$work/kirsch-$np" input/plate_hole_gmsh.cfg --set output.mesh=true --set solver.petsc=\"mumps\"
  same "$work/kirsch" "$work/kirsch-$np" "$np" 1e-10
  [ "$np" = 1 ] || probe_same "$work/kirsch" "$work/kirsch-$np" scf
done
# a probe's point is checked against the ranks' parts (no rank reads the whole mesh for it): outside all of them, the
# serial message with the whole body's bounds, once, exit 2
expect_failure 2 "probe 'out' at (0.5, 0.5) lies outside the body, the elements of input/meshes/plate_hole.msh (bounds x in [0, 5], y in [0, 5])" -- \
  "${MPIRUN[@]}" -np 3 "$MICA" run input/plate_hole_gmsh.cfg -o "$work/kirsch_out" "${Q[@]}" "${D[@]}" \
  --set 'output.probes=({ name = "out"; point = ["0.5", "0.5"]; field = "sxx"; })'
[ ! -e "$work/kirsch_out" ] || fail "the refused probe left $work/kirsch_out"
# the cost guard from the reader's first pass (no rank reads the whole mesh for it): the serial estimate with the
# same solver, and its refusal at the deck's line
"$MICA" check input/plate_hole_gmsh.cfg -o "$work/kirsch_estimate" "${Q[@]}" --set solver.linear=\"petsc\" \
  > "$work/kirsch_estimate.log" 2>&1 || fail "kirsch_estimate: $(tail -n 2 "$work/kirsch_estimate.log")"
"${MPIRUN[@]}" -np 2 "$MICA" check input/plate_hole_gmsh.cfg -o "$work/kirsch_estimate-2" "${Q[@]}" "${D[@]}" \
  > "$work/kirsch_estimate-2.log" 2>&1 || fail "kirsch_estimate-2: $(tail -n 2 "$work/kirsch_estimate-2.log")"
a=$(json_value estimate_memory "$work/kirsch_estimate/summary.json"); b=$(json_value estimate_memory "$work/kirsch_estimate-2/summary.json")
[ -n "$a" ] && [ "$a" = "$b" ] || fail "the distributed Gmsh estimate $b, serially $a"
ok "the distributed Gmsh deck's estimate is the serial one ($a bytes)"
expect_failure 2 "plate_hole_gmsh.cfg:9: geometry.mesh = \"meshes/plate_hole.msh\" needs about" -- \
  "${MPIRUN[@]}" -np 2 "$MICA" check input/plate_hole_gmsh.cfg -o "$work/kirsch_guard" "${Q[@]}" "${D[@]}" \
  --set limits.memory_gb=0.001
REFERENCE=umfpack serial "$work/kirsch_lagrange" input/plate_hole_gmsh.cfg --set bc.method=\"lagrange\"
for np in $(ranks 2 3); do
  distributed "$np" "$work/kirsch_lagrange-$np" input/plate_hole_gmsh.cfg --set bc.method=\"lagrange\" \
    --set solver.petsc=\"mumps\"
  same "$work/kirsch_lagrange" "$work/kirsch_lagrange-$np" "$np" 1e-10
  equal_keys "$work/kirsch_lagrange" "$work/kirsch_lagrange-$np" dofs nnz
done
REFERENCE=cholmod-sym serial "$work/cube_gmsh" tests/decks/parallel/cube_gmsh.cfg --set quadrature.error_order=3
for np in $(ranks 2 3 4); do
  distributed "$np" "$work/cube_gmsh-$np" tests/decks/parallel/cube_gmsh.cfg --set quadrature.error_order=3 \
    --set solver.petsc=\"mumps\"
  same "$work/cube_gmsh" "$work/cube_gmsh-$np" "$np" 1e-10
  # one rank had Gmsh mesh the .geo (the others read their regions of the .msh it wrote), and the file is gone
  [ "$(json_value gmsh_meshings "$work/cube_gmsh-$np/summary.json")" = 1 ] \
    || fail "cube_gmsh-$np: the .geo meshed $(json_value gmsh_meshings "$work/cube_gmsh-$np/summary.json") times"
  ! ls -A "$work/cube_gmsh-$np" | grep -q '\.msh$' || fail "cube_gmsh-$np: the .geo's .msh was left among the results"
done
ok "the .geo meshed once, by rank 0, at P = 2-4"
# a .geo that Gmsh cannot mesh under mpirun: rank 0's error, reported once, exit 2, nothing left
printf 'Point(1) = {0, 0, 0, 1};\nLine(1) = {1, 2};\n' > "$work/broken.geo"
"${MPIRUN[@]}" -np 3 "$MICA" run tests/decks/parallel/cube_gmsh.cfg -o "$work/broken" "${Q[@]}" "${D[@]}" \
  --set geometry.mesh=\"$work/broken.geo\" > "$work/broken.log" 2> "$work/broken.err"; rc=$?
[ "$rc" = 2 ] || fail "a broken .geo under mpirun: exit $rc, expected 2: $(cat "$work/broken.err")"
[ "$(grep -c 'broken.geo' "$work/broken.err")" = 1 ] || fail "a broken .geo: not reported once: $(cat "$work/broken.err")"
[ ! -e "$work/broken" ] || fail "a broken .geo left $work/broken"
ok "a broken .geo under mpirun: exit 2, reported once, nothing left"
for np in 2 4; do # 4: rank_counts below
  distributed "$np" "$work/cube_gmsh-$np-gamg" tests/decks/parallel/cube_gmsh.cfg --set quadrature.error_order=3 \
    --set solver.petsc=\"gamg\" --set solver.linear_rtol=1e-12
  same "$work/cube_gmsh" "$work/cube_gmsh-$np-gamg" "$np" 1e-7
done
rank_counts "$work/cube_gmsh" "$work/cube_gmsh-4-gamg"
# NSNI on a Gmsh mesh (cells from the Gauss points nearest to each particle, each rank from the elements around its
# box): Kirsch (quadratic basis, Petrov–Galerkin VCI; serial UMFPACK) at P = 2-4 and the cube of cube.geo (linear
# basis: symmetric VCI with MUMPS over the ranks, the Hessians' wider supports; serial CHOLMOD) at P = 2, 4
REFERENCE=umfpack serial "$work/kirsch_nsni" input/plate_hole_gmsh.cfg --set quadrature.mode=\"nsni\"
for np in $(ranks 2 3 4); do
  distributed "$np" "$work/kirsch_nsni-$np" input/plate_hole_gmsh.cfg --set quadrature.mode=\"nsni\" --set solver.petsc=\"mumps\"
  same "$work/kirsch_nsni" "$work/kirsch_nsni-$np" "$np" 1e-10
done
serial "$work/cube_gmsh_nsni" tests/decks/parallel/cube_gmsh.cfg --set quadrature.mode=\"nsni\"
[ "$(json_value vci_symmetric "$work/cube_gmsh_nsni/summary.json")" = true ] || fail "cube_gmsh_nsni: not the symmetric VCI"
for np in $(ranks 2 4); do
  distributed "$np" "$work/cube_gmsh_nsni-$np" tests/decks/parallel/cube_gmsh.cfg --set quadrature.mode=\"nsni\" \
    --set solver.petsc=\"mumps\"
  same "$work/cube_gmsh_nsni" "$work/cube_gmsh_nsni-$np" "$np" 1e-10
done
# the region reads of a 3-D .msh file (cube.msh) and of a 2.2 file (plate_hole_v22.msh, whose groups live on its
# elements): MUMPS at P = 2-4
sed "s|\"../../../input/meshes/cube.geo\"; mesh_size_factor = 0.5;|\"$PWD/input/meshes/cube.msh\";|" \
  tests/decks/parallel/cube_gmsh.cfg > "$work/cube_msh.cfg"
sed "s|\"meshes/plate_hole.msh\"|\"$PWD/tests/meshes/plate_hole_v22.msh\"|" input/plate_hole_gmsh.cfg > "$work/kirsch_v22.cfg"
grep -q 'cube.msh' "$work/cube_msh.cfg" && grep -q 'plate_hole_v22.msh' "$work/kirsch_v22.cfg" \
  || fail "cube_msh.cfg, kirsch_v22.cfg: the mesh paths were not rewritten"
for deck in cube_msh kirsch_v22; do
  REFERENCE=cholmod-sym serial "$work/$deck" "$work/$deck.cfg"
  for np in $(ranks 2 3 4); do
    distributed "$np" "$work/$deck-$np" "$work/$deck.cfg" --set solver.petsc=\"mumps\"
    same "$work/$deck" "$work/$deck-$np" "$np" 1e-10
  done
done
ok "Gmsh meshes on distributed data: Kirsch (2-D, VCI, Lagrange) and the cube of cube.geo as serially"

# ---- refusals ------------------------------------------------------------------------------------------------
# variant NAME GROUPS...: the cook deck with the group lines appended (particles, quadrature, solver and output:
# 9 x 9 particles, order 5, petsc over one step, no mesh, unless given); prints its path
variant() {
  local name=$1; shift
  local deck="$work/$name.cfg" given="$*"
  {
    grep -v '^particles\|^quadrature\|^solver' tests/decks/parallel/cook.cfg
    for group in 'particles = { count = [9, 9]; };' 'quadrature = { order = 5; };' \
                 'solver = { linear = "petsc"; steps = 1; };' 'output = { mesh = false; };'; do
      [[ " $given" == *" ${group%% *} = "* ]] || echo "$group"
    done
    printf '%s\n' "$@"
  } > "$deck"
  echo "$deck"
}
refuse() { # refuse NAME PATTERN LINES...: exit 2 at -np 2 naming the deck's last line
  local name=$1 pattern=$2; shift 2
  local deck; deck=$(variant "$name" "$@")
  local line; line=$(wc -l < "$deck")
  expect_failure 2 "$deck:$line: $pattern" -- "${MPIRUN[@]}" -np 2 "$MICA" run "$deck" -o "$work/$name" --set output.monitor=false
}
pd='parallel = { data = "distributed"; };'
refuse umfpack 'solver.linear is not available with parallel.data = "distributed"' "$pd" \
  'solver = { linear = "umfpack"; steps = 1; };'
# the nodal modes other than NSNI need the grid's dual cells: refused as serially, at the mode's line
refuse irregular_nodal 'quadrature.mode = "nodal" needs particles on a logical grid' "$pd" \
  'particles = { count = [9, 9]; layout = "irregular"; };' 'quadrature = { mode = "nodal"; };'
# ---- rigid motions: checked on the ranks' shares of the sets, the sums over all ranks --------------------------
# Cook's membrane with ux alone on its left edge leaves the translation in y free. At P = 2, 3 some ranks hold none
# of that edge's points and the others part of it (no rank builds a whole set); the message is the serial one,
# printed once, exit 2 on every rank. The held direction: the 12³ cube at P = 4 below (blocks 1 × 2 × 2: two ranks
# hold none of the face y = 0, where uy is held; without the sums they stop with "translation in y" free).
free_deck="$work/free.cfg"
sed 's/ux = "0"; uy = "0";/ux = "0";/' tests/decks/parallel/cook.cfg > "$free_deck"
grep -q 'set = "left"; ux = "0"; }' "$free_deck" || fail "free.cfg: the left edge's condition was not rewritten"
free_message='the body can move freely: 1 rigid mode is not held (translation in y); add Dirichlet conditions on uy'
expect_failure 2 "$free_message" -- "$MICA" run "$free_deck" -o "$work/free-1" "${Q[@]}" "${D[@]}"
for np in $(ranks 2 3); do
  err=$("${MPIRUN[@]}" -np "$np" "$MICA" run "$free_deck" -o "$work/free-$np" "${Q[@]}" "${D[@]}" \
    --set "particles.count=[9,9]" --set solver.steps=1 2>&1 >/dev/null); rc=$?
  [ "$rc" = 2 ] || fail "np $np: the free body exited $rc, expected 2; stderr: $err"
  grep -qF -- "$free_message" <<<"$err" || fail "np $np: stderr lacks '$free_message': $err"
  count=$(grep -c 'can move freely' <<<"$err")
  [ "$count" = 1 ] || fail "np $np: the free-body message printed $count times, not once"
  [ ! -e "$work/free-$np" ] || [ -z "$(ls -A "$work/free-$np")" ] || fail "np $np: the refused run left files"
done
ok "rigid motions summed over the ranks' shares of the boundary sets (P = 2, 3)"

# serially too: a distributed deck means the same on one process
expect_failure 2 '--set problem.method="fe": problem.method is not available with parallel.data = "distributed"' -- \
  "$MICA" run tests/decks/parallel/cook.cfg -o "$work/serial_fe" --set parallel.data=\"distributed\" --set problem.method=\"fe\"
[ ! -e "$work/serial_fe" ] || fail "the refused FE run left $work/serial_fe"
ok "parallel.data = distributed"
