/* The deck of `mica sweep`: a run deck (every setting of mica_run_schema) plus the `sweep` group. The run
 * schema is copied at program start rather than repeated here, so a setting added to `mica run` is
 * sweepable at once. */
#include <stdio.h>
#include <stdlib.h>

#include "run.h"
#include "sweep.h"

#define NOLIMIT 1.0, 0.0

static const MicaDeckKey sweep_keys[] = {
    {"sweep.parameters", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 1, 0,
     "the swept settings: ( { path = \"parameters.L\"; values = [4.0, 8.0]; }, ... ); any scalar setting of the run deck"},
    {"sweep.parameters.[].path", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0,
     "the setting swept: \"parameters.L\", \"mls.dilation\", \"material.model\", ..."},
    {"sweep.parameters.[].values", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 1, SWEEP_MAX_POINTS,
     "its values: numbers, or expressions of the deck's parameters"},
    {"sweep.parameters.[].words", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0,
     "... or, for a string setting, its values as words: \"linear, svk\""},
    {"sweep.parameters.[].range", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 2, 2,
     "... or the first and last of `points` values spaced by `scale`"},
    {"sweep.parameters.[].points", MICA_KEY_INT, NULL, 2, SWEEP_MAX_POINTS, NULL, 0, 0, "number of values of a range"},
    {"sweep.parameters.[].scale", MICA_KEY_CHOICE, "\"linear\"", NOLIMIT, "linear|log", 0, 0,
     "spacing of a range: equal differences or equal ratios"},
    {"sweep.mode", MICA_KEY_CHOICE, "\"grid\"", NOLIMIT, "grid|zip", 0, 0,
     "grid: every combination of the values; zip: the i-th values together (equal numbers of values)"},
    {"sweep.probe", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0,
     "the probe charted (an output.probes name; default: the first)"},
    {"sweep.x", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0,
     "the swept path on the chart's x axis (default: the first numeric one); the other paths make the curves"},
    {"sweep.analytic", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 0, 0,
     "reference curves: ( { name = \"beam\"; f = \"P*x^3/(3*E*I)\"; }, ... )"},
    {"sweep.analytic.[].name", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0, "legend of the curve"},
    {"sweep.analytic.[].f", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0,
     "the curve as an expression of x (the swept x value) and the deck's parameters"},
    {"sweep.experiments", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 0, 0,
     "measured points: ( { name = \"Lam et al. 2003\"; file = \"data/epoxy.csv\"; }, ... )"},
    {"sweep.experiments.[].name", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0, "legend of the points"},
    {"sweep.experiments.[].file", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0,
     "CSV of x,y rows (other lines are skipped), relative to the deck's directory"},
    {"sweep.logx", MICA_KEY_BOOL, "false", NOLIMIT, NULL, 0, 0, "logarithmic x axis"},
    {"sweep.logy", MICA_KEY_BOOL, "false", NOLIMIT, NULL, 0, 0, "logarithmic y axis (only positive values show)"},
    {"sweep.chart", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0, "draw sweep.png and sweep.svg with gnuplot"},
    {"sweep.classical", MICA_KEY_STRING, "\"linear\"", NOLIMIT, NULL, 0, 0,
     "when material.model is swept: the model the others are compared with"},
    {"sweep.tolerance", MICA_KEY_FLOAT, "0.01", 0, 1e300, NULL, 0, 0,
     "... a model agrees with it where |probe / probe_classical - 1| <= tolerance"},
    {NULL, 0, NULL, 0, 0, NULL, 0, 0, NULL},
};

MicaDeckKey mica_sweep_schema[SWEEP_SCHEMA_MAX];

static int count_keys(const MicaDeckKey *keys) {
  int n = 0;
  while (keys[n].path) n++;
  return n;
}

/* mica_command_sweep.schema must be a constant address filled before main() loads a deck: the copy is
 * made by a constructor (GCC and Clang) into a static array. */
__attribute__((constructor)) static void sweep_schema_build(void) {
  const int nrun = count_keys(mica_run_schema), nsweep = count_keys(sweep_keys);
  if (nrun + nsweep + 1 > SWEEP_SCHEMA_MAX) {
    fprintf(stderr, "mica: the sweep schema needs %d keys; raise SWEEP_SCHEMA_MAX in src/study/sweep.h\n",
            nrun + nsweep + 1);
    abort();
  }
  for (int i = 0; i < nrun; i++) mica_sweep_schema[i] = mica_run_schema[i];
  for (int i = 0; i <= nsweep; i++) mica_sweep_schema[nrun + i] = sweep_keys[i]; /* with the terminator */
}
