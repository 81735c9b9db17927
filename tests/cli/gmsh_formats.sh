# Gmsh meshes as users have them (docs/verification.md, "Gmsh meshes"): the Kirsch deck input/plate_hole_gmsh.cfg
# run on the same mesh as 4.1 ASCII (input/meshes/plate_hole.msh), 2.2 ASCII and 4.1 binary
# (tests/meshes/plate_hole_v22.msh, plate_hole_binary.msh) and as the .geo itself (input/meshes/plate_hole.geo,
# meshed by the Gmsh library): the same particles, points and dofs, and the probes (SCF, u_x at (b, 0), u_y at
# (0, b)) agree to 1e-12 relative (the binary file and the .geo hold Gmsh's doubles, the ASCII files 16 digits
# of them: the meshes differ by at most 3.1e-15, tests/unit/test_geom_gmsh.c). Then the refusals: a .geo with
# SystemCall "touch pwned" (exit 2 naming file:LINE, no file made), a mesh with no physical groups (how to add
# one), geometry.mesh_size_factor with a .msh (the deck line), the Gmsh library missing (the Debian package).
source "$(dirname "$0")/common.bash"
work="$OUT_DIR/gmsh_formats"
rm -rf "$work" && mkdir -p "$work"
work=$(cd "$work" && pwd) root=$PWD

probes='output.probes=( { name = "scf"; point = ["0", "a"]; field = "sxx"; scale = "1/p"; },
  { name = "ux_right"; point = ["b", "0"]; field = "ux"; }, { name = "uy_top"; point = ["0", "b"]; field = "uy"; } )'
forms=(ascii41 ascii22 binary41 geo)
declare -A mesh=([ascii41]="$root/input/meshes/plate_hole.msh" [ascii22]="$root/tests/meshes/plate_hole_v22.msh"
  [binary41]="$root/tests/meshes/plate_hole_binary.msh" [geo]="$root/input/meshes/plate_hole.geo")
for f in "${forms[@]}"; do
  run_deck "$work/$f" input/plate_hole_gmsh.cfg --set "geometry.mesh=\"${mesh[$f]}\"" --set "$probes"
done
within "$(json_value scf "$work/ascii41/summary.json")" 3 0.01 "Kirsch SCF on the 4.1 ASCII mesh"
for f in ascii22 binary41 geo; do
  for key in particles quadrature_points boundary_points dofs; do
    [ "$(json_value $key "$work/$f/summary.json")" = "$(json_value $key "$work/ascii41/summary.json")" ] \
      || fail "$f: $key differs from the 4.1 ASCII mesh's"
  done
  for key in scf ux_right uy_top volume; do
    within "$(json_value $key "$work/$f/summary.json")" "$(json_value $key "$work/ascii41/summary.json")" 1e-12 \
      "$f against 4.1 ASCII: $key"
  done
done

# A .geo is a program: mica refuses what would reach a shell, before Gmsh runs it.
mkdir -p "$work/shared"
sed 's/^Physical Surface/SystemCall "touch pwned";\nPhysical Surface/' input/meshes/plate_hole.geo > "$work/shared/plate.geo"
line=$(grep -n SystemCall "$work/shared/plate.geo" | cut -d: -f1)
cd "$work/shared"
expect_failure 2 "plate.geo:$line: SystemCall runs a shell command" -- \
  "$MICA" run "$root/input/plate_hole_gmsh.cfg" -o "$work/shared/out" --set "geometry.mesh=\"$work/shared/plate.geo\""
cd "$root"
[ ! -e "$work/shared/pwned" ] && [ ! -e pwned ] || fail "the .geo's SystemCall ran"
[ ! -e "$work/shared/out/summary.json" ] || fail "a refused run wrote a summary"
ok "SystemCall \"touch pwned\" made no file"

# No physical groups: the boundary conditions' sets cannot exist; the message says how to add one.
expect_failure 2 'Physical Curve("left") = {4};' -- \
  "$MICA" run input/plate_hole_gmsh.cfg -o "$work/nophys" --set "geometry.mesh=\"$root/tests/meshes/square_nophys.msh\""
expect_failure 2 "has no physical groups" -- \
  "$MICA" run input/plate_hole_gmsh.cfg -o "$work/nophys" --set "geometry.mesh=\"$root/tests/meshes/square_nophys.geo\""

# geometry.mesh_size_factor scales a .geo's mesh; on a mesh file it would do nothing.
expect_failure 2 "geometry.mesh_size_factor scales the mesh of a .geo" -- \
  "$MICA" run input/plate_hole_gmsh.cfg -o "$work/factor" --set geometry.mesh_size_factor=0.5
run_deck "$work/coarse" input/plate_hole_gmsh.cfg --set geometry.mesh='"meshes/plate_hole.geo"' \
  --set geometry.mesh_size_factor=2
[ "$(json_value particles "$work/coarse/summary.json")" = 119 ] || fail "mesh_size_factor 2: not the 119 nodes of gmsh -clscale 2"
ok "geometry.mesh_size_factor = 2: 119 particles, as gmsh -2 -clscale 2"

# Without the library a .geo names the package to install (exit 1: the machine, not the deck); .msh files
# never load it.
MICA_GMSH_LIBRARY=/nonexistent/libgmsh.so expect_failure 1 "install Debian's libgmsh-dev" -- \
  "$MICA" run input/plate_hole_gmsh.cfg -o "$work/nolib" --set geometry.mesh='"meshes/plate_hole.geo"'
MICA_GMSH_LIBRARY=/nonexistent/libgmsh.so run_deck "$work/nolib_msh" input/plate_hole_gmsh.cfg
ok "a .msh deck runs without the library"
