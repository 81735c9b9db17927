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

/* ---- runs dealt to groups of ranks ---------------------------------------------------------------------- */

int mica_study_ranks_per_point(const MicaDeck *deck, const char *key, int *ranks) {
  long value;
  char where[256];
  MICA_CALL(mica_deck_int(deck, key, &value));
  const int size = mica_parallel_size();
  mica_deck_where(deck, key, where, sizeof where);
  MICA_CHECK(value <= size, MICA_ERR_INPUT, "%s: %s = %ld: more ranks than the run has (%d%s)", where, key, value,
             size, size == 1 ? ": a serial run; start it with mpirun -np P" : "");
  MICA_CHECK(size % value == 0, MICA_ERR_INPUT,
             "%s: %s = %ld does not divide the %d ranks of the run into groups of equal size", where, key, value,
             size);
  *ranks = (int)value;
  return MICA_SUCCESS;
}

/* A rank other than 0 that writes into rank 0's directory must see it: the ranks share a file system. */
static int check_visible(const char *dir) {
  struct stat st;
  MICA_CHECK(stat(dir, &st) == 0 && S_ISDIR(st.st_mode), MICA_ERR_IO,
             "rank %d cannot see rank 0's results directory %s: groups of ranks write their points there, so the "
             "ranks must share a file system (or set the ranks per point to every rank)",
             mica_parallel_world_rank(), dir);
  return MICA_SUCCESS;
}

int mica_study_groups_begin(int ranks, const char *outdir, MicaStudyGroups *g) {
  memset(g, 0, sizeof *g);
  g->outdir = outdir;
  int ierr = MICA_MALLOC(g->outdir_shared, strlen(outdir) + 1);
  if (!ierr) strcpy(g->outdir_shared, outdir);
  MICA_CALL(mica_parallel_broadcast_text(ierr, &g->outdir_shared, 0)); /* rank 0's directory on every rank */
  const int leader = mica_parallel_rank() % ranks == 0; /* rank 0 of its group-to-be */
  if (leader && mica_parallel_rank() != 0) ierr = check_visible(g->outdir_shared);
  MICA_CALL(mica_parallel_agree(ierr));
  MICA_CALL(mica_parallel_groups_begin(ranks, &g->groups));
  g->active = 1;
  return MICA_SUCCESS;
}

int mica_study_groups_end(int ierr, MicaStudyGroups *g) {
  if (g->active) mica_parallel_groups_end(&g->groups);
  g->active = 0;
  return mica_parallel_agree(ierr);
}

int mica_study_groups_mine(const MicaStudyGroups *g, long i) { return i % g->groups.ngroups == g->groups.group; }

const char *mica_study_groups_outdir(const MicaStudyGroups *g) {
  return g->groups.leader || g->groups.outer == MPI_COMM_NULL ? g->outdir_shared : g->outdir;
}

void mica_study_groups_free(MicaStudyGroups *g) {
  if (g->active) mica_parallel_groups_end(&g->groups);
  g->active = 0;
  MICA_FREE(g->outdir_shared);
}

int mica_pack_put(MicaPack *pack, const void *bytes, long n) {
  if (pack->size + n > pack->room) {
    const long room = 2 * (pack->size + n) + 256;
    MICA_CALL(MICA_REALLOC(pack->data, room));
    pack->room = room;
  }
  if (n > 0) memcpy(pack->data + pack->size, bytes, (size_t)n);
  pack->size += n;
  return MICA_SUCCESS;
}

int mica_pack_put_text(MicaPack *pack, const char *text) {
  const long length = text ? (long)strlen(text) : -1;
  MICA_CALL(mica_pack_put(pack, &length, sizeof length));
  return text ? mica_pack_put(pack, text, length) : MICA_SUCCESS;
}

int mica_pack_get(MicaPack *pack, void *bytes, long n) {
  MICA_CHECK(n >= 0 && pack->at + n <= pack->size, MICA_ERR_LIBRARY, "a gathered record ends early (%ld of %ld bytes)",
             pack->at, pack->size);
  memcpy(bytes, pack->data + pack->at, (size_t)n);
  pack->at += n;
  return MICA_SUCCESS;
}

int mica_pack_get_text(MicaPack *pack, char **text) {
  long length;
  *text = NULL;
  MICA_CALL(mica_pack_get(pack, &length, sizeof length));
  if (length < 0) return MICA_SUCCESS;
  MICA_CALL(MICA_MALLOC(*text, length + 1));
  const int ierr = mica_pack_get(pack, *text, length);
  if (ierr) MICA_FREE(*text);
  else (*text)[length] = '\0';
  return ierr;
}

void mica_pack_free(MicaPack *pack) {
  MICA_FREE(pack->data);
  pack->size = pack->room = pack->at = 0;
}

int mica_pack_allgather(int ierr, const MicaPack *mine, MicaPack *all) {
  memset(all, 0, sizeof *all);
  MICA_CALL(mica_parallel_allgather(ierr, mine->data, mine->size, &all->data, &all->size));
  all->room = all->size;
  return MICA_SUCCESS;
}
