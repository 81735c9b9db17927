#!/usr/bin/env bash
# Fields on the cells for ParaView (docs/input.md "Outputs", docs/verification.md "Output files"): each run
# writes mesh_NNNN.vtu beside step_NNNN.vtu and lists both in solution.pvd. tests/cli/vtu_readback.py reads
# them back with Python's xml module and struct (no VTK) and checks the format, the cell types, the cells'
# area or volume against summary.json, and that the fields at a cell vertex equal probes placed there:
#  - 2-D classical, 10 load steps: bilinear quadrilaterals (VTK 9), times k/10 with the last t = 1;
#  - 3-D classical: trilinear hexahedra (12);
#  - 2-D Cosserat plate with a hole: biquadratic quadrilaterals (28) following the arc, micro-rotation and
#    couple stress; the same deck with problem.method = "fe" (Q2 elements, 28);
#  - axisymmetric Cosserat torsion: components named r, z, theta, points on the axis;
#  - gradient micromorph: micro_deformation = I + A and det(I + A)^(-1/3) (I + A) under u = A x (kinds F and
#    isochoric), and R(phi) of the written micro-rotation (kind rotation, the glide layer);
#  - a cylinder (triquadratic hexahedra, 29) and a Gmsh mesh (triangles, 5);
#  - output.mesh = false writes no mesh files; output.mesh = true with output.vtu = false is refused.
source "$(dirname "$0")/common.bash"
out=$OUT_DIR/vtu_mesh
rm -rf "$out" && mkdir -p "$out"
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
readback() { "$PY" tests/cli/vtu_readback.py "$@" || fail "vtu_readback.py $*"; }
# run_vtu DIR DECK [--set ...]: mica run with its VTU files (run_deck turns them off)
run_vtu() {
  local dir=$1 deck=$2; shift 2
  "$MICA" run "$deck" -o "$dir" --set output.monitor=false "$@" > "$dir.log" 2>&1 \
    || fail "mica run $deck $* failed: $(tail -n 3 "$dir.log")"
}

run_vtu "$out/plane" tests/decks/vtu/plane.cfg
readback "$out/plane" --types 9 --steps 10 --at 2.5,0.75 --probe p_ux=displacement.x --probe p_uy=displacement.y \
  --probe p_sxx=stress.xx --probe p_syy=stress.yy --probe p_sxy=stress.xy --probe p_szz=stress.zz \
  --probe p_exx=strain.xx --probe p_exy=strain.xy --probe p_mises=von_mises
ok "2-D classical: quadrilaterals, 10 steps, vertex values = probes"

run_vtu "$out/cube" tests/decks/vtu/cube.cfg
readback "$out/cube" --types 12 --at 1.5,0.5,0.5 --probe p_ux=displacement.x --probe p_uz=displacement.z \
  --probe p_sxx=stress.xx --probe p_syz=stress.yz --probe p_sxz=stress.xz --probe p_eyy=strain.yy --probe p_mises=von_mises
ok "3-D classical: hexahedra, vertex values = probes"

# the probe point of cosserat_hole.cfg: the plate_hole map at xi = 3/8, eta = 1/4 (a = 1, b = 4)
hole_point=$(awk 'BEGIN { pi = atan2(0, -1); xi = 0.375; eta = 0.25
                          printf "%.17g,%.17g", (1-eta)*sin(pi/2*(1-xi)) + eta*4, (1-eta)*sin(pi/2*xi) + eta*2*xi*4 }')
cosserat_probes=(--probe p_ux=displacement.x --probe p_uy=displacement.y --probe p_phiz=microrotation.z
  --probe p_sxx=stress.xx --probe p_sxy=stress.xy --probe p_syx=stress.yx --probe p_mzx=couple_stress.zx
  --probe p_mzy=couple_stress.zy --probe p_mises=von_mises)
# the quadratic cells' area is within 1e-6 of the exact 16 - pi/4 (measured 1.0e-8; linear cells on the corners: 8.3e-5)
run_vtu "$out/hole" tests/decks/vtu/cosserat_hole.cfg
readback "$out/hole" --types 28 --volume-rtol 1e-6 --at "$hole_point" "${cosserat_probes[@]}"
ok "Cosserat hole: biquadratic cells on the arc, micro-rotation and couple stress = probes"
run_vtu "$out/hole_fe" tests/decks/vtu/cosserat_hole.cfg --set problem.method=fe
readback "$out/hole_fe" --types 28 --at "$hole_point" "${cosserat_probes[@]}"
ok "Cosserat hole with Q2 finite elements: the elements as biquadratic cells, vertex values = probes"

run_vtu "$out/axi" tests/decks/vtu/axisymmetric.cfg
readback "$out/axi" --types 9 --axisymmetric --at 0.5,0.5 --probe p_ur=displacement.r --probe p_utheta=displacement.theta \
  --probe p_uz=displacement.z --probe p_phir=microrotation.r --probe p_phiz=microrotation.z --probe p_stz=stress.thetaz \
  --probe p_szt=stress.ztheta --probe p_stt=stress.thetatheta --probe p_srr=stress.rr --probe p_mzz=couple_stress.zz \
  --probe p_mrt=couple_stress.rtheta --probe p_mises=von_mises
ok "axisymmetric Cosserat: components r, z, theta, vertex values = probes"

# micromorph: chi under a homogeneous deformation (patch-test error of the quadrature: 5.6e-9), and chi = R(phi)
run_vtu "$out/micromorph" tests/decks/vtu/micromorph.cfg
readback "$out/micromorph" --types 9 --expect micro_deformation=1.01,0.002,0,-0.003,1.005,0,0,0,1 --expect-tol 1e-7
chi=$(awk 'BEGIN { a11 = 0.01; a12 = 0.002; a21 = -0.003; a22 = 0.005; J = (1 + a11) * (1 + a22) - a12 * a21
               j = exp(-log(J) / 3); printf "%.17g,%.17g,0,%.17g,%.17g,0,0,0,%.17g", j * (1 + a11), j * a12, j * a21, j * (1 + a22), j }')
run_vtu "$out/isochoric" tests/decks/vtu/micromorph.cfg --set material.micro_kind=isochoric
readback "$out/isochoric" --types 9 --expect micro_deformation="$chi" --expect-tol 1e-7
run_vtu "$out/glide" input/micromorph_glide.cfg
readback "$out/glide" --types 9 --rotation micro_deformation=microrotation
ok "micromorph kinds F, isochoric, rotation: micro_deformation"

# the elliptical grid map of the cylinder bends more: triquadratic cells within 1e-4 of its volume (measured 2.9e-5;
# trilinear cells on the corners: 1.2e-2)
run_vtu "$out/cylinder" input/cylinder_tension.cfg
readback "$out/cylinder" --types 29 --volume-rtol 1e-4 --at 0,0,2 --probe top_uz=displacement.z
ok "cylinder: triquadratic hexahedra"
run_vtu "$out/gmsh" input/plate_hole_gmsh.cfg
readback "$out/gmsh" --types 5 --at 0,1 --probe scf=stress.xx
ok "Gmsh mesh: its triangles"

run_vtu "$out/no_mesh" tests/decks/vtu/cube.cfg --set output.mesh=false
readback "$out/no_mesh" --no-mesh --at 1.5,0.5,0.5 --probe p_ux=displacement.x
ok "output.mesh = false: particles only"
expect_failure 2 "output.mesh = true writes the fields on the cells with the VTU files, but output.vtu = false" -- \
  "$MICA" run tests/decks/vtu/cube.cfg -o "$out/refused" --set output.vtu=false --set output.mesh=true
