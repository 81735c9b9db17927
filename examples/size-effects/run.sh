#!/usr/bin/env bash
# The size-effect studies of issue 4, from the repository root:  bash examples/size-effects/run.sh
# Writes examples/size-effects/out/<study>/ (sweep.csv, summary.json, charts and their gnuplot script
# sweep_chart.gp) and copies the charts to examples/size-effects/figures/. The analytic references
# (Kaloni & Ariman, Gauthier & Jahsman, 1 + (l/h)^2) are formulas in the decks, evaluated by mica.
set -euo pipefail
cd "$(dirname "$0")/../.."
here=examples/size-effects
make -s bin/mica >/dev/null
for study in hole_scf beam_thickness bone_torsion; do
  bin/mica sweep "$here/$study.cfg" -o "$here/out/$study"
  cp "$here/out/$study/sweep.png" "$here/figures/$study.png"
  cp "$here/out/$study/sweep.svg" "$here/figures/$study.svg"
done
