#!/usr/bin/env bash
# Leaner supports and cheaper points (issue 20, item 2): per-phase cost of the peers problems, this build against
# a baseline build, alternating, the minimum of LEAN_REPEAT (3) runs per phase; and, with valgrind, the
# instructions of each phase (callgrind counts are the same under any load: same binary and input, same count).
#   BASE_DIR=/path/to/baseline/worktree bash bench/bench_lean.sh      (built there: bin/mica, lib/libmica.a)
#   [LEAN_IR=0 skips callgrind; LEAN_ONLY="hole-q4fb block-lin" restricts the decks; LEAN_SHAPE=0 skips part 1]
# Part 1: bench/bench_shape.c (MLS shape functions per point at the peers' bases and supports) built against this
# library and the baseline's, alternating, the minimum of LEAN_REPEAT runs of CPU µs per point, with the
# instructions per point under callgrind and a checksum of every N, ∇N, ∇∇N (equal: the same results).
# Part 2: the peers decks.
# Columns: pts/dof quadrature points per unknown, supp mean supporting particles per point, nnz/row of the tangent,
# then seconds per phase from summary.json (wall; CPU for cache+pattern and assembly: cpu_*), and with LEAN_IR the
# instructions (10^6) in the shape functions (mica_shape_cache_create: search, weights, basis, moment matrix; the
# boundary points too), the pattern (mica_sparse_create), the assemblies (mica_solid_assemble) and the whole solve
# (mica_solid_create_sharing + mica_newton_solve). Prints figures only; never fails on time.
set -u
cd "$(dirname "$0")/.."
NEW=${MICA_BIN:-bin/mica}
BASE_DIR=${BASE_DIR:-}
BASE=${BASE_BIN:-}
[ -n "$BASE_DIR" ] && [ -z "$BASE" ] && BASE=$BASE_DIR/bin/mica
REPEAT=${LEAN_REPEAT:-3}
IR=${LEAN_IR:-1}
out=${OUT_DIR:-build/bench-out}/lean
mkdir -p "$out"
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
command -v valgrind > /dev/null || IR=0

# name | deck and settings (the peers variants of bench/peers/peers.py at one of their benchmark sizes)
decks=(
  "beam-q-d4|input/timoshenko.cfg mls.order=2 mls.dilation=4.0 quadrature.order=4 particles.count=[33,9]"
  "beam-q|input/timoshenko.cfg mls.order=2 mls.dilation=3.0 quadrature.order=5 particles.count=[33,9]"
  "cook-q|input/cook_neohooke.cfg particles.count=[9,9]"
  "hole-q4fb|input/cosserat_hole.cfg mls.spacing=far mls.support=ball mls.dilation=2.7 quadrature.order=4 particles.count=[11,16]"
  "hole-q5r|input/cosserat_hole.cfg mls.dilation=3.5 quadrature.order=5 particles.count=[13,19]"
  "block-lin|bench/peers/block3d.cfg mls.order=1 mls.dilation=2.0 quadrature.order=4 particles.count=[13,4,4]"
  "block-quad|bench/peers/block3d.cfg mls.order=2 mls.dilation=3.0 quadrature.order=5 particles.count=[9,3,3]"
)
[ -n "${LEAN_EXTRA:-}" ] && decks+=("$LEAN_EXTRA")

v() { sed -n "s/^ *\"$1\": *\([^,]*\),\{0,1\}$/\1/p" "$2" | head -n 1; }
phases="time_search time_shape_functions time_pattern time_assemble cpu_cache_and_pattern cpu_assemble time_analyze time_factor time_newton"

run() { # bin dir deck sets...
  local bin=$1 dir=$2 deck=$3
  shift 3
  local sets=(--set output.vtu=false --set output.monitor=false)
  for s in "$@"; do sets+=(--set "$s"); done
  "$bin" run "$deck" -o "$dir" "${sets[@]}" > "$dir.log" 2>&1 || { echo "failed: $bin $deck (see $dir.log)" >&2; return 1; }
}

# min over the repeats of every phase: "phase value" lines
minima() { # dir-prefix
  for p in $phases; do
    local best=""
    for r in $(seq 1 "$REPEAT"); do
      local x
      x=$(v "$p" "$1-$r/summary.json")
      best=$(awk -v a="$best" -v b="$x" 'BEGIN { if (a == "" || b + 0 < a + 0) print b; else print a }')
    done
    echo "$p $best"
  done
}

# instructions (millions) per phase under callgrind
instructions() { # bin dir deck sets...
  local bin=$1 dir=$2 deck=$3
  shift 3
  local sets=(--set output.vtu=false --set output.monitor=false)
  for s in "$@"; do sets+=(--set "$s"); done
  valgrind --tool=callgrind --callgrind-out-file="$dir.cg" --toggle-collect=mica_solid_create_sharing \
    --toggle-collect=mica_newton_solve "$bin" run "$deck" -o "$dir" "${sets[@]}" > "$dir.cglog" 2>&1 || return 1
  callgrind_annotate --inclusive=yes "$dir.cg" 2> /dev/null | awk '
    { gsub(",", "", $1) }
    /PROGRAM TOTALS/ { total = $1 }
    /:mica_shape_cache_create / { shape = $1 } /:mica_sparse_create / { pattern = $1 }
    /:mica_solid_assemble / { assemble = $1 }
    END { printf "%.1f %.1f %.1f %.1f", shape / 1e6, pattern / 1e6, assemble / 1e6, total / 1e6 }'
}

# ---- part 1: shape functions per point ----
shape_part() {
  local new_shape=build/bench/bench_shape base_shape=$out/bench_shape_base npts=${LEAN_POINTS:-5000}
  make -s build/bench/bench_shape > /dev/null || return
  mpicc -Iinclude -I/usr/include/suitesparse -std=c11 -D_POSIX_C_SOURCE=200809L -O2 -g bench/bench_shape.c \
    "$BASE_DIR/lib/libmica.a" $(pkg-config --libs PETSc) -lmetis -lconfig -lmatheval -lcholmod -lumfpack \
    -lsuitesparseconfig -llapacke -llapack -lblas -lm -o "$base_shape" || return
  for r in $(seq 1 "$REPEAT"); do
    "$base_shape" "$npts" > "$out/shape-base-$r.txt"
    "$new_shape" "$npts" > "$out/shape-new-$r.txt"
  done
  echo "MLS shape functions per point (bench/bench_shape.c, $npts random points, CPU us/pt: min of $REPEAT alternating runs)"
  printf '%-26s %4s %-4s %-13s %13s %9s %9s %7s' case m supp dilation support us.base us.new ratio
  [ "$IR" = 1 ] && printf ' %10s %10s %7s' Ir.base Ir.new ratio
  printf ' %s\n' results
  local ncases
  ncases=$(wc -l < "$out/shape-new-1.txt")
  for i in $(seq 0 $((ncases - 1))); do
    local line b n
    line=$(sed -n "$((i + 1))p" "$out/shape-new-1.txt")
    b=$(for r in $(seq 1 "$REPEAT"); do sed -n "$((i + 1))p" "$out/shape-base-$r.txt"; done | sed 's/.* \([0-9.]*\) us\/pt.*/\1/' | sort -g | head -n 1)
    n=$(for r in $(seq 1 "$REPEAT"); do sed -n "$((i + 1))p" "$out/shape-new-$r.txt"; done | sed 's/.* \([0-9.]*\) us\/pt.*/\1/' | sort -g | head -n 1)
    printf '%s %9.3f %9.3f %7.2f' "$(echo "$line" | sed 's/ *[0-9.]* us\/pt.*//')" "$b" "$n" "$(awk -v b="$b" -v n="$n" 'BEGIN { print b / n }')"
    if [ "$IR" = 1 ]; then
      local ib in
      ib=$(valgrind --tool=callgrind --toggle-collect=mls_eval --callgrind-out-file=/dev/null "$base_shape" 300 "$i" 2>&1 >/dev/null | sed -n 's/.*Collected : \([0-9]*\).*/\1/p')
      in=$(valgrind --tool=callgrind --toggle-collect=mls_eval --callgrind-out-file=/dev/null "$new_shape" 300 "$i" 2>&1 >/dev/null | sed -n 's/.*Collected : \([0-9]*\).*/\1/p')
      printf ' %10.0f %10.0f %7.2f' "$(awk -v x="$ib" 'BEGIN { print x / 900 }')" "$(awk -v x="$in" 'BEGIN { print x / 900 }')" \
        "$(awk -v b="$ib" -v n="$in" 'BEGIN { print b / n }')"
    fi
    local cb cn
    cb=$(sed -n "$((i + 1))p" "$out/shape-base-1.txt" | sed 's/.*checksum //'); cn=$(echo "$line" | sed 's/.*checksum //')
    [ "$cb" = "$cn" ] && printf ' identical\n' || printf ' differ (%s, %s)\n' "$cb" "$cn"
  done
  echo "(Ir: instructions per point in mls_eval under callgrind, 300 points x 3 repeats; results: the checksum of"
  echo " every N, dN (ddN) to 17 digits, base against new)"
  echo
}
[ -n "$BASE_DIR" ] && [ "${LEAN_SHAPE:-1}" = 1 ] && shape_part

# ---- part 2: the peers decks per phase ----
printf '%-11s %-5s %7s %6s %7s %8s %8s %8s %8s %8s %8s %8s %8s %8s' deck build pts/dof supp nnz/row search shape \
  pattern assemble cpu.c+p cpu.asm analyze factor newton
[ "$IR" = 1 ] && printf ' %9s %9s %9s %9s' Mi.shape Mi.patt Mi.asm Mi.solve
echo
for entry in "${decks[@]}"; do
  name=${entry%%|*}
  words=(${entry#*|})
  deck=${words[0]}
  sets=("${words[@]:1}")
  if [ -n "${LEAN_ONLY:-}" ] && [[ " $LEAN_ONLY " != *" $name "* ]]; then continue; fi
  builds="new"
  [ -n "$BASE" ] && builds="base new"
  for r in $(seq 1 "$REPEAT"); do # alternating: base, new, base, new, ...
    for b in $builds; do
      bin=$NEW
      [ "$b" = base ] && bin=$BASE
      run "$bin" "$out/$name-$b-$r" "$deck" "${sets[@]}" || continue 3
    done
  done
  for b in $builds; do
    s="$out/$name-$b-1/summary.json"
    bin=$NEW
    [ "$b" = base ] && bin=$BASE
    printf '%-11s %-5s %7.2f %6.1f %7.0f' "$name" "$b" \
      "$(awk -v p="$(v quadrature_points "$s")" -v d="$(v dofs "$s")" 'BEGIN { print p / d }')" "$(v support_mean "$s")" \
      "$(awk -v n="$(v nnz "$s")" -v d="$(v dofs "$s")" 'BEGIN { print n / d }')"
    minima "$out/$name-$b" | awk '{ printf " %8.4f", $2 }'
    [ "$IR" = 1 ] && printf ' %9s %9s %9s %9s' $(instructions "$bin" "$out/$name-$b-ir" "$deck" "${sets[@]}")
    echo
  done
  # the same answer: every probe and error norm of the two builds' first runs, all 17 digits of summary.json
  if [ -n "$BASE" ]; then
    keys="$(sed -n 's/^probe \([^ ]*\) = .*/\1/p' "$out/$name-new-1.log") error_l2 error_energy"
    a="" c=""
    for k in $keys; do
      a="$a $k=$(v "$k" "$out/$name-base-1/summary.json")"; c="$c $k=$(v "$k" "$out/$name-new-1/summary.json")"
    done
    [ "$a" = "$c" ] && echo "            identical:$a" || echo "            differ: base [$a] new [$c]"
  fi
done
echo "(seconds: wall per phase from summary.json but cpu.c+p and cpu.asm (CPU); min of $REPEAT alternating runs;"
echo " Mi.*: 10^6 instructions under callgrind; analyze/factor: CHOLMOD, factor includes analyze)"
