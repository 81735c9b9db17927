# Probes outside the body (docs/input.md §output): a point probe must lie in the body or on its boundary
# (within 1e-8 of the body's size), by the geometry's own inside test — each built-in shape's exact geometry,
# a Gmsh mesh's elements — or the run stops with exit 2, the probe's deck line and the body's bounds, before
# anything is solved. `extrapolate = true` lets a probe outside report the MLS approximation's value there.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/probes"
rm -rf "$work" && mkdir -p "$work"
D=tests/decks/probes

# the beam [0, 48] x [-6, 6] with a probe at (48.8, 0), line 22 of the deck
expect_failure 2 "beam_outside.cfg:22: probe 'past_tip_uy' at (48.8, 0) lies outside the body, the box" -- \
  "$MICA" run $D/beam_outside.cfg -o "$work/beam"
expect_failure 2 "bounds x in [0, 48], y in [-6, 6]" -- "$MICA" run $D/beam_outside.cfg -o "$work/beam"
[ ! -e "$work/beam/summary.json" ] || fail "a refused probe left a summary.json"
expect_failure 2 "beam_outside.cfg:22: probe 'past_tip_uy'" -- "$MICA" check $D/beam_outside.cfg -o "$work/beam"
# with extrapolate = true it runs; the linear MLS continues the field past the tip: within 1 % of the exact
# solution's polynomial continued to x = 48.8 (0.0091194; at the tip itself 0.0089 is met to 0.3 %)
run_deck "$work/extrapolate" $D/beam_outside.cfg --set 'output.probes.[1].extrapolate=true'
within "$(json_value past_tip_uy "$work/extrapolate/summary.json")" 0.0091194246913580 0.01 \
  "extrapolated probe at (48.8, 0)"
within "$(json_value tip_uy "$work/extrapolate/summary.json")" 0.0089 0.005 "probe on the tip's edge (48, 0)"

# on the boundary: corners and edges, and round-off past them, are inside; 1e-6 of the length past is not
probe() { printf 'output.probes=( { name = "p"; point = [%s]; field = "%s"; } )' "$1" "${2:-ux}"; }
for at in '"L", "D/2"' '"0", "-D/2"' '"L*(1 + 1e-12)", "0"' '"L/2", "D/2*(1 + 1e-12)"'; do
  "$MICA" check input/timoshenko.cfg -o "$work/x" --set "$(probe "$at")" > "$work/check.log" 2>&1 \
    || fail "a probe at ($at) on the beam's boundary was refused: $(tail -n 1 "$work/check.log")"
done
ok "probes on the beam's boundary (corners, edges, round-off past them) are accepted"
expect_failure 2 "lies outside the body, the box" -- "$MICA" check input/timoshenko.cfg -o "$work/x" \
  --set "$(probe '"L*(1 + 1e-6)", "0"')"

# each built-in shape by its own geometry: inside its bounding box but outside the body is refused
expect_failure 2 "outside the body, the quarter plate with a hole of radius 1 (bounds x in [0, 5], y in [0, 5])" -- \
  "$MICA" check input/plate_hole.cfg -o "$work/x" --set "$(probe '0.5, 0.5' sxx)"
"$MICA" check input/plate_hole.cfg -o "$work/x" --set "$(probe '"a*cos(0.3)", "a*sin(0.3)"' sxx)" > /dev/null \
  || fail "a probe on the hole's arc was refused"
expect_failure 2 "outside the body, the quadrilateral (bounds x in [0, 48], y in [0, 60])" -- \
  "$MICA" check input/cook_linear.cfg -o "$work/x" --set "$(probe '48.0, 30.0' uy)"
"$MICA" check input/cook_linear.cfg -o "$work/x" --set "$(probe '24.0, 52.0' uy)" > /dev/null \
  || fail "a probe on Cook's top edge was refused"
expect_failure 2 "outside the body, the annulus sector 1 <= r <= 2, 0 <= theta <= 90 degrees" -- \
  "$MICA" check input/lame_cylinder.cfg -o "$work/x" --set "$(probe '1.5, -0.01')"
expect_failure 2 "bounds x in [0, 2], y in [0, 2]" -- \
  "$MICA" check input/lame_cylinder.cfg -o "$work/x" --set "$(probe '2.1, 0.1')"
for at in '1.5, 0.0' '0.0, 1.0' '"sqrt(2)", "sqrt(2)"'; do
  "$MICA" check input/lame_cylinder.cfg -o "$work/x" --set "$(probe "$at")" > /dev/null \
    || fail "a probe at ($at) on the annulus' boundary was refused"
done
expect_failure 2 "outside the body, the cylinder of radius 1 and height 2 (bounds x in [-1, 1], y in [-1, 1], z in [0, 2])" -- \
  "$MICA" check input/cylinder_tension.cfg -o "$work/x" --set "$(probe '0.72, 0.72, 1.0' uz)"
"$MICA" check input/cylinder_tension.cfg -o "$work/x" --set "$(probe '"sqrt(0.5)", "sqrt(0.5)", "2"' uz)" > /dev/null \
  || fail "a probe on the cylinder's rim was refused"
# a Gmsh mesh by its elements: a point in the hole (inside the mesh's bounding box) is outside
expect_failure 2 "outside the body, the elements of input/meshes/plate_hole.msh" -- \
  "$MICA" check input/plate_hole_gmsh.cfg -o "$work/x" --set "$(probe '0.5, 0.5' sxx)"
"$MICA" check input/plate_hole_gmsh.cfg -o "$work/x" --set "$(probe '5.0, 5.0' sxx)" > /dev/null \
  || fail "a probe at the mesh's corner node was refused"

# extrapolate is refused where it cannot act: on the energy probe (no point) and with finite elements
expect_failure 2 "probe 'U': extrapolate is for a probe at a point" -- "$MICA" check input/timoshenko.cfg -o "$work/x" \
  --set 'output.probes=( { name = "U"; field = "energy"; extrapolate = true; } )'
expect_failure 2 "finite elements (problem.method = \"fe\") have no values outside their elements" -- \
  "$MICA" check $D/beam_outside.cfg -o "$work/x" --set problem.method=fe --set mls.order=1 \
  --set 'output.probes.[1].extrapolate=true'
