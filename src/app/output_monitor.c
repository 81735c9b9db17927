/* output.monitor: the progress of the solve on stdout, one line per Newton iteration. Newton prints it as it
 * iterates (mica_newton_solve's verbose option, which run.c's read_newton sets from this key), so the type has no
 * ops: it declares the setting, among the other outputs. */
#include "run.h"

MICA_SCHEMA_TABLES

static const MicaDeckKey monitor_keys[] = {
    {"monitor", MICA_KEY_BOOL, "true", 1.0, 0.0, NULL, 0, 0, "print one line per Newton iteration"},
    {NULL},
};

const MicaOutputOps run_output_monitor = {
    .type = {"monitor", "one line per Newton iteration on stdout, printed by the solver", 0, monitor_keys, NULL},
};
