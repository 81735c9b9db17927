/* Chart helpers (src/io/plot.c): the series styles stay apart for MICA_GNUPLOT_SERIES series, deck strings
 * lose what gnuplot would run or read as a new command, a fitted range holds its values with a margin. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/plot.h"

static void test_series_distinct(void **state) {
  (void)state;
  char style[MICA_GNUPLOT_SERIES][96];
  for (int k = 0; k < MICA_GNUPLOT_SERIES; k++) {
    char line[96];
    mica_gnuplot_series(k, style[k], sizeof style[k]);
    mica_gnuplot_line(k, line, sizeof line);
    /* colour and dash alone tell series apart (a chart of lines has no points) */
    for (int j = 0; j < k; j++) {
      char other[96];
      mica_gnuplot_line(j, other, sizeof other);
      if (!strcmp(line, other)) fail_msg("series %d and %d look alike: %s", j, k, line);
    }
    assert_non_null(strstr(style[k], line));
    assert_null(strstr(style[k], "'black'")); /* black is kept for references */
  }
  /* the first seven are Okabe & Ito's colours, solid */
  assert_string_equal(style[0], "lc rgb '#0072B2' dt 1 pt 7");
  assert_string_equal(mica_gnuplot_colour(1), "#D55E00");
  char wrapped[96];
  mica_gnuplot_series(MICA_GNUPLOT_SERIES, wrapped, sizeof wrapped);
  assert_string_equal(wrapped, style[0]);
}

static void test_label_safe(void **state) {
  (void)state;
  char out[128];
  /* gnuplot 5.4 single quotes: only the quote is special (doubled); a line break would end the command */
  mica_gnuplot_quote("a`touch x`'b\"c\\d\nset output 'e' @m $(f) ;!g", out, sizeof out);
  assert_string_equal(out, "'a`touch x`''b\"c\\d set output ''e'' @m $(f) ;!g'");
  mica_gnuplot_quote("x_1^2 {a} & ~", out, sizeof out); /* printed as written: the terminals are noenhanced */
  assert_string_equal(out, "'x_1^2 {a} & ~'");
  mica_gnuplot_words("a_over_l", out, sizeof out);
  assert_string_equal(out, "a over l");
  mica_gnuplot_quote("σ_max/σ_∞", out, sizeof out); /* UTF-8 passes */
  assert_string_equal(out, "'σ_max/σ_∞'");
  /* truncation keeps the closing quote its own: never half a '' pair, never half a UTF-8 character */
  mica_gnuplot_quote("abcdef", out, 6);
  assert_string_equal(out, "'abc'");
  mica_gnuplot_quote("ab'cd", out, 6);
  assert_string_equal(out, "'ab'");
  mica_gnuplot_quote("a'", out, 6);
  assert_string_equal(out, "'a'''");
  mica_gnuplot_quote("aσ", out, 5);
  assert_string_equal(out, "'a'");
  mica_gnuplot_quote("anything", out, 2);
  assert_string_equal(out, "");
  /* data files: \" and \\ inside double quotes, one line */
  mica_gnuplot_datum("p\\\"q\nr'", out, sizeof out);
  assert_string_equal(out, "\"p\\\\\\\"q r'\"");
}

/* Reads "set Xrange [lo:hi]" from what mica_gnuplot_range wrote. */
static void range_of(double lo, double hi, int logscale, double *rlo, double *rhi, char *text, size_t size) {
  FILE *fp = fmemopen(text, size, "w");
  assert_non_null(fp);
  mica_gnuplot_range(fp, 'y', lo, hi, logscale, 0.06);
  fclose(fp);
  const char *r = strstr(text, "set yrange [");
  assert_non_null(r);
  assert_int_equal(sscanf(r, "set yrange [%lf:%lf]", rlo, rhi), 2);
}

static void test_range_margin(void **state) {
  (void)state;
  char text[512];
  double lo, hi;
  range_of(1.93, 3.0, 0, &lo, &hi, text, sizeof text); /* the classical 3 is the largest value */
  assert_true(lo < 1.93 - 0.05 * 1.07 && hi > 3.0 + 0.05 * 1.07);
  range_of(1.0, 7.0, 1, &lo, &hi, text, sizeof text);
  assert_true(lo < 1.0 && hi > 7.0);
  assert_non_null(strstr(text, "set ytics add (")); /* under a decade: tics between the decades */
  range_of(3.0, 3.0, 0, &lo, &hi, text, sizeof text); /* one value: a range around it */
  assert_true(lo < 3.0 && hi > 3.0);
  memset(text, 0, sizeof text);
  FILE *fp = fmemopen(text, sizeof text, "w");
  mica_gnuplot_range(fp, 'y', -1.0, 2.0, 1, 0.06); /* nothing positive to fit on a log axis: autoscale */
  fclose(fp);
  assert_string_equal(text, "");
}

static void test_key(void **state) {
  (void)state;
  assert_int_equal(mica_gnuplot_key_rows(5, 2), 3);
  assert_int_equal(mica_gnuplot_key_rows(0, 2), 0);
  assert_int_equal(mica_gnuplot_key_columns(900, 45, 3), 1);
  assert_int_equal(mica_gnuplot_key_columns(1100, 22, 4), 3);
  char text[256];
  FILE *fp = fmemopen(text, sizeof text, "w");
  assert_int_equal(mica_gnuplot_key_below(fp, 7, 2), 4);
  fclose(fp);
  assert_non_null(strstr(text, "set key at screen 0.5, screen 0.01 center bottom horizontal maxcols 2"));
  assert_non_null(strstr(text, "set bmargin 10\n")); /* 3 + 4 rows at 1.2 + 2 */
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_series_distinct), cmocka_unit_test(test_label_safe), cmocka_unit_test(test_range_margin),
      cmocka_unit_test(test_key),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
