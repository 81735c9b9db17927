#!/usr/bin/env python3
"""Compares what `mpirun -np P mica run` wrote in pieces with what the serial run wrote whole, with no VTK: the
parallel solution.pvd lists per step a .pvtu for each part (particles, mesh), each .pvtu names its pieces and
declares their arrays; the pieces are read with vtu_readback.py's reader (which checks the appended blocks).
tests/cli/mpi_output.sh drives it; docs/verification.md.

    pvtu_compare.py SERIAL_DIR PARALLEL_DIR RANKS [--tol T]

Checks (printing "ok: ..." and exiting 1 at the first failure):
  - both PVDs list the same steps, times and part names; the serial one .vtu files, the parallel one .pvtu;
  - each .pvtu declares exactly the arrays (names, components, component names) its pieces hold, and names
    RANKS particle pieces (at most RANKS mesh pieces: a rank may have no cells);
  - particles: the pieces' point counts sum to the serial count, each smaller; every serial particle is in
    exactly one piece (the same coordinates, bit for bit);
  - mesh: the pieces' cell counts sum to the serial count, each smaller; the cells (type and node coordinates)
    are the serial cells; every point of a piece is a serial point, every serial point is in a piece;
  - every array at every point of every step equals the serial value there to T (default 1e-10) times the
    array's largest magnitude in the serial file (for `error`, computed minus exact displacement, the
    displacement's largest magnitude).
"""
import argparse
import os
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vtu_readback import fail, ok, read_pvd, read_vtu  # noqa: E402


def read_pvtu(path):
    root = ET.parse(path).getroot()
    if root.get("type") != "PUnstructuredGrid":
        fail("%s: not a PUnstructuredGrid" % path)
    grid = root.find("PUnstructuredGrid")
    arrays = {}
    for element in grid.findall("PPointData/PDataArray"):
        ncomp = int(element.get("NumberOfComponents", "1"))
        arrays[element.get("Name")] = (ncomp, [element.get("ComponentName%d" % c) for c in range(ncomp)])
    pieces = [p.get("Source") for p in grid.findall("Piece")]
    return arrays, pieces


def key(point):
    return tuple(point)


def compare_values(what, serial, index, piece, tol):
    """piece's arrays at its points against the serial arrays at serial point index[i]; returns the worst
    difference relative to each array's largest serial magnitude."""
    worst = 0.0
    for name, (ncomp, _, values) in piece["arrays"].items():
        reference = serial["arrays"][name][2]
        # the error field is a difference of displacements, small where the approximation is good: its round-off
        # is the displacement's, so it is measured against the displacement's largest value
        scale = max(abs(v) for v in serial["arrays"]["displacement" if name == "error" else name][2]) or 1.0
        for i, s in enumerate(index):
            for c in range(ncomp):
                d = abs(values[ncomp * i + c] - reference[ncomp * s + c]) / scale
                if d > tol:
                    fail("%s: %s[%d] at point %d is %.17g, serial %.17g (relative %.3g > %g)"
                         % (what, name, c, i, values[ncomp * i + c], reference[ncomp * s + c], d, tol))
                worst = max(worst, d)
    return worst


def check_part(serial_path, pvtu_path, part, ranks, tol):
    serial = read_vtu(serial_path)
    declared, pieces = read_pvtu(pvtu_path)
    if part == "particles" and len(pieces) != ranks:
        fail("%s: %d pieces for %d ranks" % (pvtu_path, len(pieces), ranks))
    if not 1 <= len(pieces) <= ranks:
        fail("%s: %d pieces for %d ranks" % (pvtu_path, len(pieces), ranks))
    where = {key(p): i for i, p in enumerate(serial["points"])}
    if len(where) != len(serial["points"]):
        fail("%s: points repeated" % serial_path)
    seen = [0] * len(serial["points"])
    total_points = total_cells = 0
    cells = []
    worst = 0.0
    counts = []
    for source in pieces:
        path = os.path.join(os.path.dirname(pvtu_path), source)
        piece = read_vtu(path)
        held = {name: (n, names) for name, (n, names, _) in piece["arrays"].items()}
        if held != declared:
            fail("%s: arrays %s, the .pvtu declares %s" % (path, held, declared))
        if set(held) != set(serial["arrays"]):
            fail("%s: arrays %s, the serial file has %s" % (path, sorted(held), sorted(serial["arrays"])))
        n, m = len(piece["points"]), len(piece["cells"])
        if n >= len(serial["points"]) or m >= len(serial["cells"]):
            fail("%s: %d points and %d cells, not fewer than the serial %d and %d"
                 % (path, n, m, len(serial["points"]), len(serial["cells"])))
        index = []
        for p in piece["points"]:
            if key(p) not in where:
                fail("%s: point %s is not a serial point" % (path, p))
            index.append(where[key(p)])
            seen[where[key(p)]] += 1
        cells += [(t, tuple(key(piece["points"][k]) for k in nodes)) for t, nodes in piece["cells"]]
        worst = max(worst, compare_values(path, serial, index, piece, tol))
        total_points += n
        total_cells += m
        counts.append(n)
    if part == "particles":
        if total_points != len(serial["points"]) or any(s != 1 for s in seen):
            fail("%s: the pieces hold %d points (%d serial particles, %d in no piece, %d in several)"
                 % (pvtu_path, total_points, len(serial["points"]), seen.count(0), sum(s > 1 for s in seen)))
    elif any(s == 0 for s in seen):
        fail("%s: %d serial mesh points are in no piece" % (pvtu_path, seen.count(0)))
    serial_cells = sorted((t, tuple(key(serial["points"][k]) for k in nodes)) for t, nodes in serial["cells"])
    if total_cells != len(serial["cells"]) or sorted(cells) != serial_cells:
        fail("%s: the pieces' %d cells are not the serial %d cells" % (pvtu_path, total_cells, len(serial["cells"])))
    ok("%s: %d pieces of %s points (serial %d), %d cells (serial %d); values within %.2g of the serial run"
       % (os.path.basename(pvtu_path), len(pieces), "+".join(map(str, counts)), len(serial["points"]), total_cells,
          len(serial["cells"]), worst))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("serial")
    parser.add_argument("parallel")
    parser.add_argument("ranks", type=int)
    parser.add_argument("--tol", type=float, default=1e-10)
    args = parser.parse_args()
    serial = read_pvd(os.path.join(args.serial, "solution.pvd"))
    parallel = read_pvd(os.path.join(args.parallel, "solution.pvd"))
    if [(t, p, n) for t, p, n, _ in serial] != [(t, p, n) for t, p, n, _ in parallel]:
        fail("the PVDs list other steps or parts: %s, %s" % (serial, parallel))
    for (t, _, name, s_file), (_, _, _, p_file) in zip(serial, parallel):
        if not s_file.endswith(".vtu") or s_file.endswith(".pvtu") or not p_file.endswith(".pvtu"):
            fail("step %s, part %s: serial %s, parallel %s" % (t, name, s_file, p_file))
        check_part(os.path.join(args.serial, s_file), os.path.join(args.parallel, p_file), name, args.ranks,
                   args.tol)
    ok("%d step files of %d ranks match the serial run's" % (len(parallel), args.ranks))


if __name__ == "__main__":
    main()
