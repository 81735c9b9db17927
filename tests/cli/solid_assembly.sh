# Assembly passes of a linear solve (src/solve/newton.c, docs/performance.md §profiles): the Timoshenko beam,
# linear and quadratic bases (Nitsche, CHOLMOD), is solved with ONE assembly (residual and tangent together);
# the residual after the solve is R + K du (residual_updates = 1) instead of a second and third assembly. That
# skipped pass must not change the answer: the tip deflection is within 0.1 % of the analytic 0.0089, and equals
# to 1e-10 relative the run whose residual after the solve IS assembled (solver.line_search = true: the line
# search assembles R(u + du) and Newton reuses it), whose final |R| must also be at round-off (≤ 1e-12 |R0|).
# A nonlinear model (Neo-Hooke) never takes the shortcut (residual_updates = 0).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/solid_assembly"
rm -rf "$work" && mkdir -p "$work"

# |R| of the last iteration over |R| of the first, from residual_history_last_step
residual_drop() { awk '/"residual_history_last_step"/ { on = 1; next } on && /\]/ { exit }
                       on { gsub(/,/, ""); v[n++] = $1 } END { printf "%.3e", v[n - 1] / v[0] }' "$1"; }

for order in 1 2; do
  if [ $order = 1 ]; then sets=(--set mls.order=1); else sets=(--set mls.order=2 --set mls.dilation=3.0 --set quadrature.order=5); fi
  d="$work/p$order"
  run_deck "$d" input/timoshenko.cfg "${sets[@]}"
  s="$d/summary.json"
  [ "$(json_value assemblies "$s")" = 1 ] || fail "order $order: $(json_value assemblies "$s") assemblies, expected 1"
  [ "$(json_value tangent_assemblies "$s")" = 1 ] || fail "order $order: tangent assemblies $(json_value tangent_assemblies "$s")"
  [ "$(json_value residual_updates "$s")" = 1 ] || fail "order $order: residual_updates $(json_value residual_updates "$s")"
  ok "order $order: one assembly, residual after the solve from R + K du"
  within "$(json_value tip_uy "$s")" 0.0089 0.001 "order $order: tip deflection with the skipped residual pass"
  drop=$(residual_drop "$s")
  less_than "$drop" 1e-12 || fail "order $order: |R|/|R0| = $drop after the solve"
  ok "order $order: |R|/|R0| = $drop (R + K du)"

  a="$work/p${order}_assembled"
  run_deck "$a" input/timoshenko.cfg "${sets[@]}" --set solver.line_search=true
  [ "$(json_value residual_updates "$a/summary.json")" = 0 ] || fail "order $order: line search run took the shortcut"
  drop=$(residual_drop "$a/summary.json")
  less_than "$drop" 1e-12 || fail "order $order: assembled |R|/|R0| = $drop after the solve"
  ok "order $order: assembled |R|/|R0| = $drop"
  within "$(json_value tip_uy "$s")" "$(json_value tip_uy "$a/summary.json")" 1e-10 \
    "order $order: tip deflection, R + K du against an assembled residual"
done

d="$work/neohooke"
run_deck "$d" input/cook_neohooke.cfg --set "particles.count=[5,5]" --set solver.steps=2
[ "$(json_value residual_updates "$d/summary.json")" = 0 ] || fail "Neo-Hooke took the linear shortcut"
ok "Neo-Hooke: no linear shortcut ($(json_value newton_iterations "$d/summary.json") Newton iterations, $(json_value assemblies "$d/summary.json") assemblies)"
