/* Outputs of `mica study`: study.csv (one row per combination) and two charts drawn by gnuplot from
 * study_points.dat, study_front.dat, study_fastest.dat and study_chart.gp (kept in the output directory for
 * re-plotting): study_time.png/.svg, the error against time on log-log axes with the Pareto front as a
 * staircase, its points labelled by their choices, the target error and the fastest combination that
 * reaches it; study_dofs.png/.svg, the error against the number of unknowns. Combinations that differ only
 * in the last choice (the one that varies fastest: typically the resolution) are joined by a line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/files.h"
#include "mica/plot.h"
#include "study.h"

enum { LABEL_MAX = 2048 };

/* ---- study.csv ---------------------------------------------------------------------------------------- */

/* A number, or an empty field when there is none. */
static void put_number(FILE *fp, const char *format, double v) {
  fputc(',', fp);
  if (isfinite(v)) fprintf(fp, format, v);
}

static void put_row(FILE *fp, const StudySpec *spec, long p, const StudyRow *row) {
  sweep_csv_choices(fp, spec->choices, spec->nchoices, p, row->choice);
  const int ok = row->status == MICA_SUCCESS;
  fprintf(fp, ",%s", ok ? "ok" : row->reached ? "failed" : "error");
  if (ok)
    fprintf(fp, ",%ld,%ld,%ld,%ld,%ld,%ld,%ld,%ld", row->dofs, row->particles, row->quadrature_points, row->nnz,
            row->nnz_factor, row->cache_bytes, row->matrix_bytes, study_memory_bytes(row));
  else
    fprintf(fp, ",,,,,,,,");
  for (int k = 0; k < STUDY_NPHASES; k++) put_number(fp, "%.9g", row->phase[k]);
  put_number(fp, "%.9g", ok ? study_solve_time(row) : NAN);
  put_number(fp, "%.9g", ok ? study_total_time(row) : NAN);
  put_number(fp, "%.17g", row->error_l2);
  put_number(fp, "%.17g", row->error_h1);
  put_number(fp, "%.17g", row->error_energy);
  for (int i = 0; i < spec->nprobes; i++) put_number(fp, "%.17g", row->probe[i]);
  put_number(fp, "%.17g", row->error);
  put_number(fp, "%.17g", row->time); /* exact: the Pareto flags can be checked from the file */
  fprintf(fp, ",%d,", row->pareto);
  if (!ok) sweep_csv_quoted(fp, row->message ? row->message : "");
  fputc('\n', fp);
}

int study_write_csv(const StudySpec *spec, const StudyRow *rows, const char *outdir) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "study.csv", &out));
  sweep_csv_header(out.fp, spec->choices, spec->nchoices);
  fprintf(out.fp, ",status,dofs,particles,quadrature_points,nnz,nnz_factor,cache_bytes,matrix_bytes,memory_bytes");
  for (int k = 0; k < STUDY_NPHASES; k++) fprintf(out.fp, ",%s", study_phase_column[k]);
  fprintf(out.fp, ",time_solve_total,time_total,error_l2,error_h1,error_energy");
  for (int i = 0; i < spec->nprobes; i++) fprintf(out.fp, ",%s", spec->probes[i]);
  fprintf(out.fp, ",error,time,pareto,message\n");
  for (long p = 0; p < spec->ncombinations; p++) put_row(out.fp, spec, p, &rows[p]);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

/* ---- chart data --------------------------------------------------------------------------------------- */

static int plotted(const StudyRow *row) {
  return row->status == MICA_SUCCESS && row->error > 0 && row->time > 0 && isfinite(row->error) && isfinite(row->time);
}

/* Rows p and q differ at most in the last choice. */
static int same_curve(const StudySpec *spec, const StudyRow *rows, long p, long q) {
  for (int c = 0; c + 1 < spec->nchoices; c++)
    if (rows[p].choice[c] != rows[q].choice[c]) return 0;
  return 1;
}

/* The curves: one per combination of every choice but the last, each named by its first row. */
typedef struct {
  long n;
  long *first;
  int *npoints;
} Curves;

static int curves_find(const StudySpec *spec, const StudyRow *rows, Curves *cv) {
  MICA_CALL(MICA_MALLOC(cv->first, spec->ncombinations));
  MICA_CALL(MICA_CALLOC(cv->npoints, spec->ncombinations));
  cv->n = 0;
  for (long p = 0; p < spec->ncombinations; p++)
    if (rows[p].choice[spec->nchoices - 1] == 0) cv->first[cv->n++] = p;
  return MICA_SUCCESS;
}

static void curve_label(const StudySpec *spec, const StudyRow *rows, long first, char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  for (int c = 0; c + 1 < spec->nchoices; c++) {
    char label[LABEL_MAX];
    sweep_value_label(&spec->choices[c], rows[first].choice[c], label, sizeof label);
    const int n = snprintf(buf + used, size - used, "%s%s", used ? " " : "", label);
    if (n > 0 && (size_t)n < size - used) used += (size_t)n;
  }
  if (!used) snprintf(buf, size, "%s", spec->choices[spec->nchoices - 1].label);
}

/* study_points.dat: one block per curve, "time error dofs" in the order of the last choice's values. */
static int write_points(const StudySpec *spec, const StudyRow *rows, const char *outdir, Curves *cv) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "study_points.dat", &out));
  char error[LABEL_MAX], path[LABEL_MAX]; /* in data-file quotes: one comment line */
  mica_gnuplot_datum(spec->error_name, error, sizeof error);
  mica_gnuplot_datum(spec->choices[spec->nchoices - 1].path, path, sizeof path);
  fprintf(out.fp, "# time (s), %s error, dofs; one block per combination of all choices but %s\n", error, path);
  for (long k = 0; k < cv->n; k++) {
    for (long p = 0; p < spec->ncombinations; p++)
      if (same_curve(spec, rows, p, cv->first[k]) && plotted(&rows[p])) {
        fprintf(out.fp, "%.10g %.10g %ld\n", rows[p].time, rows[p].error, rows[p].dofs);
        cv->npoints[k]++;
      }
    fprintf(out.fp, "\n\n");
  }
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

/* study_front.dat: the front by increasing time, "time error dofs \"label\"". Returns the number of points. */
static int write_front(const StudySpec *spec, const StudyRow *rows, const char *outdir, long *nfront) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  *nfront = 0;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "study_front.dat", &out));
  char error[256];
  mica_gnuplot_datum(spec->error_name, error, sizeof error);
  fprintf(out.fp, "# the Pareto front by increasing time: time (s), %s error, dofs, choice\n", error);
  double last = -INFINITY;
  for (;;) { /* selection by increasing time */
    long next = -1;
    for (long p = 0; p < spec->ncombinations; p++)
      if (rows[p].pareto && plotted(&rows[p]) && rows[p].time > last && (next < 0 || rows[p].time < rows[next].time))
        next = p;
    if (next < 0) break;
    last = rows[next].time;
    for (long p = 0; p < spec->ncombinations; p++) /* equal times: every one of them */
      if (rows[p].pareto && plotted(&rows[p]) && rows[p].time == last) {
        char text[LABEL_MAX], safe[LABEL_MAX];
        study_choice_text(spec, rows[p].choice, text, sizeof text);
        mica_gnuplot_datum(text, safe, sizeof safe);
        fprintf(out.fp, "%.10g %.10g %ld %s\n", rows[p].time, rows[p].error, rows[p].dofs, safe);
        ++*nfront;
      }
  }
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

static int write_fastest(const StudyRow *rows, long fastest, const char *outdir) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "study_fastest.dat", &out));
  fprintf(out.fp, "# the fastest combination that reaches the target: time (s), error, dofs\n");
  if (fastest >= 0) fprintf(out.fp, "%.10g %.10g %ld\n", rows[fastest].time, rows[fastest].error, rows[fastest].dofs);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

/* ---- the script --------------------------------------------------------------------------------------- */

typedef struct {
  FILE *fp;
  int nplots;
} Plot;

static void item(Plot *pl, const char *text) { fprintf(pl->fp, "%s%s", pl->nplots++ ? ", \\\n     " : "", text); }

/* One chart: x column 1 (time) or 3 (dofs) of the data files. */
static void write_chart(const StudySpec *spec, const StudyRow *rows, const Curves *cv, long nfront, long fastest,
                        int xcol, FILE *fp) {
  Plot pl = {fp, 0};
  char text[LABEL_MAX + 256], label[LABEL_MAX], safe[LABEL_MAX];
  const char *x = xcol == 1 ? "($1 > 0 ? $1 : 1/0)" : "($3 > 0 ? $3 : 1/0)";
  fprintf(fp, "plot ");
  for (long k = 0; k < cv->n; k++) {
    if (!cv->npoints[k]) continue;
    curve_label(spec, rows, cv->first[k], label, sizeof label);
    mica_gnuplot_quote(label, safe, sizeof safe);
    char series[96];
    mica_gnuplot_series((int)k, series, sizeof series);
    snprintf(text, sizeof text, "'study_points.dat' index %ld using %s:($2 > 0 ? $2 : 1/0) with linespoints lw 1.2 ps 0.9 %s "
             "title %s", k, x, series, safe);
    item(&pl, text);
  }
  if (nfront) {
    if (xcol == 1) {
      item(&pl, "'study_front.dat' using 1:2 with steps lw 2.5 lc rgb 'black' title 'Pareto front'");
      item(&pl, "'study_front.dat' using 1:2:4 with labels left offset 0.6,0.6 font ',8' rotate by 20 notitle");
    }
    snprintf(text, sizeof text, "'study_front.dat' using %s:2 with points pt 6 ps 1.8 lw 1.5 lc rgb 'black' title '%s'",
             x, xcol == 1 ? "on the front" : "on the front (error against time)");
    item(&pl, text);
  }
  if (fastest >= 0) {
    snprintf(label, sizeof label, "fastest to %s error <= %g", spec->error_name, spec->target);
    mica_gnuplot_quote(label, safe, sizeof safe);
    snprintf(text, sizeof text, "'study_fastest.dat' using %s:2 with points pt 7 ps 2.4 lc rgb 'black' title %s", x,
             safe);
    item(&pl, text);
  }
  snprintf(text, sizeof text, "%.17g with lines dt 2 lw 1.5 lc rgb 'black' title 'target %g'", spec->target,
           spec->target);
  item(&pl, text);
  fprintf(fp, "\n");
}

/* The key's entries (titled plot items) of a chart and the longest curve title. */
static int key_entries(const StudySpec *spec, const StudyRow *rows, const Curves *cv, long nfront, long fastest,
                       int xcol, size_t *longest) {
  int n = 1; /* the target */
  char label[LABEL_MAX];
  char fastest_title[LABEL_MAX];
  snprintf(fastest_title, sizeof fastest_title, "fastest to %s error <= %g", spec->error_name, spec->target);
  *longest = strlen(fastest_title);
  for (long k = 0; k < cv->n; k++)
    if (cv->npoints[k]) {
      curve_label(spec, rows, cv->first[k], label, sizeof label);
      if (strlen(label) > *longest) *longest = strlen(label);
      n++;
    }
  if (nfront) n += xcol == 1 ? 2 : 1;
  return n + (fastest >= 0);
}

static int write_script(const StudySpec *spec, const StudyRow *rows, const Curves *cv, long nfront, long fastest,
                        const char *outdir) {
  char title[512], error_title[MICA_DECK_TEXT_MAX + 64], text[1024], quoted[3][1024];
  const char *deck_title;
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_deck_string(spec->deck, "problem.title", &deck_title));
  snprintf(title, sizeof title, "%s", deck_title[0] ? deck_title : mica_deck_name(spec->deck));
  study_error_title(spec, error_title, sizeof error_title); /* a probe's name is the deck's */
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "study_chart.gp", &out));
  mica_gnuplot_quote(error_title, quoted[0], sizeof quoted[0]);
  fprintf(out.fp, "# mica study: %s against time and against dofs (data: study_points.dat, study_front.dat, "
          "study_fastest.dat)\n", quoted[0]);
  for (int chart = 0; chart < 2; chart++)
    for (int pass = 0; pass < 2; pass++) {
      const char *name = chart ? "study_dofs" : "study_time";
      size_t longest;
      const int entries = key_entries(spec, rows, cv, nfront, fastest, chart ? 3 : 1, &longest);
      const int columns = mica_gnuplot_key_columns(1100, longest, 4);
      const int height = 760 + 22 * mica_gnuplot_key_rows(entries, columns);
      fprintf(out.fp, "reset\n");
      fprintf(out.fp, pass ? "set terminal svg size 1100,%d noenhanced\nset output '%s.svg'\n"
                           : "set terminal pngcairo size 1100,%d noenhanced\nset output '%s.png'\n", height, name);
      /* the target across the whole width (the plotted constant keeps it inside the y range, and in the key) */
      fprintf(out.fp, "set arrow 1 from graph 0, first %.17g to graph 1, first %.17g nohead dt 2 lw 1.5 lc rgb 'black'\n",
              spec->target, spec->target);
      snprintf(text, sizeof text, "%s: %s against %s", title, error_title, chart ? "dofs" : "time");
      mica_gnuplot_quote(text, quoted[0], sizeof quoted[0]);
      mica_gnuplot_quote(chart ? "unknowns (degrees of freedom)" : study_time_title(spec), quoted[1], sizeof quoted[1]);
      mica_gnuplot_quote(error_title, quoted[2], sizeof quoted[2]);
      fprintf(out.fp, "set title %s\nset xlabel %s\nset ylabel %s\nset logscale xy\n"
              "set format y '%%.0e'\nset grid\nset offsets 0, graph 0.12, graph 0.04, graph 0.04\n", quoted[0],
              quoted[1], quoted[2]);
      mica_gnuplot_key_below(out.fp, entries, columns);
      write_chart(spec, rows, cv, nfront, fastest, chart ? 3 : 1, out.fp);
      fprintf(out.fp, "set output\n");
    }
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

int study_write_charts(const StudySpec *spec, const StudyRow *rows, long fastest, const char *outdir) {
  Curves cv = {0, NULL, NULL};
  long nfront = 0;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(curves_find(spec, rows, &cv));
  MICA_CALL_CLEANUP(write_points(spec, rows, outdir, &cv));
  MICA_CALL_CLEANUP(write_front(spec, rows, outdir, &nfront));
  MICA_CALL_CLEANUP(write_fastest(rows, fastest, outdir));
  MICA_CALL_CLEANUP(write_script(spec, rows, &cv, nfront, fastest, outdir));
  MICA_CALL_CLEANUP(mica_gnuplot(outdir, "study_chart.gp", "study.chart"));
cleanup:
  free(cv.first);
  free(cv.npoints);
  return ierr;
}
