/* Ranks, agreement on errors, failure injection, and the collectives the solver uses (parallel.h).
 *
 * Agreement: every collective of the parallel solver is preceded by mica_parallel_agree(ierr), an
 * MPI_Allreduce (MIN) of "the first failing rank" followed, if one failed, by the broadcast of its code and
 * message. A rank that fails therefore skips the work up to the next agreement point and meets the others
 * there; all then unwind with the same code. The command line agrees once more at the end of a command, so
 * an error that does not pass through the solver (a deck error, a failure while building) is met there. An
 * error once agreed is not agreed again (its generation is remembered), so ranks that unwind through
 * several agreement points stay in step.
 *
 * Groups: comm_ is the current group's communicator between mica_parallel_groups_begin and _end (rank_
 * and size_ then the group's); the remembered agreement is dropped at both ends, because an error one
 * group agreed on is not known to the others. Messages, injection and abort use the rank in MPI_COMM_WORLD. */
#include <limits.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "mica/parallel.h"
#include "mica/timer.h"

static int started, rank_, size_ = 1, alone, world_rank_, world_size_ = 1;
static MPI_Comm comm_ = MPI_COMM_NULL; /* the ranks that share the work: MPI_COMM_WORLD or a group's */
static unsigned long agreed_generation; /* mica_error_generation() of the agreed error; 0: none */

void mica_parallel_start(void) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) return;
  started = 1;
  comm_ = MPI_COMM_WORLD;
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  world_rank_ = rank_, world_size_ = size_;
  if (rank_ != 0 && !freopen("/dev/null", "w", stdout)) fclose(stdout);
}

MPI_Comm mica_parallel_comm(void) { return started ? comm_ : MPI_COMM_SELF; }
int mica_parallel_rank(void) { return rank_; }
int mica_parallel_world_rank(void) { return world_rank_; }
int mica_parallel_world_size(void) { return world_size_; }
int mica_parallel_size(void) { return size_; }
int mica_parallel_active(void) { return started && size_ > 1 && !alone; }

int mica_parallel_set_alone(int value) {
  const int previous = alone;
  alone = value;
  return previous;
}

int mica_parallel_error_agreed(void) {
  return !mica_parallel_active() || (agreed_generation && agreed_generation == mica_error_generation());
}

int mica_parallel_agree(int ierr) {
  if (!mica_parallel_active()) return ierr;
  if (ierr && mica_parallel_error_agreed()) return ierr;
  int first = ierr ? rank_ : size_, failing = size_;
  MPI_Allreduce(&first, &failing, 1, MPI_INT, MPI_MIN, comm_);
  if (failing == size_) return MICA_SUCCESS;
  struct {
    int code, world_rank;
    char message[1536];
  } error;
  memset(&error, 0, sizeof error);
  if (rank_ == failing) {
    error.code = ierr;
    error.world_rank = world_rank_; /* messages name ranks of MPI_COMM_WORLD, inside a group too */
    snprintf(error.message, sizeof error.message, "%s", mica_error_message());
  }
  MPI_Bcast(&error, (int)sizeof error, MPI_BYTE, failing, comm_);
  /* every rank, the failing one too, gets the message with the failing rank in front (rank 0's as it is:
   * a deck error fails every rank alike) */
  if (failing == 0 || strncmp(error.message, "rank ", 5) == 0)
    mica_error_set(__FILE__, __LINE__, __func__, error.code, "%s", error.message);
  else
    mica_error_set(__FILE__, __LINE__, __func__, error.code, "rank %d: %s", error.world_rank, error.message);
  agreed_generation = mica_error_generation();
  return error.code;
}

int mica_parallel_inject(const char *phase) {
  const char *spec = getenv("MICA_INJECT_FAILURE");
  if (!spec || !*spec) return MICA_SUCCESS;
  char *end = NULL;
  const long rank = strtol(spec, &end, 10);
  if (end == spec || *end != ':' || rank != world_rank_) return MICA_SUCCESS;
  const char *name = end + 1, *colon = strchr(name, ':');
  const size_t length = colon ? (size_t)(colon - name) : strlen(name);
  if (length != strlen(phase) || strncmp(name, phase, length) != 0) return MICA_SUCCESS;
  if (colon && !strcmp(colon + 1, "exit")) {
    fprintf(stderr, "mica: rank %d: MICA_INJECT_FAILURE=%s: leaving at once (a simulated crash)\n", world_rank_, spec);
    fflush(stderr);
    _exit(1);
  }
  MICA_ERROR(MICA_ERR_LIBRARY, "failure injected at phase '%s' (MICA_INJECT_FAILURE=%s, a testing aid)", phase,
             spec);
}

/* ---- groups of ranks ---- */

int mica_parallel_groups_begin(int ranks_per_group, MicaParallelGroups *groups) {
  memset(groups, 0, sizeof *groups);
  groups->ngroups = 1;
  groups->ranks = 1;
  groups->leader = 1;
  groups->outer = MPI_COMM_NULL;
  if (!started) { /* serial: one group of one rank, nothing changes */
    MICA_CHECK(ranks_per_group == 1, MICA_ERR_ARGUMENT, "groups of %d ranks in a serial run", ranks_per_group);
    return MICA_SUCCESS;
  }
  MICA_CHECK(ranks_per_group >= 1 && ranks_per_group <= size_ && size_ % ranks_per_group == 0, MICA_ERR_ARGUMENT,
             "groups of %d ranks do not divide %d ranks", ranks_per_group, size_);
  MPI_Comm group_comm = MPI_COMM_NULL;
  /* consecutive ranks form a group; the outer rank orders the ranks inside it */
  if (MPI_Comm_split(comm_, rank_ / ranks_per_group, rank_, &group_comm) != MPI_SUCCESS)
    MICA_ERROR(MICA_ERR_LIBRARY, "MPI_Comm_split into groups of %d ranks failed", ranks_per_group);
  groups->outer = comm_;
  groups->outer_rank = rank_;
  groups->outer_size = size_;
  groups->group = rank_ / ranks_per_group;
  groups->ngroups = size_ / ranks_per_group;
  groups->ranks = ranks_per_group;
  comm_ = group_comm;
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  groups->leader = rank_ == 0;
  agreed_generation = 0;
  return MICA_SUCCESS;
}

void mica_parallel_groups_end(MicaParallelGroups *groups) {
  if (groups->outer == MPI_COMM_NULL) return;
  MPI_Comm_free(&comm_);
  comm_ = groups->outer;
  rank_ = groups->outer_rank;
  size_ = groups->outer_size;
  groups->outer = MPI_COMM_NULL;
  agreed_generation = 0; /* an error the group agreed on is not yet agreed by the outer ranks */
}

int mica_parallel_allgather(int ierr, const void *mine, long nbytes, char **all, long *total) {
  int *counts = NULL, *offsets = NULL;
  *all = NULL;
  *total = 0;
  MICA_CALL(mica_parallel_agree(ierr));
  if (!mica_parallel_active()) {
    MICA_CALL(MICA_MALLOC(*all, nbytes > 0 ? nbytes : 1));
    if (nbytes > 0) memcpy(*all, mine, (size_t)nbytes);
    *total = nbytes;
    return MICA_SUCCESS;
  }
  ierr = nbytes <= INT_MAX ? MICA_SUCCESS
                           : mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                                            "mica_parallel_allgather: %ld bytes on one rank (at most INT_MAX)", nbytes);
  if (!ierr) ierr = MICA_CALLOC(counts, size_);
  if (!ierr) ierr = MICA_CALLOC(offsets, size_);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  const int count = (int)nbytes;
  MPI_Allgather(&count, 1, MPI_INT, counts, 1, MPI_INT, comm_);
  long sum = 0;
  for (int r = 0; r < size_; r++) offsets[r] = (int)sum, sum += counts[r];
  ierr = sum <= INT_MAX ? MICA_SUCCESS
                        : mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                                         "mica_parallel_allgather: %ld bytes in all (at most INT_MAX)", sum);
  if (!ierr) ierr = MICA_MALLOC(*all, sum > 0 ? sum : 1);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Allgatherv(mine, count, MPI_BYTE, *all, counts, offsets, MPI_BYTE, comm_);
  *total = sum;
cleanup:
  if (ierr) MICA_FREE(*all);
  free(counts);
  free(offsets);
  return ierr;
}

/* MPI counts are int: long vectors go in chunks. */
enum { CHUNK = 1 << 28 };

int mica_parallel_sum(int ierr, double *v, long n) {
  MICA_CALL(mica_parallel_agree(ierr));
  if (!mica_parallel_active()) return MICA_SUCCESS;
  for (long first = 0; first < n; first += CHUNK) {
    const int count = (int)(n - first < CHUNK ? n - first : CHUNK);
    /* reduce to rank 0, then broadcast: every rank holds bitwise the same sums, so decisions taken on them
     * (convergence, step cuts) are the same everywhere */
    if (rank_ == 0) MPI_Reduce(MPI_IN_PLACE, v + first, count, MPI_DOUBLE, MPI_SUM, 0, comm_);
    else MPI_Reduce(v + first, NULL, count, MPI_DOUBLE, MPI_SUM, 0, comm_);
    MPI_Bcast(v + first, count, MPI_DOUBLE, 0, comm_);
  }
  return MICA_SUCCESS;
}

int mica_parallel_max(int ierr, double *v, long n) {
  MICA_CALL(mica_parallel_agree(ierr));
  if (!mica_parallel_active()) return MICA_SUCCESS;
  for (long first = 0; first < n; first += CHUNK) {
    const int count = (int)(n - first < CHUNK ? n - first : CHUNK);
    MPI_Allreduce(MPI_IN_PLACE, v + first, count, MPI_DOUBLE, MPI_MAX, comm_);
  }
  return MICA_SUCCESS;
}

int mica_parallel_broadcast(int ierr, double *v, long n, int root) {
  MICA_CALL(mica_parallel_agree(ierr));
  if (!mica_parallel_active()) return MICA_SUCCESS;
  for (long first = 0; first < n; first += CHUNK) {
    const int count = (int)(n - first < CHUNK ? n - first : CHUNK);
    MPI_Bcast(v + first, count, MPI_DOUBLE, root, comm_);
  }
  return MICA_SUCCESS;
}

int mica_parallel_broadcast_text(int ierr, char **text, int root) {
  MICA_CALL(mica_parallel_agree(ierr));
  if (!mica_parallel_active()) return MICA_SUCCESS;
  long length = rank_ == root ? (long)strlen(*text) : 0;
  MPI_Bcast(&length, 1, MPI_LONG, root, comm_);
  int failed = 0;
  if (rank_ != root) {
    free(*text);
    failed = MICA_MALLOC(*text, length + 1);
  }
  MICA_CALL(mica_parallel_agree(failed));
  for (long first = 0; first < length; first += CHUNK) {
    const int count = (int)(length - first < CHUNK ? length - first : CHUNK);
    MPI_Bcast(*text + first, count, MPI_CHAR, root, comm_);
  }
  (*text)[length] = '\0';
  return MICA_SUCCESS;
}

static char *shared_dir_; /* mica_parallel_share_dir */

int mica_parallel_share_dir(int ierr, const char *dir) {
  char *copy = NULL;
  MICA_FREE(shared_dir_);
  if (!ierr && rank_ == 0) ierr = MICA_MALLOC(copy, strlen(dir) + 1);
  if (!ierr && rank_ == 0) strcpy(copy, dir);
  ierr = mica_parallel_broadcast_text(ierr, &copy, 0);
  if (ierr) MICA_FREE(copy);
  shared_dir_ = copy;
  return ierr;
}

const char *mica_parallel_shared_dir(void) { return shared_dir_; }

void mica_parallel_unshare_dir(void) { MICA_FREE(shared_dir_); }

int mica_parallel_append_in_order(int ierr, const char *path, const char *text) {
  char *where = NULL;
  if (!ierr && rank_ == 0) ierr = MICA_MALLOC(where, strlen(path) + 1);
  if (!ierr && rank_ == 0) strcpy(where, path);
  MICA_CALL(mica_parallel_broadcast_text(ierr, &where, 0));
  int failed = 0;
  for (int r = 1; r < size_; r++) { /* rank r appends once rank r − 1 has: the token is its status */
    if (rank_ == r - 1 && r > 1) MPI_Send(&failed, 1, MPI_INT, r, 0, comm_);
    if (rank_ != r) continue;
    if (r > 1) MPI_Recv(&failed, 1, MPI_INT, r - 1, 0, comm_, MPI_STATUS_IGNORE);
    FILE *fp = failed ? NULL : fopen(where, "a");
    if (!failed && (!fp || fputs(text, fp) == EOF)) failed = 1;
    if (fp && fclose(fp) != 0) failed = 1;
  }
  if (failed) ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "cannot append rank %d's rows to %s",
                                    rank_, where);
  free(where);
  return mica_parallel_agree(ierr);
}

static double residual_wall, residual_cpu;
static long residual_calls;

int mica_parallel_residual(int ierr, double *R, long n) {
  const double wall = mica_wtime(), cpu = mica_cputime();
  if (!ierr) ierr = mica_parallel_inject("assemble");
  ierr = mica_parallel_sum(ierr, R, n);
  residual_wall += mica_wtime() - wall;
  residual_cpu += mica_cputime() - cpu;
  residual_calls++;
  return ierr;
}

void mica_parallel_residual_time(double *wall, double *cpu, long *calls) {
  *wall = residual_wall, *cpu = residual_cpu, *calls = residual_calls;
}

long mica_parallel_max_long(long v) {
  if (mica_parallel_active()) MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_LONG, MPI_MAX, comm_);
  return v;
}

long mica_parallel_sum_long(long v) {
  if (mica_parallel_active()) MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_LONG, MPI_SUM, comm_);
  return v;
}

long mica_parallel_peak_memory(void) {
  struct rusage usage;
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return (long)usage.ru_maxrss * 1024; /* kilobytes on Linux */
}

void mica_parallel_abort(const char *program, int status) {
  fprintf(stderr, "%s: rank %d: %s\n", program, world_rank_, mica_error_message());
  fflush(stderr);
  if (started) MPI_Abort(MPI_COMM_WORLD, status ? status : 1);
  exit(status ? status : 1);
}
