# quadrature.mode = "nsni" (naturally stabilized nodal integration with VCI; docs/theory.md §NSNI,
# docs/verification.md §NSNI):
# - patch tests to round-off (L2 and energy ≤ 1e-10; measured 1e-16 – 1e-12), UMFPACK (cholmod-sym, auto's
#   choice for a Petrov–Galerkin tangent, stops at its 1e-10 residual tolerance: 1e-9 on the quadratic patch):
#   linear (input/patch_linear.cfg) and quadratic (input/patch_quadratic.cfg, mls.order 2) in 2-D, the 3-D cube
#   in tension (linear) and the 3-D quadratic patch (tests/decks/nsni/patch_quadratic3d.cfg), the Cosserat linear
#   patch in 2-D (tests/decks/cosserat/patch_nitsche.cfg) and 3-D (tests/decks/nsni/cosserat_patch3d.cfg) and
#   quadratic fields in 2-D (input/cosserat_manufactured.cfg, mls.order 2); regular, jittered and irregular
#   particles each (irregular: cells from the Gauss points nearest to each particle); the linear-basis patches
#   off the grid must take the symmetric VCI (vci_symmetric), on the grid the Petrov–Galerkin one;
# - convergence (input/manufactured.cfg, 21², 41², 81², least-squares slopes): regular order 1 L2 ≥ 1.8
#   (measured 2.11), energy ≥ 0.9 (1.30); regular order 2 L2 ≥ 2.7 (2.81), energy ≥ 1.8 (2.60); jittered
#   order 2 L2 ≥ 2.0 (2.10), energy ≥ 1.8 (2.04); jittered order 1 (symmetric VCI) L2 ≥ 1.8 (1.99), energy
#   ≥ 0.9 (1.09); irregular order 1 L2 ≥ 1.8 (1.97), energy ≥ 0.9 (1.04), order 2 L2 ≥ 1.8 (2.06), energy
#   ≥ 1.8 (2.01). The order-2 L2 rates off the grid are below 0.9 × optimal — the measured limit, kept honest
#   (docs/verification.md §NSNI says what remains); in 3-D (input/manufactured3d.cfg, 7³, 9³, 13³) orders 1
#   and 2 on regular and jittered particles: L2 ≥ 1.8 / 2.7, energy ≥ 0.9 / 1.8 (measured below);
# - the shipped benchmark decks that pass in NSNI (Cook linear and Neo-Hooke, the 3-D tension cube and cylinder,
#   the elastica at k = 1) against solid_benchmarks.sh's references and tolerances;
# - finite-rotation Cosserat by the paired rule: rigid turns in 2-D and 3-D to 1e-8, the rolled strip within the
#   deck's tolerances;
# - bad input, exit 2 with the deck line: a second-order model.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/nsni"
rm -rf "$work" && mkdir -p "$work"
err() { json_value "$2" "$work/$1/summary.json"; }

patch() { # NAME DECK [--set ...]: both errors ≤ 1e-10
  local name=$1 deck=$2; shift 2
  run_deck "$work/$name" "$deck" --set quadrature.mode=nsni --set solver.linear=umfpack "$@"
  less_than "$(err $name error_l2)" 1e-10 || fail "$name: L2 $(err $name error_l2) > 1e-10"
  less_than "$(err $name error_energy)" 1e-10 || fail "$name: energy $(err $name error_energy) > 1e-10"
  grep -q '"vci": true' "$work/$name/summary.json" || grep -q 'quadrature.vci = auto: on' "$work/$name.log" \
    || fail "$name: VCI not on"
  ok "patch, NSNI, $name: L2 $(err $name error_l2), energy $(err $name error_energy)"
}
symmetric() { # NAME true|false: which VCI the patch took
  grep -q "\"vci_symmetric\": $2" "$work/$1/summary.json" || fail "$1: vci_symmetric is not $2"
}
for layout in regular jittered irregular; do
  patch linear_$layout input/patch_linear.cfg --set particles.layout=$layout
  patch quadratic_$layout input/patch_quadratic.cfg --set particles.layout=$layout
  patch cube_$layout input/cube3d.cfg --set particles.layout=$layout
  patch cosserat_linear_$layout tests/decks/cosserat/patch_nitsche.cfg --set particles.layout=$layout
  patch cosserat_quadratic_$layout input/cosserat_manufactured.cfg --set particles.layout=$layout
  patch quadratic3d_$layout tests/decks/nsni/patch_quadratic3d.cfg --set particles.layout=$layout
  patch cosserat_linear3d_$layout tests/decks/nsni/cosserat_patch3d.cfg --set particles.layout=$layout
  want=true && [ $layout = regular ] && want=false
  for name in linear cube cosserat_linear cosserat_linear3d; do symmetric ${name}_$layout $want; done
  for name in quadratic cosserat_quadratic quadratic3d; do symmetric ${name}_$layout false; done
done

# slopes ORDER LAYOUT DIM COUNTS... [--set ...]: "l2 energy" least-squares slopes of the manufactured field
# (input/manufactured.cfg in 2-D, manufactured3d.cfg in 3-D) over the particle counts per side
slopes() {
  local order=$1 layout=$2 dim=$3 l2="" en="" name n deck=input/manufactured.cfg counts=() sets=()
  shift 3
  while [ $# -gt 0 ] && [ "$1" != --set ]; do counts+=("$1"); shift; done
  sets=("$@")
  [ "$dim" = 3 ] && deck=input/manufactured3d.cfg
  for n in "${counts[@]}"; do
    name=mms${dim}d_${order}_${layout}_$n
    local count="[$n, $n]"
    [ "$dim" = 3 ] && count="[$n, $n, $n]"
    run_deck "$work/$name" $deck --set quadrature.mode=nsni --set mls.order=$order \
      --set mls.dilation=$((order + 1)).0 --set particles.layout=$layout --set "particles.count=$count" "${sets[@]}"
    h=$(awk -v n=$n 'BEGIN { print 2 / (n - 1) }')
    l2+="$h $(err $name error_l2)"$'\n'
    en+="$h $(err $name error_energy)"$'\n'
    echo "report: manufactured ${dim}-D, NSNI, order $order, $layout, $n: L2 $(err $name error_l2), energy $(err $name error_energy)" >&2
  done
  echo "$(printf '%s' "$l2" | ls_rate) $(printf '%s' "$en" | ls_rate)"
}
# The convergence studies run the patch tests' code at up to 81² and 13³: 130 of the 151 seconds of the script's
# runs (plain, 2026-12-07), and the script took 668 s under the sanitizers; under SAN=1 they are left to the plain
# run, which asserts them.
if [ "${SAN:-}" != 1 ]; then
rates() { slopes "$1" "$2" 2 21 41 81 --set solver.linear=umfpack; } # ORDER LAYOUT: 21², 41², 81², UMFPACK
read -r l2 en <<<"$(rates 1 regular)"
at_least "$l2" 1.8 "NSNI order 1 regular: L2 rate"
at_least "$en" 0.9 "NSNI order 1 regular: energy rate"
read -r l2 en <<<"$(rates 2 regular)"
at_least "$l2" 2.7 "NSNI order 2 regular: L2 rate"
at_least "$en" 1.8 "NSNI order 2 regular: energy rate"
read -r l2 en <<<"$(rates 2 jittered)"
# 2.10 since the constraint holds the body load's expansion (vci.c add_stabilization; 2.31 before, whose errors
# at 41² and 81² were 13 % and 18 % lower, at 21² 9 % higher, the energy errors all 5-7 % higher)
at_least "$l2" 2.0 "NSNI order 2 jittered: L2 rate (below 0.9 × 3: the measured limit)"
at_least "$en" 1.8 "NSNI order 2 jittered: energy rate"
read -r l2 en <<<"$(rates 1 jittered)"
at_least "$l2" 1.8 "NSNI order 1 jittered: L2 rate"
at_least "$en" 0.9 "NSNI order 1 jittered: energy rate"
read -r l2 en <<<"$(rates 1 irregular)"
at_least "$l2" 1.8 "NSNI order 1 irregular: L2 rate"
at_least "$en" 0.9 "NSNI order 1 irregular: energy rate"
read -r l2 en <<<"$(rates 2 irregular)"
at_least "$l2" 1.8 "NSNI order 2 irregular: L2 rate (below 0.9 × 3: the measured limit)"
at_least "$en" 1.8 "NSNI order 2 irregular: energy rate"

# 3-D (input/manufactured3d.cfg, 7³, 9³, 13³, solver.linear = auto): measured L2 / energy slopes order 1 regular
# 2.26 / 1.51, jittered 2.22 / 1.44; order 2 regular 3.84 / 2.75, jittered 2.98 / 2.02 (2.66 / 2.20 and 2.69 / 2.00
# before the constraint held the body load's expansion, vci.c add_stabilization: asserted ≥ 2.5 then, 0.9 × 3 now)
rates3d() { slopes "$1" "$2" 3 7 9 13; } # ORDER LAYOUT: 7³, 9³, 13³, solver.linear = auto
for layout in regular jittered; do
  read -r l2 en <<<"$(rates3d 1 $layout)"
  at_least "$l2" 1.8 "NSNI 3-D order 1 $layout: L2 rate"
  at_least "$en" 0.9 "NSNI 3-D order 1 $layout: energy rate"
  read -r l2 en <<<"$(rates3d 2 $layout)"
  at_least "$l2" 2.7 "NSNI 3-D order 2 $layout: L2 rate (0.9 × 3)"
  at_least "$en" 1.8 "NSNI 3-D order 2 $layout: energy rate"
done
fi # SAN

# The shipped benchmark decks of solid_benchmarks.sh in NSNI, against the same references and tolerances
# (measured 2026-12-04: cube 1.3e-15, cylinder 6.2e-15; 2026-12-07, once VCI's constraint held the body load's
# expansion (vci.c add_stabilization): Cook linear 25.0573, was 25.2007 (the deck on Gauss cells 25.0917: now from
# below, as the Galerkin answers converge; 17²: 24.9230, was 25.1797), Cook Neo-Hooke 13.7598, was 13.8194; the
# elastica at k = 1 v/L 0.30113 and u/L 0.056228, was 0.29790). Not passing, so not here (docs/verification.md §NSNI): the elastica
# at k = 2 (v/L 0.49162 within 0.5 % of 0.49346, u/L 0.15946 0.73 % from 0.16064; was 0.4871), the Kirsch plate
# (VCI underdetermined near the hole), the Lamé cylinder (L2 1.0e-2 against 1e-3, UMFPACK). The elastica's is VCI's
# error at free edges (a traction boundary: tests/decks/nsni/harmonic_traction.cfg, bench/nsni_free_edge.sh).
nsni_deck() { run_deck "$work/bench_$1" "$2" --set quadrature.mode=nsni "${@:3}"; }
nsni_deck cook input/cook_linear.cfg
within "$(err bench_cook tip_uy)" 25.18 0.005 "NSNI, Cook linear tip u_y"
nsni_deck cube input/cube3d.cfg
less_than "$(err bench_cube error_l2)" 1e-5 || fail "NSNI, 3-D tension: L2 error $(err bench_cube error_l2)"
within "$(err bench_cube corner_ux)" 0.01 1e-5 "NSNI, 3-D tension: corner u_x"
nsni_deck cylinder input/cylinder_tension.cfg
less_than "$(err bench_cylinder error_l2)" 1e-4 || fail "NSNI, cylinder in tension: L2 error $(err bench_cylinder error_l2)"
within "$(err bench_cylinder top_uz)" 0.02 1e-4 "NSNI, cylinder in tension: top u_z"
nsni_deck cook_nh input/cook_neohooke.cfg
at_most "$(awk -v v="$(err bench_cook_nh tip_uy)" 'BEGIN { d = v - 13.772; print d < 0 ? -d : d }')" 0.02 \
  "NSNI, Cook Neo-Hooke: |tip u_y - 13.772|"
nsni_deck elastica input/elastica.cfg --set parameters.k=1
within "$(err bench_elastica tip_uy)" 0.30172 0.005 "NSNI, elastica k = 1: v/L"
within "$(awk -v u="$(err bench_elastica tip_ux)" 'BEGIN { print -u }')" 0.05643 0.005 "NSNI, elastica k = 1: u/L"

# solver.linear = "auto" (the deck's default) picks cholmod-sym for NSNI's Petrov–Galerkin tangent; with a
# quadratic basis on jittered particles its skew part is too large (the refinement stops contracting:
# |b − A x| / |b| = 8.6 on this 6³ cube), and auto moves to UMFPACK with a note instead of failing the run
run_deck "$work/auto_skew" input/cube3d.cfg --set quadrature.mode=nsni --set mls.order=2 \
  --set "particles.count=[6,6,6]" --set particles.layout=jittered --set particles.jitter=0.2 --set output.monitor=true
grep -q 'stopped contracting.*switching to umfpack' "$work/auto_skew.log" || fail "auto: no note of the move to UMFPACK"
grep -q '"linear_solver": "umfpack"' "$work/auto_skew/summary.json" || fail "auto: the run did not end on UMFPACK"
less_than "$(err auto_skew error_l2)" 1e-10 || fail "auto, NSNI quadratic jittered cube: L2 $(err auto_skew error_l2)"
ok "auto: cholmod-sym's stalled refinement moves to UMFPACK (L2 $(err auto_skew error_l2))"

expect_failure 2 "quadrature.mode = \"nsni\" expands the kinematics" -- "$MICA" run input/beam_gradient.cfg \
  -o "$work/x" --set material.model=strain-gradient --set material.l=0.1 --set quadrature.mode=nsni

# Finite-rotation Cosserat takes the paired rule (src/assemble/nsni_pairs.c): the free block and cube turned
# rigidly (2π in 2-D, 3π/2 about a skew axis in 3-D) against their decks' references, 1e-8; the strip rolled into a
# circle (input/cosserat_roll.cfg, 10 steps) within the deck's own tolerances (0.5 % of L; φ 1 %). VCI is off for
# the roll: with it NSNI's Cosserat strip is 2.0× too flexible already at small strain (docs/verification.md §NSNI,
# "what remains"), the paired rule adds nothing to that.
run_deck "$work/rotate" input/cosserat_rotate.cfg --set quadrature.mode=nsni
grep -q 'NSNI: the paired rule' "$work/rotate.log" || fail "rotate: not the paired rule: $(grep NSNI "$work/rotate.log")"
within "$(err rotate corner_phi)" 6.283185307179586 1e-8 "NSNI paired rule, 2-D rigid turn by 2 pi: corner phi"
at_most "$(awk -v v="$(err rotate corner_ux)" 'BEGIN { print v < 0 ? -v : v }')" 1e-8 "NSNI paired rule, 2-D: |corner ux|"
run_deck "$work/rotate3d" input/cosserat_rotate3d.cfg --set quadrature.mode=nsni
within "$(err rotate3d corner_ux)" -0.3041673295 1e-8 "NSNI paired rule, 3-D turn: corner ux"
within "$(err rotate3d corner_phiz)" 3.778316794 1e-8 "NSNI paired rule, 3-D turn: corner phi_z"
run_deck "$work/roll" input/cosserat_roll.cfg --set quadrature.mode=nsni --set quadrature.vci=false --set solver.steps=10
within "$(err roll tip_ux)" -1 0.005 "NSNI paired rule, rolled strip: tip ux / L"
at_most "$(awk -v v="$(err roll tip_uy)" 'BEGIN { print v < 0 ? -v : v }')" 0.005 "NSNI paired rule, rolled strip: |tip uy| / L"
within "$(err roll tip_phi)" 6.283185 0.01 "NSNI paired rule, rolled strip: tip phi"
within "$(err roll mid_ux)" -0.5 0.005 "NSNI paired rule, rolled strip: mid ux / L"
within "$(err roll mid_uy)" 0.31831 0.005 "NSNI paired rule, rolled strip: mid uy / L"
