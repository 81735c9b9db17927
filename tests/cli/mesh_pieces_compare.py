#!/usr/bin/env python3
"""The output mesh of a distributed run (a piece per rank, mesh_NNNN_R.vtu, listed by mesh_NNNN.pvtu) against a
serial run's mesh_NNNN.vtu (tests/cli/mpi_distributed.sh):

    mesh_pieces_compare.py SERIAL_DIR DISTRIBUTED_DIR NP --tol T

- every step's .pvtu lists NP pieces (each rank writes the mesh of its block of cells);
- the pieces' cells sum to the serial cells, of the same types;
- every piece point is a serial mesh point (the same coordinates to 1e-12 of the body's extent), and every serial
  point is in some piece; at each, every array equals the serial value within T relative to the array's largest
  magnitude (the error's: the displacement's, as pvtu_compare.py; a point on two ranks' blocks is in both pieces,
  with both values checked).
"""
import argparse
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vtu_readback import read_vtu  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("serial")
    ap.add_argument("distributed")
    ap.add_argument("np", type=int)
    ap.add_argument("--tol", type=float, required=True)
    a = ap.parse_args()
    steps = sorted(f for f in os.listdir(a.serial) if re.fullmatch(r"mesh_\d{4}\.vtu", f))
    if not steps:
        sys.exit("FAIL: no serial mesh files in %s" % a.serial)
    for name in steps:
        step = name[5:9]
        pvtu = os.path.join(a.distributed, "mesh_%s.pvtu" % step)
        listed = re.findall(r'Source="([^"]+)"', open(pvtu).read())
        if len(listed) != a.np:
            sys.exit("FAIL: %s lists %d pieces, not %d" % (pvtu, len(listed), a.np))
        ref = read_vtu(os.path.join(a.serial, name))
        extent = max(max(abs(c) for c in p) for p in ref["points"]) or 1.0
        key = lambda p: tuple(round(c / extent, 11) for c in p)
        index = {key(p): i for i, p in enumerate(ref["points"])}
        # as pvtu_compare.py: the error (computed minus exact) against the displacement's magnitude
        scale = {n: max(abs(v) for v in ref["arrays"]["displacement" if n == "error" else n][2]) or 1.0
                 for n in ref["arrays"]}
        seen, cells, worst = set(), 0, 0.0
        for piece in listed:
            got = read_vtu(os.path.join(os.path.dirname(pvtu), piece))
            cells += len(got["cells"])
            if {t for t, _ in got["cells"]} - {t for t, _ in ref["cells"]}:
                sys.exit("FAIL: %s: cell types differ from the serial mesh's" % piece)
            for i, p in enumerate(got["points"]):
                j = index.get(key(p))
                if j is None:
                    sys.exit("FAIL: %s: point %s is no serial mesh point" % (piece, p))
                seen.add(j)
                for n, (ncomp, _, values) in ref["arrays"].items():
                    mine = got["arrays"][n][2]
                    for c in range(ncomp):
                        d = abs(mine[i * ncomp + c] - values[j * ncomp + c]) / scale[n]
                        worst = max(worst, d)
                        if d > a.tol:
                            sys.exit("FAIL: %s: %s[%d] at %s differs by %.3g > %g" % (piece, n, c, p, d, a.tol))
        if cells != len(ref["cells"]):
            sys.exit("FAIL: step %s: %d cells in the pieces, %d serially" % (step, cells, len(ref["cells"])))
        if len(seen) != len(ref["points"]):
            sys.exit("FAIL: step %s: %d of the %d serial points in the pieces" % (step, len(seen), len(ref["points"])))
        print("ok: step %s: %d pieces, %d cells, every point within %.2g of the serial mesh's" % (step, a.np, cells, worst))


main()
