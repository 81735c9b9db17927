# Output in parallel (issue 19): under `mpirun -np P mica run` every rank writes its piece of each step's fields,
# the particles it owns (step_NNNN_R.vtu) and its block of cells (mesh_NNNN_R.vtu), rank 0 a .pvtu per step and
# part that lists them, and solution.pvd names the .pvtu files. On the Timoshenko beam over 2 load steps, with
# -np 2 and -np 3 (tests/cli/pvtu_compare.py, which reads the pieces with vtu_readback.py's reader): the particle
# pieces' point counts sum to the serial count, each smaller, every particle in one piece; the mesh pieces' cells
# are the serial cells; every field at every point equals the serial run's to 1e-10 of the field's largest
# value (the error field: of the displacement's). The serial run (and mpirun -np 1) writes the whole files as before, no .pvtu. The results are
# published as one directory, with no piece left in a staging or scratch directory.
source "$(dirname "$0")/common.bash"
work="$(cd "$(dirname "$OUT_DIR")" 2>/dev/null && pwd)/$(basename "$OUT_DIR")/mpi_output" # absolute: mpirun's TMPDIR
rm -rf "$work" && mkdir -p "$work/tmp"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=false
export TMPDIR="$work/tmp"
MPIRUN=(timeout 300 mpirun --oversubscribe)
[ "$(id -u)" = 0 ] && MPIRUN+=(--allow-run-as-root)
mpi_leak_checks
if ! out=$("${MPIRUN[@]}" -np 2 "$MICA" --version 2>&1) || [ "$(grep -c '^mica ' <<<"$out")" -lt 1 ]; then
  echo "### SKIPPED: mpirun cannot start 2 processes here, so the parallel output is untested ###"
  echo "### mpirun said: $out"
  exit 0
fi

deck=input/timoshenko.cfg
args=(--set output.monitor=false --set solver.steps=2)
"$MICA" run $deck -o "$work/serial" "${args[@]}" > "$work/serial.log" 2>&1 || fail "serial run: $(tail -3 "$work/serial.log")"
ls "$work/serial"/*.pvtu "$work/serial"/*_*_*.vtu > /dev/null 2>&1 && fail "the serial run wrote pieces: $(ls "$work/serial")"
for f in step_0001.vtu step_0002.vtu mesh_0001.vtu mesh_0002.vtu solution.pvd; do
  [ -f "$work/serial/$f" ] || fail "the serial run did not write $f"
done
ok "serial: whole step and mesh files, no pieces"

"${MPIRUN[@]}" -np 1 "$MICA" run $deck -o "$work/np1" "${args[@]}" > "$work/np1.log" 2>&1 || fail "-np 1: $(tail -3 "$work/np1.log")"
ls "$work/np1"/*.pvtu > /dev/null 2>&1 && fail "mpirun -np 1 wrote .pvtu files"
python3 tests/cli/vtu_readback.py "$work/np1" --types 9 --steps 2 > "$work/np1.check" 2>&1 \
  || fail "mpirun -np 1 files: $(cat "$work/np1.check")"
ok "mpirun -np 1 takes the serial path: whole files"

for np in 2 3; do
  d="$work/np$np"
  "${MPIRUN[@]}" -np $np "$MICA" run $deck -o "$d" "${args[@]}" > "$d.log" 2>&1 || fail "-np $np: $(tail -5 "$d.log")"
  for s in 0001 0002; do
    for r in $(seq 0 $((np - 1))); do [ -f "$d/step_${s}_$r.vtu" ] || fail "-np $np: no step_${s}_$r.vtu: $(ls "$d")"; done
    [ -f "$d/step_$s.pvtu" ] && [ -f "$d/mesh_$s.pvtu" ] || fail "-np $np: no .pvtu of step $s: $(ls "$d")"
    [ ! -e "$d/step_$s.vtu" ] && [ ! -e "$d/mesh_$s.vtu" ] || fail "-np $np: whole files besides the pieces"
  done
  [ -z "$(ls -A "$work" | grep staging)" ] || fail "-np $np: a staging directory was left behind"
  [ -z "$(ls -A "$TMPDIR" | grep mica-rank)" ] || fail "-np $np: scratch directories left: $(ls "$TMPDIR")"
  python3 tests/cli/pvtu_compare.py "$work/serial" "$d" $np > "$d.check" 2>&1 || fail "-np $np: $(cat "$d.check")"
  sed "s/^ok: /ok: -np $np: /" "$d.check"
  echo
done
