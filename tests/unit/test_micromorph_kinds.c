/* The gradient micromorph kinds χ = J^(−1/3) F (isochoric) and χ = R(Φ) (rotation), docs/theory.md §micromorph:
 *   - s against central differences of W and D against central differences of s at random finite states, for
 *     every micro energy, micro dimensions 1-3, 2-D and 3-D;
 *   - isochoric: a Hessian whose variation along the micro axis is a pure volume change (∂_n χ = 0) leaves exactly
 *     the classical energy ψ(F), while χ = F sees it; at q = 0, ½ qᵀDq is the strain-gradient energy of the
 *     deviatoric part of ∇∇u, g_n = sym(dev(∇∇u)·n) (derived in docs/theory.md);
 *   - rotation: objectivity (a superposed rotation Q: F → QF, R → QR leaves W unchanged); at q = 0, D equals the
 *     small-strain Cosserat D (src/models/cosserat.c) of λ, μ − κ_c/2, κ_c, α = −μ l²/12, β = −λ l²/12,
 *     γ = (λ + 3μ) l²/12 for a micro cube (2-D: square) of side l; a micro line along y gives
 *     ½ (l²/12) [(λ + 2μ) φ_,x² + μ φ_,y²];
 *   - bad input. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "mica/cosserat.h"
#include "mica/micromorph.h"
#include "mica/rotation.h"

#include "field_check.h"

static MicaMaterial material(const MicaModelOps *micro, int dim, double nu) {
  MicaMaterial mat;
  assert_int_equal(mica_material_set(micro, 1000.0, nu, dim == 2 ? MICA_PLANE_STRAIN : MICA_PLANE_NONE, &mat), 0);
  return mat;
}

static const MicaModelOps *const MICRO[] = {&mica_model_linear, &mica_model_svk, &mica_model_neohooke,
                                            &mica_model_neohooke_cook};
static const double SIZES[][3] = {{0, 0.5, 0}, {0.3, 0.7, 0}, {0.4, 0.2, 0.6}};

static void test_isochoric_tangents(void **state) {
  (void)state;
  uint64_t rng = 17;
  double worst_s = 0, worst_d = 0;
  for (int dim = 2; dim <= 3; dim++)
    for (int e = 0; e < 4; e++)
      for (int k = 0; k < 3; k++) {
        if (dim == 2 && k == 2) continue;
        const MicaMaterial mat = material(MICRO[e], dim, 0.3);
        MicaFieldModel m;
        assert_int_equal(mica_micromorph_isochoric_set(&m, dim, MICRO[e], &mat, SIZES[k]), 0);
        double q[64], es, ed;
        random_q(mica_field_model_nq(&m, dim), 0.15, &rng, q);
        check_derivatives(&m, dim, q, &es, &ed);
        worst_s = fmax(worst_s, es), worst_d = fmax(worst_d, ed);
      }
  printf("isochoric: |s - dW| %.2e, |D - ds| %.2e (relative to max)\n", worst_s, worst_d);
  assert_true(worst_s < 1e-7);
  assert_true(worst_d < 1e-6);
}

/* A state whose χ = J^(−1/3) F does not vary along the micro axis e_x: ∂_x χ_aJ... contracted with Y = y e_x,
 * ∂_K χ_a0 = 0, i.e. u_a,0K = ⅓ F_a0 t_K with t = ∇ ln J. With G_bJK (J, K ≥ 1) random, r_K = F⁻¹_Jb G_bJK over
 * J ≥ 1, the consistent t is t_0 = 0, t_K = 3/2 r_K (docs/theory.md). */
static void volume_gradient_state(int dim, uint64_t *rng, double *q) {
  const int nh = dim * (dim + 1) / 2, hess0 = dim * (1 + dim), nq = dim * (1 + dim) + dim * nh;
  double F[9], Finv[9], G[27] = {0}, t[3] = {0, 0, 0};
  random_q(nq, 0.2, rng, q);
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = (a == J) + q[dim + a * dim + J];
  if (dim == 2) {
    const double det = F[0] * F[3] - F[1] * F[2];
    Finv[0] = F[3] / det, Finv[1] = -F[1] / det, Finv[2] = -F[2] / det, Finv[3] = F[0] / det;
  } else {
    const double det = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                       F[2] * (F[3] * F[7] - F[4] * F[6]);
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < 3; k++) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        Finv[i * 3 + k] = (F[k1 * 3 + i1] * F[k2 * 3 + i2] - F[k1 * 3 + i2] * F[k2 * 3 + i1]) / det;
      }
  }
  for (int b = 0; b < dim; b++)
    for (int J = 1; J < dim; J++)
      for (int K = J; K < dim; K++) G[(b * dim + J) * dim + K] = G[(b * dim + K) * dim + J] = 0.3 * rnd(rng);
  for (int K = 1; K < dim; K++) {
    double r = 0;
    for (int J = 1; J < dim; J++)
      for (int b = 0; b < dim; b++) r += Finv[J * dim + b] * G[(b * dim + J) * dim + K];
    t[K] = 1.5 * r;
  }
  for (int b = 0; b < dim; b++)
    for (int K = 0; K < dim; K++) G[(b * dim + 0) * dim + K] = G[(b * dim + K) * dim + 0] = F[b * dim + 0] * t[K] / 3;
  for (int b = 0; b < dim; b++)
    for (int J = 0; J < dim; J++)
      for (int K = J; K < dim; K++) {
        const int h = J == K ? J : (dim == 2 ? 2 : 6 - J - K);
        q[hess0 + b * nh + h] = G[(b * dim + J) * dim + K];
      }
}

static void test_isochoric_ignores_volume_gradient(void **state) {
  (void)state;
  uint64_t rng = 5;
  double worst = 0, least_excess = 1e300;
  for (int dim = 2; dim <= 3; dim++)
    for (int trial = 0; trial < 5; trial++) {
      const MicaMaterial mat = material(&mica_model_svk, dim, 0.3);
      const double line[3] = {0.8, 0, 0};
      MicaFieldModel iso, full;
      assert_int_equal(mica_micromorph_isochoric_set(&iso, dim, &mica_model_svk, &mat, line), 0);
      assert_int_equal(mica_micromorph_set(&full, dim, &mica_model_svk, &mat, line), 0);
      double q[64], F[9], W_iso, W_full, psi;
      volume_gradient_state(dim, &rng, q);
      for (int a = 0; a < dim * dim; a++) F[a] = (a / dim == a % dim) + q[dim + a];
      assert_int_equal(mica_model_svk.eval(&mat, dim, F, &psi, NULL, NULL), 0);
      assert_int_equal(iso.ops->eval(&iso, dim, q, &W_iso, NULL, NULL), 0);
      assert_int_equal(full.ops->eval(&full, dim, q, &W_full, NULL, NULL), 0);
      /* χ = F sees u_a,xK: its excess over ψ(F) is the second variation of ψ at F, of the order of
       * (l²/12) μ |u_a,xK|² (0.09 of it at the least in these states); a lost micro term would give round-off */
      const int nh = dim * (dim + 1) / 2, hess0 = dim * (1 + dim);
      double scale = 0;
      for (int a = 0; a < dim; a++)
        for (int K = 0; K < dim; K++) scale += pow(q[hess0 + a * nh + (K == 0 ? 0 : dim == 2 ? 2 : 6 - K)], 2);
      scale *= line[0] * line[0] / 12 * mat.mu;
      worst = fmax(worst, fabs(W_iso - psi) / psi);
      least_excess = fmin(least_excess, (W_full - psi) / scale);
    }
  printf("volume gradient along the micro axis: isochoric |W - psi(F)|/psi %.2e; chi = F excess >= %.3f (l^2/12) mu |u_a,xK|^2\n", worst,
         least_excess);
  assert_true(worst < 1e-13);
  assert_true(least_excess > 0.01);
}

/* ε:C:ε for the isotropic C with λ, μ (dim × dim tensors, plane strain in 2-D). */
static double strain_energy2(int dim, double lambda, double mu, const double *e) {
  double tr = 0, ee = 0;
  for (int i = 0; i < dim; i++) tr += e[i * dim + i];
  for (int i = 0; i < dim * dim; i++) ee += e[i] * e[i];
  return lambda * tr * tr + 2 * mu * ee;
}

static double quadratic_form(int nq, const double *D, const double *q) {
  double w = 0;
  for (int i = 0; i < nq; i++)
    for (int j = 0; j < nq; j++) w += 0.5 * q[i] * D[i * nq + j] * q[j];
  return w;
}

/* At q = 0: ½ qᵀDq = ½ ε:C:ε + ½ Σ_n (l_n²/12) g_n:C:g_n, g_n = sym_aK(u_a,nK − ⅓ δ_an θ_,K), θ = div u. */
static void test_isochoric_small_strain(void **state) {
  (void)state;
  uint64_t rng = 23;
  double worst = 0;
  for (int dim = 2; dim <= 3; dim++)
    for (int k = 0; k < 3; k++) {
      if (dim == 2 && k == 2) continue;
      const MicaMaterial mat = material(&mica_model_linear, dim, 0.27);
      MicaFieldModel m;
      assert_int_equal(mica_micromorph_isochoric_set(&m, dim, &mica_model_linear, &mat, SIZES[k]), 0);
      const int nq = mica_field_model_nq(&m, dim), nh = dim * (dim + 1) / 2, hess0 = dim * (1 + dim);
      double zero[64] = {0}, D[64 * 64], q[64], G[27], eps[9], grad_theta[3] = {0, 0, 0};
      assert_int_equal(m.ops->eval(&m, dim, zero, NULL, NULL, D), 0);
      random_q(nq, 1.0, &rng, q);
      for (int b = 0; b < dim; b++)
        for (int J = 0; J < dim; J++)
          for (int K = 0; K < dim; K++)
            G[(b * dim + J) * dim + K] = q[hess0 + b * nh + (J == K ? J : (dim == 2 ? 2 : 6 - J - K))];
      for (int K = 0; K < dim; K++)
        for (int b = 0; b < dim; b++) grad_theta[K] += G[(b * dim + b) * dim + K];
      for (int i = 0; i < dim; i++)
        for (int j = 0; j < dim; j++) eps[i * dim + j] = 0.5 * (q[dim + i * dim + j] + q[dim + j * dim + i]);
      double expected = 0.5 * strain_energy2(dim, mat.lambda, mat.mu, eps);
      for (int n = 0; n < dim; n++) {
        if (SIZES[k][n] == 0) continue;
        double g[9], raw[9];
        for (int a = 0; a < dim; a++)
          for (int K = 0; K < dim; K++) raw[a * dim + K] = G[(a * dim + n) * dim + K] - (a == n) * grad_theta[K] / 3;
        for (int a = 0; a < dim; a++)
          for (int K = 0; K < dim; K++) g[a * dim + K] = 0.5 * (raw[a * dim + K] + raw[K * dim + a]);
        expected += 0.5 * SIZES[k][n] * SIZES[k][n] / 12 * strain_energy2(dim, mat.lambda, mat.mu, g);
      }
      worst = fmax(worst, fabs(quadratic_form(nq, D, q) - expected) / expected);
    }
  printf("isochoric at q = 0 vs the deviatoric strain-gradient energy: relative difference %.2e\n", worst);
  assert_true(worst < 1e-12);
}

static void test_rotation_tangents(void **state) {
  (void)state;
  uint64_t rng = 41;
  double worst_s = 0, worst_d = 0;
  for (int dim = 2; dim <= 3; dim++)
    for (int e = 0; e < 4; e++)
      for (int k = 0; k < 3; k++) {
        if (dim == 2 && k == 2) continue;
        const MicaMaterial mat = material(MICRO[e], dim, 0.3);
        MicaFieldModel m;
        assert_int_equal(mica_micromorph_rotation_set(&m, dim, MICRO[e], &mat, SIZES[k], 0.5), 0);
        const int nq = mica_field_model_nq(&m, dim), ncomp = dim == 2 ? 3 : 6;
        double q[64], es, ed;
        random_q(nq, 0.3, &rng, q);
        for (int c = dim; c < ncomp; c++) q[c] = 1.5 * rnd(&rng); /* finite rotations, |Φ| up to 2.6 */
        check_derivatives(&m, dim, q, &es, &ed);
        worst_s = fmax(worst_s, es), worst_d = fmax(worst_d, ed);
      }
  printf("rotation: |s - dW| %.2e, |D - ds| %.2e (relative to max)\n", worst_s, worst_d);
  assert_true(worst_s < 1e-7);
  assert_true(worst_d < 1e-6);
}

static void mat3_mul(const double *a, const double *b, double *c) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

/* x → Q x: F → QF, R → QR (Φ' = log(Q R)), and the material curvature Γ = T ∇Φ is unchanged, so
 * ∇Φ' = T(Φ')⁻¹ T(Φ) ∇Φ. W must not change (hyperelastic micro energies; the linear one is not objective). */
static void test_rotation_objectivity(void **state) {
  (void)state;
  uint64_t rng = 7;
  double worst = 0;
  for (int dim = 2; dim <= 3; dim++)
    for (int e = 1; e < 4; e++) {
      const MicaMaterial mat = material(MICRO[e], dim, 0.3);
      MicaFieldModel m;
      assert_int_equal(mica_micromorph_rotation_set(&m, dim, MICRO[e], &mat, SIZES[dim == 2 ? 1 : 2], 0.6), 0);
      const int nq = mica_field_model_nq(&m, dim), ncomp = dim == 2 ? 3 : 6;
      double q[64], qr[64], W, Wr;
      random_q(nq, 0.3, &rng, q);
      memcpy(qr, q, sizeof qr);
      const double omega[3] = {dim == 3 ? 0.4 : 0, dim == 3 ? -0.7 : 0, 1.1};
      MicaRotation Q, Rot, Rot2;
      mica_rotation_eval(omega, 0, &Q);
      double F3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, QF[9];
      for (int a = 0; a < dim; a++)
        for (int J = 0; J < dim; J++) F3[3 * a + J] += q[ncomp + a * dim + J];
      mat3_mul(Q.R, F3, QF);
      for (int a = 0; a < dim; a++)
        for (int J = 0; J < dim; J++) qr[ncomp + a * dim + J] = QF[3 * a + J] - (a == J);
      if (dim == 2) {
        qr[2] = q[2] + omega[2];
      } else {
        double phi[3] = {q[3], q[4], q[5]}, QR[9], phi2[3], grad[9], Gamma[9], Tinv_Gamma[9];
        mica_rotation_eval(phi, 0, &Rot);
        mat3_mul(Q.R, Rot.R, QR);
        mica_rotation_log(QR, phi2);
        mica_rotation_eval(phi2, 0, &Rot2);
        for (int k = 0; k < 3; k++)
          for (int L = 0; L < 3; L++) grad[3 * k + L] = q[ncomp + (3 + k) * 3 + L];
        mat3_mul(Rot.T, grad, Gamma);
        /* solve T(Φ') X = Γ by Cramer's rule, column by column */
        const double *T = Rot2.T;
        const double det = T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                           T[2] * (T[3] * T[7] - T[4] * T[6]);
        for (int L = 0; L < 3; L++)
          for (int i = 0; i < 3; i++) {
            double Ti[9];
            memcpy(Ti, T, sizeof Ti);
            for (int r = 0; r < 3; r++) Ti[3 * r + i] = Gamma[3 * r + L];
            Tinv_Gamma[3 * i + L] = (Ti[0] * (Ti[4] * Ti[8] - Ti[5] * Ti[7]) - Ti[1] * (Ti[3] * Ti[8] - Ti[5] * Ti[6]) +
                                     Ti[2] * (Ti[3] * Ti[7] - Ti[4] * Ti[6])) / det;
          }
        for (int k = 0; k < 3; k++) qr[3 + k] = phi2[k];
        for (int k = 0; k < 3; k++)
          for (int L = 0; L < 3; L++) qr[ncomp + (3 + k) * 3 + L] = Tinv_Gamma[3 * k + L];
      }
      assert_int_equal(m.ops->eval(&m, dim, q, &W, NULL, NULL), 0);
      assert_int_equal(m.ops->eval(&m, dim, qr, &Wr, NULL, NULL), 0);
      worst = fmax(worst, fabs(Wr - W) / W);
    }
  printf("rotation: superposed rigid rotation, |W' - W|/W %.2e\n", worst);
  assert_true(worst < 1e-12);
}

static void test_rotation_small_strain_is_cosserat(void **state) {
  (void)state;
  double worst = 0;
  for (int dim = 2; dim <= 3; dim++)
    for (int e = 0; e < 4; e++) {
      const double l = 0.7, s2 = l * l / 12, N = 0.4, box[3] = {l, l, dim == 3 ? l : 0};
      const MicaMaterial mat = material(MICRO[e], dim, 0.3);
      MicaFieldModel m, cos;
      assert_int_equal(mica_micromorph_rotation_set(&m, dim, MICRO[e], &mat, box, N), 0);
      const double lambda = mat.lambda, mu = mat.mu, kc = 2 * mu * N * N / (1 - N * N);
      assert_int_equal(mica_cosserat_set_eringen(&cos, dim, lambda, mu - kc / 2, kc, -mu * s2, -lambda * s2,
                                                 (lambda + 3 * mu) * s2), 0);
      const int nq = mica_field_model_nq(&m, dim);
      assert_int_equal(nq, mica_field_model_nq(&cos, dim));
      double zero[64] = {0}, D[64 * 64], Dc[64 * 64], dmax = 0, diff = 0;
      assert_int_equal(m.ops->eval(&m, dim, zero, NULL, NULL, D), 0);
      assert_int_equal(cos.ops->eval(&cos, dim, zero, NULL, NULL, Dc), 0);
      for (int i = 0; i < nq * nq; i++) dmax = fmax(dmax, fabs(Dc[i])), diff = fmax(diff, fabs(D[i] - Dc[i]));
      worst = fmax(worst, diff / dmax);
    }
  /* a micro line along y in 2-D: W = ½ (l²/12) [(λ + 2μ) φ_,x² + μ φ_,y²] for a pure rotation gradient */
  const double line[3] = {0, 0.9, 0}, s2 = 0.81 / 12;
  const MicaMaterial mat = material(&mica_model_svk, 2, 0.3);
  MicaFieldModel m;
  assert_int_equal(mica_micromorph_rotation_set(&m, 2, &mica_model_svk, &mat, line, 0.4), 0);
  double zero[64] = {0}, D[64 * 64], q[64] = {0};
  assert_int_equal(m.ops->eval(&m, 2, zero, NULL, NULL, D), 0);
  q[7] = 0.3, q[8] = -1.1; /* φ_,x, φ_,y */
  const double expected = 0.5 * s2 * ((mat.lambda + 2 * mat.mu) * 0.09 + mat.mu * 1.21);
  const double line_err = fabs(quadratic_form(9, D, q) - expected) / expected;
  printf("rotation at q = 0 vs small-strain Cosserat (micro square/cube): %.2e; micro line formula: %.2e\n", worst,
         line_err);
  assert_true(worst < 1e-12);
  assert_true(line_err < 1e-12);
}

static void test_bad_input(void **state) {
  (void)state;
  const MicaMaterial mat = material(&mica_model_svk, 2, 0.3);
  MicaFieldModel m;
  const double none[3] = {0, 0, 0}, line[3] = {0, 0.5, 0}, negative[3] = {-0.1, 0.5, 0};
  assert_int_equal(mica_micromorph_rotation_set(&m, 2, &mica_model_svk, &mat, none, 0.5), MICA_ERR_INPUT);
  assert_int_equal(mica_micromorph_rotation_set(&m, 2, &mica_model_svk, &mat, line, 1.0), MICA_ERR_INPUT);
  assert_int_equal(mica_micromorph_rotation_set(&m, 2, &mica_model_svk, &mat, negative, 0.5), MICA_ERR_INPUT);
  assert_int_equal(mica_micromorph_isochoric_set(&m, 2, &mica_model_svk, &mat, negative), MICA_ERR_INPUT);
  /* det F ≤ 0: a numerical error (Newton cuts the step), not a crash */
  assert_int_equal(mica_micromorph_isochoric_set(&m, 2, &mica_model_svk, &mat, line), 0);
  double q[64] = {0}, W;
  q[2] = -2.0; /* F_11 = −1 */
  assert_int_equal(m.ops->eval(&m, 2, q, &W, NULL, NULL), MICA_ERR_NUMERIC);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_isochoric_tangents),
      cmocka_unit_test(test_isochoric_ignores_volume_gradient),
      cmocka_unit_test(test_isochoric_small_strain),
      cmocka_unit_test(test_rotation_tangents),
      cmocka_unit_test(test_rotation_objectivity),
      cmocka_unit_test(test_rotation_small_strain_is_cosserat),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
