/* Internal interface of the MLS accuracy study (`mica mls`), shared by its files. */
#ifndef MICA_MLS_STUDY_H
#define MICA_MLS_STUDY_H

#include "mica/command.h"
#include "mica/mls.h"

extern const MicaDeckKey mica_mls_schema[];

/* Exact and approximate f, ∂f/∂a, ∂²f/∂a² at one sample point (a = sample.axis). */
typedef struct {
  double x[3];
  double param;  /* position along the line, 0 at from, 1 at to (volume samples: 0) */
  long support;  /* supporting particles */
  double f, fh, df, dfh, ddf, ddfh;
} MlsSample;

/* Errors of one sample set, relative to the largest |exact value| of that set. */
typedef struct {
  double scale_f, scale_df, scale_ddf;
  double f_max, f_rms, df_max, df_rms, ddf_max, ddf_rms;
  long support_min, support_max;
} MlsErrors;

typedef struct {
  char name[256]; /* a variant's name (at most MICA_DECK_TEXT_MAX) or the deck file's stem (a file name) */
  int dim, axis;
  long nparticles;
  MlsSample *line, *volume;
  long nline, nvolume;
  MlsErrors line_err, volume_err;
  double evals_per_s, eval_seconds, setup_seconds, rcond_min;
} MlsVariantResult;

void mls_study_errors(const MlsSample *samples, long n, MlsErrors *err);
/* mls.csv: one row per variant × sample. */
int mls_study_write_csv(const MlsVariantResult *results, int nvariants, const char *outdir);
/* mls_error.png / .svg through gnuplot: relative errors along the line, one curve per variant. */
int mls_study_write_chart(const MlsVariantResult *results, int nvariants, const char *title,
                          const char *outdir);

#endif
