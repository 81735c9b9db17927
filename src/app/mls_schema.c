/* The deck of `mica mls`: every setting, its type, default, range and meaning (docs/input.md is generated
 * from this table by `mica help mls`). Names follow those of the run decks (docs/input.md). */
#include "mls_study.h"

MICA_SCHEMA_TABLES

#define NOLIMIT 1.0, 0.0 /* min > max: no range check */

const MicaDeckKey mica_mls_schema[] = {
    {"parameters", MICA_KEY_PARAMETERS, NULL, NOLIMIT, NULL, 0, 0,
     "named numbers (or expressions of earlier ones) usable in any numeric setting and expression"},
    {"problem.title", MICA_KEY_STRING, "\"\"", NOLIMIT, NULL, 0, 0, "a title for charts and the summary"},
    {"geometry.shape", MICA_KEY_CHOICE, "\"box\"", NOLIMIT, "box", 0, 0, "the domain: an axis-aligned box"},
    {"geometry.lower", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 1, 3,
     "lower corner of the box; its length sets the dimension (1, 2 or 3)"},
    {"geometry.upper", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 1, 3, "upper corner of the box"},
    {"particles.count", MICA_KEY_INTS, NULL, 2, 1e6, NULL, 1, 3,
     "particles per axis of the regular grid (one entry per dimension)"},
    {"particles.jitter", MICA_KEY_FLOAT, "0.0", 0, 0.45, NULL, 0, 0,
     "random shift of each interior particle, uniform in ±jitter × spacing per axis"},
    {"particles.seed", MICA_KEY_INT, "1", 0, 2147483647, NULL, 0, 0, "seed of the jitter"},
    {.path = "mls", .type = MICA_KEY_FRAGMENT, .fragment = mls_keys}, /* src/mls/settings.c */
    {"function.f", MICA_KEY_FUNCTION, NULL, NOLIMIT, NULL, 0, 0,
     "the target function of x, y, z (and the parameters); its derivatives are taken symbolically"},
    {"sample.axis", MICA_KEY_CHOICE, "\"x\"", NOLIMIT, "x|y|z", 0, 0,
     "the derivatives reported are d/daxis and d²/daxis²"},
    {"sample.line.from", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 1, 3, "start of the sample line"},
    {"sample.line.to", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 1, 3, "end of the sample line"},
    {"sample.line.samples", MICA_KEY_INT, "201", 2, 1e7, NULL, 0, 0, "evenly spaced samples on the line, ends included"},
    {"sample.volume.points", MICA_KEY_INT, "0", 0, 1e8, NULL, 0, 0,
     "random sample points, uniform in the box (0: none)"},
    {"sample.volume.seed", MICA_KEY_INT, "1", 0, 2147483647, NULL, 0, 0, "seed of the volume samples"},
    {"limits.mls_samples", MICA_KEY_INT, "1000000", 1, 1e8, NULL, 0, 0,
     "the most samples (line and volume together) a variant evaluates; more are refused before they are made"},
    {"study.variants", MICA_KEY_OVERLAY, NULL, NOLIMIT, NULL, 0, 0,
     "list of variants to compare: ( { name = \"...\"; mls = { order = 2; }; }, ... ), any settings"},
    {"study.repeat", MICA_KEY_INT, "3", 1, 1000, NULL, 0, 0,
     "times each variant's shape-function evaluation is repeated for timing (the fastest counts)"},
    {"output.chart", MICA_KEY_BOOL, "true", NOLIMIT, NULL, 0, 0, "draw the error chart with gnuplot (PNG and SVG)"},
    {NULL, 0, NULL, 0, 0, NULL, 0, 0, NULL},
};
