/* Decks: values, defaults, parameters, overrides, variants, the resolved deck, and every kind of input
 * error with its "file:line:" (or "--set ...:") and the setting it names. Run from the repo root. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mica/deck.h"

MICA_SCHEMA_TABLES

/* A schema like the real commands': numbers, arrays, choices, functions, an implied group
 * (sample.line), a list of probes and an overlay of study variants. */
static const MicaDeckKey schema[] = {
    {"parameters", MICA_KEY_PARAMETERS, NULL, 1, 0, NULL, 0, 0, "named numbers and expressions"},
    {"geometry.lower", MICA_KEY_FLOATS, "[0.0, 0.0]", 1, 0, NULL, 1, 3, "lower corner"},
    {"geometry.upper", MICA_KEY_FLOATS, NULL, 1, 0, NULL, 1, 3, "upper corner"},
    {"particles.count", MICA_KEY_INTS, "[11, 11]", 2, 100000, NULL, 1, 3, "particles per axis"},
    {"particles.jitter", MICA_KEY_FLOAT, "0.0", 0, 0.5, NULL, 0, 0, "fraction of the spacing"},
    {"mls.order", MICA_KEY_INT, "1", 0, 3, NULL, 0, 0, "basis order"},
    {"mls.weight", MICA_KEY_CHOICE, "\"cubic\"", 1, 0, "cubic|quartic|quartic-c3|gauss|exponential", 0, 0,
     "weight function"},
    {"mls.radius", MICA_KEY_FLOATS, NULL, 0, INFINITY, NULL, 1, 3, "support radius"},
    {"function.f", MICA_KEY_FUNCTION, "\"0\"", 1, 0, NULL, 0, 0, "the function to approximate"},
    {"sample.line.samples", MICA_KEY_INT, "101", 2, 1e6, NULL, 0, 0, "samples along the line"},
    {"study.variants", MICA_KEY_OVERLAY, NULL, 1, 0, NULL, 0, 0, "variants of the deck"},
    {"output.verbose", MICA_KEY_BOOL, "false", 1, 0, NULL, 0, 0, "print more"},
    {"output.probes", MICA_KEY_LIST, NULL, 1, 0, NULL, 0, 0, "points to report"},
    {"output.probes.[].name", MICA_KEY_STRING, NULL, 1, 0, NULL, 0, 0, "probe name"},
    {"output.probes.[].point", MICA_KEY_FLOATS, NULL, 1, 0, NULL, 1, 3, "probe location"},
    {"output.probes.[].field", MICA_KEY_CHOICE, "\"u\"", 1, 0, "u|stress", 0, 0, "what to report"},
    {NULL, 0, NULL, 0, 0, NULL, 0, 0, NULL}};

static const char *const no_overrides[1] = {NULL};

static MicaDeck *load_ok(const char *path, int noverrides, const char *const *overrides) {
  MicaDeck *deck = NULL;
  int ierr = mica_deck_load(path, schema, noverrides, overrides, &deck);
  if (ierr) fail_msg("loading %s failed: %s", path, mica_error_message());
  return deck;
}

/* The load fails with MICA_ERR_INPUT and a message holding both where and what. */
static void expect_input_error(const char *path, int noverrides, const char *const *overrides, const char *where,
                               const char *what) {
  MicaDeck *deck = NULL;
  int ierr = mica_deck_load(path, schema, noverrides, overrides, &deck);
  const char *message = mica_error_message();
  if (ierr != MICA_ERR_INPUT) fail_msg("expected MICA_ERR_INPUT, got %d: %s", ierr, message);
  assert_null(deck);
  if (!strstr(message, where) || !strstr(message, what))
    fail_msg("message \"%s\" lacks \"%s\" or \"%s\"", message, where, what);
  mica_error_clear();
}

static void assert_message_has(const char *what) {
  if (!strstr(mica_error_message(), what)) fail_msg("message \"%s\" lacks \"%s\"", mica_error_message(), what);
}

static double read_float(const MicaDeck *deck, const char *path) {
  double value = NAN;
  if (mica_deck_float(deck, path, &value)) fail_msg("%s: %s", path, mica_error_message());
  return value;
}

static long read_int(const MicaDeck *deck, const char *path) {
  long value = -1;
  if (mica_deck_int(deck, path, &value)) fail_msg("%s: %s", path, mica_error_message());
  return value;
}

static const char *read_string(const MicaDeck *deck, const char *path) {
  const char *value = NULL;
  if (mica_deck_string(deck, path, &value)) fail_msg("%s: %s", path, mica_error_message());
  return value;
}

static double function_at(const MicaDeck *deck, const char *path, double x) {
  MicaFunction *f = NULL;
  if (mica_deck_function(deck, path, &f)) fail_msg("%s: %s", path, mica_error_message());
  double value = mica_function_eval(f, (double[3]){x, 0, 0}, 0);
  mica_function_destroy(&f);
  return value;
}

/* ---- a good deck ---- */

static void test_values_and_parameters(void **state) {
  (void)state;
  MicaDeck *deck = load_ok("tests/decks/good.cfg", 0, no_overrides);
  assert_string_equal(mica_deck_name(deck), "good");
  assert_string_equal(mica_deck_path(deck), "tests/decks/good.cfg");
  assert_int_equal(read_int(deck, "mls.order"), 2);
  assert_string_equal(read_string(deck, "mls.weight"), "quartic");
  double values[3];
  int count;
  assert_int_equal(mica_deck_floats(deck, "mls.radius", values, 3, &count), MICA_SUCCESS); /* a scalar */
  assert_int_equal(count, 1);
  assert_true(values[0] == 2.5);
  assert_int_equal(mica_deck_floats(deck, "geometry.upper", values, 3, &count), MICA_SUCCESS); /* ("L", "D / 2") */
  assert_int_equal(count, 2);
  assert_true(values[0] == 48.0 && values[1] == 6.0);
  long counts[3];
  assert_int_equal(mica_deck_ints(deck, "particles.count", counts, 3, &count), MICA_SUCCESS); /* ("N", 11) */
  assert_int_equal(count, 2);
  assert_true(counts[0] == 21 && counts[1] == 11);
  assert_true(read_float(deck, "parameters.D") == 12.0);
  assert_true(fabs(function_at(deck, "function.f", 0.0) - 1000.0) < 1e-9);
  assert_true(fabs(function_at(deck, "function.f", 24.0) - 237.3046875) < 1e-9);
  mica_deck_destroy(&deck);
  assert_null(deck);
}

static void test_defaults(void **state) {
  (void)state;
  MicaDeck *deck = load_ok("tests/decks/good.cfg", 0, no_overrides);
  assert_int_equal(read_int(deck, "sample.line.samples"), 101); /* implied groups created */
  int verbose = -1;
  assert_int_equal(mica_deck_bool(deck, "output.verbose", &verbose), MICA_SUCCESS);
  assert_int_equal(verbose, 0);
  assert_int_equal(mica_deck_list_length(deck, "output.probes"), 2);
  assert_string_equal(read_string(deck, "output.probes.[0].name"), "tip");
  assert_string_equal(read_string(deck, "output.probes.[0].field"), "u"); /* default in each element */
  assert_string_equal(read_string(deck, "output.probes.[1].field"), "stress");
  double point[3];
  int count;
  assert_int_equal(mica_deck_floats(deck, "output.probes.[0].point", point, 3, &count), MICA_SUCCESS);
  assert_true(count == 2 && point[0] == 48.0 && point[1] == 0.0);
  assert_true(mica_deck_has(deck, "mls.order"));
  assert_false(mica_deck_has(deck, "mls.nothing"));
  char where[128];
  assert_int_equal(mica_deck_where(deck, "mls.order", where, sizeof where), MICA_SUCCESS);
  assert_string_equal(where, "tests/decks/good.cfg:17");
  assert_int_equal(mica_deck_where(deck, "particles.count.[0]", where, sizeof where), MICA_SUCCESS);
  assert_string_equal(where, "tests/decks/good.cfg:13");
  mica_deck_destroy(&deck);
}

static void test_getter_errors(void **state) {
  (void)state;
  MicaDeck *deck = load_ok("tests/decks/minimal.cfg", 0, no_overrides);
  double values[3];
  int count;
  assert_int_equal(mica_deck_floats(deck, "geometry.upper", values, 3, &count), MICA_ERR_INPUT);
  assert_message_has("geometry.upper is not set");
  assert_int_equal(mica_deck_floats(deck, "no.such.key", values, 3, &count), MICA_ERR_ARGUMENT);
  long order;
  assert_int_equal(mica_deck_int(deck, "mls.order", &order), MICA_SUCCESS);
  assert_int_equal(order, 1);
  mica_error_clear();
  mica_deck_destroy(&deck);
}

static void test_missing_file(void **state) {
  (void)state;
  expect_input_error("tests/decks/no_such_deck.cfg", 0, no_overrides, "no_such_deck.cfg", "cannot read deck");
}

/* ---- overrides ---- */

static void test_overrides(void **state) {
  (void)state;
  const char *const overrides[] = {"mls.order=3",   "particles.count=[21,21,21]", "mls.weight=gauss",
                                   "mls.radius=[1.5, 2.5]", "function.f=\"x^2\"", "output.verbose=true",
                                   "sample.line.samples=7"};
  MicaDeck *deck = load_ok("tests/decks/good.cfg", 7, overrides);
  assert_int_equal(read_int(deck, "mls.order"), 3);
  long counts[3];
  int count;
  assert_int_equal(mica_deck_ints(deck, "particles.count", counts, 3, &count), MICA_SUCCESS);
  assert_true(count == 3 && counts[0] == 21 && counts[2] == 21);
  assert_string_equal(read_string(deck, "mls.weight"), "gauss"); /* a bare word is a string */
  double radius[3];
  assert_int_equal(mica_deck_floats(deck, "mls.radius", radius, 3, &count), MICA_SUCCESS);
  assert_true(count == 2 && radius[0] == 1.5 && radius[1] == 2.5);
  assert_true(function_at(deck, "function.f", 3.0) == 9.0);
  int verbose;
  assert_int_equal(mica_deck_bool(deck, "output.verbose", &verbose), MICA_SUCCESS);
  assert_int_equal(verbose, 1);
  assert_int_equal(read_int(deck, "sample.line.samples"), 7);
  char where[128];
  assert_int_equal(mica_deck_where(deck, "mls.order", where, sizeof where), MICA_SUCCESS);
  assert_string_equal(where, "--set mls.order=3");
  assert_int_equal(mica_deck_where(deck, "mls.weight", where, sizeof where), MICA_SUCCESS);
  assert_string_equal(where, "--set mls.weight=gauss");
  assert_int_equal(mica_deck_where(deck, "mls.radius", where, sizeof where), MICA_SUCCESS);
  assert_string_equal(where, "--set mls.radius=[1.5, 2.5]");
  mica_deck_destroy(&deck);
}

/* Bare text that is no libconfig value (x^2+1, L) is a string: an expression. */
static void test_bare_expression_overrides(void **state) {
  (void)state;
  const char *const overrides[] = {"function.f=x^2+1", "geometry.upper=L", "particles.jitter=1/8"};
  MicaDeck *deck = load_ok("tests/decks/good.cfg", 3, overrides);
  assert_true(function_at(deck, "function.f", 2.0) == 5.0);
  double upper[3];
  int count;
  assert_int_equal(mica_deck_floats(deck, "geometry.upper", upper, 3, &count), MICA_SUCCESS);
  assert_true(count == 1 && upper[0] == 48.0);
  assert_true(read_float(deck, "particles.jitter") == 0.125);
  mica_deck_destroy(&deck);
}

/* --set parameters.P changes every use of P; --set parameters.L keeps L before D, which uses it. */
static void test_parameter_overrides(void **state) {
  (void)state;
  const char *const overrides[] = {"parameters.P=2000", "parameters.L=100"};
  MicaDeck *deck = load_ok("tests/decks/good.cfg", 2, overrides);
  assert_true(fabs(function_at(deck, "function.f", 0.0) - 2000.0) < 1e-9);
  assert_true(fabs(function_at(deck, "function.f", 50.0) - 2000.0 * pow(0.75, 5)) < 1e-9);
  double upper[3];
  int count;
  assert_int_equal(mica_deck_floats(deck, "geometry.upper", upper, 3, &count), MICA_SUCCESS);
  assert_true(count == 2 && upper[0] == 100.0 && upper[1] == 12.5);
  mica_deck_destroy(&deck);
}

static void test_override_errors(void **state) {
  (void)state;
  const char *const misspelt[] = {"mls.oder=3"};
  expect_input_error("tests/decks/good.cfg", 1, misspelt, "--set mls.oder=3: ",
                     "unknown setting 'mls.oder'; did you mean 'mls.order'?");
  const char *const unknown_group[] = {"mesh.size=3"};
  expect_input_error("tests/decks/good.cfg", 1, unknown_group, "--set mesh.size=3: ", "unknown setting 'mesh'");
  const char *const float_order[] = {"mls.order=2.0"};
  expect_input_error("tests/decks/good.cfg", 1, float_order, "--set mls.order=2.0: ",
                     "mls.order must be an integer like 2");
  const char *const out_of_range[] = {"mls.order=9"};
  expect_input_error("tests/decks/good.cfg", 1, out_of_range, "--set mls.order=9: ",
                     "mls.order = 9 is out of range [0, 3]");
  const char *const broken_array[] = {"particles.count=[1,2"};
  expect_input_error("tests/decks/good.cfg", 1, broken_array, "--set particles.count=[1,2: ", "cannot read the value");
  const char *const no_equals[] = {"mls.order"};
  expect_input_error("tests/decks/good.cfg", 1, no_equals, "--set mls.order: ", "expected path=value");
  const char *const bad_path[] = {"mls..order=1"};
  expect_input_error("tests/decks/good.cfg", 1, bad_path, "--set mls..order=1: ", "not a setting path");
  const char *const into_scalar[] = {"mls.order.x=1"};
  expect_input_error("tests/decks/good.cfg", 1, into_scalar, "--set mls.order.x=1: ", "mls.order is an integer, not a group");
  const char *const bad_name[] = {"function.f=x^2+q"};
  expect_input_error("tests/decks/good.cfg", 1, bad_name, "--set function.f=x^2+q: ", "unknown name 'q'");
}

/* ---- errors in deck files: file:line and the setting ---- */

static void test_unknown_key(void **state) {
  (void)state;
  expect_input_error("tests/decks/unknown_key.cfg", 0, no_overrides, "unknown_key.cfg:7: ",
                     "unknown setting 'mls.oder'; did you mean 'mls.order'?");
}

static void test_wrong_type(void **state) {
  (void)state;
  expect_input_error("tests/decks/wrong_type.cfg", 0, no_overrides, "wrong_type.cfg:8: ",
                     "mls.order must be an integer, not a string");
}

static void test_out_of_range(void **state) {
  (void)state;
  expect_input_error("tests/decks/out_of_range.cfg", 0, no_overrides, "out_of_range.cfg:8: ",
                     "mls.order = 7 is out of range [0, 3]");
}

static void test_bad_expression(void **state) {
  (void)state;
  expect_input_error("tests/decks/bad_expression.cfg", 0, no_overrides, "bad_expression.cfg:10: function.f: ",
                     "unknown name 'q' in \"x^2 + q\"; an expression may use x, y, z, t and the parameters (L, P)");
  expect_input_error("tests/decks/bad_parameter.cfg", 0, no_overrides, "bad_parameter.cfg:4: parameters.D: ",
                     "unknown name 'E'");
}

static void test_bad_choice(void **state) {
  (void)state;
  expect_input_error("tests/decks/bad_choice.cfg", 0, no_overrides, "bad_choice.cfg:6: ",
                     "mls.weight = \"cubik\" is not one of cubic|quartic|quartic-c3|gauss|exponential; "
                     "did you mean \"cubic\"?");
}

static void test_syntax_error(void **state) {
  (void)state;
  expect_input_error("tests/decks/syntax_error.cfg", 0, no_overrides, "syntax_error.cfg:6: ", "syntax error");
}

static void test_bad_array_length(void **state) {
  (void)state;
  expect_input_error("tests/decks/bad_array_length.cfg", 0, no_overrides, "bad_array_length.cfg:6: ",
                     "particles.count has 4 values; it needs 1 to 3");
}

static void test_bad_list_member(void **state) {
  (void)state;
  expect_input_error("tests/decks/bad_list.cfg", 0, no_overrides, "bad_list.cfg:8: ",
                     "unknown setting 'output.probes.[1].nmae'; did you mean 'output.probes.[1].name'?");
}

static void test_scalar_for_group(void **state) {
  (void)state;
  expect_input_error("tests/decks/scalar_group.cfg", 0, no_overrides, "scalar_group.cfg:5: ",
                     "mls must be a group { name = value; ... }, not an integer");
}

static void test_bad_variant(void **state) {
  (void)state;
  expect_input_error("tests/decks/bad_variant.cfg", 0, no_overrides, "bad_variant.cfg:9: ",
                     "study.variants.[1].mls.order = 9 is out of range [0, 3]");
}

/* ---- variants ---- */

static void test_variants(void **state) {
  (void)state;
  MicaDeck *deck = load_ok("tests/decks/good.cfg", 0, no_overrides);
  assert_int_equal(mica_deck_list_length(deck, "study.variants"), 2);
  MicaDeck *first = NULL, *second = NULL;
  assert_int_equal(mica_deck_variant(deck, "study.variants", 0, &first), MICA_SUCCESS);
  assert_int_equal(mica_deck_variant(deck, "study.variants", 1, &second), MICA_SUCCESS);
  assert_string_equal(mica_deck_name(first), "p1");
  assert_string_equal(mica_deck_name(second), "variant 2");
  assert_int_equal(read_int(first, "mls.order"), 1);
  assert_true(read_float(first, "mls.radius") == 2.5); /* from the base */
  assert_string_equal(read_string(first, "mls.weight"), "quartic");
  assert_int_equal(read_int(second, "mls.order"), 3);
  assert_true(read_float(second, "mls.radius") == 3.0); /* "D / 4" */
  assert_true(fabs(function_at(second, "function.f", 0.0) - 2000.0) < 1e-9); /* its own P */
  assert_true(fabs(function_at(deck, "function.f", 0.0) - 1000.0) < 1e-9);
  char where[128];
  assert_int_equal(mica_deck_where(first, "mls.order", where, sizeof where), MICA_SUCCESS);
  assert_string_equal(where, "tests/decks/good.cfg:32");
  assert_int_equal(mica_deck_where(first, "mls.radius", where, sizeof where), MICA_SUCCESS);
  assert_string_equal(where, "tests/decks/good.cfg:19");
  MicaDeck *third = NULL;
  assert_int_equal(mica_deck_variant(deck, "study.variants", 2, &third), MICA_ERR_ARGUMENT);
  assert_null(third);
  mica_error_clear();
  mica_deck_destroy(&first);
  mica_deck_destroy(&second);
  mica_deck_destroy(&deck);
}

/* A base expression is checked with the base's parameters at load; a variant's parameters can put it
 * out of range, which the getter reports with the base's line. */
static void test_variant_parameters_checked_by_getter(void **state) {
  (void)state;
  MicaDeck *deck = load_ok("tests/decks/variant_parameters.cfg", 0, no_overrides);
  MicaDeck *rough = NULL;
  assert_int_equal(mica_deck_variant(deck, "study.variants", 0, &rough), MICA_SUCCESS);
  double jitter;
  assert_int_equal(mica_deck_float(deck, "particles.jitter", &jitter), MICA_SUCCESS);
  assert_true(jitter == 0.1);
  assert_int_equal(mica_deck_float(rough, "particles.jitter", &jitter), MICA_ERR_INPUT);
  assert_message_has("variant_parameters.cfg:9: particles.jitter = \"J\" = 0.9 is out of range [0, 0.5]");
  mica_error_clear();
  mica_deck_destroy(&rough);
  mica_deck_destroy(&deck);
}

/* ---- the resolved deck ---- */

static char *read_text(const char *path) {
  FILE *stream = fopen(path, "r");
  assert_non_null(stream);
  static char text[16384];
  size_t length = fread(text, 1, sizeof text - 1, stream);
  text[length] = '\0';
  fclose(stream);
  return text;
}

static void test_write_resolved(void **state) {
  (void)state;
  char dir[] = "/tmp/mica_test_deck_XXXXXX";
  assert_non_null(mkdtemp(dir));
  char resolved[128], variant_path[128];
  snprintf(resolved, sizeof resolved, "%s/resolved.cfg", dir);
  snprintf(variant_path, sizeof variant_path, "%s/p1.cfg", dir);
  const char *const overrides[] = {"mls.order=3", "parameters.P=2000"};
  MicaDeck *deck = load_ok("tests/decks/good.cfg", 2, overrides);
  assert_int_equal(mica_deck_write_resolved(deck, resolved), MICA_SUCCESS);
  const char *text = read_text(resolved);
  assert_non_null(strstr(text, "# resolved by mica from tests/decks/good.cfg with --set mls.order=3 --set "
                               "parameters.P=2000\n"));
  assert_non_null(strstr(text, "samples = 101;")); /* a default, filled in */
  MicaDeck *again = load_ok(resolved, 0, no_overrides);
  assert_int_equal(read_int(again, "mls.order"), 3);
  assert_true(fabs(function_at(again, "function.f", 0.0) - 2000.0) < 1e-9);
  mica_deck_destroy(&again);

  MicaDeck *first = NULL;
  assert_int_equal(mica_deck_variant(deck, "study.variants", 0, &first), MICA_SUCCESS);
  assert_int_equal(mica_deck_write_resolved(first, variant_path), MICA_SUCCESS);
  MicaDeck *alone = load_ok(variant_path, 0, no_overrides);
  assert_int_equal(read_int(alone, "mls.order"), 1);
  assert_true(read_float(alone, "mls.radius") == 2.5);
  assert_int_equal(mica_deck_list_length(alone, "study.variants"), 0);
  mica_deck_destroy(&alone);
  mica_deck_destroy(&first);
  mica_deck_destroy(&deck);
  assert_int_equal(access(variant_path, F_OK), 0);
  unlink(resolved);
  unlink(variant_path);
  rmdir(dir);
}

static void test_print_schema(void **state) {
  (void)state;
  char *text = NULL;
  size_t size = 0;
  FILE *stream = open_memstream(&text, &size);
  assert_non_null(stream);
  mica_deck_print_schema(schema, 100, stream);
  fclose(stream);
  assert_non_null(strstr(text, "mls.order"));
  assert_non_null(strstr(text, "cubic|quartic|quartic-c3|gauss|exponential"));
  assert_non_null(strstr(text, "[0, 3]"));
  assert_non_null(strstr(text, "floats[1-3]"));
  free(text);
}

/* At 70 columns the choices wrap after a '|' under the range column (22 + 11 + 10 + 3 x 2 = 49: 21 columns
 * are left), the help goes under the setting, and no line is wider. */
static void test_print_schema_narrow(void **state) {
  (void)state;
  char *text = NULL;
  size_t size = 0;
  FILE *stream = open_memstream(&text, &size);
  assert_non_null(stream);
  mica_deck_print_schema(schema, 70, stream);
  fclose(stream);
  const char *weight = "mls.weight              choice       \"cubic\"     cubic|quartic|\n"
                       "                                                 quartic-c3|gauss|\n"
                       "                                                 exponential\n"
                       "    weight function\n";
  assert_non_null(strstr(text, weight));
  assert_non_null(strstr(text, "setting                 type         default     range\n    description\n"));
  for (const char *line = text; *line; line = strchr(line, '\n') + 1) assert_true(strcspn(line, "\n") <= 70);
  free(text);
}

/* ---- integers past 32 bits (libconfig 1.5 alone wraps them; deck_text.c keeps them whole) ---- */

static void test_big_integers_keep_their_value(void **state) {
  (void)state;
  MicaDeck *deck = load_ok("tests/decks/big_numbers.cfg", 0, no_overrides);
  assert_true(read_float(deck, "parameters.E") == 2e20);
  assert_true(read_float(deck, "parameters.G") == 7e10);
  assert_true(read_float(deck, "parameters.H") == 4294967296.0);
  double values[3];
  int count;
  assert_int_equal(mica_deck_floats(deck, "geometry.upper", values, 3, &count), MICA_SUCCESS);
  assert_true(count == 2 && values[0] == 2e20 && values[1] == 7e10);
  assert_int_equal(mica_deck_floats(deck, "geometry.lower", values, 3, &count), MICA_SUCCESS);
  assert_true(count == 2 && values[0] == 4294967296.0 && values[1] == -9e9);
  assert_string_equal(read_string(deck, "output.probes.[0].name"), "4294967301 # not a comment");
  mica_deck_destroy(&deck);
}

static void test_big_integers_out_of_range(void **state) {
  (void)state;
  expect_input_error("tests/decks/big_count.cfg", 0, no_overrides, "big_count.cfg:4: ",
                     "particles.count.[1] = 4294967301 is out of range [2, 100000]");
  expect_input_error("tests/decks/big_order.cfg", 0, no_overrides, "big_order.cfg:4: ",
                     "mls.order = 4294967298 is out of range [0, 3]");
  expect_input_error("tests/decks/big_order_real.cfg", 0, no_overrides, "big_order_real.cfg:3: ",
                     "mls.order = 2e+20 is out of range [0, 3]");
  expect_input_error("tests/decks/big_long.cfg", 0, no_overrides, "big_long.cfg:3: ",
                     "99999999999999999999 does not fit in a 64-bit integer");
  const char *const count[] = {"particles.count=[21,4294967301]"};
  expect_input_error("tests/decks/minimal.cfg", 1, count, "--set particles.count=[21,4294967301]: ",
                     "particles.count.[1] = 4294967301 is out of range [2, 100000]");
  const char *const order[] = {"mls.order=4294967298"};
  expect_input_error("tests/decks/minimal.cfg", 1, order, "--set mls.order=4294967298: ",
                     "mls.order = 4294967298 is out of range [0, 3]");
  const char *const jitter[] = {"particles.jitter=-4294967296"};
  expect_input_error("tests/decks/minimal.cfg", 1, jitter, "--set particles.jitter=-4294967296: ",
                     "particles.jitter = -4294967296 is out of range [0, 0.5]");
}

static void test_big_integers_in_included_files(void **state) {
  (void)state;
  expect_input_error("tests/decks/include_big.cfg", 0, no_overrides, "tests/decks/include_big_part.cfg:3: ",
                     "particles.count.[0] = 4294967301 is out of range [2, 100000]");
  const char *const count[] = {"particles.count=[21,21]"};
  expect_input_error("tests/decks/include_big.cfg", 1, count, "tests/decks/include_big.cfg:4: ",
                     "output.verbose must be true or false, not an integer");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_values_and_parameters),
      cmocka_unit_test(test_defaults),
      cmocka_unit_test(test_getter_errors),
      cmocka_unit_test(test_missing_file),
      cmocka_unit_test(test_overrides),
      cmocka_unit_test(test_bare_expression_overrides),
      cmocka_unit_test(test_parameter_overrides),
      cmocka_unit_test(test_override_errors),
      cmocka_unit_test(test_unknown_key),
      cmocka_unit_test(test_wrong_type),
      cmocka_unit_test(test_out_of_range),
      cmocka_unit_test(test_bad_expression),
      cmocka_unit_test(test_bad_choice),
      cmocka_unit_test(test_syntax_error),
      cmocka_unit_test(test_bad_array_length),
      cmocka_unit_test(test_bad_list_member),
      cmocka_unit_test(test_scalar_for_group),
      cmocka_unit_test(test_bad_variant),
      cmocka_unit_test(test_variants),
      cmocka_unit_test(test_variant_parameters_checked_by_getter),
      cmocka_unit_test(test_write_resolved),
      cmocka_unit_test(test_print_schema),
      cmocka_unit_test(test_print_schema_narrow),
      cmocka_unit_test(test_big_integers_keep_their_value),
      cmocka_unit_test(test_big_integers_out_of_range),
      cmocka_unit_test(test_big_integers_in_included_files),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
