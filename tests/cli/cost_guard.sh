# The cost guard (src/app/estimate.c, docs/performance.md §the cost estimate): decks whose estimated peak
# memory exceeds limits.memory_gb (default: the physical memory) are refused with exit 2 before anything is
# allocated, naming the deck line, the estimate and the setting; sweeps, studies and MLS sample lists beyond
# their caps, and mesh files that are not regular files or are too large, likewise. The estimate is checked
# against the peak memory getrusage measures (summary.json) on two real decks.
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/cost_guard"
rm -rf "$work" && mkdir -p "$work"

# refused STATUS REGEX -- command...: like refused, with an extended regular expression
refused() {
  local status=$1 pattern=$2; shift 3
  local err rc
  err=$("$@" 2>&1 >/dev/null); rc=$?
  [ "$rc" -eq "$status" ] || fail "'$*' exited $rc, expected $status; stderr: $err"
  grep -qE -- "$pattern" <<<"$err" || fail "'$*' stderr does not match '$pattern': $err"
  ok "exit $status with '$pattern'"
}

box2() {  # box2 FILE N: the unit square, N x N particles, linear elasticity
  cat > "$1" <<EOF
geometry = { shape = "box"; lower = [0.0, 0.0]; upper = [1.0, 1.0]; };
particles = { count = [$2, $2]; };
material = { model = "linear"; E = 1.0; nu = 0.3; };
bcs = { dirichlet = ( { set = "left"; ux = "0"; uy = "0"; } ); traction = ( { set = "right"; tx = "1"; } ); };
output = { vtu = false; probes = ( { name = "tip_ux"; point = [1.0, 0.5]; field = "ux"; } ); };
EOF
}
box2 "$work/big.cfg" 3000
box2 "$work/huge.cfg" 100000
box2 "$work/small.cfg" 80

# ---- memory ----------------------------------------------------------------------------------------------
cp "$work/big.cfg" "$work/big_sweep.cfg"
echo 'sweep = { parameters = ( { path = "material.E"; values = [1.0, 2.0]; } ); };' >> "$work/big_sweep.cfg"
cp "$work/big.cfg" "$work/big_study.cfg"
echo 'study = { choices = ( { path = "mls.dilation"; values = [2.0, 3.0]; } ); error = "tip_ux"; reference = 1.0; };' >> "$work/big_study.cfg"
for command in check run stability; do
  refused 2 "big.cfg:2: particles.count = \[3000, 3000\] needs about [0-9.]+ GB \\(estimate" \
    -- "$MICA" $command "$work/big.cfg" -o "$work/x"
done
refused 2 "big_sweep.cfg:2: particles.count = \[3000, 3000\] needs about" -- "$MICA" sweep "$work/big_sweep.cfg" -o "$work/x"
refused 2 "big_study.cfg:2: particles.count = \[3000, 3000\] needs about" -- "$MICA" study "$work/big_study.cfg" -o "$work/x"
refused 2 "more than this machine's [0-9.]* GB \\(limits.memory_gb\\); lower particles.count or raise limits.memory_gb" \
  -- "$MICA" run "$work/big.cfg" -o "$work/x"
ok "particles.count = [3000, 3000] refused by check, run, sweep, study, stability"
refused 2 "huge.cfg:2: particles.count = \[100000, 100000\] needs about" -- "$MICA" check "$work/huge.cfg" -o "$work/x"
refused 2 "more than limits.memory_gb = 100 \\(this machine has" \
  -- "$MICA" run "$work/huge.cfg" -o "$work/x" --set limits.memory_gb=100
ok "particles.count = [100000, 100000] refused, also under a raised limit below its estimate"
refused 2 "small.cfg:2: particles.count = \[80, 80\] needs about 0\\.[0-9]+ GB .*more than limits.memory_gb = 0.05" \
  -- "$MICA" run "$work/small.cfg" -o "$work/x" --set limits.memory_gb=0.05
ok "a lowered limits.memory_gb refuses a deck that fits the machine"

# ---- a normal deck: check prints the estimate, run's measured peak is within a factor of it -----------------
"$MICA" check "$work/small.cfg" -o "$work/check" > "$work/check.log" || fail "check of a normal deck failed"
grep -Eq "^estimate: 0\.[0-9]+ GB peak memory \(cache .*, matrix .*, factor .* GB with cholmod\), roughly .* s" "$work/check.log" \
  || fail "check prints no estimate: $(cat "$work/check.log")"
[ -n "$(json_value estimate_memory "$work/check/summary.json")" ] || fail "no estimate_memory in check's summary"
ok "mica check prints the estimate"
# the estimate is an upper bound of getrusage's peak, and at most twice it (docs/performance.md's table)
compare() {  # compare DIR WHAT
  local est peak
  est=$(json_value estimate_memory "$1/summary.json")
  peak=$(json_value peak_memory "$1/summary.json")
  awk -v e="$est" -v p="$peak" 'BEGIN { exit !(e >= p && e <= 2 * p) }' \
    || fail "$2: estimate $est bytes against measured peak $peak bytes: not within [1, 2] times"
  ok "$2: estimate $(awk -v e="$est" -v p="$peak" 'BEGIN { printf "%.2f", e / p }') x the measured peak"
}
if [ "${SAN:-0}" = 1 ]; then  # the sanitizers' shadow memory and redzones are not mica's: the normal run checks
  ok "estimate against the measured peak: not under SAN=1"
else
  run_deck "$work/r2" "$work/small.cfg"
  compare "$work/r2" "2-D, 80 x 80, CHOLMOD"
  run_deck "$work/r3" input/cube3d.cfg --set 'particles.count=[10,10,10]'
  compare "$work/r3" "3-D cube, 10^3, CHOLMOD"
fi
"$MICA" check input/plate_hole_gmsh.cfg -o "$work/gmsh" | grep -q "^estimate: " || fail "no estimate for a Gmsh deck"
ok "Gmsh deck: estimated from the mesh's counts"

# ---- counts: sweeps, studies, MLS samples ----------------------------------------------------------------
box2 "$work/sweep.cfg" 10
cat >> "$work/sweep.cfg" <<'EOF'
sweep = { parameters = ( { path = "material.E"; range = [1.0, 2.0]; points = 100000; },
                         { path = "material.nu"; range = [0.1, 0.2]; points = 100000; } ); };
EOF
refused 2 "sweep.cfg:[0-9]+: 10000000000 points \(100000 x 100000\), more than limits.sweep_points = 100000; use fewer values or raise limits.sweep_points" \
  -- "$MICA" sweep "$work/sweep.cfg" -o "$work/x"
ok "a 10^10-point sweep refused"
box2 "$work/study.cfg" 10
cat >> "$work/study.cfg" <<'EOF'
study = { choices = ( { path = "material.E"; range = [1.0, 2.0]; points = 100000; },
                      { path = "material.nu"; range = [0.1, 0.2]; points = 100000; },
                      { path = "mls.dilation"; range = [2.0, 3.0]; points = 100000; } ); };
EOF
refused 2 "study.cfg:[0-9]+: 1000000000000000 combinations \(100000 x 100000 x 100000\), more than limits.study_combinations = 100000; use fewer values or raise limits.study_combinations" \
  -- "$MICA" study "$work/study.cfg" -o "$work/x"
ok "a 10^15-combination study refused"
# The caps are limits.* settings: a 2 x 3 grid is refused under a limit of 5 and runs, all 6 points, under 6;
# one axis beyond the limit is refused before its values are made (points = 10^9 allocates nothing).
box2 "$work/grid.cfg" 5
cat >> "$work/grid.cfg" <<'EOF'
sweep = { parameters = ( { path = "material.E"; values = [1.0, 2.0]; }, { path = "material.nu"; values = [0.1, 0.2, 0.3]; } ); };
study = { choices = ( { path = "material.E"; values = [1.0, 2.0]; }, { path = "material.nu"; values = [0.1, 0.2, 0.3]; } );
          error = "tip_ux"; reference = 1.0; };
EOF
refused 2 "grid.cfg:6: 6 points \(2 x 3\), more than limits.sweep_points = 5; use fewer values or raise limits.sweep_points" \
  -- "$MICA" sweep "$work/grid.cfg" -o "$work/x" --set limits.sweep_points=5
refused 2 "grid.cfg:7: 6 combinations \(2 x 3\), more than limits.study_combinations = 5; use fewer values or raise limits.study_combinations" \
  -- "$MICA" study "$work/grid.cfg" -o "$work/x" --set limits.study_combinations=5
"$MICA" sweep "$work/grid.cfg" -o "$work/grid_sweep" --set limits.sweep_points=6 > "$work/grid_sweep.log" 2>&1 \
  || fail "a 6-point sweep under limits.sweep_points = 6: $(tail -n 3 "$work/grid_sweep.log")"
[ "$(($(wc -l < "$work/grid_sweep/sweep.csv") - 1))" -eq 6 ] || fail "sweep.csv has not 6 points"
"$MICA" study "$work/grid.cfg" -o "$work/grid_study" --set limits.study_combinations=6 > "$work/grid_study.log" 2>&1 \
  || fail "a 6-combination study under limits.study_combinations = 6: $(tail -n 3 "$work/grid_study.log")"
[ "$(json_value combinations "$work/grid_study/summary.json")" = 6 ] || fail "the study did not run 6 combinations"
ok "limits.sweep_points and limits.study_combinations: refused at 5, all 6 run at 6"
box2 "$work/axis.cfg" 5
echo 'sweep = { parameters = ( { path = "material.E"; range = [1.0, 2.0]; points = 1000000000; } ); };' >> "$work/axis.cfg"
refused 2 "axis.cfg:6: sweep.parameters.\\[0\\].points has 1000000000 values, more points than limits.sweep_points = 100000" \
  -- "$MICA" sweep "$work/axis.cfg" -o "$work/x"
start=$(date +%s.%N)
refused 2 "10000000000 points" -- "$MICA" sweep "$work/sweep.cfg" -o "$work/x"
elapsed=$(echo "$(date +%s.%N) - $start" | bc)
less_than "$elapsed" 20 || fail "refusing a 10^10-point sweep took $elapsed s (before: minutes, every value tried first)"
ok "a 10^10-point sweep refused in $elapsed s"
cat > "$work/mls.cfg" <<'EOF'
geometry = { lower = [0.0]; upper = [1.0]; };
particles = { count = [11]; };
function = { f = "x^2"; };
sample = { line = { from = [0.0]; to = [1.0]; samples = 10000000; }; };
output = { chart = false; };
EOF
refused 2 "mls.cfg:4: 10000000 line and 0 volume samples are more than limits.mls_samples = 1000000; lower sample.line.samples or raise limits.mls_samples" \
  -- "$MICA" mls "$work/mls.cfg" -o "$work/x"
"$MICA" mls "$work/mls.cfg" -o "$work/mls" --set sample.line.samples=2001 > /dev/null || fail "2001 MLS samples refused"
ok "10^7 MLS samples refused, 2001 accepted"

# ---- mesh files ------------------------------------------------------------------------------------------
mesh_deck() {  # mesh_deck FILE MESH
  sed "s|\"meshes/plate_hole.msh\"|\"$2\"|" input/plate_hole_gmsh.cfg > "$1"
  grep -q "\"$2\"" "$1" || fail "mesh_deck: no geometry.mesh to replace in input/plate_hole_gmsh.cfg"
}
mesh_deck "$work/zero.cfg" /dev/zero
refused 2 "zero.cfg:[0-9]*: the mesh /dev/zero is not a regular file" -- "$MICA" check "$work/zero.cfg" -o "$work/x"
mkfifo "$work/fifo.msh"
mesh_deck "$work/fifo.cfg" fifo.msh
refused 2 "fifo.cfg:[0-9]*: the mesh .*fifo.msh is not a regular file" -- "$MICA" run "$work/fifo.cfg" -o "$work/x"
mkdir -p "$work/dir.msh"
mesh_deck "$work/dir.cfg" dir.msh
refused 2 "the mesh .*dir.msh is not a regular file" -- "$MICA" run "$work/dir.cfg" -o "$work/x"
refused 2 "plate_hole_gmsh.cfg:[0-9]*: the mesh .*plate_hole.msh has 0.[0-9]* MB, more than limits.mesh_mb = 0.01; use a coarser mesh or raise limits.mesh_mb" \
  -- "$MICA" check input/plate_hole_gmsh.cfg -o "$work/x" --set limits.mesh_mb=0.01
ok "mesh = /dev/zero, a FIFO, a directory and a too-large mesh refused before reading"
