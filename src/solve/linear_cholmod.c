/* CHOLMOD supernodal Cholesky (cholmod_l_*, 64-bit indices) for symmetric positive definite matrices.
 *
 * The MicaSparse arrays are lent to CHOLMOD as a packed, sorted cholmod_sparse with stype = 1 (only the
 * upper triangle is read), so nothing is copied. The symbolic factor (fill-reducing ordering, supernodes)
 * comes from the first factorization and is reused while the pattern is unchanged (linear_private.h):
 * Newton iterations and load steps pay only for cholmod_l_factorize. CHOLMOD prints nothing (print = 0);
 * its status is turned into mica errors here.
 */
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

#include "linear_private.h"
#include "mica/timer.h"

typedef struct {
  cholmod_common common;
  cholmod_factor *L;      /* symbolic, then numeric factor; NULL before the first analysis */
  MicaPatternKey pattern; /* of the matrix L was analyzed for */
  double analysis_flops;  /* Common->fl of that analysis: the flops of one factorization */
  int factored;           /* L holds a complete factorization that solve may use */
} CholmodData;

/* The caller's matrix as a cholmod_sparse that borrows its arrays (CHOLMOD only reads them). */
static cholmod_sparse borrow_matrix(const MicaSparse *A) {
  cholmod_sparse view;
  memset(&view, 0, sizeof view);
  view.nrow = (size_t)A->n;
  view.ncol = (size_t)A->n;
  view.nzmax = (size_t)A->nnz;
  view.p = A->colptr;
  view.i = A->rowind;
  view.x = A->val;
  view.stype = 1;
  view.itype = CHOLMOD_LONG;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  return view;
}

/* A negative Common->status is a failure of CHOLMOD itself (memory, size limits, bad input). */
static int library_error(const cholmod_common *common, const char *what) {
  if (common->status == CHOLMOD_OUT_OF_MEMORY) MICA_ERROR(MICA_ERR_MEMORY, "CHOLMOD %s: out of memory", what);
  MICA_ERROR(MICA_ERR_LIBRARY, "CHOLMOD %s failed (status %d)", what, common->status);
}

/* Entries of L as stored: per supernode a trapezoid of nscol columns and nsrow rows. */
static long factor_entries(const cholmod_factor *L) {
  if (!L->is_super) {
    long count = 0;
    const long *column_counts = L->nz;
    for (size_t j = 0; j < L->n; j++) count += column_counts[j];
    return count;
  }
  const long *super = L->super, *pi = L->pi;
  long count = 0;
  for (size_t s = 0; s < L->nsuper; s++) {
    long nscol = super[s + 1] - super[s], nsrow = pi[s + 1] - pi[s];
    count += nscol * nsrow - nscol * (nscol - 1) / 2;
  }
  return count;
}

/* The column of A (not of the permuted matrix CHOLMOD factors) where the factorization broke down. */
static long failed_column(const cholmod_factor *L) {
  const long *perm = L->Perm;
  if (L->minor >= L->n) return -1;
  return perm ? perm[L->minor] : (long)L->minor;
}

static int cholmod_create(MicaLinearSolver *solver) {
  CholmodData *data = NULL;
  MICA_CALL(MICA_CALLOC(data, 1));
  if (!cholmod_l_start(&data->common)) {
    free(data);
    MICA_ERROR(MICA_ERR_LIBRARY, "CHOLMOD: cholmod_l_start failed");
  }
  data->common.supernodal = CHOLMOD_SUPERNODAL;
  data->common.print = 0;
  solver->data = data;
  return MICA_SUCCESS;
}

/* Fill-reducing ordering and symbolic factor for A's pattern, replacing any earlier one. */
static int analyze(MicaLinearSolver *solver, cholmod_sparse *view, MicaPatternKey key) {
  CholmodData *data = solver->data;
  double start = mica_wtime();
  cholmod_l_free_factor(&data->L, &data->common);
  data->L = cholmod_l_analyze(view, &data->common);
  solver->stats.time_analyze += mica_wtime() - start;
  if (!data->L) return library_error(&data->common, "analysis");
  data->pattern = key;
  data->analysis_flops = data->common.fl;
  solver->stats.analyses++;
  return MICA_SUCCESS;
}

static int cholmod_factor_matrix(MicaLinearSolver *solver, const MicaSparse *A) {
  CholmodData *data = solver->data;
  cholmod_sparse view = borrow_matrix(A);
  MicaPatternKey key = mica_pattern_key(A);
  data->factored = 0;
  if (!data->L || !mica_pattern_key_equal(key, data->pattern)) MICA_CALL(analyze(solver, &view, key));
  int ok = cholmod_l_factorize(&view, data->L, &data->common);
  if (data->common.status == CHOLMOD_NOT_POSDEF || (ok && data->L->minor < data->L->n))
    MICA_ERROR(MICA_ERR_NUMERIC,
               "matrix is not positive definite (CHOLMOD: column %ld); use solver.linear = umfpack or check the "
               "constraints",
               failed_column(data->L));
  if (!ok || data->common.status < CHOLMOD_OK) return library_error(&data->common, "factorization");
  data->factored = 1;
  solver->stats.nnz_factor = factor_entries(data->L);
  solver->stats.flops = data->analysis_flops;
  return MICA_SUCCESS;
}

static int cholmod_solve_system(MicaLinearSolver *solver, const double *b, double *x) {
  CholmodData *data = solver->data;
  MICA_CHECK(data->factored, MICA_ERR_ARGUMENT, "CHOLMOD solve: no successful factorization to solve with");
  size_t n = data->L->n;
  cholmod_dense rhs;
  memset(&rhs, 0, sizeof rhs);
  rhs.nrow = n;
  rhs.ncol = 1;
  rhs.nzmax = n;
  rhs.d = n;
  rhs.x = (double *)b; /* read only */
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  cholmod_dense *solution = cholmod_l_solve(CHOLMOD_A, data->L, &rhs, &data->common);
  if (!solution) return library_error(&data->common, "solve");
  memcpy(x, solution->x, n * sizeof *x);
  cholmod_l_free_dense(&solution, &data->common);
  return MICA_SUCCESS;
}

static void cholmod_destroy(MicaLinearSolver *solver) {
  CholmodData *data = solver->data;
  if (!data) return;
  cholmod_l_free_factor(&data->L, &data->common);
  cholmod_l_finish(&data->common);
  free(data);
  solver->data = NULL;
}

const MicaLinearSolverOps mica_linear_cholmod = {
    {"cholmod", "CHOLMOD supernodal Cholesky (symmetric positive definite)", MICA_LINEAR_SPD_ONLY, NULL, NULL},
    cholmod_create, cholmod_factor_matrix,
                                                 cholmod_solve_system, cholmod_destroy};
