# output.quadrature_fields (src/app/quadrature_output.c): the fields at the error-norm points, from which a
# reader computes its own error norms. On the Timoshenko beam (exact solution, plane stress) the file must
# reproduce mica's own numbers: Σ w W over the rows = the `energy` probe (1e-10 relative: the same points, the
# same kernel; only the summation order and the %.17g print differ), W = ½ ε:C:ε of the row's own gradients
# (1e-10 of the largest W), and the relative energy-norm error from the rows' gradients against the exact
# ones = error_energy (1e-8), on the solve's points and on quadrature.error_order's own. Also: rows = points, off → no file,
# a wrong type → exit 2 at the deck line with no file left behind, MPI without error_order → exit 2.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/quadrature_fields"
rm -rf "$work" && mkdir -p "$work"
energy_probe=(--set 'output.probes=( { name = "U"; field = "energy"; } )')

# check DIR: Σ w W, W per row and the energy-norm error recomputed from DIR/quadrature_fields.csv (plain python,
# the exact gradients of input/timoshenko.cfg); prints "sum_wW max_W_mismatch/max_W rel_energy_error rows"
check() {
  python3 - "$1/quadrature_fields.csv" <<'EOF'
import csv, math, sys
L, D, E, nu, P = 48.0, 12.0, 3.0e7, 0.3, 1000.0
I = D ** 3 / 12
k = P / (6 * E * I)
def exact_grad(x, y):  # d(ux)/dx, d(ux)/dy, d(uy)/dx, d(uy)/dy of the deck's exact solution
    return (-k * y * (6 * L - 6 * x),
            -k * ((6 * L - 3 * x) * x + (2 + nu) * (y * y - D * D / 4)) - k * y * (2 + nu) * 2 * y,
            k * (-3 * nu * y * y + (4 + 5 * nu) * D * D / 4 + 6 * L * x - 3 * x * x),
            k * 6 * nu * y * (L - x))
def eCe(g):  # ε:C:ε, plane stress, ε = sym(∇u)
    exx, eyy, exy = g[0], g[3], 0.5 * (g[1] + g[2])
    c = E / (1 - nu * nu)
    return c * (exx * exx + eyy * eyy + 2 * nu * exx * eyy) + 4 * E / (2 * (1 + nu)) * exy * exy
rows = list(csv.DictReader(open(sys.argv[1])))
names = ("dux_dx", "dux_dy", "duy_dx", "duy_dy")
sum_w_W = err = ref = worst = 0.0
W_max = max(abs(float(r["W"])) for r in rows)
for r in rows:
    w, W = float(r["w"]), float(r["W"])
    g = [float(r[n]) for n in names]
    ge = exact_grad(float(r["x"]), float(r["y"]))
    sum_w_W += w * W
    worst = max(worst, abs(W - 0.5 * eCe(g)) / W_max)
    err += w * eCe([a - b for a, b in zip(g, ge)])
    ref += w * eCe(ge)
print("%.17g %.3e %.17g %d" % (sum_w_W, worst, math.sqrt(err / ref), len(rows)))
EOF
}

# the solve's own points (quadratic basis, 5 x 5 Gauss points per cell)
base=(--set mls.order=2 --set mls.dilation=3.0 --set quadrature.order=5 --set "particles.count=[25,7]")
run_deck "$work/solve" input/timoshenko.cfg "${base[@]}" "${energy_probe[@]}" --set output.quadrature_fields=true
s="$work/solve/summary.json"
read -r sum worst err rows <<<"$(check "$work/solve")"
[ "$rows" = "$(json_value error_points "$s")" ] || fail "rows $rows, error_points $(json_value error_points "$s")"
[ "$rows" = "$(json_value quadrature_fields_points "$s")" ] || fail "rows $rows, quadrature_fields_points"
ok "solve points: $rows rows = error_points"
within "$sum" "$(json_value U "$s")" 1e-10 "solve points: Σ w W of the rows against the energy probe"
within "$sum" "$(json_value quadrature_fields_energy "$s")" 1e-10 "solve points: Σ w W against quadrature_fields_energy"
less_than "$worst" 1e-10 || fail "W is not ½ ε:C:ε of the row's gradients (worst relative mismatch $worst)"
ok "solve points: W = ½ ε:C:ε of the row's gradients (worst $worst)"
within "$err" "$(json_value error_energy "$s")" 1e-8 "solve points: energy-norm error from the rows against error_energy"

# quadrature.error_order's own points: 8 x 8 per background cell (24 x 6 cells)
run_deck "$work/e8" input/timoshenko.cfg "${base[@]}" "${energy_probe[@]}" --set output.quadrature_fields=true \
  --set quadrature.error_order=8
s="$work/e8/summary.json"
read -r sum worst err rows <<<"$(check "$work/e8")"
[ "$rows" = $((24 * 6 * 64)) ] || fail "error_order = 8: $rows rows, expected 24 x 6 cells x 64 points"
[ "$rows" = "$(json_value error_points "$s")" ] || fail "error_order = 8: rows $rows, error_points $(json_value error_points "$s")"
ok "error_order = 8: $rows rows = error_points"
within "$err" "$(json_value error_energy "$s")" 1e-8 "error_order = 8: energy-norm error from the rows against error_energy"
# other points, other sum: the 8 x 8 points' Σ w W differs from the 5 x 5 solve points' by 3e-7 (measured)
within "$sum" "$(json_value U "$s")" 1e-5 "error_order = 8: Σ w W against the energy probe (other points)"

# off (the default): no file
run_deck "$work/off" input/timoshenko.cfg "${base[@]}"
[ ! -e "$work/off/quadrature_fields.csv" ] || fail "output.quadrature_fields = false wrote quadrature_fields.csv"
ok "off: no quadrature_fields.csv"

# a wrong type: exit 2 at the deck's line, nothing written
sed 's/^output = {/output = { quadrature_fields = "yes";/' input/timoshenko.cfg > "$work/bad_qf.cfg"
line=$(grep -n 'quadrature_fields = "yes"' "$work/bad_qf.cfg" | cut -d: -f1)
expect_failure 2 "bad_qf.cfg:$line: output.quadrature_fields must be" -- "$MICA" run "$work/bad_qf.cfg" -o "$work/bad"
[ -z "$(ls -A "$work/bad" 2>/dev/null)" ] || fail "the refused deck left files: $(ls -A "$work/bad")"
ok "wrong type: nothing written"

# MPI: the solve's points are split among the ranks, so the option needs quadrature.error_order
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
MPIRUN=(timeout 300 mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
mpi_leak_checks # under SAN=1: the ranks leak-checked with the slow unwinder (common.bash)
if out=$("${MPIRUN[@]}" -np 2 "$MICA" --version 2>&1) && [ "$(grep -c '^mica ' <<<"$out")" -ge 1 ]; then
  expect_failure 2 "output.quadrature_fields under MPI needs quadrature.error_order" -- "${MPIRUN[@]}" -np 2 \
    "$MICA" run input/timoshenko.cfg -o "$work/mpi_refused" --set output.quadrature_fields=true --set output.vtu=false
  [ ! -e "$work/mpi_refused/quadrature_fields.csv" ] || fail "MPI: refused run wrote quadrature_fields.csv"
  "${MPIRUN[@]}" -np 2 "$MICA" run input/timoshenko.cfg -o "$work/mpi" --set output.quadrature_fields=true \
    --set output.vtu=false --set output.monitor=false --set quadrature.error_order=6 > "$work/mpi.log" 2>&1 \
    || fail "MPI with error_order: $(tail -n 3 "$work/mpi.log")"
  run_deck "$work/serial6" input/timoshenko.cfg --set output.quadrature_fields=true --set quadrature.error_order=6
  cmp -s "$work/mpi/quadrature_fields.csv" "$work/serial6/quadrature_fields.csv" \
    && ok "MPI with error_order: rank 0 writes the serial run's file" \
    || { read -r _ _ e_mpi _ <<<"$(check "$work/mpi")"; read -r _ _ e_ser _ <<<"$(check "$work/serial6")"
         within "$e_mpi" "$e_ser" 1e-8 "MPI with error_order: energy-norm error from the rows against the serial file's"; }
else
  echo "### SKIPPED: mpirun cannot start 2 processes here; the MPI checks of output.quadrature_fields are untested ###"
fi
