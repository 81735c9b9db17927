# Newton's method converges quadratically on Cook's membrane with Neo-Hooke (finite strain), with Nitsche's
# consistent linearization and with Lagrange multipliers: the order estimated from the last load step's
# increments, log(|Δu_i+1|/|Δu_i|) / log(|Δu_i|/|Δu_i−1|), reaches at least 1.8.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/solid_newton"
rm -rf "$work" && mkdir -p "$work"
# the increments of the last step, one per line
increments() { awk '/"increment_history_last_step"/ { f = 1; next } f && /\]/ { exit } f { gsub(/[ ,]/, ""); print }' "$1"; }
for method in nitsche lagrange; do
  run_deck "$work/$method" input/cook_neohooke.cfg --set "particles.count=[13,13]" --set bc.method=$method
  order=$(increments "$work/$method/summary.json" | awk '{ d[n++] = $1 } END {
    best = 0; for (i = 2; i < n; i++) if (d[i] > 0 && d[i-1] > 0 && d[i-2] > 0) {
      r = log(d[i] / d[i-1]) / log(d[i-1] / d[i-2]); if (r > best) best = r }
    printf "%.2f", best }')
  at_least "$order" 1.8 "Newton order on Cook Neo-Hooke ($method), last step increments: $(increments "$work/$method/summary.json" | tr '\n' ' ')"
done

# the whole load in one step with 6 iterations fails and is cut back; the answer is the same as with 10
# steps; so is the answer with line search; and every converged step writes a VTU file listed in the PVD.
run_deck "$work/steps10" input/cook_neohooke.cfg --set "particles.count=[13,13]"
ref=$(json_value tip_uy "$work/steps10/summary.json")
"$MICA" run input/cook_neohooke.cfg -o "$work/cut" --set "particles.count=[13,13]" --set solver.steps=1 \
  --set solver.max_iterations=6 > "$work/cut.log" 2>&1 || fail "cut-back run failed"
grep -q "cut back" "$work/cut.log" || fail "no step was cut back"
[ "$(json_value step_cuts "$work/cut/summary.json")" -ge 1 ] || fail "step_cuts is not reported"
within "$(json_value tip_uy "$work/cut/summary.json")" "$ref" 1e-6 "cut-back run, tip"
steps=$(json_value load_steps "$work/cut/summary.json")
[ "$(ls "$work/cut"/step_*.vtu | wc -l)" = "$steps" ] || fail "expected $steps VTU files"
[ "$(ls "$work/cut"/mesh_*.vtu | wc -l)" = "$steps" ] || fail "expected $steps mesh VTU files"
for part in 0 1; do
  [ "$(grep -c "part=\"$part\"" "$work/cut/solution.pvd")" = "$steps" ] || fail "the PVD does not list $steps steps of part $part"
done
grep 'part="1"' "$work/cut/solution.pvd" | tail -n 1 | grep -q 'timestep="1"' || fail "the last step after a cut is not at t = 1"
ok "VTU per load step (particles and mesh) and PVD ($steps steps, the last at t = 1)"
run_deck "$work/ls" input/cook_neohooke.cfg --set "particles.count=[13,13]" --set solver.line_search=true
within "$(json_value tip_uy "$work/ls/summary.json")" "$ref" 1e-6 "line search run, tip"
