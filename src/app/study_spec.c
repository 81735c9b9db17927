/* `mica study`: reading the `study` group and checking it against the run deck before anything is solved.
 * The choices are read exactly like the sweep's parameters (sweep_axis_read): every value is tried as an
 * override of the run deck, so an unknown path, a value out of range or a word that is no choice stops the
 * study with the deck layer's message and the choice's line. Then the error measure: a norm needs an exact
 * solution, a probe needs its reference value. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"
#include "study_common.h"
#include "study.h"

const char *const study_phase_key[STUDY_NPHASES] = {"time_discretize", "time_mls_setup", "time_cache_and_pattern",
                                                     "time_assemble",   "time_factor",    "time_solve"};
const char *const study_phase_column[STUDY_NPHASES] = {"time_discretize", "time_mls", "time_cache_pattern",
                                                        "time_assemble",   "time_factor", "time_solve"};

/* The line of a setting; for a setting the deck does not give (a default), the line of the study group. */
static void where_of(const MicaDeck *deck, const char *path, char *buf) {
  mica_deck_where(deck, path, buf, SWEEP_WHERE_MAX);
  if (strstr(buf, " (default)")) mica_deck_where(deck, "study", buf, SWEEP_WHERE_MAX);
}

/* ---- the choices ------------------------------------------------------------------------------------- */

static int read_choice(StudySpec *spec, const SweepLimit *limit, int c) {
  char element[64], path[96];
  snprintf(element, sizeof element, "study.choices.[%d]", c);
  MICA_CALL(sweep_axis_read(spec->deck, element, limit, spec->choices, c));
  snprintf(path, sizeof path, "%s.name", element);
  if (mica_deck_has(spec->deck, path)) MICA_CALL(mica_deck_string(spec->deck, path, &spec->choices[c].label));
  return MICA_SUCCESS;
}

static int try_choice(StudySpec *spec, int c) {
  char element[64];
  snprintf(element, sizeof element, "study.choices.[%d]", c);
  return sweep_axis_try(spec->deck, element, &spec->choices[c]);
}

static int count_combinations(StudySpec *spec, const SweepLimit *limit) {
  char where[SWEEP_WHERE_MAX];
  where_of(spec->deck, "study.choices", where);
  MICA_CALL(sweep_limit_check(limit, spec->choices, spec->nchoices, 0, where));
  spec->ncombinations = 1;
  for (int c = 0; c < spec->nchoices; c++) spec->ncombinations *= spec->choices[c].nvalues;
  return MICA_SUCCESS;
}

void study_combination(const StudySpec *spec, long p, int *choice) {
  for (int c = spec->nchoices - 1; c >= 0; c--) {
    const int n = spec->choices[c].nvalues;
    choice[c] = (int)(p % n);
    p /= n;
  }
}

void study_choice_text(const StudySpec *spec, const int *choice, char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  for (int c = 0; c < spec->nchoices; c++) {
    char label[256];
    sweep_value_label(&spec->choices[c], choice[c], label, sizeof label);
    const int n = snprintf(buf + used, size - used, "%s%s", used ? " " : "", label);
    if (n > 0 && (size_t)n < size - used) used += (size_t)n;
  }
}

/* ---- the error measure ------------------------------------------------------------------------------- */

static int read_probes(StudySpec *spec) {
  spec->nprobes = mica_deck_list_length(spec->deck, "output.probes");
  MICA_CALL(MICA_CALLOC(spec->probes, spec->nprobes > 0 ? spec->nprobes : 1));
  for (int i = 0; i < spec->nprobes; i++) {
    char path[64];
    snprintf(path, sizeof path, "output.probes.[%d].name", i);
    MICA_CALL(mica_deck_string(spec->deck, path, &spec->probes[i]));
  }
  return MICA_SUCCESS;
}

/* Some exact.* expression: run.c then requires one for every unknown of the model. */
static int has_exact(const MicaDeck *deck) {
  static const char *const names[] = {"ux", "uy", "uz", "phix", "phiy", "phiz", "ur", "utheta", "phir", "phitheta"};
  for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
    char path[32];
    snprintf(path, sizeof path, "exact.%s", names[i]);
    if (mica_deck_has(deck, path)) return 1;
  }
  return 0;
}

static int read_measure(StudySpec *spec) {
  const MicaDeck *deck = spec->deck;
  char where[SWEEP_WHERE_MAX];
  MICA_CALL(mica_deck_string(deck, "study.error", &spec->error_name));
  where_of(deck, "study.error", where);
  const char *name = spec->error_name;
  const int norm = !strcmp(name, "l2") || !strcmp(name, "h1") || !strcmp(name, "energy");
  const int has_reference = mica_deck_has(deck, "study.reference");
  if (norm) {
    spec->measure = !strcmp(name, "l2") ? STUDY_ERROR_L2 : !strcmp(name, "h1") ? STUDY_ERROR_H1 : STUDY_ERROR_ENERGY;
    MICA_CHECK(has_exact(deck), MICA_ERR_INPUT,
               "%s: error = \"%s\" is measured against an exact solution, and this deck has none: add exact = { ux "
               "= \"...\"; uy = \"...\"; } or use a probe with its reference value (error = \"tip_uy\"; reference "
               "= ...;)", where, name);
    char rwhere[SWEEP_WHERE_MAX];
    where_of(deck, "study.reference", rwhere);
    MICA_CHECK(!has_reference, MICA_ERR_INPUT, "%s: reference is the exact value of a probe; error = \"%s\" is a norm "
               "against the exact solution and needs none", rwhere, name);
    return MICA_SUCCESS;
  }
  spec->measure = STUDY_ERROR_PROBE;
  spec->probe = -1;
  for (int i = 0; i < spec->nprobes && spec->probe < 0; i++)
    if (!strcmp(spec->probes[i], name)) spec->probe = i;
  MICA_CHECK(spec->probe >= 0, MICA_ERR_INPUT,
             "%s: error = \"%s\" is neither l2, h1, energy nor a probe of this deck (output.probes: %s%s)", where, name,
             spec->nprobes ? spec->probes[0] : "none", spec->nprobes > 1 ? ", ..." : "");
  MICA_CHECK(has_reference, MICA_ERR_INPUT,
             "%s: error = \"%s\" is a probe: give its exact (or overkill) value as reference = ... (a number or an "
             "expression of the parameters)", where, name);
  double reference;
  MICA_CALL(mica_deck_float(deck, "study.reference", &reference)); /* an expression that evaluates */
  return MICA_SUCCESS;
}

static int read_options(StudySpec *spec) {
  const MicaDeck *deck = spec->deck;
  const char *time;
  long repeat;
  MICA_CALL(mica_deck_float(deck, "study.target", &spec->target));
  MICA_CALL(mica_deck_string(deck, "study.time", &time));
  spec->time_total = !strcmp(time, "total");
  MICA_CALL(mica_deck_int(deck, "study.repeat", &repeat));
  MICA_CALL(mica_study_ranks_per_point(deck, "study.ranks_per_point", &spec->ranks_per_point));
  spec->repeat = (int)repeat;
  MICA_CALL(mica_deck_bool(deck, "study.chart", &spec->chart));
  return MICA_SUCCESS;
}

const char *study_error_title(const StudySpec *spec, char *buf, size_t size) {
  switch (spec->measure) {
  case STUDY_ERROR_L2: snprintf(buf, size, "relative L2 error"); break;
  case STUDY_ERROR_H1: snprintf(buf, size, "relative H1-seminorm error"); break;
  case STUDY_ERROR_ENERGY: snprintf(buf, size, "relative energy error"); break;
  default: snprintf(buf, size, "relative error of %s", spec->error_name); break;
  }
  return buf;
}

const char *study_time_title(const StudySpec *spec) {
  return spec->time_total ? "total time (every phase), s" : "solve time (assembly + factorization + solution), s";
}

/* ---- the whole group --------------------------------------------------------------------------------- */

int study_spec_read(const MicaDeck *deck, StudySpec *spec) {
  memset(spec, 0, sizeof *spec);
  spec->deck = deck;
  spec->nchoices = mica_deck_list_length(deck, "study.choices");
  char where[SWEEP_WHERE_MAX];
  snprintf(where, sizeof where, "%s", mica_deck_path(deck));
  MICA_CHECK(spec->nchoices > 0, MICA_ERR_INPUT,
             "%s: nothing to study: add study = { choices = ( { path = \"mls.order\"; values = [1, 2]; }, { path = "
             "\"parameters.n\"; values = [9, 17, 33]; } ); error = \"energy\"; target = 1e-3; }", where);
  MICA_CALL(MICA_CALLOC(spec->choices, spec->nchoices));
  MICA_CALL(read_probes(spec));
  SweepLimit limit = {"limits.study_combinations", "combinations", 0};
  MICA_CALL(sweep_limit_read(deck, &limit));
  for (int c = 0; c < spec->nchoices; c++) MICA_CALL(read_choice(spec, &limit, c));
  MICA_CALL(count_combinations(spec, &limit));
  for (int c = 0; c < spec->nchoices; c++) MICA_CALL(try_choice(spec, c)); /* after the count: 10^5 values are slow */
  MICA_CALL(read_measure(spec));
  MICA_CALL(read_options(spec));
  return MICA_SUCCESS;
}

void study_spec_free(StudySpec *spec) {
  for (int c = 0; c < spec->nchoices && spec->choices; c++) sweep_axis_free(&spec->choices[c]);
  free(spec->choices);
  free(spec->probes);
  memset(spec, 0, sizeof *spec);
}

/* ---- costs of a row ---------------------------------------------------------------------------------- */

double study_solve_time(const StudyRow *row) {
  return row->phase[STUDY_ASSEMBLE] + row->phase[STUDY_FACTOR] + row->phase[STUDY_SOLVE];
}

double study_total_time(const StudyRow *row) {
  double t = 0;
  for (int k = 0; k < STUDY_NPHASES; k++) t += row->phase[k];
  return t;
}

long study_memory_bytes(const StudyRow *row) { return row->cache_bytes + row->matrix_bytes + 8 * row->nnz_factor; }
