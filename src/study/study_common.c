/* Pieces every study command shares: the MLS settings of a deck, and what an MLS failure means to a user. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mica/files.h"
#include "study_common.h"

/* The mls.* settings (docs/input.md): basis, order, weight, support, radius or dilation, search. */
int mica_study_mls_options(const MicaDeck *deck, int dim, MlsOptions *opt) {
  const char *name;
  mls_options_default(opt);
  MICA_CALL(mica_deck_string(deck, "mls.basis", &name));
  opt->basis = mls_basis_find(name);
  MICA_CALL(mica_deck_string(deck, "mls.weight", &name));
  opt->weight = mls_weight_find(name);
  MICA_CHECK(opt->basis && opt->weight, MICA_ERR_ARGUMENT, "schema and registry disagree on mls names");
  long order;
  MICA_CALL(mica_deck_int(deck, "mls.order", &order));
  opt->order = (int)order;
  char where[256];
  mica_deck_where(deck, "mls.order", where, sizeof where);
  MICA_CHECK(order >= opt->basis->min_order && order <= opt->basis->max_order, MICA_ERR_INPUT,
             "%s: the %s basis has orders %d to %d, not %ld", where, opt->basis->name,
             opt->basis->min_order, opt->basis->max_order, order);
  MICA_CALL(mica_deck_string(deck, "mls.support", &name));
  opt->support = strcmp(name, "ball") == 0 ? MLS_SUPPORT_BALL : MLS_SUPPORT_BOX;
  MICA_CALL(mica_deck_string(deck, "mls.search", &name));
  opt->search = strcmp(name, "cells") == 0 ? MLS_SEARCH_CELLS : MLS_SEARCH_KDTREE;
  MICA_CALL(mica_deck_string(deck, "mls.spacing", &name));
  opt->spacing = strcmp(name, "far") == 0 ? MLS_SPACING_FAR : MLS_SPACING_NEAR;
  MICA_CALL(mica_deck_float(deck, "mls.alpha", &opt->alpha));
  MICA_CALL(mica_deck_float(deck, "mls.rcond_min", &opt->rcond_min));
  const int has_radius = mica_deck_has(deck, "mls.radius"), has_dilation = mica_deck_has(deck, "mls.dilation");
  mica_deck_where(deck, has_radius ? "mls.radius" : "mls.dilation", where, sizeof where);
  MICA_CHECK(!(has_radius && has_dilation), MICA_ERR_INPUT,
             "%s: give mls.radius (absolute) or mls.dilation (times the spacing), not both", where);
  opt->dilation = 0;
  if (has_radius) {
    int n;
    MICA_CALL(mica_deck_floats(deck, "mls.radius", opt->radius, 3, &n));
    MICA_CHECK(n == 1 || n == dim, MICA_ERR_INPUT, "%s: mls.radius needs 1 or %d values, not %d", where, dim, n);
    MICA_CHECK(n == 1 || opt->support == MLS_SUPPORT_BOX, MICA_ERR_INPUT,
               "%s: a ball support has one radius; give mls.radius as a single number", where);
  } else if (has_dilation) {
    MICA_CALL(mica_deck_float(deck, "mls.dilation", &opt->dilation));
  } else {
    opt->dilation = opt->order + 1.0;
  }
  return MICA_SUCCESS;
}


/* A moment matrix that is singular at some point follows from the deck's particles, radius and basis: for
 * a command that reads a deck it is bad input (exit status 2), whatever the MLS library calls it. */
int mica_study_mls_input(int ierr) {
  if (ierr == MICA_ERR_NUMERIC) {
    char message[2048]; /* the message is rewritten from a copy: it cannot be its own source */
    snprintf(message, sizeof message, "%s", mica_error_message());
    return mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%s", message);
  }
  return ierr;
}

/* ---- solving a deck many times ------------------------------------------------------------------------ */

int mica_study_log_open(const char *dir, int *saved) {
  char *log = NULL;
  MICA_CALL(mica_path_join(dir, "run.log", &log));
  fflush(stdout);
  *saved = dup(STDOUT_FILENO);
  const int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  free(log);
  if (*saved < 0 || fd < 0 || dup2(fd, STDOUT_FILENO) < 0) {
    const int error = errno;
    if (*saved >= 0) close(*saved);
    if (fd >= 0) close(fd);
    MICA_ERROR(MICA_ERR_IO, "cannot write %s/run.log: %s", dir, strerror(error));
  }
  close(fd);
  return MICA_SUCCESS;
}

void mica_study_log_close(int saved) {
  fflush(stdout);
  dup2(saved, STDOUT_FILENO);
  close(saved);
}

int mica_study_solve_reached(const MicaJson *summary) {
  const char *status = NULL;
  if (mica_json_get_string(summary, "status", &status) == MICA_SUCCESS) return !strcmp(status, "failed");
  mica_error_clear();
  return 0;
}

int mica_study_add_failure(MicaJson *summary, int code, const char *message) {
  MICA_CALL(mica_json_string(summary, "error", message ? message : ""));
  return mica_json_int(summary, "exit_status", mica_exit_status(code));
}

int mica_study_run_logged(const MicaCommand *command, const MicaDeck *deck, const char *dir, MicaJson *summary) {
  int saved;
  MICA_CALL(mica_study_log_open(dir, &saved));
  const int ierr = command->run(deck, dir, summary);
  mica_study_log_close(saved);
  return ierr;
}
