/* UMFPACK sparse LU (umfpack_dl_*, 64-bit indices) for unsymmetric or indefinite matrices: Lagrange
 * multipliers, saddle points, tangents that lost positive definiteness.
 *
 * UMFPACK reads the full CSC arrays directly (SuiteSparse_long is long here). The symbolic analysis
 * (column ordering, strategy) is done once per pattern (linear_private.h) and reused by every numeric
 * factorization; the solve keeps UMFPACK's default iterative refinement, which reads A again, so the
 * matrix passed to factor must stay alive and unchanged until the solves with that factorization are done.
 */
#include <stdlib.h>
#include <string.h>

#include <umfpack.h>

#include "linear_private.h"
#include "mica/timer.h"

typedef struct {
  void *symbolic, *numeric;
  MicaPatternKey pattern; /* of the matrix the symbolic object was made for */
  const MicaSparse *A;    /* the matrix of the current numeric factorization (for refinement) */
  double control[UMFPACK_CONTROL];
  double info[UMFPACK_INFO];
} UmfpackData;

static const char *status_name(int status) {
  switch (status) {
  case UMFPACK_WARNING_singular_matrix: return "UMFPACK_WARNING_singular_matrix";
  case UMFPACK_ERROR_out_of_memory: return "UMFPACK_ERROR_out_of_memory";
  case UMFPACK_ERROR_invalid_matrix: return "UMFPACK_ERROR_invalid_matrix";
  case UMFPACK_ERROR_different_pattern: return "UMFPACK_ERROR_different_pattern";
  case UMFPACK_ERROR_ordering_failed: return "UMFPACK_ERROR_ordering_failed";
  case UMFPACK_ERROR_internal_error: return "UMFPACK_ERROR_internal_error";
  default: return "UMFPACK error";
  }
}

static int library_error(int status, const char *what) {
  if (status == UMFPACK_ERROR_out_of_memory) MICA_ERROR(MICA_ERR_MEMORY, "UMFPACK %s: out of memory", what);
  MICA_ERROR(MICA_ERR_LIBRARY, "UMFPACK %s failed: %s (status %d)", what, status_name(status), status);
}

static int umfpack_create(MicaLinearSolver *solver) {
  UmfpackData *data = NULL;
  MICA_CALL(MICA_CALLOC(data, 1));
  umfpack_dl_defaults(data->control);
  solver->data = data;
  return MICA_SUCCESS;
}

static void free_numeric(UmfpackData *data) {
  if (data->numeric) umfpack_dl_free_numeric(&data->numeric);
  data->numeric = NULL;
  data->A = NULL;
}

/* Column ordering and symbolic analysis for A's pattern, replacing any earlier one. */
static int analyze(MicaLinearSolver *solver, const MicaSparse *A, MicaPatternKey key) {
  UmfpackData *data = solver->data;
  free_numeric(data);
  if (data->symbolic) umfpack_dl_free_symbolic(&data->symbolic);
  data->symbolic = NULL;
  double start = mica_wtime();
  int status = (int)umfpack_dl_symbolic(A->n, A->n, A->colptr, A->rowind, A->val, &data->symbolic, data->control,
                                        data->info);
  solver->stats.time_analyze += mica_wtime() - start;
  if (status != UMFPACK_OK) {
    data->symbolic = NULL;
    return library_error(status, "symbolic analysis");
  }
  data->pattern = key;
  solver->stats.analyses++;
  return MICA_SUCCESS;
}

static int umfpack_factor_matrix(MicaLinearSolver *solver, const MicaSparse *A) {
  UmfpackData *data = solver->data;
  MicaPatternKey key = mica_pattern_key(A);
  if (!data->symbolic || !mica_pattern_key_equal(key, data->pattern)) MICA_CALL(analyze(solver, A, key));
  free_numeric(data);
  int status = (int)umfpack_dl_numeric(A->colptr, A->rowind, A->val, data->symbolic, &data->numeric, data->control,
                                       data->info);
  if (status != UMFPACK_OK) {
    free_numeric(data); /* a singular factorization exists but must not be used */
    if (status == UMFPACK_WARNING_singular_matrix)
      MICA_ERROR(MICA_ERR_NUMERIC, "matrix is singular (UMFPACK: %s); check the constraints and supports",
                 status_name(status));
    return library_error(status, "factorization");
  }
  data->A = A;
  long lnz = 0, unz = 0, nrow = 0, ncol = 0, nz_udiag = 0;
  umfpack_dl_get_lunz(&lnz, &unz, &nrow, &ncol, &nz_udiag, data->numeric);
  solver->stats.nnz_factor = lnz + unz;
  solver->stats.flops = data->info[UMFPACK_FLOPS];
  return MICA_SUCCESS;
}

static int umfpack_solve_system(MicaLinearSolver *solver, const double *b, double *x) {
  UmfpackData *data = solver->data;
  MICA_CHECK(data->numeric, MICA_ERR_ARGUMENT, "UMFPACK solve: no successful factorization to solve with");
  const MicaSparse *A = data->A;
  double *rhs_copy = NULL; /* UMFPACK needs x and b apart: solving in place goes through a copy of b */
  if (x == b) {
    MICA_CALL(MICA_MALLOC(rhs_copy, A->n));
    memcpy(rhs_copy, b, (size_t)A->n * sizeof *rhs_copy);
    b = rhs_copy;
  }
  int status = (int)umfpack_dl_solve(UMFPACK_A, A->colptr, A->rowind, A->val, x, b, data->numeric, data->control,
                                     data->info);
  free(rhs_copy);
  if (status != UMFPACK_OK) return library_error(status, "solve");
  return MICA_SUCCESS;
}

static void umfpack_destroy(MicaLinearSolver *solver) {
  UmfpackData *data = solver->data;
  if (!data) return;
  free_numeric(data);
  if (data->symbolic) umfpack_dl_free_symbolic(&data->symbolic);
  free(data);
  solver->data = NULL;
}

const MicaLinearSolverOps mica_linear_umfpack = {
    {"umfpack", "UMFPACK sparse LU (any nonsingular matrix)", 0, NULL, NULL},
    umfpack_create, umfpack_factor_matrix,
                                                 umfpack_solve_system, umfpack_destroy};
