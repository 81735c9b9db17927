#!/usr/bin/python3
"""The FEniCS (legacy DOLFIN 2019) side of `make bench-peers`: one problem, one variant, one size per call.

    /usr/bin/python3 bench/peers/fenics_peer.py PROBLEM VARIANT N

PROBLEM VARIANT: timoshenko P1|P2|P3, cook P2|P3, cosserat P2P1|P2P2|P3P2 (suffix r: half the cells along the
hole), block3d P1|P2|P3, manufactured2d P1|P2|P3, manufactured3d P1|P2|P3. N is the refinement parameter (the
same k as the mica side uses, see peers.py). Prints one JSON object on the last line:
dofs, cells, qoi (the quantity each problem measures: see below), error (only where an exact solution
exists), and the times

    time_mesh      mesh creation (and, for the hole, writing/reading the quadratic XDMF mesh and the space)
    time_jit       function spaces, expressions, Form objects: the FFC/dijitso JIT, a cache lookup when warm
    time_assemble  assembly of matrix and right-hand side (assemble_system: sparsity pattern included)
    time_factor    the factorization: MUMPS through PETSc, Cholesky (every problem's matrix is symmetric: Dirichlet
                   conditions applied symmetrically by assemble_system), positive definite (MUMPS's SYM = 1)
                   except Cook's Neo-Hooke tangent (SYM = 2, LDLᵀ with pivoting); Cook's Newton iterations
                   assemble into the same matrix, so PETSc reuses the symbolic analysis and refactors only
    time_solve_lin the triangular solves
    time_solve     time_assemble + time_factor + time_solve_lin: "the solve phases", as counted for mica
    time_post      error norms, energies, probes

The problems are those of the mica decks (same geometry, material, boundary conditions, loads); Dirichlet
conditions are imposed strongly here (weakly in mica). The manufactured fields (input/manufactured.cfg,
input/manufactured3d.cfg) have no polynomial part: no element holds them exactly.
"""
import json
import math
import os
import sys
import time

import numpy as np

T_START = time.perf_counter()
from dolfin import (MPI, XDMFFile, Constant, DirichletBC, Expression, FacetNormal, Form, Function,  # noqa: E402
                    FunctionSpace, Identity, Mesh, MeshFunction, MixedElement, PETScMatrix,
                    PETScVector, Point, RectangleMesh, BoxMesh, SubDomain, TestFunction, TrialFunction,
                    VectorElement, FiniteElement, VectorFunctionSpace, as_matrix, as_vector, assemble,
                    assemble_system, derivative, det, diff, dot, ds, dx, grad, inner, ln, parameters, split, tr,
                    variable, Measure, near, set_log_level, LogLevel, as_backend_type)
from petsc4py import PETSc  # noqa: E402

set_log_level(LogLevel.WARNING)
parameters["form_compiler"]["optimize"] = True
parameters["form_compiler"]["cpp_optimize"] = True
parameters["form_compiler"]["cpp_optimize_flags"] = "-O2"
T_IMPORT = time.perf_counter() - T_START
LINEAR_SOLVER = "mumps"


def compiled(form):
    """A DOLFIN Form compiled now (JIT, or a cache lookup), so that assembly later times no compilation.
    (DOLFIN 2019's assemble() asks a precompiled Form for a _compiled_form attribute that Form never sets.)"""
    f = Form(form)
    f._compiled_form = True
    return f


class Timer:
    def __init__(self):
        self.t = {}

    def add(self, key, dt):
        self.t[key] = self.t.get(key, 0.0) + dt


class DirectSolver:
    """MUMPS through PETSc's KSP (preonly): Cholesky, positive definite unless told otherwise. The same object
    factors every matrix a problem hands it; a matrix reassembled in place (the same PETSc Mat, the same
    nonzero pattern) keeps its symbolic analysis: PCSetUp then refactors numerically only."""

    def __init__(self, spd=True):
        self.ksp = PETSc.KSP().create(PETSc.COMM_SELF)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("cholesky")
        pc.setFactorSolverType(LINEAR_SOLVER)
        self.spd = spd

    def solve(self, A, b, x, timer):
        """Factor A (timed as time_factor) and solve A x = b (time_solve_lin)."""
        M = as_backend_type(A).mat()
        M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        if self.spd:
            M.setOption(PETSc.Mat.Option.SPD, True)
        t0 = time.perf_counter()
        self.ksp.setOperators(M)
        self.ksp.getPC().setUp()  # the factorization (KSPSetUp alone would skip it for a refilled matrix)
        t1 = time.perf_counter()
        self.ksp.solve(as_backend_type(b).vec(), as_backend_type(x).vec())
        t2 = time.perf_counter()
        if self.ksp.getConvergedReason() < 0:
            raise RuntimeError("MUMPS solve failed: reason %d" % self.ksp.getConvergedReason())
        timer.add("time_factor", t1 - t0)
        timer.add("time_solve_lin", t2 - t1)
        return self


def spd_solve(A, b, x, timer):
    """One symmetric positive definite solve (DirectSolver)."""
    return DirectSolver().solve(A, b, x, timer)


# ---- Timoshenko cantilever (input/timoshenko.cfg) --------------------------------------------------------------

def timoshenko(variant, k, timer):
    L, D, E, nu, P = 48.0, 12.0, 3.0e7, 0.3, 1000.0
    I = D ** 3 / 12.0
    deg = int(variant[1:])
    t0 = time.perf_counter()
    mesh = RectangleMesh(Point(0.0, -D / 2), Point(L, D / 2), 4 * k, k)  # "right" diagonals
    t1 = time.perf_counter()
    V = VectorFunctionSpace(mesh, "P", deg)
    cst = dict(P=P, E=E, I=I, L=L, D=D, nu=nu, degree=4, domain=mesh)
    # the exact solution is a cubic: interpolated in degree 4 it is exact
    ue = Expression(("-P*x[1]/(6*E*I)*((6*L - 3*x[0])*x[0] + (2 + nu)*(x[1]*x[1] - D*D/4))",
                     "P/(6*E*I)*(3*nu*x[1]*x[1]*(L - x[0]) + (4 + 5*nu)*D*D*x[0]/4 + (3*L - x[0])*x[0]*x[0])"), **cst)
    tr_ = Expression(("0.0", "P/(2*I)*(D*D/4 - x[1]*x[1])"), P=P, I=I, D=D, degree=2)
    mu = E / (2 * (1 + nu))
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    lam_s = 2 * lam * mu / (lam + 2 * mu)  # plane stress

    def eps(w):
        return 0.5 * (grad(w) + grad(w).T)

    def sig(w):
        return lam_s * tr(eps(w)) * Identity(2) + 2 * mu * eps(w)

    right = MeshFunction("size_t", mesh, 1, 0)

    class Right(SubDomain):
        def inside(self, x, on):
            return on and near(x[0], L)
    Right().mark(right, 1)
    dsr = Measure("ds", domain=mesh, subdomain_data=right)
    u, v = TrialFunction(V), TestFunction(V)
    a = compiled(inner(sig(u), eps(v)) * dx)
    Lf = compiled(dot(tr_, v) * dsr(1))
    bc = DirichletBC(V, ue, lambda x, on: on and near(x[0], 0.0))
    uh = Function(V)
    e = uh - ue
    err_form = compiled(inner(sig(e), eps(e)) * dx(degree=2 * max(deg, 3)))
    ref_form = compiled(inner(sig(ue), eps(ue)) * dx(degree=6))
    t2 = time.perf_counter()
    A, b = assemble_system(a, Lf, bc)
    t3 = time.perf_counter()
    timer.add("time_assemble", t3 - t2)
    spd_solve(A, b, uh.vector(), timer)
    t4 = time.perf_counter()
    err = math.sqrt(abs(assemble(err_form)) / assemble(ref_form))
    tip = uh(Point(L, 0.0))[1]
    timer.add("time_post", time.perf_counter() - t4)
    timer.add("time_mesh", t1 - t0)
    timer.add("time_jit", t2 - t1)
    return dict(dofs=V.dim(), cells=mesh.num_cells(), error=err, qoi=tip, qoi_name="tip_uy")


# ---- Cook's membrane, Neo-Hooke (input/cook_neohooke.cfg) ------------------------------------------------------

def cook(variant, k, timer):
    deg = int(variant[1:])
    mu_, nu_ = 0.4225, 0.3
    E_ = 2 * mu_ * (1 + nu_)
    kap_ = E_ / (3 * (1 - 2 * nu_))
    t0 = time.perf_counter()
    n = k
    mesh = RectangleMesh(Point(0.0, 0.0), Point(1.0, 1.0), n, n)
    xy = mesh.coordinates()
    xi, eta = xy[:, 0].copy(), xy[:, 1].copy()
    v = np.array([[0.0, 0.0], [48.0, 44.0], [48.0, 60.0], [0.0, 44.0]])
    X = ((1 - xi) * (1 - eta))[:, None] * v[0] + (xi * (1 - eta))[:, None] * v[1] + \
        (xi * eta)[:, None] * v[2] + ((1 - xi) * eta)[:, None] * v[3]
    mesh.coordinates()[:] = X
    mesh.bounding_box_tree().build(mesh)
    t1 = time.perf_counter()
    V = VectorFunctionSpace(mesh, "P", deg)
    right = MeshFunction("size_t", mesh, 1, 0)

    class Right(SubDomain):
        def inside(self, x, on):
            return on and near(x[0], 48.0)
    Right().mark(right, 1)
    dsr = Measure("ds", domain=mesh, subdomain_data=right)
    u, du, w = Function(V), TrialFunction(V), TestFunction(V)
    load = Constant(0.0)
    F2 = Identity(2) + grad(u)
    F = as_matrix([[F2[0, 0], F2[0, 1], 0.0], [F2[1, 0], F2[1, 1], 0.0], [0.0, 0.0, 1.0]])  # plane strain
    J = det(F)
    I1 = tr(F.T * F)
    W = mu_ / 2 * (J ** (-2.0 / 3.0) * I1 - 3) + kap_ / 4 * (J ** 2 - 1 - 2 * ln(J))
    Pi = W * dx - load * dot(Constant((0.0, 1.0 / 16.0)), u) * dsr(1)
    R = derivative(Pi, u, w)
    K = derivative(R, u, du)
    Rf, Kf = compiled(R), compiled(K)
    bc = DirichletBC(V, Constant((0.0, 0.0)), lambda x, on: on and near(x[0], 0.0))
    t2 = time.perf_counter()
    iters = 0
    A, b = PETScMatrix(), PETScVector()
    solver = DirectSolver(spd=False)  # the Neo-Hooke tangent: symmetric, definiteness not assumed
    dx_ = Function(V)
    for step in range(1, 11):  # 10 load steps, Newton to |R| <= 1e-10 |R0| of the step (mica's default rtol)
        load.assign(step / 10.0)
        r0 = None
        for it in range(30):
            ta = time.perf_counter()
            assemble_system(Kf, Rf, bc, A_tensor=A, b_tensor=b)  # in place: the pattern and analysis reused
            tb = time.perf_counter()
            timer.add("time_assemble", tb - ta)
            rn = b.norm("l2")
            if r0 is None:
                r0 = rn
            if rn <= 1e-10 * r0 or rn == 0.0:
                break
            solver.solve(A, b, dx_.vector(), timer)
            u.vector().axpy(-1.0, dx_.vector())
            iters += 1
        else:
            raise RuntimeError("Newton did not converge")
    t3 = time.perf_counter()
    tip = u(Point(48.0, 60.0))[1]
    energy = assemble(W * dx)
    timer.add("time_post", time.perf_counter() - t3)
    timer.add("time_mesh", t1 - t0)
    timer.add("time_jit", t2 - t1)
    return dict(dofs=V.dim(), cells=mesh.num_cells(), qoi=tip, qoi_name="tip_uy", energy=energy,
                newton_iterations=iters)


# ---- Cosserat plate with a hole (input/cosserat_hole.cfg) ------------------------------------------------------

def graded_axis(n, ratio):
    """mica's graded layout (src/geom/layout.c): n points on [0, 1], last spacing / first = ratio."""
    q = ratio ** (1.0 / (n - 2)) if n > 2 else 1.0
    h = q ** np.arange(n - 1)
    t = np.concatenate([[0.0], np.cumsum(h)]) / h.sum()
    t[-1] = 1.0
    return t


def plate_hole_map(a, b, xi, eta):
    """mica's plate_hole map (src/geom/shapes.c): X = (1 − η) H(ξ) + η S(ξ)."""
    h = np.array([a * math.sin(0.5 * math.pi * (1 - xi)), a * math.sin(0.5 * math.pi * xi)])
    s = np.array([b, 2 * xi * b]) if xi <= 0.5 else np.array([(2 - 2 * xi) * b, b])
    return (1 - eta) * h + eta * s


def quadratic_quad_mesh(Xmap, txi, teta, fname):
    """Triangles with curved (quadratic) edges on a mapped grid: every cell of the (ξ, η) grid split in two,
    the edge nodes at the parameter midpoints mapped by Xmap, read back through XDMF as Triangle_6
    (DOLFIN wants vertex nodes first and each cell's vertices in increasing order)."""
    nx, ny = len(txi), len(teta)
    # parameter values on the doubled grid
    sx = np.empty(2 * nx - 1)
    sx[0::2] = txi
    sx[1::2] = 0.5 * (txi[1:] + txi[:-1])
    sy = np.empty(2 * ny - 1)
    sy[0::2] = teta
    sy[1::2] = 0.5 * (teta[1:] + teta[:-1])
    N1, N2 = len(sx), len(sy)
    num = -np.ones((N1, N2), dtype=np.int64)
    cnt = 0
    for j in range(0, N2, 2):
        for i in range(0, N1, 2):
            num[i, j] = cnt
            cnt += 1
    for j in range(N2):
        for i in range(N1):
            if num[i, j] < 0:
                num[i, j] = cnt
                cnt += 1
    pts = np.empty((cnt, 2))
    for j in range(N2):
        for i in range(N1):
            pts[num[i, j]] = Xmap(sx[i], sy[j])
    cells = []
    for j in range(0, N2 - 1, 2):
        for i in range(0, N1 - 1, 2):
            v00, v20, v02, v22 = num[i, j], num[i + 2, j], num[i, j + 2], num[i + 2, j + 2]
            cells.append([v00, v20, v22, num[i + 1, j], num[i + 2, j + 1], num[i + 1, j + 1]])
            cells.append([v00, v02, v22, num[i, j + 1], num[i + 1, j + 2], num[i + 1, j + 1]])
    cells = np.array(cells)
    with open(fname, "w") as f:
        f.write('<?xml version="1.0"?>\n<Xdmf Version="3.0"><Domain><Grid Name="mesh">'
                '<Topology TopologyType="Triangle_6" NumberOfElements="%d" NodesPerElement="6">'
                '<DataItem Format="XML" Dimensions="%d 6">%s</DataItem></Topology>'
                '<Geometry GeometryType="XY"><DataItem Format="XML" Dimensions="%d 2">%s</DataItem></Geometry>'
                '</Grid></Domain></Xdmf>\n' % (len(cells), len(cells), " ".join(map(str, cells.ravel())), cnt,
                                              " ".join("%.17g" % x for x in pts.ravel())))
    mesh = Mesh()
    XDMFFile(MPI.comm_self, fname).read(mesh)
    return mesh


COSSERAT = dict(a=1.0, a_over_l=1.063, N=0.93, G=1000.0, nu=0.3, p=1.0)


def cosserat_constants():
    """λ, μ, κ, γ of the hole deck's technical constants G, ν, N, l (as mica converts them), with a, b, p."""
    c = COSSERAT
    a, Nc, G, nu = c["a"], c["N"], c["G"], c["nu"]
    kap = 2 * G * Nc ** 2 / (1 - Nc ** 2)
    return dict(a=a, b=40 * a, p=c["p"], lam=2 * G * nu / (1 - 2 * nu), mu=G - kap / 2, kap=kap,
                gam=4 * G * (a / c["a_over_l"]) ** 2)


def cosserat_space(variant, k):
    """The hole's mesh (see cosserat) and the mixed space of a variant: (mesh, V, degree of u, of φ)."""
    du, dp = int(variant[1]), int(variant[3])
    angular = 2 * k if variant.endswith("r") else 4 * k  # "r": half the cells along the hole (mica's nitsche-q8r)
    a, b = COSSERAT["a"], 40 * COSSERAT["a"]
    fname = os.path.join(os.environ.get("PEERS_TMP", "/tmp"), "peers_hole_%d_%d.xdmf" % (k, os.getpid()))
    mesh = quadratic_quad_mesh(lambda s, t: plate_hole_map(a, b, s, t), np.linspace(0, 1, angular + 1),
                               graded_axis(3 * k + 1, 40.0), fname)
    os.remove(fname)
    el = MixedElement([VectorElement("P", mesh.ufl_cell(), du), FiniteElement("P", mesh.ufl_cell(), dp)])
    return mesh, FunctionSpace(mesh, el), du, dp


def cosserat(variant, k, timer):
    """Plane-strain Cosserat, unknowns (u1, u2, φ3), the constitutive law of docs/theory.md:
    ε_kl = u_l,k + e_lkm φ_m, σ_kl = λ ε_rr δ_kl + (μ + κ) ε_kl + μ ε_lk, in-plane m = γ ∇φ3,
    W = ½ σ:ε + ½ γ |∇φ3|²; technical constants G, ν, N, l as mica converts them.
    Mesh: mica's plate_hole map and graded layout (ratio 40 outwards) on a (4k) × (3k) grid of cells (mica's
    k of peers.py has (8k) × (6k): FEniCS k = 2 is mica's grid; variants ending in r: (2k) × (3k)), each split
    into two triangles with quadratic (curved) edges.
    With PEERS_SAVE_SOLUTION set, the solution's coefficient vector is saved there (numpy .npy) for
    energy_norm.py, which rebuilds the same space with cosserat_space."""
    cc = cosserat_constants()
    a, b, p, G = cc["a"], cc["b"], cc["p"], COSSERAT["G"]
    lam, mu, kap, gam = cc["lam"], cc["mu"], cc["kap"], cc["gam"]
    t0 = time.perf_counter()
    mesh, V, du, dp = cosserat_space(variant, k)
    t1 = time.perf_counter()

    def strain(w):
        uu, ph = split(w)
        return grad(uu).T + as_matrix([[0.0, -ph], [ph, 0.0]])  # ε_kl = u_l,k + e_lkm φ_m

    def stress(e):
        return lam * tr(e) * Identity(2) + (mu + kap) * e + mu * e.T

    def energy_density(w):
        e = strain(w)
        return 0.5 * inner(stress(e), e) + 0.5 * gam * dot(grad(split(w)[1]), grad(split(w)[1]))

    right = MeshFunction("size_t", mesh, 1, 0)

    class Right(SubDomain):
        def inside(self, x, on):
            return on and near(x[0], b)
    Right().mark(right, 1)
    dsr = Measure("ds", domain=mesh, subdomain_data=right)
    w, z = TrialFunction(V), TestFunction(V)
    aform = compiled((inner(stress(strain(w)), strain(z)) + gam * dot(grad(split(w)[1]), grad(split(z)[1]))) * dx)
    Lform = compiled(p * split(z)[0][0] * dsr(1))
    left = lambda x, on: on and near(x[0], 0.0)
    bottom = lambda x, on: on and near(x[1], 0.0)
    bcs = [DirichletBC(V.sub(0).sub(0), Constant(0.0), left), DirichletBC(V.sub(1), Constant(0.0), left),
           DirichletBC(V.sub(0).sub(1), Constant(0.0), bottom), DirichletBC(V.sub(1), Constant(0.0), bottom)]
    wh = Function(V)
    Uform = compiled(energy_density(wh) * dx)
    t2 = time.perf_counter()
    A, bb = assemble_system(aform, Lform, bcs)
    t3 = time.perf_counter()
    timer.add("time_assemble", t3 - t2)
    spd_solve(A, bb, wh.vector(), timer)
    t4 = time.perf_counter()
    U = assemble(Uform)
    if os.environ.get("PEERS_SAVE_SOLUTION"):
        np.save(os.environ["PEERS_SAVE_SOLUTION"], wh.vector().get_local())
    # σ_11 at (0, a) from the cell that holds the point: σ_11 = λ (u1,1 + u2,2) + 2G u1,1
    uh = wh.split(deepcopy=True)[0]
    Vg = FunctionSpace(mesh, "DG", du - 1)
    from dolfin import project
    s11 = project(lam * (uh[0].dx(0) + uh[1].dx(1)) + 2 * G * uh[0].dx(0), Vg, solver_type="mumps")
    s11.set_allow_extrapolation(True)  # the point lies on the curved edge; the affine cell search may miss it
    scf = s11(Point(0.0, a * (1 + 1e-10))) / p
    timer.add("time_post", time.perf_counter() - t4)
    timer.add("time_mesh", t1 - t0)
    timer.add("time_jit", t2 - t1)
    return dict(dofs=V.dim(), cells=mesh.num_cells(), qoi=U, qoi_name="strain_energy", scf=scf)


# ---- 3-D cantilever block (bench/peers/block3d.cfg) ------------------------------------------------------------

BLOCK = dict(L=4.0, B=1.0, H=1.0, E=1000.0, nu=0.3, q=1.0)


def block3d(variant, k, timer):
    """Block [0, L] × [0, B] × [0, H] clamped on x = 0, uniform shear traction t_z = −q on x = L."""
    deg = int(variant[1:])
    L, B, H, E, nu, q = (BLOCK[s] for s in ("L", "B", "H", "E", "nu", "q"))
    t0 = time.perf_counter()
    mesh = BoxMesh(Point(0, 0, 0), Point(L, B, H), 4 * k, k, k)
    t1 = time.perf_counter()
    V = VectorFunctionSpace(mesh, "P", deg)
    mu = E / (2 * (1 + nu))
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))

    def eps(w):
        return 0.5 * (grad(w) + grad(w).T)

    def sig(w):
        return lam * tr(eps(w)) * Identity(3) + 2 * mu * eps(w)
    right = MeshFunction("size_t", mesh, 2, 0)

    class Right(SubDomain):
        def inside(self, x, on):
            return on and near(x[0], L)
    Right().mark(right, 1)
    dsr = Measure("ds", domain=mesh, subdomain_data=right)
    u, v = TrialFunction(V), TestFunction(V)
    a = compiled(inner(sig(u), eps(v)) * dx)
    Lf = compiled(dot(Constant((0.0, 0.0, -q)), v) * dsr(1))
    bc = DirichletBC(V, Constant((0.0, 0.0, 0.0)), lambda x, on: on and near(x[0], 0.0))
    uh = Function(V)
    Uform = compiled(0.5 * inner(sig(uh), eps(uh)) * dx)
    t2 = time.perf_counter()
    A, b = assemble_system(a, Lf, bc)
    t3 = time.perf_counter()
    timer.add("time_assemble", t3 - t2)
    spd_solve(A, b, uh.vector(), timer)
    t4 = time.perf_counter()
    U = assemble(Uform)
    tip = uh(Point(L, B / 2, H / 2))[2]
    timer.add("time_post", time.perf_counter() - t4)
    timer.add("time_mesh", t1 - t0)
    timer.add("time_jit", t2 - t1)
    return dict(dofs=V.dim(), cells=mesh.num_cells(), qoi=U, qoi_name="strain_energy", tip_uz=tip)


# ---- manufactured fields (input/manufactured.cfg, input/manufactured3d.cfg) -------------------------------------

MANUFACTURED = dict(E=100.0, nu=0.3)


def manufactured(dim, variant, k, timer):
    """Linear elasticity on [−1, 1]^dim (plane strain in 2-D), u_i = sin(π x_i / 2) Π_{j≠i} cos(π x_j / 2), the
    body force b = (dim π² / 4)(λ + 2μ) u that makes it exact (−μ Δu − (λ + μ) ∇(∇·u), both dim π²/4 u), Dirichlet
    u on the whole boundary; a k^dim grid of cells (each split into triangles / tetrahedra). The relative
    energy-norm error against the exact field: its expression interpolated at degree + 3, the error form
    integrated at 2 (degree + 3)."""
    deg = int(variant[1:])
    E, nu = MANUFACTURED["E"], MANUFACTURED["nu"]
    mu = E / (2 * (1 + nu))
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    t0 = time.perf_counter()
    if dim == 2:
        mesh = RectangleMesh(Point(-1.0, -1.0), Point(1.0, 1.0), k, k)
        comps = ("sin(pi*x[0]/2)*cos(pi*x[1]/2)", "cos(pi*x[0]/2)*sin(pi*x[1]/2)")
    else:
        mesh = BoxMesh(Point(-1.0, -1.0, -1.0), Point(1.0, 1.0, 1.0), k, k, k)
        comps = ("sin(pi*x[0]/2)*cos(pi*x[1]/2)*cos(pi*x[2]/2)", "cos(pi*x[0]/2)*sin(pi*x[1]/2)*cos(pi*x[2]/2)",
                 "cos(pi*x[0]/2)*cos(pi*x[1]/2)*sin(pi*x[2]/2)")
    t1 = time.perf_counter()
    V = VectorFunctionSpace(mesh, "P", deg)
    ue = Expression(comps, degree=deg + 3, domain=mesh)
    f = Expression(tuple("%.17g*(%s)" % (dim * math.pi ** 2 / 4 * (lam + 2 * mu), c) for c in comps),
                   degree=deg + 3, domain=mesh)

    def eps(w):
        return 0.5 * (grad(w) + grad(w).T)

    def sig(w):
        return lam * tr(eps(w)) * Identity(dim) + 2 * mu * eps(w)
    u, v = TrialFunction(V), TestFunction(V)
    a = compiled(inner(sig(u), eps(v)) * dx)
    Lf = compiled(dot(f, v) * dx)
    bc = DirichletBC(V, ue, lambda x, on: on)
    uh = Function(V)
    e = uh - ue
    err_form = compiled(inner(sig(e), eps(e)) * dx(degree=2 * (deg + 3)))
    ref_form = compiled(inner(sig(ue), eps(ue)) * dx(degree=2 * (deg + 3)))
    t2 = time.perf_counter()
    A, b = assemble_system(a, Lf, bc)
    t3 = time.perf_counter()
    timer.add("time_assemble", t3 - t2)
    spd_solve(A, b, uh.vector(), timer)
    t4 = time.perf_counter()
    err = math.sqrt(abs(assemble(err_form)) / assemble(ref_form))
    timer.add("time_post", time.perf_counter() - t4)
    timer.add("time_mesh", t1 - t0)
    timer.add("time_jit", t2 - t1)
    return dict(dofs=V.dim(), cells=mesh.num_cells(), error=err, qoi=err, qoi_name="error_energy")


PROBLEMS = dict(timoshenko=timoshenko, cook=cook, cosserat=cosserat, block3d=block3d,
                manufactured2d=lambda v, k, t: manufactured(2, v, k, t),
                manufactured3d=lambda v, k, t: manufactured(3, v, k, t))


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in PROBLEMS:
        sys.exit(__doc__)
    problem, variant, k = sys.argv[1], sys.argv[2], int(sys.argv[3])
    timer = Timer()
    out = PROBLEMS[problem](variant, k, timer)
    t = timer.t
    t.setdefault("time_factor", 0.0)
    t.setdefault("time_solve_lin", 0.0)
    t["time_solve"] = t.get("time_assemble", 0.0) + t["time_factor"] + t["time_solve_lin"]
    t["time_import"] = T_IMPORT
    t["time_script"] = time.perf_counter() - T_START
    out.update(t)
    out.update(problem=problem, variant=variant, k=k, linear_solver=LINEAR_SOLVER)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
