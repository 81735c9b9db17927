/* The finite-rotation module (mica/rotation.h): R = exp(skew Φ) is orthogonal with det 1 and rotates about Φ
 * by |Φ|; Rᵀ ∂R/∂Φ_i = skew(T e_i); the first and second derivatives of R and T agree with central
 * differences; the series and the closed forms agree where they meet (θ = 1); log inverts exp. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "mica/mls.h"
#include "mica/rotation.h"

static double rnd(uint64_t *state) {
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*state >> 11) / 9007199254740992.0 * 2 - 1;
}

/* Rotation vectors spanning θ from 0 through the series/closed-form switch (θ = 1) to just below 2π. */
static void sample_phi(int k, uint64_t *state, double phi[3]) {
  static const double theta[] = {0.0, 1e-9, 1e-3, 0.3, 0.999999, 1.000001, 2.0, 3.1, 3.14159, 4.5, 6.0};
  const int n = (int)(sizeof theta / sizeof theta[0]);
  double axis[3] = {rnd(state), rnd(state), rnd(state)};
  const double norm = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  for (int i = 0; i < 3; i++) phi[i] = theta[k % n] * axis[i] / norm;
}

static double max_abs_diff(const double *a, const double *b, int n) {
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

static void matmul_tn(const double *A, const double *B, double *C) { /* C = Aᵀ B */
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      C[i * 3 + j] = 0;
      for (int k = 0; k < 3; k++) C[i * 3 + j] += A[k * 3 + i] * B[k * 3 + j];
    }
}

static void test_orthogonal_and_axis(void **state) {
  (void)state;
  uint64_t seed = 7;
  for (int k = 0; k < 44; k++) {
    double phi[3], RtR[9], Rphi[3];
    sample_phi(k, &seed, phi);
    MicaRotation rot;
    mica_rotation_eval(phi, 0, &rot);
    matmul_tn(rot.R, rot.R, RtR);
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    assert_true(max_abs_diff(RtR, I, 9) < 1e-14);
    const double *R = rot.R;
    const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                       R[2] * (R[3] * R[7] - R[4] * R[6]);
    assert_true(fabs(det - 1) < 1e-14);
    for (int i = 0; i < 3; i++) Rphi[i] = R[i * 3] * phi[0] + R[i * 3 + 1] * phi[1] + R[i * 3 + 2] * phi[2];
    assert_true(max_abs_diff(Rphi, phi, 3) < 1e-14 * (1 + fabs(phi[0]) + fabs(phi[1]) + fabs(phi[2])));
    const double theta = sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]);
    assert_true(fabs(0.5 * (R[0] + R[4] + R[8] - 1) - cos(theta)) < 1e-14); /* tr R = 1 + 2 cos θ */
  }
}

/* A rotation by θ about e_z, in closed form. */
static void test_about_z(void **state) {
  (void)state;
  const double theta = 2.5, phi[3] = {0, 0, theta};
  MicaRotation rot;
  mica_rotation_eval(phi, 0, &rot);
  const double expected[9] = {cos(theta), -sin(theta), 0, sin(theta), cos(theta), 0, 0, 0, 1};
  assert_true(max_abs_diff(rot.R, expected, 9) < 1e-15);
}

/* Central differences of R and T (first) and of dR, dT (second), with step h. */
static void check_derivatives(const double phi[3], double *worst_first, double *worst_second) {
  const double h = 1e-5;
  MicaRotation rot, plus, minus;
  mica_rotation_eval(phi, 2, &rot);
  for (int i = 0; i < 3; i++) {
    double pp[3] = {phi[0], phi[1], phi[2]}, pm[3] = {phi[0], phi[1], phi[2]};
    pp[i] += h, pm[i] -= h;
    mica_rotation_eval(pp, 1, &plus);
    mica_rotation_eval(pm, 1, &minus);
    for (int e = 0; e < 9; e++) {
      *worst_first = fmax(*worst_first, fabs((plus.R[e] - minus.R[e]) / (2 * h) - rot.dR[i][e]));
      *worst_first = fmax(*worst_first, fabs((plus.T[e] - minus.T[e]) / (2 * h) - rot.dT[i][e]));
      for (int j = 0; j < 3; j++) {
        const int hh = mls_hess_index(3, i, j);
        *worst_second = fmax(*worst_second, fabs((plus.dR[j][e] - minus.dR[j][e]) / (2 * h) - rot.ddR[hh][e]));
        *worst_second = fmax(*worst_second, fabs((plus.dT[j][e] - minus.dT[j][e]) / (2 * h) - rot.ddT[hh][e]));
      }
    }
  }
}

static void test_derivatives_match_differences(void **state) {
  (void)state;
  uint64_t seed = 11;
  double worst_first = 0, worst_second = 0;
  for (int k = 0; k < 44; k++) {
    double phi[3];
    sample_phi(k, &seed, phi);
    check_derivatives(phi, &worst_first, &worst_second);
  }
  print_message("worst |FD - exact|: first %.2e, second %.2e\n", worst_first, worst_second);
  assert_true(worst_first < 1e-8); /* central differences: O(h²) ≈ 1e-10 with O(1) third derivatives */
  assert_true(worst_second < 1e-8);
}

/* Rᵀ ∂R/∂Φ_i = skew(T e_i): the defining property of the right tangent. */
static void test_right_tangent(void **state) {
  (void)state;
  uint64_t seed = 3;
  for (int k = 0; k < 44; k++) {
    double phi[3], RtdR[9];
    sample_phi(k, &seed, phi);
    MicaRotation rot;
    mica_rotation_eval(phi, 1, &rot);
    for (int i = 0; i < 3; i++) {
      matmul_tn(rot.R, rot.dR[i], RtdR);
      const double w[3] = {rot.T[0 * 3 + i], rot.T[1 * 3 + i], rot.T[2 * 3 + i]};
      const double skew[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
      assert_true(max_abs_diff(RtdR, skew, 9) < 1e-14);
    }
  }
}

/* The series (θ < 1) and the closed forms (θ ≥ 1) meet continuously, derivatives included. */
static void test_switch_is_continuous(void **state) {
  (void)state;
  const double below[3] = {0, 0, 1 - 2.3e-16}, above[3] = {0, 0, 1}; /* s just below 1: series; s = 1: closed */
  MicaRotation a, b;
  mica_rotation_eval(below, 2, &a);
  mica_rotation_eval(above, 2, &b);
  assert_true(max_abs_diff(a.R, b.R, 9) < 1e-15);
  assert_true(max_abs_diff(a.T, b.T, 9) < 1e-15);
  assert_true(max_abs_diff(a.ddR[0], b.ddR[0], 6 * 9) < 1e-11);
  assert_true(max_abs_diff(a.ddT[0], b.ddT[0], 6 * 9) < 1e-11);
}

static void test_log_inverts_exp(void **state) {
  (void)state;
  uint64_t seed = 5;
  for (int k = 0; k < 44; k++) {
    double phi[3], back[3];
    sample_phi(k, &seed, phi);
    const double theta = sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]);
    if (theta > 3.14159265358979) continue; /* log returns θ ∈ [0, π] */
    MicaRotation rot;
    mica_rotation_eval(phi, 0, &rot);
    mica_rotation_log(rot.R, back);
    assert_true(max_abs_diff(phi, back, 3) < 1e-9); /* acos near θ = π loses half the digits */
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_orthogonal_and_axis),  cmocka_unit_test(test_about_z),
      cmocka_unit_test(test_derivatives_match_differences), cmocka_unit_test(test_right_tangent),
      cmocka_unit_test(test_switch_is_continuous), cmocka_unit_test(test_log_inverts_exp),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
