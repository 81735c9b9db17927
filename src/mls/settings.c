/* The mls.* settings, declared once for every command that builds an MLS approximation (run, check, sweep,
 * study, stability, mls; docs/input.md), and read into MlsOptions with their cross-checks. The weight's
 * own settings (mls.alpha of the exponential weight) come from its registry (weight.c). */
#include <string.h>

#include "mica/mls.h"

#define NOLIMIT 1.0, 0.0 /* min > max: no range check */

MICA_SCHEMA_TABLES

const MicaDeckKey mls_keys[] = {
    {"basis", MICA_KEY_CHOICE, "\"pascal\"", NOLIMIT, "pascal|lagrange|bernstein", 0, 0,
     "polynomial basis: complete (pascal) or tensor product (lagrange, bernstein)"},
    {"order", MICA_KEY_INT, "1", 0, 3, NULL, 0, 0, "basis order: pascal 0-3, lagrange and bernstein 1-3"},
    {.path = "weight", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mls_weight_registry,
     .help = "weight function (docs/theory.md §weights)"},
    {"support", MICA_KEY_CHOICE, "\"box\"", NOLIMIT, "box|ball", 0, 0, "support shape: box (radius per axis) or ball"},
    {"radius", MICA_KEY_FLOATS, NULL, 1e-12, 1e12, NULL, 1, 3,
     "absolute support radius (one value, or one per axis for box supports)"},
    {"dilation", MICA_KEY_FLOAT, NULL, 1e-3, 1e3, NULL, 0, 0,
     "support radius as a multiple of the local particle spacing (default: order + 1)"},
    {"spacing", MICA_KEY_CHOICE, "\"near\"", NOLIMIT, "near|far", 0, 0,
     "the local spacing mls.dilation multiplies, per axis: near, the nearer neighbor's distance; far, the "
     "farther side's (if at most twice the nearer), for graded clouds (docs/theory.md §supports)"},
    {"rcond_min", MICA_KEY_FLOAT, "1e-13", 0, 1e-2, NULL, 0, 0,
     "a moment matrix with a smaller reciprocal condition number is an error"},
    {"search", MICA_KEY_CHOICE, "\"kdtree\"", NOLIMIT, "kdtree|cells", 0, 0, "neighbor search structure"},
    {NULL},
};

static int read_choices(const MicaSettings *s, const char *group, MlsOptions *opt) {
  const char *name;
  MICA_CALL(mica_settings_string(s, group, "basis", &name));
  opt->basis = mls_basis_find(name);
  MICA_CALL(mica_settings_string(s, group, "weight", &name));
  opt->weight = mls_weight_find(name);
  MICA_CHECK(opt->basis && opt->weight, MICA_ERR_ARGUMENT, "schema and registry disagree on mls names");
  MICA_CALL(mica_settings_string(s, group, "support", &name));
  opt->support = strcmp(name, "ball") == 0 ? MLS_SUPPORT_BALL : MLS_SUPPORT_BOX;
  MICA_CALL(mica_settings_string(s, group, "search", &name));
  opt->search = strcmp(name, "cells") == 0 ? MLS_SEARCH_CELLS : MLS_SEARCH_KDTREE;
  MICA_CALL(mica_settings_string(s, group, "spacing", &name));
  opt->spacing = strcmp(name, "far") == 0 ? MLS_SPACING_FAR : MLS_SPACING_NEAR;
  const MicaType *weight = &opt->weight->type;
  if (weight->from_settings) MICA_CALL(weight->from_settings(weight, s, group, opt));
  return MICA_SUCCESS;
}

static int read_order(const MicaSettings *s, const char *group, MlsOptions *opt) {
  long order;
  MICA_CALL(mica_settings_int(s, group, "order", &order));
  opt->order = (int)order;
  char where[256];
  mica_settings_where(s, group, "order", where, sizeof where);
  MICA_CHECK(order >= opt->basis->min_order && order <= opt->basis->max_order, MICA_ERR_INPUT,
             "%s: the %s basis has orders %d to %d, not %ld", where, opt->basis->name, opt->basis->min_order,
             opt->basis->max_order, order);
  return MICA_SUCCESS;
}

/* mls.radius (absolute) or mls.dilation (times the spacing), not both; neither: dilation order + 1. */
static int read_radius(const MicaSettings *s, const char *group, int dim, MlsOptions *opt) {
  const int has_radius = mica_settings_has(s, group, "radius"), has_dilation = mica_settings_has(s, group, "dilation");
  char where[256];
  mica_settings_where(s, group, has_radius ? "radius" : "dilation", where, sizeof where);
  MICA_CHECK(!(has_radius && has_dilation), MICA_ERR_INPUT,
             "%s: give mls.radius (absolute) or mls.dilation (times the spacing), not both", where);
  opt->dilation = 0;
  if (has_radius) {
    int n;
    MICA_CALL(mica_settings_floats(s, group, "radius", opt->radius, 3, &n));
    MICA_CHECK(n == 1 || n == dim, MICA_ERR_INPUT, "%s: mls.radius needs 1 or %d values, not %d", where, dim, n);
    MICA_CHECK(n == 1 || opt->support == MLS_SUPPORT_BOX, MICA_ERR_INPUT,
               "%s: a ball support has one radius; give mls.radius as a single number", where);
  } else if (has_dilation) {
    MICA_CALL(mica_settings_float(s, group, "dilation", &opt->dilation));
  } else {
    opt->dilation = opt->order + 1.0;
  }
  return MICA_SUCCESS;
}

int mls_options_from_settings(const MicaSettings *settings, const char *group, int dim, MlsOptions *opt) {
  mls_options_default(opt);
  MICA_CALL(read_choices(settings, group, opt));
  MICA_CALL(read_order(settings, group, opt));
  MICA_CALL(mica_settings_float(settings, group, "rcond_min", &opt->rcond_min));
  MICA_CALL(read_radius(settings, group, dim, opt));
  return MICA_SUCCESS;
}
