#!/usr/bin/env bash
# The fill-reducing ordering of CHOLMOD's factorization (src/solve/linear_cholmod.c, node_ordering): this build
# against a baseline binary, alternating, the minimum of ORDERING_REPEAT (3) runs, on the peers problems at one of
# their sizes and on larger 3-D boxes. Per deck and binary: the ordering summary.json reports (factor_ordering;
# the baseline has none: CHOLMOD's default, AMD on the unknowns, METIS when AMD fills much), the factor's entries
# and flops, the analysis and the numeric factorization (seconds, wall; time_factor less time_analyze), the solve
# phases in all, and the energy error where the deck has one (the same to round-off: only the order of the
# elimination changes).
#   BASE_BIN=/path/to/baseline/bin/mica bash bench/bench_ordering.sh     [ORDERING_ONLY="m3-ball-13 block-k3"]
# Prints figures only; never fails on time.
set -u
cd "$(dirname "$0")/.."
NEW=${MICA_BIN:-bin/mica}
BASE=${BASE_BIN:?set BASE_BIN to a baseline build of bin/mica}
REPEAT=${ORDERING_REPEAT:-3}
out=${OUT_DIR:-build/bench-out}/ordering
mkdir -p "$out"
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
v() { sed -n "s/^ *\"$1\": *\"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$2" | head -n 1; }

# name | deck and settings
decks=(
  "m3-ball-13|input/manufactured3d.cfg mls.order=2 mls.dilation=3.0 mls.support=ball quadrature.order=2 quadrature.vci=true particles.count=[13,13,13]"
  "m3-box-13|input/manufactured3d.cfg mls.order=2 mls.dilation=3.0 quadrature.order=3 particles.count=[13,13,13]"
  "m3-lin-21|input/manufactured3d.cfg mls.order=1 mls.dilation=2.0 quadrature.order=3 particles.count=[21,21,21]"
  "block-k3|bench/peers/block3d.cfg mls.order=2 mls.dilation=4.0 quadrature.order=2 particles.count=[13,4,4]"
  "block-k4|bench/peers/block3d.cfg mls.order=2 mls.dilation=4.0 quadrature.order=2 particles.count=[17,5,5]"
  "m2-d4-31|input/manufactured.cfg mls.order=2 mls.dilation=4.0 quadrature.order=4 particles.count=[31,31]"
  "hole-q4fb|input/cosserat_hole.cfg mls.spacing=far mls.support=ball mls.dilation=2.7 quadrature.order=4 particles.count=[13,19]"
  "beam-d4|input/timoshenko.cfg mls.order=2 mls.dilation=4.0 quadrature.order=4 particles.count=[65,17]"
)

run_one() { # binary deck settings... -> "analyze factor solve_phases ordering nnz_factor flops error"
  local bin=$1 dir=$2 deck=$3; shift 3
  local sets=()
  for s in "$@"; do sets+=(--set "$s"); done
  rm -rf "$dir"
  "$bin" run "$deck" -o "$dir" --set output.vtu=false --set output.monitor=false "${sets[@]}" > "$dir.log" 2>&1 \
    || { echo "failed: $bin $deck $*" >&2; tail -n 3 "$dir.log" >&2; return 1; }
  local s=$dir/summary.json
  awk -v a="$(v time_analyze "$s")" -v f="$(v time_factor "$s")" -v m="$(v time_mls_setup "$s")" \
      -v c="$(v time_cache_and_pattern "$s")" -v n="$(v time_newton "$s")" -v o="$(v factor_ordering "$s")" \
      -v l="$(v nnz_factor "$s")" -v fl="$(v factor_flops "$s")" -v e="$(v error_energy "$s")" \
      'BEGIN { printf "%.4f %.4f %.4f %s %d %.3g %s\n", a, f - a, m + c + n, (o == "" ? "default" : o), l, fl, (e == "" ? "-" : e) }'
}

min_of() { sort -g | head -n 1; }

printf "%-10s %-5s %-8s %12s %10s %9s %9s %9s %-14s\n" deck build ordering "nnz(L)" flops analyze factor solve error
for entry in "${decks[@]}"; do
  name=${entry%%|*}
  if [ -n "${ORDERING_ONLY:-}" ] && ! grep -qw -- "$name" <<<"$ORDERING_ONLY"; then continue; fi
  read -r -a args <<<"${entry#*|}"
  : > "$out/$name.base" && : > "$out/$name.new"
  for ((r = 0; r < REPEAT; r++)); do
    run_one "$BASE" "$out/$name-base" "${args[@]}" >> "$out/$name.base" || exit 1
    run_one "$NEW" "$out/$name-new" "${args[@]}" >> "$out/$name.new" || exit 1
  done
  for build in base new; do
    f=$out/$name.$build
    a=$(cut -d' ' -f1 "$f" | min_of); fa=$(cut -d' ' -f2 "$f" | min_of); t=$(cut -d' ' -f3 "$f" | min_of)
    read -r _ _ _ ord lnz fl err < "$f"
    printf "%-10s %-5s %-8s %12d %10s %9.4f %9.4f %9.4f %-14s\n" "$name" "$build" "$ord" "$lnz" "$fl" "$a" "$fa" "$t" "$err"
  done
  tb=$(cut -d' ' -f3 "$out/$name.base" | min_of); tn=$(cut -d' ' -f3 "$out/$name.new" | min_of)
  awk -v b="$tb" -v n="$tn" -v d="$name" 'BEGIN { printf "%-10s solve phases new / base: %.3f\n", d, n / b }'
done
