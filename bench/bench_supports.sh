#!/usr/bin/env bash
# How small may the supports be (issue 20, item 2)? For basis order 1 and 2 in 2-D and 3-D, on regular and on
# jittered (0.3 spacing) particles, a scan of mls.dilation on a smooth manufactured field (input/manufactured.cfg,
# 2-D: sin/cos, 21 x 21 particles; bench/lean_manufactured3d.cfg, 3-D: 9 x 9 x 9): the smallest reciprocal condition
# estimate of a moment matrix (rcond_min in summary.json; the run stops at mls.rcond_min = 1e-13), the mean
# supporting particles per point, nonzeros per row, the relative L2 and energy errors, and the CPU seconds of the
# shape functions + pattern and the assembly with the wall seconds of the factorization.
#   bash bench/bench_supports.sh        SUPPORTS_ONLY="2 1" runs one dimension and order
#   SUPPORTS_MODE=cost bash bench/bench_supports.sh   error against cost under refinement, a few dilations
# Prints figures only; never fails on time or error.
set -u
cd "$(dirname "$0")/.."
MICA=${MICA_BIN:-bin/mica}
out=${OUT_DIR:-build/bench-out}/supports
mkdir -p "$out"
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
v() { sed -n "s/^ *\"$1\": *\([^,]*\),\{0,1\}$/\1/p" "$2" | head -n 1; }

scan() { # dim order support "dilations"
  local dim=$1 order=$2 support=$3 dils=$4 deck count qo
  if [ "$dim" = 2 ]; then deck=input/manufactured.cfg count="[21,21]" qo=$((order + 3)); else
    deck=bench/lean_manufactured3d.cfg count="[9,9,9]" qo=$((order + 2)); fi
  for layout in regular jittered; do
    for dil in $dils; do
      local d="$out/d$dim-o$order-$support-$layout-$dil"
      local sets=(--set "particles.count=$count" --set "mls.order=$order" --set "mls.dilation=$dil"
        --set "mls.support=$support" --set "quadrature.order=$qo" --set output.vtu=false --set output.monitor=false)
      [ "$layout" = jittered ] && sets+=(--set particles.layout=jittered --set particles.jitter=0.3)
      printf '%d-D %d %-4s %-8s %4s ' "$dim" "$order" "$support" "$layout" "$dil"
      if ! "$MICA" run "$deck" -o "$d" "${sets[@]}" > "$d.log" 2>&1; then
        echo "  failed: $(grep -o 'reciprocal condition [^ ]*' "$d.log" | head -n 1 || true) (see $d.log)"
        continue
      fi
      local s="$d/summary.json"
      awk -v sp="$(v support_mean "$s")" -v nnz="$(v nnz "$s")" -v dofs="$(v dofs "$s")" -v rc="$(v rcond_min "$s")" \
        -v l2="$(v error_l2 "$s")" -v en="$(v error_energy "$s")" -v cp="$(v cpu_cache_and_pattern "$s")" \
        -v ca="$(v cpu_assemble "$s")" -v fa="$(v time_factor "$s")" \
        'BEGIN { printf "%7.1f %8.0f %9.2e %9.2e %9.2e %8.4f %8.4f %8.4f\n", sp, nnz / dofs, rc, l2, en, cp, ca, fa }'
    done
  done
}

# Error per cost: the same field refined at a few dilations (SUPPORTS_MODE=cost); cost = CPU seconds of shape
# functions + pattern + assembly and the wall seconds of the factorization (one run each).
refine() { # dim order layout "dilations" "counts"
  local dim=$1 order=$2 layout=$3 dils=$4 counts=$5 deck qo
  if [ "$dim" = 2 ]; then deck=input/manufactured.cfg qo=$((order + 3)); else deck=bench/lean_manufactured3d.cfg qo=$((order + 2)); fi
  for dil in $dils; do
    for n in $counts; do
      local count="[$n,$n]"
      [ "$dim" = 3 ] && count="[$n,$n,$n]"
      local d="$out/r$dim-o$order-$layout-$dil-$n"
      local sets=(--set "particles.count=$count" --set "mls.order=$order" --set "mls.dilation=$dil"
        --set "quadrature.order=$qo" --set output.vtu=false --set output.monitor=false)
      [ "$layout" = jittered ] && sets+=(--set particles.layout=jittered --set particles.jitter=0.3)
      printf '%d-D %d %-8s %4s %4s ' "$dim" "$order" "$layout" "$dil" "$n"
      if ! "$MICA" run "$deck" -o "$d" "${sets[@]}" > "$d.log" 2>&1; then echo "  failed (see $d.log)"; continue; fi
      local s="$d/summary.json"
      awk -v dofs="$(v dofs "$s")" -v sp="$(v support_mean "$s")" -v nnz="$(v nnz "$s")" -v rc="$(v rcond_min "$s")" \
        -v en="$(v error_energy "$s")" -v cp="$(v cpu_cache_and_pattern "$s")" -v ca="$(v cpu_assemble "$s")" \
        -v fa="$(v time_factor "$s")" \
        'BEGIN { printf "%7d %7.1f %8.0f %9.2e %9.2e %8.4f\n", dofs, sp, nnz / dofs, rc, en, cp + ca + fa }'
    done
  done
}
if [ "${SUPPORTS_MODE:-scan}" = cost ]; then
  echo "dim order layout dilation n | dofs supp nnz/row rcond_min e_energy cost[s]"
  refine 2 1 regular "1.5 2.0 2.5" "11 21 41"
  refine 2 2 regular "2.5 3.0 3.5" "11 21 41"
  refine 2 2 jittered "2.7 3.0 3.5" "11 21 41"
  refine 3 1 regular "1.5 2.0" "7 9 13"
  refine 3 2 regular "2.5 3.0" "5 7 9"
  exit 0
fi

echo "dim order support layout dilation | supp nnz/row rcond_min e_L2 e_energy cpu.c+p cpu.asm factor"
want() { [ -z "${SUPPORTS_ONLY:-}" ] || [ "$SUPPORTS_ONLY" = "$1 $2" ]; }
want 2 1 && scan 2 1 box "1.1 1.3 1.5 1.7 2.0"
want 2 1 && scan 2 1 ball "1.1 1.3 1.5 1.7 2.0"
want 2 2 && scan 2 2 box "1.6 1.8 2.0 2.2 2.5 2.7 3.0"
want 2 2 && scan 2 2 ball "1.6 1.8 2.0 2.2 2.5 2.7 3.0"
want 3 1 && scan 3 1 box "1.1 1.3 1.5 1.7 2.0"
want 3 1 && scan 3 1 ball "1.1 1.3 1.5 1.7 2.0"
want 3 2 && scan 3 2 box "1.6 1.8 2.0 2.2 2.5 3.0"
want 3 2 && scan 3 2 ball "1.8 2.0 2.2 2.5 3.0"
echo "(supp: mean supporting particles per quadrature point; 2-D: 21 x 21 particles, Gauss order = order + 3;"
echo " 3-D: 9 x 9 x 9, Gauss order = order + 2; jittered: particles.jitter = 0.3; default mls.dilation = order + 1)"
