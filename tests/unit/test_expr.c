/* Expressions: evaluation, parameters bound as constants, exact derivatives against hand-computed
 * values, and the errors for unknown names and bad syntax. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mica/expr.h"

static MicaFunction *compile_ok(const char *text, int nparams, const char *const *names, const double *values) {
  MicaFunction *f = NULL;
  if (mica_function_create(text, nparams, names, values, &f)) fail_msg("\"%s\": %s", text, mica_error_message());
  return f;
}

static double at(const MicaFunction *f, double x, double y, double z, double t) {
  return mica_function_eval(f, (double[3]){x, y, z}, t);
}

static void assert_close(double got, double want) {
  if (!(fabs(got - want) <= 1e-12 * fmax(1.0, fabs(want)))) fail_msg("got %.17g, want %.17g", got, want);
}

static void expect_error(const char *text, int nparams, const char *const *names, const double *values,
                         const char *what) {
  MicaFunction *f = NULL;
  int ierr = mica_function_create(text, nparams, names, values, &f);
  assert_int_equal(ierr, MICA_ERR_INPUT);
  assert_null(f);
  if (!strstr(mica_error_message(), what)) fail_msg("message \"%s\" lacks \"%s\"", mica_error_message(), what);
  mica_error_clear();
}

static void test_evaluate_variables(void **state) {
  (void)state;
  MicaFunction *f = compile_ok("x + 2*y - z/4 + t^2 + sin(pi/2)", 0, NULL, NULL);
  assert_close(at(f, 1, 2, 4, 3), 1 + 4 - 1 + 9 + 1);
  assert_string_equal(mica_function_text(f), "x + 2*y - z/4 + t^2 + sin(pi/2)");
  mica_function_destroy(&f);
  assert_null(f);
  f = compile_ok("2.5e-1*x + .5 + 3. + exp(-x^2)", 0, NULL, NULL);
  assert_close(at(f, 2, 0, 0, 0), 0.5 + 0.5 + 3 + exp(-4.0));
  mica_function_destroy(&f);
}

static void test_parameters(void **state) {
  (void)state;
  const char *names[] = {"L", "P", "n"};
  const double values[] = {35.0, 100.0, 5.0};
  MicaFunction *f = compile_ok("P*(1-(x/L)^2)^n", 3, names, values);
  assert_close(at(f, 2, 0, 0, 0), 100.0 * pow(1 - 4.0 / 1225.0, 5));
  assert_string_equal(mica_function_text(f), "P*(1-(x/L)^2)^n"); /* as written */
  mica_function_destroy(&f);
}

/* d/dx 100*(1-(x/35)^2)^5 = 100*5*(1-(x/35)^2)^4 * (-2x/35^2); d2/dx2 by hand as well. */
static void test_derivatives(void **state) {
  (void)state;
  MicaFunction *f = compile_ok("100*(1-(x/35)^2)^5", 0, NULL, NULL), *df = NULL, *d2f = NULL;
  assert_int_equal(mica_function_derivative(f, 0, &df), MICA_SUCCESS);
  assert_int_equal(mica_function_derivative(df, 0, &d2f), MICA_SUCCESS);
  double x = 2.0, u = 1 - x * x / 1225.0, du = -2 * x / 1225.0, d2u = -2 / 1225.0;
  assert_close(at(df, x, 0, 0, 0), 500 * pow(u, 4) * du);
  assert_close(at(d2f, x, 0, 0, 0), 500 * (4 * pow(u, 3) * du * du + pow(u, 4) * d2u));
  mica_function_destroy(&d2f);
  mica_function_destroy(&df);
  assert_int_equal(mica_function_derivative(f, 1, &df), MICA_SUCCESS); /* no y in it */
  assert_close(at(df, x, 3, 0, 0), 0.0);
  mica_function_destroy(&df);
  mica_function_destroy(&f);
}

/* x^P with P a parameter is differentiated as a constant power: P*x^(P-1), finite at x = 0. */
static void test_parameter_power_derivative(void **state) {
  (void)state;
  const char *names[] = {"P"};
  const double values[] = {3.0};
  MicaFunction *f = compile_ok("x^P * y + t*z", 1, names, values), *dfdx = NULL, *dfdy = NULL, *dfdt = NULL;
  assert_int_equal(mica_function_derivative(f, 0, &dfdx), MICA_SUCCESS);
  assert_int_equal(mica_function_derivative(f, 1, &dfdy), MICA_SUCCESS);
  assert_int_equal(mica_function_derivative(f, 3, &dfdt), MICA_SUCCESS);
  assert_close(at(dfdx, 2, 5, 0, 0), 3 * 4 * 5.0);
  assert_close(at(dfdx, 0, 5, 0, 0), 0.0);
  assert_close(at(dfdy, 2, 5, 0, 0), 8.0);
  assert_close(at(dfdt, 2, 5, 7, 0), 7.0);
  MicaFunction *bad = NULL;
  assert_int_equal(mica_function_derivative(f, 4, &bad), MICA_ERR_ARGUMENT);
  mica_error_clear();
  mica_function_destroy(&dfdx);
  mica_function_destroy(&dfdy);
  mica_function_destroy(&dfdt);
  mica_function_destroy(&f);
}

static void test_unknown_names(void **state) {
  (void)state;
  const char *names[] = {"L", "D", "P"};
  const double values[] = {1, 2, 3};
  expect_error("x^2+q", 3, names, values,
               "unknown name 'q' in \"x^2+q\"; an expression may use x, y, z, t and the parameters (L, D, P)");
  expect_error("x*0 + w", 0, NULL, NULL, "unknown name 'w' in \"x*0 + w\"; an expression may use x, y, z, t");
  double value;
  assert_int_equal(mica_constant_eval("2*x", 3, names, values, &value), MICA_ERR_INPUT);
  if (!strstr(mica_error_message(), "unknown name 'x' in \"2*x\"; a constant expression may use numbers and the "
                                    "parameters (L, D, P)"))
    fail_msg("%s", mica_error_message());
  mica_error_clear();
}

static void test_syntax_errors(void **state) {
  (void)state;
  const char *bad[] = {"x^^2", "sin(x", "x y", "2x", "ln(x)", "x % 2", "", "()", "sin x", "pi(x)", "1.2.3", "+x"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    char expected[64];
    snprintf(expected, sizeof expected, "cannot parse expression \"%s\"", bad[i]);
    expect_error(bad[i], 0, NULL, NULL, expected);
  }
  const char *reserved[] = {"t"};
  const double one[] = {1.0};
  expect_error("x", 1, reserved, one, "parameter 't' has the name of a coordinate");
}

static void test_constant_eval(void **state) {
  (void)state;
  const char *names[] = {"L", "D"};
  const double values[] = {48.0, 12.0};
  double value = 0;
  assert_int_equal(mica_constant_eval("L / 4 + D^2", 2, names, values, &value), MICA_SUCCESS);
  assert_close(value, 12.0 + 144.0);
  assert_int_equal(mica_constant_eval("-D/2", 2, names, values, &value), MICA_SUCCESS);
  assert_close(value, -6.0);
  assert_int_equal(mica_constant_eval("2e3", 0, NULL, NULL, &value), MICA_SUCCESS);
  assert_close(value, 2000.0);
  assert_int_equal(mica_constant_eval("1/0", 0, NULL, NULL, &value), MICA_ERR_INPUT);
  if (!strstr(mica_error_message(), "not a finite number")) fail_msg("%s", mica_error_message());
  mica_error_clear();
}

static void assert_relative(double got, double want, double tol, const char *what) {
  if (!(fabs(got - want) <= tol * fabs(want))) fail_msg("%s: got %.17g, want %.17g (relative %.1e)", what, got, want, tol);
}

/* besselk0/1, besseli0/1 against tabulated values (Abramowitz & Stegun, Tables 9.8 and 9.1; 10 digits), the
 * Wronskian I0 K1 + I1 K0 = 1/u, which holds only if all four are right, and the derivatives K0' = -K1,
 * I0' = I1 through libmatheval's differentiation of the sums. */
static void test_bessel(void **state) {
  (void)state;
  const struct { double u, k0, k1, i0, i1; } table[] = {
      {0.1, 2.427069025, 9.853844781, 1.002501563, 0.05006252604},
      {1.0, 0.4210244382, 0.6019072302, 1.266065878, 0.5651591040},
      {10.0, 1.778006232e-5, 1.864877345e-5, 2815.716628, 2670.988304},
  };
  MicaFunction *k0 = compile_ok("besselk0(x)", 0, NULL, NULL), *k1 = compile_ok("besselk1(x)", 0, NULL, NULL);
  MicaFunction *i0 = compile_ok("besseli0(x)", 0, NULL, NULL), *i1 = compile_ok("besseli1(x)", 0, NULL, NULL);
  for (size_t n = 0; n < sizeof table / sizeof *table; n++) {
    const double u = table[n].u;
    assert_relative(at(k0, u, 0, 0, 0), table[n].k0, 1e-9, "K0");
    assert_relative(at(k1, u, 0, 0, 0), table[n].k1, 1e-9, "K1");
    assert_relative(at(i0, u, 0, 0, 0), table[n].i0, 1e-9, "I0");
    assert_relative(at(i1, u, 0, 0, 0), table[n].i1, 1e-9, "I1");
  }
  const double wronskian_at[] = {1e-5, 1e-3, 0.3, 2.0, 17.0, 80.0, 250.0};
  for (size_t n = 0; n < sizeof wronskian_at / sizeof *wronskian_at; n++) {
    const double u = wronskian_at[n];
    const double w = at(i0, u, 0, 0, 0) * at(k1, u, 0, 0, 0) + at(i1, u, 0, 0, 0) * at(k0, u, 0, 0, 0);
    assert_relative(w, 1 / u, 1e-12, "Wronskian I0 K1 + I1 K0");
  }
  MicaFunction *dk0 = NULL, *di0 = NULL;
  assert_int_equal(mica_function_derivative(k0, 0, &dk0), MICA_SUCCESS);
  assert_int_equal(mica_function_derivative(i0, 0, &di0), MICA_SUCCESS);
  assert_relative(at(dk0, 1.5, 0, 0, 0), -at(k1, 1.5, 0, 0, 0), 1e-12, "K0' = -K1");
  assert_relative(at(di0, 1.5, 0, 0, 0), at(i1, 1.5, 0, 0, 0), 1e-12, "I0' = I1");
  assert_true(isnan(at(k0, 0, 0, 0, 0)) && isnan(at(k1, -1, 0, 0, 0))); /* K_n is not defined for u <= 0 */
  assert_relative(at(i1, -2, 0, 0, 0), -at(i1, 2, 0, 0, 0), 1e-14, "I1 is odd");
  /* parameters inside the argument, nested calls, a constant expression */
  const char *names[] = {"N"};
  const double values[] = {0.5};
  MicaFunction *f = compile_ok("besselk0(x*N)/besselk1(x*N)", 1, names, values);
  assert_relative(at(f, 2, 0, 0, 0), table[1].k0 / table[1].k1, 1e-9, "K0(x N)/K1(x N)");
  double v = 0;
  assert_int_equal(mica_constant_eval("besseli0(besselk0(1)) * 2", 0, NULL, NULL, &v), MICA_SUCCESS);
  assert_true(v > 2 && v < 2.2);
  assert_int_equal(mica_constant_eval("besselk0(0)", 0, NULL, NULL, &v), MICA_ERR_INPUT); /* K0(0): not finite */
  mica_error_clear();
  expect_error("besselk2(x)", 0, NULL, NULL, "unknown function");
  MicaFunction *all[] = {k0, k1, i0, i1, dk0, di0, f};
  for (size_t n = 0; n < sizeof all / sizeof *all; n++) mica_function_destroy(&all[n]);
}

/* mica_function_eval_finite: a finite value passes through; one that is not names the origin, the text, the
 * point (2 or 3 coordinates) and the load factor; a derivative names the setting it came from. */
static void test_eval_finite(void **state) {
  (void)state;
  MicaFunction *f = compile_ok("1/(x-1)", 0, NULL, NULL), *df = NULL;
  mica_function_set_origin(f, "deck.cfg:7", "loads.by");
  double v = 0;
  assert_int_equal(mica_function_eval_finite(f, "in the whole body", 2, (double[3]){3, 0, 0}, 0.5, &v), MICA_SUCCESS);
  assert_close(v, 0.5);
  assert_int_equal(mica_function_eval_finite(f, "in the whole body", 2, (double[3]){1, 2, 0}, 0.5, &v), MICA_ERR_INPUT);
  assert_string_equal(mica_error_message(), "deck.cfg:7: loads.by \"1/(x-1)\" is inf at (x, y) = (1, 2), load factor "
                                            "0.5; write an expression that is finite in the whole body");
  mica_error_clear();
  assert_int_equal(mica_function_derivative(f, 0, &df), MICA_SUCCESS);
  assert_int_equal(mica_function_eval_finite(df, "on the whole set", 3, (double[3]){1, 2, 3}, 1, &v), MICA_ERR_INPUT);
  assert_non_null(strstr(mica_error_message(), "deck.cfg:7: the x-derivative of loads.by \"d(1/(x-1))/dx\" is"));
  assert_non_null(strstr(mica_error_message(), "at (x, y, z) = (1, 2, 3), load factor 1;"));
  mica_error_clear();
  MicaFunction *g = compile_ok("sqrt(x)", 0, NULL, NULL); /* no origin: not from a deck */
  assert_int_equal(mica_function_eval_finite(g, "on the whole set", 2, (double[3]){-1, 0, 0}, 1, &v), MICA_ERR_INPUT);
  assert_string_equal(mica_error_message(), "the expression \"sqrt(x)\" is NaN at (x, y) = (-1, 0), load factor 1; "
                                            "write an expression that is finite on the whole set");
  mica_error_clear();
  mica_function_destroy(&f), mica_function_destroy(&df), mica_function_destroy(&g);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_evaluate_variables), cmocka_unit_test(test_parameters),
      cmocka_unit_test(test_derivatives),        cmocka_unit_test(test_parameter_power_derivative),
      cmocka_unit_test(test_unknown_names),      cmocka_unit_test(test_syntax_errors),
      cmocka_unit_test(test_constant_eval),      cmocka_unit_test(test_bessel),
      cmocka_unit_test(test_eval_finite),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
