# Convergence with the default settings off a grid (issue 21 item 1; docs/verification.md §"VCI by default"):
# quadrature.vci = "auto" turns VCI on for jittered and irregular particles. Smooth manufactured solutions,
# Dirichlet conditions on the whole boundary (Nitsche, the default), mls.dilation = order + 1 and Gauss order 4
# (the defaults; input/manufactured.cfg's own dilation 2 and order 5 are set back to them), jitter 0.3,
# irregular = Poisson-disk interior. Three refinements each; least-squares slopes of the relative errors
# against h, asserted ≥ 0.9 × the optimal rates, L2 m + 1 and energy m for basis order m:
#   2-D classical  input/manufactured.cfg        9, 17, 33 particles per side
#   2-D Cosserat   input/cosserat_smooth.cfg     9, 17, 33
#   3-D classical  input/manufactured3d.cfg      order 1: 5, 7, 9
#   3-D Cosserat   input/cosserat_smooth3d.cfg   order 1: 5, 7, 9
# 3-D order 2 is not run here: UMFPACK takes minutes on the unsymmetric tangent at 9^3 (189 s measured), and
# 5, 7, 9 is still pre-asymptotic (docs/verification.md gives the one measured series).
# Every run must report that auto chose VCI (vci_setting "auto", vci true).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/vci_rates"
rm -rf "$work" && mkdir -p "$work"

# rates NAME DECK ORDER LAYOUT "COUNTS" [--set ...]: asserts the slopes, prints one table row
rates() {
  local name=$1 deck=$2 order=$3 layout=$4 counts=$5; shift 5
  local l2="" en="" row="" d n dim
  for n in $counts; do
    d="$work/${name}_p${order}_${layout}_$n"
    dim=$(grep -c "upper = \[1.0, 1.0, 1.0\]" "$deck")
    local c="[$n,$n]"; [ "$dim" = 1 ] && c="[$n,$n,$n]"
    run_deck "$d" "$deck" --set mls.order=$order --set mls.dilation=$((order + 1)).0 --set quadrature.order=4 \
      --set particles.layout=$layout --set particles.jitter=0.3 --set "particles.count=$c" "$@"
    [ "$(json_value vci_setting "$d/summary.json")" = auto ] && [ "$(json_value vci "$d/summary.json")" = true ] \
      || fail "$name $layout $n: quadrature.vci = auto did not choose VCI"
    local h; h=$(awk -v n=$n 'BEGIN { print 2 / (n - 1) }')
    l2+="$h $(json_value error_l2 "$d/summary.json")"$'\n'
    en+="$h $(json_value error_energy "$d/summary.json")"$'\n'
    row+=" $(json_value error_l2 "$d/summary.json" | awk '{ printf "%.2e", $1 }')/$(json_value error_energy "$d/summary.json" | awk '{ printf "%.2e", $1 }')"
  done
  local rl2 ren; rl2=$(printf '%s' "$l2" | ls_rate); ren=$(printf '%s' "$en" | ls_rate)
  echo "report: | $name | $order | $layout | $counts |$row | $rl2 | $ren |"
  at_least "$rl2" "${MIN_L2:-$(awk -v m=$order 'BEGIN { print 0.9 * (m + 1) }')}" "$name p$order $layout: L2 rate"
  at_least "$ren" "${MIN_EN:-$(awk -v m=$order 'BEGIN { print 0.9 * m }')}" "$name p$order $layout: energy rate"
}

for layout in jittered irregular; do
  for order in 1 2; do
    rates classical2d input/manufactured.cfg $order $layout "9 17 33"
    rates cosserat2d input/cosserat_smooth.cfg $order $layout "9 17 33"
    [ $order = 1 ] || continue
    # 3-D irregular, 5 to 9 per side, is short of 0.9 × optimal: the honest bound is asserted (the gap is in
    # docs/verification.md: pairwise energy rates 0.68, 0.83, 0.87 from 5 to 11, still rising)
    l2=""; en=""; [ $layout = irregular ] && l2=1.7 en=0.7
    MIN_L2=$l2 MIN_EN=$en rates classical3d input/manufactured3d.cfg $order $layout "5 7 9"
    MIN_L2=$l2 MIN_EN=$en rates cosserat3d input/cosserat_smooth3d.cfg $order $layout "5 7 9"
  done
done
