# Nearly incompressible solids (issue 21 item 2; docs/verification.md §Nearly incompressible Cook's membrane,
# docs/theory.md §Nearly incompressible solids): material.pressure = "cell-linear" (a pressure linear in each
# background cell, condensed: B-bar / F-bar) against the Taylor-Hood P2/P1 references computed with FEniCS
# (bench/peers/cook_taylor_hood.py; the values are committed, FEniCS is not needed here):
#  - Cook's membrane, plane strain, E = 1, nu = 0.4999, linear (F = 1) and Neo-Hooke (F = 0.3): the mixed
#    form within 0.5 % of the reference; the displacement form (material.pressure = "none") beside it, more
#    than 1 % off; Newton's last iterations on Neo-Hooke converge quadratically (rate >= 1.5 in the log);
#  - order 1 with a small support (dilation 1.5, uniform 33 x 33): the mixed form within 2.5 % of the
#    reference, the displacement form locks (more than 10 % off);
#  - the inf-sup test of `mica stability` on input/infsup_block.cfg, N = 5, 9, 17, 25: the mixed form's β
#    bounded below (each ratio β_N'/β_N >= 0.85, slope > -0.2, the last ratio >= 0.95), the displacement
#    form's falling (slope < -1.5);
#  - bad input: an unknown pressure space, and each combination the cell pressure refuses, exit 2 with the line.
source "$(dirname "$0")/common.bash"
out="$OUT_DIR/incompressible"
rm -rf "$out" && mkdir -p "$out"
deck=input/cook_incompressible.cfg
TH_LINEAR=19.4229   # Taylor-Hood P2/P1, N = 256 (docs/verification.md)
TH_NEOHOOKE=5.2240  # Taylor-Hood P2/P1, N = 256 (docs/verification.md)
tip() { json_value tip_uy "$1/summary.json"; }
# off VALUE REFERENCE: |VALUE/REFERENCE - 1|
off() { awk -v v="$1" -v r="$2" 'BEGIN { d = v / r - 1; printf "%.5f", d < 0 ? -d : d }'; }

# ---- Cook, linear ----------------------------------------------------------------------------------------
run_deck "$out/linear_mixed" $deck
run_deck "$out/linear_disp" $deck --set material.pressure=none
mixed=$(tip "$out/linear_mixed") disp=$(tip "$out/linear_disp")
within "$mixed" $TH_LINEAR 0.005 "Cook linear, nu = 0.4999, cell-linear pressure: tip u_y"
at_least "$(off "$disp" $TH_LINEAR)" 0.01 "Cook linear, displacement form ($disp): relative error"
grep -q '"pressure": "cell-linear"' "$out/linear_mixed/summary.json" || fail "summary.json lacks pressure = cell-linear"
grep -q "(cholmod)" "$out/linear_mixed.log" || grep -q "(umfpack)" "$out/linear_mixed.log" || fail "no solver named"

# ---- Cook, Neo-Hooke -------------------------------------------------------------------------------------
nh=(--set material.model=neohooke --set parameters.F=0.3 --set solver.steps=8)
"$MICA" run $deck -o "$out/nh_mixed" "${nh[@]}" --set output.vtu=false > "$out/nh_mixed.log" 2>&1 \
  || fail "Neo-Hooke mixed run failed: $(tail -n 3 "$out/nh_mixed.log")"
run_deck "$out/nh_disp" $deck "${nh[@]}" --set material.pressure=none
mixed=$(tip "$out/nh_mixed") disp=$(tip "$out/nh_disp")
within "$mixed" $TH_NEOHOOKE 0.005 "Cook Neo-Hooke, nu = 0.4999, F-bar with cell-linear pressure: tip u_y"
at_least "$(off "$disp" $TH_NEOHOOKE)" 0.01 "Cook Neo-Hooke, displacement form ($disp): relative error"
# quadratic convergence: the last rate printed in the last load step (log |du_k+1| / log |du_k| ratios)
rate=$(awk '/^  step/ { s = $2; if ($NF != "-") r[s] = $NF } END { print (s in r) ? r[s] : 0 }' "$out/nh_mixed.log")
at_least "$rate" 1.5 "Cook Neo-Hooke, F-bar: Newton's convergence rate in the last load step"

# ---- order 1, small support -----------------------------------------------------------------------------
small=(--set mls.order=1 --set mls.dilation=1.5 --set particles.layout=regular --set "particles.count=[33, 33]"
       --set "quadrature.cells=[16, 16]")
run_deck "$out/small_mixed" $deck "${small[@]}"
run_deck "$out/small_disp" $deck "${small[@]}" --set material.pressure=none
mixed=$(tip "$out/small_mixed") disp=$(tip "$out/small_disp")
within "$mixed" $TH_LINEAR 0.025 "order 1, dilation 1.5, cell-linear: tip u_y"
at_least "$(off "$disp" $TH_LINEAR)" 0.10 "order 1, dilation 1.5, displacement form ($disp) locks: relative error"

# ---- inf-sup ----------------------------------------------------------------------------------------------
inf_sup() { # inf_sup DIR [--set ...]: the β column of inf_sup.csv and the slope
  local dir=$1; shift
  "$MICA" stability input/infsup_block.cfg -o "$dir" "$@" > "$dir.log" 2>&1 || fail "mica stability failed: $(tail -n 3 "$dir.log")"
}
inf_sup "$out/infsup_mixed"
inf_sup "$out/infsup_disp" --set material.pressure=none
betas=$(awk -F, 'NR > 1 { printf "%s ", $7 }' "$out/infsup_mixed/inf_sup.csv")
[ "$(awk -F, 'NR > 1' "$out/infsup_mixed/inf_sup.csv" | wc -l)" -ge 4 ] || fail "fewer than 4 inf-sup rows"
awk -F, 'NR > 2 && !($7 >= 0.85 * prev) { exit 1 } { prev = $7 }' "$out/infsup_mixed/inf_sup.csv" \
  || fail "cell-linear: β falls by more than 15 % in a refinement: $betas"
awk -F, 'NR > 1 { b[NR] = $7 } END { exit !(b[NR] >= 0.95 * b[NR - 1] && b[NR] > 0.5) }' "$out/infsup_mixed/inf_sup.csv" \
  || fail "cell-linear: the last refinement's β is not settled above 0.5: $betas"
slope=$(json_value inf_sup_slope "$out/infsup_mixed/summary.json")
less_than -0.2 "$slope" || fail "cell-linear inf-sup slope $slope"
ok "cell-linear: β bounded below for N = 5, 9, 17, 25: $betas(slope $slope)"
dbetas=$(awk -F, 'NR > 1 { printf "%s ", $7 }' "$out/infsup_disp/inf_sup.csv")
dslope=$(json_value inf_sup_slope "$out/infsup_disp/summary.json")
less_than "$dslope" -1.5 || fail "displacement form's inf-sup slope $dslope is not below -1.5: $dbetas"
ok "displacement form: β falls for N = 5, 9, 17, 25: $dbetas(slope $dslope)"

# ---- bad input --------------------------------------------------------------------------------------------
line=$(grep -n '^material = ' $deck | cut -d: -f1)
sed 's/pressure = "cell-linear"/pressure = "bogus"/' $deck > "$out/bogus.cfg"
expect_failure 2 "$out/bogus.cfg:$line: material.pressure = \"bogus\" is not one of none|cell-constant|cell-linear" -- \
  "$MICA" run "$out/bogus.cfg" -o "$out/bad1"
expect_failure 2 "is not one of none|cell-constant|cell-linear" -- "$MICA" run $deck -o "$out/bad1" --set material.pressure=bogus
expect_failure 2 "plane stress" -- "$MICA" run $deck -o "$out/bad2" --set material.plane=stress
expect_failure 2 "$deck:$line: material.pressure = \"cell-linear\" does not combine with quadrature.vci" -- \
  "$MICA" run $deck -o "$out/bad3" --set quadrature.vci=true
expect_failure 2 "$deck:$line: material.pressure = \"cell-linear\" lives on the background cells" -- \
  "$MICA" run $deck -o "$out/bad4" --set quadrature.mode=scni --set particles.layout=regular
expect_failure 2 "$deck:$line: material.pressure = \"cell-linear\" modifies the deformation gradient of a classical" -- \
  "$MICA" run $deck -o "$out/bad5" --set material.model=cosserat --set material.G=0.3 --set material.N=0.5 \
  --set material.l=1 --set bcs.traction.[0].ty=0
ok "incompressible: all checks passed"
