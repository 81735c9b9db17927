/* The pieces of the `mica` program: the invocation that its arguments describe, the tables that declare
 * its options, the parser that reads arguments against a table (options.c, on glibc's getopt_long) and
 * the help texts made from the same tables (help.c), so that help and parser cannot disagree. */
#ifndef MICA_CLI_H
#define MICA_CLI_H

#include <stdio.h>

#include "mica/command_registry.h"

#define MICA_VERSION "0.1.0"

enum {
  CLI_WIDTH = 100, /* every help text fits a terminal this many columns wide */
  CLI_USAGE = 2,   /* exit status of a bad command line, as of bad input (docs/input.md) */
  CLI_STOP = -1    /* a word handler's "stop here" */
};

typedef struct {
  const MicaCommand *command;
  const char *deck_path;
  const char *outdir; /* NULL: out/<deck name> */
  const char **overrides; /* room for one per argument: no --set is ever turned away */
  int noverrides, room;
  int help, version; /* asked for; the parser stops at either */
  int markdown;       /* mica help --markdown <command>: the deck settings as docs/input.md's table */
  const char *group;  /* ... --group GROUP: only the settings under GROUP (NULL: all) */
} Invocation;

/* One option: --name (and -letter), its value's name or none, and what applying it does. */
typedef struct {
  const char *name;   /* "output": --output */
  int letter;         /* 'o': -o; 0: no short form */
  const char *value;  /* "DIR" in the help; NULL: the option takes no value */
  int repeatable;     /* shown as [--set PATH=VALUE]... */
  const char *help;   /* what it does, for the help text */
  int (*apply)(Invocation *inv, const char *who, const char *value); /* 0, or prints why and CLI_USAGE */
} CliOption;

/* A table of options ends with {NULL}. */
extern const CliOption cli_program_options[]; /* mica --help, --version */
extern const CliOption cli_command_options[]; /* every command's: --output, --set, --help */
extern const CliOption cli_help_options[];    /* mica help's: --markdown, --group */

/* Reads argv[1..argc) against options, applying each option in order; argv[0] is only skipped. A word
 * (an argument that is no option, and everything after "--") goes to word(), which returns 0 to go on,
 * CLI_STOP to stop there (then *stopped = its index in argv) or an exit status. Stops at an option that
 * asks for help or the version. Returns 0 or CLI_USAGE, having printed "<who>: " and why. */
int cli_parse(int argc, char **argv, const char *who, const CliOption *options, Invocation *inv,
              int (*word)(Invocation *inv, const char *who, const char *arg), int *stopped);

/* "-o, --output DIR" and its help, one option a line, the help wrapped in a column of its own. */
void cli_print_options(const CliOption *options, FILE *out);
/* "[-o DIR] [--set PATH=VALUE]..." (the help option left out) */
void cli_print_option_synopsis(const CliOption *options, FILE *out);
/* The closest of candidates (NULL-terminated) to word, if close enough to suggest, else NULL. */
const char *cli_closest(const char *word, const char *const *candidates);

/* `mica --help`: usage, the commands, the options (help.c). */
void cli_print_program_help(FILE *out);
/* `mica help <command>` and `mica <command> --help`: usage, description, options, deck settings. */
int cli_print_command_help(const MicaCommand *command, FILE *out); /* an error code */
/* `mica help --markdown [--group GROUP] <command>`: the command's deck settings (those under group, NULL:
 * all) as a Markdown table, the tables of docs/input.md (docs/gen_input_tables.sh). An error code. */
int cli_print_command_markdown(const MicaCommand *command, const char *group, FILE *out);
/* "usage: mica run [-o DIR] [--set PATH=VALUE]... [--] DECK" */
void cli_print_command_usage(const MicaCommand *command, FILE *out);

#endif
