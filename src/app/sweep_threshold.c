/* Exact model-economy thresholds (docs/theory.md §"Model-economy thresholds"): where a sweep compares models,
 * the size x at which a model's probe comes within the tolerance of the classical model's,
 *   d(x) = max over the other axes' combinations of |p_model(x) / p_classical(x) − 1| ≤ tolerance,
 * bracketed by the sampled points — lo the largest sampled x where d > tolerance, hi the smallest from which
 * d ≤ tolerance at every larger sampled x — and narrowed by bisection: at the midpoint m (geometric on a log
 * x axis), the model and the classical model are solved for every combination of the other axes (each a
 * `mica run` of the sweep's deck with x = m), and m replaces lo or hi. It assumes d crosses the tolerance once
 * between lo and hi (the grid shows whether it crosses more often elsewhere). Steps stop at
 * sweep.threshold_steps or when (hi − lo) / hi ≤ sweep.threshold_rtol; the estimate is the midpoint. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/files.h"
#include "sweep.h"

/* The sampled bracket of model w: hi the smallest sampled x from which every pair agrees, vhi its value index,
 * lo the next smaller sampled x with data (NAN if none). State as SweepThreshold.state. */
static int sampled_bracket(const SweepSpec *spec, const SweepPoint *pts, int w, int classical, SweepThreshold *t,
                           int *vhi) {
  const SweepAxis *xa = &spec->axes[spec->x];
  const int k = spec->probe;
  double last = INFINITY;
  t->state = -1, t->lo = NAN, *vhi = -1;
  for (;;) { /* x values from the largest down */
    int vx = -1;
    for (int v = 0; v < xa->nvalues; v++)
      if (xa->values[v] < last && (vx < 0 || xa->values[v] > xa->values[vx])) vx = v;
    if (vx < 0) return MICA_SUCCESS;
    last = xa->values[vx];
    int seen = 0, agree = 1;
    for (long p = 0; p < spec->npoints; p++) {
      if (pts[p].choice[spec->x] != vx || pts[p].choice[spec->model_axis] != w || pts[p].status) continue;
      const long q = sweep_partner(spec, pts, p, classical);
      if (q < 0 || pts[q].status) continue;
      const double a = pts[p].probe[k], b = pts[q].probe[k];
      const double d = b != 0 ? fabs(a / b - 1) : (a == 0 ? 0 : INFINITY);
      seen = 1, agree &= d <= spec->tolerance;
    }
    if (!seen) continue;
    if (!agree) {
      if (t->state < 0) t->state = 0;
      else t->lo = last;
      return MICA_SUCCESS;
    }
    t->state = 1, t->hi = last, *vhi = vx;
  }
}

/* The overrides of point p with x replaced by the value x (17 digits, as sweep_override_text writes numbers). */
static int overrides_at(const SweepSpec *spec, const SweepPoint *pt, double x, SweepOverrides *o) {
  MICA_CALL(sweep_overrides_create(spec->axes, spec->naxes, pt->choice, o));
  snprintf(o->text[spec->x], sizeof o->text[spec->x], "%s=%.17g", spec->axes[spec->x].path, x);
  return MICA_SUCCESS;
}

/* Solves point p of the grid with x = value into dir; *probe its probe (NAN and *ok = 0 if the run failed). */
static int solve_at(const SweepSpec *spec, const SweepPoint *pt, double x, const char *dir, RunReuse *reuse,
                    double *probe, int *ok) {
  SweepOverrides o = {0};
  MicaJson *json = NULL;
  char *path = NULL;
  int ierr = MICA_SUCCESS;
  *probe = NAN, *ok = 0;
  MICA_CALL_CLEANUP(overrides_at(spec, pt, x, &o));
  MICA_CALL_CLEANUP(mica_make_dir(dir));
  MICA_CALL_CLEANUP(mica_json_create(&json));
  MICA_CALL_CLEANUP(sweep_summary_header(json, spec->deck, "sweep_point", 0, &o));
  if (sweep_point_solve(spec, dir, &o, json, reuse) != MICA_SUCCESS) {
    mica_error_clear(); /* a failed run ends the bisection, not the sweep */
    goto cleanup;
  }
  if (mica_json_get_number(json, spec->probes[spec->probe], probe) != MICA_SUCCESS) {
    mica_error_clear();
    goto cleanup;
  }
  *ok = isfinite(*probe);
  MICA_CALL_CLEANUP(mica_path_join(dir, "summary.json", &path));
  MICA_CALL_CLEANUP(mica_json_write(json, path));
cleanup:
  sweep_overrides_destroy(&o);
  mica_json_destroy(&json);
  free(path);
  return ierr;
}

/* d(x) ≤ tolerance for every combination of the other axes (the grid's points of model w at value index vhi
 * and their classical partners, solved at x instead): *agree, or *ok = 0 when a run failed. */
static int agree_at(const SweepSpec *spec, const SweepPoint *pts, const char *outdir, int w, int classical, int vhi,
                    double x, int step, RunReuse *reuse, SweepThreshold *t, int *agree, int *ok) {
  char name[96];
  *agree = 1, *ok = 1;
  int n = 0;
  for (long p = 0; p < spec->npoints && *ok; p++) {
    if (pts[p].choice[spec->x] != vhi || pts[p].choice[spec->model_axis] != w || pts[p].status) continue;
    const long q = sweep_partner(spec, pts, p, classical);
    if (q < 0 || pts[q].status) continue;
    double a, b;
    char *dir = NULL;
    n++;
    snprintf(name, sizeof name, "thresholds/%s/%d_%d_%s", spec->axes[spec->model_axis].words[w], step, n,
             spec->axes[spec->model_axis].words[w]);
    MICA_CALL(mica_path_join(outdir, name, &dir));
    const int ierr = solve_at(spec, &pts[p], x, dir, reuse, &a, ok);
    free(dir);
    MICA_CALL(ierr);
    t->solves++;
    if (!*ok) break;
    snprintf(name, sizeof name, "thresholds/%s/%d_%d_%s", spec->axes[spec->model_axis].words[w], step, n,
             spec->classical);
    MICA_CALL(mica_path_join(outdir, name, &dir));
    const int ierr2 = solve_at(spec, &pts[q], x, dir, reuse, &b, ok);
    free(dir);
    MICA_CALL(ierr2);
    t->solves++;
    const double d = b != 0 ? fabs(a / b - 1) : (a == 0 ? 0 : INFINITY);
    *agree &= d <= spec->tolerance;
  }
  return MICA_SUCCESS;
}

static double midpoint(const SweepSpec *spec, double lo, double hi) {
  return spec->logx && lo > 0 ? sqrt(lo * hi) : 0.5 * (lo + hi);
}

int sweep_threshold(const SweepSpec *spec, const SweepPoint *pts, const char *outdir, int w, int classical,
                    SweepThreshold *t) {
  int vhi;
  memset(t, 0, sizeof *t);
  MICA_CALL(sampled_bracket(spec, pts, w, classical, t, &vhi));
  if (t->state != 1) return MICA_SUCCESS;
  RunReuse *reuse = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(run_reuse_create(&reuse));
  while (!isnan(t->lo) && t->steps < spec->threshold_steps && (t->hi - t->lo) > spec->threshold_rtol * fabs(t->hi)) {
    const double m = midpoint(spec, t->lo, t->hi);
    int agree, ok;
    MICA_CALL_CLEANUP(agree_at(spec, pts, outdir, w, classical, vhi, m, t->steps + 1, reuse, t, &agree, &ok));
    if (!ok) {
      t->failed = 1;
      break;
    }
    t->steps++;
    if (agree) t->hi = m;
    else t->lo = m;
  }
  t->x = isnan(t->lo) ? t->hi : midpoint(spec, t->lo, t->hi);
cleanup:
  run_reuse_destroy(&reuse);
  return ierr;
}
