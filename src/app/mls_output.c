/* Outputs of `mica mls`: the sample table (mls.csv) and the error chart drawn by gnuplot. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mica/files.h"
#include "mica/plot.h"
#include "mls_study.h"

static double relative(double approx, double exact, double scale) {
  return fabs(approx - exact) / (scale > 0 ? scale : 1.0);
}

static void write_rows(FILE *fp, const MlsVariantResult *r, const char *set, const MlsSample *s, long n,
                       const MlsErrors *e) {
  for (long i = 0; i < n; i++)
    fprintf(fp, "\"%s\",%s,%ld,%.17g,%.17g,%.17g,%.17g,%ld,%.17g,%.17g,%.6e,%.17g,%.17g,%.6e,%.17g,%.17g,%.6e\n",
            r->name, set, i, s[i].param, s[i].x[0], s[i].x[1], s[i].x[2], s[i].support, s[i].f, s[i].fh,
            relative(s[i].fh, s[i].f, e->scale_f), s[i].df, s[i].dfh, relative(s[i].dfh, s[i].df, e->scale_df),
            s[i].ddf, s[i].ddfh, relative(s[i].ddfh, s[i].ddf, e->scale_ddf));
}

int mls_study_write_csv(const MlsVariantResult *results, int nvariants, const char *outdir) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "mls.csv", &out));
  /* err_* are relative to the largest |exact| value of the same variant and sample set */
  fprintf(out.fp, "variant,set,sample,s,x,y,z,support,f,f_h,err_f,df,df_h,err_df,ddf,ddf_h,err_ddf\n");
  for (int v = 0; v < nvariants; v++) {
    const MlsVariantResult *r = &results[v];
    write_rows(out.fp, r, "line", r->line, r->nline, &r->line_err);
    write_rows(out.fp, r, "volume", r->volume, r->nvolume, &r->volume_err);
  }
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

/* gnuplot data: one block per variant (separated by two blank lines, so `index v` selects it). */
static int write_chart_data(const MlsVariantResult *results, int nvariants, const char *outdir) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "mls_line.dat", &out));
  for (int v = 0; v < nvariants; v++) {
    const MlsVariantResult *r = &results[v];
    const MlsErrors *e = &r->line_err;
    char name[512];
    mica_gnuplot_datum(r->name, name, sizeof name); /* one line */
    fprintf(out.fp, "# variant %s: position along the axis, relative errors of f, df, ddf\n", name);
    for (long i = 0; i < r->nline; i++) {
      const MlsSample *s = &r->line[i];
      fprintf(out.fp, "%.10g %.6e %.6e %.6e\n", s->x[r->axis], relative(s->fh, s->f, e->scale_f),
              relative(s->dfh, s->df, e->scale_df), relative(s->ddfh, s->ddf, e->scale_ddf));
    }
    fprintf(out.fp, "\n\n");
  }
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

static void write_panel(FILE *fp, int nvariants, int column, const char *ylabel, const MlsVariantResult *r) {
  char text[160];
  mica_gnuplot_quote(ylabel, text, sizeof text);
  fprintf(fp, "set ylabel %s\nplot ", text);
  for (int v = 0; v < nvariants; v++) {
    mica_gnuplot_quote(r[v].name, text, sizeof text);
    char series[96];
    mica_gnuplot_line(v, series, sizeof series);
    fprintf(fp, "%s'mls_line.dat' index %d using 1:($%d > 0 ? $%d : 1/0) with lines lw 1.5 %s title %s",
            v ? ", " : "", v, column, column, series, text);
  }
  fprintf(fp, "\n");
}

static int write_chart_script(const MlsVariantResult *r, int nvariants, const char *title, const char *outdir) {
  char safe_title[512];
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  const char axis = (char)('x' + r[0].axis);
  mica_gnuplot_quote(title && title[0] ? title : "MLS approximation error along the sample line", safe_title,
                     sizeof safe_title);
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, "mls_chart.gp", &out));
  FILE *fp = out.fp;
  for (int pass = 0; pass < 2; pass++) {
    if (pass == 0) fprintf(fp, "set terminal pngcairo size 900,1100 noenhanced\nset output 'mls_error.png'\n");
    else fprintf(fp, "set terminal svg size 900,1100 noenhanced\nset output 'mls_error.svg'\n");
    fprintf(fp, "set multiplot layout 3,1 title %s\nset logscale y\nset format y '%%.0e'\nset grid\n"
                "set key outside right top\nset xlabel 'position %c along the sample line'\n", safe_title, axis);
    char label[64];
    write_panel(fp, nvariants, 2, "relative error of f", r);
    snprintf(label, sizeof label, "relative error of df/d%c", axis);
    write_panel(fp, nvariants, 3, label, r);
    snprintf(label, sizeof label, "relative error of d2f/d%c2", axis);
    write_panel(fp, nvariants, 4, label, r);
    fprintf(fp, "unset multiplot\nset output\n");
  }
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}


int mls_study_write_chart(const MlsVariantResult *results, int nvariants, const char *title, const char *outdir) {
  MICA_CALL(write_chart_data(results, nvariants, outdir));
  MICA_CALL(write_chart_script(results, nvariants, title, outdir));
  MICA_CALL(mica_gnuplot(outdir, "mls_chart.gp", "output.chart"));
  return MICA_SUCCESS;
}
