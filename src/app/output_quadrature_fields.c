/* output.quadrature_fields: the kinematic fields at the error-norm points, written to quadrature_fields.csv,
 * so that a reader can measure the solution against a reference it holds itself (bench/peers: the energy-norm
 * error against a FEniCS overkill solution). One row per point of run_error_points — quadrature.error_order's
 * own points when set, else the solve's volume points (under nodal integration the background Gauss points) —
 * with its weight, every unknown's value and geometric gradient, and the model's energy density W there: over
 * the solve's own points Σ w W is the `energy` probe. Under MPI with replicated data the error points must be
 * whole on every rank (quadrature.error_order > 0) and rank 0 writes; with distributed data each rank has its
 * cells' (or its nodal cells') points, and the ranks append their rows in rank order to the one file. */
#include <stdio.h>
#include <string.h>

#include "mica/files.h"
#include "run.h"

MICA_SCHEMA_TABLES

static const MicaDeckKey quadrature_fields_keys[] = {
    {"quadrature_fields", MICA_KEY_BOOL, "false", 1.0, 0.0, NULL, 0, 0,
     "write quadrature_fields.csv: one row per error-norm point (quadrature.error_order's own points when set, "
     "else the solve's volume points): coordinates, weight w, every unknown and its gradient, energy density W "
     "(over the solve's points Σ w W is the energy probe); summary: quadrature_fields_points, "
     "quadrature_fields_energy. MPI: replicated data needs quadrature.error_order > 0 (rank 0 writes); distributed "
     "data: each rank's rows, in rank order"},
    {NULL},
};

static int quadrature_fields_from_settings(const MicaType *type, const MicaSettings *settings, const char *group,
                                           void *options) {
  (void)type;
  return mica_settings_bool(settings, group, "quadrature_fields", &((MicaOutput *)options)->enabled);
}

/* The model layout's column of geometric derivative J: the same, or for an axisymmetric section (r, z) the
 * 3-D gradient's columns r and z (run_output.c: to_model_layout). */
static int gradient_column(const RunProblem *rp, int J) {
  return rp->axisymmetric ? (J == 0 ? 0 : 2) : J;
}

static void write_header(const RunProblem *rp, FILE *fp) {
  static const char *const axes[3] = {"x", "y", "z"};
  const int dim = rp->disc->dim, ncomp = rp->solid->ncomp;
  for (int J = 0; J < dim; J++) fprintf(fp, "%s,", axes[J]);
  fprintf(fp, "w");
  for (int c = 0; c < ncomp; c++) fprintf(fp, ",%s", run_unknown_name(rp, c));
  for (int c = 0; c < ncomp; c++)
    for (int J = 0; J < dim; J++) fprintf(fp, ",d%s_d%s", run_unknown_name(rp, c), axes[J]);
  fprintf(fp, ",W\n");
}

static void write_row(const RunProblem *rp, FILE *fp, const double *x, double w, const double *q, double W) {
  const int dim = rp->disc->dim, ncomp = rp->solid->ncomp, mdim = rp->solid->model_dim;
  for (int J = 0; J < dim; J++) fprintf(fp, "%.17g,", x[J]);
  fprintf(fp, "%.17g", w);
  for (int c = 0; c < ncomp; c++) fprintf(fp, ",%.17g", q[c]);
  for (int c = 0; c < ncomp; c++)
    for (int J = 0; J < dim; J++) fprintf(fp, ",%.17g", q[ncomp + c * mdim + gradient_column(rp, J)]);
  fprintf(fp, ",%.17g\n", W);
}

static int quadrature_fields_check(MicaOutputRun *run, void *ctx) {
  (void)ctx;
  const RunProblem *rp = run->rp;
  const MicaDeck *deck = rp->deck;
  long error_order;
  MICA_CALL(mica_deck_int(deck, "quadrature.error_order", &error_order));
  if (!rp->dist || rp->owned_data || error_order > 0) return MICA_SUCCESS;
  char where[256];
  mica_deck_where(deck, "output.quadrature_fields", where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT,
             "%s: output.quadrature_fields under MPI needs quadrature.error_order > 0 (points every rank holds "
             "whole; the solve's own points are split among the ranks); set quadrature.error_order, e.g. 8, or run "
             "without mpirun", where);
}

/* The rows of the points c holds (fp: NULL to count only), and Σ w W over them. */
static int write_rows(const RunProblem *rp, const MicaShapeCache *c, const double *qx, const double *qw,
                      const double *u, FILE *fp, double *energy) {
  const MicaSolid *s = rp->solid;
  double q[128], W;
  *energy = 0;
  for (long p = 0; p < c->npoints; p++) {
    mica_solid_kinematics(s, c, p, u, q);
    MICA_CALL(s->opt.field.ops->eval(&s->opt.field, s->model_dim, q, &W, NULL, NULL));
    *energy += qw[p] * W;
    if (fp) write_row(rp, fp, qx + p * rp->disc->dim, qw[p], q, W);
  }
  return MICA_SUCCESS;
}

/* Distributed data: rank 0's rows into its file, the others' (formatted in memory) appended in rank order; ierr:
 * rank 0's opening of the file (every rank reaches the collective append). */
static int write_owned(int ierr, const RunProblem *rp, const MicaShapeCache *c, const double *qx, const double *qw,
                       const double *u, MicaOutFile *out, double *energy) {
  char *text = NULL;
  size_t size = 0;
  FILE *fp = out->fp;
  if (!ierr && !fp && !(fp = open_memstream(&text, &size)))
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_MEMORY, "quadrature_fields.csv: no memory stream");
  if (!ierr) ierr = write_rows(rp, c, qx, qw, u, fp, energy);
  if (fp && fp != out->fp) fclose(fp);
  else if (fp && fflush(fp) != 0)
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "cannot write %s", out->tmp_path);
  ierr = mica_parallel_append_in_order(ierr, out->tmp_path, text ? text : "");
  free(text);
  return ierr;
}

/* Writes the rows (rank 0; with distributed data every rank its own) and adds Σ w W and the row count to the
 * summary (every rank computes them). */
static int quadrature_fields_finish(MicaOutputRun *run, void *ctx, const double *u, MicaJson *summary) {
  (void)ctx;
  RunProblem *rp = run->rp;
  const char *outdir = mica_output_dir(run);
  const MicaShapeCache *c = NULL;
  const double *qx = NULL, *qw = NULL;
  int whole = 0;
  MICA_CALL(run_error_points(rp, &c, &qx, &qw, &whole));
  MICA_CHECK(whole || !rp->dist || rp->owned_data, MICA_ERR_ARGUMENT,
             "run_quadrature_fields: points split among the ranks");
  const int writer = mica_output_writer(run);
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  double sums[2] = {0, (double)c->npoints}; /* Σ w W, points */
  if (writer) {
    ierr = mica_out_open_in(outdir, "quadrature_fields.csv", &out);
    if (!ierr) write_header(rp, out.fp);
  }
  if (rp->owned_data) {
    MICA_CALL_CLEANUP(write_owned(ierr, rp, c, qx, qw, u, &out, &sums[0]));
    MICA_CALL_CLEANUP(mica_parallel_sum(MICA_SUCCESS, sums, 2));
  } else {
    MICA_CALL_CLEANUP(ierr);
    MICA_CALL_CLEANUP(write_rows(rp, c, qx, qw, u, writer ? out.fp : NULL, &sums[0]));
  }
  if (writer) MICA_CALL_CLEANUP(mica_out_commit(&out));
  MICA_CALL_CLEANUP(mica_json_int(summary, "quadrature_fields_points", (long)sums[1]));
  MICA_CALL_CLEANUP(mica_json_number(summary, "quadrature_fields_energy", sums[0]));
cleanup:
  mica_out_abort(&out);
  return ierr;
}

const MicaOutputOps run_output_quadrature_fields = {
    .type = {"quadrature_fields", "the kinematic fields at the error-norm points (quadrature_fields.csv)",
             MICA_OUTPUT_AT_END, quadrature_fields_keys, quadrature_fields_from_settings},
    .check = quadrature_fields_check,
    .finish = quadrature_fields_finish,
};
