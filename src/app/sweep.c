/* `mica sweep`: a run deck solved at every point of a grid (or zip) of values of some of its settings.
 *
 * Each point is the run deck loaded again with the point's values as --set overrides (after the user's)
 * and solved by `mica run`'s own entry point, into DIR/points/<n>/ (its summary.json and run.log). A point
 * that fails is recorded and the sweep goes on; the sweep fails only when every point does. Results:
 * sweep.csv (one row per point), summary.json (counts, and how the models compare when material.model is
 * swept), sweep.png/.svg (the probe against x, with analytic curves and measured points). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mica/files.h"
#include "mica/parallel.h"
#include "mica/timer.h"
#include "run.h"
#include "study_common.h"
#include "sweep.h"

/* Points write no fields and no Newton monitor unless the user's --set says otherwise (these come first). */
static const char *const point_defaults[] = {"output.vtu=false", "output.monitor=false"};

/* ---- directories ------------------------------------------------------------------------------------ */

static int point_dir(const char *outdir, long p, char **dir) {
  char name[64];
  snprintf(name, sizeof name, "points/%ld", p + 1);
  MICA_CALL(mica_path_join(outdir, name, dir));
  MICA_CALL(mica_make_dir(*dir));
  return MICA_SUCCESS;
}

/* ---- one point -------------------------------------------------------------------------------------- */

/* `mica run` with stdout in dir/run.log (the run's own lines would drown the progress), reusing what the
 * previous point built when its settings leave it unchanged. */
static int run_logged(const MicaDeck *deck, const char *dir, MicaJson *summary, RunReuse *reuse) {
  int saved;
  MICA_CALL(mica_study_log_open(dir, &saved));
  const int ierr = run_solve_reusing(deck, dir, summary, reuse);
  mica_study_log_close(saved);
  return ierr;
}

int sweep_point_solve(const SweepSpec *spec, const char *dir, const SweepOverrides *o, MicaJson *json,
                      RunReuse *reuse) {
  MicaDeck *deck = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(sweep_load(spec, 2, point_defaults, o->n, o->list, &deck));
  MICA_CALL_CLEANUP(run_logged(deck, dir, json, reuse));
cleanup:
  mica_deck_destroy(&deck);
  return ierr;
}

static int record_failure(SweepPoint *pt, int ierr) {
  pt->status = ierr;
  const char *message = mica_error_message();
  MICA_CALL(MICA_MALLOC(pt->message, strlen(message) + 1));
  strcpy(pt->message, message);
  mica_error_clear();
  return MICA_SUCCESS;
}

/* What the point spent building its problem, and whether it computed shape functions. */
static void read_setup(const MicaJson *json, SweepPoint *pt) {
  static const char *const phases[] = {"time_discretize", "time_mls_setup", "time_cache_and_pattern"};
  pt->setup = 0;
  for (int i = 0; i < 3; i++) {
    double t = NAN;
    if (mica_json_get_number(json, phases[i], &t) != MICA_SUCCESS) mica_error_clear();
    pt->setup += t;
  }
  if (mica_json_get_number(json, "shape_caches_built", &pt->caches_built) != MICA_SUCCESS) {
    pt->caches_built = NAN;
    mica_error_clear();
  }
}

static void read_probes(const SweepSpec *spec, const MicaJson *json, SweepPoint *pt) {
  for (int i = 0; i < spec->nprobes; i++)
    if (mica_json_get_number(json, spec->probes[i], &pt->probe[i]) != MICA_SUCCESS) {
      pt->probe[i] = NAN; /* a probe the run did not report (it failed before the probes) */
      mica_error_clear();
    }
}

/* Under mpirun, the group of ranks that solved the point (1-based) and how many ranks it has. */
static int add_group(MicaJson *json, int group) {
  if (mica_parallel_world_size() == 1) return MICA_SUCCESS;
  MICA_CALL(mica_json_int(json, "group", group + 1));
  return mica_json_int(json, "group_ranks", mica_parallel_size());
}

/* A failed run may have left its summary half-built: the point's summary is then written afresh. */
static int write_failure_summary(const SweepSpec *spec, long p, const SweepOverrides *o, const SweepPoint *pt,
                                 const char *path) {
  MicaJson *json = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_json_create(&json));
  MICA_CALL_CLEANUP(sweep_summary_header(json, spec->deck, "sweep_point", p, o));
  MICA_CALL_CLEANUP(add_group(json, pt->group));
  MICA_CALL_CLEANUP(mica_json_string(json, "status", "error"));
  MICA_CALL_CLEANUP(mica_json_string(json, "error", pt->message ? pt->message : ""));
  MICA_CALL_CLEANUP(mica_json_int(json, "exit_status", mica_exit_status(pt->status)));
  MICA_CALL_CLEANUP(mica_json_number(json, "time_total", pt->time));
  MICA_CALL_CLEANUP(mica_json_write(json, path));
cleanup:
  mica_json_destroy(&json);
  return ierr;
}

/* Runs point p into outdir/points/<p+1>/. Only the sweep's own failures (files, memory) are returned. */
static int run_point(const SweepSpec *spec, long p, const char *outdir, RunReuse *reuse, SweepPoint *pt) {
  SweepOverrides o = {0};
  MicaJson *json = NULL;
  char *dir = NULL, *path = NULL;
  int ierr = MICA_SUCCESS;
  const double start = mica_wtime();
  sweep_point_choice(spec, p, pt->choice);
  MICA_CALL_CLEANUP(sweep_overrides_create(spec->axes, spec->naxes, pt->choice, &o));
  MICA_CALL_CLEANUP(point_dir(outdir, p, &dir));
  MICA_CALL_CLEANUP(mica_path_join(dir, "summary.json", &path));
  MICA_CALL_CLEANUP(mica_json_create(&json));
  MICA_CALL_CLEANUP(sweep_summary_header(json, spec->deck, "sweep_point", p, &o));
  MICA_CALL_CLEANUP(add_group(json, pt->group));
  int failed = mica_parallel_inject("point");
  if (!failed) failed = sweep_point_solve(spec, dir, &o, json, reuse);
  pt->time = mica_wtime() - start;
  if (failed) MICA_CALL_CLEANUP(record_failure(pt, failed)); /* first: reading the summary clears errors */
  pt->reached = failed && mica_study_solve_reached(json);
  read_setup(json, pt);
  if (failed && !pt->reached) {
    MICA_CALL_CLEANUP(write_failure_summary(spec, p, &o, pt, path));
  } else { /* a Newton run that stopped keeps its summary: how far it got, and why (no probes) */
    if (failed) MICA_CALL_CLEANUP(mica_study_add_failure(json, pt->status, pt->message));
    else read_probes(spec, json, pt);
    MICA_CALL_CLEANUP(mica_json_number(json, "time_total", pt->time));
    MICA_CALL_CLEANUP(mica_json_write(json, path));
  }
cleanup:
  sweep_overrides_destroy(&o);
  mica_json_destroy(&json);
  free(dir);
  free(path);
  return ierr;
}

/* ---- progress --------------------------------------------------------------------------------------- */

/* "point 3/12  L=8 model=svk  tip_uy=0.0256  elapsed 4.1 s  remaining ~12 s" for a point this rank solved
 * (the done-th of its own), "point 4/12  L=16 model=svk  tip_uy=0.204  (group 2 of 2)" for another group's. */
static void print_progress(const SweepSpec *spec, long p, const SweepPoint *pt, int ngroups, double elapsed,
                           long done, long own) {
  printf("point %ld/%ld ", p + 1, spec->npoints);
  for (int a = 0; a < spec->naxes; a++) {
    char label[2048]; /* "path = word": a path and a word of at most MICA_DECK_LONG_TEXT_MAX */
    sweep_value_label(&spec->axes[a], pt->choice[a], label, sizeof label);
    printf(" %s", label);
  }
  if (pt->status == MICA_SUCCESS)
    printf("  %s=%.6g", spec->probes[spec->probe], pt->probe[spec->probe]);
  else
    printf("  failed: %.*s", (int)strcspn(pt->message, "\n"), pt->message);
  if (ngroups > 1) printf("  (group %d of %d)", pt->group + 1, ngroups);
  if (done > 0) printf("  elapsed %.1f s  remaining ~%.0f s", elapsed, elapsed / (double)done * (double)(own - done));
  printf("\n");
  fflush(stdout);
}

/* ---- comparing models ------------------------------------------------------------------------------- */

long sweep_partner(const SweepSpec *spec, const SweepPoint *pts, long p, int classical) {
  const int m = spec->model_axis;
  for (long q = 0; q < spec->npoints; q++) {
    int same = pts[q].choice[m] == classical;
    for (int a = 0; a < spec->naxes && same; a++) {
      const SweepAxis *axis = &spec->axes[a];
      const int u = pts[p].choice[a], v = pts[q].choice[a];
      if (a != m) same = axis->values ? axis->values[u] == axis->values[v] : !strcmp(axis->words[u], axis->words[v]);
    }
    if (same) return q;
  }
  return -1;
}

/* The statement and the summary of model w against the classical one: "agrees_with_classical_above" (the
 * smallest x known to agree: the bisection bracket's upper end) and "model_thresholds" (estimate, bracket,
 * steps), written by compare_models in two passes. */
static void print_threshold(const SweepSpec *spec, const char *model, const SweepThreshold *t) {
  const char *probe = spec->probes[spec->probe], *xl = spec->axes[spec->x].label;
  if (t->state < 0) {
    printf("%s: no pair of successful points to compare with %s\n", model, spec->classical);
    return;
  }
  if (t->state == 0) {
    printf("%s does not agree with %s (|%s / %s_%s - 1| <= %g) at the largest %s\n", model, spec->classical, probe,
           probe, spec->classical, spec->tolerance, xl);
    return;
  }
  printf("%s agrees with %s (|%s / %s_%s - 1| <= %g) for %s >= %g", model, spec->classical, probe, probe,
         spec->classical, spec->tolerance, xl, t->hi);
  if (isnan(t->lo)) printf(" (at every sampled %s)\n", xl);
  else
    printf("; the threshold lies in [%.6g, %.6g], estimate %.6g (%d bisection step%s, %d runs%s)\n", t->lo, t->hi,
           t->x, t->steps, t->steps == 1 ? "" : "s", t->solves, t->failed ? "; stopped by a failed run" : "");
}

static int write_threshold(const char *model, const SweepThreshold *t, MicaJson *summary) {
  MICA_CALL(mica_json_open_object(summary, model));
  if (t->state != 1) {
    MICA_CALL(mica_json_string(summary, "threshold", t->state == 0 ? "never" : "no data"));
    return mica_json_close(summary);
  }
  MICA_CALL(mica_json_number(summary, "threshold", t->x));
  MICA_CALL(mica_json_open_array(summary, "bracket"));
  if (isnan(t->lo)) MICA_CALL(mica_json_string(summary, NULL, "below the sampled range"));
  else MICA_CALL(mica_json_number(summary, NULL, t->lo));
  MICA_CALL(mica_json_number(summary, NULL, t->hi));
  MICA_CALL(mica_json_close(summary));
  MICA_CALL(mica_json_int(summary, "bisection_steps", t->steps));
  MICA_CALL(mica_json_int(summary, "bisection_runs", t->solves));
  if (t->failed) MICA_CALL(mica_json_string(summary, "bisection", "stopped: a run failed (see thresholds/)"));
  return mica_json_close(summary);
}

/* Each model against the classical one (sweep_threshold.c); threshold[w]: model w's estimate for the chart
 * (NAN: none). */
static int compare_models(const SweepSpec *spec, const SweepPoint *pts, const char *outdir, MicaJson *summary,
                          double *threshold) {
  const int m = spec->model_axis;
  if (m < 0) return MICA_SUCCESS;
  const SweepAxis *axis = &spec->axes[m];
  int classical = -1;
  for (int v = 0; v < axis->nvalues; v++)
    if (!strcmp(axis->words[v], spec->classical)) classical = v;
  if (classical < 0 || spec->x < 0) {
    printf("no model comparison: %s\n", classical < 0 ? "the classical model is not among material.model's words"
                                                       : "no numeric swept path for x");
    return MICA_SUCCESS;
  }
  SweepThreshold *t;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(t, axis->nvalues));
  for (int w = 0; w < axis->nvalues; w++) {
    if (w == classical) continue;
    MICA_CALL_CLEANUP(sweep_threshold(spec, pts, outdir, w, classical, &t[w]));
    print_threshold(spec, axis->words[w], &t[w]);
    if (t[w].state == 1) threshold[w] = t[w].x;
  }
  MICA_CALL_CLEANUP(mica_json_open_object(summary, "agrees_with_classical_above"));
  for (int w = 0; w < axis->nvalues; w++) {
    if (w == classical) continue;
    if (t[w].state == 1) MICA_CALL_CLEANUP(mica_json_number(summary, axis->words[w], t[w].hi));
    else MICA_CALL_CLEANUP(mica_json_string(summary, axis->words[w], t[w].state == 0 ? "never" : "no data"));
  }
  MICA_CALL_CLEANUP(mica_json_close(summary));
  MICA_CALL_CLEANUP(mica_json_open_object(summary, "model_thresholds"));
  for (int w = 0; w < axis->nvalues; w++)
    if (w != classical) MICA_CALL_CLEANUP(write_threshold(axis->words[w], &t[w], summary));
  MICA_CALL_CLEANUP(mica_json_close(summary));
cleanup:
  free(t);
  return ierr;
}

/* ---- the command ------------------------------------------------------------------------------------ */

static int points_create(const SweepSpec *spec, SweepPoint **pts) {
  MICA_CALL(MICA_CALLOC(*pts, spec->npoints));
  for (long p = 0; p < spec->npoints; p++) {
    MICA_CALL(MICA_CALLOC((*pts)[p].choice, spec->naxes));
    MICA_CALL(MICA_MALLOC((*pts)[p].probe, spec->nprobes));
    for (int i = 0; i < spec->nprobes; i++) (*pts)[p].probe[i] = NAN;
  }
  return MICA_SUCCESS;
}

static void points_free(const SweepSpec *spec, SweepPoint **pts) {
  for (long p = 0; *pts && p < spec->npoints; p++) {
    free((*pts)[p].choice);
    free((*pts)[p].probe);
    free((*pts)[p].message);
  }
  MICA_FREE(*pts);
}

/* This rank's points (all of them when serial), in order, each reusing what the previous one built when it
 * can. The ranks of a group agree after every point, so that they take the next one together. */
static int run_own_points(const SweepSpec *spec, SweepPoint *pts, const MicaStudyGroups *g) {
  const double start = mica_wtime();
  long own = 0, done = 0;
  RunReuse *reuse = NULL;
  int ierr = MICA_SUCCESS;
  for (long p = 0; p < spec->npoints; p++) own += mica_study_groups_mine(g, p);
  MICA_CALL(run_reuse_create(&reuse));
  for (long p = 0; p < spec->npoints && !ierr; p++) {
    if (!mica_study_groups_mine(g, p)) continue;
    pts[p].group = g->groups.group;
    ierr = run_point(spec, p, mica_study_groups_outdir(g), reuse, &pts[p]);
    ierr = mica_parallel_agree(ierr);
    if (!ierr) print_progress(spec, p, &pts[p], g->groups.ngroups, mica_wtime() - start, ++done, own);
  }
  run_reuse_destroy(&reuse);
  return ierr;
}

/* One point's outcome, packed for the other ranks (the leader of the group that solved it sends it). */
static int pack_point(const SweepSpec *spec, long p, const SweepPoint *pt, MicaPack *pack) {
  MICA_CALL(mica_pack_put(pack, &p, sizeof p));
  MICA_CALL(mica_pack_put(pack, &pt->group, sizeof pt->group));
  MICA_CALL(mica_pack_put(pack, &pt->status, sizeof pt->status));
  MICA_CALL(mica_pack_put(pack, &pt->reached, sizeof pt->reached));
  MICA_CALL(mica_pack_put(pack, &pt->time, sizeof pt->time));
  MICA_CALL(mica_pack_put(pack, &pt->setup, sizeof pt->setup));
  MICA_CALL(mica_pack_put(pack, &pt->caches_built, sizeof pt->caches_built));
  MICA_CALL(mica_pack_put(pack, pt->probe, (long)sizeof *pt->probe * spec->nprobes));
  return mica_pack_put_text(pack, pt->message);
}

static int unpack_point(const SweepSpec *spec, SweepPoint *pts, MicaPack *pack) {
  long p;
  MICA_CALL(mica_pack_get(pack, &p, sizeof p));
  MICA_CHECK(p >= 0 && p < spec->npoints, MICA_ERR_LIBRARY, "a gathered point has index %ld of %ld", p, spec->npoints);
  SweepPoint *pt = &pts[p];
  MICA_CALL(mica_pack_get(pack, &pt->group, sizeof pt->group));
  MICA_CALL(mica_pack_get(pack, &pt->status, sizeof pt->status));
  MICA_CALL(mica_pack_get(pack, &pt->reached, sizeof pt->reached));
  MICA_CALL(mica_pack_get(pack, &pt->time, sizeof pt->time));
  MICA_CALL(mica_pack_get(pack, &pt->setup, sizeof pt->setup));
  MICA_CALL(mica_pack_get(pack, &pt->caches_built, sizeof pt->caches_built));
  MICA_CALL(mica_pack_get(pack, pt->probe, (long)sizeof *pt->probe * spec->nprobes));
  MICA_FREE(pt->message);
  MICA_CALL(mica_pack_get_text(pack, &pt->message));
  sweep_point_choice(spec, p, pt->choice);
  return MICA_SUCCESS;
}

/* Every rank gets every point's outcome from the leader of the group that solved it; rank 0 prints the
 * progress lines of the other groups' points. */
static int gather_points(int ierr, const SweepSpec *spec, SweepPoint *pts, const MicaStudyGroups *g) {
  MicaPack mine = {0}, all = {0};
  for (long p = 0; p < spec->npoints && !ierr && g->groups.leader; p++)
    if (mica_study_groups_mine(g, p)) ierr = pack_point(spec, p, &pts[p], &mine);
  ierr = mica_pack_allgather(ierr, &mine, &all);
  while (!ierr && all.at < all.size) ierr = unpack_point(spec, pts, &all);
  mica_pack_free(&mine);
  mica_pack_free(&all);
  MICA_CALL(mica_parallel_agree(ierr));
  for (long p = 0; p < spec->npoints; p++)
    if (pts[p].group != g->groups.group) print_progress(spec, p, &pts[p], g->groups.ngroups, 0, 0, 0);
  return MICA_SUCCESS;
}

/* Every point, by the groups of ranks (one group of the one rank when serial); *nfailed counts the failures.
 * With no success, the first failure is the error. */
static int run_points(const SweepSpec *spec, SweepPoint *pts, const char *outdir, long *nfailed) {
  MicaStudyGroups g;
  long first_failure = -1;
  *nfailed = 0;
  int ierr = mica_study_groups_begin(spec->ranks_per_point, outdir, &g);
  if (!ierr) ierr = run_own_points(spec, pts, &g);
  ierr = mica_study_groups_end(ierr, &g);
  if (!ierr) ierr = gather_points(ierr, spec, pts, &g);
  mica_study_groups_free(&g);
  MICA_CALL(ierr);
  for (long p = 0; p < spec->npoints; p++)
    if (pts[p].status) {
      ++*nfailed;
      if (first_failure < 0) first_failure = p;
    }
  if (*nfailed == spec->npoints)
    return mica_error_set(__FILE__, __LINE__, __func__, pts[first_failure].status,
                          "every point of the sweep failed (%ld); point %ld: %s", spec->npoints, first_failure + 1,
                          pts[first_failure].message);
  return MICA_SUCCESS;
}

/* How much the points reused: those that computed no shape function, and the setup time of the first
 * point against the mean of the reusing ones (the saving a sweep over material settings gets). */
static int add_reuse(const SweepSpec *spec, const SweepPoint *pts, MicaJson *summary) {
  long reusing = 0;
  double reused_setup = 0;
  for (long p = 0; p < spec->npoints; p++)
    if (!pts[p].status && pts[p].caches_built == 0) reusing++, reused_setup += pts[p].setup;
  MICA_CALL(mica_json_int(summary, "points_sharing_shape_functions", reusing));
  if (!reusing || pts[0].status) return MICA_SUCCESS;
  MICA_CALL(mica_json_number(summary, "setup_first_point", pts[0].setup));
  MICA_CALL(mica_json_number(summary, "setup_sharing_points_mean", reused_setup / (double)reusing));
  printf("reuse: %ld of %ld points computed no shape function; setup %.3g s on the first point, %.3g s mean on "
         "those\n", reusing, spec->npoints, pts[0].setup, reused_setup / (double)reusing);
  return MICA_SUCCESS;
}

/* The chart is drawn last and is not the result: when gnuplot fails, the sweep's numbers still stand. */
static int draw_chart(const SweepSpec *spec, const SweepPoint *pts, const double *threshold, const char *outdir,
                      MicaJson *summary) {
  if (!spec->chart || spec->x < 0) return mica_json_string(summary, "chart", spec->chart ? "none: no numeric x" : "off");
  if (sweep_write_chart(spec, pts, threshold, outdir) == MICA_SUCCESS) return mica_json_string(summary, "chart", "sweep.png");
  fprintf(stderr, "mica sweep: no chart: %s\n", mica_error_message());
  mica_error_clear();
  return mica_json_string(summary, "chart", "failed: see gnuplot.log");
}

static int add_summary(const SweepSpec *spec, long nfailed, MicaJson *summary) {
  MICA_CALL(mica_json_string(summary, "mode", spec->zip ? "zip" : "grid"));
  MICA_CALL(mica_json_open_array(summary, "swept"));
  for (int a = 0; a < spec->naxes; a++) MICA_CALL(mica_json_string(summary, NULL, spec->axes[a].path));
  MICA_CALL(mica_json_close(summary));
  MICA_CALL(mica_json_string(summary, "probe", spec->probes[spec->probe]));
  if (spec->x >= 0) MICA_CALL(mica_json_string(summary, "x", spec->axes[spec->x].path));
  MICA_CALL(mica_json_int(summary, "points_total", spec->npoints));
  MICA_CALL(mica_json_int(summary, "points_ok", spec->npoints - nfailed));
  MICA_CALL(mica_json_int(summary, "points_failed", nfailed));
  return MICA_SUCCESS;
}

/* Under mpirun: how the points were dealt, and how many each group solved (as the groups reported them). */
static int add_groups(const SweepSpec *spec, const SweepPoint *pts, MicaJson *summary) {
  if (mica_parallel_world_size() == 1) return MICA_SUCCESS;
  const int ngroups = mica_parallel_world_size() / spec->ranks_per_point;
  MICA_CALL(mica_json_int(summary, "ranks_per_point", spec->ranks_per_point));
  MICA_CALL(mica_json_int(summary, "groups", ngroups));
  MICA_CALL(mica_json_open_array(summary, "points_per_group"));
  for (int g = 0; g < ngroups; g++) {
    long n = 0;
    for (long p = 0; p < spec->npoints; p++) n += pts[p].group == g;
    MICA_CALL(mica_json_int(summary, NULL, n));
  }
  return mica_json_close(summary);
}

static int sweep_run(const MicaDeck *deck, const char *outdir, MicaJson *summary) {
  SweepSpec spec;
  SweepPoint *pts = NULL;
  char *points = NULL;
  double *threshold = NULL; /* per word of the model axis */
  long nfailed = 0;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(sweep_spec_read(deck, &spec));
  MICA_CALL_CLEANUP(mica_path_join(outdir, "points", &points));
  printf("sweep: %ld point%s (%s of %d setting%s)\n", spec.npoints, spec.npoints > 1 ? "s" : "",
         spec.zip ? "zip" : "grid", spec.naxes, spec.naxes > 1 ? "s" : "");
  if (mica_parallel_world_size() > 1)
    printf("sweep: %d group%s of %d rank%s, point i solved by group i mod %d\n",
           mica_parallel_world_size() / spec.ranks_per_point, mica_parallel_world_size() > spec.ranks_per_point ? "s" : "",
           spec.ranks_per_point, spec.ranks_per_point > 1 ? "s" : "", mica_parallel_world_size() / spec.ranks_per_point);
  MICA_CALL_CLEANUP(points_create(&spec, &pts));
  MICA_CALL_CLEANUP(run_points(&spec, pts, outdir, &nfailed));
  MICA_CALL_CLEANUP(sweep_write_csv(&spec, pts, outdir));
  MICA_CALL_CLEANUP(add_summary(&spec, nfailed, summary));
  MICA_CALL_CLEANUP(add_groups(&spec, pts, summary));
  MICA_CALL_CLEANUP(add_reuse(&spec, pts, summary));
  if (spec.model_axis >= 0) {
    MICA_CALL_CLEANUP(MICA_MALLOC(threshold, spec.axes[spec.model_axis].nvalues));
    for (int w = 0; w < spec.axes[spec.model_axis].nvalues; w++) threshold[w] = NAN;
  }
  MICA_CALL_CLEANUP(compare_models(&spec, pts, outdir, summary, threshold));
  MICA_CALL_CLEANUP(draw_chart(&spec, pts, threshold, outdir, summary));
  printf("sweep: %ld of %ld points ok, %ld failed%s\n", spec.npoints - nfailed, spec.npoints, nfailed,
         nfailed ? " (see sweep.csv and points/<n>/summary.json)" : "");
cleanup:
  if (ierr && points) mica_remove_tree(points);
  free(points);
  free(threshold);
  points_free(&spec, &pts);
  sweep_spec_free(&spec);
  return ierr;
}

const MicaCommand mica_command_sweep = {
    {"sweep",
     "solve a run deck at every point of a grid of values of its settings; CSV, chart, model comparison",
     0, NULL, NULL},
    "The deck is a run deck plus a `sweep` group naming settings and their values (numbers, words or a\n"
    "range). Every combination (mode = \"grid\") or every i-th tuple (mode = \"zip\") is solved like\n"
    "`mica run` with the values as --set overrides, into DIR/points/<n>/. A failing point is recorded and the\n"
    "sweep goes on. Writes sweep.csv (per point: the swept values, every probe, the time, the status),\n"
    "summary.json, and sweep.png/.svg: the chosen probe against the x path, one curve per combination of the\n"
    "other paths, with analytic curves and measured points. When material.model is swept, the summary says\n"
    "above which x each model agrees with the classical one within the tolerance. Under mpirun -np P the\n"
    "points are dealt to P / sweep.ranks_per_point groups of ranks (default: one rank per point) and the\n"
    "table is gathered to rank 0.",
    mica_run_schema,
    sweep_run,
};
