/* The program's commands (src/cli/commands.c): the registry of the MicaCommands of src/app (mica/command.h). */
#ifndef MICA_COMMAND_REGISTRY_H
#define MICA_COMMAND_REGISTRY_H

#include "mica/command.h"

/* run (the default), check, mls, sweep, study, stability */
extern MicaRegistry mica_command_registry;
const MicaCommand *mica_command_find(const char *name);
/* The i-th command (registry order), or NULL past the last. */
const MicaCommand *mica_command_at(int i);

#endif
