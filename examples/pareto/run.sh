#!/usr/bin/env bash
# The speed-against-accuracy studies of issue 5, from the repository root:  bash examples/pareto/run.sh
# Writes examples/pareto/out/<study>/ (study.csv, summary.json, points/, charts), copies the charts to
# examples/pareto/figures/, and prints, from each study.csv, the fastest combination that reaches the
# deck's target under both time measures (solve: assembly + factorization + solution; total: every phase).
set -euo pipefail
cd "$(dirname "$0")/../.."
here=examples/pareto
make -s bin/mica >/dev/null
mkdir -p "$here/figures"
for study in timoshenko timoshenko_fe manufactured; do
  bin/mica study "$here/$study.cfg" -o "$here/out/$study" "$@"
  for chart in study_time study_dofs; do
    cp "$here/out/$study/$chart.png" "$here/figures/${study}_${chart#study_}.png"
    cp "$here/out/$study/$chart.svg" "$here/figures/${study}_${chart#study_}.svg"
  done
done
# EFG against the FE measuring stick on the same beam: energy error against solve time, one point set per
# basis order or element, from the two study.csv files (columns found by name)
efg=$here/out/timoshenko/study.csv fe=$here/out/timoshenko_fe/study.csv
series() {  # series CSV ORDER: "time error" of the ok rows of that order
  awk -F, -v k="$2" 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    $c["status"] == "ok" && $c["parameters.k"] == k { print $c["time_solve_total"], $c["error_energy"] }' "$1"
}
for k in 1 2 3; do series "$efg" $k > "$here/out/efg_k$k.dat"; done
for k in 1 2; do series "$fe" $k > "$here/out/fe_k$k.dat"; done
gnuplot <<GP
set terminal pngcairo size 1050,600 noenhanced
set output "$here/figures/timoshenko_efg_fe.png"
set logscale xy; set grid; set key outside right top box; set format y "%.0e"; set format x "%g"
set xlabel "solve time (assembly + factorization + solution), s"; set ylabel "relative energy-norm error"
set title "Timoshenko cantilever: EFG (MLS) against finite elements on the same particles"
set arrow from graph 0, first 1e-3 to graph 1, first 1e-3 nohead dt 2 lw 1.5 lc rgb "black"  # the target, full width
# Okabe & Ito's colours (docs/input.md §Charts): EFG open markers, FE filled
plot "$here/out/efg_k1.dat" t "EFG linear" pt 6 lc rgb "#0072B2", "$here/out/efg_k2.dat" t "EFG quadratic" pt 8 lc rgb "#D55E00", \
     "$here/out/efg_k3.dat" t "EFG cubic" pt 4 lc rgb "#009E73", "$here/out/fe_k1.dat" t "FE Q1" pt 7 lc rgb "#CC79A7", \
     "$here/out/fe_k2.dat" t "FE Q2" pt 9 lc rgb "#E69F00", 1e-3 t "target 1e-3" dt 2 lw 1.5 lc rgb "black"
GP
# the fastest to the target by each time measure, recomputed from study.csv
for study in timoshenko timoshenko_fe manufactured; do
  csv=$here/out/$study/study.csv
  target=$(sed -n 's/^ *"target": \(.*\),$/\1/p' "$here/out/$study/summary.json")
  for measure in time_solve_total time_total; do
    awk -F, -v measure=$measure -v T="$target" -v study=$study '
      NR == 1 { for (i = 1; i <= NF; i++) { c[$i] = i; h[i] = $i }; next }
      $c["status"] == "ok" && $c["error"] + 0 <= T + 0 && (best == "" || $c[measure] + 0 < bt + 0) { best = $0; bt = $c[measure] }
      END {
        if (best == "") { printf "%s: no combination reaches %g\n", study, T; exit }
        split(best, f, ",")
        printf "%s: fastest to error <= %g by %s: combination %s (", study, T, measure, f[1]
        for (i = 2; i < c["status"]; i++) printf "%s%s=%s", (i > 2 ? " " : ""), h[i], f[i]
        printf ") %s = %.4g s, error %.3e, %s dofs\n", measure, bt, f[c["error"]], f[c["dofs"]]
      }' "$csv"
  done
done
