#!/usr/bin/env python3
# A Gmsh 2.2 ASCII mesh of the unit cube: N^3 cubes of 6 tetrahedra each (Kuhn's split along the main diagonal),
# two triangles per boundary square in the physical groups left, right, bottom, top, back, front (x = 0, 1; y = 0, 1;
# z = 0, 1), the tetrahedra in "cube" — the boundary sets of mica's box. For benchmarks of Gmsh meshes at sizes the
# shipped meshes do not reach (bench/bench_mesh_regions.sh). Usage: python3 bench/gmsh_cube_mesh.py N > cube.msh
import sys
n = int(sys.argv[1])
h = 1.0 / n
nid = lambda i, j, k: 1 + i + (n + 1) * (j + (n + 1) * k)
w = sys.stdout.write
w('$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n7\n2 1 "left"\n2 2 "right"\n2 3 "bottom"\n2 4 "top"\n'
  '2 5 "back"\n2 6 "front"\n3 7 "cube"\n$EndPhysicalNames\n$Nodes\n%d\n' % (n + 1) ** 3)
for k in range(n + 1):
    for j in range(n + 1):
        w("".join("%d %.17g %.17g %.17g\n" % (nid(i, j, k), i * h, j * h, k * h) for i in range(n + 1)))
w("$EndNodes\n")
elems = []
def square(a, b, c, d, phys):
    elems.append((2, phys, (a, b, c)))
    elems.append((2, phys, (a, c, d)))
for a in range(n):
    for b in range(n):
        square(nid(0, a, b), nid(0, a + 1, b), nid(0, a + 1, b + 1), nid(0, a, b + 1), 1)
        square(nid(n, a, b), nid(n, a + 1, b), nid(n, a + 1, b + 1), nid(n, a, b + 1), 2)
        square(nid(a, 0, b), nid(a + 1, 0, b), nid(a + 1, 0, b + 1), nid(a, 0, b + 1), 3)
        square(nid(a, n, b), nid(a + 1, n, b), nid(a + 1, n, b + 1), nid(a, n, b + 1), 4)
        square(nid(a, b, 0), nid(a + 1, b, 0), nid(a + 1, b + 1, 0), nid(a, b + 1, 0), 5)
        square(nid(a, b, n), nid(a + 1, b, n), nid(a + 1, b + 1, n), nid(a, b + 1, n), 6)
for k in range(n):
    for j in range(n):
        for i in range(n):
            v = [nid(i + a, j + b, k + c) for c in (0, 1) for b in (0, 1) for a in (0, 1)]  # v[a + 2 b + 4 c]
            for x, y in ((1, 3), (3, 2), (2, 6), (6, 4), (4, 5), (5, 1)):
                elems.append((4, 7, (v[0], v[x], v[y], v[7])))
w("$Elements\n%d\n" % len(elems))
w("".join("%d %d 2 %d %d %s\n" % (e, t, p, p, " ".join(map(str, nodes))) for e, (t, p, nodes) in enumerate(elems, 1)))
w("$EndElements\n")
