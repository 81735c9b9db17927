#!/usr/bin/env python3
# A Gmsh 4.1 ASCII strip of ROWS x COLS quadrangles whose every boundary edge is a curve entity of its own (physical
# groups bottom, right, top, left; the quadrangles one surface "body"): many entities of one dimension, for the
# cost of finding an element's entity (docs/verification.md, "Fuzzing": 4 x 20000 took 14.4 s before the binary
# search, 0.57 s after). Usage: python3 bench/gmsh_strip_mesh.py 4 20000 > /tmp/strip.msh
import sys
rows, cols = int(sys.argv[1]), int(sys.argv[2])
nid = lambda i, j: j * (cols + 1) + i + 1
edges = []  # (phys, n1, n2)
for i in range(cols): edges.append((1, nid(i, 0), nid(i + 1, 0)))
for j in range(rows): edges.append((2, nid(cols, j), nid(cols, j + 1)))
for i in range(cols, 0, -1): edges.append((3, nid(i, rows), nid(i - 1, rows)))
for j in range(rows, 0, -1): edges.append((4, nid(0, j), nid(0, j - 1)))
out = []
w = out.append
w("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n5\n1 1 \"bottom\"\n1 2 \"right\"\n1 3 \"top\"\n1 4 \"left\"\n2 5 \"body\"\n$EndPhysicalNames\n")
w("$Entities\n0 %d 1 0\n" % len(edges))
for k, (p, a, b) in enumerate(edges): w("%d 0 0 0 %d %d 0 1 %d 0\n" % (k + 1, cols, rows, p))
w("1 0 0 0 %d %d 0 1 5 0\n$EndEntities\n" % (cols, rows))
nn = (rows + 1) * (cols + 1)
w("$Nodes\n1 %d 1 %d\n2 1 0 %d\n" % (nn, nn, nn))
for j in range(rows + 1):
    for i in range(cols + 1): w("%d\n" % nid(i, j))
for j in range(rows + 1):
    for i in range(cols + 1): w("%g %g 0\n" % (i, j))
w("$EndNodes\n")
ne = len(edges) + rows * cols
w("$Elements\n%d %d 1 %d\n" % (len(edges) + 1, ne, ne))
t = 1
for k, (p, a, b) in enumerate(edges):
    w("1 %d 1 1\n%d %d %d\n" % (k + 1, t, a, b)); t += 1
w("2 1 3 %d\n" % (rows * cols))
for j in range(rows):
    for i in range(cols):
        w("%d %d %d %d %d\n" % (t, nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1))); t += 1
w("$EndElements\n")
sys.stdout.write("".join(out))
