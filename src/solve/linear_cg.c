/* solver.linear = "cg": preconditioned conjugate gradients for symmetric positive definite tangents.
 *
 * Why: a Cholesky factor of a 3-D MLS tangent fills in far beyond the matrix (nnz(L) grows as n^(4/3) with a
 * nested-dissection ordering, from ~1000 couplings per row), so at 10⁶ dofs it does not fit in memory; CG
 * needs the matrix, five n-vectors and the preconditioner (ndof² doubles per node).
 *
 * The matrix is the full symmetric CSC of sparse.h. Because A = Aᵀ, column j is also row j, so the product
 * y_j = Σ_i A_ij x_i reads each column as a row: no scattered writes, and the dot product pᵀAp comes out of
 * the same pass. The preconditioners act on the ndof × ndof diagonal blocks of the nodes (the couplings of
 * one particle's displacement components), factored once per "factor" call:
 *   jacobi - z_J = D_J⁻¹ r_J;
 *   sgs    - symmetric block Gauss–Seidel, M = (D + L) D⁻¹ (D + U): a forward sweep (D + L) y = r and a
 *            backward sweep (D + U) z = D y, each one pass over the matrix. M is symmetric positive definite
 *            when A is, so CG may use it; it typically needs 2–3× fewer iterations than Jacobi for ≈ 3× the
 *            matrix traffic per iteration (docs/performance.md has the measured trade).
 * Stopping: the recursive residual |r| ≤ rtol |b|; the true residual |b − A x| / |b| is computed once at
 * the end and reported. A zero right-hand side gives x = 0 at once. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/sparse.h"
#include "mica/timer.h"

typedef struct {
  const MicaSparse *A; /* the matrix of the last factor call (borrowed) */
  long nblocks;        /* nodes: n / ndof */
  int ndof;
  double *dinv;        /* [nblocks][ndof][ndof]: D_J⁻¹, symmetric */
  long *diag;          /* [n]: position of the first row of column j's diagonal block */
  double *r, *z, *p, *q; /* work vectors [n] */
} Cg;

static int cg_create(MicaLinearSolver *solver) {
  Cg *cg = NULL;
  MICA_CALL(MICA_CALLOC(cg, 1));
  solver->data = cg;
  return MICA_SUCCESS;
}

static void cg_free_arrays(Cg *cg) {
  free(cg->dinv), free(cg->diag), free(cg->r), free(cg->z), free(cg->p), free(cg->q);
  cg->dinv = NULL, cg->diag = NULL, cg->r = cg->z = cg->p = cg->q = NULL;
}

static void cg_destroy(MicaLinearSolver *solver) {
  Cg *cg = solver->data;
  if (!cg) return;
  cg_free_arrays(cg);
  free(cg);
  solver->data = NULL;
}

static int cg_allocate(Cg *cg, const MicaSparse *A) {
  cg_free_arrays(cg);
  const long n = A->n;
  cg->ndof = A->ndof;
  cg->nblocks = n / A->ndof;
  MICA_CALL(MICA_MALLOC(cg->dinv, cg->nblocks * A->ndof * A->ndof));
  MICA_CALL(MICA_MALLOC(cg->diag, n));
  MICA_CALL(MICA_MALLOC(cg->r, n));
  MICA_CALL(MICA_MALLOC(cg->z, n));
  MICA_CALL(MICA_MALLOC(cg->p, n));
  MICA_CALL(MICA_MALLOC(cg->q, n));
  return MICA_SUCCESS;
}

/* In place: the inverse of a small symmetric positive definite matrix (Cholesky, then L⁻ᵀ L⁻¹).
 * Returns 0 if it is not positive definite. */
static int invert_spd(int m, double *a) {
  double l[8][8] = {{0}}, li[8][8] = {{0}};
  for (int j = 0; j < m; j++) {
    double d = a[j * m + j];
    for (int k = 0; k < j; k++) d -= l[j][k] * l[j][k];
    if (!(d > 0)) return 0;
    l[j][j] = sqrt(d);
    for (int i = j + 1; i < m; i++) {
      double s = a[i * m + j];
      for (int k = 0; k < j; k++) s -= l[i][k] * l[j][k];
      l[i][j] = s / l[j][j];
    }
  }
  for (int j = 0; j < m; j++) { /* L⁻¹, lower triangular */
    li[j][j] = 1.0 / l[j][j];
    for (int i = j + 1; i < m; i++) {
      double s = 0;
      for (int k = j; k < i; k++) s -= l[i][k] * li[k][j];
      li[i][j] = s / l[i][i];
    }
  }
  for (int i = 0; i < m; i++)
    for (int j = 0; j < m; j++) {
      double s = 0;
      for (int k = i > j ? i : j; k < m; k++) s += li[k][i] * li[k][j];
      a[i * m + j] = s;
    }
  return 1;
}

/* The diagonal blocks: positions and inverses. */
static int cg_factor(MicaLinearSolver *solver, const MicaSparse *A) {
  Cg *cg = solver->data;
  MICA_CHECK(A->ndof >= 1 && A->ndof <= 8 && A->n % A->ndof == 0, MICA_ERR_ARGUMENT,
             "cg: %d unknowns per node (1 to 8 supported)", A->ndof);
  if (cg->A != A || !cg->dinv || cg->nblocks * cg->ndof != A->n) MICA_CALL(cg_allocate(cg, A));
  cg->A = A;
  const int m = A->ndof;
  for (long J = 0; J < cg->nblocks; J++) {
    double *block = cg->dinv + J * m * m;
    const long first = J * m;
    for (int b = 0; b < m; b++) {
      const long j = first + b;
      long pos = A->colptr[j];
      while (pos < A->colptr[j + 1] && A->rowind[pos] < first) pos++;
      MICA_CHECK(pos + m <= A->colptr[j + 1] && A->rowind[pos] == first && A->rowind[pos + m - 1] == first + m - 1,
                 MICA_ERR_ARGUMENT, "cg: the diagonal block of node %ld is not in the pattern", J);
      cg->diag[j] = pos;
      for (int a = 0; a < m; a++) block[a * m + b] = A->val[pos + a];
    }
    if (!invert_spd(m, block))
      MICA_ERROR(MICA_ERR_NUMERIC,
                 "cg: the tangent is not positive definite (the diagonal block of node %ld is not); use "
                 "solver.linear = \"umfpack\"",
                 J);
  }
  return MICA_SUCCESS;
}

/* ---- the operators ---------------------------------------------------------------------------------------- */

/* y = A x (A symmetric: column j read as row j); returns xᵀ A x. */
static double matvec(const MicaSparse *A, const double *x, double *y) {
  double xax = 0;
  for (long j = 0; j < A->n; j++) {
    double s = 0;
    for (long p = A->colptr[j]; p < A->colptr[j + 1]; p++) s += A->val[p] * x[A->rowind[p]];
    y[j] = s;
    xax += s * x[j];
  }
  return xax;
}

static void block_apply(int m, const double *dinv, const double *s, double *out) {
  for (int a = 0; a < m; a++) {
    double t = 0;
    for (int b = 0; b < m; b++) t += dinv[a * m + b] * s[b];
    out[a] = t;
  }
}

static void jacobi(const Cg *cg, const double *r, double *z) {
  const int m = cg->ndof;
  for (long J = 0; J < cg->nblocks; J++) block_apply(m, cg->dinv + J * m * m, r + J * m, z + J * m);
}

/* z = M⁻¹ r, M = (D + L) D⁻¹ (D + U). Forward: y_J = D_J⁻¹ (r_J − Σ_{i before J} A_Ji y_i), into z. Then
 * backward: z_J = D_J⁻¹ (D_J y_J − Σ_{i after J} A_Ji z_i) = y_J − D_J⁻¹ Σ_{i after J} A_Ji z_i. */
static void sgs(const Cg *cg, const double *r, double *z) {
  const MicaSparse *A = cg->A;
  const int m = cg->ndof;
  double s[8], t[8];
  for (long J = 0; J < cg->nblocks; J++) {
    for (int a = 0; a < m; a++) {
      const long j = J * m + a;
      double v = r[j];
      for (long p = A->colptr[j]; p < cg->diag[j]; p++) v -= A->val[p] * z[A->rowind[p]];
      s[a] = v;
    }
    block_apply(m, cg->dinv + J * m * m, s, z + J * m);
  }
  for (long J = cg->nblocks - 1; J >= 0; J--) {
    for (int a = 0; a < m; a++) {
      const long j = J * m + a;
      double v = 0;
      for (long p = cg->diag[j] + m; p < A->colptr[j + 1]; p++) v += A->val[p] * z[A->rowind[p]];
      s[a] = v;
    }
    block_apply(m, cg->dinv + J * m * m, s, t);
    for (int a = 0; a < m; a++) z[J * m + a] -= t[a];
  }
}

static void precondition(const Cg *cg, MicaPreconditioner kind, const double *r, double *z) {
  if (kind == MICA_PRECONDITIONER_SGS) sgs(cg, r, z);
  else jacobi(cg, r, z);
}

static double dot(long n, const double *a, const double *b) {
  double s = 0;
  for (long i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

/* ---- CG ----------------------------------------------------------------------------------------------------- */

static const char *preconditioner_name(MicaPreconditioner kind) {
  return kind == MICA_PRECONDITIONER_SGS ? "sgs" : "jacobi";
}

/* x from 0 until |r| ≤ rtol |b|; *iterations done. MICA_ERR_NUMERIC on pᵀAp ≤ 0 or no convergence. */
static int pcg(Cg *cg, const MicaKrylovOptions *opt, const double *b, double bnorm, double *x, int *iterations) {
  const double tol = opt->rtol * bnorm;
  const int max_it = opt->max_iterations;
  const MicaSparse *A = cg->A;
  const long n = A->n;
  double *r = cg->r, *z = cg->z, *p = cg->p, *q = cg->q;
  memset(x, 0, sizeof(double) * (size_t)n);
  memcpy(r, b, sizeof(double) * (size_t)n);
  double rnorm = sqrt(dot(n, r, r));
  *iterations = 0;
  if (rnorm <= tol) return MICA_SUCCESS;
  precondition(cg, opt->preconditioner, r, z);
  memcpy(p, z, sizeof(double) * (size_t)n);
  double rz = dot(n, r, z);
  for (int it = 1; it <= max_it; it++) {
    const double pq = matvec(A, p, q);
    if (!(pq > 0))
      MICA_ERROR(MICA_ERR_NUMERIC, "cg: the tangent is not positive definite (pᵀAp = %g at iteration %d); use "
                 "solver.linear = \"umfpack\"", pq, it);
    const double alpha = rz / pq;
    double rr = 0;
    for (long i = 0; i < n; i++) {
      x[i] += alpha * p[i];
      r[i] -= alpha * q[i];
      rr += r[i] * r[i];
    }
    rnorm = sqrt(rr);
    *iterations = it;
    if (rnorm <= tol) return MICA_SUCCESS;
    precondition(cg, opt->preconditioner, r, z);
    const double rz_new = dot(n, r, z), beta = rz_new / rz;
    rz = rz_new;
    for (long i = 0; i < n; i++) p[i] = z[i] + beta * p[i];
  }
  MICA_ERROR(MICA_ERR_NUMERIC,
             "cg (%s) did not converge in %d iterations (|r| / |b| %.3e, wanted %.3e); raise "
             "solver.linear_max_iterations or use solver.preconditioner = \"sgs\"",
             preconditioner_name(opt->preconditioner), max_it, rnorm / bnorm, opt->rtol);
}

static int cg_solve(MicaLinearSolver *solver, const double *b, double *x) {
  Cg *cg = solver->data;
  MICA_CHECK(cg->A, MICA_ERR_ARGUMENT, "cg: solve before factor");
  MicaKrylovOptions opt = solver->krylov;
  if (!(opt.rtol > 0)) opt.rtol = 1e-10;
  if (opt.max_iterations <= 0) opt.max_iterations = 10000;
  const long n = cg->A->n;
  const double bnorm = sqrt(dot(n, b, b)), start = mica_wtime(), cpu = mica_cputime();
  int iterations = 0;
  MICA_CALL(pcg(cg, &opt, b, bnorm, x, &iterations));
  matvec(cg->A, x, cg->q); /* the true residual, once */
  double rr = 0;
  for (long i = 0; i < n; i++) rr += (b[i] - cg->q[i]) * (b[i] - cg->q[i]);
  const double relative = bnorm > 0 ? sqrt(rr) / bnorm : 0;
  MicaLinearSolverStats *st = &solver->stats;
  st->krylov_iterations += iterations;
  if (iterations > st->krylov_iterations_max) st->krylov_iterations_max = iterations;
  st->krylov_residual = relative;
  st->krylov_cpu += mica_cputime() - cpu;
  if (opt.verbose)
    printf("    cg (%s): %d iterations, |b - Ax| / |b| %.3e (rtol %.1e), %.3g s (CPU %.3g s)\n",
           preconditioner_name(opt.preconditioner), iterations, relative, opt.rtol, mica_wtime() - start,
           mica_cputime() - cpu);
  return MICA_SUCCESS;
}

/* cg's own setting: solver.preconditioner (solver.linear_rtol and .linear_max_iterations serve Schwarz too). */
static const MicaDeckKey cg_keys[] = {
    {.path = "preconditioner", .type = MICA_KEY_CHOICE, .def = "\"jacobi\"", .min = 1.0, .max = 0.0,
     .choices = "jacobi|sgs",
     .help = "block Jacobi on each particle's unknowns, or symmetric block Gauss–Seidel (fewer iterations, 3 "
             "matrix passes each)"},
    {0},
};

static int cg_from_settings(const MicaType *type, const MicaSettings *settings, const char *group, void *options) {
  (void)type;
  const char *name;
  MICA_CALL(mica_settings_string(settings, group, "preconditioner", &name));
  ((MicaKrylovOptions *)options)->preconditioner =
      strcmp(name, "sgs") ? MICA_PRECONDITIONER_JACOBI : MICA_PRECONDITIONER_SGS;
  return MICA_SUCCESS;
}

const MicaLinearSolverOps mica_linear_cg = {
    {"cg", "preconditioned conjugate gradients (symmetric positive definite, no factorization)",
     MICA_LINEAR_SPD_ONLY | MICA_LINEAR_ITERATIVE, cg_keys, cg_from_settings},
    cg_create, cg_factor, cg_solve, cg_destroy};
