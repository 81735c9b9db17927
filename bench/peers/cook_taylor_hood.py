#!/usr/bin/python3
"""Cook's membrane at nu = 0.4999, plane strain, E = 1: the Taylor-Hood P2/P1 reference of issue 21 item 2.

    /usr/bin/python3 bench/peers/cook_taylor_hood.py linear|neohooke [N ...]

Legacy FEniCS (DOLFIN 2019, Debian python3-dolfin), independent of mica: a displacement-pressure mixed form
with continuous quadratic displacements and continuous linear pressures (Taylor-Hood, inf-sup stable) on
triangles of an N x N mapped grid ("crossed" diagonals), for each N given (default 8 16 32 64 128). Prints,
per N, the tip displacement u_y(48, 60) and its change from the previous N; the last line is a JSON object
with every value. docs/verification.md §Nearly incompressible Cook's membrane says which value is committed.

The problem is input/cook_incompressible.cfg's: the trapezoid (0,0), (48,44), (48,60), (0,44) clamped at
x = 0 (strongly, here), a uniform shear traction t_y = F/16 on x = 48, E = 1, nu = 0.4999.

linear    F = 1. Herrmann's form: 2 mu eps(u):eps(v) + p div v = t.v, (div u - p/lambda) q = 0
          (p = lambda div u: condensed, it is linear elasticity with lambda).
neohooke  F = 0.3, mica's `neohooke` energy W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2, plane strain
          (I1 = tr(F^T F) + 1), in the mixed form W = mu/2 (I1 - 3) - mu ln J + p ln J - p^2/(2 lambda)
          (stationary in p: p = lambda ln J, the same energy), solved by Newton in 10 load steps.
"""
import json
import sys

from dolfin import (Constant, DirichletBC, FiniteElement, Function, FunctionSpace, Identity, MeshFunction,
                    MixedElement, NonlinearVariationalProblem, NonlinearVariationalSolver, Point,
                    RectangleMesh, SubDomain, TestFunctions, TrialFunction, VectorElement, derivative, det, div,
                    dx, grad, inner, ln, near, parameters, set_log_level, split, sym, tr, Measure, LogLevel,
                    solve, TrialFunctions)

set_log_level(LogLevel.WARNING)
parameters["form_compiler"]["quadrature_degree"] = 6

E, NU = 1.0, 0.4999
MU = E / (2 * (1 + NU))
LMBDA = E * NU / ((1 + NU) * (1 - 2 * NU))


def cook_mesh(n):
    """N x N crossed triangles of the unit square mapped onto the trapezoid (exact: the map is bilinear in
    xi and affine along each edge, so straight edges stay straight)."""
    mesh = RectangleMesh(Point(0, 0), Point(1, 1), n, n, "crossed")
    x = mesh.coordinates()
    xi, eta = x[:, 0].copy(), x[:, 1].copy()
    x[:, 0] = 48.0 * xi
    x[:, 1] = 44.0 * xi + eta * (44.0 + 16.0 * xi - 44.0 * xi)
    return mesh


class Left(SubDomain):
    def inside(self, x, on_boundary):
        return on_boundary and near(x[0], 0.0)


class Right(SubDomain):
    def inside(self, x, on_boundary):
        return on_boundary and near(x[0], 48.0)


def spaces(mesh):
    element = MixedElement([VectorElement("CG", mesh.ufl_cell(), 2), FiniteElement("CG", mesh.ufl_cell(), 1)])
    W = FunctionSpace(mesh, element)
    facets = MeshFunction("size_t", mesh, mesh.topology().dim() - 1, 0)
    Right().mark(facets, 1)
    ds = Measure("ds", domain=mesh, subdomain_data=facets)
    bc = DirichletBC(W.sub(0), Constant((0.0, 0.0)), Left())
    return W, ds, bc


def tip(w):
    return w.sub(0, deepcopy=True)(Point(48.0, 60.0))[1]


def linear(n, force=1.0):
    mesh = cook_mesh(n)
    W, ds, bc = spaces(mesh)
    (u, p) = TrialFunctions(W)
    (v, q) = TestFunctions(W)
    t = Constant((0.0, force / 16.0))
    a = 2 * MU * inner(sym(grad(u)), sym(grad(v))) * dx + p * div(v) * dx + (div(u) - p / LMBDA) * q * dx
    L = inner(t, v) * ds(1)
    w = Function(W)
    solve(a == L, w, bc, solver_parameters={"linear_solver": "mumps"})
    return tip(w), W.dim()


def neohooke(n, force=0.3, steps=10):
    mesh = cook_mesh(n)
    W, ds, bc = spaces(mesh)
    w = Function(W)
    u, p = split(w)
    F = Identity(2) + grad(u)
    J = det(F)
    I1 = tr(F.T * F) + 1.0
    psi = MU / 2 * (I1 - 3) - MU * ln(J) + p * ln(J) - p ** 2 / (2 * LMBDA)
    load = Constant(0.0)
    t = Constant((0.0, force / 16.0))
    Pi = psi * dx - load * inner(t, u) * ds(1)
    residual = derivative(Pi, w)
    jacobian = derivative(residual, w, TrialFunction(W))
    problem = NonlinearVariationalProblem(residual, w, bc, jacobian)
    solver = NonlinearVariationalSolver(problem)
    prm = solver.parameters["newton_solver"]
    prm["linear_solver"] = "mumps"
    prm["relative_tolerance"] = 1e-10
    prm["absolute_tolerance"] = 1e-11
    prm["maximum_iterations"] = 30
    for k in range(1, steps + 1):
        load.assign(k / steps)
        solver.solve()
    return tip(w), W.dim()


def main():
    kind = sys.argv[1] if len(sys.argv) > 1 else "linear"
    counts = [int(a) for a in sys.argv[2:]] or [8, 16, 32, 64, 128]
    run = {"linear": linear, "neohooke": neohooke}[kind]
    rows, previous = [], None
    for n in counts:
        value, dofs = run(n)
        change = abs(value - previous) / abs(value) if previous is not None else float("nan")
        print(f"{kind} N = {n:4d}: {dofs:7d} dofs, tip u_y = {value:.7f}, change from previous {change:.2e}",
              flush=True)
        rows.append({"N": n, "dofs": dofs, "tip_uy": value})
        previous = value
    print(json.dumps({"problem": kind, "E": E, "nu": NU, "rows": rows}))


if __name__ == "__main__":
    main()
