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
