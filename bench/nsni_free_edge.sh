#!/usr/bin/env bash
# NSNI's free-edge defect (issue 20; docs/verification.md §NSNI, "free edges"): the relative L2 error of
# tests/decks/nsni/harmonic_traction.cfg (a smooth field, one traction edge, no body force) at 21², 41², 81²
# particles, bases of order 1 and 2, for Gauss quadrature, NSNI (VCI on, its default) and NSNI without VCI, with
# the slopes of successive pairs (log2 of the error ratio; optimal: order + 1). Figures only: it never fails on
# them. About a minute.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
out=${OUT_DIR:-build/bench-out}/nsni_free_edge
mkdir -p "$out"
deck=tests/decks/nsni/harmonic_traction.cfg
# l2 ORDER N SETTINGS...: the run's relative L2 error
l2() {
  local order=$1 n=$2
  shift 2
  "$MICA" run "$deck" -o "$out/run" --set "particles.count=[$n,$n]" --set "mls.order=$order" \
    --set "mls.dilation=$((order + 1))" "$@" > "$out/last.log" 2>&1 ||
    { echo "nsni_free_edge: failed: order $order, $n², $*"; tail -n 3 "$out/last.log"; exit 1; }
  sed -n 's/.*"error_l2": \([-0-9.e+]*\).*/\1/p' "$out/run/summary.json"
}
printf '%-5s %-22s %-10s %-10s %-10s %-6s %-6s\n' order integration 21² 41² 81² slope slope
for order in 1 2; do
  for mode in gauss nsni nsni-novci; do
    case $mode in
      gauss) set=(--set quadrature.mode=gauss) ;;
      nsni) set=(--set quadrature.mode=nsni) ;;
      nsni-novci) set=(--set quadrature.mode=nsni --set quadrature.vci=false) ;;
    esac
    e=()
    for n in 21 41 81; do e+=("$(l2 "$order" "$n" "${set[@]}")"); done
    awk -v o="$order" -v m="$mode" -v a="${e[0]}" -v b="${e[1]}" -v c="${e[2]}" 'BEGIN {
      printf "%-5s %-22s %-10.3e %-10.3e %-10.3e %-6.2f %-6.2f\n", o, m, a, b, c, log(a / b) / log(2), log(b / c) / log(2) }'
  done
done
