#!/usr/bin/env bash
# Axisymmetric solids (docs/theory.md §axisymmetric, docs/verification.md §axisymmetric):
#  - Lamé's cylinder as a section: u_r at the bore against the exact solution, errors converge;
#  - classical torsion of a cylinder: the torque from the strain energy equals G J tau (u_theta = tau z r
#    lies in the quadratic basis);
#  - Cosserat bone torsion against Gauthier & Jahsman's rigidity ratio over diameters 0.2-10 mm, computed by
#    the independent tests/reference/gauthier_jahsman.c;
#  - the section against the full 3-D Cosserat cylinder;
#  - bad input.
source "$(dirname "$0")/common.bash"
out=$OUT_DIR/axisymmetric
rm -rf "$out" && mkdir -p "$out"

# Lamé: u_r(a) = (1+nu)/E a^2 p/(b^2-a^2) ((1-2nu) a + b^2/a) = 0.00190666...
run_deck "$out/lame9" input/lame_axisymmetric.cfg
run_deck "$out/lame17" input/lame_axisymmetric.cfg --set particles.count=[17,4]
within "$(json_value ur_inner "$out/lame17/summary.json")" 0.0019066666666666668 1e-4 "Lame axisymmetric u_r(a), 17 particles"
e9=$(json_value error_energy "$out/lame9/summary.json"); e17=$(json_value error_energy "$out/lame17/summary.json")
less_than "$e17" 1e-3 || fail "Lame axisymmetric energy error $e17 >= 1e-3"
rate=$(printf '%s %s\n%s %s\n' 0.125 "$e9" 0.0625 "$e17" | ls_rate) # h, error
at_least "$rate" 1.8 "Lame axisymmetric energy-error rate (quadratic basis; $e9 -> $e17)"

# Classical torsion: a linear model on the same section and ends, without the micro-rotation conditions.
sed -e 's/model = "cosserat"; G = "G"; nu = "nu"; N = "N"; l_t = "l_t"; l_b = "l_b"; psi = "psi";/model = "linear"; E = "2*G*(1 + nu)"; nu = "nu";/' \
    -e 's/ phiz = "0";//; s/ phiz = "tau\*L";//' -e '/phir_surface/d' -e 's/scale = "4\/(tau^2\*L\*G\*3.14159265358979\*R^4)"; },/scale = "4\/(tau^2*L*G*3.14159265358979*R^4)"; } ); };/' \
    input/bone_torsion.cfg > "$out/classical_torsion.cfg"
run_deck "$out/classical" "$out/classical_torsion.cfg"
within "$(json_value rigidity_ratio "$out/classical/summary.json")" 1.0 1e-8 "classical axisymmetric torsion: torque / (G J tau)"

# Cosserat bone torsion against Gauthier & Jahsman (Lakes' constants, docs/verification.md §References).
cc -O2 tests/reference/gauthier_jahsman.c -lm -o "$out/gauthier_jahsman" || fail "cannot build the reference program"
for d in 0.2 1 2 10; do
  run_deck "$out/bone_$d" input/bone_torsion.cfg --set parameters.diameter=$d
  ref=$("$out/gauthier_jahsman" 0.62 0.22 1.5 "$(awk -v d=$d 'BEGIN { print d / 2 }')")
  within "$(json_value rigidity_ratio "$out/bone_$d/summary.json")" "$ref" 1e-5 "bone torsion d = $d mm: rigidity ratio vs Gauthier-Jahsman"
done

# The section against the full 3-D cylinder (coarse 3-D: 243 particles; finer 3-D runs in docs/verification.md).
run_deck "$out/bone3d" input/bone_torsion_3d.cfg
within "$(json_value rigidity_ratio "$out/bone3d/summary.json")" "$(json_value rigidity_ratio "$out/bone_2/summary.json")" \
  5e-4 "3-D Cosserat cylinder vs the axisymmetric section (d = 2 mm)"

# Bad input.
expect_failure 2 "needs a 2-D (r, z) section" -- "$MICA" run input/bone_torsion_3d.cfg -o "$out/bad1" --set geometry.axisymmetric=true
expect_failure 2 "is not available for axisymmetric solids" -- "$MICA" run input/lame_axisymmetric.cfg -o "$out/bad2" --set bc.method=nitsche
expect_failure 2 "lies in x = r" -- "$MICA" run input/lame_axisymmetric.cfg -o "$out/bad3" --set parameters.a=-1
expect_failure 2 "has no axisymmetric form" -- "$MICA" run input/beam_gradient.cfg -o "$out/bad4" --set geometry.axisymmetric=true
expect_failure 2 "needs r > 0" -- "$MICA" run input/bone_torsion.cfg -o "$out/bad5" --set 'output.probes.[1].point=["0", "L/2"]'
sed 's/{ name = "ur_inner"; point = \["a", "h\/2"\]; field = "ur"; }/{ name = "ur_inner"; field = "ur"; }/' input/lame_axisymmetric.cfg > "$out/no_point.cfg"
expect_failure 2 "needs a point" -- "$MICA" run "$out/no_point.cfg" -o "$out/bad6"
expect_failure 2 "not available for axisymmetric solids" -- "$MICA" run input/lame_axisymmetric.cfg -o "$out/bad7" --set quadrature.vci=true
echo "axisymmetric: all checks passed"
