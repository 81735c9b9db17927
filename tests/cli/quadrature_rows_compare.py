#!/usr/bin/env python3
"""quadrature_fields.csv of a distributed run (the ranks' rows appended in rank order) against a serial run's
(tests/cli/mpi_distributed.sh): the same header, the same number of rows, and row by row — matched by their
coordinates, as the ranks hold their own cells' points — every column within TOL of the serial value, relative to
the column's largest magnitude (the unknowns together, the gradients together); summary.json's quadrature_fields_points equal and quadrature_fields_energy within TOL.

    quadrature_rows_compare.py SERIAL_DIR DISTRIBUTED_DIR --tol T
"""
import argparse
import csv
import json
import os
import sys

ap = argparse.ArgumentParser()
ap.add_argument("serial")
ap.add_argument("distributed")
ap.add_argument("--tol", type=float, required=True)
a = ap.parse_args()
read = lambda d: list(csv.reader(open(os.path.join(d, "quadrature_fields.csv"))))
s, p = read(a.serial), read(a.distributed)
if s[0] != p[0]:
    sys.exit("FAIL: headers differ: %s / %s" % (s[0], p[0]))
if len(s) != len(p):
    sys.exit("FAIL: %d rows, %d serially" % (len(p) - 1, len(s) - 1))
dim = s[0].index("w")
rows = lambda t: sorted((tuple(round(float(v), 12) for v in r[:dim]), [float(v) for v in r]) for r in t[1:])
sr, pr = rows(s), rows(p)
# scales: a column's largest magnitude, the unknowns' and the gradients' taken together (a component that is zero
# in the exact field holds round-off alone, which its own scale would inflate)
head = s[0]
group = ["grad" if h.startswith("d") and "_d" in h else "value" if dim < k < len(head) - 1 else h
         for k, h in enumerate(head)]
largest = {}
for k, g in enumerate(group):
    largest[g] = max(largest.get(g, 0.0), max(abs(r[1][k]) for r in sr))
scale = [largest[g] or 1.0 for g in group]
worst = 0.0
for (ks, vs), (kp, vp) in zip(sr, pr):
    if ks != kp:
        sys.exit("FAIL: the points differ: %s / %s" % (ks, kp))
    for k in range(len(vs)):
        worst = max(worst, abs(vs[k] - vp[k]) / scale[k])
if worst > a.tol:
    sys.exit("FAIL: a column differs by %.3g > %g" % (worst, a.tol))
js = [json.load(open(os.path.join(d, "summary.json"))) for d in (a.serial, a.distributed)]
if js[0]["quadrature_fields_points"] != js[1]["quadrature_fields_points"]:
    sys.exit("FAIL: quadrature_fields_points %s, serially %s" % (js[1]["quadrature_fields_points"], js[0]["quadrature_fields_points"]))
e0, e1 = js[0]["quadrature_fields_energy"], js[1]["quadrature_fields_energy"]
if abs(e0 - e1) > a.tol * abs(e0):
    sys.exit("FAIL: quadrature_fields_energy %.17g, serially %.17g" % (e1, e0))
print("ok: %d rows, every column within %.2g of the serial run's, energy %.12g" % (len(s) - 1, worst, e1))
