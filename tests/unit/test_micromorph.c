/* The gradient micromorph field model (χ = F): s against central differences of W and D against central
 * differences of s, for every micro energy and micro-space dimension in 2-D and 3-D; and, with the linear
 * micro energy, equality with first strain-gradient elasticity with l_K²/12 per micro axis:
 *   W = ½ ε:C:ε + ½ Σ_K (l_K²/12) ∂_K ε : C : ∂_K ε,   ε = sym ∇u. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "mica/model.h"

#include "field_check.h"

static void make_model(MicaFieldModel *m, int dim, const MicaModelOps *micro, const double *sizes) {
  MicaMaterial mat;
  assert_int_equal(mica_material_set(micro, 1000.0, 0.3, dim == 2 ? MICA_PLANE_STRAIN : MICA_PLANE_NONE, &mat), 0);
  assert_int_equal(mica_micromorph_set(m, dim, micro, &mat, sizes), 0);
}

static void test_tangents_match_finite_differences(void **state) {
  (void)state;
  const MicaModelOps *micro[] = {&mica_model_linear, &mica_model_svk, &mica_model_neohooke, &mica_model_neohooke_cook};
  const double sizes_list[][3] = {{0, 0.5, 0}, {0.3, 0.7, 0}, {0.4, 0.2, 0.6}};
  uint64_t rng = 11;
  double worst_s = 0, worst_d = 0;
  for (int dim = 2; dim <= 3; dim++)
    for (size_t e = 0; e < sizeof micro / sizeof *micro; e++)
      for (int k = 0; k < 3; k++) {
        if (dim == 2 && k == 2) continue;
        MicaFieldModel m;
        make_model(&m, dim, micro[e], sizes_list[k]);
        double q[64];
        random_q(mica_field_model_nq(&m, dim), 0.1, &rng, q);
        double es, ed;
        check_derivatives(&m, dim, q, &es, &ed);
        worst_s = fmax(worst_s, es), worst_d = fmax(worst_d, ed);
      }
  printf("micromorph: |s - dW| %.2e, |D - ds| %.2e (relative to max)\n", worst_s, worst_d);
  assert_true(worst_s < 1e-7);
  assert_true(worst_d < 1e-6);
}

/* ε:C:ε for the plane-strain / 3-D isotropic C with λ, μ. */
static double strain_energy2(int dim, double lambda, double mu, const double *e) {
  double tr = 0, ee = 0;
  for (int i = 0; i < dim; i++) tr += e[i * dim + i];
  for (int i = 0; i < dim * dim; i++) ee += e[i] * e[i];
  return lambda * tr * tr + 2 * mu * ee;
}

static void test_linear_micro_energy_is_strain_gradient(void **state) {
  (void)state;
  uint64_t rng = 3;
  double worst = 0;
  for (int dim = 2; dim <= 3; dim++) {
    const double sizes[3] = {0.3, 0.8, dim == 3 ? 0.5 : 0};
    MicaFieldModel m;
    make_model(&m, dim, &mica_model_linear, sizes);
    const int nq = mica_field_model_nq(&m, dim), nh = dim * (dim + 1) / 2, hess0 = dim * (1 + dim);
    double q[64], W;
    random_q(nq, 0.05, &rng, q);
    assert_int_equal(m.ops->eval(&m, dim, q, &W, NULL, NULL), 0);
    /* ε = sym ∇u; ∂_K ε_ij = sym(u_i,jK) */
    double eps[9], expected;
    for (int i = 0; i < dim; i++)
      for (int j = 0; j < dim; j++) eps[i * dim + j] = 0.5 * (q[dim + i * dim + j] + q[dim + j * dim + i]);
    expected = 0.5 * strain_energy2(dim, m.material.lambda, m.material.mu, eps);
    for (int K = 0; K < dim; K++) {
      double deps[9];
      for (int i = 0; i < dim; i++)
        for (int j = 0; j < dim; j++) {
          const int hij = j == K ? j : (dim == 2 ? 2 : 6 - j - K), hji = i == K ? i : (dim == 2 ? 2 : 6 - i - K);
          deps[i * dim + j] = 0.5 * (q[hess0 + i * nh + hij] + q[hess0 + j * nh + hji]);
        }
      expected += 0.5 * sizes[K] * sizes[K] / 12 * strain_energy2(dim, m.material.lambda, m.material.mu, deps);
    }
    worst = fmax(worst, fabs(W - expected) / fabs(expected));
  }
  printf("micromorph (linear micro energy) vs strain gradient with l^2/12: relative difference %.2e\n", worst);
  assert_true(worst < 1e-12);
}

/* Strain-gradient and couple-stress kernels: s and D against differences (D comes from polarization). */
static void test_gradient_models_match_finite_differences(void **state) {
  (void)state;
  uint64_t rng = 29;
  double worst_s = 0, worst_d = 0;
  for (int dim = 2; dim <= 3; dim++)
    for (int couple = 0; couple <= 1; couple++) {
      MicaMaterial mat;
      MicaFieldModel m;
      assert_int_equal(mica_material_set(&mica_model_linear, 1000.0, 0.25, dim == 2 ? MICA_PLANE_STRAIN : MICA_PLANE_NONE,
                                         &mat), 0);
      assert_int_equal(mica_strain_gradient_set(&m, &mat, 0.3, couple), 0);
      double q[64], es, ed;
      random_q(mica_field_model_nq(&m, dim), 0.1, &rng, q);
      check_derivatives(&m, dim, q, &es, &ed);
      worst_s = fmax(worst_s, es), worst_d = fmax(worst_d, ed);
    }
  printf("strain gradient / couple stress: |s - dW| %.2e, |D - ds| %.2e\n", worst_s, worst_d);
  assert_true(worst_s < 1e-7);
  assert_true(worst_d < 1e-6);
}

static void test_bad_micro_size(void **state) {
  (void)state;
  MicaFieldModel m;
  MicaMaterial mat;
  assert_int_equal(mica_material_set(&mica_model_linear, 1.0, 0.3, MICA_PLANE_STRAIN, &mat), 0);
  const double sizes[3] = {-1, 0.5, 0};
  assert_int_equal(mica_micromorph_set(&m, 2, &mica_model_linear, &mat, sizes), MICA_ERR_INPUT);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tangents_match_finite_differences),
      cmocka_unit_test(test_linear_micro_energy_is_strain_gradient),
      cmocka_unit_test(test_gradient_models_match_finite_differences),
      cmocka_unit_test(test_bad_micro_size),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
