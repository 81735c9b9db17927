# Penalty and Nitsche parameters: the results (tip deflection, and the L2 error against the exact solution)
# change by less than 1e-3 relative when α varies tenfold around its default (α/√10 to α√10); for Nitsche
# also over a hundredfold range (α/10 to 10α). Timoshenko beam, linear and quadratic bases.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/solid_alpha"
rm -rf "$work" && mkdir -p "$work"
check_range() { # method default factors...
  local method=$1 alpha=$2 order=$3; shift 3
  local dil=$([ "$order" = 1 ] && echo 2.0 || echo 3.0)
  run_deck "$work/${method}_${order}_ref" input/timoshenko.cfg --set bc.method=$method --set bc.alpha=$alpha \
    --set mls.order=$order --set mls.dilation=$dil
  local tip0=$(json_value tip_uy "$work/${method}_${order}_ref/summary.json")
  local err0=$(json_value error_l2 "$work/${method}_${order}_ref/summary.json")
  for f in "$@"; do
    local a=$(awk -v a=$alpha -v f=$f 'BEGIN { print a * f }')
    run_deck "$work/${method}_${order}_$f" input/timoshenko.cfg --set bc.method=$method --set bc.alpha=$a \
      --set mls.order=$order --set mls.dilation=$dil
    within "$(json_value tip_uy "$work/${method}_${order}_$f/summary.json")" "$tip0" 1e-3 \
      "$method order $order, alpha $a vs $alpha: tip"
    local e=$(json_value error_l2 "$work/${method}_${order}_$f/summary.json")
    awk -v a="$e" -v b="$err0" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d < 1e-3) }' \
      || fail "$method order $order, alpha $a: L2 error $e vs $err0 differs by more than 1e-3"
  done
}
for order in 1 2; do
  check_range penalty 1000 $order 0.316 3.16
  check_range nitsche 100 $order 0.316 3.16 0.1 10
done
