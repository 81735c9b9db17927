/* Registries of types in a composed schema (mica/registry.h, mica/schema.h): a chooser's own words before the
 * types' ("auto"), its own default, a key several types declare with different defaults (bc.alpha), and
 * mica_type_float's fallback to the type's own default; a registry fragment (the outputs' idiom: every type's
 * keys in registry order, each naming its type, no chooser; a key two types declare refused); the converted
 * families' flags; the schema as docs/input.md's Markdown table. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "mica/bc.h"
#include "mica/deck.h"
#include "mica/fe.h"

MICA_SCHEMA_TABLES

static const MicaDeckKey a_keys[] = {
    {.path = "alpha", .type = MICA_KEY_FLOAT, .def = "1", .min = 0, .max = 10, .help = "the factor"},
    {.path = "beta", .type = MICA_KEY_INT, .def = "3", .min = 0, .max = 10, .help = "a's own"},
    {0}};
static const MicaDeckKey b_keys[] = {
    {.path = "alpha", .type = MICA_KEY_FLOAT, .def = "2.5", .min = 0, .max = 10, .help = "the factor"}, {0}};
static const MicaDeckKey c_keys[] = {
    {.path = "beta", .type = MICA_KEY_INT, .def = "3", .min = 0, .max = 10, .help = "a's own"}, {0}};
static const MicaType type_a = {"a", "first", 1, a_keys, NULL}, type_b = {"b", "second", 2, b_keys, NULL},
                      type_c = {"c", "third", 0, c_keys, NULL};
static const MicaType *const builtin[] = {&type_a, &type_b, &type_c, NULL};
static MicaRegistry toy = {"toy", "a", builtin, NULL, 0, NULL};

static const MicaDeckKey base[] = {
    {.path = "g.kind", .type = MICA_KEY_CHOICE, .def = "\"auto\"", .min = 1, .max = 0, .choices = "auto",
     .registry = &toy, .help = "which"},
    {0}};

static void test_compose_choices_and_defaults(void **state) {
  (void)state;
  MicaSchema *schema = NULL;
  assert_int_equal(mica_schema_compose(base, &schema), MICA_SUCCESS);
  const MicaDeckKey *keys = mica_schema_keys(schema);
  const MicaDeckKey *kind = mica_schema_find(keys, "g.kind");
  assert_non_null(kind);
  assert_string_equal(kind->choices, "auto|a|b|c");
  assert_string_equal(kind->def, "\"auto\"");
  const MicaDeckKey *alpha = mica_schema_find(keys, "g.alpha");
  assert_non_null(alpha);
  assert_null(alpha->def); /* 1 with a, 2.5 with b: none in the schema */
  assert_string_equal(alpha->owner, "a|b");
  assert_string_equal(alpha->help, "with g.kind = a or b: the factor (default: 1 with a, 2.5 with b)");
  const MicaDeckKey *beta = mica_schema_find(keys, "g.beta"); /* a and c agree: the default stays */
  assert_non_null(beta);
  assert_string_equal(beta->def, "3");
  assert_string_equal(beta->help, "with g.kind = a or c: a's own");
  mica_schema_destroy(&schema);
}

/* A family whose types are enabled side by side: each type's keys under the fragment's path, in registry order. */
static const MicaDeckKey on_keys[] = {
    {.path = "on", .type = MICA_KEY_BOOL, .def = "true", .min = 1, .max = 0, .help = "switch"}, {0}};
static const MicaDeckKey list_keys[] = {
    {.path = "items", .type = MICA_KEY_LIST, .min = 1, .max = 0, .help = "the list"},
    {.path = "items.[].name", .type = MICA_KEY_STRING, .min = 1, .max = 0, .help = "a name"}, {0}};
static const MicaType side_on = {"on", "switched", 0, on_keys, NULL}, side_none = {"none", "no keys", 0, NULL, NULL},
                      side_list = {"list", "listed", 0, list_keys, NULL}, side_twice = {"twice", "again", 0, on_keys, NULL};
static const MicaType *const side_builtin[] = {&side_on, &side_none, &side_list, NULL};
static MicaRegistry side = {"side", NULL, side_builtin, NULL, 0, NULL};
static const MicaDeckKey side_base[] = {
    {.path = "first", .type = MICA_KEY_INT, .def = "1", .min = 0, .max = 9, .help = "before"},
    {.path = "out", .type = MICA_KEY_FRAGMENT, .min = 1, .max = 0, .registry = &side},
    {.path = "last", .type = MICA_KEY_INT, .def = "2", .min = 0, .max = 9, .help = "after"},
    {0}};

static void test_registry_fragment(void **state) {
  (void)state;
  MicaSchema *schema = NULL;
  assert_int_equal(mica_schema_compose(side_base, &schema), MICA_SUCCESS);
  const MicaDeckKey *keys = mica_schema_keys(schema);
  static const char *const order[] = {"first", "out.on", "out.items", "out.items.[].name", "last"};
  static const char *const owner[] = {NULL, "on", "list", "list", NULL};
  for (int i = 0; i < 5; i++) {
    assert_non_null(keys[i].path);
    assert_string_equal(keys[i].path, order[i]);
    if (owner[i]) {
      assert_string_equal(keys[i].owner, owner[i]);
      assert_ptr_equal(keys[i].family, &side);
    } else {
      assert_null(keys[i].owner);
    }
    assert_null(keys[i].chooser);
  }
  assert_null(keys[5].path);
  assert_string_equal(mica_schema_find(keys, "out.on")->help, "switch"); /* no "with ... =": nothing chooses */
  mica_schema_destroy(&schema);
  /* a type added at run time follows the built-in ones; one that declares a key again is refused */
  static const MicaType side_more = {"more", "added", 0, c_keys, NULL};
  assert_int_equal(mica_registry_add(&side, &side_more), MICA_SUCCESS);
  assert_int_equal(mica_schema_compose(side_base, &schema), MICA_SUCCESS);
  assert_string_equal(mica_schema_keys(schema)[4].path, "out.beta");
  mica_schema_destroy(&schema);
  assert_int_equal(mica_registry_add(&side, &side_twice), MICA_SUCCESS);
  assert_int_equal(mica_schema_compose(side_base, &schema), MICA_ERR_ARGUMENT);
  assert_null(schema);
  free(side.added);
  side.added = NULL, side.nadded = 0;
}

/* A reader with one setting, g.alpha = 7, or none. */
static int given;
static int toy_has(const void *ctx, const char *path) { return (void)ctx, given && !strcmp(path, "g.alpha"); }
static int toy_float(const void *ctx, const char *path, double *value) {
  (void)ctx;
  if (!given || strcmp(path, "g.alpha")) return MICA_ERR_ARGUMENT;
  *value = 7;
  return MICA_SUCCESS;
}
static const MicaSettingsOps toy_ops = {toy_has, NULL, toy_float, NULL, NULL, NULL, NULL};

static void test_type_float(void **state) {
  (void)state;
  const MicaSettings settings = {&toy_ops, NULL};
  double value = 0;
  given = 0;
  assert_int_equal(mica_type_float(&type_a, &settings, "g", "alpha", &value), MICA_SUCCESS);
  assert_true(value == 1.0);
  assert_int_equal(mica_type_float(&type_b, &settings, "g", "alpha", &value), MICA_SUCCESS);
  assert_true(value == 2.5);
  assert_int_equal(mica_type_float(&type_c, &settings, "g", "alpha", &value), MICA_ERR_ARGUMENT);
  mica_error_clear();
  given = 1;
  assert_int_equal(mica_type_float(&type_b, &settings, "g", "alpha", &value), MICA_SUCCESS);
  assert_true(value == 7.0);
}

/* The converted families: names, defaults and the flags code asks instead of comparing ops pointers. */
static void test_families(void **state) {
  (void)state;
  assert_string_equal(mica_registry_default(&mica_bc_method_registry)->name, "nitsche");
  assert_true(mica_bc_method_has(&mica_bc_nitsche, MICA_BC_SYMMETRIC_DEFINITE | MICA_BC_MODEL_TRACTION));
  assert_true(mica_bc_method_has(&mica_bc_lagrange, MICA_BC_MULTIPLIERS));
  assert_false(mica_bc_method_has(&mica_bc_lagrange, MICA_BC_SYMMETRIC_DEFINITE));
  assert_false(mica_bc_method_has(&mica_bc_penalty, MICA_BC_MODEL_TRACTION));
  assert_true(mica_bc_method_has(&mica_bc_collocation, MICA_BC_COLLOCATION));
  assert_false(mica_bc_method_has(&mica_bc_collocation, MICA_BC_SYMMETRIC_DEFINITE | MICA_BC_MULTIPLIERS));
  assert_ptr_equal(mica_bc_method_find("penalty"), &mica_bc_penalty);
  assert_null(mica_bc_method_find("nitsch"));
  assert_true(mica_linear_solver_has(&mica_linear_cholmod, MICA_LINEAR_SPD_ONLY));
  assert_false(mica_linear_solver_has(&mica_linear_cholmod, MICA_LINEAR_DISTRIBUTED));
  assert_true(mica_linear_solver_has(&mica_linear_petsc, MICA_LINEAR_DISTRIBUTED));
  assert_false(mica_linear_solver_has(&mica_linear_umfpack, MICA_LINEAR_SPD_ONLY));
  assert_true(mica_approx_has(&mica_approx_mls, MICA_APPROX_MLS));
  assert_false(mica_approx_has(&mica_approx_mls, MICA_APPROX_INTERPOLATING));
  assert_string_equal(mica_registry_default(&mica_approx_registry)->name, "efg");
  char choices[128];
  assert_int_equal(mica_registry_choices(&mica_approx_registry, choices, sizeof choices), MICA_SUCCESS);
  assert_string_equal(choices, "efg|fe");
}

/* The Markdown table of docs/input.md (mica_deck_print_schema_markdown): one row per composed key in schema
 * order; a chooser's types and a fragment type's description after the help, as the text help prints them
 * under it; '|', '*' and a '<' that would open a tag escaped; --group's rows only, none of them bad input. */
static const MicaDeckKey md_base[] = {
    {.path = "g.kind", .type = MICA_KEY_CHOICE, .min = 1, .max = 0, .registry = &toy, .help = "which: x|y, 2*3 < 4 <b>"},
    {.path = "out", .type = MICA_KEY_FRAGMENT, .min = 1, .max = 0, .registry = &side},
    {.path = "h.n", .type = MICA_KEY_INT, .def = "4", .min = 1, .max = 9, .help = "count"},
    {0}};

static char *markdown(const char *group, int expect) {
  char *text = NULL;
  size_t size = 0;
  FILE *stream = open_memstream(&text, &size);
  assert_non_null(stream);
  assert_int_equal(mica_deck_print_schema_markdown(md_base, group, stream), expect);
  fclose(stream);
  return text;
}

static void test_markdown_table(void **state) {
  (void)state;
  const char *head = "| setting | type | default | range | meaning |\n|---|---|---|---|---|\n";
  const char *g = "| `g.kind` | choice | \"a\" | a\\|b\\|c | which: x\\|y, 2\\*3 < 4 &lt;b><br>`a`: first<br>`b`: second"
                  "<br>`c`: third |\n"
                  "| `g.alpha` | float | - | [0, 10] | with g.kind = a or b: the factor (default: 1 with a, 2.5 with b) |\n"
                  "| `g.beta` | int | 3 | [0, 10] | with g.kind = a or c: a's own |\n";
  const char *out = "| `out.on` | bool | true |  | switch<br>side `on`: switched |\n"
                    "| `out.items` | list | - |  | the list<br>side `list`: listed |\n"
                    "| `out.items.[].name` | string | - |  | a name |\n";
  const char *h = "| `h.n` | int | 4 | [1, 9] | count |\n";
  char expected[2048], *text = markdown(NULL, MICA_SUCCESS);
  snprintf(expected, sizeof expected, "%s%s%s%s", head, g, out, h);
  assert_string_equal(text, expected);
  free(text);
  text = markdown("g", MICA_SUCCESS);
  snprintf(expected, sizeof expected, "%s%s", head, g);
  assert_string_equal(text, expected);
  free(text);
  text = markdown("out.items", MICA_SUCCESS); /* a group's first row keeps its type's description */
  snprintf(expected, sizeof expected, "%s%s", head, strstr(out, "| `out.items`"));
  assert_string_equal(text, expected);
  free(text);
  for (int i = 0; i < 2; i++) { /* "g.k" is no group of g.kind; nothing printed */
    text = markdown(i ? "g.k" : "nothing", MICA_ERR_INPUT);
    assert_string_equal(text, "");
    assert_non_null(strstr(mica_error_message(), "no setting is in the group"));
    mica_error_clear();
    free(text);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_compose_choices_and_defaults),
      cmocka_unit_test(test_type_float),
      cmocka_unit_test(test_registry_fragment),
      cmocka_unit_test(test_families),
      cmocka_unit_test(test_markdown_table),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
