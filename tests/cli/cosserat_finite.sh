# Cosserat with finite rotations (issue 4, item 2; docs/verification.md §"Cosserat with finite rotations"):
# (a) an end couple M = 2 pi D/L rolls a strip into a full circle; the positions and rotations are asserted
#     against the exact pure-bending solution of the strip (thickness stretch included) and the tip against the
#     elastica's return to the origin; Newton converges quadratically;
# (b) rotate and return: 2-D by 2 pi (u back to 0, phi = 2 pi) and back to 0; 3-D by 3 pi/2 about a skew axis
#     and back; bad input.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/cosserat_finite"
rm -rf "$work" && mkdir -p "$work"
# the increments of the last step, one per line; the order log(d_i/d_i-1)/log(d_i-1/d_i-2) of Newton's final
# approach: the lower of the last two triples' (a finite-rotation step wanders before it gets there)
increments() { awk '/"increment_history_last_step"/ { f = 1; next } f && /\]/ { exit } f { gsub(/[ ,]/, ""); print }' "$1"; }
newton_order() { increments "$1" | awk '{ d[n++] = $1 } END { low = 99; for (i = n - 2; i < n; i++)
  { r = i >= 2 ? log(d[i] / d[i-1]) / log(d[i-1] / d[i-2]) : 0; if (r < low) low = r }
  printf "%.2f", low }'; }
# at_most VALUE MAX WHAT (absolute values)
at_most() {
  awk -v v="$1" -v m="$2" 'BEGIN { if (v < 0) v = -v; exit !(v <= m) }' || fail "$3: |$1| > $2"
  ok "$3: |$1| <= $2"
}

# ---- (a) the strip rolled into a circle ----
run_deck "$work/roll" input/cosserat_roll.cfg
s="$work/roll/summary.json"
v() { json_value "$1" "$s"; }
# Exact pure bending of this strip (nu = 0, docs/verification.md): M = E k (sinh(kh) - kh)/(2 k^3 cosh^2(kh/2))
# + gamma h k for the curvature k (the first term is E h^3/12 k (1 - (kh)^2/5 + ...)); the centreline is a circle
# of radius 1/k, the rotation is phi = k x. Parameters of the deck: L = 1, h = 0.02, G = 5000, l = h/10.
k=$(awk 'BEGIN { L = 1; h = 0.02; G = 5000; E = 2 * G; l = h / 10; g = 4 * G * l * l; pi = atan2(0, -1)
  D = E * h^3 / 12 + g * h; M = 2 * pi * D / L; a = 1e-6; b = 100
  for (i = 0; i < 200; i++) { c = (a + b) / 2; x = c * h
    f = E * c * ((exp(x) - exp(-x)) / 2 - x) / (2 * c^3 * ((exp(x / 2) + exp(-x / 2)) / 2)^2) + g * h * c - M
    if (f > 0) b = c; else a = c }
  printf "%.12g", (a + b) / 2 }')
exact() { awk -v k="$k" "BEGIN { L = 1; printf \"%.12g\", $1 }"; }
echo "exact curvature of the strip k = $k (elastica: 2 pi = 6.283185307; k L / 2 pi - 1 = $(exact 'k * L / (2 * atan2(0, -1)) - 1'))"
within "$(v mid_phi)" "$(exact 'k * L / 2')" 1e-3 "roll: rotation at x = L/2 against the exact k L/2"
within "$(v mid_uy)" "$(exact '(1 - cos(k * L / 2)) / k')" 1e-3 "roll: u_y(L/2) against the exact circle"
at_most "$(awk -v a="$(v mid_ux)" -v k="$k" 'BEGIN { print a - (sin(k / 2) / k - 0.5) }')" 1e-3 \
  "roll: u_x(L/2) minus the exact value"
at_most "$(awk -v a="$(v tip_ux)" -v k="$k" 'BEGIN { print 1 + a - sin(k) / k }')" 1e-3 "roll: tip x minus the exact value"
at_most "$(awk -v a="$(v tip_uy)" -v k="$k" 'BEGIN { print a - (1 - cos(k)) / k }')" 1e-3 "roll: tip y minus the exact value"
# the elastica (Euler-Bernoulli) closes the circle exactly; the strip misses the origin by the thickness effect
at_most "$(awk -v a="$(v tip_ux)" -v b="$(v tip_uy)" 'BEGIN { print sqrt((1 + a)^2 + b^2) }')" 5e-3 \
  "roll: distance of the tip from the origin (elastica: 0), / L"
# the end face's tilt from its corners is the macro rotation of the tip: k L - 2 pi, modulo 2 pi
tilt=$(awk -v tx="$(v top_ux)" -v ty="$(v top_uy)" -v bx="$(v bottom_ux)" -v by="$(v bottom_uy)" \
  'BEGIN { h = 0.02; printf "%.9g", atan2(-(tx - bx), h + ty - by) }')
at_most "$(awk -v t="$tilt" -v k="$k" 'BEGIN { print t - (k - 2 * atan2(0, -1)) }')" 5e-3 \
  "roll: tilt of the end face ($tilt) minus the exact k L - 2 pi (rad)"
# the micro-rotation at the loaded end runs ahead of the macro rotation in a boundary layer of length ~ l
within "$(v tip_phi)" "$(exact '2 * atan2(0, -1)')" 1e-2 "roll: micro-rotation at the tip against 2 pi"
at_least "$(newton_order "$s")" 1.8 "roll: Newton order, last step increments $(increments "$s" | tail -n 4 | tr '\n' ' ')"

# ---- (b) rotate and return ----
run_deck "$work/rot2" input/cosserat_rotate.cfg
s="$work/rot2/summary.json"
for p in corner_ux corner_uy center_ux; do at_most "$(v $p)" 1e-8 "2-D, theta = 2 pi: $p back to 0"; done
for p in corner_phi center_phi; do within "$(v $p)" 6.283185307179586 1e-8 "2-D, theta = 2 pi: $p = 2 pi"; done
run_deck "$work/rot2back" input/cosserat_rotate.cfg --set parameters.path=1 --set solver.steps=32
s="$work/rot2back/summary.json"
for p in corner_ux corner_uy corner_phi center_ux center_phi; do at_most "$(v $p)" 1e-8 "2-D, 2 pi and back: $p = 0"; done

run_deck "$work/rot3" input/cosserat_rotate3d.cfg
s="$work/rot3/summary.json"
# (R - I) X at X = (1, 1, 1) and Phi = Theta n for Theta = 3 pi/2, n = (1, 2, 3)/sqrt(14)
exact3() { awk -v i="$1" 'BEGIN { t = 1.5 * atan2(0, -1); r = sqrt(14); n[0] = 1 / r; n[1] = 2 / r; n[2] = 3 / r
  c[0] = n[1] - n[2]; c[1] = n[2] - n[0]; c[2] = n[0] - n[1]; d = n[0] + n[1] + n[2]
  if (i < 3) printf "%.15g", sin(t) * c[i] + (1 - cos(t)) * (n[i] * d - 1); else printf "%.15g", t * n[i - 3] }'; }
i=0
for p in corner_ux corner_uy corner_uz corner_phix corner_phiy corner_phiz; do
  within "$(v $p)" "$(exact3 $i)" 1e-8 "3-D, 3 pi/2 about (1, 2, 3): $p"; i=$((i + 1))
done
run_deck "$work/rot3back" input/cosserat_rotate3d.cfg --set parameters.path=1 --set solver.steps=24
s="$work/rot3back/summary.json"
for p in corner_ux corner_uy corner_uz corner_phix corner_phiy corner_phiz; do
  at_most "$(v $p)" 1e-8 "3-D, 3 pi/2 and back: $p = 0"
done

# ---- bad input ----
expect_failure 2 "cosserat_rotate.cfg:" -- "$MICA" run input/cosserat_rotate.cfg -o "$work/x" --set material.N=1.0
expect_failure 2 "coupling number N" -- "$MICA" run input/cosserat_rotate.cfg -o "$work/x" --set material.N=1.0
expect_failure 3 "≥ 2π" -- "$MICA" run input/cosserat_rotate3d.cfg -o "$work/x" --set 'parameters.Theta="2*pi"' \
  --set solver.max_cuts=1
