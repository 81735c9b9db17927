/* mica_nonlinear_solve on problems given by callbacks alone (no solid): the scalar equations u³ + u = 2t per
 * unknown (root u = 1 at t = 1, quadratic convergence), an affine problem 2u = 2t (one assembly per step, the
 * residual after the solve taken from the tangent), the fallback solver replacing a preferred one that refuses
 * the tangent, and the problem's own error when the first factorization fails. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "mica/newton.h"

typedef struct {
  int cubic; /* 1: u³ + u − 2t; 0: 2u − 2t */
} Toy;

static int toy_residual(void *ctx, double t, const double *u, double *R, MicaSparse *K) {
  const Toy *toy = ctx;
  for (long i = 0; i < 2; i++) {
    R[i] = toy->cubic ? u[i] * u[i] * u[i] + u[i] - 2 * t : 2 * u[i] - 2 * t;
    if (K) K->val[K->colptr[i]] = toy->cubic ? 3 * u[i] * u[i] + 1 : 2;
  }
  return MICA_SUCCESS;
}

/* A direct solver that refuses every matrix, as CHOLMOD refuses an indefinite one. */
static int refuse_create(MicaLinearSolver *s) { (void)s; return MICA_SUCCESS; }
static int refuse_factor(MicaLinearSolver *s, const MicaSparse *A) {
  (void)s, (void)A;
  MICA_ERROR(MICA_ERR_NUMERIC, "refused");
}
static int refuse_solve(MicaLinearSolver *s, const double *b, double *x) { (void)s, (void)b, (void)x; return 0; }
static void refuse_destroy(MicaLinearSolver *s) { (void)s; }
static const MicaLinearSolverOps refusing = {{.name = "refusing"}, refuse_create, refuse_factor, refuse_solve, refuse_destroy};

static int explained(void *ctx) {
  (void)ctx;
  MICA_ERROR(MICA_ERR_INPUT, "explained by the problem");
}

static MicaSparse *diagonal(void) {
  const long ptr[] = {0, 1, 2}, nodes[] = {0, 1};
  MicaSparse *K = NULL;
  assert_int_equal(mica_sparse_create(2, 1, 2, ptr, nodes, &K), MICA_SUCCESS);
  return K;
}

static MicaNewtonOptions options(void) {
  MicaNewtonOptions opt;
  memset(&opt, 0, sizeof opt);
  opt.steps = 2, opt.max_iterations = 20, opt.rtol = 1e-12, opt.atol = 1e-14, opt.max_cuts = 2;
  return opt;
}

static MicaNonlinearProblem problem(Toy *toy, MicaSparse *K) {
  return (MicaNonlinearProblem){.n = 2, .ctx = toy, .residual = toy_residual, .K = K, .affine = !toy->cubic,
                                .linear_preferred = &mica_linear_umfpack};
}

static void test_cubic_converges(void **state) {
  (void)state;
  Toy toy = {1};
  MicaSparse *K = diagonal();
  MicaNonlinearProblem p = problem(&toy, K);
  MicaNewtonOptions opt = options();
  MicaNewtonStats st;
  double u[2] = {0, 0};
  assert_int_equal(mica_nonlinear_solve(&p, &opt, u, NULL, NULL, &st), MICA_SUCCESS);
  assert_true(fabs(u[0] - 1) < 1e-12 && fabs(u[1] - 1) < 1e-12);
  assert_int_equal(st.steps_done, 2);
  assert_string_equal(st.linear_name, "umfpack");
  assert_int_equal(st.residual_updates, 0);
  assert_true(st.iterations_total >= 4); /* a nonlinear root takes more than one iteration per step */
  mica_sparse_destroy(&K);
}

static void test_affine_one_assembly_per_step(void **state) {
  (void)state;
  Toy toy = {0};
  MicaSparse *K = diagonal();
  MicaNonlinearProblem p = problem(&toy, K);
  MicaNewtonOptions opt = options();
  MicaNewtonStats st;
  double u[2] = {0, 0};
  assert_int_equal(mica_nonlinear_solve(&p, &opt, u, NULL, NULL, &st), MICA_SUCCESS);
  assert_true(fabs(u[0] - 1) < 1e-14);
  assert_int_equal(st.assemblies, 2); /* one per load step: R after the solve is R + K du */
  assert_int_equal(st.residual_updates, 2);
  mica_sparse_destroy(&K);
}

static void test_fallback_replaces_refusing_solver(void **state) {
  (void)state;
  Toy toy = {1};
  MicaSparse *K = diagonal();
  MicaNonlinearProblem p = problem(&toy, K);
  p.linear_preferred = &refusing, p.linear_fallback = &mica_linear_umfpack;
  MicaNewtonOptions opt = options();
  MicaNewtonStats st;
  double u[2] = {0, 0};
  assert_int_equal(mica_nonlinear_solve(&p, &opt, u, NULL, NULL, &st), MICA_SUCCESS);
  assert_string_equal(st.linear_name, "umfpack");
  assert_true(fabs(u[0] - 1) < 1e-12);
  /* a solver named in the options has no fallback */
  opt.linear = &refusing;
  u[0] = u[1] = 0;
  assert_int_equal(mica_nonlinear_solve(&p, &opt, u, NULL, NULL, &st), MICA_ERR_NUMERIC);
  mica_error_clear();
  mica_sparse_destroy(&K);
}

static void test_first_factorization_explained_by_problem(void **state) {
  (void)state;
  Toy toy = {1};
  MicaSparse *K = diagonal();
  MicaNonlinearProblem p = problem(&toy, K);
  p.linear_preferred = &refusing, p.first_factor_failed = explained;
  MicaNewtonOptions opt = options();
  MicaNewtonStats st;
  double u[2] = {0, 0};
  assert_int_equal(mica_nonlinear_solve(&p, &opt, u, NULL, NULL, &st), MICA_ERR_INPUT);
  assert_non_null(strstr(mica_error_message(), "explained by the problem"));
  mica_error_clear();
  mica_sparse_destroy(&K);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_cubic_converges),
      cmocka_unit_test(test_affine_one_assembly_per_step),
      cmocka_unit_test(test_fallback_replaces_refusing_solver),
      cmocka_unit_test(test_first_factorization_explained_by_problem),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
