/* Commands of the `mica` program, a registry of types (mica/registry.h): each names its deck schema and runs
 * one study or solve on a checked deck, writing into outdir and adding its results to the summary. Adding a
 * command is one new file in src/app that fills one MicaCommand and one line in src/cli/commands.c. */
#ifndef MICA_COMMAND_H
#define MICA_COMMAND_H

#include "mica/deck.h"
#include "mica/json.h"
#include "mica/registry.h"

typedef struct MicaCommand {
  MicaType type;           /* name "mls"; description: one line for `mica --help` */
  const char *text;        /* a paragraph for `mica help <command>` */
  const MicaDeckKey *schema;
  int (*run)(const MicaDeck *deck, const char *outdir, MicaJson *summary);
} MicaCommand;

extern const MicaCommand mica_command_mls, mica_command_run, mica_command_check, mica_command_sweep,
    mica_command_study;
extern const MicaCommand mica_command_stability;

/* The registry of the program's commands is src/cli's (mica/command_registry.h). */

#endif
