/* The mls.* settings, declared once for every command that builds an MLS approximation (run, check, sweep,
 * study, stability, mls; docs/input.md), and read into MlsOptions with their cross-checks. The weight's
 * own settings (mls.alpha of the exponential weight) come from its registry (weight.c); the basis, support,
 * search and spacing choices and their defaults from theirs (basis.c, kinds.c). */
#include "mica/mls.h"


MICA_SCHEMA_TABLES

const MicaDeckKey mls_keys[] = {
    {.path = "basis", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mls_basis_registry,
     .help = "polynomial basis: complete (pascal) or tensor product (lagrange, bernstein)"},
    {"order", MICA_KEY_INT, "1", 0, 3, NULL, 0, 0, "basis order: pascal 0-3, lagrange and bernstein 1-3"},
    {.path = "weight", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mls_weight_registry,
     .help = "weight function (docs/theory.md §weights)"},
    {.path = "support", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mls_support_registry,
     .help = "support shape: box (radius per axis) or ball"},
    {"radius", MICA_KEY_FLOATS, NULL, 1e-12, 1e12, NULL, 1, 3,
     "absolute support radius (one value, or one per axis for box supports)"},
    {"dilation", MICA_KEY_FLOAT, NULL, 1e-3, 1e3, NULL, 0, 0,
     "support radius as a multiple of the local particle spacing (default: order + 1)"},
    {.path = "spacing", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mls_spacing_registry,
     .help = "the local spacing mls.dilation multiplies, per axis: near, the nearer neighbor's distance; far, the "
     "farther side's (if at most twice the nearer), for graded clouds (docs/theory.md §supports)"},
    {"rcond_min", MICA_KEY_FLOAT, "1e-13", 0, 1e-2, NULL, 0, 0,
     "a moment matrix with a smaller reciprocal condition number is an error"},
    {.path = "search", .type = MICA_KEY_CHOICE, .min = 1.0, .max = 0.0, .registry = &mls_search_registry,
     .help = "neighbor search structure"},
    {NULL},
};

/* The type a chooser names, from its registry. */
static int read_type(const MicaSettings *s, const char *group, const char *name, const MicaRegistry *registry,
                     const MicaType **type) {
  const char *word;
  MICA_CALL(mica_settings_string(s, group, name, &word));
  return mica_registry_get(registry, word, type);
}

static int read_choices(const MicaSettings *s, const char *group, MlsOptions *opt) {
  const MicaType *type;
  MICA_CALL(read_type(s, group, "basis", &mls_basis_registry, &type));
  opt->basis = mls_basis_of(type);
  MICA_CALL(read_type(s, group, "support", &mls_support_registry, &type));
  opt->support = (MlsSupportKind)mls_kind_value(type);
  MICA_CALL(read_type(s, group, "search", &mls_search_registry, &type));
  opt->search = (MlsSearchKind)mls_kind_value(type);
  MICA_CALL(read_type(s, group, "spacing", &mls_spacing_registry, &type));
  opt->spacing = (MlsSpacingRule)mls_kind_value(type);
  MICA_CALL(read_type(s, group, "weight", &mls_weight_registry, &type));
  opt->weight = mls_weight_of(type);
  if (type->from_settings) MICA_CALL(type->from_settings(type, s, group, opt));
  return MICA_SUCCESS;
}

static int read_order(const MicaSettings *s, const char *group, MlsOptions *opt) {
  long order;
  MICA_CALL(mica_settings_int(s, group, "order", &order));
  opt->order = (int)order;
  char where[256];
  mica_settings_where(s, group, "order", where, sizeof where);
  MICA_CHECK(order >= opt->basis->min_order && order <= opt->basis->max_order, MICA_ERR_INPUT,
             "%s: the %s basis has orders %d to %d, not %ld", where, opt->basis->type.name, opt->basis->min_order,
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
    opt->dilation = mls_default_dilation(opt->order);
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
