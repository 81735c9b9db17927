/* Internal interface of `mica study` (src/app/study*.c): speed against accuracy. A run deck with an exact
 * solution (or a probe with a reference value) is solved for every combination of the values of some of
 * its settings (the `study.choices`, read with the sweep's value lists: src/app/sweep_spec.c); each
 * combination's error and costs are measured, the Pareto front of error against time is marked, and the
 * fastest combination that reaches the target error is named. study_spec.c: reading and checking the
 * `study` group; study.c: the combinations, the front, the summary; study_output.c: study.csv and charts. */
#ifndef MICA_STUDY_H
#define MICA_STUDY_H

#include "sweep.h"

typedef enum { STUDY_ERROR_L2, STUDY_ERROR_H1, STUDY_ERROR_ENERGY, STUDY_ERROR_PROBE } StudyMeasure;

/* The timed phases of one solve, as `mica run` reports them (summary.json keys). */
typedef enum {
  STUDY_DISCRETIZE, /* time_discretize: particles, cells, quadrature points */
  STUDY_MLS,        /* time_mls_setup: search structure, radii */
  STUDY_CACHE,      /* time_cache_and_pattern: shape functions at every quadrature point, sparsity pattern */
  STUDY_ASSEMBLE,   /* time_assemble: residuals and tangents, every Newton iteration */
  STUDY_FACTOR,     /* time_factor: symbolic analysis and numeric factorization */
  STUDY_SOLVE,      /* time_solve: triangular solves */
  STUDY_NPHASES
} StudyPhase;

extern const char *const study_phase_key[STUDY_NPHASES];  /* "time_discretize", ... (run's summary) */
extern const char *const study_phase_column[STUDY_NPHASES]; /* "time_discretize", ... (study.csv) */

typedef struct StudySpec {
  const MicaDeck *deck;
  int nchoices;
  SweepAxis *choices;     /* the varied settings (sweep_axis_read), label = study.choices.[].name or short path */
  long ncombinations;     /* every combination: the product of the numbers of values */
  int nprobes;
  const char **probes;    /* the deck's probe names (borrowed) */
  StudyMeasure measure;   /* study.error */
  int probe;              /* STUDY_ERROR_PROBE: the probe, an index into probes */
  const char *error_name; /* "energy", "l2", "h1" or the probe's name (borrowed) */
  double target;          /* study.target */
  int time_total;         /* study.time: 0 "solve" (assembly + factorization + solution), 1 "total" (every phase) */
  int repeat;             /* study.repeat: solves per combination; the minimum time of each phase is kept */
  int chart;
  int ranks_per_point;    /* study.ranks_per_point: under mpirun, the ranks of the group that solves a combination */
} StudySpec;

/* One combination and what it measured. */
typedef struct StudyRow {
  int *choice;           /* per choice, the index of the combination's value */
  int status;            /* MICA_SUCCESS, or the failure's error code */
  char *message;         /* the failure's message, or NULL */
  int reached;           /* 1: it failed but wrote what it reached (a Newton run that stopped: "failed") */
  long dofs, particles, quadrature_points, nnz, nnz_factor, cache_bytes, matrix_bytes;
  double phase[STUDY_NPHASES]; /* seconds, the minimum over the repeats */
  double error_l2, error_h1, error_energy; /* relative; NAN without an exact solution */
  double *probe;         /* per probe (NAN when absent) */
  double reference;      /* STUDY_ERROR_PROBE: the probe's reference for this combination */
  double error, time;    /* the study's measures (study.error, study.time) */
  int pareto;            /* 1: no other combination has both a smaller time and a smaller error */
  int group;             /* the group of ranks that solved it (0 when serial) */
} StudyRow;

int study_spec_read(const MicaDeck *deck, StudySpec *spec);
void study_spec_free(StudySpec *spec);
/* The value indices of combination p (0-based) in choice[nchoices]; the last choice varies fastest. */
void study_combination(const StudySpec *spec, long p, int *choice);
/* "order=2 dilation=3 m=8": each choice's label and value, for progress lines, charts and the summary. */
void study_choice_text(const StudySpec *spec, const int *choice, char *buf, size_t size);
/* "relative energy error", "relative error of tip_uy"; "solve time (assembly + factorization + solution)". */
const char *study_error_title(const StudySpec *spec, char *buf, size_t size);
const char *study_time_title(const StudySpec *spec);

double study_solve_time(const StudyRow *row); /* assembly + factorization + solution */
double study_total_time(const StudyRow *row); /* every phase */
long study_memory_bytes(const StudyRow *row); /* cache + matrix + the factor's values (an estimate) */

int study_write_csv(const StudySpec *spec, const StudyRow *rows, const char *outdir);
/* study_time.png/.svg (error against time, the Pareto front drawn and labelled, the target line) and
 * study_dofs.png/.svg (error against dofs); fastest is the row named for the target, or -1. */
int study_write_charts(const StudySpec *spec, const StudyRow *rows, long fastest, const char *outdir);

#endif
