/* solver.parallel = gather: the tangent's contributions summed on rank 0, factored there by CHOLMOD or
 * UMFPACK (whose symbolic analysis is reused while the gathered pattern is unchanged, as in a serial run),
 * the solution broadcast. The gathered matrix is the serial one up to the order of the sums, so the
 * solution equals the serial one to round-off. */
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "mica/timer.h"
#include "parallel_private.h"

static int parallel_create(MicaLinearSolver *solver) {
  ParallelSolver *ps = NULL;
  MICA_CALL(MICA_CALLOC(ps, 1));
  solver->data = ps;
  return MICA_SUCCESS;
}

static void parallel_destroy(MicaLinearSolver *solver) {
  ParallelSolver *ps = solver->data;
  if (!ps) return;
  mica_linear_solver_destroy(&ps->inner);
  redistribution_destroy(&ps->rd);
  free(ps->krylov);
  free(ps);
  solver->data = NULL;
}

/* Node sets of the gather: rank 0 takes every node. */
static int gather_setup(ParallelSolver *ps, const MicaSparse *L) {
  const int P = mica_parallel_size();
  const long nnodes = L->n / L->ndof;
  char *all = NULL;
  const char **member = NULL;
  int ierr = MICA_CALLOC(member, P);
  if (!ierr) ierr = MICA_MALLOC(all, nnodes + 1);
  if (!ierr) {
    memset(all, 1, (size_t)nnodes);
    member[0] = all;
  }
  redistribution_destroy(&ps->rd);
  ierr = mica_parallel_agree(ierr);
  if (!ierr) ierr = redistribution_create(L, member, nnodes, &ps->rd);
  free(all);
  free(member);
  MICA_CALL(ierr);
  ps->pattern_n = L->n, ps->pattern_nnz = L->nnz;
  return MICA_SUCCESS;
}

static int gather_factor(MicaLinearSolver *solver, const MicaSparse *L) {
  ParallelSolver *ps = solver->data;
  const int root = mica_parallel_rank() == 0;
  if (!ps->rd || ps->pattern_n != L->n || ps->pattern_nnz != L->nnz) MICA_CALL(gather_setup(ps, L));
  const double start = mica_wtime();
  MICA_CALL(redistribution_move(ps->rd, mica_parallel_inject("solve"), L));
  ps->dist->stats.time_gather += mica_wtime() - start;
  int ierr = MICA_SUCCESS;
  if (root && !ps->inner) ierr = mica_linear_solver_create(ps->inner_ops, &ps->inner);
  if (root && !ierr) ierr = mica_linear_solver_set_krylov(ps->inner, &solver->krylov); /* cg on rank 0 */
  if (root && !ierr) {
    const double before = ps->inner->stats.time_analyze;
    ierr = mica_linear_solver_factor(ps->inner, ps->rd->A);
    solver->stats.time_analyze += ps->inner->stats.time_analyze - before;
    solver->stats.analyses = ps->inner->stats.analyses;
    solver->stats.nnz_factor = ps->inner->stats.nnz_factor;
    solver->stats.flops = ps->inner->stats.flops;
  }
  MICA_CALL(mica_parallel_agree(ierr));
  return MICA_SUCCESS;
}

static int gather_solve(MicaLinearSolver *solver, const double *b, double *x) {
  ParallelSolver *ps = solver->data;
  const long n = ps->pattern_n;
  int ierr = MICA_SUCCESS;
  if (mica_parallel_rank() == 0) {
    ierr = mica_linear_solver_solve(ps->inner, b, x);
    solver->stats.krylov_iterations = ps->inner->stats.krylov_iterations;
    solver->stats.krylov_iterations_max = ps->inner->stats.krylov_iterations_max;
    solver->stats.krylov_residual = ps->inner->stats.krylov_residual;
  }
  return mica_parallel_broadcast(ierr, x, n, 0);
}

const MicaLinearSolverOps mica_linear_gather = {"gather", parallel_create, gather_factor, gather_solve,
                                                parallel_destroy};

int mica_parallel_linear_create(MicaDistribution *dist, const MicaLinearSolverOps *inner, MicaLinearSolver **solver) {
  const MicaLinearSolverOps *ops = dist->opt.solver == MICA_PARALLEL_SCHWARZ ? &mica_linear_schwarz : &mica_linear_gather;
  MICA_CALL(mica_linear_solver_create(ops, solver));
  ParallelSolver *ps = (*solver)->data;
  ps->dist = dist;
  /* Schwarz is the Krylov method: its subdomains are factored (cg asked for: CHOLMOD there) */
  ps->inner_ops = dist->opt.solver == MICA_PARALLEL_SCHWARZ && mica_linear_solver_iterative(inner) ? &mica_linear_cholmod
                                                                                                   : inner;
  return MICA_SUCCESS;
}

/* Destroy for both (the Schwarz file defines its factor and solve). */
void parallel_solver_destroy(MicaLinearSolver *solver) { parallel_destroy(solver); }
int parallel_solver_create(MicaLinearSolver *solver) { return parallel_create(solver); }

int mica_parallel_matrix_nnz(const MicaSparse *L, long *nnz) {
  ParallelSolver ps;
  memset(&ps, 0, sizeof ps);
  int ierr = gather_setup(&ps, L);
  long count = !ierr && ps.rd && ps.rd->A ? ps.rd->A->nnz : 0;
  redistribution_destroy(&ps.rd);
  MICA_CALL(mica_parallel_broadcast(ierr, NULL, 0, 0));
  MPI_Bcast(&count, 1, MPI_LONG, 0, MPI_COMM_WORLD);
  *nnz = count;
  return MICA_SUCCESS;
}
