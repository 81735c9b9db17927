/* solver.linear = "cg" (src/solve/linear_cg.c) on block matrices assembled like a stiffness: 200 nodes with 3
 * unknowns each, cliques of 4 consecutive nodes with random SPD element matrices (B Bᵀ + I). Checks: cg with
 * block Jacobi and with symmetric block Gauss–Seidel gives CHOLMOD's solution to 1e-8 relative at rtol 1e-12;
 * the reported true residual is ≤ rtol; Gauss–Seidel needs fewer iterations than Jacobi; a zero right-hand
 * side gives x = 0 in 0 iterations; an indefinite matrix and too few iterations give MICA_ERR_NUMERIC. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mica/random.h"
#include "mica/sparse.h"

enum { NODES = 200, NDOF = 3, CLIQUE = 4, M = CLIQUE * NDOF, N = NODES * NDOF };

/* The pattern of the chain of cliques {c, c+1, c+2, c+3}, values: Σ random SPD element matrices; sign −1 on
 * the element at the middle makes the sum indefinite. */
static MicaSparse *chain_matrix(double middle_sign) {
  long ptr[NODES], nodes[NODES * CLIQUE], ncliques = NODES - CLIQUE + 1;
  for (long c = 0; c <= ncliques; c++) ptr[c] = c * CLIQUE;
  for (long c = 0; c < ncliques; c++)
    for (int k = 0; k < CLIQUE; k++) nodes[c * CLIQUE + k] = c + k;
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(NODES, NDOF, ncliques, ptr, nodes, &A), MICA_SUCCESS);
  MicaRandom rng = mica_random_seed(7);
  double B[M * M], K[M * M];
  for (long c = 0; c < ncliques; c++) {
    for (int i = 0; i < M * M; i++) B[i] = mica_random_uniform(&rng) - 0.5;
    const double sign = c == ncliques / 2 ? middle_sign * 50 : 1.0;
    for (int i = 0; i < M; i++)
      for (int j = 0; j < M; j++) {
        double s = i == j ? 1.0 : 0.0;
        for (int k = 0; k < M; k++) s += B[i * M + k] * B[j * M + k];
        K[i * M + j] = sign * s;
      }
    assert_int_equal(mica_sparse_add_clique(A, CLIQUE, nodes + c * CLIQUE, K), MICA_SUCCESS);
  }
  return A;
}

static void solve_with(const MicaLinearSolverOps *ops, const MicaKrylovOptions *opt, const MicaSparse *A,
                       const double *b, double *x, MicaLinearSolverStats *stats) {
  MicaLinearSolver *solver = NULL;
  assert_int_equal(mica_linear_solver_create(ops, &solver), MICA_SUCCESS);
  if (opt) assert_int_equal(mica_linear_solver_set_krylov(solver, opt), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_factor(solver, A), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_solve(solver, b, x), MICA_SUCCESS);
  if (stats) *stats = solver->stats;
  mica_linear_solver_destroy(&solver);
}

static void test_cg_equals_cholmod(void **state) {
  (void)state;
  MicaSparse *A = chain_matrix(1.0);
  double b[N], x_ref[N], x[N];
  for (int i = 0; i < N; i++) b[i] = sin(0.1 * i) + 0.3;
  solve_with(&mica_linear_cholmod, NULL, A, b, x_ref, NULL);
  long iterations[2];
  for (int kind = 0; kind < 2; kind++) {
    MicaKrylovOptions opt = {1e-12, 5000, kind ? MICA_PRECONDITIONER_SGS : MICA_PRECONDITIONER_JACOBI, 0};
    MicaLinearSolverStats st;
    solve_with(&mica_linear_cg, &opt, A, b, x, &st);
    double diff = 0, norm = 0;
    for (int i = 0; i < N; i++) diff += (x[i] - x_ref[i]) * (x[i] - x_ref[i]), norm += x_ref[i] * x_ref[i];
    assert_true(sqrt(diff / norm) < 1e-8);
    assert_true(st.krylov_residual <= 1e-12);
    assert_true(st.krylov_iterations > 1);
    iterations[kind] = st.krylov_iterations;
  }
  assert_true(iterations[1] < iterations[0]);
  mica_sparse_destroy(&A);
}

static void test_cg_zero_rhs(void **state) {
  (void)state;
  MicaSparse *A = chain_matrix(1.0);
  double b[N] = {0}, x[N];
  for (int i = 0; i < N; i++) x[i] = 1.0;
  MicaLinearSolverStats st;
  solve_with(&mica_linear_cg, NULL, A, b, x, &st);
  for (int i = 0; i < N; i++) assert_true(x[i] == 0.0);
  assert_int_equal(st.krylov_iterations, 0);
  mica_sparse_destroy(&A);
}

static void expect_numeric(const MicaSparse *A, const MicaKrylovOptions *opt) {
  double b[N], x[N];
  for (int i = 0; i < N; i++) b[i] = 1.0;
  MicaLinearSolver *solver = NULL;
  assert_int_equal(mica_linear_solver_create(&mica_linear_cg, &solver), MICA_SUCCESS);
  assert_int_equal(mica_linear_solver_set_krylov(solver, opt), MICA_SUCCESS);
  int ierr = mica_linear_solver_factor(solver, A);
  if (!ierr) ierr = mica_linear_solver_solve(solver, b, x);
  assert_int_equal(ierr, MICA_ERR_NUMERIC);
  mica_error_clear();
  mica_linear_solver_destroy(&solver);
}

static void test_cg_refuses(void **state) {
  (void)state;
  MicaSparse *indefinite = chain_matrix(-1.0), *spd = chain_matrix(1.0);
  MicaKrylovOptions opt = {1e-10, 5000, MICA_PRECONDITIONER_JACOBI, 0};
  expect_numeric(indefinite, &opt);
  opt.max_iterations = 2;
  expect_numeric(spd, &opt);
  mica_sparse_destroy(&indefinite);
  mica_sparse_destroy(&spd);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_cg_equals_cholmod),
      cmocka_unit_test(test_cg_zero_rhs),
      cmocka_unit_test(test_cg_refuses),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
