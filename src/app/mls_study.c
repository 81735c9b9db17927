/* `mica mls`: the MLS approximation accuracy study of seed 001 §3.2, generalized.
 *
 * For each variant (the base deck, or each element of study.variants overlaid on it): particles on a
 * regular or jittered grid carry the nodal values f(x_I); the MLS approximation f_h = Σ N_I f(x_I) and its
 * derivatives along sample.axis are compared with the exact ones (libmatheval differentiates the deck's
 * expression symbolically) on a sample line and at random points in the volume. The shape-function
 * evaluation is timed separately so that accuracy can be charted against cost.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/random.h"
#include "mica/timer.h"
#include "mls_study.h"
#include "study_common.h"

typedef struct {
  int dim;
  double lower[3], upper[3];
  long count[3];
} GridSpec;

/* ---- reading the deck ----------------------------------------------------------------------------- */

static int read_grid(const MicaDeck *deck, GridSpec *grid) {
  int nlow, nup, ncount;
  char where[256];
  MICA_CALL(mica_deck_floats(deck, "geometry.lower", grid->lower, 3, &nlow));
  MICA_CALL(mica_deck_floats(deck, "geometry.upper", grid->upper, 3, &nup));
  MICA_CALL(mica_deck_ints(deck, "particles.count", grid->count, 3, &ncount));
  grid->dim = nlow;
  mica_deck_where(deck, "geometry.upper", where, sizeof where);
  MICA_CHECK(nup == nlow, MICA_ERR_INPUT, "%s: geometry.upper has %d entries but geometry.lower has %d",
             where, nup, nlow);
  for (int d = 0; d < nlow; d++)
    MICA_CHECK(grid->upper[d] > grid->lower[d], MICA_ERR_INPUT,
               "%s: geometry.upper must exceed geometry.lower along every axis (axis %d: %g <= %g)", where,
               d, grid->upper[d], grid->lower[d]);
  mica_deck_where(deck, "particles.count", where, sizeof where);
  MICA_CHECK(ncount == nlow, MICA_ERR_INPUT,
             "%s: particles.count needs %d entries, one per axis of the %d-D box, not %d", where, nlow,
             nlow, ncount);
  return MICA_SUCCESS;
}

/* ---- particles and samples ------------------------------------------------------------------------ */

/* Regular grid, then each coordinate not on the box's boundary shifted by ±jitter × spacing. */
static int make_particles(const MicaDeck *deck, const GridSpec *g, double **xout, long *nout) {
  double jitter;
  long seed;
  MICA_CALL(mica_deck_float(deck, "particles.jitter", &jitter));
  MICA_CALL(mica_deck_int(deck, "particles.seed", &seed));
  long n = 1;
  for (int d = 0; d < g->dim; d++) n *= g->count[d];
  double *x;
  MICA_CALL(MICA_MALLOC(x, n * g->dim));
  MicaRandom rng = mica_random_seed((uint64_t)seed);
  for (long i = 0; i < n; i++) {
    long rest = i;
    for (int d = 0; d < g->dim; d++) {
      const long k = rest % g->count[d];
      rest /= g->count[d];
      const double h = (g->upper[d] - g->lower[d]) / (double)(g->count[d] - 1);
      const double shift = jitter * h * (2 * mica_random_uniform(&rng) - 1);
      const int on_boundary = k == 0 || k == g->count[d] - 1;
      x[i * g->dim + d] = g->lower[d] + h * (double)k + (on_boundary ? 0.0 : shift);
    }
  }
  *xout = x;
  *nout = n;
  return MICA_SUCCESS;
}

/* A sample point outside the box has no meaning for the study (and would have no support): a deck error. */
static int check_inside(const MicaDeck *deck, const char *path, const GridSpec *g, const double *p) {
  for (int d = 0; d < g->dim; d++) {
    const double tol = 1e-12 * (g->upper[d] - g->lower[d]);
    if (p[d] < g->lower[d] - tol || p[d] > g->upper[d] + tol) {
      char where[256];
      mica_deck_where(deck, path, where, sizeof where);
      MICA_ERROR(MICA_ERR_INPUT, "%s: %s lies outside the box along axis %d (%g not in [%g, %g]); move it inside",
                 where, path, d, p[d], g->lower[d], g->upper[d]);
    }
  }
  return MICA_SUCCESS;
}

/* The samples of a variant, line and volume together, at most limits.mls_samples (checked before either list
 * is allocated: the schema's ranges alone allow 10^8). */
static int check_sample_count(const MicaDeck *deck) {
  long line, volume, limit;
  MICA_CALL(mica_deck_int(deck, "sample.line.samples", &line));
  MICA_CALL(mica_deck_int(deck, "sample.volume.points", &volume));
  MICA_CALL(mica_deck_int(deck, "limits.mls_samples", &limit));
  if (line + volume <= limit) return MICA_SUCCESS;
  char where[256];
  const char *path = line >= volume ? "sample.line.samples" : "sample.volume.points";
  mica_deck_where(deck, path, where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT, "%s: %ld line and %ld volume samples are more than limits.mls_samples = %ld; lower %s "
             "or raise limits.mls_samples", where, line, volume, limit, path);
}

static int make_line_samples(const MicaDeck *deck, const GridSpec *g, MlsSample **out, long *nout) {
  const int dim = g->dim;
  double from[3] = {0}, to[3] = {0};
  int nf, nt;
  long n;
  MICA_CALL(mica_deck_floats(deck, "sample.line.from", from, 3, &nf));
  MICA_CALL(mica_deck_floats(deck, "sample.line.to", to, 3, &nt));
  MICA_CALL(mica_deck_int(deck, "sample.line.samples", &n));
  MICA_CALL(check_sample_count(deck));
  char where[256];
  mica_deck_where(deck, nf != dim ? "sample.line.from" : "sample.line.to", where, sizeof where);
  MICA_CHECK(nf == dim && nt == dim, MICA_ERR_INPUT,
             "%s: sample.line.from and .to need %d coordinates for a %d-D box", where, dim, dim);
  MICA_CALL(check_inside(deck, "sample.line.from", g, from));
  MICA_CALL(check_inside(deck, "sample.line.to", g, to));
  MlsSample *s;
  MICA_CALL(MICA_CALLOC(s, n));
  for (long i = 0; i < n; i++) {
    s[i].param = (double)i / (double)(n - 1);
    for (int d = 0; d < dim; d++) s[i].x[d] = from[d] + s[i].param * (to[d] - from[d]);
  }
  *out = s;
  *nout = n;
  return MICA_SUCCESS;
}

static int make_volume_samples(const MicaDeck *deck, const GridSpec *g, MlsSample **out, long *nout) {
  long n, seed;
  MICA_CALL(mica_deck_int(deck, "sample.volume.points", &n));
  MICA_CALL(mica_deck_int(deck, "sample.volume.seed", &seed));
  MlsSample *s;
  MICA_CALL(MICA_CALLOC(s, n));
  MicaRandom rng = mica_random_seed((uint64_t)seed + 7919);
  for (long i = 0; i < n; i++)
    for (int d = 0; d < g->dim; d++)
      s[i].x[d] = g->lower[d] + mica_random_uniform(&rng) * (g->upper[d] - g->lower[d]);
  *out = s;
  *nout = n;
  return MICA_SUCCESS;
}

/* ---- evaluation ----------------------------------------------------------------------------------- */

typedef struct {
  MicaFunction *f, *df, *ddf;
} TargetFunction;

static void target_destroy(TargetFunction *t) {
  mica_function_destroy(&t->f);
  mica_function_destroy(&t->df);
  mica_function_destroy(&t->ddf);
}

static int target_create(const MicaDeck *deck, int axis, TargetFunction *t) {
  MICA_CALL(mica_deck_function(deck, "function.f", &t->f));
  MICA_CALL(mica_function_derivative(t->f, axis, &t->df));
  MICA_CALL(mica_function_derivative(t->df, axis, &t->ddf));
  return MICA_SUCCESS;
}

/* Checks an exact value: a target function that is not finite at a sample is a deck error. */
static int exact_value(const MicaDeck *deck, const MicaFunction *f, const double *x, double *value) {
  *value = mica_function_eval(f, x, 0.0);
  if (isfinite(*value)) return MICA_SUCCESS;
  char where[256];
  mica_deck_where(deck, "function.f", where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT, "%s: function.f \"%s\" (or a derivative) is not finite at (%g, %g, %g)", where,
             mica_function_text(f), x[0], x[1], x[2]);
}

static int evaluate_samples(const MicaDeck *deck, const MlsApprox *mls, MlsShape *sh, const double *u,
                            const TargetFunction *t, int axis, const char *set, MlsSample *s, long n,
                            double *rcond_min) {
  const int dim = mls_dim(mls), hh = mls_hess_index(dim, axis, axis);
  for (long i = 0; i < n; i++) {
    int ierr = mica_study_mls_input(mls_eval(mls, s[i].x, MLS_HESSIAN, sh));
    if (ierr) {
      mica_error_prefix("%s sample %ld", set, i + 1);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
    double grad[3], hess[6];
    mls_shape_apply(sh, u, &s[i].fh, grad, hess);
    s[i].dfh = grad[axis];
    s[i].ddfh = hess[hh];
    s[i].support = sh->n;
    *rcond_min = fmin(*rcond_min, sh->rcond);
    MICA_CALL(exact_value(deck, t->f, s[i].x, &s[i].f));
    MICA_CALL(exact_value(deck, t->df, s[i].x, &s[i].df));
    MICA_CALL(exact_value(deck, t->ddf, s[i].x, &s[i].ddf));
  }
  return MICA_SUCCESS;
}

/* Shape functions with Hessians at every sample, repeated; the fastest repetition counts. */
static int time_evaluation(const MlsApprox *mls, MlsShape *sh, const MlsVariantResult *r, long repeat,
                           double *seconds) {
  *seconds = INFINITY;
  for (long rep = 0; rep < repeat; rep++) {
    const double start = mica_wtime();
    for (long i = 0; i < r->nline; i++) MICA_CALL(mls_eval(mls, r->line[i].x, MLS_HESSIAN, sh));
    for (long i = 0; i < r->nvolume; i++) MICA_CALL(mls_eval(mls, r->volume[i].x, MLS_HESSIAN, sh));
    *seconds = fmin(*seconds, mica_wtime() - start);
  }
  return MICA_SUCCESS;
}

void mls_study_errors(const MlsSample *s, long n, MlsErrors *e) {
  memset(e, 0, sizeof *e);
  if (n == 0) return;
  e->support_min = s[0].support;
  for (long i = 0; i < n; i++) {
    e->scale_f = fmax(e->scale_f, fabs(s[i].f));
    e->scale_df = fmax(e->scale_df, fabs(s[i].df));
    e->scale_ddf = fmax(e->scale_ddf, fabs(s[i].ddf));
    e->support_min = s[i].support < e->support_min ? s[i].support : e->support_min;
    e->support_max = s[i].support > e->support_max ? s[i].support : e->support_max;
  }
  /* a function that vanishes on the whole set is measured absolutely */
  const double sf = e->scale_f > 0 ? e->scale_f : 1, sd = e->scale_df > 0 ? e->scale_df : 1,
               sdd = e->scale_ddf > 0 ? e->scale_ddf : 1;
  double sum_f = 0, sum_d = 0, sum_dd = 0;
  for (long i = 0; i < n; i++) {
    const double ef = fabs(s[i].fh - s[i].f) / sf, ed = fabs(s[i].dfh - s[i].df) / sd,
                 edd = fabs(s[i].ddfh - s[i].ddf) / sdd;
    e->f_max = fmax(e->f_max, ef), e->df_max = fmax(e->df_max, ed), e->ddf_max = fmax(e->ddf_max, edd);
    sum_f += ef * ef, sum_d += ed * ed, sum_dd += edd * edd;
  }
  e->f_rms = sqrt(sum_f / (double)n), e->df_rms = sqrt(sum_d / (double)n), e->ddf_rms = sqrt(sum_dd / (double)n);
}

static int axis_of(const MicaDeck *deck, int dim, int *axis) {
  const char *name;
  MICA_CALL(mica_deck_string(deck, "sample.axis", &name));
  *axis = name[0] - 'x';
  char where[256];
  mica_deck_where(deck, "sample.axis", where, sizeof where);
  MICA_CHECK(*axis < dim, MICA_ERR_INPUT, "%s: sample.axis = \"%s\" does not exist in %d-D", where, name, dim);
  return MICA_SUCCESS;
}

/* One variant: particles, MLS, samples, errors, timing. listed: a variant of study.variants (its name goes
 * in front of error messages). */
static int run_variant(const MicaDeck *deck, int listed, MlsVariantResult *r) {
  GridSpec grid;
  MlsOptions opt;
  TargetFunction target = {0};
  MlsApprox *mls = NULL;
  MlsShape *sh = NULL;
  double *x = NULL, *u = NULL;
  int ierr = MICA_SUCCESS;
  long repeat;
  snprintf(r->name, sizeof r->name, "%s", mica_deck_name(deck));
  MICA_CALL_CLEANUP(read_grid(deck, &grid));
  r->dim = grid.dim;
  MICA_CALL_CLEANUP(axis_of(deck, grid.dim, &r->axis));
  MICA_CALL_CLEANUP(mica_study_mls_options(deck, grid.dim, &opt));
  MICA_CALL_CLEANUP(mica_deck_int(deck, "study.repeat", &repeat));
  MICA_CALL_CLEANUP(target_create(deck, r->axis, &target));
  MICA_CALL_CLEANUP(make_particles(deck, &grid, &x, &r->nparticles));
  MICA_CALL_CLEANUP(make_line_samples(deck, &grid, &r->line, &r->nline));
  MICA_CALL_CLEANUP(make_volume_samples(deck, &grid, &r->volume, &r->nvolume));
  MICA_CALL_CLEANUP(MICA_MALLOC(u, r->nparticles));
  for (long i = 0; i < r->nparticles; i++) {
    double p[3] = {0, 0, 0};
    memcpy(p, x + i * grid.dim, sizeof(double) * (size_t)grid.dim);
    MICA_CALL_CLEANUP(exact_value(deck, target.f, p, &u[i]));
  }
  const double setup_start = mica_wtime();
  MICA_CALL_CLEANUP(mica_study_mls_input(mls_create(grid.dim, r->nparticles, x, &opt, &mls)));
  MICA_CALL_CLEANUP(mls_shape_create(mls, &sh));
  r->setup_seconds = mica_wtime() - setup_start;
  r->rcond_min = INFINITY;
  MICA_CALL_CLEANUP(evaluate_samples(deck, mls, sh, u, &target, r->axis, "line", r->line, r->nline, &r->rcond_min));
  MICA_CALL_CLEANUP(evaluate_samples(deck, mls, sh, u, &target, r->axis, "volume", r->volume, r->nvolume, &r->rcond_min));
  MICA_CALL_CLEANUP(time_evaluation(mls, sh, r, repeat, &r->eval_seconds));
  r->evals_per_s = (double)(r->nline + r->nvolume) / fmax(r->eval_seconds, 1e-9);
  mls_study_errors(r->line, r->nline, &r->line_err);
  mls_study_errors(r->volume, r->nvolume, &r->volume_err);
cleanup:
  if (ierr && listed) mica_error_prefix("variant '%s'", r->name);
  target_destroy(&target);
  mls_shape_destroy(&sh);
  mls_destroy(&mls);
  free(x);
  free(u);
  return ierr;
}

/* ---- summary -------------------------------------------------------------------------------------- */

static int add_errors(MicaJson *json, const char *prefix, const MlsErrors *e) {
  const struct { const char *key; double value; } items[] = {
      {"err_f_max", e->f_max},     {"err_f_rms", e->f_rms},       {"err_dx_max", e->df_max},
      {"err_dx_rms", e->df_rms},   {"err_dxx_max", e->ddf_max},   {"err_dxx_rms", e->ddf_rms},
  };
  char key[64];
  for (size_t i = 0; i < sizeof items / sizeof *items; i++) {
    snprintf(key, sizeof key, "%s%s", prefix, items[i].key);
    MICA_CALL(mica_json_number(json, key, items[i].value));
  }
  return MICA_SUCCESS;
}

/* The members describing one variant's result (into the innermost open object). */
static int add_variant_members(MicaJson *json, const MlsVariantResult *r) {
  MICA_CALL(mica_json_int(json, "particles", r->nparticles));
  MICA_CALL(mica_json_int(json, "samples_line", r->nline));
  MICA_CALL(mica_json_int(json, "samples_volume", r->nvolume));
  MICA_CALL(mica_json_int(json, "support_min", r->nline ? r->line_err.support_min : r->volume_err.support_min));
  MICA_CALL(mica_json_int(json, "support_max", r->nline ? r->line_err.support_max : r->volume_err.support_max));
  MICA_CALL(add_errors(json, "", &r->line_err));
  if (r->nvolume) {
    MICA_CALL(add_errors(json, "volume_", &r->volume_err));
    MICA_CALL(mica_json_int(json, "volume_support_min", r->volume_err.support_min));
    MICA_CALL(mica_json_int(json, "volume_support_max", r->volume_err.support_max));
  }
  MICA_CALL(mica_json_number(json, "rcond_min", r->rcond_min));
  MICA_CALL(mica_json_number(json, "evals_per_s", r->evals_per_s));
  MICA_CALL(mica_json_number(json, "time_setup", r->setup_seconds));
  MICA_CALL(mica_json_number(json, "time_eval", r->eval_seconds));
  return MICA_SUCCESS;
}

static int write_summary(MicaJson *json, const MlsVariantResult *results, int nvariants) {
  MICA_CALL(mica_json_int(json, "dim", results[0].dim));
  MICA_CALL(mica_json_int(json, "variants_count", nvariants));
  if (nvariants == 1) MICA_CALL(add_variant_members(json, &results[0]));
  MICA_CALL(mica_json_open_array(json, "variants"));
  for (int v = 0; v < nvariants; v++) {
    MICA_CALL(mica_json_open_object(json, NULL));
    MICA_CALL(mica_json_string(json, "name", results[v].name));
    MICA_CALL(add_variant_members(json, &results[v]));
    MICA_CALL(mica_json_close(json));
  }
  MICA_CALL(mica_json_close(json));
  return MICA_SUCCESS;
}

static void print_variant(const MlsVariantResult *r, int v, int nvariants) {
  printf("variant %d/%d %-24s support %ld-%ld  err f %.3e  d %.3e  dd %.3e (max, line)  %.3g evals/s\n", v + 1,
         nvariants, r->name, r->line_err.support_min, r->line_err.support_max, r->line_err.f_max,
         r->line_err.df_max, r->line_err.ddf_max, r->evals_per_s);
  fflush(stdout);
}

static void free_results(MlsVariantResult *results, int n) {
  for (int v = 0; v < n; v++) {
    free(results[v].line);
    free(results[v].volume);
  }
  free(results);
}

static int run_mls_study(const MicaDeck *deck, const char *outdir, MicaJson *summary) {
  const int nlisted = mica_deck_list_length(deck, "study.variants");
  const int nvariants = nlisted > 0 ? nlisted : 1;
  MlsVariantResult *results = NULL;
  MicaDeck *variant = NULL;
  int ierr = MICA_SUCCESS, chart;
  const char *title;
  MICA_CALL(MICA_CALLOC(results, nvariants));
  for (int v = 0; v < nvariants; v++) {
    if (nlisted > 0) MICA_CALL_CLEANUP(mica_deck_variant(deck, "study.variants", v, &variant));
    MICA_CALL_CLEANUP(run_variant(variant ? variant : deck, variant != NULL, &results[v]));
    mica_deck_destroy(&variant);
    print_variant(&results[v], v, nvariants);
  }
  MICA_CALL_CLEANUP(write_summary(summary, results, nvariants));
  MICA_CALL_CLEANUP(mls_study_write_csv(results, nvariants, outdir));
  MICA_CALL_CLEANUP(mica_deck_bool(deck, "output.chart", &chart));
  MICA_CALL_CLEANUP(mica_deck_string(deck, "problem.title", &title));
  if (chart) MICA_CALL_CLEANUP(mls_study_write_chart(results, nvariants, title, outdir));
cleanup:
  mica_deck_destroy(&variant);
  free_results(results, nvariants);
  return ierr;
}

const MicaCommand mica_command_mls = {
    {"mls",
     "MLS approximation accuracy study: a function and its derivatives against exact values", 0, NULL, NULL},
    "Particles on a regular or jittered grid carry the values of function.f; the MLS approximation and\n"
    "its first and second derivatives along sample.axis are compared with the exact ones (differentiated\n"
    "symbolically) on a sample line and at random points. Variants (study.variants) compare bases, orders,\n"
    "weights, supports and radii in one run. Writes mls.csv, summary.json, mls_error.png/.svg.",
    mica_mls_schema,
    run_mls_study,
};
