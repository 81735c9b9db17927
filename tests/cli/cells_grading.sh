# quadrature.cells with counts other than the particle spacings (src/geom/cells.c): the cells follow the particle
# lines, so k (count − 1) cells split every spacing of a graded layout into k equal parts. On the Timoshenko beam
# (0 ≤ x ≤ 48) with 9 particles along x graded 4:1 (x_i = 48 Σ_{m<i} q^m / Σ_{m<8} q^m, q = 4^(1/7); layout.c) and
# 16 cells along x, Gauss order 2: every particle spacing must hold exactly 2 cells × 2 points × (2 cells × 2
# points across) = 16 points of quadrature_fields.csv, and the two points of a cell must sit at the Gauss
# abscissae of the half-spacing (±1/√3 of its half width, 1e-9). Equal cells in parameter space (the behaviour
# before) put 8 points in the first spacing and 28 in the last. The tip deflection must stay within 1 % of the
# analytic 0.0089 (the quadrature changed, not the problem).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/cells_grading"
rm -rf "$work" && mkdir -p "$work"

run_deck "$work/graded" input/timoshenko.cfg --set particles.layout='"graded"' --set 'particles.count=[9,3]' \
  --set 'particles.grading=[4.0,1.0]' --set 'quadrature.cells=[16,2]' --set quadrature.order=2 \
  --set mls.dilation=3.0 --set output.quadrature_fields=true
python3 - "$work/graded/quadrature_fields.csv" <<'EOF'
import csv, math, sys
n, L, grading = 9, 48.0, 4.0
q = grading ** (1.0 / (n - 2))
h = [q ** m for m in range(n - 1)]
x = [L * sum(h[:i]) / sum(h) for i in range(n)]
xs = [float(r["x"]) for r in csv.DictReader(open(sys.argv[1]))]
counts = [sum(1 for v in xs if x[i] < v < x[i + 1]) for i in range(n - 1)]
print("points per particle spacing:", counts)
if counts != [16] * (n - 1):
    sys.exit("FAIL: the cells do not follow the graded particle lines (expected 16 points in every spacing)")
worst = 0.0
for i in range(n - 1):  # two cells per spacing, Gauss abscissae ±1/√3 of each half
    for half in range(2):
        a = x[i] + half * (x[i + 1] - x[i]) / 2
        b = a + (x[i + 1] - x[i]) / 2
        mid, rad = (a + b) / 2, (b - a) / 2 / math.sqrt(3)
        for g in (mid - rad, mid + rad):
            worst = max(worst, min(abs(v - g) for v in xs))
print("largest distance of a Gauss abscissa from the nearest point: %.2e" % worst)
if worst > 1e-9:
    sys.exit("FAIL: a cell's Gauss points are not at the half-spacing's abscissae")
print("ok: 16 points in every graded spacing, at the half-spacings' Gauss abscissae")
EOF
within "$(json_value tip_uy "$work/graded/summary.json")" 0.0089 0.01 "graded cells: tip deflection"
