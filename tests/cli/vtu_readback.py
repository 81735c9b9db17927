#!/usr/bin/env python3
"""Reads back what `mica run` wrote for ParaView, with no VTK: solution.pvd (xml.etree) and the VTU files it
lists (the XML header with xml.etree, the raw appended blocks with struct), and checks them against the format
and against the run's own summary.json (tests/cli/vtu_mesh.sh drives it; docs/verification.md).

    vtu_readback.py DIR --types 9[,28] [--steps N] [--axisymmetric] [--volume-rtol T]
                        [--at X,Y[,Z] --probe KEY=ARRAY[.COMPONENT] ...] [--no-mesh]
                        [--expect ARRAY=V1,V2,... [--expect-tol T]] [--rotation ARRAY=VECTOR]

Checks, printing "ok: ..." per check and exiting 1 at the first failure ("FAIL: ..."):
  - the PVD lists, per load step, the particles (part 0) and the mesh (part 1), at times k/N exactly, the last
    written "1";
  - every VTU: block byte counts (UInt64 headers) that tile the appended section, the closing tags right after
    the last block, NumberOfPoints and NumberOfCells equal to the blocks' lengths, node counts per VTK cell
    type, point indices in range, every value finite, vector and tensor component names (x, y, z, or r, z,
    theta for an axisymmetric run);
  - the particle file: one vertex cell (type 1) per point;
  - the mesh file: only the cell types given, each point written once and used by a cell, a positive Jacobian
    at every Gauss point of every cell (interpolating the points with VTK's node order, written out here from
    VTK's documentation), and the cells' total area or volume (axisymmetric: the volume of revolution, 2 pi r
    dA) equal to summary.json's "volume" to --volume-rtol;
  - at the mesh point nearest (X, Y[, Z]) (it must lie within 1e-10 of it), each ARRAY[.COMPONENT] of the last
    step equals the probe KEY of summary.json to 1e-12 relative (plus 1e-13 of the array's largest value, for
    components near zero);
  - --expect: ARRAY equals the given values at every point of the last step's files, to --expect-tol;
  - --rotation: the 3x3 ARRAY equals exp(skew(VECTOR)) (Rodrigues' formula, written out here) at every point of
    the last step's files, to 1e-14.
"""
import argparse
import json
import math
import os
import struct
import sys
import xml.etree.ElementTree as ET

# Nodes per VTK cell type (vtkCellType.h).
NODES = {1: 1, 5: 3, 9: 4, 10: 4, 12: 8, 22: 6, 23: 8, 24: 10, 25: 20, 28: 9, 29: 27}
TYPE_SIZE = {"Float64": ("d", 8), "Int64": ("q", 8), "UInt8": ("B", 1)}


def fail(message):
    print("FAIL: " + message, file=sys.stderr)
    sys.exit(1)


def ok(message):
    print("ok: " + message)


# ---- the file formats --------------------------------------------------------------------------------------

def read_vtu(path):
    """The arrays of a VTU file with raw appended data: {name: (components, names, values)} plus the points
    and cells, after checking the block layout."""
    with open(path, "rb") as f:
        raw = f.read()
    start = raw.find(b"<AppendedData")
    if start < 0:
        fail("%s: no <AppendedData>" % path)
    marker = raw.index(b"_", start)
    root = ET.fromstring(raw[:marker].decode("utf-8").rstrip() + "</AppendedData></VTKFile>")
    if root.get("type") != "UnstructuredGrid" or root.get("header_type") != "UInt64":
        fail("%s: not an UnstructuredGrid with UInt64 headers" % path)
    if root.find("AppendedData").get("encoding") != "raw":
        fail("%s: appended data not raw" % path)
    order = "<" if root.get("byte_order") == "LittleEndian" else ">"
    data = raw[marker + 1:]
    piece = root.find("UnstructuredGrid/Piece")
    arrays, position = {}, 0
    elements = piece.findall("PointData/DataArray") + piece.findall("Points/DataArray") + piece.findall("Cells/DataArray")
    for element in elements:
        if element.get("format") != "appended":
            fail("%s: DataArray %s is not appended" % (path, element.get("Name")))
        offset = int(element.get("offset"))
        if offset != position:
            fail("%s: DataArray %s at offset %d, expected %d (blocks must tile the section)"
                 % (path, element.get("Name"), offset, position))
        (nbytes,) = struct.unpack(order + "Q", data[offset:offset + 8])
        code, size = TYPE_SIZE[element.get("type")]
        if nbytes % size:
            fail("%s: block of %s has %d bytes, not a multiple of %d" % (path, element.get("Name"), nbytes, size))
        values = struct.unpack("%s%d%s" % (order, nbytes // size, code), data[offset + 8:offset + 8 + nbytes])
        ncomp = int(element.get("NumberOfComponents", "1"))
        names = [element.get("ComponentName%d" % c) for c in range(ncomp)]
        arrays[element.get("Name") or "Points"] = (ncomp, names, values)
        position = offset + 8 + nbytes
    if data[position:] != b"\n  </AppendedData>\n</VTKFile>\n":
        fail("%s: the closing tags do not follow the last block" % path)
    npoints, ncells = int(piece.get("NumberOfPoints")), int(piece.get("NumberOfCells"))
    points = arrays.pop("Points")[2]
    conn, offsets, types = arrays.pop("connectivity")[2], arrays.pop("offsets")[2], arrays.pop("types")[2]
    if len(points) != 3 * npoints:
        fail("%s: %d point coordinates for NumberOfPoints = %d" % (path, len(points), npoints))
    if len(types) != ncells or len(offsets) != ncells:
        fail("%s: %d types and %d offsets for NumberOfCells = %d" % (path, len(types), len(offsets), ncells))
    for name, (ncomp, _, values) in arrays.items():
        if len(values) != ncomp * npoints:
            fail("%s: array %s has %d values, not %d x %d" % (path, name, len(values), ncomp, npoints))
    cells, begin = [], 0
    for c in range(ncells):
        nodes = conn[begin:offsets[c]]
        if NODES.get(types[c]) != len(nodes):
            fail("%s: cell %d of type %d has %d nodes" % (path, c, types[c], len(nodes)))
        if any(p < 0 or p >= npoints for p in nodes):
            fail("%s: cell %d refers to a point outside [0, %d)" % (path, c, npoints))
        cells.append((types[c], nodes))
        begin = offsets[c]
    if begin != len(conn):
        fail("%s: %d connectivity entries, the offsets end at %d" % (path, len(conn), begin))
    for name, (_, _, values) in list(arrays.items()) + [("points", (3, None, points))]:
        if not all(math.isfinite(v) for v in values):
            fail("%s: %s holds a non-finite value" % (path, name))
    return {"points": [points[3 * i:3 * i + 3] for i in range(npoints)], "cells": cells, "arrays": arrays}


def read_pvd(path):
    root = ET.parse(path).getroot()
    if root.get("type") != "Collection":
        fail("%s: not a Collection" % path)
    return [(d.get("timestep"), int(d.get("part")), d.get("name"), d.get("file"))
            for d in root.findall("Collection/DataSet")]


# ---- cell geometry in VTK's node order ------------------------------------------------------------------------

# Positions in the reference box [0, 1]^d (vtkQuad, vtkBiQuadraticQuad, vtkHexahedron, vtkTriQuadraticHexahedron):
# corners; edge midpoints along (0,1), (1,2), (3,2), (0,3) [, (4,5), (5,6), (7,6), (4,7), (0,4), (1,5), (2,6),
# (3,7)]; face centres x = 0, x = 1, y = 0, y = 1, z = 0, z = 1; the centre.
H = 0.5
QUAD = [(0, 0), (1, 0), (1, 1), (0, 1)]
BIQUAD = QUAD + [(H, 0), (1, H), (H, 1), (0, H), (H, H)]
HEX = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
TRIQUAD = HEX + [(H, 0, 0), (1, H, 0), (H, 1, 0), (0, H, 0), (H, 0, 1), (1, H, 1), (H, 1, 1), (0, H, 1),
                 (0, 0, H), (1, 0, H), (1, 1, H), (0, 1, H),
                 (0, H, H), (1, H, H), (H, 0, H), (H, 1, H), (H, H, 0), (H, H, 1), (H, H, H)]
TENSOR_NODES = {9: QUAD, 12: HEX, 28: BIQUAD, 29: TRIQUAD}


def lagrange_1d(nodes, node, t):
    """The 1-D Lagrange polynomial of `node` on the node set and its derivative at t."""
    value, derivative = 1.0, 0.0
    for other in nodes:
        if other == node:
            continue
        term = 1.0 / (node - other)
        derivative = derivative * (t - other) * term + value * term
        value *= (t - other) * term
    return value, derivative


def tensor_shape(layout, r):
    dim = len(r)
    axis_nodes = sorted({p[0] for p in layout})
    shape = []
    for p in layout:
        f = [lagrange_1d(axis_nodes, p[d], r[d]) for d in range(dim)]
        value = math.prod(v for v, _ in f)
        grad = [math.prod(f[e][1] if e == d else f[e][0] for e in range(dim)) for d in range(dim)]
        shape.append((value, grad))
    return shape


def gauss_unit(n=3):
    x = [-math.sqrt(0.6), 0.0, math.sqrt(0.6)]
    w = [5 / 9, 8 / 9, 5 / 9]
    return [(0.5 * (1 + xi), 0.5 * wi) for xi, wi in zip(x, w)][:n]


def det(m):
    if len(m) == 2:
        return m[0][0] * m[1][1] - m[0][1] * m[1][0]
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def cell_measure(kind, xs, dim, axisymmetric):
    """Area or volume of a cell through its nodes' interpolation (axisymmetric: ∫ 2 pi r dA), and the smallest
    Jacobian determinant at the Gauss points."""
    rule = gauss_unit()
    if kind in (5, 10):  # simplices: constant Jacobian, the centroid rule is exact for 1 and r
        jac = [[xs[k + 1][i] - xs[0][i] for k in range(dim)] for i in range(dim)]
        d = det(jac)
        centroid_r = sum(x[0] for x in xs) / len(xs)
        size = d / math.factorial(dim)
        return size * (2 * math.pi * centroid_r if axisymmetric else 1.0), d
    total, smallest = 0.0, math.inf
    points = [(a,) for a in rule]
    for _ in range(dim - 1):
        points = [p + (a,) for p in points for a in rule]
    for p in points:
        r = [a[0] for a in p]
        w = math.prod(a[1] for a in p)
        shape = tensor_shape(TENSOR_NODES[kind], r)
        jac = [[sum(shape[a][1][k] * xs[a][i] for a in range(len(xs))) for k in range(dim)] for i in range(dim)]
        d = det(jac)
        smallest = min(smallest, d)
        radius = sum(shape[a][0] * xs[a][0] for a in range(len(xs)))
        total += w * d * (2 * math.pi * radius if axisymmetric else 1.0)
    return total, smallest


# ---- checks -------------------------------------------------------------------------------------------------

def check_names(path, arrays, axisymmetric):
    vector = ["r", "z", "theta"] if axisymmetric else ["x", "y", "z"]
    tensor = [a + b for a in vector for b in vector]
    for name, (ncomp, names, _) in arrays.items():
        want = vector if ncomp == 3 else tensor if ncomp == 9 else [None]
        if names != want:
            fail("%s: %s has components %s, expected %s" % (path, name, names, want))
    ok("%s: components named %s (vectors) and %s... (tensors) in %d arrays"
       % (os.path.basename(path), ", ".join(vector), ", ".join(tensor[:3]), len(arrays)))


def check_particles(path, vtu):
    if any(kind != 1 or len(nodes) != 1 for kind, nodes in vtu["cells"]) or len(vtu["cells"]) != len(vtu["points"]):
        fail("%s: the particle file is not one vertex cell per point" % path)


def check_mesh(path, vtu, types, dim, axisymmetric, volume, volume_rtol):
    points, cells = vtu["points"], vtu["cells"]
    seen = {kind for kind, _ in cells}
    if not seen or not seen <= set(types):
        fail("%s: cell types %s, expected %s" % (path, sorted(seen), types))
    scale = max(max(abs(c) for c in p) for p in points)
    keys = {tuple(round(c / scale, 11) for c in p) for p in points}
    if len(keys) != len(points):
        fail("%s: %d points but %d distinct positions (shared points written more than once)"
             % (path, len(points), len(keys)))
    used = {p for _, nodes in cells for p in nodes}
    if len(used) != len(points):
        fail("%s: %d of %d points belong to no cell" % (path, len(points) - len(used), len(points)))
    if any(p[2] != 0.0 for p in points) and dim == 2:
        fail("%s: a 2-D mesh has points off z = 0" % path)
    total, smallest = 0.0, math.inf
    for kind, nodes in cells:
        size, d = cell_measure(kind, [points[p][:dim] for p in nodes], dim, axisymmetric)
        total += size
        smallest = min(smallest, d)
    if not smallest > 0:
        fail("%s: a cell has Jacobian determinant %g <= 0 (wrong node order or orientation)" % (path, smallest))
    relative = abs(total - volume) / volume
    if relative > volume_rtol:
        fail("%s: the cells' %s %.15g differs from summary.json's volume %.15g by %.3g (> %g)"
             % (path, "volume" if dim == 3 or axisymmetric else "area", total, volume, relative, volume_rtol))
    ok("%s: %d points, %d cells of types %s, each point once, Jacobians > 0 (min %.3g), measure %.12g vs volume "
       "%.12g (rel. %.2g)" % (os.path.basename(path), len(points), len(cells), sorted(seen), smallest, total, volume,
                              relative))


def check_probes(path, vtu, at, probes, summary):
    distances = [math.dist(p[:len(at)], at) for p in vtu["points"]]
    nearest = min(range(len(distances)), key=distances.__getitem__)
    if distances[nearest] > 1e-10:
        fail("%s: no mesh point at %s (nearest %s, %.3g away)" % (path, at, vtu["points"][nearest], distances[nearest]))
    worst = 0.0
    for spec in probes:
        key, field = spec.split("=")
        name, _, component = field.partition(".")
        if name not in vtu["arrays"]:
            fail("%s: no array %s" % (path, name))
        ncomp, names, values = vtu["arrays"][name]
        c = names.index(component) if component else 0
        value = values[nearest * ncomp + c]
        largest = max(abs(values[i * ncomp + c]) for i in range(len(vtu["points"])))
        probe = summary[key]
        difference = abs(value - probe)
        if difference > 1e-12 * max(abs(probe), abs(value)) + 1e-13 * largest:
            fail("%s: %s at %s is %.17g, probe %s = %.17g (difference %.3g)" % (path, field, at, value, key, probe,
                                                                               difference))
        worst = max(worst, difference / max(abs(probe), 1e-300))
    ok("%s: point %d at %s: %d fields equal their probes (largest relative difference %.2g)"
       % (os.path.basename(path), nearest, at, len(probes), worst))


def check_everywhere(path, vtu, expect, tol, rotation):
    """The --expect and --rotation checks at every point of one file."""
    for spec in expect:
        name, values = spec.split("=")
        want = [float(v) for v in values.split(",")]
        ncomp, _, data = vtu["arrays"][name]
        if ncomp != len(want):
            fail("%s: %s has %d components, --expect gives %d" % (path, name, ncomp, len(want)))
        worst = max(abs(data[i] - want[i % ncomp]) for i in range(len(data)))
        if worst > tol:
            fail("%s: %s differs from %s by %.3g somewhere (> %g)" % (path, name, values, worst, tol))
        ok("%s: %s = (%s) at all %d points (largest difference %.2g)"
           % (os.path.basename(path), name, values, len(data) // ncomp, worst))
    if rotation:
        name, vector = rotation.split("=")
        _, _, chi = vtu["arrays"][name]
        _, _, phi = vtu["arrays"][vector]
        worst = 0.0
        for i in range(len(phi) // 3):
            v = phi[3 * i:3 * i + 3]
            theta = math.sqrt(sum(c * c for c in v))
            k = [[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]]
            k2 = [[sum(k[a][c] * k[c][b] for c in range(3)) for b in range(3)] for a in range(3)]
            a_ = math.sin(theta) / theta if theta > 0 else 1.0
            b_ = (1 - math.cos(theta)) / theta ** 2 if theta > 0 else 0.5
            for a in range(3):
                for b in range(3):
                    r = (a == b) + a_ * k[a][b] + b_ * k2[a][b]
                    worst = max(worst, abs(chi[9 * i + 3 * a + b] - r))
        if worst > 1e-14:
            fail("%s: %s is not exp(skew(%s)) (difference %.3g)" % (path, name, vector, worst))
        ok("%s: %s = exp(skew(%s)) at all %d points (largest difference %.2g)"
           % (os.path.basename(path), name, vector, len(phi) // 3, worst))


def check_times(steps, per_step, datasets):
    times = [datasets[i][0] for i in range(0, len(datasets), per_step)]
    if len(times) != steps:
        fail("solution.pvd lists %d steps, expected %d" % (len(times), steps))
    for k, text in enumerate(times, 1):
        if float(text) != k / steps:
            fail("solution.pvd: step %d at t = %s, not %d/%d" % (k, text, k, steps))
    if times[-1] != "1":
        fail("solution.pvd: the last step is at t = %s, not 1" % times[-1])
    ok("solution.pvd: %d steps at t = k/%d exactly (%s ... %s)" % (steps, steps, times[0], times[-1]))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("dir")
    parser.add_argument("--types", default="")
    parser.add_argument("--steps", type=int, default=1)
    parser.add_argument("--axisymmetric", action="store_true")
    parser.add_argument("--volume-rtol", type=float, default=1e-12)
    parser.add_argument("--at", default=None)
    parser.add_argument("--probe", action="append", default=[])
    parser.add_argument("--no-mesh", action="store_true")
    parser.add_argument("--expect", action="append", default=[])
    parser.add_argument("--expect-tol", type=float, default=1e-10)
    parser.add_argument("--rotation", default=None)
    args = parser.parse_args()
    with open(os.path.join(args.dir, "summary.json")) as f:
        summary = json.load(f)
    dim = summary["dim"]
    datasets = read_pvd(os.path.join(args.dir, "solution.pvd"))
    per_step = 1 if args.no_mesh else 2
    want_parts = [(0, "particles")] if args.no_mesh else [(0, "particles"), (1, "mesh")]
    for i in range(0, len(datasets), per_step):
        step = datasets[i:i + per_step]
        if [(part, name) for _, part, name, _ in step] != want_parts or len({t for t, _, _, _ in step}) != 1:
            fail("solution.pvd: step %d lists %s, expected parts %s at one time" % (i // per_step + 1, step, want_parts))
    ok("solution.pvd: each step lists %s" % " and ".join("part %d (%s)" % p for p in want_parts))
    check_times(args.steps, per_step, datasets)
    for _, part, _, name in datasets:
        path = os.path.join(args.dir, name)
        vtu = read_vtu(path)
        if part == 0:
            check_particles(path, vtu)
        else:
            check_mesh(path, vtu, [int(t) for t in args.types.split(",")], dim, args.axisymmetric, summary["volume"],
                       args.volume_rtol)
        check_names(path, vtu["arrays"], args.axisymmetric)
    for _, _, _, name in datasets[-per_step:]:
        path = os.path.join(args.dir, name)
        check_everywhere(path, read_vtu(path), args.expect, args.expect_tol, args.rotation)
    if args.no_mesh and any(f.startswith("mesh_") for f in os.listdir(args.dir)):
        fail("%s: mesh files written with output.mesh = false" % args.dir)
    if args.at:
        last = datasets[-1][3]
        at = [float(v) for v in args.at.split(",")]
        check_probes(os.path.join(args.dir, last), read_vtu(os.path.join(args.dir, last)), at, args.probe, summary)
        if not args.no_mesh and summary["method"] == "efg":  # MLS at a particle sitting there: the probe too
            particles = os.path.join(args.dir, datasets[-2][3])
            vtu = read_vtu(particles)
            if min(math.dist(p[:len(at)], at) for p in vtu["points"]) <= 1e-10:
                check_probes(particles, vtu, at, args.probe, summary)


if __name__ == "__main__":
    main()
