/* The registry of commands: one line per command. */
#include <string.h>

#include "mica/command.h"

static const MicaCommand *const commands[] = {&mica_command_run, &mica_command_check, &mica_command_mls, &mica_command_sweep, &mica_command_study, &mica_command_stability, NULL};

const MicaCommand *const *mica_commands(void) { return commands; }

const MicaCommand *mica_command_find(const char *name) {
  for (int i = 0; commands[i]; i++)
    if (strcmp(commands[i]->name, name) == 0) return commands[i];
  return NULL;
}
