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

/* The mls.* settings (docs/input.md): src/mls/settings.c reads them. */
int mica_study_mls_options(const MicaDeck *deck, int dim, MlsOptions *opt) {
  MicaSettings settings;
  mica_deck_settings(deck, &settings);
  return mls_options_from_settings(&settings, "mls", dim, opt);
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
