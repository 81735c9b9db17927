/* output.probes: values of the final solution reported in summary.json (and printed), each a field at a point
 * or the strain energy of the whole body. Checked before the solve (the point in the body, or extrapolate =
 * true). Every rank computes them (the energy sums over the ranks' points); with parallel.data = "distributed" a
 * point probe is evaluated by the lowest rank holding its whole support (mica_owned_point_rank) and broadcast. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "run.h"

MICA_SCHEMA_TABLES

#define NOLIMIT 1.0, 0.0

static const MicaDeckKey probe_keys[] = {
    {"probes", MICA_KEY_LIST, NULL, NOLIMIT, NULL, 0, 0,
     "values reported in summary.json: ( { name = \"tip_uy\"; point = [\"L\", \"0\"]; field = \"uy\"; }, ... )"},
    {"probes.[].name", MICA_KEY_STRING, NULL, NOLIMIT, NULL, 0, 0, "key in summary.json"},
    {"probes.[].point", MICA_KEY_FLOATS, NULL, NOLIMIT, NULL, 2, 3,
     "where: in the body or on its boundary (else an error, unless extrapolate); not for energy"},
    {"probes.[].extrapolate", MICA_KEY_BOOL, "false", NOLIMIT, NULL, 0, 0,
     "allow a point outside the body: report the MLS approximation's value there (not with finite elements)"},
    {"probes.[].field", MICA_KEY_CHOICE, NULL, NOLIMIT,
     "ux|uy|uz|phix|phiy|phiz|exx|eyy|ezz|exy|eyz|exz|sxx|syy|szz|sxy|syx|syz|szy|sxz|szx|mxx|myy|mzz|mxy|myx|myz|mzy|mxz|mzx|mises|"
     "ur|utheta|phir|phitheta|srr|stt|srt|str|srz|szr|stz|szt|mrr|mtt|mrt|mtr|mrz|mzr|mtz|mzt|energy",
     0, 0, "an unknown (displacement, micro-rotation), a strain, a force stress s.. or couple stress m.. component "
     "(axisymmetric: axes r, t = θ, z), or energy: the strain energy ∫W dV of the whole body (no point)"},
    {"probes.[].scale", MICA_KEY_FLOAT, "1.0", NOLIMIT, NULL, 0, 0, "multiplies the value (e.g. \"1/p\")"},
    {"probes.[].inverse", MICA_KEY_BOOL, "false", NOLIMIT, NULL, 0, 0,
     "report scale / value instead (a stiffness from a displacement)"},
    {NULL},
};

/* Enabled when the deck lists probes. */
static int probes_from_settings(const MicaType *type, const MicaSettings *settings, const char *group,
                                void *options) {
  (void)type;
  ((MicaOutput *)options)->enabled = mica_settings_has(settings, group, "probes");
  return MICA_SUCCESS;
}

/* The value of a named field at a point: an unknown by its name ("ux", "phiz"), a strain e.., a force
 * stress s.. or couple stress m.. component (first index the one contracted with the normal; axes x, y, z or,
 * axisymmetric, r, t = θ, z), or mises. */
static double probe_field(const RunProblem *rp, const char *field, const double *q, const double *strain,
                          const double *sigma, const double *couple) {
  const char *axes = rp->axisymmetric ? "rtz" : "xyz";
  for (int c = 0; c < rp->solid->ncomp; c++)
    if (!strcmp(field, run_unknown_name(rp, c))) return q[c];
  if (!strcmp(field, "mises")) return run_von_mises(sigma);
  const double *tensor = field[0] == 'e' ? strain : field[0] == 'm' ? couple : sigma;
  const int i = (int)(strchr(axes, field[1]) - axes), j = (int)(strchr(axes, field[2]) - axes);
  return tensor[i * 3 + j];
}

/* Does this model (in this dimension, plain or axisymmetric) have the probe's field? */
static int probe_field_exists(const RunProblem *rp, const char *field) {
  const char *axes = rp->axisymmetric ? "rtz" : "xyz";
  for (int c = 0; c < rp->solid->ncomp; c++)
    if (!strcmp(field, run_unknown_name(rp, c))) return 1;
  if (!strcmp(field, "mises")) return 1;
  return (field[0] == 's' || field[0] == 'e' || field[0] == 'm') && strlen(field) == 3 && strchr(axes, field[1]) &&
         strchr(axes, field[2]);
}

/* The strain energy of the whole body, Σ_p w_p W(q_p) over the volume quadrature (with 2πr if axisymmetric). */
static int strain_energy(const RunProblem *rp, const double *u, double *energy) {
  const MicaSolid *s = rp->solid;
  double q[128], W;
  int ierr = MICA_SUCCESS;
  *energy = 0;
  for (long p = 0; p < s->volume->npoints && !ierr; p++) {
    mica_solid_kinematics(s, s->volume, p, u, q);
    ierr = s->opt.field.ops->eval(&s->opt.field, s->model_dim, q, &W, NULL, NULL);
    *energy += s->disc->qw[p] * W; /* s->disc: under MPI, this rank's points, summed below */
  }
  if (rp->dist) MICA_CALL(mica_parallel_sum(ierr, energy, 1));
  return ierr;
}

/* Probe i's point (dim coordinates) and where the deck gives it ("deck.cfg:LINE"). */
static int probe_point(const RunProblem *rp, int i, const char *name, double point[3], char *where, size_t size) {
  char path[96];
  int n = 0;
  snprintf(path, sizeof path, "output.probes.[%d].point", i);
  mica_deck_where(rp->deck, path, where, size);
  if (!mica_deck_has(rp->deck, path)) {
    snprintf(path, sizeof path, "output.probes.[%d]", i);
    mica_deck_where(rp->deck, path, where, size);
    MICA_ERROR(MICA_ERR_INPUT, "%s: probe '%s' needs a point (only field = \"energy\" has none)", where, name);
  }
  point[0] = point[1] = point[2] = 0;
  MICA_CALL(mica_deck_floats(rp->deck, path, point, 3, &n));
  MICA_CHECK(n == rp->disc->dim, MICA_ERR_INPUT, "%s: probe '%s' needs a point with %d coordinates", where, name,
             rp->disc->dim);
  return MICA_SUCCESS;
}

/* The field at a point from the shape functions there: a cache of one point, from the approximation (it finds the
 * element). */
static int probe_value(const RunProblem *rp, const char *name, const char *field, const double *point,
                       const char *where, const double *u, double *raw) {
  const MicaSolid *s = rp->solid;
  MicaShapeCache *c = NULL;
  int ierr = rp->approx.ops->points(rp->approx.ctx, 1, point, NULL, s->opt.field.ops->order, "probe", &c);
  if (ierr) {
    mica_error_prefix("%s: probe '%s'", where, name);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr == MICA_ERR_NUMERIC ? MICA_ERR_INPUT : ierr);
  }
  double q[128] = {0}, sigma[9], couple[9] = {0}, strain[9];
  mica_solid_kinematics(s, c, 0, u, q);
  mica_shape_cache_destroy(&c);
  MICA_CALL(run_stresses(rp, q, sigma, couple, strain));
  *raw = probe_field(rp, field, q, strain, sigma, couple);
  return MICA_SUCCESS;
}

/* The raw value of a point probe: the field at the deck's point. */
static int probe_at_point(RunProblem *rp, int i, const char *name, const char *field, const double *u, double *raw) {
  const MicaSolid *s = rp->solid;
  const int dim = rp->disc->dim;
  char where[256];
  double point[3];
  MICA_CALL(probe_point(rp, i, name, point, where, sizeof where));
  MICA_CHECK(probe_field_exists(rp, field), MICA_ERR_INPUT,
             "%s: probe '%s' asks for %s, which this model in %d-D%s does not have", where, name, field, dim,
             rp->axisymmetric ? " (axisymmetric: axes r, t, z)" : "");
  MICA_CHECK(!(field[0] == 'e' && strlen(field) == 3 && !s->opt.field.classical), MICA_ERR_INPUT,
             "%s: probe '%s': strains are reported for classical models only", where, name);
  MICA_CHECK(!rp->axisymmetric || point[0] > 0, MICA_ERR_INPUT,
             "%s: probe '%s': an axisymmetric probe needs r > 0 (the hoop terms divide by r)", where, name);
  if (!rp->owned_data) return probe_value(rp, name, field, point, where, u, raw);
  /* parallel.data = "distributed": the lowest rank holding the point's whole support answers */
  int root;
  int ierr = mica_owned_point_rank(rp->dist, point, &root);
  if (ierr) {
    mica_error_prefix("%s: probe '%s'", where, name);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  ierr = mica_parallel_rank() == root ? probe_value(rp, name, field, point, where, u, raw) : MICA_SUCCESS;
  return mica_parallel_broadcast(ierr, raw, 1, root);
}

static int probe_one(RunProblem *rp, int i, const double *u, MicaJson *summary) {
  const MicaDeck *deck = rp->deck;
  char path[96];
  const char *name, *field;
  double scale, raw;
  int inverse;
  snprintf(path, sizeof path, "output.probes.[%d].name", i);
  MICA_CALL(mica_deck_string(deck, path, &name));
  snprintf(path, sizeof path, "output.probes.[%d].field", i);
  MICA_CALL(mica_deck_string(deck, path, &field));
  snprintf(path, sizeof path, "output.probes.[%d].scale", i);
  MICA_CALL(mica_deck_float(deck, path, &scale));
  snprintf(path, sizeof path, "output.probes.[%d].inverse", i);
  MICA_CALL(mica_deck_bool(deck, path, &inverse));
  if (!strcmp(field, "energy"))
    MICA_CALL(strain_energy(rp, u, &raw));
  else
    MICA_CALL(probe_at_point(rp, i, name, field, u, &raw));
  MICA_CHECK(!inverse || raw != 0, MICA_ERR_NUMERIC, "probe '%s': %s is 0 at the point; it has no inverse", name, field);
  const double value = inverse ? scale / raw : scale * raw;
  MICA_CALL(mica_json_number(summary, name, value));
  printf("probe %s = %.10g\n", name, value);
  return MICA_SUCCESS;
}

/* "x in [0, 48], y in [-6, 6]" */
static void bounds_text(const MicaBody *body, char *buf, size_t size) {
  double lo[3], hi[3];
  size_t len = 0;
  mica_body_bounds(body, lo, hi);
  buf[0] = '\0';
  for (int d = 0; d < mica_body_dim(body) && len < size; d++)
    len += (size_t)snprintf(buf + len, size - len, "%s%c in [%g, %g]", d ? ", " : "", "xyz"[d], lo[d], hi[d]);
}

/* Probe i's point lies in the body (within MICA_BODY_TOLERANCE of its size), or the probe allows
 * extrapolation; extrapolate on a probe without a point, or with finite elements, is refused. */
static int check_probe_point(const RunProblem *rp, MicaBody *body, int i) {
  const char *name, *field;
  char path[96], where[256];
  int extrapolate;
  snprintf(path, sizeof path, "output.probes.[%d].name", i);
  MICA_CALL(mica_deck_string(rp->deck, path, &name));
  snprintf(path, sizeof path, "output.probes.[%d].field", i);
  MICA_CALL(mica_deck_string(rp->deck, path, &field));
  snprintf(path, sizeof path, "output.probes.[%d].extrapolate", i);
  MICA_CALL(mica_deck_bool(rp->deck, path, &extrapolate));
  mica_deck_where(rp->deck, path, where, sizeof where);
  if (!strcmp(field, "energy")) {
    MICA_CHECK(!extrapolate, MICA_ERR_INPUT,
               "%s: probe '%s': extrapolate is for a probe at a point; field = \"energy\" has none (remove it)", where,
               name);
    return MICA_SUCCESS;
  }
  MICA_CHECK(!(extrapolate && rp->fe), MICA_ERR_INPUT,
             "%s: probe '%s': extrapolate = true needs the MLS approximation; finite elements (problem.method = "
             "\"fe\") have no values outside their elements", where, name);
  double point[3];
  MICA_CALL(probe_point(rp, i, name, point, where, sizeof where));
  if (extrapolate) return MICA_SUCCESS;
  double inside = mica_body_contains(body, point);
  if (rp->owned_data && rp->dist->cells_mesh) MICA_CALL(mica_parallel_max(MICA_SUCCESS, &inside, 1)); /* any rank's part */
  if (inside > 0) return MICA_SUCCESS;
  char at[96], shape[600], bounds[256];
  if (rp->disc->dim == 3)
    snprintf(at, sizeof at, "(%g, %g, %g)", point[0], point[1], point[2]);
  else
    snprintf(at, sizeof at, "(%g, %g)", point[0], point[1]);
  mica_body_describe(body, shape, sizeof shape);
  bounds_text(body, bounds, sizeof bounds);
  MICA_ERROR(MICA_ERR_INPUT,
             "%s: probe '%s' at %s lies outside the body, %s (bounds %s); move it inside or onto the boundary, or "
             "set extrapolate = true in the probe to report the approximation's value there anyway",
             where, name, at, shape, bounds);
}

/* The body the probes' points must lie in: with distributed data on a Gmsh mesh the rank's part, whose bounds become
 * the whole body's (collective), so that no rank reads the whole mesh; else the deck's shape's. */
static int probe_body(const RunProblem *rp, MicaBody **body) {
  if (!(rp->owned_data && rp->dist->cells_mesh)) return run_body_create(rp->deck, body);
  MicaShapeSpec shape;
  char mesh[PATH_MAX];
  MICA_CALL(run_read_shape(rp->deck, &shape, mesh, sizeof mesh));
  int ierr = mica_body_create_part(&shape, rp->dist->cells_mesh, body);
  double bounds[6] = {0, 0, 0, 0, 0, 0}; /* −lower, upper */
  if (!ierr) mica_body_bounds(*body, bounds, bounds + 3);
  for (int d = 0; d < 3; d++) bounds[d] = -bounds[d];
  ierr = mica_parallel_max(ierr, bounds, 6);
  if (ierr) {
    mica_body_destroy(body);
    return ierr;
  }
  for (int d = 0; d < 3; d++) bounds[d] = -bounds[d];
  mica_body_set_bounds(*body, bounds, bounds + 3);
  return MICA_SUCCESS;
}

static int probes_check(MicaOutputRun *run, void *ctx) {
  (void)ctx;
  const RunProblem *rp = run->rp;
  const int count = mica_deck_list_length(rp->deck, "output.probes");
  if (count == 0) return MICA_SUCCESS;
  MicaBody *body = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(probe_body(rp, &body));
  for (int i = 0; i < count && !ierr; i++) ierr = check_probe_point(rp, body, i);
  mica_body_destroy(&body);
  return ierr;
}

static int probes_finish(MicaOutputRun *run, void *ctx, const double *u, MicaJson *summary) {
  (void)ctx;
  RunProblem *rp = run->rp;
  const int count = mica_deck_list_length(rp->deck, "output.probes");
  if (count == 0) return MICA_SUCCESS;
  for (int i = 0; i < count; i++) MICA_CALL(probe_one(rp, i, u, summary));
  return MICA_SUCCESS;
}

const MicaOutputOps run_output_probes = {
    .type = {"probes", "values of the final solution at points, or the strain energy, in summary.json",
             MICA_OUTPUT_AT_END, probe_keys, probes_from_settings},
    .check = probes_check,
    .finish = probes_finish,
};
