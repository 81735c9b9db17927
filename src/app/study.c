/* `mica study`: speed against accuracy. Every combination of the deck's `study.choices` is solved like
 * `mica run` (the run deck loaded again with the combination's values as --set overrides, after the
 * user's), `study.repeat` times, into DIR/points/<n>/; its error (a norm against the exact solution, or a
 * probe against its reference) and its costs (dofs, nnz, memory, the minimum time of every phase over the
 * repeats) make one row of study.csv. A combination that fails is recorded and the study goes on; the
 * study fails only when every combination does. Then the Pareto front of error against time (a row is on
 * it when no other row has both a smaller time and a smaller error), the fastest combination that reaches
 * study.target, summary.json and the charts. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/files.h"
#include "mica/parallel.h"
#include "mica/timer.h"
#include "run.h"
#include "study.h"
#include "study_common.h"

/* Combinations write no fields and no Newton monitor unless the user's --set says otherwise. */
static const char *const point_defaults[] = {"output.vtu=false", "output.monitor=false"};

enum { CHOICE_TEXT = 2048 };

/* ---- one combination ---------------------------------------------------------------------------------- */

/* A member of a run's summary, or NAN when the run did not report it. */
static double get_number(const MicaJson *json, const char *key) {
  double v;
  if (mica_json_get_number(json, key, &v) == MICA_SUCCESS) return v;
  mica_error_clear();
  return NAN;
}

/* Loads and solves the combination once; the error code is the combination's. On success, *reference
 * is study.reference as the combination's deck evaluates it (it may use a varied parameter). */
static int solve_once(const StudySpec *spec, const char *dir, const SweepOverrides *o, MicaJson *json, double *reference) {
  MicaDeck *deck = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(sweep_deck_load(spec->deck, 2, point_defaults, o->n, o->list, &deck));
  MICA_CALL_CLEANUP(mica_study_run_logged(&mica_command_run, deck, dir, json));
  if (spec->measure == STUDY_ERROR_PROBE) MICA_CALL_CLEANUP(mica_deck_float(deck, "study.reference", reference));
cleanup:
  mica_deck_destroy(&deck);
  return ierr;
}

static void read_row(const StudySpec *spec, const MicaJson *json, StudyRow *row) {
  row->dofs = (long)get_number(json, "dofs");
  row->particles = (long)get_number(json, "particles");
  row->quadrature_points = (long)get_number(json, "quadrature_points");
  row->nnz = (long)get_number(json, "nnz");
  row->nnz_factor = (long)get_number(json, "nnz_factor");
  row->cache_bytes = (long)get_number(json, "cache_bytes");
  row->matrix_bytes = (long)get_number(json, "matrix_bytes");
  row->error_l2 = get_number(json, "error_l2");
  row->error_h1 = get_number(json, "error_h1");
  row->error_energy = get_number(json, "error_energy");
  for (int i = 0; i < spec->nprobes; i++) row->probe[i] = get_number(json, spec->probes[i]);
}

/* |p − p_ref| / |p_ref| (|p| when the reference is 0). */
static double measured_error(const StudySpec *spec, const StudyRow *row) {
  switch (spec->measure) {
  case STUDY_ERROR_L2: return row->error_l2;
  case STUDY_ERROR_H1: return row->error_h1;
  case STUDY_ERROR_ENERGY: return row->error_energy;
  default: {
    const double p = row->probe[spec->probe], r = row->reference;
    return r != 0 ? fabs(p - r) / fabs(r) : fabs(p);
  }
  }
}

static int record_failure(StudyRow *row, int ierr) {
  row->status = ierr;
  const char *message = mica_error_message();
  MICA_CALL(MICA_MALLOC(row->message, strlen(message) + 1));
  strcpy(row->message, message);
  mica_error_clear();
  return MICA_SUCCESS;
}

/* Under mpirun, the group of ranks that solved the combination (1-based) and how many ranks it has. */
static int add_group(MicaJson *json, int group) {
  if (mica_parallel_world_size() == 1) return MICA_SUCCESS;
  MICA_CALL(mica_json_int(json, "group", group + 1));
  return mica_json_int(json, "group_ranks", mica_parallel_size());
}

static int write_failure_summary(const StudySpec *spec, long p, const SweepOverrides *o, const StudyRow *row,
                                 const char *path) {
  MicaJson *json = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_json_create(&json));
  MICA_CALL_CLEANUP(sweep_summary_header(json, spec->deck, "study_combination", p, o));
  MICA_CALL_CLEANUP(add_group(json, row->group));
  MICA_CALL_CLEANUP(mica_json_string(json, "status", "error"));
  MICA_CALL_CLEANUP(mica_json_string(json, "error", row->message ? row->message : ""));
  MICA_CALL_CLEANUP(mica_json_int(json, "exit_status", mica_exit_status(row->status)));
  MICA_CALL_CLEANUP(mica_json_write(json, path));
cleanup:
  mica_json_destroy(&json);
  return ierr;
}

/* Solves combination p study.repeat times into outdir/points/<p+1>/ (the first solve's summary is kept;
 * the row has the minimum of each phase). Only the study's own failures (files, memory) are returned. */
static int run_combination(const StudySpec *spec, long p, const char *outdir, StudyRow *row) {
  SweepOverrides o = {0};
  MicaJson *json = NULL, *first = NULL;
  char *dir = NULL, *path = NULL, name[64];
  int ierr = MICA_SUCCESS;
  study_combination(spec, p, row->choice);
  for (int k = 0; k < STUDY_NPHASES; k++) row->phase[k] = INFINITY;
  MICA_CALL_CLEANUP(sweep_overrides_create(spec->choices, spec->nchoices, row->choice, &o));
  snprintf(name, sizeof name, "points/%ld", p + 1);
  MICA_CALL_CLEANUP(mica_path_join(outdir, name, &dir));
  MICA_CALL_CLEANUP(mica_make_dir(dir));
  MICA_CALL_CLEANUP(mica_path_join(dir, "summary.json", &path));
  for (int r = 0; r < spec->repeat && !row->status; r++) {
    MICA_CALL_CLEANUP(mica_json_create(&json));
    MICA_CALL_CLEANUP(sweep_summary_header(json, spec->deck, "study_combination", p, &o));
    MICA_CALL_CLEANUP(add_group(json, row->group));
    int failed = mica_parallel_inject("point");
    if (!failed) failed = solve_once(spec, dir, &o, json, &row->reference);
    if (failed) {
      MICA_CALL_CLEANUP(record_failure(row, failed));
      row->reached = mica_study_solve_reached(json);
      if (row->reached) { /* its summary says how far it got, and why: it is the combination's */
        mica_json_destroy(&first);
        first = json;
        json = NULL;
      }
    } else {
      for (int k = 0; k < STUDY_NPHASES; k++) row->phase[k] = fmin(row->phase[k], get_number(json, study_phase_key[k]));
      if (r == 0) { /* the first solve's summary is the combination's */
        read_row(spec, json, row);
        first = json;
        json = NULL;
      }
    }
    mica_json_destroy(&json);
  }
  if (row->status && row->reached) {
    MICA_CALL_CLEANUP(mica_study_add_failure(first, row->status, row->message));
    MICA_CALL_CLEANUP(mica_json_write(first, path));
  } else if (row->status) {
    MICA_CALL_CLEANUP(write_failure_summary(spec, p, &o, row, path));
  }
  if (row->status) {
    row->error = row->time = NAN;
    for (int k = 0; k < STUDY_NPHASES; k++) row->phase[k] = NAN;
  } else {
    row->error = measured_error(spec, row);
    row->time = spec->time_total ? study_total_time(row) : study_solve_time(row);
    MICA_CALL_CLEANUP(mica_json_int(first, "study_repeat", spec->repeat));
    MICA_CALL_CLEANUP(mica_json_write(first, path));
  }
cleanup:
  sweep_overrides_destroy(&o);
  mica_json_destroy(&json);
  mica_json_destroy(&first);
  free(dir);
  free(path);
  return ierr;
}

/* ---- progress ----------------------------------------------------------------------------------------- */

/* "combination 3/60  order=1 m=8  energy 2.07e-02  time 0.052 s  elapsed 4.1 s  remaining ~60 s" for a
 * combination this rank solved (the done-th of its own); another group's ends "(group 2 of 2)". */
static void print_progress(const StudySpec *spec, long p, const StudyRow *row, int ngroups, double elapsed,
                           long done, long own) {
  char text[CHOICE_TEXT];
  study_choice_text(spec, row->choice, text, sizeof text);
  printf("combination %ld/%ld  %s", p + 1, spec->ncombinations, text);
  if (row->status == MICA_SUCCESS)
    printf("  %s %.3e  time %.3g s", spec->error_name, row->error, row->time);
  else
    printf("  failed: %.*s", (int)strcspn(row->message, "\n"), row->message);
  if (ngroups > 1) printf("  (group %d of %d)", row->group + 1, ngroups);
  if (done > 0) printf("  elapsed %.1f s  remaining ~%.0f s", elapsed, elapsed / (double)done * (double)(own - done));
  printf("\n");
  fflush(stdout);
}

/* ---- the front and the fastest ------------------------------------------------------------------------ */

static int usable(const StudyRow *row) { return row->status == MICA_SUCCESS && isfinite(row->error) && isfinite(row->time); }

/* A row is on the front when no other row has both a smaller time and a smaller error. */
static long mark_pareto(const StudySpec *spec, StudyRow *rows) {
  long n = 0;
  for (long i = 0; i < spec->ncombinations; i++) {
    rows[i].pareto = usable(&rows[i]);
    for (long j = 0; j < spec->ncombinations && rows[i].pareto; j++)
      if (usable(&rows[j]) && rows[j].time < rows[i].time && rows[j].error < rows[i].error) rows[i].pareto = 0;
    n += rows[i].pareto;
  }
  return n;
}

/* The row of least time whose error is at most the target (the first of equal times), or -1. */
static long fastest_for_target(const StudySpec *spec, const StudyRow *rows) {
  long best = -1;
  for (long i = 0; i < spec->ncombinations; i++)
    if (usable(&rows[i]) && rows[i].error <= spec->target && (best < 0 || rows[i].time < rows[best].time)) best = i;
  return best;
}

static long smallest_error(const StudySpec *spec, const StudyRow *rows) {
  long best = -1;
  for (long i = 0; i < spec->ncombinations; i++)
    if (usable(&rows[i]) && (best < 0 || rows[i].error < rows[best].error)) best = i;
  return best;
}

/* ---- summary ------------------------------------------------------------------------------------------ */

static int add_row_object(const StudySpec *spec, const StudyRow *rows, long i, const char *key, MicaJson *summary) {
  char text[CHOICE_TEXT];
  study_choice_text(spec, rows[i].choice, text, sizeof text);
  MICA_CALL(mica_json_open_object(summary, key));
  MICA_CALL(mica_json_string(summary, "choice", text));
  MICA_CALL(mica_json_int(summary, "combination", i + 1));
  MICA_CALL(mica_json_number(summary, "time", rows[i].time));
  MICA_CALL(mica_json_number(summary, "error", rows[i].error));
  MICA_CALL(mica_json_int(summary, "dofs", rows[i].dofs));
  MICA_CALL(mica_json_close(summary));
  return MICA_SUCCESS;
}

/* The front's rows by increasing time, in order[]; returns how many. */
static long front_order(const StudySpec *spec, const StudyRow *rows, long *order) {
  long n = 0;
  for (long i = 0; i < spec->ncombinations; i++)
    if (rows[i].pareto) {
      long k = n++;
      while (k > 0 && rows[order[k - 1]].time > rows[i].time) order[k] = order[k - 1], k--;
      order[k] = i;
    }
  return n;
}

static int add_summary(const StudySpec *spec, const StudyRow *rows, long nfailed, long fastest, MicaJson *summary) {
  long *order = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_json_open_array(summary, "choices"));
  for (int c = 0; c < spec->nchoices; c++) MICA_CALL_CLEANUP(mica_json_string(summary, NULL, spec->choices[c].path));
  MICA_CALL_CLEANUP(mica_json_close(summary));
  MICA_CALL_CLEANUP(mica_json_string(summary, "error_measure", spec->error_name));
  MICA_CALL_CLEANUP(mica_json_string(summary, "time_measure", spec->time_total ? "total" : "solve"));
  MICA_CALL_CLEANUP(mica_json_int(summary, "repeat", spec->repeat));
  MICA_CALL_CLEANUP(mica_json_int(summary, "combinations", spec->ncombinations));
  MICA_CALL_CLEANUP(mica_json_int(summary, "ok", spec->ncombinations - nfailed));
  MICA_CALL_CLEANUP(mica_json_int(summary, "failed", nfailed));
  MICA_CALL_CLEANUP(MICA_MALLOC(order, spec->ncombinations));
  const long nfront = front_order(spec, rows, order);
  MICA_CALL_CLEANUP(mica_json_int(summary, "pareto_points", nfront));
  MICA_CALL_CLEANUP(mica_json_open_array(summary, "pareto_front"));
  for (long k = 0; k < nfront; k++) {
    char text[CHOICE_TEXT];
    study_choice_text(spec, rows[order[k]].choice, text, sizeof text);
    MICA_CALL_CLEANUP(mica_json_string(summary, NULL, text));
  }
  MICA_CALL_CLEANUP(mica_json_close(summary));
  MICA_CALL_CLEANUP(mica_json_number(summary, "target", spec->target));
  if (fastest >= 0) {
    MICA_CALL_CLEANUP(add_row_object(spec, rows, fastest, "fastest_for_target", summary));
  } else {
    char text[CHOICE_TEXT];
    snprintf(text, sizeof text, "none: no combination reaches %s error <= %g", spec->error_name, spec->target);
    MICA_CALL_CLEANUP(mica_json_string(summary, "fastest_for_target", text));
  }
  const long best = smallest_error(spec, rows);
  if (best >= 0) MICA_CALL_CLEANUP(add_row_object(spec, rows, best, "smallest_error", summary));
cleanup:
  free(order);
  return ierr;
}

static int print_report(const StudySpec *spec, const StudyRow *rows, long nfailed, long fastest) {
  long *order = NULL;
  char text[CHOICE_TEXT];
  MICA_CALL(MICA_MALLOC(order, spec->ncombinations));
  const long nfront = front_order(spec, rows, order);
  printf("study: %ld of %ld combinations ok, %ld failed%s\n", spec->ncombinations - nfailed, spec->ncombinations,
         nfailed, nfailed ? " (see study.csv and points/<n>/summary.json)" : "");
  printf("Pareto front (%s error against %s time), %ld combination%s:\n", spec->error_name,
         spec->time_total ? "total" : "solve", nfront, nfront == 1 ? "" : "s");
  for (long k = 0; k < nfront; k++) {
    const StudyRow *row = &rows[order[k]];
    study_choice_text(spec, row->choice, text, sizeof text);
    printf("  %-10.4g s  %s %.3e  dofs %-8ld %s\n", row->time, spec->error_name, row->error, row->dofs, text);
  }
  free(order);
  if (fastest >= 0) {
    study_choice_text(spec, rows[fastest].choice, text, sizeof text);
    printf("fastest to %s error <= %g: %s in %.4g s (%s error %.3e, %ld dofs; combination %ld)\n", spec->error_name,
           spec->target, text, rows[fastest].time, spec->error_name, rows[fastest].error, rows[fastest].dofs,
           fastest + 1);
  } else {
    const long best = smallest_error(spec, rows);
    study_choice_text(spec, rows[best].choice, text, sizeof text);
    printf("no combination reaches %s error <= %g; the smallest, %.3e, is %s (%.4g s)\n", spec->error_name,
           spec->target, rows[best].error, text, rows[best].time);
  }
  return MICA_SUCCESS;
}

/* ---- the command -------------------------------------------------------------------------------------- */

static int rows_create(const StudySpec *spec, StudyRow **rows) {
  MICA_CALL(MICA_CALLOC(*rows, spec->ncombinations));
  for (long p = 0; p < spec->ncombinations; p++) {
    StudyRow *row = &(*rows)[p];
    MICA_CALL(MICA_CALLOC(row->choice, spec->nchoices));
    MICA_CALL(MICA_MALLOC(row->probe, spec->nprobes > 0 ? spec->nprobes : 1));
    for (int i = 0; i < spec->nprobes; i++) row->probe[i] = NAN;
    row->error_l2 = row->error_h1 = row->error_energy = row->error = row->time = row->reference = NAN;
  }
  return MICA_SUCCESS;
}

static void rows_destroy(long n, StudyRow **rows) {
  for (long p = 0; *rows && p < n; p++) {
    free((*rows)[p].choice);
    free((*rows)[p].probe);
    free((*rows)[p].message);
  }
  MICA_FREE(*rows);
}

/* This rank's combinations (all of them when serial), in order; the ranks of a group agree after each. */
static int run_own(const StudySpec *spec, StudyRow *rows, const MicaStudyGroups *g) {
  const double start = mica_wtime();
  long own = 0, done = 0;
  int ierr = MICA_SUCCESS;
  for (long p = 0; p < spec->ncombinations; p++) own += mica_study_groups_mine(g, p);
  for (long p = 0; p < spec->ncombinations && !ierr; p++) {
    if (!mica_study_groups_mine(g, p)) continue;
    rows[p].group = g->groups.group;
    ierr = run_combination(spec, p, mica_study_groups_outdir(g), &rows[p]);
    ierr = mica_parallel_agree(ierr);
    if (!ierr) print_progress(spec, p, &rows[p], g->groups.ngroups, mica_wtime() - start, ++done, own);
  }
  return ierr;
}

/* The scalar members of a row, in the order they are packed. */
static int pack_row(const StudySpec *spec, long p, const StudyRow *row, MicaPack *pack) {
  const long counts[] = {row->dofs, row->particles, row->quadrature_points, row->nnz, row->nnz_factor,
                         row->cache_bytes, row->matrix_bytes};
  const double measures[] = {row->error_l2, row->error_h1, row->error_energy, row->reference, row->error, row->time};
  MICA_CALL(mica_pack_put(pack, &p, sizeof p));
  MICA_CALL(mica_pack_put(pack, &row->group, sizeof row->group));
  MICA_CALL(mica_pack_put(pack, &row->status, sizeof row->status));
  MICA_CALL(mica_pack_put(pack, &row->reached, sizeof row->reached));
  MICA_CALL(mica_pack_put(pack, counts, sizeof counts));
  MICA_CALL(mica_pack_put(pack, row->phase, sizeof row->phase));
  MICA_CALL(mica_pack_put(pack, measures, sizeof measures));
  MICA_CALL(mica_pack_put(pack, row->probe, (long)sizeof *row->probe * spec->nprobes));
  return mica_pack_put_text(pack, row->message);
}

static int unpack_row(const StudySpec *spec, StudyRow *rows, MicaPack *pack) {
  long p, counts[7];
  double measures[6];
  MICA_CALL(mica_pack_get(pack, &p, sizeof p));
  MICA_CHECK(p >= 0 && p < spec->ncombinations, MICA_ERR_LIBRARY, "a gathered combination has index %ld of %ld", p,
             spec->ncombinations);
  StudyRow *row = &rows[p];
  MICA_CALL(mica_pack_get(pack, &row->group, sizeof row->group));
  MICA_CALL(mica_pack_get(pack, &row->status, sizeof row->status));
  MICA_CALL(mica_pack_get(pack, &row->reached, sizeof row->reached));
  MICA_CALL(mica_pack_get(pack, counts, sizeof counts));
  MICA_CALL(mica_pack_get(pack, row->phase, sizeof row->phase));
  MICA_CALL(mica_pack_get(pack, measures, sizeof measures));
  MICA_CALL(mica_pack_get(pack, row->probe, (long)sizeof *row->probe * spec->nprobes));
  MICA_FREE(row->message);
  MICA_CALL(mica_pack_get_text(pack, &row->message));
  row->dofs = counts[0], row->particles = counts[1], row->quadrature_points = counts[2], row->nnz = counts[3];
  row->nnz_factor = counts[4], row->cache_bytes = counts[5], row->matrix_bytes = counts[6];
  row->error_l2 = measures[0], row->error_h1 = measures[1], row->error_energy = measures[2];
  row->reference = measures[3], row->error = measures[4], row->time = measures[5];
  study_combination(spec, p, row->choice);
  return MICA_SUCCESS;
}

/* Every rank gets every row from the leader of the group that solved it; rank 0 prints the progress lines of
 * the other groups' combinations. */
static int gather_rows(int ierr, const StudySpec *spec, StudyRow *rows, const MicaStudyGroups *g) {
  MicaPack mine = {0}, all = {0};
  for (long p = 0; p < spec->ncombinations && !ierr && g->groups.leader; p++)
    if (mica_study_groups_mine(g, p)) ierr = pack_row(spec, p, &rows[p], &mine);
  ierr = mica_pack_allgather(ierr, &mine, &all);
  while (!ierr && all.at < all.size) ierr = unpack_row(spec, rows, &all);
  mica_pack_free(&mine);
  mica_pack_free(&all);
  MICA_CALL(mica_parallel_agree(ierr));
  for (long p = 0; p < spec->ncombinations; p++)
    if (rows[p].group != g->groups.group) print_progress(spec, p, &rows[p], g->groups.ngroups, 0, 0, 0);
  return MICA_SUCCESS;
}

/* Every combination, by the groups of ranks (one group of the one rank when serial); with no success, the
 * first failure is the study's error. */
static int run_all(const StudySpec *spec, StudyRow *rows, const char *outdir, long *nfailed) {
  MicaStudyGroups g;
  long first_failure = -1;
  *nfailed = 0;
  int ierr = mica_study_groups_begin(spec->ranks_per_point, outdir, &g);
  if (!ierr) ierr = run_own(spec, rows, &g);
  ierr = mica_study_groups_end(ierr, &g);
  if (!ierr) ierr = gather_rows(ierr, spec, rows, &g);
  mica_study_groups_free(&g);
  MICA_CALL(ierr);
  for (long p = 0; p < spec->ncombinations; p++)
    if (rows[p].status) {
      ++*nfailed;
      if (first_failure < 0) first_failure = p;
    }
  for (long p = 0; p < spec->ncombinations; p++)
    if (usable(&rows[p])) return MICA_SUCCESS;
  if (first_failure < 0) /* every combination ran, none has a finite error */
    MICA_ERROR(MICA_ERR_NUMERIC, "no combination of the study has a finite %s error", spec->error_name);
  MICA_ERROR(rows[first_failure].status, "every combination of the study failed (%ld); combination %ld: %s",
             spec->ncombinations, first_failure + 1, rows[first_failure].message);
}

/* Under mpirun: how the combinations were dealt, and how many each group solved (as the groups reported). */
static int add_groups(const StudySpec *spec, const StudyRow *rows, MicaJson *summary) {
  if (mica_parallel_world_size() == 1) return MICA_SUCCESS;
  const int ngroups = mica_parallel_world_size() / spec->ranks_per_point;
  MICA_CALL(mica_json_int(summary, "ranks_per_point", spec->ranks_per_point));
  MICA_CALL(mica_json_int(summary, "groups", ngroups));
  MICA_CALL(mica_json_open_array(summary, "combinations_per_group"));
  for (int g = 0; g < ngroups; g++) {
    long n = 0;
    for (long p = 0; p < spec->ncombinations; p++) n += rows[p].group == g;
    MICA_CALL(mica_json_int(summary, NULL, n));
  }
  return mica_json_close(summary);
}

/* The charts are drawn last and are not the result: when gnuplot fails, the numbers still stand. */
static int draw_charts(const StudySpec *spec, const StudyRow *rows, long fastest, const char *outdir,
                       MicaJson *summary) {
  if (!spec->chart) return mica_json_string(summary, "chart", "off");
  if (study_write_charts(spec, rows, fastest, outdir) == MICA_SUCCESS)
    return mica_json_string(summary, "chart", "study_time.png");
  fprintf(stderr, "mica study: no chart: %s\n", mica_error_message());
  mica_error_clear();
  return mica_json_string(summary, "chart", "failed: see gnuplot.log");
}

static int study_run(const MicaDeck *deck, const char *outdir, MicaJson *summary) {
  StudySpec spec;
  StudyRow *rows = NULL;
  char *points = NULL, title[MICA_DECK_TEXT_MAX + 64]; /* "relative error of " and a probe's name */
  long nfailed = 0;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(study_spec_read(deck, &spec));
  MICA_CALL_CLEANUP(mica_path_join(outdir, "points", &points));
  printf("study: %ld combination%s of %d choice%s, %s against %s time, %d solve%s each\n", spec.ncombinations,
         spec.ncombinations > 1 ? "s" : "", spec.nchoices, spec.nchoices > 1 ? "s" : "",
         study_error_title(&spec, title, sizeof title), spec.time_total ? "total" : "solve", spec.repeat,
         spec.repeat > 1 ? "s (the minimum time is kept)" : "");
  if (mica_parallel_world_size() > 1)
    printf("study: %d group%s of %d rank%s%s\n", mica_parallel_world_size() / spec.ranks_per_point,
           mica_parallel_world_size() > spec.ranks_per_point ? "s" : "", spec.ranks_per_point,
           spec.ranks_per_point > 1 ? "s" : "",
           mica_parallel_world_size() > spec.ranks_per_point
               ? " solving at the same time: each time is measured while the other groups share the machine"
               : "");
  MICA_CALL_CLEANUP(rows_create(&spec, &rows));
  MICA_CALL_CLEANUP(run_all(&spec, rows, outdir, &nfailed));
  mark_pareto(&spec, rows);
  const long fastest = fastest_for_target(&spec, rows);
  MICA_CALL_CLEANUP(study_write_csv(&spec, rows, outdir));
  MICA_CALL_CLEANUP(add_summary(&spec, rows, nfailed, fastest, summary));
  MICA_CALL_CLEANUP(add_groups(&spec, rows, summary));
  MICA_CALL_CLEANUP(print_report(&spec, rows, nfailed, fastest));
  MICA_CALL_CLEANUP(draw_charts(&spec, rows, fastest, outdir, summary));
cleanup:
  if (ierr && points) mica_remove_tree(points);
  free(points);
  rows_destroy(spec.ncombinations, &rows);
  study_spec_free(&spec);
  return ierr;
}

const MicaCommand mica_command_study = {
    {"study",
     "speed against accuracy: solve every combination of some settings; errors, costs, Pareto front, fastest",
     0, NULL, NULL},
    "The deck is a run deck with an exact solution (or a probe with a reference value) plus a `study` group\n"
    "listing choices: settings and their values (numbers, words or a range, as in a sweep). Every combination\n"
    "is solved like `mica run` with the values as --set overrides, `repeat` times (the minimum time of each\n"
    "phase is kept), into DIR/points/<n>/. A failing combination is recorded and the study goes on. Writes\n"
    "study.csv (per combination: the values, dofs, nnz, memory, the time of every phase, the error norms and\n"
    "probes, the status and whether it is on the Pareto front of error against time), summary.json (the\n"
    "front, and the fastest combination that reaches the target error), and the charts study_time.png (error\n"
    "against time, the front drawn and labelled) and study_dofs.png (error against dofs). Under mpirun -np P\n"
    "the combinations are dealt to P / study.ranks_per_point groups of ranks (default: one rank each), which\n"
    "solve at the same time: their times are measured while the groups share the machine.",
    mica_run_schema,
    study_run,
};
