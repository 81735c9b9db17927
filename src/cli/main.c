/* The `mica` program: a thin layer over libmica.
 *
 *   mica <command> [-o DIR] [--set PATH=VALUE]... [--] DECK
 *   mica --help | mica help [<command>] | mica <command> --help | mica --version
 *
 * The options are declared once, in the tables below; the parser (options.c) and the help (help.c) both
 * read them. A run writes into a staging directory beside DIR and swaps it in as DIR with one rename only
 * when it succeeds (publish.h), so a failed or interrupted run leaves the results of an earlier one complete
 * and untouched. The one exception is a run that failed but wrote what it reached (a Newton solve that
 * stopped after its cut-backs: its summary says "status": "failed"): the user asked for that run, so its
 * results replace the earlier ones, whole, and it exits 3. Exit status:
 * 0 success, 2 bad input (deck or command line), 3 numerical failure, 1 anything else.
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "mica/files.h"
#include "mica/parallel.h"
#include "mica/publish.h"
#include "mica/timer.h"

/* ---- the options ---- */

static int set_output(Invocation *inv, const char *who, const char *value) {
  if (inv->outdir) { /* the first would have no effect */
    fprintf(stderr, "%s: --output given twice ('%s' and '%s'); one output directory per run\n", who, inv->outdir,
            value);
    return CLI_USAGE;
  }
  inv->outdir = value;
  return 0;
}

static int add_override(Invocation *inv, const char *who, const char *value) {
  if (inv->noverrides == inv->room) { /* cannot happen: each --set is at least one argument */
    fprintf(stderr, "%s: more --set overrides than arguments\n", who);
    return CLI_USAGE;
  }
  inv->overrides[inv->noverrides++] = value;
  return 0;
}

static int ask_help(Invocation *inv, const char *who, const char *value) {
  (void)who, (void)value;
  inv->help = 1;
  return 0;
}

static int ask_version(Invocation *inv, const char *who, const char *value) {
  (void)who, (void)value;
  inv->version = 1;
  return 0;
}

const CliOption cli_command_options[] = {
    {"output", 'o', "DIR", 0,
     "write the results to DIR (default out/<deck name>, relative to the working directory); a failed run "
     "leaves the results already in DIR untouched, except a run whose Newton solve stopped: what it reached "
     "replaces them (exit status 3)",
     set_output},
    {"set", 0, "PATH=VALUE", 1,
     "override a deck setting (repeatable; applied in order, after the deck): VALUE in libconfig syntax, "
     "a bare word is a string (mica --help shows examples)",
     add_override},
    {"help", 'h', NULL, 0, "print this help (the command's options and deck settings) and exit", ask_help},
    {NULL, 0, NULL, 0, NULL, NULL}};

static int ask_markdown(Invocation *inv, const char *who, const char *value) {
  (void)who, (void)value;
  inv->markdown = 1;
  return 0;
}

static int set_group(Invocation *inv, const char *who, const char *value) {
  if (inv->group) {
    fprintf(stderr, "%s: --group given twice ('%s' and '%s'); one group per table\n", who, inv->group, value);
    return CLI_USAGE;
  }
  inv->group = value;
  return 0;
}

const CliOption cli_help_options[] = {
    {"markdown", 0, NULL, 0,
     "print only the command's deck settings, as a Markdown table (the tables of docs/input.md, which "
     "docs/gen_input_tables.sh rewrites with it)",
     ask_markdown},
    {"group", 0, "GROUP", 0, "with --markdown: only the settings under GROUP (study: study and study.*)",
     set_group},
    {"help", 'h', NULL, 0, "list the commands and options and exit (as does mica help)", ask_help},
    {NULL, 0, NULL, 0, NULL, NULL}};

const CliOption cli_program_options[] = {
    {"help", 'h', NULL, 0, "list the commands and options and exit (as does mica help)", ask_help},
    {"version", 0, NULL, 0, "print the version and exit", ask_version},
    {NULL, 0, NULL, 0, NULL, NULL}};

/* ---- the arguments ---- */

static int stop_at_command(Invocation *inv, const char *who, const char *arg) {
  (void)inv, (void)who, (void)arg;
  return CLI_STOP;
}

static int take_deck(Invocation *inv, const char *who, const char *arg) {
  if (inv->deck_path) {
    fprintf(stderr, "%s: one deck at a time: '%s' and '%s'\n", who, inv->deck_path, arg);
    return CLI_USAGE;
  }
  inv->deck_path = arg;
  return 0;
}

/* The command called name, or NULL after saying there is none (and which one was probably meant). */
static const MicaCommand *find_command(const char *who, const char *name) {
  const MicaCommand *command = mica_command_find(name);
  if (command) return command;
  const char *names[64] = {"help"};
  int n = 1;
  for (const MicaCommand *c; n < 63 && (c = mica_command_at(n - 1)); n++) names[n] = c->type.name;
  names[n] = NULL;
  const char *closest = cli_closest(name, names);
  fprintf(stderr, "%s: unknown command '%s'%s%s%s (`mica --help` lists the commands)\n", who, name,
          closest ? "; did you mean '" : "", closest ? closest : "", closest ? "'?" : "");
  return NULL;
}

/* mica help [--markdown [--group GROUP]] [<command>] */
/* The exit status of printing a help text: composing a schema fails only for want of memory, a Markdown table
 * also for a --group that holds no setting (bad input). */
static int help_status(int ierr, const char *who) {
  if (!ierr) return 0;
  mica_error_report(who);
  return mica_exit_status(ierr);
}

/* The topic of mica help: one command. */
static int take_topic(Invocation *inv, const char *who, const char *arg) {
  if (inv->command) {
    fprintf(stderr, "%s: one command at a time ('%s' and '%s'); `mica help` lists them\n", who,
            inv->command->type.name, arg);
    return CLI_USAGE;
  }
  inv->command = find_command(who, arg);
  return inv->command ? 0 : CLI_USAGE;
}

/* An option of mica help that would have no effect is refused, as a deck setting would be. */
static int check_help_options(const Invocation *inv) {
  if (inv->group && !inv->markdown) {
    fprintf(stderr, "mica help: --group %s needs --markdown (it selects the rows of the Markdown table)\n",
            inv->group);
    return CLI_USAGE;
  }
  if (inv->markdown && !inv->command) {
    fprintf(stderr, "mica help: --markdown prints one command's settings: which command? (mica help "
                    "--markdown run)\n");
    return CLI_USAGE;
  }
  return 0;
}

static int print_help_topic(int argc, char **argv) {
  Invocation inv = {0};
  int status = cli_parse(argc, argv, "mica help", cli_help_options, &inv, take_topic, NULL);
  if (!status && !inv.help) status = check_help_options(&inv);
  if (status) return status;
  if (inv.help || !inv.command) {
    cli_print_program_help(stdout);
    return 0;
  }
  if (inv.markdown) return help_status(cli_print_command_markdown(inv.command, inv.group, stdout), "mica help");
  return help_status(cli_print_command_help(inv.command, stdout), "mica help");
}

/* The command's own arguments, argv[0] being its name. */
static int parse_command(int argc, char **argv, Invocation *inv, int *done) {
  char who[64];
  snprintf(who, sizeof who, "mica %s", inv->command->type.name);
  int status = cli_parse(argc, argv, who, cli_command_options, inv, take_deck, NULL);
  if (status) return status;
  if (inv->help) {
    return help_status(cli_print_command_help(inv->command, stdout), "mica");
  }
  if (!inv->deck_path) {
    fprintf(stderr, "%s: which deck? ", who);
    cli_print_command_usage(inv->command, stderr);
    return CLI_USAGE;
  }
  *done = 0;
  return 0;
}

/* Fills inv from argv; returns 0, or an exit status to stop with (after printing why). */
static int parse_arguments(int argc, char **argv, Invocation *inv, int *done) {
  int at = 0;
  *done = 1;
  if (argc < 2) {
    cli_print_program_help(stderr);
    return CLI_USAGE;
  }
  int status = cli_parse(argc, argv, "mica", cli_program_options, inv, stop_at_command, &at);
  if (status) return status;
  if (inv->version) {
    printf("mica %s\n", MICA_VERSION);
    return 0;
  }
  if (inv->help) {
    cli_print_program_help(stdout);
    return 0;
  }
  if (!at) {
    fprintf(stderr, "mica: which command? `mica --help` lists them\n");
    return CLI_USAGE;
  }
  if (!strcmp(argv[at], "help")) return print_help_topic(argc - at, argv + at);
  inv->command = find_command("mica", argv[at]);
  if (!inv->command) return CLI_USAGE;
  return parse_command(argc - at, argv + at, inv, done);
}

static int default_outdir(const MicaDeck *deck, char **outdir) {
  return mica_path_join("out", mica_deck_name(deck), outdir);
}

/* Rank 0: the output directory's staging directory (publish.h) and the resolved deck in it. Ranks other
 * than 0 run the command into a private scratch directory, removed at the end, so that every file of the
 * results is written once, by rank 0 (src/parallel). */
static int prepare_outdir(const Invocation *inv, const MicaDeck *deck, char **outdir, MicaStaging **staging) {
  char *path = NULL;
  if (mica_parallel_rank() != 0) return mica_staging_create_scratch(mica_parallel_rank(), staging);
  if (inv->outdir) {
    MICA_CALL(MICA_MALLOC(*outdir, strlen(inv->outdir) + 1));
    strcpy(*outdir, inv->outdir);
  } else {
    MICA_CALL(default_outdir(deck, outdir));
  }
  MICA_CALL(mica_staging_create_results(*outdir, staging));
  MICA_CALL(mica_path_join(mica_staging_dir(*staging), "resolved.cfg", &path));
  int ierr = mica_deck_write_resolved(deck, path);
  free(path);
  return ierr;
}

/* Rank 0: summary.json into the staging directory, then everything into outdir. */
static int publish(MicaStaging *staging, const char *outdir, MicaJson *summary, double start, const char *what) {
  char *path = NULL;
  MICA_CALL(mica_json_number(summary, "time_total", mica_wtime() - start));
  MICA_CALL(mica_path_join(mica_staging_dir(staging), "summary.json", &path));
  int ierr = mica_json_write(summary, path);
  free(path);
  MICA_CALL(ierr);
  MICA_CALL(mica_staging_publish(staging));
  printf("%s in %s/ (summary.json, resolved.cfg)\n", what, outdir);
  fflush(stdout);
  return MICA_SUCCESS;
}

/* The command failed numerically (failure agreed by every rank). If it wrote what it reached — its summary
 * says "status": "failed" (src/app/run.c) — rank 0 publishes that like a success's results; the failure is
 * then set again and agreed, so that every rank exits 3 with its message. Rank 0's summary decides for all:
 * the ranks must take the same collective steps. A failure to publish replaces it (with its reason). */
static int publish_reached(MicaStaging *staging, const char *outdir, MicaJson *summary, double start) {
  const int root = mica_parallel_rank() == 0;
  char reason[1536];
  snprintf(reason, sizeof reason, "%s", mica_error_message());
  const char *status = NULL;
  double reached =
      root && mica_json_get_string(summary, "status", &status) == MICA_SUCCESS && !strcmp(status, "failed");
  mica_error_clear(); /* from here every rank passes each agreement point with a fresh code */
  int ierr = mica_parallel_broadcast(MICA_SUCCESS, &reached, 1, 0);
  if (!ierr && reached && root) {
    ierr = publish(staging, outdir, summary, start, "partial results (the converged load steps)");
    if (ierr) mica_error_prefix("%s; the results it reached were not published", reason);
  }
  MICA_CALL(mica_parallel_agree(ierr));
  return mica_parallel_agree(mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_NUMERIC, "%s", reason));
}

/* Loads the deck, runs the command into a staging directory, publishes on success. Under MPI every rank
 * loads the deck and runs the command; rank 0 alone writes the results; the ranks agree on the outcome
 * after loading, after the command and at the end, so they all exit with the same status. */
static int run_command(const Invocation *inv) {
  MicaDeck *deck = NULL;
  MicaJson *summary = NULL;
  char *outdir = NULL;
  MicaStaging *staging = NULL;
  int ierr = MICA_SUCCESS;
  const int root = mica_parallel_rank() == 0;
  const double start = mica_wtime();
  ierr = mica_deck_load(inv->deck_path, inv->command->schema, inv->noverrides, inv->overrides, &deck);
  if (!ierr) ierr = mica_parallel_inject("deck");
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  ierr = prepare_outdir(inv, deck, &outdir, &staging);
  if (mica_parallel_active()) ierr = mica_parallel_share_dir(ierr, root && !ierr ? mica_staging_dir(staging) : NULL);
  if (!ierr) ierr = mica_json_create(&summary);
  if (!ierr) ierr = mica_json_string(summary, "status", "ok");
  if (!ierr) ierr = mica_json_string(summary, "command", inv->command->type.name);
  if (!ierr) ierr = mica_json_string(summary, "deck", inv->deck_path);
  if (!ierr && mica_parallel_active()) ierr = mica_json_int(summary, "ranks", mica_parallel_size());
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  ierr = inv->command->run(deck, mica_staging_dir(staging), summary);
  if (!ierr) ierr = mica_parallel_inject("output");
  ierr = mica_parallel_agree(ierr);
  if (ierr == MICA_ERR_NUMERIC) ierr = publish_reached(staging, outdir, summary, start);
  MICA_CALL_CLEANUP(ierr);
  if (root) ierr = publish(staging, outdir, summary, start, "results");
cleanup:
  ierr = mica_parallel_agree(ierr); /* every rank passes here once more: a failure of rank 0's publishing */
  mica_parallel_unshare_dir();
  mica_staging_destroy(&staging); /* the staging directory of a failed run, the old results of a good one */
  free(outdir);
  mica_json_destroy(&summary);
  mica_deck_destroy(&deck);
  return ierr;
}

int main(int argc, char **argv) {
  Invocation inv = {0};
  if (MICA_MALLOC(inv.overrides, argc)) {
    mica_error_report("mica");
    return 1;
  }
  inv.room = argc;
  int done, status = parse_arguments(argc, argv, &inv, &done);
  if (done || status) {
    free(inv.overrides);
    return status;
  }
  /* MPI starts only under a launcher (mpirun sets these): a plain `mica` run is one serial process and
   * pays neither MPI's start-up time nor its one-time allocations. */
  const int launched = getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
  if (launched) {
    MPI_Init(&argc, &argv);
    mica_parallel_start();
    /* PETSc once, on every rank, now: collective, and a rank group (sweeps) may not all create a solver; a
     * serial run starts it only if it creates one (src/solve/linear_petsc.c) */
    if (mica_petsc_initialize()) mica_parallel_abort("mica", 1);
  }
  int ierr = run_command(&inv);
  /* an error every rank agreed on is reported once, by rank 0; any other ends every rank at once */
  if (ierr && !mica_parallel_error_agreed()) mica_parallel_abort("mica", mica_exit_status(ierr));
  if (ierr && mica_parallel_rank() == 0) mica_error_report("mica");
  mica_petsc_finalize();
  if (launched) MPI_Finalize();
  free(inv.overrides);
  return mica_exit_status(ierr);
}
