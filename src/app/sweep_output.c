/* Outputs of `mica sweep`: sweep.csv (one row per point), the measured points of sweep.experiments, and
 * the chart sweep.png/.svg drawn by gnuplot from sweep_points.dat, sweep_analytic.dat,
 * sweep_experiments.dat and sweep_chart.gp (kept in the output directory for re-plotting). */
#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mica/files.h"
#include "mica/plot.h"
#include "sweep.h"

enum { FINE = 201 }; /* samples of an analytic curve */
/* A chart's curve values ("a = 1, model = svk") and titles: room for several axes of a path and a word each;
 * titles, labels and names of the deck are at most MICA_DECK_TEXT_MAX (deck_check.c refuses longer ones). */
enum { VALUES_MAX = 4096, TITLE_MAX = VALUES_MAX + 512 };

/* ---- sweep.csv -------------------------------------------------------------------------------------- */

void sweep_csv_quoted(FILE *fp, const char *text) {
  fputc('"', fp);
  for (const char *c = text; *c; c++) {
    if (*c == '"') fputc('"', fp);
    fputc(*c == '\n' || *c == '\r' ? ' ' : *c, fp);
  }
  fputc('"', fp);
}

void sweep_csv_header(FILE *fp, const SweepAxis *axes, int naxes) {
  fprintf(fp, "index");
  for (int a = 0; a < naxes; a++) fprintf(fp, ",%s", axes[a].path);
}

void sweep_csv_choices(FILE *fp, const SweepAxis *axes, int naxes, long p, const int *choice) {
  fprintf(fp, "%ld", p + 1);
  for (int a = 0; a < naxes; a++) {
    fputc(',', fp);
    if (axes[a].values) fprintf(fp, "%.17g", axes[a].values[choice[a]]);
    else sweep_csv_quoted(fp, axes[a].words[choice[a]]);
  }
}

static void put_row(FILE *fp, const SweepSpec *spec, long p, const SweepPoint *pt) {
  sweep_csv_choices(fp, spec->axes, spec->naxes, p, pt->choice);
  for (int i = 0; i < spec->nprobes; i++) {
    fputc(',', fp);
    if (isfinite(pt->probe[i])) fprintf(fp, "%.17g", pt->probe[i]);
  }
  fprintf(fp, ",%.6g,%s,", pt->time, !pt->status ? "ok" : pt->reached ? "failed" : "error");
  if (pt->status) sweep_csv_quoted(fp, pt->message ? pt->message : "");
  fputc('\n', fp);
}

int sweep_write_csv(const SweepSpec *spec, const SweepPoint *points, const char *outdir) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "sweep.csv", &out));
  sweep_csv_header(out.fp, spec->axes, spec->naxes);
  for (int i = 0; i < spec->nprobes; i++) fprintf(out.fp, ",%s", spec->probes[i]);
  fprintf(out.fp, ",time_total,status,message\n");
  for (long p = 0; p < spec->npoints; p++) put_row(out.fp, spec, p, &points[p]);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

/* ---- measured points -------------------------------------------------------------------------------- */

/* "x,y", "x;y" or "x y"; any other line (a header, a comment) is not a point. */
static int parse_pair(const char *line, double *x, double *y) {
  char *end;
  *x = strtod(line, &end);
  if (end == line) return 0;
  const char *next = end + strspn(end, " \t,;");
  *y = strtod(next, &end);
  return end != next && isfinite(*x) && isfinite(*y);
}

static int data_path(const SweepSpec *spec, const char *file, const char *where, char *buf, size_t size) {
  char deck_path[4096];
  snprintf(deck_path, sizeof deck_path, "%s", mica_deck_path(spec->deck));
  const int n = file[0] == '/' ? snprintf(buf, size, "%s", file) : snprintf(buf, size, "%s/%s", dirname(deck_path), file);
  MICA_CHECK(n >= 0 && (size_t)n < size, MICA_ERR_INPUT, "%s: the file's path, beside the deck, is %d bytes long; at "
             "most %zu are allowed: move the deck or the file to a shorter path", where, n, size - 1);
  return MICA_SUCCESS;
}

static int read_points(FILE *fp, SweepData *data) {
  char line[4096];
  int capacity = 0;
  while (fgets(line, sizeof line, fp)) {
    double x, y;
    if (!parse_pair(line + strspn(line, " \t"), &x, &y)) continue;
    if (data->n == capacity) {
      capacity = capacity ? 2 * capacity : 64;
      MICA_CALL(MICA_REALLOC(data->x, capacity));
      MICA_CALL(MICA_REALLOC(data->y, capacity));
    }
    data->x[data->n] = x, data->y[data->n] = y;
    data->n++;
  }
  return MICA_SUCCESS;
}

static int read_experiment(SweepSpec *spec, int e) {
  char path[96], where[SWEEP_WHERE_MAX], file[4096];
  const char *name;
  SweepData *data = &spec->experiments[e];
  snprintf(path, sizeof path, "sweep.experiments.[%d].name", e);
  data->name = mica_deck_has(spec->deck, path) && mica_deck_string(spec->deck, path, &name) == MICA_SUCCESS
                   ? name : "measured";
  snprintf(path, sizeof path, "sweep.experiments.[%d].file", e);
  mica_deck_where(spec->deck, path, where, sizeof where);
  MICA_CHECK(mica_deck_has(spec->deck, path), MICA_ERR_INPUT, "%s: sweep.experiments.[%d] needs a file", where, e);
  MICA_CALL(mica_deck_string(spec->deck, path, &name));
  MICA_CALL(data_path(spec, name, where, file, sizeof file));
  FILE *fp = fopen(file, "r");
  MICA_CHECK(fp, MICA_ERR_INPUT, "%s: cannot read %s: %s", where, file, strerror(errno));
  const int ierr = read_points(fp, data);
  fclose(fp);
  MICA_CALL(ierr);
  MICA_CHECK(data->n > 0, MICA_ERR_INPUT, "%s: %s has no x,y rows", where, file);
  return MICA_SUCCESS;
}

int sweep_read_experiments(SweepSpec *spec) {
  MICA_CALL(MICA_CALLOC(spec->experiments, spec->nexperiments > 0 ? spec->nexperiments : 1));
  for (int e = 0; e < spec->nexperiments; e++) MICA_CALL(read_experiment(spec, e));
  return MICA_SUCCESS;
}

/* ---- curves ----------------------------------------------------------------------------------------- */

/* The curves of the chart: in a grid, one per combination of the axes other than x, each represented by
 * its point at the first x value; in a zip, one. */
typedef struct {
  int n;
  long *first; /* the representative point of each curve */
} Curves;

static int curves_find(const SweepSpec *spec, const SweepPoint *pts, Curves *c) {
  MICA_CALL(MICA_MALLOC(c->first, spec->npoints));
  c->n = 0;
  for (long p = 0; p < spec->npoints; p++)
    if (spec->zip ? p == 0 : pts[p].choice[spec->x] == 0) c->first[c->n++] = p;
  return MICA_SUCCESS;
}

static int same_curve(const SweepSpec *spec, const SweepPoint *pts, long p, long first) {
  if (spec->zip) return 1;
  for (int a = 0; a < spec->naxes; a++)
    if (a != spec->x && pts[p].choice[a] != pts[first].choice[a]) return 0;
  return 1;
}

/* One block per curve: the curve's successful points by increasing x. Returns the number of points. */
static int write_curve(FILE *fp, const SweepSpec *spec, const SweepPoint *pts, long first) {
  const SweepAxis *xa = &spec->axes[spec->x];
  double last = -INFINITY;
  int written = 0;
  for (;;) { /* selection by increasing x: the axis's values need not be sorted */
    long next = -1;
    for (long p = 0; p < spec->npoints; p++) {
      const double x = xa->values[pts[p].choice[spec->x]];
      if (x > last && same_curve(spec, pts, p, first) && (next < 0 || x < xa->values[pts[next].choice[spec->x]]))
        next = p;
    }
    if (next < 0) break;
    last = xa->values[pts[next].choice[spec->x]];
    for (long p = 0; p < spec->npoints; p++) /* every point at this x (a zip may repeat an x) */
      if (xa->values[pts[p].choice[spec->x]] == last && same_curve(spec, pts, p, first) && !pts[p].status &&
          isfinite(pts[p].probe[spec->probe])) {
        fprintf(fp, "%.17g %.17g\n", last, pts[p].probe[spec->probe]);
        written++;
      }
  }
  fprintf(fp, "\n\n");
  return written;
}

/* ---- analytic curves -------------------------------------------------------------------------------- */

static void fine_grid(const SweepSpec *spec, double *x) {
  const SweepAxis *xa = &spec->axes[spec->x];
  double lo = xa->values[0], hi = xa->values[0];
  for (int v = 1; v < xa->nvalues; v++) lo = fmin(lo, xa->values[v]), hi = fmax(hi, xa->values[v]);
  const int logscale = spec->logx && lo > 0;
  for (int i = 0; i < FINE; i++) {
    const double s = (double)i / (FINE - 1);
    x[i] = logscale ? lo * pow(hi / lo, s) : lo + (hi - lo) * s;
  }
}

/* The analytic curves of one chart curve: its values of the other axes are overrides, so the deck's
 * parameters they change are bound in the expressions. y[k * FINE + i] = curve k at x[i]. */
static int analytic_eval(const SweepSpec *spec, const SweepPoint *pts, long first, const double *x, double *y) {
  char (*text)[SWEEP_OVERRIDE_MAX] = NULL;
  const char **list = NULL;
  MicaDeck *deck = NULL;
  MicaFunction *f = NULL;
  int n = 0, ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(text, spec->naxes));
  MICA_CALL_CLEANUP(MICA_CALLOC(list, spec->naxes));
  for (int a = 0; a < spec->naxes && !spec->zip; a++)
    if (a != spec->x) {
      sweep_override_text(&spec->axes[a], pts[first].choice[a], text[n], sizeof text[n]);
      list[n] = text[n];
      n++;
    }
  MICA_CALL_CLEANUP(sweep_load(spec, 0, NULL, n, list, &deck));
  for (int k = 0; k < spec->nanalytic; k++) {
    char path[64];
    snprintf(path, sizeof path, "sweep.analytic.[%d].f", k);
    MICA_CALL_CLEANUP(mica_deck_function(deck, path, &f));
    for (int i = 0; i < FINE; i++) y[k * FINE + i] = mica_function_eval(f, (double[3]){x[i], 0, 0}, 0.0);
    mica_function_destroy(&f);
  }
cleanup:
  mica_function_destroy(&f);
  mica_deck_destroy(&deck);
  free(text);
  free(list);
  return ierr;
}

/* Analytic curve k of chart curve c, unless an earlier chart curve gave the same values (the
 * expression does not depend on what distinguishes them). */
static int analytic_repeats(const double *y, int nanalytic, int c, int k) {
  for (int b = 0; b < c; b++)
    if (!memcmp(&y[(b * nanalytic + k) * FINE], &y[(c * nanalytic + k) * FINE], FINE * sizeof *y)) return 1;
  return 0;
}

/* A gap in the line is one blank line between finite values (two would end the block, and a block without a
 * data line would not count as one for gnuplot's `index`: a curve with no finite value is one NaN). */
static void write_analytic_block(FILE *fp, const double *x, const double *y) {
  int written = 0, gap = 0;
  for (int i = 0; i < FINE; i++) {
    if (!isfinite(y[i])) {
      gap = written;
      continue;
    }
    fprintf(fp, "%s%.10g %.10g\n", gap ? "\n" : "", x[i], y[i]);
    written = 1, gap = 0;
  }
  if (!written) fprintf(fp, "%.10g NaN\n", x[0]);
  fprintf(fp, "\n\n");
}

/* ---- the chart -------------------------------------------------------------------------------------- */

typedef struct {
  Curves curves;
  int *npoints;       /* per curve: points written */
  double x[FINE];
  double *analytic;   /* [curve][analytic][FINE] */
  int *shared;        /* per analytic curve: 1 when every chart curve gives it the same values */
  FILE *script;       /* the plot command being written (a memory stream) */
  int nplots;
  size_t longest;     /* the longest title, for the key's columns */
  double xlo, xhi, ylo, yhi; /* what the chart shows: points, analytic curves, experiments */
  const double *threshold;    /* per word of the model axis: its threshold (NAN: none), or NULL */
} Chart;

/* The models' thresholds as vertical lines over the chart's y extent (sweep_thresholds.dat, a block each). */
static int write_thresholds_file(const SweepSpec *spec, const char *outdir, const Chart *ch) {
  if (!ch->threshold) return MICA_SUCCESS;
  int any = 0;
  for (int w = 0; w < spec->axes[spec->model_axis].nvalues; w++) any |= isfinite(ch->threshold[w]);
  if (!any) return MICA_SUCCESS;
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "sweep_thresholds.dat", &out));
  fprintf(out.fp, "# each model's threshold (summary.json model_thresholds): one vertical line a block\n");
  for (int w = 0; w < spec->axes[spec->model_axis].nvalues; w++)
    if (isfinite(ch->threshold[w]))
      fprintf(out.fp, "%.17g %.17g\n%.17g %.17g\n\n\n", ch->threshold[w], ch->ylo, ch->threshold[w], ch->yhi);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

static int write_points_file(const SweepSpec *spec, const SweepPoint *pts, const char *outdir, Chart *ch) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(ch->npoints, ch->curves.n));
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "sweep_points.dat", &out));
  char x[256], y[256]; /* in data-file quotes: one comment line */
  mica_gnuplot_datum(spec->axes[spec->x].path, x, sizeof x);
  mica_gnuplot_datum(spec->probes[spec->probe], y, sizeof y);
  fprintf(out.fp, "# x = %s, y = %s; one block per curve\n", x, y);
  for (int c = 0; c < ch->curves.n; c++) ch->npoints[c] = write_curve(out.fp, spec, pts, ch->curves.first[c]);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

static void find_shared(const SweepSpec *spec, Chart *ch) {
  for (int k = 0; k < spec->nanalytic; k++) {
    ch->shared[k] = 1;
    for (int c = 1; c < ch->curves.n && ch->shared[k]; c++) ch->shared[k] = analytic_repeats(ch->analytic, spec->nanalytic, c, k);
  }
}

static int write_analytic_file(const SweepSpec *spec, const SweepPoint *pts, const char *outdir, Chart *ch) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  if (!spec->nanalytic) return MICA_SUCCESS;
  fine_grid(spec, ch->x);
  MICA_CALL_CLEANUP(MICA_MALLOC(ch->analytic, (size_t)ch->curves.n * (size_t)spec->nanalytic * FINE));
  MICA_CALL_CLEANUP(MICA_CALLOC(ch->shared, spec->nanalytic));
  for (int c = 0; c < ch->curves.n; c++)
    MICA_CALL_CLEANUP(analytic_eval(spec, pts, ch->curves.first[c], ch->x, &ch->analytic[c * spec->nanalytic * FINE]));
  find_shared(spec, ch);
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "sweep_analytic.dat", &out));
  fprintf(out.fp, "# one block per chart curve and analytic curve (curve-major)\n");
  for (int c = 0; c < ch->curves.n; c++)
    for (int k = 0; k < spec->nanalytic; k++)
      write_analytic_block(out.fp, ch->x, &ch->analytic[(c * spec->nanalytic + k) * FINE]);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

static int write_experiments_file(const SweepSpec *spec, const char *outdir) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  if (!spec->nexperiments) return MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "sweep_experiments.dat", &out));
  for (int e = 0; e < spec->nexperiments; e++) {
    char name[512];
    mica_gnuplot_datum(spec->experiments[e].name, name, sizeof name);
    fprintf(out.fp, "# %s\n", name);
    for (int i = 0; i < spec->experiments[e].n; i++)
      fprintf(out.fp, "%.17g %.17g\n", spec->experiments[e].x[i], spec->experiments[e].y[i]);
    fprintf(out.fp, "\n\n");
  }
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

/* ---- what the chart shows: its ranges ---- */

static void extend(const SweepSpec *spec, Chart *ch, double x, double y) {
  if (!isfinite(x) || !isfinite(y) || (spec->logx && x <= 0) || (spec->logy && y <= 0)) return;
  ch->xlo = fmin(ch->xlo, x), ch->xhi = fmax(ch->xhi, x);
  ch->ylo = fmin(ch->ylo, y), ch->yhi = fmax(ch->yhi, y);
}

/* Analytic curve k of chart curve c is drawn: it has a value the axes can show, and no earlier chart curve
 * drew the same one. */
static int analytic_drawn(const SweepSpec *spec, const Chart *ch, int c, int k) {
  if (analytic_repeats(ch->analytic, spec->nanalytic, c, k)) return 0;
  const double *y = &ch->analytic[(c * spec->nanalytic + k) * FINE];
  for (int i = 0; i < FINE; i++)
    if (isfinite(y[i]) && (!spec->logy || y[i] > 0) && (!spec->logx || ch->x[i] > 0)) return 1;
  return 0;
}

static void find_extent(const SweepSpec *spec, const SweepPoint *pts, Chart *ch) {
  ch->xlo = ch->ylo = INFINITY, ch->xhi = ch->yhi = -INFINITY;
  for (long p = 0; p < spec->npoints; p++)
    if (!pts[p].status) extend(spec, ch, spec->axes[spec->x].values[pts[p].choice[spec->x]], pts[p].probe[spec->probe]);
  for (int c = 0; c < ch->curves.n; c++)
    for (int k = 0; k < spec->nanalytic; k++)
      if (analytic_drawn(spec, ch, c, k))
        for (int i = 0; i < FINE; i++) extend(spec, ch, ch->x[i], ch->analytic[(c * spec->nanalytic + k) * FINE + i]);
  for (int e = 0; e < spec->nexperiments; e++)
    for (int i = 0; i < spec->experiments[e].n; i++) extend(spec, ch, spec->experiments[e].x[i], spec->experiments[e].y[i]);
}

/* ---- the plot command ---- */

/* "N = 0.93, L = 8": the values that make chart curve `first`, or "" for a single curve. */
static void curve_values(const SweepSpec *spec, const SweepPoint *pts, long first, char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  for (int a = 0; a < spec->naxes && !spec->zip; a++) {
    if (a == spec->x) continue;
    const SweepAxis *axis = &spec->axes[a];
    const int v = pts[first].choice[a];
    char value[MICA_DECK_LONG_TEXT_MAX + 1];
    if (axis->values) snprintf(value, sizeof value, "%g", axis->values[v]);
    else snprintf(value, sizeof value, "%s", axis->words[v]);
    const int n = snprintf(buf + used, size - used, "%s%s = %s", used ? ", " : "", axis->label, value);
    if (n > 0 && (size_t)n < size - used) used += (size_t)n;
  }
}

/* One plot item, its title made safe for gnuplot; on log axes values that are not positive are left out. */
static void plot_item(const SweepSpec *spec, Chart *ch, const char *file, int index, const char *style,
                      const char *title) {
  char safe[2 * TITLE_MAX + 3]; /* every quote doubled, and the two around it */
  mica_gnuplot_quote(title, safe, sizeof safe);
  if (strlen(title) > ch->longest) ch->longest = strlen(title);
  fprintf(ch->script, "%s'%s' index %d using %s:%s %s title %s", ch->nplots++ ? ", \\\n     " : "", file, index,
          spec->logx ? "($1 > 0 ? $1 : 1/0)" : "1", spec->logy ? "($2 > 0 ? $2 : 1/0)" : "2", style, safe);
}

static void plot_points(const SweepSpec *spec, const SweepPoint *pts, Chart *ch) {
  for (int c = 0; c < ch->curves.n; c++) {
    if (!ch->npoints[c]) continue;
    char values[VALUES_MAX], title[TITLE_MAX], series[96], style[160];
    curve_values(spec, pts, ch->curves.first[c], values, sizeof values);
    snprintf(title, sizeof title, values[0] ? "mica, %s" : "mica", values);
    mica_gnuplot_series(c, series, sizeof series);
    snprintf(style, sizeof style, "with linespoints lw 1.5 ps 1.1 %s", series);
    plot_item(spec, ch, "sweep_points.dat", c, style, title);
  }
}

/* A level (the same constant for every chart curve: a classical limit) is drawn once, in black, dashed; a
 * reference shared by several chart curves once, in black, dash-dot; any other for each chart curve, in its
 * colour, dashed (dash-dot, dotted for a second and third such reference). */
static int analytic_level(const SweepSpec *spec, const Chart *ch, int k) {
  const double *y = &ch->analytic[k * FINE];
  double first = NAN;
  for (int i = 0; i < FINE; i++)
    if (isfinite(y[i])) {
      if (isnan(first)) first = y[i];
      else if (y[i] != first) return 0;
    }
  (void)spec;
  return ch->shared[k] && !isnan(first);
}

static void analytic_style(const SweepSpec *spec, const Chart *ch, int c, int k, char *style, size_t size) {
  static const int dash[] = {2, 4, 3};
  int rank = 0; /* the references before k drawn in the curves' colours */
  for (int j = 0; j < k; j++) rank += !analytic_level(spec, ch, j) && !(ch->shared[j] && ch->curves.n > 1);
  if (analytic_level(spec, ch, k)) snprintf(style, size, "with lines lw 1.5 lc rgb 'black' dt 2");
  else if (ch->shared[k] && ch->curves.n > 1) snprintf(style, size, "with lines lw 2 lc rgb 'black' dt 4");
  else snprintf(style, size, "with lines lw 2 lc rgb '%s' dt %d", mica_gnuplot_colour(c), dash[rank % 3]);
}

static void plot_analytic(const SweepSpec *spec, const SweepPoint *pts, Chart *ch) {
  for (int c = 0; c < ch->curves.n; c++)
    for (int k = 0; k < spec->nanalytic; k++) {
      if (!analytic_drawn(spec, ch, c, k)) continue;
      char path[64], title[TITLE_MAX], values[VALUES_MAX], style[128];
      const char *name = NULL;
      snprintf(path, sizeof path, "sweep.analytic.[%d].name", k);
      if (!mica_deck_has(spec->deck, path) || mica_deck_string(spec->deck, path, &name)) name = "analytic";
      curve_values(spec, pts, ch->curves.first[c], values, sizeof values);
      snprintf(title, sizeof title, !ch->shared[k] && values[0] ? "%s, %s" : "%s", name, values);
      analytic_style(spec, ch, c, k, style, sizeof style);
      plot_item(spec, ch, "sweep_analytic.dat", c * spec->nanalytic + k, style, title);
    }
}

static void plot_thresholds(const SweepSpec *spec, Chart *ch) {
  if (!ch->threshold) return;
  const SweepAxis *models = &spec->axes[spec->model_axis];
  for (int w = 0, block = 0; w < models->nvalues; w++) {
    if (!isfinite(ch->threshold[w])) continue;
    char title[TITLE_MAX];
    snprintf(title, sizeof title, "%s agrees with %s from %s = %.4g (within %g)", models->words[w], spec->classical,
             spec->axes[spec->x].label, ch->threshold[w], spec->tolerance);
    plot_item(spec, ch, "sweep_thresholds.dat", block++, "with lines lw 1.5 lc rgb 'gray30' dt 3", title);
  }
}

static void plot_items(const SweepSpec *spec, const SweepPoint *pts, Chart *ch) {
  ch->nplots = 0;
  plot_points(spec, pts, ch);
  plot_analytic(spec, pts, ch);
  plot_thresholds(spec, ch);
  static const int open_marker[] = {6, 4, 8, 10, 12, 14}; /* circle, square, triangles, diamond, pentagon */
  for (int e = 0; e < spec->nexperiments; e++) {
    char style[64]; /* a distinct open marker per data set, so the sets stay apart without colour */
    snprintf(style, sizeof style, "with points pt %d ps 1.2 lc rgb 'black'", open_marker[e % 6]);
    plot_item(spec, ch, "sweep_experiments.dat", e, style, spec->experiments[e].name);
  }
  fprintf(ch->script, "\n");
}

/* ---- the axis labels ---- */

/* sweep.xlabel, or the swept name in words: "parameter a over l" for parameters.a_over_l, "mls dilation". */
static int x_label(const SweepSpec *spec, char *buf, size_t size) {
  const SweepAxis *axis = &spec->axes[spec->x];
  const char *text;
  char words[VALUES_MAX];
  MICA_CALL(mica_deck_string(spec->deck, "sweep.xlabel", &text));
  if (text[0]) {
    snprintf(buf, size, "%s", text);
    return MICA_SUCCESS;
  }
  mica_gnuplot_words(axis->label, words, sizeof words);
  for (char *dot = strchr(words, '.'); dot; dot = strchr(dot, '.')) *dot = ' ';
  snprintf(buf, size, "%s%s", axis->label == axis->path ? "" : "parameter ", words);
  return MICA_SUCCESS;
}

/* sweep.ylabel, or the probe's name in words and what it probes: "stiffness ratio (probe of uy)". */
static int y_label(const SweepSpec *spec, char *buf, size_t size) {
  const char *text, *field = "energy";
  char path[64], words[VALUES_MAX];
  MICA_CALL(mica_deck_string(spec->deck, "sweep.ylabel", &text));
  if (text[0]) {
    snprintf(buf, size, "%s", text);
    return MICA_SUCCESS;
  }
  snprintf(path, sizeof path, "output.probes.[%d].field", spec->probe);
  if (mica_deck_has(spec->deck, path)) MICA_CALL(mica_deck_string(spec->deck, path, &field));
  mica_gnuplot_words(spec->probes[spec->probe], words, sizeof words);
  snprintf(buf, size, "%s (probe of %s)", words, field);
  return MICA_SUCCESS;
}

/* ---- the script ---- */

static int write_header(const SweepSpec *spec, Chart *ch, int pass, FILE *fp) {
  char text[TITLE_MAX], title[2 * TITLE_MAX + 3], xlabel[2 * TITLE_MAX + 3], ylabel[2 * TITLE_MAX + 3];
  const char *deck_title;
  MICA_CALL(mica_deck_string(spec->deck, "problem.title", &deck_title));
  mica_gnuplot_quote(deck_title[0] ? deck_title : mica_deck_name(spec->deck), title, sizeof title);
  MICA_CALL(x_label(spec, text, sizeof text));
  mica_gnuplot_quote(text, xlabel, sizeof xlabel);
  MICA_CALL(y_label(spec, text, sizeof text));
  mica_gnuplot_quote(text, ylabel, sizeof ylabel);
  const int columns = mica_gnuplot_key_columns(900, ch->longest, 3);
  const int rows = mica_gnuplot_key_rows(ch->nplots, columns), height = 560 + 22 * rows;
  fprintf(fp, pass ? "set terminal svg size 900,%d noenhanced\nset output 'sweep.svg'\n"
                   : "set terminal pngcairo size 900,%d noenhanced\nset output 'sweep.png'\n", height);
  fprintf(fp, "set title %s\nset xlabel %s\nset ylabel %s\nset grid\n%s%s", title, xlabel, ylabel,
          spec->logx ? "set logscale x\n" : "", spec->logy ? "set logscale y\n" : "");
  mica_gnuplot_key_below(fp, ch->nplots, columns);
  /* every curve, reference and measured point inside the frame, none on the border */
  mica_gnuplot_range(fp, 'x', ch->xlo, ch->xhi, spec->logx, 0.03);
  mica_gnuplot_range(fp, 'y', ch->ylo, ch->yhi, spec->logy, 0.06);
  return MICA_SUCCESS;
}

static int write_script(const SweepSpec *spec, const SweepPoint *pts, const char *outdir, Chart *ch) {
  MicaOutFile out = {0};
  char *items = NULL;
  size_t items_size = 0;
  int ierr = MICA_SUCCESS;
  find_extent(spec, pts, ch);
  MICA_CALL(write_thresholds_file(spec, outdir, ch));
  ch->script = open_memstream(&items, &items_size);
  MICA_CHECK(ch->script, MICA_ERR_MEMORY, "cannot open a memory stream for the chart: %s", strerror(errno));
  plot_items(spec, pts, ch);
  fclose(ch->script);
  ch->script = NULL;
  if (!ch->nplots) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_NUMERIC, "nothing to chart: no point has a finite %s",
                          spec->probes[spec->probe]);
    goto cleanup;
  }
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "sweep_chart.gp", &out));
  char probe[256], path[256];
  mica_gnuplot_quote(spec->probes[spec->probe], probe, sizeof probe);
  mica_gnuplot_quote(spec->axes[spec->x].path, path, sizeof path);
  fprintf(out.fp, "# mica sweep: %s against %s (data: sweep_points.dat, sweep_analytic.dat, sweep_experiments.dat)\n",
          probe, path);
  for (int pass = 0; pass < 2; pass++) {
    MICA_CALL_CLEANUP(write_header(spec, ch, pass, out.fp));
    fprintf(out.fp, "plot %sset output\n", items);
    if (!pass) fprintf(out.fp, "reset\n");
  }
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  free(items);
  return ierr;
}

int sweep_write_chart(const SweepSpec *spec, const SweepPoint *points, const double *threshold, const char *outdir) {
  Chart ch;
  int ierr = MICA_SUCCESS;
  memset(&ch, 0, sizeof ch);
  ch.threshold = threshold;
  MICA_CALL_CLEANUP(curves_find(spec, points, &ch.curves));
  MICA_CALL_CLEANUP(write_points_file(spec, points, outdir, &ch));
  MICA_CALL_CLEANUP(write_analytic_file(spec, points, outdir, &ch));
  MICA_CALL_CLEANUP(write_experiments_file(spec, outdir));
  MICA_CALL_CLEANUP(write_script(spec, points, outdir, &ch));
  MICA_CALL_CLEANUP(mica_gnuplot(outdir, "sweep_chart.gp", "sweep.chart"));
cleanup:
  free(ch.curves.first);
  free(ch.npoints);
  free(ch.analytic);
  free(ch.shared);
  return ierr;
}
