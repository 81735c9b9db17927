#!/usr/bin/env bash
# The size-effect studies of issue 4, from the repository root:  bash examples/size-effects/run.sh
# Writes examples/size-effects/out/<study>/ (sweep.csv, summary.json, charts) and copies the charts to
# examples/size-effects/figures/.
set -euo pipefail
cd "$(dirname "$0")/../.."
here=examples/size-effects
make -s bin/mica >/dev/null
cc -O2 tests/reference/kaloni_ariman.c -lm -o "$here/out-kaloni_ariman" 2>/dev/null || cc -O2 tests/reference/kaloni_ariman.c -lm -o /tmp/kaloni_ariman
ka=$here/out-kaloni_ariman; [ -x "$ka" ] || ka=/tmp/kaloni_ariman
for N in 0.3 0.7 0.93; do
  { echo "# a/l, SCF (Kaloni & Ariman, nu = 0.3, N = $N)"
    awk 'BEGIN { for (i = 0; i <= 48; i++) printf "%.6g\n", 0.25 * exp(i / 48 * log(64)) }' |
      while read -r al; do echo "$al,$("$ka" 0.3 $N "$al")"; done; } > "$here/data/kaloni_ariman_N$N.csv"
done
rm -f "$here/out-kaloni_ariman"
cc -O2 tests/reference/gauthier_jahsman.c -lm -o /tmp/gauthier_jahsman.$$
{ echo "# diameter (mm), rigidity ratio (Gauthier & Jahsman; N = 0.62, l_t = 0.22 mm, Psi = 1.5)"
  awk 'BEGIN { for (i = 0; i <= 48; i++) printf "%.6g\n", 0.2 * exp(i / 48 * log(50)) }' |
    while read -r d; do echo "$d,$(/tmp/gauthier_jahsman.$$ 0.62 0.22 1.5 "$(awk -v d="$d" 'BEGIN { print d / 2 }')")"; done
} > "$here/data/gauthier_jahsman.csv"
rm -f /tmp/gauthier_jahsman.$$
for study in hole_scf beam_thickness bone_torsion; do
  bin/mica sweep "$here/$study.cfg" -o "$here/out/$study"
  cp "$here/out/$study/sweep.png" "$here/figures/$study.png"
  cp "$here/out/$study/sweep.svg" "$here/figures/$study.svg"
done
