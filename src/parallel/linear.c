/* The linear solver of a distributed run, and the size of the whole tangent from the ranks' parts. Under MPI the
 * tangent is PETSc's (solver.linear = "petsc", src/solve/linear_petsc.c): a matrix distributed by the rows of each
 * rank's particles. Its solvers (MUMPS, GAMG, hypre, additive Schwarz and block Jacobi with CHOLMOD or UMFPACK
 * subdomains) replaced mica's own gather-to-rank-0, Schwarz and CG code, which PETSc does better and at scale. */
#include <mpi.h>
#include <stdlib.h>

#include "parallel_private.h"
#include "mica/sort.h"

/* The ranks' solver: a distributed one (petsc) whose every factorization starts and whose every factorization and
 * solve ends with the ranks agreeing on their state, so that an error one rank meets outside PETSc's collectives
 * (or the failure injection point "solve") ends every rank with one message instead of leaving the others waiting
 * in a collective. Not covered: an error one rank alone meets inside a PETSc collective (the others wait there;
 * PETSc's convergence results, MUMPS's and KSP's, are the same on every rank). */
typedef struct RanksSolver {
  MicaLinearSolver *inner;
} RanksSolver;

static int ranks_create(MicaLinearSolver *solver) {
  RanksSolver *rs = NULL;
  MICA_CALL(MICA_CALLOC(rs, 1));
  solver->data = rs;
  return MICA_SUCCESS;
}

static void ranks_destroy(MicaLinearSolver *solver) {
  RanksSolver *rs = solver->data;
  if (rs) mica_linear_solver_destroy(&rs->inner);
  free(rs);
  solver->data = NULL;
}

/* What Newton reads of the solver (the wrapper's own calls count the time and the factorizations). */
static void mirror_stats(MicaLinearSolverStats *out, const MicaLinearSolverStats *in) {
  out->nnz_factor = in->nnz_factor, out->flops = in->flops;
  out->time_analyze = in->time_analyze, out->analyses = in->analyses;
  out->krylov_iterations = in->krylov_iterations, out->krylov_iterations_max = in->krylov_iterations_max;
  out->krylov_residual = in->krylov_residual, out->krylov_cpu = in->krylov_cpu;
  out->halo_dofs = in->halo_dofs, out->multigrid_levels = in->multigrid_levels;
}

static int ranks_factor(MicaLinearSolver *solver, const MicaSparse *A) {
  RanksSolver *rs = solver->data;
  /* before PETSc's collectives: a rank that would not enter them stops the others first */
  int ierr = mica_parallel_agree(mica_parallel_inject("solve"));
  if (ierr) return ierr;
  ierr = mica_linear_solver_set_krylov(rs->inner, &solver->krylov);
  if (!ierr) ierr = mica_linear_solver_factor(rs->inner, A);
  mirror_stats(&solver->stats, &rs->inner->stats);
  return mica_parallel_agree(ierr);
}

static int ranks_solve(MicaLinearSolver *solver, const double *b, double *x) {
  RanksSolver *rs = solver->data;
  const int ierr = mica_linear_solver_solve(rs->inner, b, x);
  mirror_stats(&solver->stats, &rs->inner->stats);
  return mica_parallel_agree(ierr);
}

static const MicaLinearSolverOps ranks_ops = {
    {"ranks", "a distributed solver whose outcome the ranks agree on", MICA_LINEAR_DISTRIBUTED, NULL, NULL},
    ranks_create, ranks_factor, ranks_solve, ranks_destroy};

int mica_parallel_linear_create(MicaDistribution *dist, const MicaLinearSolverOps *ops, MicaLinearSolver **solver) {
  MICA_CHECK(mica_linear_solver_has(ops, MICA_LINEAR_DISTRIBUTED), MICA_ERR_INPUT,
             "solver.linear = \"%s\" solves in one process; under mpirun the tangent is distributed over the ranks: "
             "use solver.linear = \"auto\" or \"petsc\" (solver.petsc = \"mumps\" factors it, \"asm-cholmod\" "
             "gives each rank's subdomain to CHOLMOD)",
             ops->type.name);
  /* each rank's rows are those of its particles */
  MicaLinearLayout layout = {mica_parallel_comm(), dist->partition->n, dist->partition->part, NULL, 0, 0, NULL};
  if (dist->owned) { /* parallel.data = "distributed": local numbering, owned particles first (then multipliers) */
    layout.nnodes = dist->nowned + dist->nghost + dist->nextra;
    layout.node_global = dist->global_node, layout.nowned = dist->nowned_nodes, layout.nglobal = dist->nglobal_nodes;
    layout.owned_node = dist->owned_node;
  }
  MicaLinearSolver *inner = NULL;
  MICA_CALL(mica_linear_solver_create(ops, &inner));
  int ierr = mica_linear_solver_set_layout(inner, &layout);
  if (!ierr) ierr = mica_linear_solver_create(&ranks_ops, solver);
  if (ierr) {
    mica_linear_solver_destroy(&inner);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  ((RanksSolver *)(*solver)->data)->inner = inner;
  return MICA_SUCCESS;
}

/* nnz of Σ_r L_r without gathering the pattern anywhere: the upper-triangle entries (i ≤ j) go to the rank
 * that counts column j (node of j modulo the ranks: balanced), which sorts them and counts the distinct ones;
 * the tangent's pattern is symmetric, so nnz = 2 · upper − diagonal. One all-to-all of 8 bytes per entry. */
static int count_distinct(long *keys, long count, long n, long *upper, long *diagonal) {
  qsort(keys, (size_t)count, sizeof *keys, mica_compare_long);
  *upper = *diagonal = 0;
  for (long k = 0; k < count; k++) {
    if (k > 0 && keys[k] == keys[k - 1]) continue;
    (*upper)++;
    *diagonal += keys[k] / n == keys[k] % n;
  }
  return MICA_SUCCESS;
}

int mica_parallel_matrix_nnz(const MicaSparse *L, long *nnz) {
  const int P = mica_parallel_size();
  const long n = L->n, nd = L->ndof, N = n;
#define GLOBAL(j) (j)
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

