/* Shared by the study commands (src/app). */
#ifndef MICA_STUDY_COMMON_H
#define MICA_STUDY_COMMON_H

#include "mica/command.h"
#include "mica/deck.h"
#include "mica/json.h"
#include "mica/mls.h"
#include "mica/parallel.h"

/* Reads mls.basis, mls.order, mls.weight, mls.support, mls.radius | mls.dilation (default: order + 1),
 * mls.alpha, mls.rcond_min, mls.search into opt, checking them against each other with the deck's lines. */
int mica_study_mls_options(const MicaDeck *deck, int dim, MlsOptions *opt);

/* Maps an MLS failure caused by the deck's choices (MICA_ERR_NUMERIC: singular moment matrix, no
 * support) to MICA_ERR_INPUT, keeping the message; other codes pass through. */
int mica_study_mls_input(int ierr);

/* Commands that solve a run deck many times (mica study) keep each solve in DIR/points/<n>/. */

/* Sends stdout to dir/run.log until mica_study_log_close (a solve's own lines would drown the caller's
 * progress); *saved keeps the terminal's descriptor. */
int mica_study_log_open(const char *dir, int *saved);
void mica_study_log_close(int saved);
/* command->run(deck, dir, summary) with stdout in dir/run.log. The returned code is the run's. */
int mica_study_run_logged(const MicaCommand *command, const MicaDeck *deck, const char *dir, MicaJson *summary);
/* 1 if a solve that failed wrote what it reached: its summary says "status": "failed" (a Newton run that stopped
 * after its cut-backs, src/app/run.c); any other failure leaves the "ok" its caller put there. */
int mica_study_solve_reached(const MicaJson *summary);
/* Adds a failure to such a summary: "error" (the message) and "exit_status" (3), as a point that failed
 * otherwise has them. */
int mica_study_add_failure(MicaJson *summary, int code, const char *message);

#endif

/* ---- runs dealt to groups of ranks (mica sweep, mica study under mpirun) --------------------------------- */

/* Reads the deck's `key` (sweep.ranks_per_point, study.ranks_per_point): ranks per group; it must divide the
 * ranks of the run and not exceed them (an input error with the deck line). */
int mica_study_ranks_per_point(const MicaDeck *deck, const char *key, int *ranks);

/* The groups of a command's runs: run i is solved by group i mod ngroups; each group's rank 0 writes the
 * run's files into the results' directory of world rank 0 (outdir_shared; it must be visible to every
 * rank), the other ranks of a group into their own scratch directory. */
typedef struct MicaStudyGroups {
  MicaParallelGroups groups;
  char *outdir_shared; /* rank 0's outdir */
  const char *outdir;  /* this rank's own */
  int active;          /* 1 between begin and end */
} MicaStudyGroups;

/* Collective: shares rank 0's outdir, checks that every rank sees it, splits into groups of `ranks`. */
int mica_study_groups_begin(int ranks, const char *outdir, MicaStudyGroups *g);
/* Back to every rank (the outer ranks then agree on ierr, which is returned). */
int mica_study_groups_end(int ierr, MicaStudyGroups *g);
/* 1 if this rank's group solves run i. */
int mica_study_groups_mine(const MicaStudyGroups *g, long i);
/* Where this rank writes the files of its runs. */
const char *mica_study_groups_outdir(const MicaStudyGroups *g);
void mica_study_groups_free(MicaStudyGroups *g);

/* A byte buffer that records are packed into and read back from (the rows of the groups, gathered). */
typedef struct MicaPack {
  char *data;
  long size, room, at;
} MicaPack;

int mica_pack_put(MicaPack *pack, const void *bytes, long n);
int mica_pack_put_text(MicaPack *pack, const char *text); /* text may be NULL */
int mica_pack_get(MicaPack *pack, void *bytes, long n);
int mica_pack_get_text(MicaPack *pack, char **text);      /* allocated, or NULL as packed */
void mica_pack_free(MicaPack *pack);
/* Collective over the current ranks: every rank's pack concatenated, in rank order, into *all (read from 0). */
int mica_pack_allgather(int ierr, const MicaPack *mine, MicaPack *all);
