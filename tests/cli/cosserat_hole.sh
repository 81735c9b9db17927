# Cosserat plate with a hole against Kaloni & Ariman (benchmarks.md): the SCF within 1 % over a/l from 0.5
# to 8 for N = 0.5 and 0.93, rising with a/l; and the classical limit 3 as N → 0. The reference values come
# from tests/reference/kaloni_ariman.c (Bessel functions by quadrature; it reproduces the benchmark's
# example 2.1351). Under the sanitizers (SAN=1) a subset runs: the numbers are checked by the normal run.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/cosserat_hole"
rm -rf "$work" && mkdir -p "$work"
cc -O2 tests/reference/kaloni_ariman.c -lm -o "$work/kaloni_ariman" || fail "cannot build the reference program"
within "$("$work/kaloni_ariman" 0.3 0.93 1.063)" 2.1351 1e-4 "reference program: benchmarks.md's example"

ratios="0.5 1 2 4 8"; couplings="0.5 0.93"
[ "${SAN:-}" = 1 ] && { ratios="0.5 8"; couplings="0.93"; }
for N in $couplings; do
  prev=0
  for al in $ratios; do
    d="$work/N${N}_al$al"
    run_deck "$d" input/cosserat_hole.cfg --set material.N=$N --set parameters.a_over_l=$al
    scf=$(json_value scf "$d/summary.json")
    within "$scf" "$("$work/kaloni_ariman" 0.3 $N $al)" 0.01 "Cosserat hole, N = $N, a/l = $al: SCF"
    less_than "$prev" "$scf" || fail "the SCF does not rise with a/l (N = $N, a/l = $al: $scf after $prev)"
    prev=$scf
  done
done
run_deck "$work/classical" input/cosserat_hole.cfg --set material.N=0.0001
within "$(json_value scf "$work/classical/summary.json")" 3 0.01 "Cosserat hole, N → 0: the classical SCF"
