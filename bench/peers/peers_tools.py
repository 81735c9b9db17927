#!/usr/bin/python3
"""Time-to-error on an error–time curve, and the mica / peer ratios (no DOLFIN needed).

    peers_tools.py time-to-error CSV PROBLEM CODE VARIANT LEVEL
        the time (time_solve_s) at which the curve of CSV rows (problem, code, variant) reaches error LEVEL,
        interpolated linearly in log(time) against log(error) between the two consecutive refinements (in
        order of dofs) whose errors bracket LEVEL; prints the time, "not reached" (no refinement is that
        accurate) or "below range" (already the coarsest is: no extrapolation either way).
    peers_tools.py ratios CSV OUT_CSV PAIR...
        PAIR = PROBLEM:MICA_VARIANT:PEER_VARIANT:LEVEL[,LEVEL...]; a variant "*" means the fastest of that
        code's variants at the level. Writes problem, error_level, mica_time_s, peer_time_s, ratio (empty
        when either is not reached), the problem named "PROBLEM (MICA_VARIANT vs PEER_VARIANT)".

CSV columns: problem, code, variant, dofs, error, time_solve_s, time_total_s (bench/results/peers.csv).
"""
import csv
import math
import sys

COLUMNS = ["problem", "code", "variant", "dofs", "error", "time_solve_s", "time_total_s"]


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def curve(rows, problem, code, variant, column="time_solve_s"):
    """[(dofs, error, time)] of one variant, in order of dofs."""
    pts = [(int(r["dofs"]), float(r["error"]), float(r[column])) for r in rows
           if r["problem"] == problem and r["code"] == code and r["variant"] == variant
           and r["error"] not in ("", "nan")]
    return sorted(pts)


def time_to_error(points, level):
    """points: [(dofs, error, time)] in refinement order. Returns (time, status)."""
    if not points:
        return None, "no data"
    if points[0][1] <= level:
        return None, "below range"
    for (_, e0, t0), (_, e1, t1) in zip(points, points[1:]):
        if e0 > level >= e1:
            if e1 == level:
                return t1, "ok"
            s = (math.log(level) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + s * (math.log(t1) - math.log(t0))), "ok"
    return None, "not reached"


def best_time(rows, problem, code, variant, level):
    variants = sorted({r["variant"] for r in rows if r["problem"] == problem and r["code"] == code}) \
        if variant == "*" else [variant]
    found = [time_to_error(curve(rows, problem, code, v), level) for v in variants]
    if any(s == "below range" for _, s in found):  # that variant's time is unknown (below its coarsest)
        return None, "below range"
    times = [t for t, s in found if t is not None]
    if times:
        return min(times), "ok"
    return None, found[0][1] if len(found) == 1 else "not reached"


def ratios(rows, pairs):
    out = []
    for pair in pairs:
        problem, mv, pv, levels = pair.split(":")
        for lev in levels.split(","):
            level = float(lev)
            tm, sm = best_time(rows, problem, "mica", mv, level)
            tp, sp = best_time(rows, problem, "fenics", pv, level)
            mv_name = "best" if mv == "*" else mv
            pv_name = "best" if pv == "*" else pv
            out.append(dict(problem="%s (%s vs %s)" % (problem, mv_name, pv_name), error_level="%g" % level,
                            mica_time_s="%.4g" % tm if tm is not None else sm,
                            peer_time_s="%.4g" % tp if tp is not None else sp,
                            ratio="%.3g" % (tm / tp) if tm is not None and tp is not None else ""))
    return out


def write_ratios(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, ["problem", "error_level", "mica_time_s", "peer_time_s", "ratio"],
                           lineterminator="\n")
        w.writeheader()
        w.writerows(rows)


def main(argv):
    if len(argv) == 7 and argv[1] == "time-to-error":
        t, status = time_to_error(curve(read_rows(argv[2]), argv[3], argv[4], argv[5]), float(argv[6]))
        print("%.6g" % t if t is not None else status)
        return 0
    if len(argv) >= 5 and argv[1] == "ratios":
        write_ratios(argv[3], ratios(read_rows(argv[2]), argv[4:]))
        return 0
    sys.stderr.write(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
