/* Shared by the study commands (src/study). */
#ifndef MICA_STUDY_COMMON_H
#define MICA_STUDY_COMMON_H

#include "mica/deck.h"
#include "mica/mls.h"

/* Reads mls.basis, mls.order, mls.weight, mls.support, mls.radius | mls.dilation (default: order + 1),
 * mls.alpha, mls.rcond_min, mls.search into opt, checking them against each other with the deck's lines. */
int mica_study_mls_options(const MicaDeck *deck, int dim, MlsOptions *opt);

/* Maps an MLS failure caused by the deck's choices (MICA_ERR_NUMERIC: singular moment matrix, no
 * support) to MICA_ERR_INPUT, keeping the message; other codes pass through. */
int mica_study_mls_input(int ierr);

#endif
