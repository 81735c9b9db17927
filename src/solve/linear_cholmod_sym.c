/* "cholmod-sym": an unsymmetric matrix A whose symmetric part S = (A + Aᵀ)/2 is positive definite and dominates
 * its skew part W = (A − Aᵀ)/2 (VCI's Petrov–Galerkin tangent: A = K + a small correction), solved by CHOLMOD on
 * S and refinement (preconditioned Richardson):
 *   x₀ = S⁻¹ b,   x_{k+1} = x_k + S⁻¹ (b − A x_k).
 * The error contracts by I − S⁻¹A = −S⁻¹W, whose eigenvalues are imaginary (S SPD, W skew), ±iθ: it converges
 * when max θ < 1, at the rate max θ per iteration (docs/theory.md §VCI, "A CHOLMOD solve"). One CHOLMOD
 * factorization (about a third of UMFPACK's LU time on these matrices, half its entries) and a few triangular
 * solves and matrix–vector products per solve. The pattern must be symmetric (the solid's is); S shares A's
 * pattern, the values of its upper triangle (all CHOLMOD reads) are refreshed at each factorization through the
 * transposed positions, found once per pattern. Refines until |b − A x| ≤ rtol |b| (solver.linear_rtol) and then on while the residual still halves,
 * to round-off as a direct solver would (the patch tests ask 1e-10 of the solution); a solve that does not get
 * to rtol in solver.linear_max_iterations iterations, or stops contracting before, is an error naming UMFPACK. The iterations are
 * reported as krylov_iterations (flag MICA_LINEAR_REFINES). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linear_private.h"
#include "mica/timer.h"

enum { SYM_DEFAULT_MAX_ITERATIONS = 100 }; /* when the caller set no Krylov options */
static const double SYM_DEFAULT_RTOL = 1e-12;

typedef struct {
  MicaLinearSolver cholesky; /* CHOLMOD on S */
  MicaSparse S;              /* A's pattern (borrowed), its own values */
  long *transposed;          /* [nnz] position of A_ji for the entry A_ij, i ≤ j (the rest unset) */
  MicaPatternKey pattern;    /* of the A `transposed` belongs to */
  const MicaSparse *A;       /* the matrix last factored (the caller keeps it until the solves) */
  double *r, *dx;            /* [n] residual and correction */
} SymData;

static int sym_create(MicaLinearSolver *solver) {
  SymData *data = NULL;
  MICA_CALL(MICA_CALLOC(data, 1));
  data->cholesky.ops = &mica_linear_cholmod;
  int ierr = mica_linear_cholmod.create(&data->cholesky);
  if (ierr) {
    MICA_FREE(data);
    return ierr;
  }
  solver->data = data;
  return MICA_SUCCESS;
}

/* transposed[e] for every entry e of the upper triangle: walking the columns in order, the entries (j, i) of
 * column i are met in ascending j, which is the order of column i's rows, so a cursor per column finds each
 * mirror in one pass (O(nnz); the binary search per entry it replaced took 0.5 s on a 6591-unknown cube's
 * 8.9·10⁶ entries). An entry whose mirror is not where the cursor stands has none: the pattern is not symmetric. */
static int find_transposed(const MicaSparse *A, long *transposed) {
  long *cursor = NULL;
  MICA_CALL(MICA_MALLOC(cursor, A->n));
  memcpy(cursor, A->colptr, (size_t)A->n * sizeof *cursor);
  for (long j = 0; j < A->n; j++)
    for (long e = A->colptr[j]; e < A->colptr[j + 1]; e++) {
      const long i = A->rowind[e], mirror = cursor[i]++;
      if (mirror >= A->colptr[i + 1] || A->rowind[mirror] != j) {
        free(cursor);
        MICA_ERROR(MICA_ERR_ARGUMENT, "cholmod-sym: the pattern is not symmetric (entry %ld, %ld has no mirror)", i, j);
      }
      if (i <= j) transposed[e] = mirror; /* sym_factor reads the upper triangle's only */
    }
  free(cursor);
  return MICA_SUCCESS;
}

/* S's storage and the transposed positions for A's pattern, when it is new. */
static int prepare_pattern(SymData *data, const MicaSparse *A) {
  const MicaPatternKey key = mica_pattern_key(A);
  if (data->transposed && mica_pattern_key_equal(key, data->pattern)) return MICA_SUCCESS;
  MICA_FREE(data->transposed);
  MICA_FREE(data->S.val);
  MICA_FREE(data->r);
  MICA_FREE(data->dx);
  MICA_CALL(MICA_MALLOC(data->transposed, A->nnz));
  MICA_CALL(MICA_MALLOC(data->S.val, A->nnz));
  MICA_CALL(MICA_MALLOC(data->r, A->n));
  MICA_CALL(MICA_MALLOC(data->dx, A->n));
  MICA_CALL(find_transposed(A, data->transposed));
  data->pattern = key;
  return MICA_SUCCESS;
}

static int sym_factor(MicaLinearSolver *solver, const MicaSparse *A) {
  SymData *data = solver->data;
  data->A = NULL;
  MICA_CALL(prepare_pattern(data, A));
  double *val = data->S.val;
  data->S.n = A->n, data->S.nnz = A->nnz, data->S.ndof = A->ndof;
  data->S.colptr = A->colptr, data->S.rowind = A->rowind;
  /* the upper triangle only: CHOLMOD reads no other entry of S (stype = 1), and the lower half of S.val is never
   * touched (half the gathers, half the fresh pages) */
  for (long j = 0; j < A->n; j++)
    for (long e = A->colptr[j]; e < A->colptr[j + 1] && A->rowind[e] <= j; e++)
      val[e] = 0.5 * (A->val[e] + A->val[data->transposed[e]]);
  int ierr = mica_linear_cholmod.factor(&data->cholesky, &data->S);
  if (ierr) {
    mica_error_prefix("cholmod-sym: the symmetric part of the matrix");
    return ierr;
  }
  solver->stats.nnz_factor = data->cholesky.stats.nnz_factor;
  solver->stats.flops = data->cholesky.stats.flops;
  solver->stats.analyses = data->cholesky.stats.analyses;
  solver->stats.time_analyze = data->cholesky.stats.time_analyze;
  solver->stats.ordering = data->cholesky.stats.ordering;
  data->A = A;
  return MICA_SUCCESS;
}

static double norm2(long n, const double *v) {
  double s = 0;
  for (long i = 0; i < n; i++) s += v[i] * v[i];
  return sqrt(s);
}

/* r = b − A x; returns |r|. */
static double residual(const MicaSparse *A, const double *b, const double *x, double *r) {
  mica_sparse_matvec(A, x, r);
  for (long i = 0; i < A->n; i++) r[i] = b[i] - r[i];
  return norm2(A->n, r);
}

static int sym_solve(MicaLinearSolver *solver, const double *b, double *x) {
  SymData *data = solver->data;
  MICA_CHECK(data->A, MICA_ERR_ARGUMENT, "cholmod-sym solve: no successful factorization to solve with");
  const MicaSparse *A = data->A;
  const double rtol = solver->krylov.rtol > 0 ? solver->krylov.rtol : SYM_DEFAULT_RTOL;
  const int most = solver->krylov.max_iterations > 0 ? solver->krylov.max_iterations : SYM_DEFAULT_MAX_ITERATIONS;
  const double bnorm = norm2(A->n, b), cpu = mica_cputime();
  MICA_CALL(mica_linear_cholmod.solve(&data->cholesky, b, x));
  double rnorm = residual(A, b, x, data->r), last = INFINITY;
  int k = 0;
  for (;;) { /* a direct solver's accuracy: on below rtol while the residual still halves (to round-off) */
    const int reached = rnorm <= rtol * bnorm;
    if (bnorm == 0 || rnorm == 0 || (reached && !(rnorm < 0.5 * last)) || (reached && k >= most)) break;
    MICA_CHECK(reached || (k < most && rnorm < last), MICA_ERR_NUMERIC,
               "cholmod-sym: the refinement %s after %d iterations (|b - A x| / |b| = %.3e, asked %.1e): the skew "
               "part of the matrix is too large against its symmetric part; use solver.linear = \"umfpack\"",
               k < most ? "stopped contracting" : "did not converge", k, rnorm / bnorm, rtol);
    MICA_CALL(mica_linear_cholmod.solve(&data->cholesky, data->r, data->dx));
    for (long i = 0; i < A->n; i++) x[i] += data->dx[i];
    last = rnorm;
    rnorm = residual(A, b, x, data->r);
    k++;
  }
  solver->stats.krylov_iterations += k;
  if (k > solver->stats.krylov_iterations_max) solver->stats.krylov_iterations_max = k;
  solver->stats.krylov_residual = bnorm > 0 ? rnorm / bnorm : 0;
  solver->stats.krylov_cpu += mica_cputime() - cpu;
  return MICA_SUCCESS;
}

static void sym_destroy(MicaLinearSolver *solver) {
  SymData *data = solver->data;
  if (!data) return;
  mica_linear_cholmod.destroy(&data->cholesky);
  MICA_FREE(data->transposed);
  MICA_FREE(data->S.val);
  MICA_FREE(data->r);
  MICA_FREE(data->dx);
  MICA_FREE(data);
  solver->data = NULL;
}

const MicaLinearSolverOps mica_linear_cholmod_sym = {
    {"cholmod-sym", "CHOLMOD on the symmetric part and refinement: unsymmetric matrices close to symmetric "
                    "positive definite (VCI's tangent with nitsche or penalty)", MICA_LINEAR_REFINES, NULL, NULL},
    sym_create, sym_factor, sym_solve, sym_destroy};
