/* Internal interface of `mica sweep` (src/app/sweep*.c): a run deck solved at every point of a grid (or
 * a zip) of values of some of its settings, each point a `mica run` of the deck loaded again with the
 * point's values as overrides. The deck is the run deck (run_schema.c holds the sweep keys); sweep_spec.c: reading and checking the `sweep`
 * group; sweep.c: the points, the comparison of models, the summary; sweep_output.c: sweep.csv and the
 * chart. */
#ifndef MICA_SWEEP_H
#define MICA_SWEEP_H

#include <stdio.h>

#include "mica/command.h"
#include "mica/deck.h"
#include "mica/json.h"
#include "run.h"

enum { SWEEP_WHERE_MAX = 256 };
/* "path=\"word\"": a setting path and a word of a words list, each within its deck cap (deck.h) */
enum { SWEEP_OVERRIDE_MAX = MICA_DECK_TEXT_MAX + MICA_DECK_LONG_TEXT_MAX + 8 };
/* The default of limits.sweep_points and limits.study_combinations (run_schema.c): the most points of a
 * sweep's grid and combinations of a study, each a full solve. Either can be raised in the deck. */
#define SWEEP_LIMIT_DEFAULT "100000"
enum { SWEEP_LIMIT_MOST = 1000000000 }; /* the largest either may be raised to: an axis counts its values in int */

/* The cap on the runs of a sweep or a study, read from its limits.* setting. */
typedef struct SweepLimit {
  const char *setting; /* "limits.sweep_points" */
  const char *runs;    /* "points", "combinations" */
  long most;
} SweepLimit;

/* The run schema's keys followed by the sweep group's (filled at program start). */

/* One swept setting: its path and its values, numbers or words (for string settings: material.model). */
typedef struct SweepAxis {
  char *path;        /* "parameters.L" */
  const char *label; /* its short name: "L" for a parameter, else the path */
  int nvalues;
  double *values;    /* numbers, or NULL */
  char **words;      /* words, or NULL */
  int boolean;       /* the setting is true/false: its words are written unquoted */
  char where[SWEEP_WHERE_MAX]; /* "deck.cfg:12", the line of the axis's path */
} SweepAxis;

/* Measured points from a CSV file, for the chart. */
typedef struct SweepData {
  const char *name; /* legend (borrowed from the deck) */
  int n;
  double *x, *y;
} SweepData;

/* The `sweep` group, read and checked against the deck. */
typedef struct SweepSpec {
  const MicaDeck *deck;
  int naxes;
  SweepAxis *axes;
  int zip;           /* 1: point i takes the i-th value of every axis; 0: every combination */
  long npoints;
  int nprobes;
  const char **probes; /* the deck's probe names (borrowed) */
  int probe;         /* the charted probe, an index into probes */
  int x;             /* the axis on the chart's x (numeric), or -1 when no axis is numeric */
  int model_axis;    /* the material.model axis (words), or -1 */
  const char *classical; /* the model the others are compared with ("linear") */
  double tolerance;
  int threshold_steps;     /* bisection steps after the grid (sweep_threshold.c); 0: the sampled bracket only */
  double threshold_rtol;   /* ... until (hi − lo) / hi ≤ this */
  int logx, logy, chart;
  int nanalytic, nexperiments;
  SweepData *experiments; /* [nexperiments], read before anything is solved */
  int ranks_per_point; /* sweep.ranks_per_point: under mpirun, the ranks of the group that solves a point */
} SweepSpec;

/* The outcome of one point. */
typedef struct SweepPoint {
  int *choice;      /* per axis, the index of the point's value */
  double *probe;    /* per probe (NAN when the point failed) */
  double time;      /* seconds, loading and solving */
  int status;       /* MICA_SUCCESS, or the error code of the failure */
  char *message;    /* the failure's message, or NULL */
  int reached;      /* 1: the point failed but wrote what it reached (a Newton run that stopped: "failed") */
  double setup;     /* seconds building discretization, MLS, shape caches and pattern (NAN if it failed) */
  double caches_built; /* shape-function caches the point computed (0: it shared the previous point's) */
  int group;        /* the group of ranks that solved it (0 when serial) */
} SweepPoint;

int sweep_spec_read(const MicaDeck *deck, SweepSpec *spec);
/* One element of a list of varied settings ("sweep.parameters.[2]", "study.choices.[0]"): reads its path
 * and its values (values, words or range + points + scale; at most limit->most of them) into axes[a], checks
 * the path (a single-valued setting of the run deck or a parameter, not a setting of the element's own group,
 * not one of axes[0..a-1]). */
int sweep_axis_read(const MicaDeck *deck, const char *element, const SweepLimit *limit, SweepAxis *axes, int a);
/* Tries every value of the axis as an override of deck, so that a value the run deck refuses is an input
 * error with the element's line (a deck load per value: done once the grid is known to fit its limit). */
int sweep_axis_try(const MicaDeck *deck, const char *element, const SweepAxis *axis);
/* Reads limit->most from limit->setting (limit->setting and limit->runs given). */
int sweep_limit_read(const MicaDeck *deck, SweepLimit *limit);
/* The grid of the n axes (product of their numbers of values; zip: the first axis's) against the limit: an
 * input error at where, naming the count and the setting, when it has more runs. */
int sweep_limit_check(const SweepLimit *limit, const SweepAxis *axes, int n, int zip, const char *where);
void sweep_axis_free(SweepAxis *axis);
void sweep_spec_free(SweepSpec *spec);
/* The axis choices of point p (0-based) in choice[naxes]. */
void sweep_point_choice(const SweepSpec *spec, long p, int *choice);
/* "path=value" for axis a at value index v (a number as %.17g, a word quoted). */
void sweep_override_text(const SweepAxis *axis, int v, char *buf, size_t size);
/* The overrides of one point of a sweep or one combination of a study: per axis its "path=value"
 * (sweep_override_text), and the list of them as sweep_deck_load takes it. */
typedef struct SweepOverrides {
  int n;
  char (*text)[SWEEP_OVERRIDE_MAX]; /* [n]: "parameters.L=8" */
  const char **list;                /* [n]: text[a] */
} SweepOverrides;

/* The overrides of the choice[naxes] of the axes (value indices). */
int sweep_overrides_create(const SweepAxis *axes, int naxes, const int *choice, SweepOverrides *o);
void sweep_overrides_destroy(SweepOverrides *o);
/* The head of the summary of a point of a sweep or a combination of a study: "status": "ok", the command,
 * the deck, index_key ("sweep_point", "study_combination") = p + 1, and the "overrides" array. */
int sweep_summary_header(MicaJson *json, const MicaDeck *deck, const char *index_key, long p,
                         const SweepOverrides *o);
/* "L=8" (a number as %g, a word as is), for progress lines and legends. */
void sweep_value_label(const SweepAxis *axis, int v, char *buf, size_t size);
/* Loads the deck again: forced (may be NULL) first, then the user's --set, then extra[nextra]. */
int sweep_deck_load(const MicaDeck *base, int nforced, const char *const *forced, int nextra,
                    const char *const *extra, MicaDeck **deck);
/* The same for the sweep's deck. */
int sweep_load(const SweepSpec *spec, int nforced, const char *const *forced, int nextra,
               const char *const *extra, MicaDeck **deck);

/* The CSV tables of sweep.csv and study.csv (sweep_output.c): a field in double quotes, inner quotes doubled,
 * line breaks flattened; the columns "index,PATH,..." of the varied settings; a row's "N,VALUE,..." (p + 1, and
 * per axis its value: a number as %.17g, a word quoted). */
void sweep_csv_quoted(FILE *fp, const char *text);
void sweep_csv_header(FILE *fp, const SweepAxis *axes, int naxes);
void sweep_csv_choices(FILE *fp, const SweepAxis *axes, int naxes, long p, const int *choice);

/* Reads sweep.experiments' files (relative to the deck's directory): x,y rows; other lines are skipped. */
int sweep_read_experiments(SweepSpec *spec);
int sweep_write_csv(const SweepSpec *spec, const SweepPoint *points, const char *outdir);
/* Draws sweep.png and sweep.svg with gnuplot (data and script kept in outdir for re-plotting). */
/* threshold: per word of the model axis, the threshold drawn as a vertical line (NAN: none), or NULL. */
int sweep_write_chart(const SweepSpec *spec, const SweepPoint *points, const double *threshold, const char *outdir);

/* Where a model agrees with the classical one (sweep_threshold.c): the bracket [lo, hi] of the size x at which
 * |probe / probe_classical − 1| ≤ tolerance starts to hold — lo the largest x known to disagree, hi the smallest
 * known to agree (at every larger sampled x) — narrowed by bisection between grid points. */
typedef struct SweepThreshold {
  int state;     /* 1: agrees from hi on; 0: never (not at the largest x); −1: no data */
  double lo, hi; /* lo = −∞ (NAN) when it agrees already at the smallest sampled x */
  double x;      /* the estimate: the bracket's midpoint (geometric on a log axis), or hi when lo is unknown */
  int steps;     /* bisection steps taken */
  int solves;    /* runs they needed (the model and the classical one at each step, per other combination) */
  int failed;    /* 1: a bisection run failed; the bracket is the one reached before it */
} SweepThreshold;

/* The point whose values equal p's on every axis but the model's, which is `classical`; −1 if none. */
long sweep_partner(const SweepSpec *spec, const SweepPoint *pts, long p, int classical);
/* Loads and solves the point with overrides o into dir (its run.log and summary in json); the error code is
 * the point's (a failure of the run, not of the sweep). */
int sweep_point_solve(const SweepSpec *spec, const char *dir, const SweepOverrides *o, MicaJson *json,
                      RunReuse *reuse);
/* The threshold of model w against `classical` from the sampled points: bracket, then (spec->threshold_steps)
 * bisection, each step solving model w and the classical model at the midpoint for every combination of the
 * other axes, into outdir/thresholds/<model>/<step>_<n>/. */
int sweep_threshold(const SweepSpec *spec, const SweepPoint *pts, const char *outdir, int w, int classical,
                    SweepThreshold *t);

#endif
