/* Text for the terminal: widths in code points, wrapping (widths, hanging indent, breaks after '|', long
 * words cut, UTF-8 kept whole, nothing lost or added but the line breaks) and the edit distance. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/text.h"

/* What mica_text_wrap prints for these arguments (the caller frees it). */
static char *wrapped(const char *text, int column, int indent, int width, const char *breaks) {
  char *out = NULL;
  size_t size = 0;
  FILE *stream = open_memstream(&out, &size);
  assert_non_null(stream);
  mica_text_wrap(stream, text, column, indent, width, breaks);
  fclose(stream);
  return out;
}

/* Every line of out at most width code points wide (the first from column), none ending in a space. */
static void assert_fits(const char *out, int column, int width) {
  for (const char *line = out; *line; line = strchr(line, '\n') + 1) {
    size_t n = strcspn(line, "\n");
    assert_true(mica_text_width(line, n) + column <= width);
    assert_true(n == 0 || line[n - 1] != ' ');
    column = 0;
  }
}

static void test_width(void **state) {
  (void)state;
  assert_int_equal(mica_text_width("abc", SIZE_MAX), 3);
  assert_int_equal(mica_text_width("±1 × λ §", SIZE_MAX), 8); /* 12 bytes */
  assert_int_equal(mica_text_width("±1 × λ §", 3), 2);          /* "±1" */
  assert_int_equal(mica_text_width("", SIZE_MAX), 0);
}

static void test_paragraph(void **state) {
  (void)state;
  const char *text = "the local spacing mls.dilation multiplies, per axis: near, the nearer neighbor's distance";
  char *out = wrapped(text, 4, 4, 30, NULL);
  assert_string_equal(out, "the local spacing\n"
                           "    mls.dilation multiplies,\n"
                           "    per axis: near, the nearer\n"
                           "    neighbor's distance\n");
  assert_fits(out, 4, 30);
  free(out);
  out = wrapped("one\ntwo  three", 0, 0, 100, NULL); /* newlines and runs of spaces are one space */
  assert_string_equal(out, "one two three\n");
  free(out);
  out = wrapped("short", 0, 0, 100, NULL);
  assert_string_equal(out, "short\n");
  free(out);
}

static void test_choices(void **state) {
  (void)state;
  char *out = wrapped("linear|svk|neohooke|neohooke-cook|cosserat|couple-stress", 10, 10, 40, "|");
  assert_string_equal(out, "linear|svk|neohooke|\n"
                           "          neohooke-cook|cosserat|\n"
                           "          couple-stress\n");
  assert_fits(out, 10, 40);
  free(out);
}

static void test_long_words(void **state) {
  (void)state;
  char *out = wrapped("abcdefghijklmnopqrstuvwxyz", 0, 2, 10, NULL); /* cut; nothing lost */
  assert_string_equal(out, "abcdefghij\n  klmnopqr\n  stuvwxyz\n");
  free(out);
  out = wrapped("λλλλλλλλλλλλ ok", 0, 0, 5, NULL); /* cut between code points, five a line */
  assert_string_equal(out, "λλλλλ\nλλλλλ\nλλ ok\n");
  assert_fits(out, 0, 5);
  free(out);
  out = wrapped("word", 20, 4, 10, NULL); /* the caller's line is already too long: start below */
  assert_string_equal(out, "\n    word\n");
  free(out);
}

static void test_pad(void **state) {
  (void)state;
  char *out = NULL;
  size_t size = 0;
  FILE *stream = open_memstream(&out, &size);
  mica_text_pad(stream, "±x", 4);
  mica_text_pad(stream, "toolong", 3);
  fclose(stream);
  assert_string_equal(out, "±x  toolong");
  free(out);
}

static void test_distance(void **state) {
  (void)state;
  assert_int_equal(mica_text_distance("kitten", "sitting"), 3);
  assert_int_equal(mica_text_distance("outptu", "output"), 2);
  assert_int_equal(mica_text_distance("", "set"), 3);
  assert_int_equal(mica_text_distance("help", "help"), 0);
  assert_true(mica_text_close(2, "outptu"));
  assert_false(mica_text_close(3, "set"));
  assert_true(mica_text_close(3, "dilatationx")); /* 11 letters: 3 allowed */
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_width),      cmocka_unit_test(test_paragraph), cmocka_unit_test(test_choices),
      cmocka_unit_test(test_long_words), cmocka_unit_test(test_pad),       cmocka_unit_test(test_distance),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
