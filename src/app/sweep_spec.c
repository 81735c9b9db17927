/* `mica sweep`: reading the `sweep` group and checking it against the run deck before anything is solved
 * (docs/input.md: a deck is checked completely first). Every swept value is tried once by loading the deck
 * with it as an override, so a value the run deck would refuse (an unknown path, a value out of range, a
 * word that is no choice) stops the sweep with the deck layer's own message, prefixed with the sweep
 * entry's line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"
#include "study_common.h"
#include "sweep.h"

/* ---- small helpers ---------------------------------------------------------------------------------- */

static void where_of(const MicaDeck *deck, const char *path, char *buf) {
  mica_deck_where(deck, path, buf, SWEEP_WHERE_MAX);
}

static int copy_text(const char *text, size_t length, char **copy) {
  MICA_CALL(MICA_MALLOC(*copy, length + 1));
  memcpy(*copy, text, length);
  (*copy)[length] = '\0';
  return MICA_SUCCESS;
}

/* The deck's key for a setting path ("output.probes.[0].scale" -> "output.probes.[].scale"). */
static const MicaDeckKey *run_key(const MicaDeck *deck, const char *path) {
  char schema_path[512];
  size_t used = 0;
  for (const char *c = path; *c && used + 1 < sizeof schema_path; c++) {
    schema_path[used++] = *c;
    if (*c == '[')
      while (c[1] >= '0' && c[1] <= '9') c++;
  }
  schema_path[used] = '\0';
  return mica_schema_find(mica_deck_schema(deck), schema_path);
}

static int is_parameter(const char *path) { return !strncmp(path, "parameters.", 11) && path[11]; }

void sweep_override_text(const SweepAxis *axis, int v, char *buf, size_t size) {
  if (axis->values) {
    snprintf(buf, size, "%s=%.17g", axis->path, axis->values[v]);
    return;
  }
  /* true/false unquoted: libconfig's booleans */
  snprintf(buf, size, axis->boolean ? "%s=%s" : "%s=\"%s\"", axis->path, axis->words[v]);
}

int sweep_overrides_create(const SweepAxis *axes, int naxes, const int *choice, SweepOverrides *o) {
  int ierr = MICA_SUCCESS;
  *o = (SweepOverrides){0};
  MICA_CALL_CLEANUP(MICA_CALLOC(o->text, naxes));
  MICA_CALL_CLEANUP(MICA_CALLOC(o->list, naxes));
  o->n = naxes;
  for (int a = 0; a < naxes; a++) {
    sweep_override_text(&axes[a], choice[a], o->text[a], sizeof o->text[a]);
    o->list[a] = o->text[a];
  }
  return MICA_SUCCESS;
cleanup:
  sweep_overrides_destroy(o);
  return ierr;
}

void sweep_overrides_destroy(SweepOverrides *o) {
  free(o->text);
  free(o->list);
  *o = (SweepOverrides){0};
}

int sweep_summary_header(MicaJson *json, const MicaDeck *deck, const char *index_key, long p,
                         const SweepOverrides *o) {
  MICA_CALL(mica_json_string(json, "status", "ok"));
  MICA_CALL(mica_json_string(json, "command", "run"));
  MICA_CALL(mica_json_string(json, "deck", mica_deck_path(deck)));
  MICA_CALL(mica_json_int(json, index_key, p + 1));
  MICA_CALL(mica_json_open_array(json, "overrides"));
  for (int a = 0; a < o->n; a++) MICA_CALL(mica_json_string(json, NULL, o->list[a]));
  return mica_json_close(json);
}

void sweep_value_label(const SweepAxis *axis, int v, char *buf, size_t size) {
  if (axis->values) snprintf(buf, size, "%s=%g", axis->label, axis->values[v]);
  else snprintf(buf, size, "%s=%s", axis->label, axis->words[v]);
}

int sweep_deck_load(const MicaDeck *base, int nforced, const char *const *forced, int nextra,
                    const char *const *extra, MicaDeck **deck) {
  const int nuser = mica_deck_override_count(base), n = nuser + nforced + nextra;
  const char **all = NULL;
  MICA_CALL(MICA_MALLOC(all, n > 0 ? n : 1));
  /* the forced ones come first, so that the user's --set output.vtu=true still wins */
  for (int i = 0; i < nforced; i++) all[i] = forced[i];
  for (int i = 0; i < nuser; i++) all[nforced + i] = mica_deck_override_text(base, i);
  for (int i = 0; i < nextra; i++) all[nforced + nuser + i] = extra[i];
  const int ierr = mica_deck_load(mica_deck_path(base), mica_run_schema, n, all, deck);
  free(all);
  return ierr;
}

int sweep_load(const SweepSpec *spec, int nforced, const char *const *forced, int nextra, const char *const *extra,
               MicaDeck **deck) {
  return sweep_deck_load(spec->deck, nforced, forced, nextra, extra, deck);
}

/* ---- one axis --------------------------------------------------------------------------------------- */

/* Which paths can be swept: scalar settings of the run deck and the deck's own parameters, but not the
 * settings of the group that lists the values (group: "sweep", "study"). */
static int check_path(const MicaDeck *deck, const char *group, const SweepAxis *axis, int numeric) {
  const char *path = axis->path, *where = axis->where;
  const size_t glen = strlen(group);
  MICA_CHECK(strncmp(path, group, glen) || (path[glen] != '.' && path[glen] != '\0'), MICA_ERR_INPUT,
             "%s: path = \"%s\": a %s cannot vary its own settings", where, path, group);
  if (is_parameter(path)) {
    MICA_CHECK(mica_deck_has(deck, path), MICA_ERR_INPUT,
               "%s: path = \"%s\": the deck has no parameter '%s' (define it in `parameters`)", where, path, path + 11);
    MICA_CHECK(numeric, MICA_ERR_INPUT, "%s: %s is a parameter: give its values as numbers (values = [...])", where,
               path);
    return MICA_SUCCESS;
  }
  const MicaDeckKey *key = run_key(deck, path);
  if (!key) return MICA_SUCCESS; /* the trial load names it, with a "did you mean" */
  const MicaKeyType t = key->type;
  const int number = t == MICA_KEY_INT || t == MICA_KEY_FLOAT ||
                     ((t == MICA_KEY_INTS || t == MICA_KEY_FLOATS) && key->len_min <= 1);
  const int word = t == MICA_KEY_STRING || t == MICA_KEY_CHOICE || t == MICA_KEY_BOOL;
  MICA_CHECK(number || word || t == MICA_KEY_FUNCTION, MICA_ERR_INPUT,
             "%s: path = \"%s\": only single values can be swept (this setting is a group, list or array)", where,
             path);
  char example[256];
  snprintf(example, sizeof example, "%s", key->choices ? key->choices : t == MICA_KEY_BOOL ? "true, false" : "a, b");
  for (char *bar = strchr(example, '|'); bar; bar = strchr(bar, '|')) *bar = ','; /* choices "a|b" -> "a,b" */
  MICA_CHECK(!(numeric && word), MICA_ERR_INPUT, "%s: %s is a %s setting: give its values as words (words = \"%s\")",
             where, path, t == MICA_KEY_BOOL ? "true/false" : "string", example);
  MICA_CHECK(!(!numeric && number), MICA_ERR_INPUT, "%s: %s is numeric: give its values as numbers (values = [...])",
             where, path);
  return MICA_SUCCESS;
}

/* "linear, svk" -> {"linear", "svk"}: comma-separated, spaces around each word dropped. */
static int split_words(const char *text, const char *where, SweepAxis *axis) {
  int n = 1;
  for (const char *c = text; *c; c++) n += *c == ',';
  MICA_CALL(MICA_CALLOC(axis->words, n));
  axis->nvalues = n;
  for (int i = 0; i < n; i++) {
    text += strspn(text, " \t");
    size_t length = strcspn(text, ",");
    size_t trimmed = length;
    while (trimmed > 0 && (text[trimmed - 1] == ' ' || text[trimmed - 1] == '\t')) trimmed--;
    MICA_CALL(copy_text(text, trimmed, &axis->words[i]));
    MICA_CHECK(trimmed > 0, MICA_ERR_INPUT, "%s: words: value %d of %s is empty (words are separated by commas)",
               where, i + 1, axis->path);
    text += length + (text[length] == ',');
  }
  return MICA_SUCCESS;
}

/* One axis alone must fit the limit (every other axis has at least one value): checked before its values are
 * made, so that points = 10^9 allocates nothing. */
static int check_axis_count(const SweepLimit *limit, double count, const char *where, const char *path) {
  MICA_CHECK(count <= (double)limit->most, MICA_ERR_INPUT,
             "%s: %s has %.0f values, more %s than %s = %ld; use fewer values or raise %s", where, path, count,
             limit->runs, limit->setting, limit->most, limit->setting);
  return MICA_SUCCESS;
}

static int read_range(const MicaDeck *deck, const char *element, const SweepLimit *limit, const char *where,
                      SweepAxis *axis) {
  char path[128];
  double ends[2];
  long points;
  const char *scale;
  int n;
  snprintf(path, sizeof path, "%s.range", element);
  MICA_CALL(mica_deck_floats(deck, path, ends, 2, &n));
  snprintf(path, sizeof path, "%s.points", element);
  MICA_CHECK(mica_deck_has(deck, path), MICA_ERR_INPUT, "%s: a range needs points (how many values)", where);
  MICA_CALL(mica_deck_int(deck, path, &points));
  MICA_CALL(check_axis_count(limit, (double)points, where, path));
  snprintf(path, sizeof path, "%s.scale", element);
  MICA_CALL(mica_deck_string(deck, path, &scale));
  const int logscale = !strcmp(scale, "log");
  MICA_CHECK(!logscale || (ends[0] > 0 && ends[1] > 0), MICA_ERR_INPUT,
             "%s: a log range needs positive ends, not [%g, %g]", where, ends[0], ends[1]);
  MICA_CALL(MICA_MALLOC(axis->values, points));
  axis->nvalues = (int)points;
  for (long i = 0; i < points; i++) {
    const double s = (double)i / (double)(points - 1);
    char rounded[32]; /* 15 digits: 4 * 8^(2/3) is 16, not 15.999999999999998 (an integer count may follow) */
    snprintf(rounded, sizeof rounded, "%.15g",
             logscale ? ends[0] * pow(ends[1] / ends[0], s) : ends[0] + (ends[1] - ends[0]) * s);
    axis->values[i] = strtod(rounded, NULL);
  }
  return MICA_SUCCESS;
}

/* values, words or range: exactly one. */
static int read_values(const MicaDeck *deck, const char *element, const SweepLimit *limit, SweepAxis *axis) {
  char values[128], words[128], range[128];
  snprintf(values, sizeof values, "%s.values", element);
  snprintf(words, sizeof words, "%s.words", element);
  snprintf(range, sizeof range, "%s.range", element);
  const int given = mica_deck_has(deck, values) + mica_deck_has(deck, words) + mica_deck_has(deck, range);
  MICA_CHECK(given == 1, MICA_ERR_INPUT, "%s: %s: give %s of values = [...], words = \"a, b\" or range = "
             "[first, last] with points", axis->where, axis->path, given ? "only one" : "one");
  if (mica_deck_has(deck, words)) {
    const char *text;
    MICA_CALL(mica_deck_string(deck, words, &text));
    MICA_CALL(split_words(text, axis->where, axis));
  } else if (mica_deck_has(deck, range)) {
    MICA_CALL(read_range(deck, element, limit, axis->where, axis));
  } else {
    const int n = mica_deck_list_length(deck, values);
    MICA_CALL(MICA_MALLOC(axis->values, n > 0 ? n : 1));
    MICA_CALL(mica_deck_floats(deck, values, axis->values, n > 0 ? n : 1, &axis->nvalues));
  }
  return check_axis_count(limit, axis->nvalues, axis->where, axis->path);
}

/* Every value of the axis, tried as an override of the run deck: errors are the deck layer's, prefixed
 * with the list element. */
static int try_values(const MicaDeck *deck, const char *element, const SweepAxis *axis) {
  for (int v = 0; v < axis->nvalues; v++) {
    char text[SWEEP_OVERRIDE_MAX];
    const char *extra[1] = {text};
    MicaDeck *trial = NULL;
    sweep_override_text(axis, v, text, sizeof text);
    const int ierr = sweep_deck_load(deck, 0, NULL, 1, extra, &trial);
    mica_deck_destroy(&trial);
    if (ierr) {
      mica_error_prefix("%s: %s", axis->where, element);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
  }
  return MICA_SUCCESS;
}

int sweep_axis_read(const MicaDeck *deck, const char *element, const SweepLimit *limit, SweepAxis *axes, int a) {
  SweepAxis *axis = &axes[a];
  char path[160], group[32];
  const char *text;
  snprintf(group, sizeof group, "%.*s", (int)strcspn(element, "."), element);
  snprintf(path, sizeof path, "%s.path", element);
  where_of(deck, mica_deck_has(deck, path) ? path : element, axis->where);
  MICA_CHECK(mica_deck_has(deck, path), MICA_ERR_INPUT, "%s: %s needs a path (the setting varied)", axis->where,
             element);
  MICA_CALL(mica_deck_string(deck, path, &text));
  MICA_CALL(copy_text(text, strlen(text), &axis->path));
  axis->label = is_parameter(axis->path) ? axis->path + 11 : axis->path;
  const MicaDeckKey *key = run_key(deck, axis->path);
  axis->boolean = key && key->type == MICA_KEY_BOOL;
  for (int b = 0; b < a; b++)
    MICA_CHECK(strcmp(axes[b].path, axis->path), MICA_ERR_INPUT, "%s: %s is varied twice (also by %s)",
               axis->where, axis->path, axes[b].where);
  MICA_CALL(read_values(deck, element, limit, axis));
  MICA_CALL(check_path(deck, group, axis, axis->values != NULL));
  return MICA_SUCCESS;
}

int sweep_axis_try(const MicaDeck *deck, const char *element, const SweepAxis *axis) {
  return try_values(deck, element, axis);
}

int sweep_limit_read(const MicaDeck *deck, SweepLimit *limit) {
  return mica_deck_int(deck, limit->setting, &limit->most);
}

int sweep_limit_check(const SweepLimit *limit, const SweepAxis *axes, int n, int zip, const char *where) {
  double runs = n > 0 && zip ? axes[0].nvalues : 1; /* in double: 10^5 values on each of 3 axes is no overflow */
  char factors[256] = "";
  size_t used = 0;
  for (int a = 0; a < n && !zip; a++) {
    runs *= axes[a].nvalues;
    const int w = snprintf(factors + used, sizeof factors - used, "%s%d", a ? " x " : "", axes[a].nvalues);
    if (w > 0 && (size_t)w < sizeof factors - used) used += (size_t)w;
  }
  if (zip) snprintf(factors, sizeof factors, "zip of %d values", n > 0 ? axes[0].nvalues : 0);
  MICA_CHECK(runs <= (double)limit->most, MICA_ERR_INPUT,
             "%s: %.0f %s (%s), more than %s = %ld; use fewer values or raise %s", where, runs, limit->runs, factors,
             limit->setting, limit->most, limit->setting);
  return MICA_SUCCESS;
}

void sweep_axis_free(SweepAxis *axis) {
  free(axis->path);
  free(axis->values);
  for (int v = 0; axis->words && v < axis->nvalues; v++) free(axis->words[v]);
  free(axis->words);
  memset(axis, 0, sizeof *axis);
}

static int read_axis(SweepSpec *spec, const SweepLimit *limit, int a) {
  char element[64];
  snprintf(element, sizeof element, "sweep.parameters.[%d]", a);
  return sweep_axis_read(spec->deck, element, limit, spec->axes, a);
}

static int try_axis(SweepSpec *spec, int a) {
  char element[64];
  snprintf(element, sizeof element, "sweep.parameters.[%d]", a);
  return sweep_axis_try(spec->deck, element, &spec->axes[a]);
}

/* ---- the points, the probe, the chart's x ----------------------------------------------------------- */

static int count_points(SweepSpec *spec, const SweepLimit *limit) {
  const char *mode;
  char where[SWEEP_WHERE_MAX];
  MICA_CALL(mica_deck_string(spec->deck, "sweep.mode", &mode));
  where_of(spec->deck, "sweep.mode", where);
  spec->zip = !strcmp(mode, "zip");
  spec->npoints = spec->zip ? spec->axes[0].nvalues : 1;
  for (int a = 0; a < spec->naxes; a++) {
    const SweepAxis *axis = &spec->axes[a];
    if (spec->zip) {
      MICA_CHECK(axis->nvalues == spec->npoints, MICA_ERR_INPUT,
                 "%s: mode = \"zip\" takes the i-th values together, but %s has %d value%s and %s %ld; give them "
                 "equal numbers of values, or use mode = \"grid\"", where, axis->path, axis->nvalues,
                 axis->nvalues == 1 ? "" : "s", spec->axes[0].path, spec->npoints);
    }
  }
  char grid[SWEEP_WHERE_MAX];
  where_of(spec->deck, "sweep.parameters", grid);
  MICA_CALL(sweep_limit_check(limit, spec->axes, spec->naxes, spec->zip, grid));
  for (int a = 0; a < spec->naxes && !spec->zip; a++) spec->npoints *= spec->axes[a].nvalues;
  return MICA_SUCCESS;
}

void sweep_point_choice(const SweepSpec *spec, long p, int *choice) {
  for (int a = spec->naxes - 1; a >= 0; a--) { /* grid: the last axis varies fastest */
    const int n = spec->axes[a].nvalues;
    choice[a] = spec->zip ? (int)p : (int)(p % n);
    if (!spec->zip) p /= n;
  }
}

static int read_probes(SweepSpec *spec) {
  const MicaDeck *deck = spec->deck;
  const char *wanted;
  char where[SWEEP_WHERE_MAX];
  spec->nprobes = mica_deck_list_length(deck, "output.probes");
  MICA_CALL(MICA_CALLOC(spec->probes, spec->nprobes > 0 ? spec->nprobes : 1));
  for (int i = 0; i < spec->nprobes; i++) {
    char path[64];
    snprintf(path, sizeof path, "output.probes.[%d].name", i);
    MICA_CALL(mica_deck_string(deck, path, &spec->probes[i]));
  }
  MICA_CALL(mica_deck_string(deck, "sweep.probe", &wanted));
  where_of(deck, wanted[0] ? "sweep.probe" : "output.probes", where);
  MICA_CHECK(spec->nprobes > 0, MICA_ERR_INPUT,
             "%s: a sweep reports probes, and this deck has none: add output.probes = ( { name = \"tip_uy\"; "
             "point = [...]; field = \"uy\"; } )", where);
  spec->probe = wanted[0] ? -1 : 0;
  for (int i = 0; i < spec->nprobes && spec->probe < 0; i++)
    if (!strcmp(spec->probes[i], wanted)) spec->probe = i;
  MICA_CHECK(spec->probe >= 0, MICA_ERR_INPUT, "%s: probe = \"%s\" is not a probe of this deck (output.probes: %s%s)",
             where, wanted, spec->probes[0], spec->nprobes > 1 ? ", ..." : "");
  return MICA_SUCCESS;
}

static int read_x(SweepSpec *spec) {
  const char *wanted;
  char where[SWEEP_WHERE_MAX];
  MICA_CALL(mica_deck_string(spec->deck, "sweep.x", &wanted));
  where_of(spec->deck, "sweep.x", where);
  spec->x = -1;
  for (int a = 0; a < spec->naxes && spec->x < 0; a++)
    if (wanted[0] ? !strcmp(spec->axes[a].path, wanted) : spec->axes[a].values != NULL) spec->x = a;
  MICA_CHECK(spec->x >= 0 || !wanted[0], MICA_ERR_INPUT, "%s: x = \"%s\" is not a swept path", where, wanted);
  MICA_CHECK(spec->x < 0 || spec->axes[spec->x].values, MICA_ERR_INPUT,
             "%s: x = \"%s\" has words for values; the chart's x axis needs a numeric one", where, wanted);
  return MICA_SUCCESS;
}

/* sweep.threshold_* act only where models are compared along a numeric x: elsewhere they are an error. */
static int check_threshold_settings(const SweepSpec *spec) {
  static const char *const keys[] = {"sweep.threshold_steps", "sweep.threshold_rtol"};
  const int compared = spec->model_axis >= 0 && spec->x >= 0;
  for (int i = 0; i < 2; i++) {
    if (compared || !mica_deck_given(spec->deck, keys[i])) continue;
    char where[SWEEP_WHERE_MAX];
    where_of(spec->deck, keys[i], where);
    MICA_ERROR(MICA_ERR_INPUT,
               "%s: %s narrows the size at which a model agrees with sweep.classical, and this sweep compares no "
               "models along a numeric x (sweep material.model's words and a numeric path): remove it",
               where, keys[i]);
  }
  return MICA_SUCCESS;
}

static int read_options(SweepSpec *spec) {
  const MicaDeck *deck = spec->deck;
  MICA_CALL(mica_deck_bool(deck, "sweep.logx", &spec->logx));
  MICA_CALL(mica_deck_bool(deck, "sweep.logy", &spec->logy));
  MICA_CALL(mica_deck_bool(deck, "sweep.chart", &spec->chart));
  MICA_CALL(mica_deck_float(deck, "sweep.tolerance", &spec->tolerance));
  MICA_CALL(mica_study_ranks_per_point(deck, "sweep.ranks_per_point", &spec->ranks_per_point));
  MICA_CALL(mica_deck_string(deck, "sweep.classical", &spec->classical));
  long steps;
  MICA_CALL(mica_deck_int(deck, "sweep.threshold_steps", &steps));
  MICA_CALL(mica_deck_float(deck, "sweep.threshold_rtol", &spec->threshold_rtol));
  spec->threshold_steps = (int)steps;
  spec->model_axis = -1;
  for (int a = 0; a < spec->naxes; a++)
    if (!strcmp(spec->axes[a].path, "material.model") && spec->axes[a].words) spec->model_axis = a;
  MICA_CALL(check_threshold_settings(spec));
  spec->nanalytic = mica_deck_list_length(deck, "sweep.analytic");
  spec->nexperiments = mica_deck_list_length(deck, "sweep.experiments");
  char where[SWEEP_WHERE_MAX];
  where_of(deck, "sweep.logx", where);
  for (int v = 0; spec->logx && spec->x >= 0 && v < spec->axes[spec->x].nvalues; v++)
    MICA_CHECK(spec->axes[spec->x].values[v] > 0, MICA_ERR_INPUT, "%s: logx needs positive values of %s, not %g",
               where, spec->axes[spec->x].path, spec->axes[spec->x].values[v]);
  return MICA_SUCCESS;
}

/* ---- the whole group -------------------------------------------------------------------------------- */

int sweep_spec_read(const MicaDeck *deck, SweepSpec *spec) {
  memset(spec, 0, sizeof *spec);
  spec->deck = deck;
  spec->naxes = mica_deck_list_length(deck, "sweep.parameters");
  char where[SWEEP_WHERE_MAX];
  snprintf(where, sizeof where, "%s", mica_deck_path(deck)); /* the defaults made a `sweep` group: no line */
  MICA_CHECK(spec->naxes > 0, MICA_ERR_INPUT,
             "%s: nothing to sweep: add sweep = { parameters = ( { path = \"parameters.L\"; values = [4.0, 8.0]; } ); }",
             where);
  MICA_CALL(MICA_CALLOC(spec->axes, spec->naxes));
  MICA_CALL(read_probes(spec));
  SweepLimit limit = {"limits.sweep_points", "points", 0};
  MICA_CALL(sweep_limit_read(deck, &limit));
  for (int a = 0; a < spec->naxes; a++) MICA_CALL(read_axis(spec, &limit, a));
  MICA_CALL(count_points(spec, &limit));
  for (int a = 0; a < spec->naxes; a++) MICA_CALL(try_axis(spec, a)); /* after the count: 10^5 values are slow */
  MICA_CALL(read_x(spec));
  MICA_CALL(read_options(spec));
  MICA_CALL(sweep_read_experiments(spec));
  return MICA_SUCCESS;
}

void sweep_spec_free(SweepSpec *spec) {
  for (int a = 0; a < spec->naxes && spec->axes; a++) sweep_axis_free(&spec->axes[a]);
  free(spec->axes);
  free(spec->probes);
  for (int e = 0; e < spec->nexperiments && spec->experiments; e++) {
    free(spec->experiments[e].x);
    free(spec->experiments[e].y);
  }
  free(spec->experiments);
  memset(spec, 0, sizeof *spec);
}
