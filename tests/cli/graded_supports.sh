# mls.spacing (docs/theory.md §supports, docs/verification.md §graded supports): on the 40:1 graded Cosserat
# plate at 11 × 16 particles, dilation 3, Gauss order 4, the near rule leaves points along the outer, loaded
# edge covered by too few particles; the solution carries a mode that the solve's Gauss points barely see.
# Shown by the strain energy at 8 × 8 points per cell (output.quadrature_fields) against the solve's own:
# near 1.47 against 0.283 (measured), far equal to 1e-6. U_ref = 0.2802937374 (FEniCS P3/P2, k = 16: bench/peers):
# near √(|ΔU|/U) = 0.11, far 1.1e-3. The far rule widens supports toward the coarse side (59.8 particles per point
# against 34.5), and the SCF at the hole, a point value, comes out 2.09 against 2.14 (reference 2.1351): it is
# checked within 3 % here; the deck's settings keep the near rule (cosserat_hole.sh checks 1 %).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/graded_supports"
rm -rf "$work" && mkdir -p "$work"
probes='output.probes=( { name = "U"; field = "energy"; }, { name = "scf"; point = ["0", "a"]; field = "sxx"; scale = "1/p"; } )'
for rule in near far; do
  run_deck "$work/$rule" input/cosserat_hole.cfg --set mls.spacing=$rule --set mls.dilation=3.0 \
    --set quadrature.order=4 --set "particles.count=[11,16]" --set quadrature.error_order=8 \
    --set output.quadrature_fields=true --set "$probes"
done
value() { json_value "$2" "$work/$1/summary.json"; }
ratio() { awk -v a="$(value "$1" quadrature_fields_energy)" -v b="$(value "$1" U)" 'BEGIN { printf "%.6g", a / b }'; }
energy_error() { awk -v u="$(value "$1" U)" 'BEGIN { r = 0.2802937374; d = (u - r) / r; if (d < 0) d = -d; printf "%.4e", sqrt(d) }'; }

# the failure, shown: energy at the 8 × 8 points over the solve's energy
at_least "$(ratio near)" 2 "near rule: energy at 8 × 8 points / at the solve's points (a hidden mode)"
at_least "$(energy_error near)" 0.02 "near rule: energy error against U_ref"
# the cure
within "$(ratio far)" 1 1e-4 "far rule: energy at 8 × 8 points / at the solve's points"
less_than "$(energy_error far)" 2e-3 || fail "far rule: energy error $(energy_error far) >= 2e-3"
ok "far rule: energy error $(energy_error far) < 2e-3 (near: $(energy_error near))"
within "$(value far scf)" 2.1351 0.03 "far rule: SCF"
at_least "$(value far support_mean)" "$(value near support_mean)" "far rule: particles per point, not fewer than near's"
echo "report: support_mean near $(value near support_mean), far $(value far support_mean); SCF near $(value near scf), far $(value far scf)"

# a wrong value is bad input with the deck line
expect_failure 2 'mls.spacing = "wide" is not one of near|far' "mls.spacing = wide" \
  "$MICA" run input/cosserat_hole.cfg -o "$work/bad" --set mls.spacing=wide
