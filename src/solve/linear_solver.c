/* The linear-solver registry and the create / factor / solve / destroy wrappers (sparse.h).
 *
 * The wrappers check arguments, time the phases and count them, so each solver's ops only do the work:
 * an op's factor adds its own symbolic-analysis time to stats.time_analyze and counts analyses; the
 * wrapper books the rest of the call as factorization time. factorizations and solves count successful
 * calls; the times include failed ones.
 */
#include <stdlib.h>
#include <string.h>

#include "linear_private.h"
#include "mica/sparse.h"
#include "mica/timer.h"

static const MicaType *const builtin_solvers[] = {&mica_linear_cholmod.type, &mica_linear_umfpack.type,
                                                  &mica_linear_cholmod_sym.type, &mica_linear_petsc.type,
                                                  NULL};

MicaRegistry mica_linear_solver_registry = {"linear solver", "cholmod", builtin_solvers, NULL, 0, NULL};

const MicaLinearSolverOps *mica_linear_solver_find(const char *name) {
  return (const MicaLinearSolverOps *)mica_registry_find(&mica_linear_solver_registry, name);
}

int mica_linear_solver_create(const MicaLinearSolverOps *ops, MicaLinearSolver **solver_out) {
  MICA_CHECK(ops && solver_out, MICA_ERR_ARGUMENT, "mica_linear_solver_create: NULL argument");
  *solver_out = NULL;
  MicaLinearSolver *solver = NULL;
  MICA_CALL(MICA_CALLOC(solver, 1));
  solver->ops = ops;
  solver->layout = (MicaLinearLayout){MPI_COMM_SELF, 0, NULL, NULL, 0, 0, NULL};
  int ierr = ops->create(solver);
  if (ierr) {
    free(solver);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  *solver_out = solver;
  return MICA_SUCCESS;
}

int mica_linear_solver_factor(MicaLinearSolver *solver, const MicaSparse *A) {
  MICA_CHECK(solver && A, MICA_ERR_ARGUMENT, "mica_linear_solver_factor: NULL argument");
  MICA_CHECK(A->n > 0 && A->colptr[A->n] == A->nnz, MICA_ERR_ARGUMENT,
             "mica_linear_solver_factor: empty or inconsistent matrix (n %ld, nnz %ld)", A->n, A->nnz);
  double start = mica_wtime(), analyze_before = solver->stats.time_analyze;
  int ierr = solver->ops->factor(solver, A);
  double analyze = solver->stats.time_analyze - analyze_before;
  solver->stats.time_factor += mica_wtime() - start - analyze;
  MICA_CALL(ierr);
  solver->stats.factorizations++;
  return MICA_SUCCESS;
}

int mica_linear_solver_solve(MicaLinearSolver *solver, const double *b, double *x) {
  MICA_CHECK(solver && b && x, MICA_ERR_ARGUMENT, "mica_linear_solver_solve: NULL argument");
  double start = mica_wtime();
  int ierr = solver->ops->solve(solver, b, x);
  solver->stats.time_solve += mica_wtime() - start;
  MICA_CALL(ierr);
  solver->stats.solves++;
  return MICA_SUCCESS;
}

int mica_linear_solver_destroy(MicaLinearSolver **solver) {
  if (!solver || !*solver) return MICA_SUCCESS;
  (*solver)->ops->destroy(*solver);
  MICA_FREE(*solver);
  return MICA_SUCCESS;
}

int mica_linear_solver_set_krylov(MicaLinearSolver *solver, const MicaKrylovOptions *opt) {
  MICA_CHECK(solver && opt, MICA_ERR_ARGUMENT, "mica_linear_solver_set_krylov: NULL argument");
  solver->krylov = *opt;
  return MICA_SUCCESS;
}

int mica_linear_solver_set_layout(MicaLinearSolver *solver, const MicaLinearLayout *layout) {
  MICA_CHECK(solver && layout, MICA_ERR_ARGUMENT, "mica_linear_solver_set_layout: NULL argument");
  solver->layout = *layout;
  return MICA_SUCCESS;
}

/* ---- Pattern keys (linear_private.h) ------------------------------------------------------------------ */

/* FNV-1a over 64-bit words with a final avalanche (SplitMix64's finalizer): any changed index changes it. */
static uint64_t mix_words(uint64_t hash, const long *words, long count) {
  for (long k = 0; k < count; k++) hash = (hash ^ (uint64_t)words[k]) * 0x100000001b3ULL;
  return hash;
}

static uint64_t avalanche(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

MicaPatternKey mica_pattern_key(const MicaSparse *A) {
  uint64_t hash = 0xcbf29ce484222325ULL;
  hash = mix_words(hash, A->colptr, A->n + 1);
  hash = mix_words(hash, A->rowind, A->nnz);
  return (MicaPatternKey){A->n, A->nnz, avalanche(hash)};
}

int mica_pattern_key_equal(MicaPatternKey a, MicaPatternKey b) {
  return a.n == b.n && a.nnz == b.nnz && a.fingerprint == b.fingerprint;
}
