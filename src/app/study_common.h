/* Shared by the study commands (src/app). */
#ifndef MICA_STUDY_COMMON_H
#define MICA_STUDY_COMMON_H

#include "mica/command.h"
#include "mica/deck.h"
#include "mica/json.h"
#include "mica/mls.h"

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
