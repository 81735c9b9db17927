/* Benchmark of the sparse pattern, the clique scatter and the direct solvers (src/solve/sparse.c,
 * linear_cholmod.c, linear_umfpack.c) on MLS-like patterns.
 *
 * Particles sit on an m^dim grid with spacing h; there is one quadrature point per particle, and its
 * clique is every particle within a box of half-width r·h (r = 2: 5^dim = 25 nodes in 2-D, 125 in 3-D,
 * fewer at the boundary), with ndof = dim unknowns per node. Two nodes are then coupled when they are
 * within 2 r h per axis (81 neighbors in 2-D, 729 in 3-D). Each clique adds the SPD block I + g gᵀ (dense,
 * like a real clique stiffness; the values only need to make the matrix SPD). For each size it prints the
 * time to build the pattern, to scatter every clique once (the time of the add calls only) and the
 * scatter rate in block entries per second; then CHOLMOD's analysis, first factorization, refactorization
 * with new values (analysis reused), solve, nnz(L) and flop rate (of the last factorization), and
 * UMFPACK's analysis, factorization and solve. Sizes n ≈ 1e4 and 1e5 per dimension, plus a 3-D n ≈ 3e3
 * for UMFPACK; factorizations that would take minutes (3-D n ≈ 1e5, about 1.8e8 nonzeros; UMFPACK beyond
 * 2-D 1e4 and 3-D 3e3, where LU costs about 8 times the Cholesky factorization) are skipped, and say so.
 * It reports figures only: it never fails on time.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "mica/sparse.h"
#include "mica/timer.h"

enum { RADIUS = 2 }; /* clique half-width in spacings */

typedef struct {
  int dim, ndof;
  long m, nnodes, ncliques;
  long *ptr, *nodes; /* cliques, nodes ascending */
} Problem;

static long node_id(int dim, long m, const long *index) {
  long id = 0;
  for (int d = 0; d < dim; d++) id = id * m + index[d];
  return id;
}

/* The particles within RADIUS spacings of particle `center` (per axis), in ascending order. */
static long clique_of(int dim, long m, const long *center, long *out) {
  long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, index[3] = {0, 0, 0}, count = 0;
  for (int d = 0; d < dim; d++) {
    lo[d] = center[d] - RADIUS < 0 ? 0 : center[d] - RADIUS;
    hi[d] = center[d] + RADIUS > m - 1 ? m - 1 : center[d] + RADIUS;
  }
  for (index[0] = lo[0]; index[0] <= hi[0]; index[0]++)
    for (index[1] = lo[1]; index[1] <= hi[1]; index[1]++)
      for (index[2] = lo[2]; index[2] <= hi[2]; index[2]++) out[count++] = node_id(dim, m, index);
  return count;
}

static int make_problem(int dim, long target_dofs, Problem *p) {
  p->dim = dim;
  p->ndof = dim;
  p->m = lround(pow((double)target_dofs / dim, 1.0 / dim));
  p->nnodes = dim == 2 ? p->m * p->m : p->m * p->m * p->m;
  p->ncliques = p->nnodes;
  long max_size = dim == 2 ? 25 : 125;
  p->ptr = malloc((size_t)(p->ncliques + 1) * sizeof *p->ptr);
  p->nodes = malloc((size_t)(p->ncliques * max_size) * sizeof *p->nodes);
  if (!p->ptr || !p->nodes) return 1;
  p->ptr[0] = 0;
  long center[3] = {0, 0, 0};
  for (long c = 0; c < p->ncliques; c++) {
    for (long rest = c, d = dim - 1; d >= 0; d--) center[d] = rest % p->m, rest /= p->m;
    p->ptr[c + 1] = p->ptr[c] + clique_of(dim, p->m, center, p->nodes + p->ptr[c]);
  }
  return 0;
}

static void free_problem(Problem *p) {
  free(p->ptr);
  free(p->nodes);
}

/* I + s g gᵀ with g_i = 1 + 0.1 sin(i + seed): dense and symmetric positive definite. */
static void clique_block(long size, double s, long seed, double *g, double *K) {
  for (long i = 0; i < size; i++) g[i] = 1.0 + 0.1 * sin((double)(i + seed));
  for (long i = 0; i < size; i++)
    for (long j = 0; j < size; j++) K[i * size + j] = (i == j) + s * g[i] * g[j];
}

/* Adds every clique once; returns the seconds spent in mica_sparse_add_clique. */
static double scatter_all(const Problem *p, MicaSparse *A, double s, double *K, double *entries) {
  double seconds = 0.0, g[375];
  *entries = 0.0;
  mica_sparse_zero(A);
  for (long c = 0; c < p->ncliques; c++) {
    long n = p->ptr[c + 1] - p->ptr[c], size = n * p->ndof;
    clique_block(size, s, c, g, K);
    double start = mica_wtime();
    if (mica_sparse_add_clique(A, n, p->nodes + p->ptr[c], K)) {
      fprintf(stderr, "bench_sparse: %s\n", mica_error_message());
      exit(1);
    }
    seconds += mica_wtime() - start;
    *entries += (double)size * (double)size;
  }
  return seconds;
}

static double relative_residual(const MicaSparse *A, const double *x, const double *b) {
  double *Ax = malloc((size_t)A->n * sizeof *Ax), r2 = 0.0, b2 = 0.0;
  if (!Ax) return NAN;
  mica_sparse_matvec(A, x, Ax);
  for (long i = 0; i < A->n; i++) r2 += (Ax[i] - b[i]) * (Ax[i] - b[i]), b2 += b[i] * b[i];
  free(Ax);
  return sqrt(r2 / b2);
}

/* Factor, optionally refactor with new values (the analysis reused), solve; prints one line. */
static void run_solver(const MicaLinearSolverOps *ops, const Problem *p, MicaSparse *A, double *K, int refactor) {
  MicaLinearSolver *solver = NULL;
  double *b = malloc((size_t)A->n * sizeof *b), *x = malloc((size_t)A->n * sizeof *x), entries;
  if (!b || !x || mica_linear_solver_create(ops, &solver)) {
    fprintf(stderr, "bench_sparse: cannot set up %s\n", ops->type.name);
    exit(1);
  }
  for (long i = 0; i < A->n; i++) b[i] = sin(0.37 * (double)i);
  if (mica_linear_solver_factor(solver, A)) goto failed;
  const double first_factor = solver->stats.time_factor;
  double last_factor = first_factor;
  if (refactor) {
    scatter_all(p, A, 0.5, K, &entries);
    if (mica_linear_solver_factor(solver, A)) goto failed;
    last_factor = solver->stats.time_factor - first_factor;
  }
  if (mica_linear_solver_solve(solver, b, x)) goto failed;
  const MicaLinearSolverStats *st = &solver->stats;
  char refactor_text[32] = "        -";
  if (refactor) snprintf(refactor_text, sizeof refactor_text, "%7.3f s", last_factor);
  printf("  %-8s analyze %7.3f s  factor %7.3f s  refactor %s  solve %6.3f s  nnz(factor) %10ld  "
         "%6.2f Gflop/s  analyses %ld  residual %.1e\n",
         ops->type.name, st->time_analyze, first_factor, refactor_text, st->time_solve, st->nnz_factor,
         st->flops / last_factor * 1e-9, st->analyses, relative_residual(A, x, b));
  goto done;
failed:
  printf("  %-8s failed: %s\n", ops->type.name, mica_error_message());
done:
  mica_linear_solver_destroy(&solver);
  free(b);
  free(x);
}

typedef struct {
  int dim;
  long target_dofs;
  int cholmod, umfpack; /* run them? (the largest sizes would take minutes) */
} Size;

static void run_size(const Size *size) {
  Problem p;
  MicaSparse *A = NULL;
  double *K = malloc(sizeof(double) * 375 * 375), entries;
  if (!K || make_problem(size->dim, size->target_dofs, &p)) {
    fprintf(stderr, "bench_sparse: out of memory\n");
    exit(1);
  }
  double start = mica_wtime();
  if (mica_sparse_create(p.nnodes, p.ndof, p.ncliques, p.ptr, p.nodes, &A)) {
    fprintf(stderr, "bench_sparse: %s\n", mica_error_message());
    exit(1);
  }
  double pattern = mica_wtime() - start;
  double scatter = scatter_all(&p, A, 1.0, K, &entries);
  printf("%dD m %3ld  n %6ld  cliques %6ld (mean %5.1f nodes)  nnz %9ld (%6.1f per row)  "
         "pattern %6.3f s  scatter %6.3f s (%.0f M block entries/s)\n",
         size->dim, p.m, A->n, p.ncliques, (double)p.ptr[p.ncliques] / (double)p.ncliques, A->nnz,
         (double)A->nnz / (double)A->n, pattern, scatter, entries / scatter * 1e-6);
  if (size->cholmod) run_solver(&mica_linear_cholmod, &p, A, K, 1);
  else printf("  cholmod  skipped at this size (time budget)\n");
  if (size->umfpack) run_solver(&mica_linear_umfpack, &p, A, K, 0);
  else printf("  umfpack  skipped at this size (time budget)\n");
  fflush(stdout);
  mica_sparse_destroy(&A);
  free_problem(&p);
  free(K);
}

int main(void) {
  const Size sizes[] = {{2, 10000, 1, 1}, {2, 100000, 1, 0}, {3, 3000, 1, 1}, {3, 10000, 1, 0}, {3, 100000, 0, 0}};
  for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) run_size(&sizes[k]);
  return 0;
}
