# Classical benchmarks of the shipped decks against their references (docs/verification.md):
#  - Kirsch plate with a hole: SCF within 1 % of 3 (mapped geometry and a Gmsh mesh);
#  - Cook's membrane, linear (plane stress, E = 1, ν = 1/3, F = 1): within 0.5 % of 25.18 and Neo-Hooke
#    (plane strain, μ = 0.4225, ν = 0.3, F = 1, 10 steps): within 0.02 mm of 13.772 — both references are
#    from independent Q2 finite-element programs (tests/reference/cook_q2_*.c), extrapolated; the values in
#    values first quoted (23.96, 14.33) disagree with both mica and those programs: see docs/verification.md;
#  - elastica k = 1 and 2: v/L and u/L within 0.5 % of the inextensible elastica;
#  - manufactured solution: L2 and energy rates (linear: ≥ 1.9, ≥ 0.95; quadratic: ≥ 2.8, ≥ 1.9);
#  - 3-D tension: the exact linear field to 1e-5.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/solid_benchmarks"
rm -rf "$work" && mkdir -p "$work"

run_deck "$work/kirsch" input/plate_hole.cfg
within "$(json_value scf "$work/kirsch/summary.json")" 3 0.01 "Kirsch SCF, mapped plate"
run_deck "$work/kirsch_gmsh" input/plate_hole_gmsh.cfg
within "$(json_value scf "$work/kirsch_gmsh/summary.json")" 3 0.01 "Kirsch SCF, Gmsh mesh"

run_deck "$work/cook" input/cook_linear.cfg
within "$(json_value tip_uy "$work/cook/summary.json")" 25.18 0.005 "Cook linear tip u_y"
run_deck "$work/cook_nh" input/cook_neohooke.cfg
v=$(json_value tip_uy "$work/cook_nh/summary.json")
awk -v v="$v" 'BEGIN { d = v - 13.772; if (d < 0) d = -d; exit !(d <= 0.02) }' || fail "Cook Neo-Hooke tip $v not within 0.02 of 13.772"
ok "Cook Neo-Hooke tip u_y: $v within 0.02 mm of 13.772"

for case in "1 0.30172 0.05643" "2 0.49346 0.16064"; do
  set -- $case
  run_deck "$work/elastica_$1" input/elastica.cfg --set parameters.k=$1
  within "$(json_value tip_uy "$work/elastica_$1/summary.json")" $2 0.005 "elastica k = $1: v/L"
  within "$(awk -v u="$(json_value tip_ux "$work/elastica_$1/summary.json")" 'BEGIN { print -u }')" $3 0.005 "elastica k = $1: u/L"
done

for order in 1 2; do
  if [ $order = 1 ]; then dil=2.0; min_l2=1.9; min_en=0.95; else dil=3.0; min_l2=2.8; min_en=1.9; fi
  l2=""; en=""
  for n in 5 9 17 33; do
    run_deck "$work/mms_${order}_$n" input/manufactured.cfg --set mls.order=$order --set mls.dilation=$dil \
      --set "particles.count=[$n,$n]"
    h=$(awk -v n=$n 'BEGIN { print 2 / (n - 1) }')
    l2+="$h $(json_value error_l2 "$work/mms_${order}_$n/summary.json")"$'\n'
    en+="$h $(json_value error_energy "$work/mms_${order}_$n/summary.json")"$'\n'
  done
  at_least "$(printf '%s' "$l2" | ls_rate)" $min_l2 "manufactured, order $order: L2 rate"
  at_least "$(printf '%s' "$en" | ls_rate)" $min_en "manufactured, order $order: energy rate"
done

run_deck "$work/cube" input/cube3d.cfg
e=$(json_value error_l2 "$work/cube/summary.json")
less_than "$e" 1e-5 || fail "3-D tension: L2 error $e"
within "$(json_value corner_ux "$work/cube/summary.json")" 0.01 1e-5 "3-D tension: corner u_x"

# the curved built-in shapes against exact solutions: a cylinder in tension (3-D, linear field) and Lamé's
# pressurized thick cylinder (annulus sector, symmetry planes, pressure as an expression of x, y)
run_deck "$work/cylinder" input/cylinder_tension.cfg
e=$(json_value error_l2 "$work/cylinder/summary.json")
less_than "$e" 1e-4 || fail "cylinder in tension: L2 error $e"
within "$(json_value top_uz "$work/cylinder/summary.json")" 0.02 1e-4 "cylinder in tension: top u_z"
run_deck "$work/lame" input/lame_cylinder.cfg
e=$(json_value error_l2 "$work/lame/summary.json")
less_than "$e" 1e-3 || fail "Lamé cylinder: L2 error $e"
ok "Lamé cylinder: L2 error $e < 1e-3"
