/* The registry of commands: one line per command. */
#include "mica/command_registry.h"

static const MicaType *const builtin_commands[] = {
    &mica_command_run.type,   &mica_command_check.type, &mica_command_mls.type, &mica_command_sweep.type,
    &mica_command_study.type, &mica_command_stability.type, NULL};

MicaRegistry mica_command_registry = {"command", "run", builtin_commands, NULL, 0, NULL};

const MicaCommand *mica_command_find(const char *name) {
  return (const MicaCommand *)mica_registry_find(&mica_command_registry, name);
}

const MicaCommand *mica_command_at(int i) { return (const MicaCommand *)mica_registry_type(&mica_command_registry, i); }
