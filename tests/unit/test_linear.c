/* The direct solvers (src/solve/linear*.c): CHOLMOD and UMFPACK on a 2-D 5-point Laplacian-like SPD
 * system (residual), reuse of the symbolic analysis over refactorizations with new values, a new analysis
 * for a new pattern, CHOLMOD's ordering chosen on the node graph, an indefinite saddle-point matrix (CHOLMOD refuses it, UMFPACK solves it), a singular
 * matrix (UMFPACK refuses it), in-place solves, the registry and the contract errors. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

#include "mica/random.h"
#include "mica/sparse.h"

enum { GRID = 50 };

/* ---- Test matrices, assembled from cliques like the real stiffness ---------------------------------- */

typedef struct {
  long nnodes, ncliques;
  long *ptr, *nodes;
} Cliques;

static void cliques_alloc(Cliques *c, long nnodes, long max_cliques, long max_entries) {
  c->nnodes = nnodes;
  c->ncliques = 0;
  c->ptr = malloc((size_t)(max_cliques + 1) * sizeof(long));
  c->nodes = malloc((size_t)max_entries * sizeof(long));
  assert_non_null(c->ptr);
  assert_non_null(c->nodes);
  c->ptr[0] = 0;
}

static void cliques_add(Cliques *c, long size, const long *nodes) {
  memcpy(c->nodes + c->ptr[c->ncliques], nodes, (size_t)size * sizeof(long));
  c->ptr[c->ncliques + 1] = c->ptr[c->ncliques] + size;
  c->ncliques++;
}

static void cliques_free(Cliques *c) {
  free(c->ptr);
  free(c->nodes);
}

/* The GRID × GRID 5-point pattern: one clique per grid edge; with_far_pair couples the first and last
 * nodes as well (another pattern with the same order). */
static MicaSparse *grid_pattern(int with_far_pair) {
  Cliques c;
  long nnodes = GRID * GRID;
  cliques_alloc(&c, nnodes, 2 * nnodes + 1, 4 * nnodes + 2);
  if (with_far_pair) cliques_add(&c, 2, (long[]){0, nnodes - 1});
  for (long i = 0; i < GRID; i++)
    for (long j = 0; j < GRID; j++) {
      long here = i * GRID + j;
      if (j + 1 < GRID) cliques_add(&c, 2, (long[]){here, here + 1});
      if (i + 1 < GRID) cliques_add(&c, 2, (long[]){here, here + GRID});
    }
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(nnodes, 1, c.ncliques, c.ptr, c.nodes, &A), MICA_SUCCESS);
  cliques_free(&c);
  return A;
}

/* Values: edge stiffness k_e = stiffness × (1 + small variation) per edge, and shift on the diagonal
 * (the boundary's share of a Dirichlet Laplacian, or any positive shift): SPD for shift > 0. */
static void grid_values(MicaSparse *A, double stiffness, double shift) {
  mica_sparse_zero(A);
  for (long i = 0; i < GRID; i++)
    for (long j = 0; j < GRID; j++) {
      long here = i * GRID + j;
      long neighbors[2] = {here + 1, here + GRID};
      int exists[2] = {j + 1 < GRID, i + 1 < GRID};
      for (int e = 0; e < 2; e++) {
        if (!exists[e]) continue;
        double k = stiffness * (1.0 + 0.1 * sin((double)(here + e)));
        double K[4] = {k, -k, -k, k};
        assert_int_equal(mica_sparse_add_clique(A, 2, (long[]){here, neighbors[e]}, K), MICA_SUCCESS);
      }
      double diagonal = shift;
      assert_int_equal(mica_sparse_add_clique(A, 1, &here, &diagonal), MICA_SUCCESS);
    }
}

static double relative_residual(const MicaSparse *A, const double *x, const double *b) {
  double *Ax = malloc((size_t)A->n * sizeof *Ax);
  assert_non_null(Ax);
  mica_sparse_matvec(A, x, Ax);
  double r2 = 0.0, b2 = 0.0;
  for (long i = 0; i < A->n; i++) r2 += (Ax[i] - b[i]) * (Ax[i] - b[i]), b2 += b[i] * b[i];
  free(Ax);
  return sqrt(r2 / b2);
}

static double *random_vector(long n, uint64_t seed) {
  MicaRandom rng = mica_random_seed(seed);
  double *v = malloc((size_t)n * sizeof *v);
  assert_non_null(v);
  for (long i = 0; i < n; i++) v[i] = mica_random_uniform(&rng) - 0.5;
  return v;
}

/* The grid's SPD values plus skew · k on every edge, (here, there) += skew k and (there, here) −= skew k: the
 * symmetric part stays the SPD grid, the skew part W grows with skew. */
static void grid_skew_values(MicaSparse *A, double skew) {
  grid_values(A, 1.0, 0.01);
  for (long i = 0; i < GRID; i++)
    for (long j = 0; j < GRID; j++) {
      long here = i * GRID + j;
      if (j + 1 < GRID) {
        double K[4] = {0.0, skew, -skew, 0.0};
        assert_int_equal(mica_sparse_add_clique(A, 2, (long[]){here, here + 1}, K), MICA_SUCCESS);
      }
    }
}

/* ---- SPD systems and reuse ---------------------------------------------------------------------------- */

static void factor_solve_check(MicaLinearSolver *solver, MicaSparse *A, const double *b, double *x) {
  int ierr = mica_linear_solver_factor(solver, A);
  if (ierr) fail_msg("factor: %s", mica_error_message());
  assert_int_equal(mica_linear_solver_solve(solver, b, x), MICA_SUCCESS);
  double residual = relative_residual(A, x, b);
  if (!(residual <= 1e-10)) fail_msg("%s: relative residual %.3g", solver->ops->type.name, residual);
  print_message("  %s: n %ld, nnz %ld, nnz(factor) %ld, relative residual %.2e\n", solver->ops->type.name, A->n, A->nnz,
                solver->stats.nnz_factor, residual);
}

/* Three factorizations with new values on one pattern: one analysis; a new pattern: a second one. */
static void check_spd_reuse(const MicaLinearSolverOps *ops) {
  MicaSparse *A = grid_pattern(0);
  double *b = random_vector(A->n, 7), *x = calloc((size_t)A->n, sizeof *x);
  MicaLinearSolver *solver = NULL;
  assert_int_equal(mica_linear_solver_create(ops, &solver), MICA_SUCCESS);
  const double stiffness[3] = {1.0, 3.0, 0.5}, shift[3] = {0.01, 1.0, 1e-4};
  for (int round = 0; round < 3; round++) {
    grid_values(A, stiffness[round], shift[round]);
    factor_solve_check(solver, A, b, x);
  }
  assert_int_equal(solver->stats.analyses, 1);
  assert_int_equal(solver->stats.factorizations, 3);
  assert_int_equal(solver->stats.solves, 3);
  assert_true(solver->stats.nnz_factor >= A->nnz / 2);
  assert_true(solver->stats.flops > 0.0);
  assert_true(solver->stats.time_analyze > 0.0 && solver->stats.time_factor > 0.0 && solver->stats.time_solve > 0.0);
  /* in place: x = A⁻¹ x */
  memcpy(x, b, (size_t)A->n * sizeof *x);
  assert_int_equal(mica_linear_solver_solve(solver, x, x), MICA_SUCCESS);
  assert_true(relative_residual(A, x, b) <= 1e-10);
  /* another pattern (the grid plus one far coupling) is analyzed anew */
  MicaSparse *B = grid_pattern(1);
  grid_values(B, 1.0, 0.1);
  factor_solve_check(solver, B, b, x);
  assert_int_equal(solver->stats.analyses, 2);
  mica_linear_solver_destroy(&solver);
  assert_null(solver);
  mica_sparse_destroy(&A);
  mica_sparse_destroy(&B);
  free(b);
  free(x);
}

static void test_cholmod_spd(void **state) {
  (void)state;
  check_spd_reuse(&mica_linear_cholmod);
}

static void test_umfpack_spd(void **state) {
  (void)state;
  check_spd_reuse(&mica_linear_umfpack);
}

/* Random cliques of 2-dof nodes, each adding B Bᵀ, plus the identity on every node: SPD with dense
 * 2 × 2 node blocks, solved by both solvers. */
static void test_random_blocks(void **state) {
  (void)state;
  enum { NODES = 300, CLIQUES = 200, SIZE = 8, NDOF = 2 };
  MicaRandom rng = mica_random_seed(21);
  Cliques c;
  cliques_alloc(&c, NODES, CLIQUES + NODES, CLIQUES * SIZE + NODES);
  for (long q = 0; q < CLIQUES; q++) {
    long nodes[SIZE], first = (long)(mica_random_uniform(&rng) * (NODES - 3 * SIZE));
    for (long k = 0; k < SIZE; k++) nodes[k] = first + 3 * k; /* ascending, spread out */
    cliques_add(&c, SIZE, nodes);
  }
  for (long i = 0; i < NODES; i++) cliques_add(&c, 1, &i);
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(NODES, NDOF, c.ncliques, c.ptr, c.nodes, &A), MICA_SUCCESS);
  double B[SIZE * NDOF * SIZE * NDOF], K[SIZE * NDOF * SIZE * NDOF];
  for (long q = 0; q < c.ncliques; q++) {
    long size = (c.ptr[q + 1] - c.ptr[q]) * NDOF;
    for (long k = 0; k < size * size; k++) B[k] = mica_random_uniform(&rng) - 0.5;
    for (long i = 0; i < size; i++)
      for (long j = 0; j < size; j++) {
        K[i * size + j] = 0.0;
        for (long k = 0; k < size; k++) K[i * size + j] += B[i * size + k] * B[j * size + k];
      }
    if (size == NDOF) K[0] = K[3] = 1.0, K[1] = K[2] = 0.0;
    assert_int_equal(mica_sparse_add_clique(A, c.ptr[q + 1] - c.ptr[q], c.nodes + c.ptr[q], K), MICA_SUCCESS);
  }
  double *b = random_vector(A->n, 13), *x = calloc((size_t)A->n, sizeof *x);
  const MicaLinearSolverOps *all[2] = {&mica_linear_cholmod, &mica_linear_umfpack};
  for (int s = 0; s < 2; s++) {
    MicaLinearSolver *solver = NULL;
    assert_int_equal(mica_linear_solver_create(all[s], &solver), MICA_SUCCESS);
    factor_solve_check(solver, A, b, x);
    mica_linear_solver_destroy(&solver);
  }
  cliques_free(&c);
  mica_sparse_destroy(&A);
  free(b);
  free(x);
}

/* ---- CHOLMOD's fill-reducing ordering, chosen on the node graph ------------------------------------------ */

static int compare_nodes(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* A side³ box of nodes, 3 unknowns each, one clique per node holding the nodes within reach along every axis
 * (a quadratic MLS support on a grid); node_of maps a grid point to its node number. Values: a random rank-one
 * block per clique plus the identity (SPD). */
static MicaSparse *box_pattern(long side, long reach, const long *node_of, MicaRandom *rng) {
  enum { NDOF = 3 };
  const long nodes = side * side * side, width = 2 * reach + 1, size = width * width * width;
  Cliques c;
  cliques_alloc(&c, nodes, 2 * nodes, nodes * (size + 1));
  for (long p = 0; p < nodes; p++) {
    long list[size], count = 0;
    const long x = p % side, y = p / side % side, z = p / (side * side);
    for (long k = z - reach; k <= z + reach; k++)
      for (long j = y - reach; j <= y + reach; j++)
        for (long i = x - reach; i <= x + reach; i++)
          if (i >= 0 && j >= 0 && k >= 0 && i < side && j < side && k < side)
            list[count++] = node_of[(k * side + j) * side + i];
    qsort(list, (size_t)count, sizeof *list, compare_nodes); /* mica_sparse_add_clique wants them ascending */
    cliques_add(&c, count, list);
    cliques_add(&c, 1, &node_of[p]);
  }
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(nodes, NDOF, c.ncliques, c.ptr, c.nodes, &A), MICA_SUCCESS);
  double *g = malloc((size_t)(size * NDOF) * sizeof *g), *K = malloc((size_t)(size * NDOF * size * NDOF) * sizeof *K);
  for (long q = 0; q < c.ncliques; q++) {
    const long count = c.ptr[q + 1] - c.ptr[q], m = count * NDOF;
    for (long i = 0; i < m; i++) g[i] = mica_random_uniform(rng) - 0.5;
    for (long i = 0; i < m; i++)
      for (long j = 0; j < m; j++) K[i * m + j] = count == 1 ? (i == j) : g[i] * g[j];
    assert_int_equal(mica_sparse_add_clique(A, count, c.nodes + c.ptr[q], K), MICA_SUCCESS);
  }
  free(g);
  free(K);
  cliques_free(&c);
  return A;
}

/* The flops of CHOLMOD's own choice on A's unknowns (AMD; METIS when AMD fills much): what the solver did before
 * it ordered the node graph. */
static double cholmod_default_flops(const MicaSparse *A) {
  cholmod_common common;
  cholmod_l_start(&common);
  common.print = 0;
  cholmod_sparse view;
  memset(&view, 0, sizeof view);
  view.nrow = view.ncol = (size_t)A->n;
  view.nzmax = (size_t)A->nnz;
  view.p = A->colptr, view.i = A->rowind, view.x = A->val;
  view.stype = 1, view.itype = CHOLMOD_LONG, view.xtype = CHOLMOD_REAL, view.dtype = CHOLMOD_DOUBLE;
  view.sorted = view.packed = 1;
  cholmod_factor *L = cholmod_l_analyze(&view, &common);
  assert_non_null(L);
  const double flops = common.fl;
  cholmod_l_free_factor(&L, &common);
  cholmod_l_finish(&common);
  return flops;
}

/* Numbered along the box's axes, the supports several nodes wide make A banded, and the natural order needs
 * fewer flops than AMD on the unknowns (the 13³ quadratic MLS cube: 3.2e10 against 7.6e10): the solver must
 * find it. Numbered at random, the natural order is the worst there is and AMD or METIS must win, within 20 %
 * of CHOLMOD's own choice (the node graph and the unknowns' graph are different inputs to the heuristics). */
static void test_cholmod_node_ordering(void **state) {
  (void)state;
  enum { SIDE = 9, REACH = 2 };
  const long nodes = SIDE * SIDE * SIDE;
  long node_of[SIDE * SIDE * SIDE];
  MicaRandom rng = mica_random_seed(5);
  for (int shuffled = 0; shuffled < 2; shuffled++) {
    for (long p = 0; p < nodes; p++) node_of[p] = p;
    for (long p = nodes - 1; shuffled && p > 0; p--) { /* Fisher–Yates */
      long q = (long)(mica_random_uniform(&rng) * (double)(p + 1)), t = node_of[p];
      if (q > p) q = p;
      node_of[p] = node_of[q], node_of[q] = t;
    }
    MicaSparse *A = box_pattern(SIDE, REACH, node_of, &rng);
    double *b = random_vector(A->n, 3), *x = calloc((size_t)A->n, sizeof *x);
    MicaLinearSolver *solver = NULL;
    assert_int_equal(mica_linear_solver_create(&mica_linear_cholmod, &solver), MICA_SUCCESS);
    factor_solve_check(solver, A, b, x);
    const double reference = cholmod_default_flops(A);
    print_message("  %s numbering: %s, %.3g flops; CHOLMOD's default %.3g\n", shuffled ? "random" : "axes",
                  solver->stats.ordering, solver->stats.flops, reference);
    if (!shuffled) {
      assert_string_equal(solver->stats.ordering, "natural");
      assert_true(solver->stats.flops < reference);
    } else {
      assert_string_not_equal(solver->stats.ordering, "natural");
      assert_true(solver->stats.flops <= 1.2 * reference);
    }
    mica_linear_solver_destroy(&solver);
    mica_sparse_destroy(&A);
    free(b);
    free(x);
  }
}

/* ---- Indefinite and singular -------------------------------------------------------------------------- */

/* [K Bᵀ; B 0]: K the 1-D chain Laplacian with shift on nodes 0..m-1, multiplier nodes m, m+1 enforcing
 * u_0 = 0 and u_{m-1} - u_{m-2} = 0. Symmetric, nonsingular, indefinite. */
static MicaSparse *saddle_point(long m) {
  Cliques c;
  cliques_alloc(&c, m + 2, m + 2, 2 * m + 8);
  for (long i = 0; i + 1 < m; i++) cliques_add(&c, 2, (long[]){i, i + 1});
  cliques_add(&c, 2, (long[]){0, m});
  cliques_add(&c, 3, (long[]){m - 2, m - 1, m + 1});
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(m + 2, 1, c.ncliques, c.ptr, c.nodes, &A), MICA_SUCCESS);
  for (long i = 0; i + 1 < m; i++)
    assert_int_equal(mica_sparse_add_clique(A, 2, (long[]){i, i + 1}, (double[]){1.1, -1, -1, 1.1}), MICA_SUCCESS);
  assert_int_equal(mica_sparse_add_clique(A, 2, (long[]){0, m}, (double[]){0, 1, 1, 0}), MICA_SUCCESS);
  const double tie[9] = {0, 0, -1, 0, 0, 1, -1, 1, 0};
  assert_int_equal(mica_sparse_add_clique(A, 3, (long[]){m - 2, m - 1, m + 1}, tie), MICA_SUCCESS);
  cliques_free(&c);
  return A;
}

static void test_indefinite(void **state) {
  (void)state;
  MicaSparse *A = saddle_point(40);
  double *b = random_vector(A->n, 3), *x = calloc((size_t)A->n, sizeof *x);
  MicaLinearSolver *cholmod = NULL, *umfpack = NULL;
  assert_int_equal(mica_linear_solver_create(&mica_linear_cholmod, &cholmod), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_factor(cholmod, A), MICA_ERR_NUMERIC);
  assert_non_null(strstr(mica_error_message(), "not positive definite"));
  assert_non_null(strstr(mica_error_message(), "umfpack"));
  assert_int_equal(cholmod->stats.factorizations, 0);
  assert_int_equal(mica_linear_solver_solve(cholmod, b, x), MICA_ERR_ARGUMENT); /* nothing to solve with */
  mica_error_clear();
  /* the same solver recovers on a positive definite matrix with another pattern */
  MicaSparse *G = grid_pattern(0);
  grid_values(G, 1.0, 0.1);
  double *g = random_vector(G->n, 5), *y = calloc((size_t)G->n, sizeof *y);
  factor_solve_check(cholmod, G, g, y);
  assert_int_equal(mica_linear_solver_create(&mica_linear_umfpack, &umfpack), MICA_SUCCESS);
  factor_solve_check(umfpack, A, b, x);
  mica_linear_solver_destroy(&cholmod);
  mica_linear_solver_destroy(&umfpack);
  mica_sparse_destroy(&A);
  mica_sparse_destroy(&G);
  free(b);
  free(x);
  free(g);
  free(y);
}

/* The grid with the coupling of one node zeroed: its row and column are in the pattern but all zero. */
static void test_singular(void **state) {
  (void)state;
  MicaSparse *A = grid_pattern(0);
  grid_values(A, 1.0, 0.1);
  long isolated = GRID * GRID / 2 + GRID / 2;
  for (long j = 0; j < A->n; j++)
    for (long p = A->colptr[j]; p < A->colptr[j + 1]; p++)
      if (j == isolated || A->rowind[p] == isolated) A->val[p] = 0.0;
  double *b = random_vector(A->n, 9), *x = calloc((size_t)A->n, sizeof *x);
  MicaLinearSolver *umfpack = NULL, *cholmod = NULL;
  assert_int_equal(mica_linear_solver_create(&mica_linear_umfpack, &umfpack), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_factor(umfpack, A), MICA_ERR_NUMERIC);
  assert_non_null(strstr(mica_error_message(), "singular"));
  assert_int_equal(mica_linear_solver_solve(umfpack, b, x), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_linear_solver_create(&mica_linear_cholmod, &cholmod), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_factor(cholmod, A), MICA_ERR_NUMERIC);
  char column[32]; /* the message names the zero column in A's numbering, not CHOLMOD's permuted one */
  snprintf(column, sizeof column, "column %ld)", isolated);
  if (!strstr(mica_error_message(), column)) fail_msg("\"%s\" lacks \"%s\"", mica_error_message(), column);
  mica_error_clear();
  mica_linear_solver_destroy(&umfpack);
  mica_linear_solver_destroy(&cholmod);
  mica_sparse_destroy(&A);
  free(b);
  free(x);
}

/* ---- Registry and contract ---------------------------------------------------------------------------- */

/* cholmod-sym: a mildly unsymmetric matrix (skew 0.05 per edge) is solved to the residual of the direct solvers
 * and agrees with UMFPACK; a strongly unsymmetric one (skew 5: ‖S⁻¹W‖ > 1) is refused with MICA_ERR_NUMERIC, as
 * is one whose symmetric part is indefinite (a negative shift). */
static void test_cholmod_sym(void **state) {
  (void)state;
  MicaSparse *A = grid_pattern(0);
  double *b = random_vector(A->n, 11), *x = calloc((size_t)A->n, sizeof *x), *y = calloc((size_t)A->n, sizeof *y);
  MicaLinearSolver *sym = NULL, *lu = NULL;
  assert_int_equal(mica_linear_solver_create(&mica_linear_cholmod_sym, &sym), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_create(&mica_linear_umfpack, &lu), MICA_SUCCESS);
  /* a symmetric A is its own symmetric part: S⁻¹ b is the answer, and the refinement has nothing left to do
   * (a wrong mirror position in S would leave it iterating, or failing) */
  grid_values(A, 1.0, 0.01);
  factor_solve_check(sym, A, b, x);
  print_message("  cholmod-sym on a symmetric matrix: %ld iterations\n", sym->stats.krylov_iterations);
  assert_true(sym->stats.krylov_iterations <= 1);
  const long iterations_before = sym->stats.krylov_iterations;
  grid_skew_values(A, 0.05);
  assert_true(mica_sparse_asymmetry(A) > 1e-2);
  factor_solve_check(sym, A, b, x);
  assert_true(sym->stats.krylov_iterations > iterations_before);
  factor_solve_check(lu, A, b, y);
  double d = 0, n = 0;
  for (long i = 0; i < A->n; i++) d = fmax(d, fabs(x[i] - y[i])), n = fmax(n, fabs(y[i]));
  print_message("  cholmod-sym: %ld iterations, max |x - x_umfpack| / max |x| %.2e\n", sym->stats.krylov_iterations,
                d / n);
  assert_true(d <= 1e-8 * n);
  assert_true(sym->stats.krylov_iterations >= 1 && sym->stats.krylov_residual <= 1e-10);
  grid_skew_values(A, 5.0);
  assert_int_equal(mica_linear_solver_factor(sym, A), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_solve(sym, b, x), MICA_ERR_NUMERIC);
  assert_non_null(strstr(mica_error_message(), "umfpack"));
  mica_error_clear();
  grid_values(A, 1.0, -0.5);
  assert_int_equal(mica_linear_solver_factor(sym, A), MICA_ERR_NUMERIC);
  mica_error_clear();
  /* a pattern without the mirror of (0, 1) */
  long colptr[3] = {0, 1, 3}, rowind[3] = {0, 0, 1};
  double val[3] = {2.0, 0.5, 2.0};
  MicaSparse lopsided = {.n = 2, .nnz = 3, .ndof = 1, .colptr = colptr, .rowind = rowind, .val = val};
  assert_int_equal(mica_linear_solver_factor(sym, &lopsided), MICA_ERR_ARGUMENT);
  assert_non_null(strstr(mica_error_message(), "not symmetric"));
  mica_error_clear();
  assert_int_equal(mica_linear_solver_destroy(&sym), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_destroy(&lu), MICA_SUCCESS);
  mica_sparse_destroy(&A);
  free(b), free(x), free(y);
}

static void test_registry_and_arguments(void **state) {
  (void)state;
  assert_ptr_equal(mica_linear_solver_find("cholmod"), &mica_linear_cholmod);
  assert_ptr_equal(mica_linear_solver_find("umfpack"), &mica_linear_umfpack);
  assert_ptr_equal(mica_linear_solver_find("cholmod-sym"), &mica_linear_cholmod_sym);
  assert_null(mica_linear_solver_find("mumps"));
  assert_null(mica_linear_solver_find(NULL));
  MicaLinearSolver *solver = NULL;
  assert_int_equal(mica_linear_solver_create(NULL, &solver), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_linear_solver_create(&mica_linear_cholmod, &solver), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_factor(solver, NULL), MICA_ERR_ARGUMENT);
  double b[1] = {1}, x[1];
  assert_int_equal(mica_linear_solver_solve(solver, b, x), MICA_ERR_ARGUMENT);
  mica_error_clear();
  assert_int_equal(mica_linear_solver_destroy(&solver), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_destroy(&solver), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_destroy(NULL), MICA_SUCCESS);
}

/* ---- PETSc: the tangent's values by position (src/solve/petsc_fill.c) ------------------------------------ */

/* One pattern, three sets of values, MUMPS on one process: the residual is taken with mica's own matrix, so a value
 * put at a wrong position of PETSc's copy fails it. Symmetric values (each column copied as its row) and skew ones
 * (the transposed walk). */
static void check_petsc_rounds(int spd) {
  MicaSparse *A = grid_pattern(0);
  double *b = random_vector(A->n, 5), *x = calloc((size_t)A->n, sizeof *x);
  MicaLinearSolver *solver = NULL;
  assert_int_equal(mica_linear_solver_create(&mica_linear_petsc, &solver), MICA_SUCCESS);
  MicaKrylovOptions k = {0};
  k.spd = spd;
  snprintf(k.petsc_preset, sizeof k.petsc_preset, "mumps");
  assert_int_equal(mica_linear_solver_set_krylov(solver, &k), MICA_SUCCESS);
  const double skew[3] = {0.3, 0.9, 0.05};
  for (int round = 0; round < 3; round++) {
    if (spd) grid_values(A, 1.0 + round, 0.01 * (round + 1));
    else grid_skew_values(A, skew[round]);
    factor_solve_check(solver, A, b, x);
  }
  assert_int_equal(solver->stats.analyses, 1);
  MicaSparse *B = grid_pattern(1); /* a new pattern: made anew */
  grid_values(B, 1.0, 0.1);
  factor_solve_check(solver, B, b, x);
  assert_int_equal(solver->stats.analyses, 2);
  mica_linear_solver_destroy(&solver);
  mica_sparse_destroy(&A);
  mica_sparse_destroy(&B);
  free(b);
  free(x);
}

static void test_petsc_symmetric_values(void **state) {
  (void)state;
  check_petsc_rounds(1);
}

static void test_petsc_unsymmetric_values(void **state) {
  (void)state;
  check_petsc_rounds(0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_petsc_symmetric_values), cmocka_unit_test(test_petsc_unsymmetric_values),
      cmocka_unit_test(test_cholmod_spd), cmocka_unit_test(test_umfpack_spd),
      cmocka_unit_test(test_random_blocks), cmocka_unit_test(test_indefinite), cmocka_unit_test(test_singular),
      cmocka_unit_test(test_cholmod_sym), cmocka_unit_test(test_cholmod_node_ordering),
      cmocka_unit_test(test_registry_and_arguments),
  };
  int failed = cmocka_run_group_tests(tests, NULL, NULL);
  mica_petsc_finalize();
  return failed;
}
