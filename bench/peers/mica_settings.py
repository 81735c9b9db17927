#!/usr/bin/python3
"""Which mica settings reach a peers problem's error levels cheapest: a grid of settings, each refined over k,
each run measured as peers.py measures it (no DOLFIN needed: the block's reference is the one the last peers run
stored in bench/results/peers_reference.json).

    /usr/bin/python3 bench/peers/mica_settings.py PROBLEM VARIANT [--grid KEY=V1,V2,...]... [--ks K1,K2,...]
                                                  [--repeats 1] [--out CSV]

PROBLEM, VARIANT: a mica variant of bench/peers/peers.py (its deck, its settings, its particle counts and ks);
every --grid setting overrides or adds to the variant's own, and the grid is their Cartesian product. Writes
bench/results/mica_settings_PROBLEM.csv (or --out): the settings, k, dofs, error, the solve phases as peers.py
times them (time_mls_setup + time_cache_and_pattern + time_newton, the minimum over the repeats), quadrature
points, supporting particles per point and nnz; prints, per combination, the time to each of the problem's error
levels (peers_tools.time_to_error, the interpolation of the ratios).
"""
import argparse
import csv
import itertools
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import peers  # noqa: E402
import peers_tools  # noqa: E402


def reference_of(problem):
    """The value error_of compares with: None for the problems with an exact solution."""
    if problem["name"] in ("timoshenko", "manufactured2d", "manufactured3d"):
        return None
    path = os.path.join(peers.RESULTS, "peers_reference.json")
    with open(path) as f:
        return json.load(f)[problem["name"]]["value"]


def grid_of(specs):
    """[(key, [values])] from KEY=V1,V2 specs, in the order given."""
    grid = []
    for spec in specs:
        key, _, values = spec.partition("=")
        if not key or not values:
            sys.exit("--grid %s: expected KEY=V1,V2,..." % spec)
        grid.append((key, values.split(",")))
    return grid


def with_settings(sets, overrides):
    """The variant's settings with every key of overrides replaced (or added)."""
    keys = {k for k, _ in overrides}
    return [s for s in sets if s.partition("=")[0] not in keys] + ["%s=%s" % kv for kv in overrides]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("problem")
    ap.add_argument("variant")
    ap.add_argument("--grid", action="append", default=[])
    ap.add_argument("--ks", default="")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    problem = next((p for p in peers.PROBLEMS if p["name"] == args.problem), None)
    if problem is None or args.variant not in problem["mica"]:
        sys.exit("no mica variant %s of problem %s in peers.py" % (args.variant, args.problem))
    deck_and_sets, count, ks = problem["mica"][args.variant]
    ks = [float(k) if "." in k else int(k) for k in args.ks.split(",")] if args.ks else ks
    ref = reference_of(problem)
    grid = grid_of(args.grid)
    out_csv = args.out or os.path.join(peers.RESULTS, "mica_settings_%s.csv" % args.problem)
    rows = []
    for combo in itertools.product(*[[(key, v) for v in values] for key, values in grid]):
        label = " ".join("%s=%s" % kv for kv in combo) or "(variant as is)"
        name = "scan"
        problem["mica"][name] = ([deck_and_sets[0]] + with_settings(deck_and_sets[1:], list(combo)), count, ks)
        curve = []
        for k in ks:
            best = None
            for _ in range(args.repeats):
                s = peers.run_mica(problem, name, k)
                if best is None or s["time_solve_total"] < best["time_solve_total"]:
                    best = s
            error = peers.error_of(problem, "mica", best, ref)
            row = dict(settings=label, k=k, dofs=best["dofs"], error=error, time_solve_s=best["time_solve_total"],
                       quadrature_points=best.get("quadrature_points", ""), support_mean=best.get("support_mean", ""),
                       nnz=best.get("nnz", ""))
            rows.append(row)
            curve.append((best["dofs"], error, best["time_solve_total"]))
            peers.log("%s k=%s: dofs %d error %.4g solve %.4g s" % (label, k, best["dofs"], error,
                                                                      best["time_solve_total"]))
        times = []
        for level in problem["levels"]:
            t, status = peers_tools.time_to_error(sorted(curve), level)
            times.append("%g: %s" % (level, "%.4g s" % t if t is not None else status))
        peers.log("%s -> %s" % (label, "; ".join(times)))
    with open(out_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    peers.log("wrote %s" % out_csv)


if __name__ == "__main__":
    main()
