/* Charts through gnuplot: a child process in the output directory, its messages in gnuplot.log. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mica/plot.h"

int mica_gnuplot(const char *dir, const char *script, const char *switch_off) {
  fflush(stdout); /* the child must not repeat buffered output */
  pid_t pid = fork();
  MICA_CHECK(pid >= 0, MICA_ERR_LIBRARY, "cannot start gnuplot: %s", strerror(errno));
  if (pid == 0) {
    if (chdir(dir) != 0) _exit(126);
    FILE *log = freopen("gnuplot.log", "w", stderr);
    (void)log;
    execlp("gnuplot", "gnuplot", script, (char *)NULL);
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  MICA_CHECK(WIFEXITED(status) && WEXITSTATUS(status) != 127, MICA_ERR_LIBRARY,
             "gnuplot is not installed: run `make deps` (package gnuplot-nox), or set %s = false", switch_off);
  MICA_CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0, MICA_ERR_LIBRARY,
             "gnuplot failed drawing the chart (exit %d); see gnuplot.log in the output directory",
             WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  return MICA_SUCCESS;
}

/* in, between the quotes q: each character of special preceded by esc, every control character a space (a
 * line break ends a gnuplot command, and a comment); truncated to size between characters, never inside a
 * UTF-8 sequence or an escape pair, so the closing quote is always the one written here. */
static void quoted(const char *in, char q, const char *special, char esc, char *out, size_t size) {
  if (size < 3) {
    if (size) out[0] = '\0';
    return;
  }
  const size_t room = size - 2; /* the closing quote and the NUL */
  size_t j = 0, start = 1;       /* start: where the last character began in out */
  out[j++] = q;
  for (const char *c = in; *c; c++) {
    const int continuation = ((unsigned char)*c & 0xC0) == 0x80;
    const char ch = (unsigned char)*c < 0x20 || *c == 0x7f ? ' ' : *c;
    const int escaped = strchr(special, ch) != NULL;
    if (j + 1 + escaped > room) {
      if (continuation) j = start; /* drop the partial character */
      break;
    }
    if (!continuation) start = j;
    if (escaped) out[j++] = esc;
    out[j++] = ch;
  }
  out[j++] = q;
  out[j] = '\0';
}

/* gnuplot 5.4 reads '...' literally: no backquote (shell) substitution, no @macro expansion, no backslash
 * escapes; the one special character is the quote, written twice. */
void mica_gnuplot_quote(const char *in, char *out, size_t size) { quoted(in, '\'', "'", '\'', out, size); }

/* gnuplot 5.4's data files read "..." with \" for a quote and \\ for a backslash. */
void mica_gnuplot_datum(const char *in, char *out, size_t size) { quoted(in, '"', "\"\\", '\\', out, size); }

void mica_gnuplot_words(const char *in, char *out, size_t size) {
  snprintf(out, size, "%s", in);
  for (char *c = out; *c; c++)
    if (*c == '_') *c = ' ';
}

/* ---- one palette ---- */

static const char *const palette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442"};
enum { NCOLOURS = sizeof palette / sizeof *palette };
static const int dashes[] = {1, 4, 5}; /* solid, dash-dot, dash-dot-dot: one per round of the colours */
/* filled circle, square, triangles, diamond, pentagon; the same open; plus, cross, star */
static const int point_types[] = {7, 5, 9, 11, 13, 15, 6, 4, 8, 10, 12, 14, 1, 2, 3};

const char *mica_gnuplot_colour(int k) { return palette[(k < 0 ? -k : k) % NCOLOURS]; }

void mica_gnuplot_line(int k, char *out, size_t size) {
  k = (k < 0 ? -k : k) % MICA_GNUPLOT_SERIES;
  snprintf(out, size, "lc rgb '%s' dt %d", palette[k % NCOLOURS], dashes[k / NCOLOURS]);
}

void mica_gnuplot_series(int k, char *out, size_t size) {
  char line[64];
  mica_gnuplot_line(k, line, sizeof line);
  k = (k < 0 ? -k : k) % MICA_GNUPLOT_SERIES;
  snprintf(out, size, "%s pt %d", line, point_types[k % (int)(sizeof point_types / sizeof *point_types)]);
}

/* ---- the key ---- */

int mica_gnuplot_key_columns(int width, size_t longest, int maxcols) {
  /* gnuplot's default font: about 8 pixels a character (9 counted), the line sample and gaps about 110 */
  const int fit = (int)((width - 40) / (9 * (long)longest + 110));
  return fit < 1 ? 1 : fit > maxcols ? maxcols : fit;
}

int mica_gnuplot_key_rows(int nentries, int columns) {
  if (columns < 1) columns = 1;
  return nentries > 0 ? (nentries + columns - 1) / columns : 0;
}

int mica_gnuplot_key_below(FILE *fp, int nentries, int columns) {
  const int rows = mica_gnuplot_key_rows(nentries, columns);
  /* margin in character heights: x tic labels and x label (3), the key's rows at spacing 1.2, its box (2) */
  fprintf(fp, "set key at screen 0.5, screen 0.01 center bottom horizontal maxcols %d box spacing 1.2 width 1\n"
              "set bmargin %d\n", columns < 1 ? 1 : columns, 3 + (12 * rows + 9) / 10 + 2);
  return rows;
}

/* ---- ranges ---- */

/* Tics at 2 and 5 (1.5, 2, 3, 5, 7 under a decade) times the powers of 10 in [lo, hi], beside gnuplot's
 * decades. */
static void log_tics(FILE *fp, char axis, double lo, double hi) {
  static const double coarse[] = {2, 5}, fine[] = {1.5, 2, 3, 5, 7};
  const int narrow = hi / lo < 10, nm = narrow ? 5 : 2;
  const double *mantissa = narrow ? fine : coarse;
  int n = 0;
  for (int e = (int)floor(log10(lo)) - 1; e <= (int)ceil(log10(hi)); e++)
    for (int m = 0; m < nm; m++) {
      const double v = mantissa[m] * pow(10.0, e);
      if (v >= lo && v <= hi) fprintf(fp, "%s%.6g", n++ ? ", " : (axis == 'x' ? "set xtics add (" : "set ytics add ("), v);
    }
  if (n) fprintf(fp, ")\n");
}

void mica_gnuplot_range(FILE *fp, char axis, double lo, double hi, int logscale, double margin) {
  if (!(isfinite(lo) && isfinite(hi)) || lo > hi || (logscale && lo <= 0)) return; /* nothing to fit: autoscale */
  if (logscale) {
    const double f = hi > lo ? pow(hi / lo, margin) : 1.1;
    lo /= f, hi *= f;
    if (hi / lo < 1000) log_tics(fp, axis, lo, hi);
  } else {
    const double span = hi > lo ? hi - lo : (lo != 0 ? fabs(lo) : 1.0);
    lo -= margin * span, hi += margin * span;
  }
  fprintf(fp, "set %crange [%.10g:%.10g]\n", axis, lo, hi);
}
