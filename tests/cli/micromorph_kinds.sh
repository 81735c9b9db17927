# Gradient micromorph kinds (docs/theory.md §micromorph):
# - isochoric (chi = J^(-1/3) F): a beam of thickness h bent about a micro line of length l across its thickness
#   (nu = 0) has D/D0 = 1 + (l/h)^2 [10/9 - (2b/(9h)) tanh(h/(2b))], b = l/sqrt(27) (the transverse strain relaxes
#   in a layer of width b to free the faces of double traction); within 1 % for l/h = 0.25, 0.5, 1, and at
#   l/h = 1 farther than 1 % from the unrelaxed 1 + (10/9)(l/h)^2, so the test tells the two apart; with an SVK
#   micro energy at a tip slope of 0.05 Newton converges quadratically;
# - rotation (chi = R(Phi)): the Cosserat glide layer with the equivalent constants at small load (B = 1e-4)
#   against the exact small-strain Cosserat solution, 1e-4; at B = 0.02 (SVK and Neo-Hooke micro energies)
#   Newton converges quadratically (order from the increments >= 1.8);
# - bad input exits 2 with the deck line.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/micromorph_kinds"
rm -rf "$work" && mkdir -p "$work"
for l in 0.25 0.5 1.0; do
  run_deck "$work/iso$l" input/beam_gradient.cfg --set material.micro_kind=isochoric --set parameters.l=$l
  r=$(json_value stiffness_ratio "$work/iso$l/summary.json")
  within "$r" "$(awk -v l=$l 'BEGIN { b = l / sqrt(27); x = 1 / (2 * b); t = (exp(2 * x) - 1) / (exp(2 * x) + 1)
    printf "%.10f", 1 + l * l * (10 / 9 - 2 * b / 9 * t) }')" 0.01 "isochoric beam, l/h = $l: stiffness ratio"
done
awk -v r="$r" 'BEGIN { n = 1 + 10 / 9; d = (r - n) / n; exit !(d < -0.01 || d > 0.01) }' \
  || fail "isochoric beam, l/h = 1: $r is within 1 % of the unrelaxed 1 + (10/9)(l/h)^2 as well"
ok "isochoric beam, l/h = 1: $r is more than 1 % from the unrelaxed 2.1111"

newton_order() { awk '/"increment_history_last_step"/ { f = 1; next } f && /\]/ { exit } f { gsub(/[ ,]/, ""); print }' \
    "$1" | awk '{ d[n++] = $1 } END { best = 0
      for (i = 2; i < n; i++) if (d[i] > 0 && d[i-1] > 0 && d[i-2] > 0) {
        r = log(d[i] / d[i-1]) / log(d[i-1] / d[i-2]); if (r > best) best = r }
      printf "%.2f", best }'; }
run_deck "$work/iso_svk" input/beam_gradient.cfg --set material.micro_kind=isochoric --set material.micro_model=svk \
  --set "parameters.M=0.05*E*I/L" --set solver.steps=2
at_least "$(newton_order "$work/iso_svk/summary.json")" 1.8 "isochoric beam, SVK micro energy, tip slope 0.05: Newton order"

run_deck "$work/glide" input/micromorph_glide.cfg
s="$work/glide/summary.json"
within "$(json_value phi_top "$s")" 3.626860407847 1e-4 "rotation kind, glide layer: phi_z/B at y = 1"
within "$(json_value ux_top "$s")" -1.65731741465 1e-4 "rotation kind, glide layer: u_x/B at y = 1"
within "$(json_value phi_mid "$s")" 1.1752011936438014 1e-4 "rotation kind, glide layer: phi_z/B at y = 0.5"
within "$(json_value ux_mid "$s")" -0.32584837256 1e-4 "rotation kind, glide layer: u_x/B at y = 0.5"
# unequal curvature moduli: l follows beta + gamma, and so does the exact solution (w = sqrt(3) at 0.3 + 1.3)
run_deck "$work/glide_unequal" input/micromorph_glide.cfg --set parameters.beta=0.3 --set parameters.gamma=1.3
s="$work/glide_unequal/summary.json"
within "$(json_value phi_top "$s")" 2.737656233858164 1e-4 "rotation kind, glide layer, beta != gamma: phi_z/B at y = 1"
within "$(json_value ux_top "$s")" -1.326458160563948 1e-4 "rotation kind, glide layer, beta != gamma: u_x/B at y = 1"
for micro in svk neohooke; do
  run_deck "$work/newton_$micro" input/micromorph_glide.cfg --set parameters.B=0.02 --set material.micro_model=$micro
  order=$(newton_order "$work/newton_$micro/summary.json")
  at_least "$order" 1.8 "rotation kind, glide layer at B = 0.02, $micro micro energy: Newton order"
done

D=tests/decks/micromorph
expect_failure 2 "bad_kind.cfg:" -- "$MICA" run $D/bad_kind.cfg -o "$work/x"
expect_failure 2 "did you mean \"rotation\"" -- "$MICA" run $D/bad_kind.cfg -o "$work/x"
expect_failure 2 "rotation_no_axes.cfg:" -- "$MICA" run $D/rotation_no_axes.cfg -o "$work/x"
expect_failure 2 "the rotation kind needs a micro space" -- "$MICA" run $D/rotation_no_axes.cfg -o "$work/x"
expect_failure 2 "needs the coupling number material.N" -- "$MICA" run $D/rotation_no_coupling.cfg -o "$work/x"
expect_failure 2 "rotation_bad_coupling.cfg:" -- "$MICA" run $D/rotation_bad_coupling.cfg -o "$work/x"
expect_failure 2 "the coupling number N must be in [0, 1)" -- "$MICA" run $D/rotation_bad_coupling.cfg -o "$work/x"
# the rotation kind is a first-order model: Nitsche applies (generalized tractions from its kernel)
run_deck "$work/glide_nitsche" input/micromorph_glide.cfg --set bc.method=nitsche
within "$(json_value phi_top "$work/glide_nitsche/summary.json")" 3.626860407847 1e-4 \
  "rotation kind, glide layer, Nitsche: phi_z/B at y = 1"
expect_failure 2 "needs a classical model" -- "$MICA" run input/beam_gradient.cfg --set bc.method=nitsche -o "$work/x"
