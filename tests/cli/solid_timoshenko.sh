# Timoshenko cantilever (docs/verification.md §References): convergence rates over four refinements for linear and quadratic
# bases with each boundary method (least-squares slopes of the relative L2 and energy errors against 1/h;
# thresholds from issue 3), and the tip deflection within 0.1 % of 0.0089 on the shipped deck.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/solid_timoshenko"
rm -rf "$work" && mkdir -p "$work"

run_deck "$work/tip" input/timoshenko.cfg
within "$(json_value tip_uy "$work/tip/summary.json")" 0.0089 0.001 "tip deflection, shipped deck"

for method in nitsche penalty lagrange; do
  for order in 1 2; do
    if [ $order = 1 ]; then dil=2.0; q=4; min_l2=1.9; min_en=0.95; else dil=3.0; q=5; min_l2=2.8; min_en=1.9; fi
    l2=""; en=""
    for k in 2 4 8 16; do
      d="$work/${method}_p${order}_$k"
      run_deck "$d" input/timoshenko.cfg --set bc.method=$method --set mls.order=$order --set mls.dilation=$dil \
        --set quadrature.order=$q --set "particles.count=[$((4 * k + 1)),$((k + 1))]"
      h=$(awk -v k=$k 'BEGIN { print 12 / k }')
      l2+="$h $(json_value error_l2 "$d/summary.json")"$'\n'
      en+="$h $(json_value error_energy "$d/summary.json")"$'\n'
    done
    at_least "$(printf '%s' "$l2" | ls_rate)" $min_l2 "$method, order $order: L2 rate"
    at_least "$(printf '%s' "$en" | ls_rate)" $min_en "$method, order $order: energy rate"
  done
done
