/* The `mica` program: a thin layer over libmica.
 *
 *   mica <command> DECK [-o DIR] [--set path=value]...
 *   mica --help | mica help <command> | mica --version
 *
 * A run writes into a staging directory inside DIR and moves its files into DIR only when it succeeds,
 * so a failed run leaves the results of an earlier one complete and untouched. Exit status: 0 success,
 * 2 bad input (deck or command line), 3 numerical failure, 1 anything else.
 */
#include <dirent.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mica/command.h"
#include "mica/files.h"
#include "mica/parallel.h"
#include "mica/timer.h"

#define MICA_VERSION "0.1.0"
enum { MAX_OVERRIDES = 256 };

typedef struct {
  const MicaCommand *command;
  const char *deck_path;
  const char *outdir; /* NULL: out/<deck name> */
  const char *overrides[MAX_OVERRIDES];
  int noverrides;
} Invocation;

static void print_usage(FILE *out) {
  fprintf(out,
          "mica " MICA_VERSION " — meshfree MLS/EFG solver for solids and generalized continua\n\n"
          "usage: mica <command> DECK [-o DIR] [--set path=value]...\n"
          "       mica help <command>      settings of a command's deck\n"
          "       mica --version\n\n"
          "commands:\n");
  for (const MicaCommand *const *c = mica_commands(); *c; c++) fprintf(out, "  %-8s %s\n", (*c)->name, (*c)->summary);
  fprintf(out,
          "\noptions:\n"
          "  -o DIR              write results to DIR (default out/<deck name>)\n"
          "  --set path=value    override a deck setting; value in libconfig syntax, a bare word is a\n"
          "                      string: --set mls.order=2 --set particles.count=[21,21,21]\n"
          "                      --set function.f=\"x^2\" --set parameters.L=10\n\n"
          "exit status: 0 success, 2 bad input, 3 numerical failure, 1 other errors\n"
          "documentation: README.md, docs/input.md\n");
}

static int print_command_help(const char *name) {
  const MicaCommand *command = mica_command_find(name);
  if (!command) {
    fprintf(stderr, "mica: no command '%s'; `mica --help` lists them\n", name);
    return 2;
  }
  printf("mica %s DECK [-o DIR] [--set path=value]...\n\n%s\n\n%s\n\nsettings:\n", command->name,
         command->summary, command->description);
  mica_deck_print_schema(command->schema, stdout);
  return 0;
}

/* Fills inv from argv; returns 0, or an exit status to stop with (after printing why). */
static int parse_arguments(int argc, char **argv, Invocation *inv, int *done) {
  *done = 0;
  if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
    print_usage(argc < 2 ? stderr : stdout);
    *done = 1;
    return argc < 2 ? 2 : 0;
  }
  if (!strcmp(argv[1], "--version")) {
    printf("mica %s\n", MICA_VERSION);
    *done = 1;
    return 0;
  }
  if (!strcmp(argv[1], "help")) {
    *done = 1;
    if (argc < 3) {
      print_usage(stdout);
      return 0;
    }
    return print_command_help(argv[2]);
  }
  inv->command = mica_command_find(argv[1]);
  if (!inv->command) {
    fprintf(stderr, "mica: unknown command '%s'; `mica --help` lists the commands\n", argv[1]);
    return 2;
  }
  for (int i = 2; i < argc; i++) {
    const char *arg = argv[i];
    if (!strcmp(arg, "-o") || !strcmp(arg, "--set")) {
      if (i + 1 >= argc) {
        fprintf(stderr, "mica: %s needs a value\n", arg);
        return 2;
      }
      if (arg[1] == 'o') inv->outdir = argv[++i];
      else if (inv->noverrides < MAX_OVERRIDES) inv->overrides[inv->noverrides++] = argv[++i];
    } else if (!strncmp(arg, "--set=", 6)) {
      if (inv->noverrides < MAX_OVERRIDES) inv->overrides[inv->noverrides++] = arg + 6;
    } else if (arg[0] == '-' && arg[1]) {
      fprintf(stderr, "mica: unknown option '%s'; `mica --help` lists the options\n", arg);
      return 2;
    } else if (!inv->deck_path) {
      inv->deck_path = arg;
    } else {
      fprintf(stderr, "mica: one deck at a time: '%s' and '%s'\n", inv->deck_path, arg);
      return 2;
    }
  }
  if (!inv->deck_path) {
    fprintf(stderr, "mica %s: which deck? usage: mica %s DECK [-o DIR] [--set path=value]...\n",
            inv->command->name, inv->command->name);
    return 2;
  }
  return 0;
}

/* Moves every entry of the staging directory into outdir (each rename is atomic). A directory (a sweep's
 * points/) replaces the one of an earlier run, which rename() cannot do while it holds files: the old one
 * goes just before the new one moves in, so a failed run leaves it untouched. */
static int publish_staging(const char *staging, const char *outdir) {
  DIR *dir = opendir(staging);
  MICA_CHECK(dir, MICA_ERR_IO, "cannot read the staging directory %s", staging);
  struct dirent *entry;
  int ierr = MICA_SUCCESS;
  while ((entry = readdir(dir)) && ierr == MICA_SUCCESS) {
    if (!strcmp(entry->d_name, ".") || !strcmp(entry->d_name, "..")) continue;
    char *from = NULL, *to = NULL;
    struct stat info;
    ierr = mica_path_join(staging, entry->d_name, &from);
    if (!ierr) ierr = mica_path_join(outdir, entry->d_name, &to);
    if (!ierr && stat(from, &info) == 0 && S_ISDIR(info.st_mode)) mica_remove_tree(to);
    if (!ierr && rename(from, to) != 0)
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "cannot move %s to %s", from, to);
    free(from);
    free(to);
  }
  closedir(dir);
  rmdir(staging);
  return ierr;
}

static int default_outdir(const MicaDeck *deck, char **outdir) {
  return mica_path_join("out", mica_deck_name(deck), outdir);
}

/* Parallel runs: ranks other than 0 run the command into a private scratch directory, removed at the end, so
 * that every file of the results is written once, by rank 0 (src/parallel). */
static int private_outdir(char **staging) {
  const char *tmp = getenv("TMPDIR");
  char pattern[1024];
  snprintf(pattern, sizeof pattern, "%s/mica-rank%d-XXXXXX", tmp && *tmp ? tmp : "/tmp", mica_parallel_rank());
  MICA_CHECK(mkdtemp(pattern), MICA_ERR_IO, "rank %d cannot make a scratch directory %s", mica_parallel_rank(),
             pattern);
  MICA_CALL(MICA_MALLOC(*staging, strlen(pattern) + 1));
  strcpy(*staging, pattern);
  return MICA_SUCCESS;
}

/* Rank 0: the output directory, its staging directory and the resolved deck in it. */
static int prepare_outdir(const Invocation *inv, const MicaDeck *deck, char **outdir, char **staging,
                          int *outdir_existed) {
  char *path = NULL;
  if (inv->outdir) {
    MICA_CALL(MICA_MALLOC(*outdir, strlen(inv->outdir) + 1));
    strcpy(*outdir, inv->outdir);
  } else {
    MICA_CALL(default_outdir(deck, outdir));
  }
  struct stat info;
  *outdir_existed = stat(*outdir, &info) == 0;
  char name[64];
  snprintf(name, sizeof name, ".staging-%ld", (long)getpid());
  MICA_CALL(mica_path_join(*outdir, name, staging));
  MICA_CALL(mica_make_dir(*staging));
  MICA_CALL(mica_path_join(*staging, "resolved.cfg", &path));
  int ierr = mica_deck_write_resolved(deck, path);
  free(path);
  return ierr;
}

/* Rank 0: summary.json into the staging directory, then everything into outdir. */
static int publish(const char *staging, const char *outdir, MicaJson *summary, double start) {
  char *path = NULL;
  MICA_CALL(mica_json_number(summary, "time_total", mica_wtime() - start));
  MICA_CALL(mica_path_join(staging, "summary.json", &path));
  int ierr = mica_json_write(summary, path);
  free(path);
  MICA_CALL(ierr);
  MICA_CALL(publish_staging(staging, outdir));
  printf("results in %s/ (summary.json, resolved.cfg)\n", outdir);
  return MICA_SUCCESS;
}

/* Loads the deck, runs the command into a staging directory, publishes on success. Under MPI every rank
 * loads the deck and runs the command; rank 0 alone writes the results; the ranks agree on the outcome
 * after loading, after the command and at the end, so they all exit with the same status. */
static int run_command(const Invocation *inv) {
  MicaDeck *deck = NULL;
  MicaJson *summary = NULL;
  char *outdir = NULL, *staging = NULL;
  int ierr = MICA_SUCCESS, outdir_existed = 1;
  const int root = mica_parallel_rank() == 0;
  const double start = mica_wtime();
  ierr = mica_deck_load(inv->deck_path, inv->command->schema, inv->noverrides, inv->overrides, &deck);
  if (!ierr) ierr = mica_parallel_inject("deck");
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  ierr = root ? prepare_outdir(inv, deck, &outdir, &staging, &outdir_existed) : private_outdir(&staging);
  if (!ierr) ierr = mica_json_create(&summary);
  if (!ierr) ierr = mica_json_string(summary, "status", "ok");
  if (!ierr) ierr = mica_json_string(summary, "command", inv->command->name);
  if (!ierr) ierr = mica_json_string(summary, "deck", inv->deck_path);
  if (!ierr && mica_parallel_active()) ierr = mica_json_int(summary, "ranks", mica_parallel_size());
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  ierr = inv->command->run(deck, staging, summary);
  if (!ierr) ierr = mica_parallel_inject("output");
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  if (root) ierr = publish(staging, outdir, summary, start);
cleanup:
  ierr = mica_parallel_agree(ierr); /* every rank passes here once more: a failure of rank 0's publishing */
  if (ierr && staging && root) mica_remove_tree(staging);
  if (staging && !root) mica_remove_tree(staging);
  if (ierr && !outdir_existed && outdir) rmdir(outdir); /* only if empty: never removes results */
  free(staging);
  free(outdir);
  mica_json_destroy(&summary);
  mica_deck_destroy(&deck);
  return ierr;
}

int main(int argc, char **argv) {
  Invocation inv = {0};
  int done, status = parse_arguments(argc, argv, &inv, &done);
  if (done || status) return status;
  /* MPI starts only under a launcher (mpirun sets these): a plain `mica` run is one serial process and
   * pays neither MPI's start-up time nor its one-time allocations. */
  const int launched = getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
  if (launched) {
    MPI_Init(&argc, &argv);
    mica_parallel_start();
  }
  int ierr = run_command(&inv);
  /* an error every rank agreed on is reported once, by rank 0; any other ends every rank at once */
  if (ierr && !mica_parallel_error_agreed()) mica_parallel_abort("mica", mica_exit_status(ierr));
  if (ierr && mica_parallel_rank() == 0) mica_error_report("mica");
  if (launched) MPI_Finalize();
  return mica_exit_status(ierr);
}
