/* Unit tests of the MLS weight functions (src/mls/weight.c): lookup, support, the analytic derivatives
 * against central finite differences, smoothness at the knots and at r = 1, and known values (the C³
 * quartic B-spline values at its knots were derived independently with sympy's bspline_basis).
 *
 * Tolerances: first and second derivatives agree with central differences (step 1e-5) to 1e-7 × (1 + |w'|);
 * the truncation error is about 1e-10 × |w'''| and the rounding error about 1e-11. Pieces meeting at a
 * knot agree to 1e-8 across a 2e-10 gap. A third derivative at a knot comes from a second-order one-sided
 * difference of w'', which is exact for the quadratic w'' of a quartic piece, so only rounding (~1e-10)
 * remains; it must agree across C³ knots to 1e-5 and must jump across the cubic spline's knot. The two
 * spline kernels also match an independent Cox-de Boor evaluation to 1e-13 on a grid. Near r = 1
 * a C^k kernel's first k derivatives, 1e-9 inside, are below 1e-6 (a C² kernel's w'' is O(1e-9 × 24)).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mica/mls.h"
#include "registry_arrays.h"

#define FD_STEP 1e-5
#define FD_TOL 1e-7

/* Shape parameters ρ/c at which the adaptive kernel is tested (the others ignore param). */

/* Types an extension adds to the registry when the test is linked with tests/extensions (test_mls_weight_ext). */
#ifndef EXTRA_WEIGHTS
#define EXTRA_WEIGHTS 0
#endif


static const double exp_params[] = {0.25, 1.0, 2.0, 5.0};
#define NUM_EXP_PARAMS (sizeof exp_params / sizeof exp_params[0])

static void weight(const MlsWeightOps *ops, double r, double param, double w[3]) { ops->eval(r, param, w); }

static void assert_close(double expected, double actual, double tol, const char *what, double r) {
  if (!(fabs(expected - actual) <= tol)) {
    print_error("%s at r = %.17g: expected %.17g, got %.17g (tolerance %.3g)\n", what, r, expected, actual,
                tol);
    fail();
  }
}

/* ---- lookup and fields ---- */

static void test_find_and_fields(void **state) {
  (void)state;
  static const struct {
    const char *name;
    const MlsWeightOps *ops;
    int continuity, adaptive;
  } expected[] = {
      {"cubic", &mls_weight_cubic, 2, 0},
      {"quartic", &mls_weight_quartic, 2, 0},
      {"quartic-c3", &mls_weight_quartic_c3, 3, 0},
      {"gauss", &mls_weight_gauss, -1, 0},
      {"exponential", &mls_weight_exponential, 0, 1},
  };
  const MlsWeightOps *const *all = weights_all();
  for (int i = 0; i < 5; i++) {
    assert_ptr_equal(mls_weight_find(expected[i].name), expected[i].ops);
    assert_ptr_equal(all[i], expected[i].ops);
    assert_string_equal(expected[i].ops->type.name, expected[i].name);
    assert_int_equal(expected[i].ops->continuity, expected[i].continuity);
    assert_int_equal(mica_type_has(&expected[i].ops->type, MLS_WEIGHT_ADAPTIVE), expected[i].adaptive);
  }
  assert_null(all[5 + EXTRA_WEIGHTS]);
  assert_null(mls_weight_find("quartic_c3"));
  assert_null(mls_weight_find("Cubic"));
  assert_null(mls_weight_find(""));
  assert_null(mls_weight_find(NULL));
}

/* ---- support ---- */

/* Every kernel, with every parameter, is exactly zero (value and derivatives) at and beyond r = 1. */
static void test_zero_outside_support(void **state) {
  (void)state;
  const double outside[] = {1.0, nextafter(1.0, 2.0), 1.0 + 1e-9, 1.5, 2.0, 1e6};
  for (const MlsWeightOps *const *ops = weights_all(); *ops; ops++)
    for (size_t p = 0; p < NUM_EXP_PARAMS; p++)
      for (size_t i = 0; i < sizeof outside / sizeof outside[0]; i++) {
        double w[3] = {NAN, NAN, NAN};
        weight(*ops, outside[i], exp_params[p], w);
        for (int n = 0; n < 3; n++) assert_true(w[n] == 0.0);
      }
}

/* Approaching r = 1 from inside: a C^k kernel's value and first k derivatives tend to zero; the
 * exponential kernel's value does but its slope does not; the truncated Gaussian jumps from exp(−6.25). */
static void test_left_limit_at_one(void **state) {
  (void)state;
  double r = 1.0 - 1e-9, w[3];
  for (const MlsWeightOps *const *ops = weights_all(); *ops; ops++) {
    int k = (*ops)->continuity;
    weight(*ops, r, 2.0, w);
    for (int n = 0; n <= k && n < 3; n++) assert_close(0.0, w[n], 1e-6, (*ops)->type.name, r);
  }
  weight(&mls_weight_gauss, r, 0.0, w);
  assert_close(exp(-6.25), w[0], 1e-10, "gauss w(1-)", r);
  weight(&mls_weight_exponential, r, 2.0, w);
  assert_close(-8.0 * exp(-4.0) / (1.0 - exp(-4.0)), w[1], 1e-7, "exponential w'(1-)", r);
}

/* ---- derivatives ---- */

/* Central differences of w (against w') and of w' (against w'') at r = 0.05, 0.15, ..., 0.95, which
 * keeps every knot (0.2, 0.5, 0.6) at least 0.05 away from the difference stencil. */
static void check_fd(const MlsWeightOps *ops, double param) {
  for (int i = 0; i < 10; i++) {
    double r = 0.05 + 0.1 * i, w[3], wp[3], wm[3];
    weight(ops, r, param, w);
    weight(ops, r + FD_STEP, param, wp);
    weight(ops, r - FD_STEP, param, wm);
    for (int n = 1; n <= 2; n++) {
      double fd = (wp[n - 1] - wm[n - 1]) / (2.0 * FD_STEP);
      assert_close(fd, w[n], FD_TOL * (1.0 + fabs(w[n])), ops->type.name, r);
    }
  }
}

static void test_derivatives_vs_fd(void **state) {
  (void)state;
  for (const MlsWeightOps *const *ops = weights_all(); *ops; ops++)
    for (size_t p = 0; p < NUM_EXP_PARAMS; p++) check_fd(*ops, exp_params[p]);
}

/* Every kernel is even in the distance, so its slope vanishes at r = 0; and the values there are known. */
static void test_values_at_zero(void **state) {
  (void)state;
  double w[3];
  for (const MlsWeightOps *const *ops = weights_all(); *ops; ops++)
    for (size_t p = 0; p < NUM_EXP_PARAMS; p++) {
      weight(*ops, 0.0, exp_params[p], w);
      assert_close(0.0, w[1], 1e-15, (*ops)->type.name, 0.0);
      double expected = *ops == &mls_weight_cubic ? 2.0 / 3.0 : 1.0;
      assert_close(expected, w[0], 1e-15, (*ops)->type.name, 0.0);
    }
}

/* ---- the piecewise kernels: continuity at the knots ---- */

/* w, w', w'' just below and just above the knot (±1e-10, so that each side is evaluated by its own piece)
 * agree to 1e-8: a jump in a coefficient would be orders of magnitude larger, while a continuous w^(n)
 * moves by at most 2e-10 × |w^(n+1)| (below 1e-8 for these kernels) across the gap. */
static void check_c2_at_knot(const MlsWeightOps *ops, double knot) {
  const double gap = 1e-10;
  double left[3], right[3];
  weight(ops, knot - gap, 1.0, left);
  weight(ops, knot + gap, 1.0, right);
  for (int n = 0; n < 3; n++) assert_close(left[n], right[n], 1e-8 * (1.0 + fabs(left[n])), ops->type.name, knot);
}

/* w''' on either side of a knot, by the second-order one-sided differences
 * (3f(k) − 4f(k ∓ h) + f(k ∓ 2h))/(±2h) of f = w'', with the stencil inside one piece. */
static void third_derivative_sides(const MlsWeightOps *ops, double knot, double *left, double *right) {
  const double h = 1e-4;
  double f0[3], f1[3], f2[3];
  weight(ops, knot, 1.0, f0); /* either piece may own the knot: w'' is continuous there */
  weight(ops, knot - h, 1.0, f1);
  weight(ops, knot - 2.0 * h, 1.0, f2);
  *left = (3.0 * f0[2] - 4.0 * f1[2] + f2[2]) / (2.0 * h);
  weight(ops, knot + h, 1.0, f1);
  weight(ops, knot + 2.0 * h, 1.0, f2);
  *right = -(3.0 * f0[2] - 4.0 * f1[2] + f2[2]) / (2.0 * h);
}

static void test_cubic_knot(void **state) {
  (void)state;
  check_c2_at_knot(&mls_weight_cubic, 0.5);
  double w[3];
  weight(&mls_weight_cubic, 0.5, 0.0, w);
  assert_close(1.0 / 6.0, w[0], 1e-15, "cubic w(0.5)", 0.5);
  assert_close(-1.0, w[1], 1e-15, "cubic w'(0.5)", 0.5);
  assert_close(4.0, w[2], 1e-14, "cubic w''(0.5)", 0.5);
  /* Only C²: w''' is 24 inside and −8 outside the knot; the one-sided differences must see that. */
  double left, right;
  third_derivative_sides(&mls_weight_cubic, 0.5, &left, &right);
  assert_close(24.0, left, 1e-5, "cubic w'''(0.5-)", 0.5);
  assert_close(-8.0, right, 1e-5, "cubic w'''(0.5+)", 0.5);
}

static void test_quartic_c3_knots(void **state) {
  (void)state;
  const double knots[] = {0.2, 0.6};
  for (int i = 0; i < 2; i++) {
    check_c2_at_knot(&mls_weight_quartic_c3, knots[i]);
    double left, right;
    third_derivative_sides(&mls_weight_quartic_c3, knots[i], &left, &right);
    assert_close(left, right, 1e-5, "quartic-c3 w''' across a knot", knots[i]);
    assert_true(fabs(left) > 1.0); /* a nontrivial value, not 0 = 0 */
  }
}

/* ---- the spline kernels against an independent B-spline evaluation ----
 * Cardinal B-spline N_d of degree d on the knots 0, 1, ..., d + 1 by the Cox-de Boor recursion
 * N_0 = 1 on [0, 1), N_d(x) = (x N_{d−1}(x) + (d + 1 − x) N_{d−1}(x − 1)) / d, and its derivatives by
 * N_d' = N_{d−1}(x) − N_{d−1}(x − 1). */
static double cardinal_bspline(int d, int nderiv, double x) {
  if (nderiv > 0)
    return cardinal_bspline(d - 1, nderiv - 1, x) - cardinal_bspline(d - 1, nderiv - 1, x - 1.0);
  if (d == 0) return x >= 0.0 && x < 1.0 ? 1.0 : 0.0;
  return (x * cardinal_bspline(d - 1, 0, x) + (d + 1 - x) * cardinal_bspline(d - 1, 0, x - 1.0)) / d;
}

/* The kernel is N_d(c (1 − r)) × scale with c = (d + 1)/2 the spline's centre: the cubic spline of eq 3.30
 * is N_3(2 − 2r) itself (w(0) = 2/3), the C³ kernel N_4(2.5 − 2.5r) / N_4(2.5). Checked at r = i/1000, which
 * includes every knot, to 1e-13 × (1 + |w^(n)|). */
static void check_against_bspline(const MlsWeightOps *ops, int d, double scale) {
  double c = 0.5 * (d + 1);
  for (int i = 0; i < 1000; i++) {
    double r = i / 1000.0, u = c * (1.0 - r), w[3];
    weight(ops, r, 1.0, w);
    double expected[3] = {scale * cardinal_bspline(d, 0, u), -c * scale * cardinal_bspline(d, 1, u),
                          c * c * scale * cardinal_bspline(d, 2, u)};
    for (int n = 0; n < 3; n++)
      assert_close(expected[n], w[n], 1e-13 * (1.0 + fabs(expected[n])), ops->type.name, r);
  }
}

static void test_splines_against_bspline(void **state) {
  (void)state;
  check_against_bspline(&mls_weight_cubic, 3, 1.0);
  check_against_bspline(&mls_weight_quartic_c3, 4, 1.0 / cardinal_bspline(4, 0, 2.5));
  assert_close(115.0 / 192.0, cardinal_bspline(4, 0, 2.5), 1e-16, "N_4(2.5)", 2.5);
}

/* Exact values of the normalized B-spline (sympy): w(0.2) = 88/115, w(0.6) = 8/115, w''(0) = −300/23,
 * and its first two pieces in r: 1 − 150/23 r² + 375/23 r⁴ on [0, 0.2], then the one below. */
static void test_quartic_c3_values(void **state) {
  (void)state;
  double w[3];
  weight(&mls_weight_quartic_c3, 0.2, 0.0, w);
  assert_close(88.0 / 115.0, w[0], 1e-15, "quartic-c3 w(0.2)", 0.2);
  weight(&mls_weight_quartic_c3, 0.6, 0.0, w);
  assert_close(8.0 / 115.0, w[0], 1e-15, "quartic-c3 w(0.6)", 0.6);
  weight(&mls_weight_quartic_c3, 0.0, 0.0, w);
  assert_close(-300.0 / 23.0, w[2], 1e-12, "quartic-c3 w''(0)", 0.0);
  double r = 0.13;
  weight(&mls_weight_quartic_c3, r, 0.0, w);
  assert_close(1.0 - 150.0 / 23.0 * r * r + 375.0 / 23.0 * r * r * r * r, w[0], 1e-14, "quartic-c3 w", r);
  /* The second knot span, from u = 2.5(1 − r): piece (-250r⁴ + 500r³ − 300r² + 20r + 22)/23. */
  r = 0.41;
  weight(&mls_weight_quartic_c3, r, 0.0, w);
  double r2 = r * r;
  assert_close((-250.0 * r2 * r2 + 500.0 * r2 * r - 300.0 * r2 + 20.0 * r + 22.0) / 23.0, w[0], 1e-14,
               "quartic-c3 w", r);
}

static void test_quartic_values(void **state) {
  (void)state;
  double w[3], r = 0.3;
  weight(&mls_weight_quartic, r, 0.0, w);
  assert_close(1.0 - 6.0 * r * r + 8.0 * r * r * r - 3.0 * r * r * r * r, w[0], 1e-15, "quartic w", r);
  assert_close(-12.0 * r * (1.0 - r) * (1.0 - r), w[1], 1e-14, "quartic w'", r);
}

/* ---- the Gaussian and the adaptive exponential ---- */

static void test_gauss_values(void **state) {
  (void)state;
  double w[3], r = 0.37;
  weight(&mls_weight_gauss, r, 0.0, w);
  assert_close(exp(-(r / 0.4) * (r / 0.4)), w[0], 1e-15, "gauss w", r);
}

/* Against the formula of eq 3.33 written directly (fine for moderate c' where there is no cancellation). */
static void test_exponential_values(void **state) {
  (void)state;
  for (size_t p = 0; p < NUM_EXP_PARAMS; p++) {
    double c = exp_params[p];
    for (int i = 0; i < 10; i++) {
      double r = 0.1 * i + 0.03, w[3];
      weight(&mls_weight_exponential, r, c, w);
      double direct = (exp(-(r * c) * (r * c)) - exp(-c * c)) / (1.0 - exp(-c * c));
      assert_close(direct, w[0], 1e-13, "exponential w", r);
    }
  }
}

/* The caller guarantees c' = ρ/c > 0. Still, c' ≤ 0 and c' so small that c'² underflows must not give
 * NaN: they take the limit c' → 0, w = 1 − r²; and small positive c' must approach that limit smoothly. */
static void test_exponential_limits(void **state) {
  (void)state;
  const double degenerate[] = {0.0, -0.0, -1.0, 1e-200};
  for (size_t i = 0; i < sizeof degenerate / sizeof degenerate[0]; i++)
    for (int j = 0; j < 10; j++) {
      double r = 0.1 * j + 0.05, w[3];
      weight(&mls_weight_exponential, r, degenerate[i], w);
      for (int n = 0; n < 3; n++) assert_true(isfinite(w[n]));
      assert_close(1.0 - r * r, w[0], 1e-15, "exponential limit w", r);
      assert_close(-2.0 * r, w[1], 1e-15, "exponential limit w'", r);
      assert_close(-2.0, w[2], 1e-15, "exponential limit w''", r);
    }
  /* Small c', q = c'²: w = (1 − r²)(1 − q r²/2) + O(q²), w' = −2r (1 + q (1/2 − r²)) + O(q²) (Taylor
   * series of the quotient). Evaluating the quotient as written would lose about 1e-16/q to cancellation. */
  const double small[] = {1e-4, 1e-5, 1e-6, 1e-7};
  for (size_t i = 0; i < sizeof small / sizeof small[0]; i++)
    for (int j = 0; j < 10; j++) {
      double q = small[i] * small[i], r = 0.1 * j + 0.05, w[3];
      weight(&mls_weight_exponential, r, small[i], w);
      assert_close((1.0 - r * r) * (1.0 - 0.5 * q * r * r), w[0], 1e-14, "exponential small c' w", r);
      assert_close(-2.0 * r * (1.0 + q * (0.5 - r * r)), w[1], 1e-14, "exponential small c' w'", r);
    }
  /* Large c': the kernel is a narrow Gaussian, still finite. */
  double w[3];
  weight(&mls_weight_exponential, 0.5, 60.0, w);
  for (int n = 0; n < 3; n++) assert_true(isfinite(w[n]));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_find_and_fields),
      cmocka_unit_test(test_zero_outside_support),
      cmocka_unit_test(test_left_limit_at_one),
      cmocka_unit_test(test_derivatives_vs_fd),
      cmocka_unit_test(test_values_at_zero),
      cmocka_unit_test(test_cubic_knot),
      cmocka_unit_test(test_quartic_c3_knots),
      cmocka_unit_test(test_quartic_c3_values),
      cmocka_unit_test(test_quartic_values),
      cmocka_unit_test(test_gauss_values),
      cmocka_unit_test(test_exponential_values),
      cmocka_unit_test(test_exponential_limits),
      cmocka_unit_test(test_splines_against_bspline),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
