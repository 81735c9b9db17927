/* Unit tests of the finite-rotation Cosserat field model (src/models/cosserat_finite.c, mica/cosserat.h).
 *
 * What is checked, and against what:
 * - s = ∂W/∂q against central differences of W and D = ∂s/∂q against central differences of s, at random
 *   finite states (|∇u| up to 0.4, 3-D |Φ| up to 3 and one below the Taylor-series switch, 2-D φ up to ±9,
 *   i.e. beyond 2π), four constant sets, 2-D and 3-D; D symmetric.
 * - Objectivity: a superposed rotation Q (F → QF, R → QR with Φ' = log(Q R(Φ)) and ∇Φ' by central
 *   differences of that log map, independent of T) leaves W unchanged. A rigid rotation (F = R(Φ), ∇Φ = 0)
 *   has W = 0 and s = 0, in 2-D also at φ = 7 > 2π.
 * - Linearization: D at q = 0 is the small-strain Cosserat D (mica_field_cosserat) to 1e-12.
 * - 2-D: φ and φ + 2π give the same W, s, D (the total rotation is path independent).
 * - stress(): σ = J⁻¹ F Pᵀ with P_lK = ∂W/∂u_l,K the gradient slots of s, and at small q the small-strain σ, m.
 * - Bad input: the small-strain setters' errors (the constants are shared), switching a non-Cosserat model,
 *   3-D |Φ| ≥ 2π (MICA_ERR_NUMERIC).
 *
 * Tolerances. W is smooth; with FD_STEP = 1e-6 on entries of order 1 the truncation error is ≈ h² |W'''| ≈
 * 1e-12 and rounding ≈ 1e-16 |W| / h ≈ 1e-10 relative: accepted at FD_TOL = 1e-6 relative to max|s| (max|D|),
 * as the brief asks. Identities exact in exact arithmetic are checked to EXACT_TOL = 1e-12 relative.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "mica/cosserat.h"
#include "mica/model.h"
#include "mica/random.h"
#include "mica/rotation.h"

#define FD_STEP 1e-6
#define FD_TOL 1e-6
#define EXACT_TOL 1e-12
#define NUM_RANDOM 12
#define NQ_MAX 24
#define TWO_PI 6.283185307179586

typedef struct {
  const char *name;
  int dim;
  int technical; /* p = G, ν, N, l_t, l_b, Ψ; else p = λ, μ, κ, α, β, γ */
  double p[6];
} ConstCase;

static const ConstCase cases[] = {
    {"plate with a hole example, 2-D", 2, 1, {1000.0, 0.3, 0.93, 1.0 / 1.063, 1.0 / 1.063, 1.0}},
    {"glide layer, 2-D", 2, 0, {1.0, -1.0, 6.0, 0.0, 0.0, 1.2}},
    {"bone (Lakes, ν = 0.3), 3-D", 3, 1, {3.5e3, 0.3, 0.62, 0.22, 0.44, 1.5}},
    {"generic Eringen, 3-D", 3, 0, {1.3, 0.7, 0.9, 0.4, -0.2, 0.8}},
};
#define NUM_CASES ((int)(sizeof cases / sizeof cases[0]))

/* The small-strain model of the case (finite = 0) or its finite-rotation twin. */
static MicaFieldModel model_of(const ConstCase *c, int finite) {
  MicaFieldModel m;
  memset(&m, 0, sizeof m);
  int ierr = c->technical ? mica_cosserat_set_technical(&m, c->dim, c->p[0], c->p[1], c->p[2], c->p[3], c->p[4], c->p[5])
                          : mica_cosserat_set_eringen(&m, c->dim, c->p[0], c->p[1], c->p[2], c->p[3], c->p[4], c->p[5]);
  assert_int_equal(ierr, MICA_SUCCESS);
  if (finite) assert_int_equal(mica_cosserat_finite_set(&m), MICA_SUCCESS);
  return m;
}

static double uniform(MicaRandom *rng, double a) { return a * (2 * mica_random_uniform(rng) - 1); }

static int ncomp(int dim) { return dim == 2 ? 3 : 6; }
static int grad_slot(int dim, int c, int J) { return ncomp(dim) + c * dim + J; }

/* A random finite state: values and ∇u of size ≤ 0.4, ∇Φ ≤ 1, Φ of magnitude `rot` in a random direction. */
static void random_state(MicaRandom *rng, int dim, double rot, double *q) {
  const int nc = ncomp(dim), nrot = dim == 2 ? 1 : 3, nu = nc - nrot;
  for (int j = 0; j < nc * (1 + dim); j++) q[j] = uniform(rng, 0.4);
  for (int c = nu; c < nc; c++)
    for (int J = 0; J < dim; J++) q[grad_slot(dim, c, J)] = uniform(rng, 1.0);
  double dir[3] = {0, 0, 1}, len = 0;
  if (dim == 3) {
    for (int i = 0; i < 3; i++) dir[i] = uniform(rng, 1.0), len += dir[i] * dir[i];
    for (int i = 0; i < 3; i++) dir[i] /= sqrt(len);
  }
  for (int i = 0; i < nrot; i++) q[nu + i] = rot * dir[3 - nrot + i];
}

static double max_abs(int n, const double *v) {
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

/* Worst |s − differences of W| / max|s| and |D − differences of s| / max|D| at q. */
static void fd_errors(const MicaFieldModel *m, int dim, const double *q, double *err_s, double *err_D) {
  const int nq = mica_field_model_nq(m, dim);
  double s[NQ_MAX], D[NQ_MAX * NQ_MAX], qp[NQ_MAX], sp[NQ_MAX], sm[NQ_MAX], W, Wp, Wm;
  assert_int_equal(m->ops->eval(m, dim, q, &W, s, D), MICA_SUCCESS);
  double es = 0, eD = 0;
  for (int j = 0; j < nq; j++) {
    memcpy(qp, q, sizeof(double) * (size_t)nq);
    qp[j] = q[j] + FD_STEP;
    assert_int_equal(m->ops->eval(m, dim, qp, &Wp, sp, NULL), MICA_SUCCESS);
    qp[j] = q[j] - FD_STEP;
    assert_int_equal(m->ops->eval(m, dim, qp, &Wm, sm, NULL), MICA_SUCCESS);
    es = fmax(es, fabs((Wp - Wm) / (2 * FD_STEP) - s[j]));
    for (int i = 0; i < nq; i++) eD = fmax(eD, fabs((sp[i] - sm[i]) / (2 * FD_STEP) - D[i * nq + j]));
  }
  *err_s = es / max_abs(nq, s);
  *err_D = eD / max_abs(nq * nq, D);
}

static void test_derivatives_against_differences(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(41);
  double worst_s = 0, worst_D = 0, asym = 0;
  for (int k = 0; k < NUM_CASES; k++) {
    const MicaFieldModel m = model_of(&cases[k], 1);
    const int dim = cases[k].dim, nq = mica_field_model_nq(&m, dim);
    for (int r = 0; r < NUM_RANDOM; r++) {
      /* 3-D: up to 3 (near π, where log(R) would switch branch) and once 1e-4 (series); 2-D up to ±9 */
      const double rot = dim == 3 ? (r == 0 ? 1e-4 : 3.0 * (r + 1) / NUM_RANDOM) : 9.0 * (2.0 * r / NUM_RANDOM - 1);
      double q[NQ_MAX], D[NQ_MAX * NQ_MAX], es, eD;
      random_state(&rng, dim, rot, q);
      fd_errors(&m, dim, q, &es, &eD);
      worst_s = fmax(worst_s, es);
      worst_D = fmax(worst_D, eD);
      assert_int_equal(m.ops->eval(&m, dim, q, NULL, NULL, D), MICA_SUCCESS);
      for (int i = 0; i < nq; i++)
        for (int j = 0; j < i; j++) asym = fmax(asym, fabs(D[i * nq + j] - D[j * nq + i]) / max_abs(nq * nq, D));
      if (es > FD_TOL || eD > FD_TOL) fail_msg("%s, state %d (|Φ| = %g): s error %.2e, D error %.2e", cases[k].name, r, rot, es, eD);
    }
  }
  printf("finite Cosserat: worst relative error of s %.2e, of D %.2e (tolerance %.0e); asymmetry of D %.2e\n", worst_s,
         worst_D, FD_TOL, asym);
  assert_true(asym <= EXACT_TOL);
}

/* ---- objectivity ---- */

static void mat_mul(const double a[9], const double b[9], double c[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

/* Φ' = log(Q R(Φ)). */
static void rotated_vector(const double Q[9], const double phi[3], double out[3]) {
  MicaRotation r;
  double QR[9];
  mica_rotation_eval(phi, 0, &r);
  mat_mul(Q, r.R, QR);
  mica_rotation_log(QR, out);
}

static void test_objectivity(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(7);
  double worst = 0;
  for (int k = 0; k < NUM_CASES; k++) {
    if (cases[k].dim != 3) continue;
    const MicaFieldModel m = model_of(&cases[k], 1);
    for (int r = 0; r < NUM_RANDOM; r++) {
      double q[NQ_MAX], qq[NQ_MAX], omega[3], W, Wq;
      random_state(&rng, 3, 1.0, q); /* |Φ| = 1, |ω| ≤ 1: |Φ'| ≤ 2 < π, away from log's branch cut */
      for (int i = 0; i < 3; i++) omega[i] = uniform(&rng, 0.57);
      MicaRotation Qrot;
      mica_rotation_eval(omega, 0, &Qrot);
      memcpy(qq, q, sizeof qq);
      double F[9], QF[9];
      for (int l = 0; l < 3; l++)
        for (int K = 0; K < 3; K++) F[3 * l + K] = (l == K) + q[grad_slot(3, l, K)];
      mat_mul(Qrot.R, F, QF);
      for (int l = 0; l < 3; l++)
        for (int K = 0; K < 3; K++) qq[grad_slot(3, l, K)] = QF[3 * l + K] - (l == K);
      rotated_vector(Qrot.R, q + 3, qq + 3);
      for (int J = 0; J < 3; J++) { /* ∂_J Φ' = (Φ'(Φ + h ∂_J Φ) − Φ'(Φ − h ∂_J Φ)) / 2h */
        const double h = 1e-5;
        double plus[3], minus[3], op[3], om[3];
        for (int i = 0; i < 3; i++) {
          plus[i] = q[3 + i] + h * q[grad_slot(3, 3 + i, J)];
          minus[i] = q[3 + i] - h * q[grad_slot(3, 3 + i, J)];
        }
        rotated_vector(Qrot.R, plus, op);
        rotated_vector(Qrot.R, minus, om);
        for (int i = 0; i < 3; i++) qq[grad_slot(3, 3 + i, J)] = (op[i] - om[i]) / (2 * h);
      }
      assert_int_equal(m.ops->eval(&m, 3, q, &W, NULL, NULL), MICA_SUCCESS);
      assert_int_equal(m.ops->eval(&m, 3, qq, &Wq, NULL, NULL), MICA_SUCCESS);
      worst = fmax(worst, fabs(Wq - W) / W);
    }
  }
  printf("finite Cosserat: superposed rotation changes W by at most %.2e relative (tolerance 1e-8)\n", worst);
  assert_true(worst <= 1e-8); /* the differences of the log map carry ≈ h² = 1e-10 */
}

/* F = R(Φ), ∇Φ = 0: W = 0, s = 0 (3-D at |Φ| = 0.3 … 6, 2-D also beyond 2π). */
static void test_rigid_rotation(void **state) {
  (void)state;
  const double angles[] = {0.3, 2.0, 3.1, 4.5, 6.0, 7.0, -11.0};
  double worst = 0;
  for (int k = 0; k < NUM_CASES; k++) {
    const MicaFieldModel m = model_of(&cases[k], 1);
    const int dim = cases[k].dim, nq = mica_field_model_nq(&m, dim);
    const double scale = max_abs(6, m.param);
    for (int a = 0; a < 7; a++) {
      if (dim == 3 && fabs(angles[a]) >= TWO_PI) continue;
      const double n[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)};
      double phi[3] = {0, 0, angles[a]}, q[NQ_MAX] = {0}, s[NQ_MAX], W;
      if (dim == 3)
        for (int i = 0; i < 3; i++) phi[i] = angles[a] * n[i];
      MicaRotation r;
      mica_rotation_eval(phi, 0, &r);
      for (int l = 0; l < dim; l++)
        for (int K = 0; K < dim; K++) q[grad_slot(dim, l, K)] = r.R[3 * l + K] - (l == K);
      if (dim == 3)
        for (int i = 0; i < 3; i++) q[3 + i] = phi[i];
      else
        q[2] = phi[2];
      assert_int_equal(m.ops->eval(&m, dim, q, &W, s, NULL), MICA_SUCCESS);
      worst = fmax(worst, fmax(fabs(W), max_abs(nq, s)) / scale);
    }
  }
  printf("finite Cosserat: rigid rotations, max |W|, |s| = %.2e × max|constant|\n", worst);
  assert_true(worst <= EXACT_TOL);
}

/* D(0) of the finite model = D of the small-strain model. */
static void test_small_strain_limit(void **state) {
  (void)state;
  double worst = 0, worst_stress = 0;
  MicaRandom rng = mica_random_seed(3);
  for (int k = 0; k < NUM_CASES; k++) {
    const MicaFieldModel fin = model_of(&cases[k], 1), lin = model_of(&cases[k], 0);
    const int dim = cases[k].dim, nq = mica_field_model_nq(&fin, dim);
    double q[NQ_MAX] = {0}, Df[NQ_MAX * NQ_MAX], Dl[NQ_MAX * NQ_MAX];
    assert_int_equal(fin.ops->eval(&fin, dim, q, NULL, NULL, Df), MICA_SUCCESS);
    assert_int_equal(lin.ops->eval(&lin, dim, q, NULL, NULL, Dl), MICA_SUCCESS);
    const double scale = max_abs(nq * nq, Dl);
    for (int i = 0; i < nq * nq; i++) worst = fmax(worst, fabs(Df[i] - Dl[i]) / scale);
    /* at q of size 1e-6 the stresses agree to O(|q|) relative */
    for (int j = 0; j < nq; j++) q[j] = uniform(&rng, 1e-6);
    double sf[9], mf[9], sl[9], ml[9];
    assert_int_equal(fin.ops->stress(&fin, dim, q, sf, mf), MICA_SUCCESS);
    assert_int_equal(lin.ops->stress(&lin, dim, q, sl, ml), MICA_SUCCESS);
    const double ss = max_abs(9, sl), ms = max_abs(9, ml);
    for (int a = 0; a < 9; a++) worst_stress = fmax(worst_stress, fmax(fabs(sf[a] - sl[a]) / ss, fabs(mf[a] - ml[a]) / ms));
  }
  printf("finite Cosserat: |D(0) − D_small| %.2e relative; stresses at |q| ~ 1e-6 differ by %.2e relative\n", worst,
         worst_stress);
  assert_true(worst <= EXACT_TOL);
  assert_true(worst_stress <= 1e-4);
}

/* 2-D: φ + 2π is the same state. */
static void test_2d_periodic(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(11);
  const MicaFieldModel m = model_of(&cases[0], 1);
  const int nq = mica_field_model_nq(&m, 2);
  double worst = 0;
  for (int r = 0; r < NUM_RANDOM; r++) {
    double q[NQ_MAX], q2[NQ_MAX], s1[NQ_MAX], s2[NQ_MAX], D1[NQ_MAX * NQ_MAX], D2[NQ_MAX * NQ_MAX], W1, W2;
    random_state(&rng, 2, uniform(&rng, 3.0), q);
    memcpy(q2, q, sizeof q2);
    q2[2] += TWO_PI;
    assert_int_equal(m.ops->eval(&m, 2, q, &W1, s1, D1), MICA_SUCCESS);
    assert_int_equal(m.ops->eval(&m, 2, q2, &W2, s2, D2), MICA_SUCCESS);
    worst = fmax(worst, fabs(W1 - W2) / W1);
    for (int j = 0; j < nq; j++) worst = fmax(worst, fabs(s1[j] - s2[j]) / max_abs(nq, s1));
    for (int j = 0; j < nq * nq; j++) worst = fmax(worst, fabs(D1[j] - D2[j]) / max_abs(nq * nq, D1));
  }
  printf("finite Cosserat 2-D: φ vs φ + 2π, worst relative difference %.2e\n", worst);
  assert_true(worst <= EXACT_TOL);
}

/* σ = J⁻¹ F Pᵀ with P from s, at finite states. */
static void test_stress_consistent_with_s(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(5);
  double worst = 0;
  for (int k = 0; k < NUM_CASES; k++) {
    const MicaFieldModel m = model_of(&cases[k], 1);
    const int dim = cases[k].dim;
    for (int r = 0; r < NUM_RANDOM; r++) {
      double q[NQ_MAX], s[NQ_MAX], sigma[9], couple[9], F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, P[9] = {0};
      random_state(&rng, dim, 2.0, q);
      for (int l = 0; l < dim; l++)
        for (int K = 0; K < dim; K++) F[3 * l + K] += q[grad_slot(dim, l, K)];
      assert_int_equal(m.ops->eval(&m, dim, q, NULL, s, NULL), MICA_SUCCESS);
      for (int l = 0; l < dim; l++)
        for (int K = 0; K < dim; K++) P[3 * l + K] = s[grad_slot(dim, l, K)];
      assert_int_equal(m.ops->stress(&m, dim, q, sigma, couple), MICA_SUCCESS);
      const double J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                       F[2] * (F[3] * F[7] - F[4] * F[6]);
      const double sc = max_abs(9, sigma);
      for (int k2 = 0; k2 < dim; k2++) /* in-plane block (P_3K of plane strain is not a slot of s) */
        for (int l = 0; l < dim; l++) {
          double v = 0;
          for (int K = 0; K < dim; K++) v += F[3 * k2 + K] * P[3 * l + K];
          worst = fmax(worst, fabs(v / J - sigma[3 * k2 + l]) / sc);
        }
    }
  }
  printf("finite Cosserat: stress() vs J⁻¹ F Pᵀ from s, worst %.2e relative\n", worst);
  assert_true(worst <= EXACT_TOL);
}

static void test_bad_input(void **state) {
  (void)state;
  MicaFieldModel m;
  memset(&m, 0, sizeof m);
  /* the constants are the small-strain model's: its setter refuses them, the model stays untouched */
  assert_int_equal(mica_cosserat_set_technical(&m, 2, 1000, 0.3, 1.0, 0.1, 0.1, 1.0), MICA_ERR_INPUT);
  assert_non_null(strstr(mica_error_message(), "coupling number N"));
  assert_null(m.ops);
  mica_error_clear();
  assert_int_equal(mica_cosserat_set_eringen(&m, 3, 1, 1, -0.5, 0, 0, 1), MICA_ERR_INPUT);
  mica_error_clear();
  assert_int_equal(mica_cosserat_finite_set(&m), MICA_ERR_ARGUMENT);
  mica_error_clear();
  /* 3-D |Φ| ≥ 2π is singular */
  m = model_of(&cases[2], 1);
  double q[NQ_MAX] = {0}, W;
  q[3] = 4.0, q[4] = 5.0;
  assert_int_equal(m.ops->eval(&m, 3, q, &W, NULL, NULL), MICA_ERR_NUMERIC);
  assert_non_null(strstr(mica_error_message(), "2π"));
  mica_error_clear();
  assert_int_equal(m.ops->eval(&m, 4, q, &W, NULL, NULL), MICA_ERR_ARGUMENT);
  mica_error_clear();
  assert_string_equal(m.ops->type.name, "cosserat-finite");
  assert_int_equal(mica_field_model_nq(&m, 2), 9);
  assert_int_equal(mica_field_model_nq(&m, 3), 24);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_derivatives_against_differences),
      cmocka_unit_test(test_objectivity),
      cmocka_unit_test(test_rigid_rotation),
      cmocka_unit_test(test_small_strain_limit),
      cmocka_unit_test(test_2d_periodic),
      cmocka_unit_test(test_stress_consistent_with_s),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
