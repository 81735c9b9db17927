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
for study in timoshenko manufactured; do
  bin/mica study "$here/$study.cfg" -o "$here/out/$study" "$@"
  for chart in study_time study_dofs; do
    cp "$here/out/$study/$chart.png" "$here/figures/${study}_${chart#study_}.png"
    cp "$here/out/$study/$chart.svg" "$here/figures/${study}_${chart#study_}.svg"
  done
done
# the fastest to the target by each time measure, recomputed from study.csv
for study in timoshenko manufactured; do
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
