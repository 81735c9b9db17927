#!/usr/bin/python3
"""The relative energy-norm error of solutions of the Cosserat hole against the FEniCS reference, at points.

    /usr/bin/python3 bench/peers/energy_norm.py REF_VARIANT REF_K REF_NPY OUT_JSON [--points CSV]
                                                [mica CSV ...] [--fenics VARIANT:K:NPY ...]

REF_NPY: the coefficient vector of the reference solution (fenics_peer.py with PEERS_SAVE_SOLUTION), which
cosserat_space(REF_VARIANT, REF_K) rebuilds. Each mica CSV is a quadrature_fields.csv (mica run with
output.quadrature_fields = true): its rows give the points x_p, weights w_p and mica's kinematics q_p =
(u1, u2, φ, u1,1, u1,2, u2,1, u2,2, φ,1, φ,2). Then

    e_E = sqrt( Σ_p w_p 2W(q_p − q_ref,p) / Σ_p w_p 2W(q_ref,p) ),   2W(q) = qᵀ D q,

D the plane-strain Cosserat matrix of fenics_peer.py (λ, μ, κ, γ from G, ν, N, l): the energy norm the issue
names, the same formula for every code. The denominator is checked against 2 U_ref (the reference's energy:
they agree to the point set's quadrature accuracy), mica's own W column against ½ qᵀDq of its row (the same
constants and sign conventions in both codes) and Σ w W against mica's `energy` probe (its summary).
--fenics VARIANT:K:NPY: a FEniCS solution measured by the same formula at the points of --points (default:
the last mica CSV), for the check that its e_E equals sqrt(|U − U_ref| / U_ref) (Galerkin orthogonality).

Evaluating a function at a physical point of a curved (P2-geometry) DOLFIN mesh: DOLFIN 2019's point
evaluation (and Expression interpolation) maps physical to reference coordinates with the cell's vertices
only, the affine map, while assembly uses the quadratic one; in a curved cell that evaluates the function
at the wrong place (measured: 18 % in a gradient on this mesh). So here each point's reference coordinates X
come from Newton's method on the cell's quadratic map, and the function is evaluated at the point whose
affine image is X. Values and gradients come from one L2 projection of (u, φ, ∇u, ∇φ) onto DG3 (LocalSolver,
per cell): exact for the P3/P2 fields on straight cells, an L2-best fit on curved ones.
"""
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fenics_peer as fp  # noqa: E402
from dolfin import (Cell, Function, LocalSolver, Point, TestFunction, TrialFunction, VectorFunctionSpace,  # noqa
                    as_vector, dx, inner, split, Vertex)

MICA_COLUMNS = ["ux", "uy", "phiz", "dux_dx", "dux_dy", "duy_dx", "duy_dy", "dphiz_dx", "dphiz_dy"]


def two_W(q, c):
    """qᵀ D q for rows q = (u1, u2, φ, u1,1, u1,2, u2,1, u2,2, φ,1, φ,2): ε_kl = u_l,k + e_lk3 φ
    (ε_12 = u2,1 − φ, ε_21 = u1,2 + φ), σ = λ tr ε I + (μ + κ) ε + μ εᵀ, 2W = σ:ε + γ |∇φ|²."""
    e11, e22 = q[:, 3], q[:, 6]
    e12, e21 = q[:, 5] - q[:, 2], q[:, 4] + q[:, 2]
    tr = e11 + e22
    return (c["lam"] * tr * tr + (c["mu"] + c["kap"]) * (e11 ** 2 + e22 ** 2 + e12 ** 2 + e21 ** 2) +
            c["mu"] * (e11 ** 2 + e22 ** 2 + 2 * e12 * e21) + c["gam"] * (q[:, 7] ** 2 + q[:, 8] ** 2))


def read_points(path):
    """x (n, 2), w (n,), q (n, 9) in the column order of two_W, W (n,) from a quadrature_fields.csv."""
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    col = {name: i for i, name in enumerate(header)}
    return (data[:, [col["x"], col["y"]]], data[:, col["w"]], data[:, [col[n] for n in MICA_COLUMNS]],
            data[:, col["W"]])


def solve2(A, b):
    """Batched 2 × 2 solves A x = b (A (n, 2, 2), b (n, 2)) by Cramer's rule; singular → inf/NaN, no exception."""
    det = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    return np.stack([A[:, 1, 1] * b[:, 0] - A[:, 0, 1] * b[:, 1], A[:, 0, 0] * b[:, 1] - A[:, 1, 0] * b[:, 0]],
                    axis=1) / det[:, None]


class Fields:
    """(u, φ, ∇u, ∇φ) of a FEniCS solution of the hole, evaluable at physical points of its curved mesh."""

    def __init__(self, variant, k, npy):
        self.mesh, V, _, _ = fp.cosserat_space(variant, k)
        w = Function(V)
        w.vector().set_local(np.load(npy))
        w.vector().apply("insert")
        u, ph = split(w)
        expr = as_vector([u[0], u[1], ph, u[0].dx(0), u[0].dx(1), u[1].dx(0), u[1].dx(1), ph.dx(0), ph.dx(1)])
        Q = VectorFunctionSpace(self.mesh, "DG", 3, dim=9)
        t, v = TrialFunction(Q), TestFunction(Q)
        solver = LocalSolver(inner(t, v) * dx(degree=8), inner(expr, v) * dx(degree=8))
        solver.factorize()
        self.q = Function(Q)
        solver.solve_local_rhs(self.q)
        self.q.set_allow_extrapolation(True)
        mesh = self.mesh
        mesh.init(0, 2)
        n = mesh.num_cells()
        self.nodes = np.array([Cell(mesh, c).get_coordinate_dofs() for c in range(n)]).reshape(n, 6, 2)
        self.vertex_cells = [Vertex(mesh, v).entities(2).copy() for v in range(mesh.num_vertices())]
        self.cell_vertices = mesh.cells()
        self.tree = mesh.bounding_box_tree()

    @staticmethod
    def shape(X):
        """P2 shape functions on the reference triangle and their derivatives, UFC order: vertices 0, 1, 2,
        then the midpoints of the edges opposite vertex 0, 1, 2."""
        L = np.stack([1 - X[:, 0] - X[:, 1], X[:, 0], X[:, 1]], axis=1)
        dL = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
        N = np.concatenate([L * (2 * L - 1), np.stack([4 * L[:, 1] * L[:, 2], 4 * L[:, 0] * L[:, 2],
                                                       4 * L[:, 0] * L[:, 1]], axis=1)], axis=1)
        dN = np.empty((len(X), 6, 2))
        for i in range(3):
            dN[:, i] = (4 * L[:, i] - 1)[:, None] * dL[i]
        for e, (i, j) in enumerate([(1, 2), (0, 2), (0, 1)]):
            dN[:, 3 + e] = 4 * (L[:, i, None] * dL[j] + L[:, j, None] * dL[i])
        return N, dN

    def reference_coordinates(self, x, cells):
        """Newton on the quadratic map of each point's cell: X with x(X) = x, and min barycentric of X."""
        c = self.nodes[cells]                                   # (n, 6, 2)
        A = np.stack([c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]], axis=2)
        X = solve2(A, x - c[:, 0])                              # the affine guess
        with np.errstate(all="ignore"):  # a far candidate cell may not converge: its X is NaN, never chosen
            for _ in range(12):
                N, dN = self.shape(X)
                step = solve2(np.einsum("pid,pie->pde", c, dN), np.einsum("pi,pid->pd", N, c) - x)  # J = ∂x/∂X
                X -= step
                if not np.nanmax(np.abs(step), initial=0) >= 1e-14:
                    break
            inside = np.minimum(np.minimum(X[:, 0], X[:, 1]), 1 - X[:, 0] - X[:, 1])
        return X, np.nan_to_num(inside, nan=-np.inf)

    def locate(self, x):
        """Each point's cell (the curved one that holds it, or the nearest) and its reference coordinates."""
        big = np.iinfo(np.uint32).max
        cells = np.empty(len(x), dtype=np.int64)
        for i, (a, b) in enumerate(x):
            c = self.tree.compute_first_entity_collision(Point(a, b))
            cells[i] = c if c < big else self.tree.compute_closest_entity(Point(a, b))[0]
        X, inside = self.reference_coordinates(x, cells)
        out = np.nonzero(inside < -1e-10)[0]  # near a curved edge: try every cell around the first guess at once
        if len(out):
            near = [np.unique(np.concatenate([self.vertex_cells[v] for v in self.cell_vertices[cells[i]]]))
                    for i in out]
            width = max(len(n) for n in near)
            cand = np.array([np.pad(n, (0, width - len(n)), mode="edge") for n in near])  # (m, width)
            Xn, inn = self.reference_coordinates(np.repeat(x[out], width, axis=0), cand.ravel())
            inn = inn.reshape(len(out), width)
            j = np.argmax(inn, axis=1)
            better = inn[np.arange(len(out)), j] > inside[out]
            pick = out[better]
            cells[pick] = cand[better, j[better]]
            X[pick] = Xn.reshape(len(out), width, 2)[better, j[better]]
            inside[pick] = inn[better, j[better]]
        return cells, X, inside

    def at(self, x):
        """q (n, 9) at physical points x (n, 2); and the worst barycentric coordinate (how far outside)."""
        cells, X, inside = self.locate(x)
        c = self.nodes[cells]
        fake = c[:, 0] + X[:, :1] * (c[:, 1] - c[:, 0]) + X[:, 1:] * (c[:, 2] - c[:, 0])
        out = np.empty((len(x), 9))
        val = np.empty(9)
        ev = self.q._cpp_object.eval
        for i, p in enumerate(fake):
            ev(val, p)
            out[i] = val
        return out, float(inside.min())


def measure(ref, points_csv, c, q_other=None):
    """e_E of mica's rows (or of q_other, another code's fields at the same points) and the checks."""
    x, w, q_mica, W_mica = read_points(points_csv)
    q_ref, worst = ref.at(x)
    q = q_mica if q_other is None else q_other.at(x)[0]
    num = float(np.sum(w * two_W(q - q_ref, c)))
    den = float(np.sum(w * two_W(q_ref, c)))
    out = dict(points=len(w), e_E=math.sqrt(abs(num) / den), two_U_ref_points=den,
               worst_barycentric=worst)
    if q_other is None:
        out["sum_wW_mica"] = float(np.sum(w * W_mica))
        out["W_formula_mismatch"] = float(np.max(np.abs(0.5 * two_W(q_mica, c) - W_mica)) / np.max(np.abs(W_mica)))
    return out


def main(argv):
    if len(argv) < 5:
        sys.exit(__doc__)
    t0 = time.perf_counter()
    ref_variant, ref_k, ref_npy, out_json = argv[1], int(argv[2]), argv[3], argv[4]
    rest = argv[5:]
    points, mica, fenics = None, [], []
    while rest:
        a = rest.pop(0)
        if a == "--points":
            points = rest.pop(0)
        elif a == "--fenics":
            fenics.append(rest.pop(0))
        else:
            mica.append(a)
    c = fp.cosserat_constants()
    ref = Fields(ref_variant, ref_k, ref_npy)
    t1 = time.perf_counter()
    result = dict(mica={}, fenics={}, time_setup=t1 - t0)
    for path in mica:
        result["mica"][path] = measure(ref, path, c)
    points = points or (mica[-1] if mica else None)
    for spec in fenics:
        variant, k, npy = spec.split(":")
        result["fenics"][spec] = dict(measure(ref, points, c, Fields(variant, int(k), npy)), variant=variant,
                                      k=int(k), points_from=points)
    result["time_total"] = time.perf_counter() - t0
    with open(out_json, "w") as f:
        json.dump(result, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
