/* Shared by the study commands (src/study). */
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

/* Runs command->run(deck, dir, summary) with stdout in dir/run.log (the run's own lines would drown the
 * caller's progress). The returned code is the run's. */
int mica_study_run_logged(const MicaCommand *command, const MicaDeck *deck, const char *dir, MicaJson *summary);
/* rm -r path (the command line's staging cleanup removes files only). */
void mica_study_remove_tree(const char *path);
/* Called on success with the staging directory DIR/.staging-<pid>: removes DIR/<name> (an earlier
 * run's subdirectory), which the command line's rename() of the staged one could not replace. */
void mica_study_clear_published(const char *staging, const char *name);

#endif
