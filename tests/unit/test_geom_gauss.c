/* Unit tests of the Gauss rules (src/geom/gauss.c).
 *
 *   - Gauss–Legendre, n = 1..20 and 32, 64: nodes ascending in (−1, 1) and symmetric, weights positive
 *     summing to 2, ∫ x^k exact for k ≤ 2n − 1 (1e-13 relative), and x^2n not exact for n ≤ 12 (the
 *     rule is the Gauss rule, not a finer one; its error at degree 2n shrinks like 4^−n).
 *   - triangle and tetrahedron (collapsed Gauss–Jacobi × Gauss–Legendre), n = 1..10 (tet 1..8): points
 *     strictly inside, weights positive summing to 1/2 (1/6), ∫ ξ^p η^q (ζ^r) exact for every total degree
 *     ≤ 2n − 1 (the contract asks 2n − 2) against p! q! (r!) / (p + q (+ r) + 2 (3))!.
 *   - n < 1 is a contract violation (MICA_ERR_ARGUMENT).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/geom.h"

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static void assert_close(double got, double want, double rtol, const char *what) {
  if (!(fabs(got - want) <= rtol * fmax(1.0, fabs(want)) || fabs(got - want) <= rtol * fabs(want))) {
    print_error("%s: got %.17g, want %.17g (rel. error %.3g)\n", what, got, want,
                fabs(got - want) / fabs(want));
    fail();
  }
}

static double relative(double got, double want) { return fabs(got - want) / fabs(want); }

static double factorial(int n) {
  double f = 1.0;
  for (int i = 2; i <= n; i++) f *= i;
  return f;
}

static void legendre_exact(int n) {
  double x[64], w[64], sum = 0.0;
  check_ok(mica_gauss_legendre(n, x, w));
  for (int i = 0; i < n; i++) {
    assert_true(x[i] > -1.0 && x[i] < 1.0 && w[i] > 0.0);
    if (i) assert_true(x[i] > x[i - 1]);
    assert_true(x[i] == -x[n - 1 - i]);
    sum += w[i];
  }
  assert_close(sum, 2.0, 1e-14, "Σ w");
  for (int k = 0; k <= 2 * n; k++) {
    double q = 0.0;
    for (int i = 0; i < n; i++) q += w[i] * pow(x[i], k);
    const double exact = k % 2 ? 0.0 : 2.0 / (k + 1);
    if (k <= 2 * n - 1) {
      if (fabs(q - exact) > 1e-13 * fmax(exact, 1e-2)) {
        print_error("n = %d: ∫x^%d = %.17g, want %.17g\n", n, k, q, exact);
        fail();
      }
    } else if (n <= 12) {
      assert_true(relative(q, exact) > 1e-8); /* degree 2n is beyond a Gauss rule (visibly for small n) */
    }
  }
}

static void test_legendre(void **state) {
  (void)state;
  for (int n = 1; n <= 20; n++) legendre_exact(n);
  legendre_exact(32);
  legendre_exact(64);
}

static void test_legendre_known(void **state) {
  (void)state;
  double x[3], w[3];
  check_ok(mica_gauss_legendre(2, x, w));
  assert_close(x[1], 1.0 / sqrt(3.0), 1e-15, "x1 (n = 2)");
  assert_close(w[0], 1.0, 1e-15, "w0 (n = 2)");
  check_ok(mica_gauss_legendre(3, x, w));
  assert_true(x[1] == 0.0);
  assert_close(x[2], sqrt(0.6), 1e-15, "x2 (n = 3)");
  assert_close(w[1], 8.0 / 9.0, 1e-15, "w1 (n = 3)");
  assert_close(w[2], 5.0 / 9.0, 1e-15, "w2 (n = 3)");
}

static void triangle_exact(int n) {
  const int m = n * n;
  double *xi = malloc(sizeof(double) * 2 * m), *w = malloc(sizeof(double) * m), sum = 0.0;
  check_ok(mica_gauss_triangle(n, xi, w));
  for (int q = 0; q < m; q++) {
    assert_true(w[q] > 0 && xi[2 * q] > 0 && xi[2 * q + 1] > 0 && xi[2 * q] + xi[2 * q + 1] < 1);
    sum += w[q];
  }
  assert_close(sum, 0.5, 1e-14, "Σ w (triangle)");
  for (int p = 0; p <= 2 * n - 1; p++)
    for (int r = 0; p + r <= 2 * n - 1; r++) {
      double integral = 0.0;
      for (int q = 0; q < m; q++) integral += w[q] * pow(xi[2 * q], p) * pow(xi[2 * q + 1], r);
      const double exact = factorial(p) * factorial(r) / factorial(p + r + 2);
      if (relative(integral, exact) > 1e-13) {
        print_error("triangle n = %d: ∫ξ^%d η^%d = %.17g, want %.17g\n", n, p, r, integral, exact);
        fail();
      }
    }
  free(xi);
  free(w);
}

static void tetrahedron_exact(int n) {
  const int m = n * n * n;
  double *xi = malloc(sizeof(double) * 3 * m), *w = malloc(sizeof(double) * m), sum = 0.0;
  check_ok(mica_gauss_tetrahedron(n, xi, w));
  for (int q = 0; q < m; q++) {
    const double *c = &xi[3 * q];
    assert_true(w[q] > 0 && c[0] > 0 && c[1] > 0 && c[2] > 0 && c[0] + c[1] + c[2] < 1);
    sum += w[q];
  }
  assert_close(sum, 1.0 / 6.0, 1e-14, "Σ w (tetrahedron)");
  for (int a = 0; a <= 2 * n - 1; a++)
    for (int b = 0; a + b <= 2 * n - 1; b++)
      for (int c = 0; a + b + c <= 2 * n - 1; c++) {
        double integral = 0.0;
        for (int q = 0; q < m; q++)
          integral += w[q] * pow(xi[3 * q], a) * pow(xi[3 * q + 1], b) * pow(xi[3 * q + 2], c);
        const double exact = factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
        if (relative(integral, exact) > 1e-13) {
          print_error("tetrahedron n = %d: ∫ξ^%d η^%d ζ^%d = %.17g, want %.17g\n", n, a, b, c, integral,
                      exact);
          fail();
        }
      }
  free(xi);
  free(w);
}

static void test_triangle(void **state) {
  (void)state;
  for (int n = 1; n <= 10; n++) triangle_exact(n);
}

static void test_tetrahedron(void **state) {
  (void)state;
  for (int n = 1; n <= 8; n++) tetrahedron_exact(n);
}

static void test_bad_n(void **state) {
  (void)state;
  double x[1], w[1];
  assert_int_equal(mica_gauss_legendre(0, x, w), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_gauss_triangle(0, x, w), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_gauss_tetrahedron(-1, x, w), MICA_ERR_ARGUMENT);
  mica_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_legendre), cmocka_unit_test(test_legendre_known),
      cmocka_unit_test(test_triangle), cmocka_unit_test(test_tetrahedron),
      cmocka_unit_test(test_bad_n),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
