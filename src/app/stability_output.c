/* Outputs of `mica stability`: eigenvalues.csv and the spectrum chart, inf_sup.csv and its chart, and the
 * mode shapes as VTU (the MLS field of a mode evaluated at the particles). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/files.h"
#include "mica/plot.h"
#include "mica/vtk.h"
#include "stability.h"

static const char *const KIND_NAMES[] = {"rigid", "spurious", "nonzero", "low_energy"};

static int write_text(const char *outdir, const char *name, int (*body)(FILE *fp, const void *ctx), const void *ctx) {
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_out_open_in(outdir, name, &out));
  MICA_CALL_CLEANUP(body(out.fp, ctx));
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

/* ---- eigenvalues ------------------------------------------------------------------------------------------ */

typedef struct {
  const EigenResult *r;
  double zero_tol;
} SpectrumCtx;

static int eigen_csv(FILE *fp, const void *ctx) {
  const EigenResult *r = ((const SpectrumCtx *)ctx)->r;
  fprintf(fp, "index,eigenvalue,relative,kind,energy_ratio\n"); /* energy_ratio: λ / (vᵀ K_ref v), below λ₁,ref */
  for (int k = 0; k < r->nvalues; k++) {
    fprintf(fp, "%d,%.17g,%.6e,%s,", k + 1, r->lambda[k], r->lambda[k] / r->lambda_max, KIND_NAMES[r->kind[k]]);
    if (isnan(r->energy_ratio[k])) fprintf(fp, "\n");
    else fprintf(fp, "%.6e\n", r->energy_ratio[k]);
  }
  return MICA_SUCCESS;
}

/* |λ|/λ_max per kind, one gnuplot block each (index 0, 1, 2, 3 as ModeKind); zeros are drawn at their round-off size, or at
 * 1e-18 if exactly 0, so the log scale can show them. */
static int spectrum_data(FILE *fp, const void *ctx) {
  const EigenResult *r = ((const SpectrumCtx *)ctx)->r;
  for (int kind = 0; kind < 4; kind++) {
    fprintf(fp, "# %s\n", KIND_NAMES[kind]);
    int any = 0;
    for (int k = 0; k < r->nvalues; k++)
      if ((int)r->kind[k] == kind) {
        fprintf(fp, "%d %.6e\n", k + 1, fmax(fabs(r->lambda[k]) / r->lambda_max, 1e-18));
        any = 1;
      }
    if (!any) fprintf(fp, "0 1e-18\n"); /* keeps the block (drawn off the chart: x = 0) */
    fprintf(fp, "\n\n");
  }
  return MICA_SUCCESS;
}

static int spectrum_script(FILE *fp, const void *ctx) {
  const SpectrumCtx *c = ctx;
  const EigenResult *r = c->r;
  const int entries = 5 + (r->band > 0);
  const int columns = mica_gnuplot_key_columns(900, strlen("lowest nonzero of the Gauss reference"), 3);
  const int height = 560 + 22 * mica_gnuplot_key_rows(entries, columns);
  const double zero_tol = c->zero_tol > 0 ? c->zero_tol : 1e-18;
  double lo = fmin(zero_tol, r->band > 0 ? r->band / r->lambda_max : 1.0);
  for (int k = 0; k < r->nvalues; k++) lo = fmin(lo, fmax(fabs(r->lambda[k]) / r->lambda_max, 1e-18));
  for (int pass = 0; pass < 2; pass++) {
    fprintf(fp, pass == 0 ? "set terminal pngcairo size 900,%d noenhanced\nset output 'spectrum.png'\n"
                          : "set terminal svg size 900,%d noenhanced\nset output 'spectrum.svg'\n", height);
    fprintf(fp, "set title 'Tangent at u = 0: %d eigenvalues of %ld unknowns; %d zero (%d rigid, %d spurious), %d "
                "low-energy'\nset logscale y\nset format y '%%.0e'\nset grid\n"
                "set xrange [0.5:%d.5]\nset xlabel 'eigenvalue index, ascending'\n"
                "set ylabel '|eigenvalue| / largest eigenvalue λ_max'\n",
            r->nvalues, r->ndof, r->zero, r->rigid, r->spurious_zero, r->low_energy, r->nvalues);
    mica_gnuplot_range(fp, 'y', lo, 1.0, 1, 0.03); /* the largest is 1; the lines and the zeros inside */
    mica_gnuplot_key_below(fp, entries, columns);
    fprintf(fp, "plot 'spectrum.dat' index 2 using 1:2 with points pt 7 ps 0.5 lc rgb '%s' title 'nonzero', "
                "'spectrum.dat' index 0 using 1:2 with points pt 5 ps 1 lc rgb '%s' title 'rigid body', "
                "'spectrum.dat' index 1 using 1:2 with points pt 9 ps 1.2 lc rgb '%s' title 'spurious zero', "
                "'spectrum.dat' index 3 using 1:2 with points pt 11 ps 1.2 lc rgb '%s' title 'low-energy', "
                "%.6e with lines dt 2 lc rgb 'black' title 'zero tolerance (stability.zero_tol)'",
            mica_gnuplot_colour(0), mica_gnuplot_colour(2), mica_gnuplot_colour(1), mica_gnuplot_colour(4),
            zero_tol);
    if (r->band > 0) /* low-energy modes are sought below the reference's lowest nonzero eigenvalue */
      fprintf(fp, ", %.6e with lines dt 4 lc rgb 'black' title 'lowest nonzero of the Gauss reference'",
              r->band / r->lambda_max);
    fprintf(fp, "\nset output\n");
  }
  return MICA_SUCCESS;
}

int stability_write_eigenvalues(const EigenResult *r, double zero_tol, const char *outdir, int chart) {
  const SpectrumCtx ctx = {r, zero_tol};
  MICA_CALL(write_text(outdir, "eigenvalues.csv", eigen_csv, &ctx));
  if (!chart) return MICA_SUCCESS;
  MICA_CALL(write_text(outdir, "spectrum.dat", spectrum_data, &ctx));
  MICA_CALL(write_text(outdir, "spectrum.gp", spectrum_script, &ctx));
  MICA_CALL(mica_gnuplot(outdir, "spectrum.gp", "stability.chart"));
  return MICA_SUCCESS;
}

/* ---- inf-sup --------------------------------------------------------------------------------------------- */

typedef struct {
  const InfSupRow *rows;
  int n;
} InfSupCtx;

static int inf_sup_csv(FILE *fp, const void *ctx) {
  const InfSupCtx *c = ctx;
  fprintf(fp, "N,particles,boundary_vertices,free_unknowns,quadrature_points,zero_eigenvalues,beta,lambda_max,"
              "pressure_modes\n");
  for (int i = 0; i < c->n; i++) {
    const InfSupRow *r = &c->rows[i];
    fprintf(fp, "%ld,%ld,%ld,%ld,%ld,%d,%.10g,%.10g,%ld\n", r->count[0], r->particles, r->constrained, r->nfree,
            r->nquad, r->zero, r->beta, r->lambda_max, r->pressure_modes);
  }
  return MICA_SUCCESS;
}

static int inf_sup_script(FILE *fp, const void *ctx) {
  const InfSupCtx *c = ctx;
  double nlo = INFINITY, nhi = -INFINITY, blo = INFINITY, bhi = -INFINITY;
  for (int i = 0; i < c->n; i++) {
    nlo = fmin(nlo, (double)c->rows[i].count[0]), nhi = fmax(nhi, (double)c->rows[i].count[0]);
    blo = fmin(blo, c->rows[i].beta), bhi = fmax(bhi, c->rows[i].beta);
  }
  for (int pass = 0; pass < 2; pass++) {
    fprintf(fp, pass == 0 ? "set terminal pngcairo size 800,620 noenhanced\nset output 'inf_sup.png'\n"
                          : "set terminal svg size 800,620 noenhanced\nset output 'inf_sup.svg'\n");
    fprintf(fp, "set title 'Numerical inf-sup test (Chapelle-Bathe), displacement formulation'\nset datafile "
                "separator ','\nset logscale xy\nset grid\n"
                "set xlabel 'N (particles along the first axis)'\nset ylabel 'inf-sup constant β_h'\n");
    mica_gnuplot_range(fp, 'x', nlo, nhi, 1, 0.05);
    mica_gnuplot_range(fp, 'y', blo, bhi, 1, 0.05);
    mica_gnuplot_key_below(fp, 1, 1);
    fprintf(fp, "plot 'inf_sup.csv' every ::1 using 1:7 with linespoints pt 7 lw 2 lc rgb '%s' title 'mica'\n",
            mica_gnuplot_colour(0));
    fprintf(fp, "set output\n");
  }
  return MICA_SUCCESS;
}

int stability_write_inf_sup(const InfSupRow *rows, int nrows, const char *outdir, int chart) {
  const InfSupCtx ctx = {rows, nrows};
  MICA_CALL(write_text(outdir, "inf_sup.csv", inf_sup_csv, &ctx));
  int positive = nrows > 0;
  for (int i = 0; i < nrows; i++) positive &= rows[i].beta > 0;
  if (!chart || !positive) return MICA_SUCCESS;
  MICA_CALL(write_text(outdir, "inf_sup.gp", inf_sup_script, &ctx));
  MICA_CALL(mica_gnuplot(outdir, "inf_sup.gp", "stability.chart"));
  return MICA_SUCCESS;
}

/* ---- mode shapes ------------------------------------------------------------------------------------------ */

int stability_write_mode(RunProblem *rp, const double *u, const char *outdir, const char *name, double eigenvalue) {
  const MicaSolid *s = rp->solid;
  const long n = rp->disc->nparticles;
  const int mdim = s->model_dim, ncomp = s->ncomp;
  double *disp = NULL, *rot = NULL, *lam = NULL;
  char *path = NULL;
  int ierr = MICA_SUCCESS;
  if (!rp->at_particles) MICA_CALL(rp->approx.ops->particles(rp->approx.ctx, s->opt.field.ops->order, &rp->at_particles));
  MICA_CALL_CLEANUP(MICA_CALLOC(disp, n * 3));
  MICA_CALL_CLEANUP(MICA_CALLOC(rot, n * 3));
  MICA_CALL_CLEANUP(MICA_MALLOC(lam, n));
  double q[128], largest = 0;
  /* axisymmetric (r, θ, z) go to the section's frame (r, z, θ), as mica run writes them */
  static const int section[3] = {0, 2, 1};
  for (long i = 0; i < n; i++) {
    mica_solid_kinematics(s, rp->at_particles, i, u, q);
    for (int a = 0; a < mdim; a++) disp[i * 3 + (rp->axisymmetric ? section[a] : a)] = q[a];
    for (int c = mdim; c < ncomp; c++) rot[i * 3 + (ncomp - mdim == 1 ? 2 : (rp->axisymmetric ? section[c - mdim] : c - mdim))] = q[c];
    for (int a = 0; a < 3; a++) largest = fmax(largest, fabs(disp[i * 3 + a]));
    lam[i] = eigenvalue;
  }
  const double scale = largest > 0 ? 1 / largest : 1;
  for (long i = 0; i < n * 3; i++) disp[i] *= scale, rot[i] *= scale;
  MicaVtkField fields[3];
  int nf = 0;
  fields[nf++] = (MicaVtkField){"displacement", 3, disp, NULL};
  if (ncomp > mdim) fields[nf++] = (MicaVtkField){"microrotation", 3, rot, NULL};
  fields[nf++] = (MicaVtkField){"eigenvalue", 1, lam, NULL};
  MICA_CALL_CLEANUP(mica_path_join(outdir, name, &path));
  MICA_CALL_CLEANUP(mica_vtu_write(path, rp->disc->dim, n, rp->disc->x, nf, fields));
cleanup:
  free(disp), free(rot), free(lam), free(path);
  return ierr;
}
