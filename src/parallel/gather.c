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
    solver->stats.krylov_cpu = ps->inner->stats.krylov_cpu;
  }
  return mica_parallel_broadcast(ierr, x, n, 0);
}

const MicaLinearSolverOps mica_linear_gather = {
    {"gather", "the tangent gathered to rank 0 for its solver", 0, NULL, NULL},
    parallel_create, gather_factor, gather_solve,
                                                parallel_destroy};

int mica_parallel_linear_create(MicaDistribution *dist, const MicaLinearSolverOps *inner, MicaLinearSolver **solver) {
  if (mica_linear_solver_has(inner, MICA_LINEAR_DISTRIBUTED)) { /* petsc: each rank's rows, those of its particles */
    MicaLinearLayout layout = {mica_parallel_comm(), dist->partition->n, dist->partition->part, NULL, 0, 0, NULL};
    if (dist->owned) { /* parallel.data = "distributed": local numbering, owned particles first (then multipliers) */
      layout.nnodes = dist->nowned + dist->nghost + dist->nextra;
      layout.node_global = dist->global_node, layout.nowned = dist->nowned_nodes, layout.nglobal = dist->nglobal_nodes;
      layout.owned_node = dist->owned_node;
    }
    MICA_CALL(mica_linear_solver_create(inner, solver));
    return mica_linear_solver_set_layout(*solver, &layout);
  }
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

/* nnz of Σ_r L_r without gathering the pattern anywhere: the upper-triangle entries (i ≤ j) go to the rank
 * that counts column j (node of j modulo the ranks: balanced), which sorts them and counts the distinct ones;
 * the tangent's pattern is symmetric, so nnz = 2 · upper − diagonal. One all-to-all of 8 bytes per entry. */
static int compare_long(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

static int count_distinct(long *keys, long count, long n, long *upper, long *diagonal) {
  qsort(keys, (size_t)count, sizeof *keys, compare_long);
  *upper = *diagonal = 0;
  for (long k = 0; k < count; k++) {
    if (k > 0 && keys[k] == keys[k - 1]) continue;
    (*upper)++;
    *diagonal += keys[k] / n == keys[k] % n;
  }
  return MICA_SUCCESS;
}

int mica_parallel_matrix_nnz_mapped(const MicaSparse *L, const long *global_node, long nglobal, long *nnz) {
  const int P = mica_parallel_size();
  const long n = L->n, nd = L->ndof, N = global_node ? nglobal * nd : n;
#define GLOBAL(j) (global_node ? global_node[(j) / nd] * nd + (j) % nd : (j))
  int *counts = NULL, *displs = NULL, *rcounts = NULL, *rdispls = NULL;
  long *send = NULL, *recv = NULL, *cursor = NULL, nrecv = 0, sendn = 0, mine[2] = {0, 0};
  int ierr = MICA_CALLOC(counts, 2L * P + 2);
  if (!ierr) ierr = MICA_CALLOC(rcounts, 2L * P + 2);
  if (!ierr) ierr = MICA_CALLOC(cursor, P + 1);
  displs = counts + P + 1, rdispls = rcounts + P + 1;
  for (long j = 0; j < n && !ierr; j++) {
    const long gj = GLOBAL(j);
    const int to = (int)((gj / nd) % P);
    for (long q = L->colptr[j]; q < L->colptr[j + 1]; q++)
      if (GLOBAL(L->rowind[q]) <= gj) counts[to]++, sendn++;
  }
  if (!ierr && sendn >= (1L << 31)) /* MPI counts and displacements are int */
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "%ld pattern entries exceed MPI's counts",
                          sendn);
  if (!ierr) ierr = MICA_MALLOC(send, sendn + 1);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoall(counts, 1, MPI_INT, rcounts, 1, MPI_INT, mica_parallel_comm());
  for (int r = 0; r < P; r++) {
    displs[r + 1] = displs[r] + counts[r], rdispls[r + 1] = rdispls[r] + rcounts[r];
    cursor[r] = displs[r];
  }
  nrecv = rdispls[P];
  for (long j = 0; j < n; j++) {
    const long gj = GLOBAL(j);
    const int to = (int)((gj / nd) % P);
    for (long q = L->colptr[j]; q < L->colptr[j + 1]; q++)
      if (GLOBAL(L->rowind[q]) <= gj) send[cursor[to]++] = gj * N + GLOBAL(L->rowind[q]);
  }
  ierr = MICA_MALLOC(recv, nrecv + 1);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoallv(send, counts, displs, MPI_LONG, recv, rcounts, rdispls, MPI_LONG, mica_parallel_comm());
  free(send);
  send = NULL;
  count_distinct(recv, nrecv, N, &mine[0], &mine[1]);
  MPI_Allreduce(MPI_IN_PLACE, mine, 2, MPI_LONG, MPI_SUM, mica_parallel_comm());
  *nnz = 2 * mine[0] - mine[1];
cleanup:
  free(counts), free(rcounts), free(cursor), free(send), free(recv);
  return ierr;
}
#undef GLOBAL

int mica_parallel_matrix_nnz(const MicaSparse *L, long *nnz) { return mica_parallel_matrix_nnz_mapped(L, NULL, 0, nnz); }
