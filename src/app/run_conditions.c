/* The conditions of a run deck (docs/input.md "bcs", "loads", "exact"): the named boundary sets they act on, the
 * unknowns and tractions they name (which the model decides), the boundary method, the body force and the
 * exact solution. run.c builds the problem from them. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"

static int find_set(const MicaDeck *deck, const MicaDiscretization *disc, const char *path, int *set) {
  const char *name;
  MICA_CALL(mica_deck_string(deck, path, &name));
  *set = mica_discretization_find_set(disc, name);
  if (*set >= 0) return MICA_SUCCESS;
  char where[256], names[512];
  const char *shape;
  mica_deck_where(deck, path, where, sizeof where);
  MICA_CALL(mica_deck_string(deck, "geometry.shape", &shape));
  if (disc->nsets == 0 && !strcmp(shape, "gmsh")) {
    const char *mesh, *kind = disc->dim == 2 ? "Curve" : "Surface";
    MICA_CALL(mica_deck_string(deck, "geometry.mesh", &mesh));
    MICA_ERROR(MICA_ERR_INPUT,
               "%s: there is no boundary set '%s': the mesh %s has no physical groups of dimension %d, and boundary "
               "conditions name them. Add one to the .geo, e.g. Physical %s(\"%s\") = {4}; for %s 4 (or in Gmsh's "
               "window: Geometry > Physical groups > Add), and mesh again",
               where, name, mesh, disc->dim - 1, kind, name, disc->dim == 2 ? "curve" : "surface");
  }
  mica_discretization_set_names(disc, names, sizeof names);
  MICA_ERROR(MICA_ERR_INPUT, "%s: there is no boundary set '%s'; this body has: %s", where, name, names);
}

/* The model's named components of a list element (prefix.[i].<name>: "ux", "phiz", "tx", "mz", ...); returns
 * the mask of those given. A name the schema knows but this model lacks ("uz" in 2-D, "phiz" for a
 * classical model) is an error naming it. */
static int read_components(const MicaDeck *deck, const char *element, const char *const *names,
                           const char *const *all_names, MicaFunction **f, int *mask) {
  *mask = 0;
  for (int c = 0; names[c]; c++) {
    char path[160];
    snprintf(path, sizeof path, "%s.%s", element, names[c]);
    if (!mica_deck_has(deck, path)) continue;
    MICA_CALL(mica_deck_function(deck, path, &f[c]));
    *mask |= 1 << c;
  }
  for (int k = 0; all_names[k]; k++) {
    int known = 0;
    for (int c = 0; names[c]; c++) known |= !strcmp(names[c], all_names[k]);
    char path[160], where[256];
    snprintf(path, sizeof path, "%s.%s", element, all_names[k]);
    if (known || !mica_deck_has(deck, path)) continue;
    mica_deck_where(deck, path, where, sizeof where);
    MICA_ERROR(MICA_ERR_INPUT, "%s: %s is not an unknown (or load) of this model in this dimension", where,
               all_names[k]);
  }
  return MICA_SUCCESS;
}

static const char *const ALL_UNKNOWNS[] = {"ux", "uy", "uz", "phix", "phiy", "phiz", "ur", "utheta", "phir", "phitheta", NULL};
static const char *const ALL_TRACTIONS[] = {"tx", "ty", "tz", "mx", "my", "mz", "tr", "ttheta", "mr", "mtheta", NULL};

/* Axisymmetric solids name their cylindrical components (r, θ, z) of the model's 3-D vectors. */
static const char *const CYLINDRICAL_UNKNOWNS[] = {"ur", "utheta", "uz", "phir", "phitheta", "phiz", NULL};
static const char *const CYLINDRICAL_TRACTIONS[] = {"tr", "ttheta", "tz", "mr", "mtheta", "mz", NULL};

int run_model_dim(const RunProblem *rp) { return rp->axisymmetric ? 3 : rp->disc->dim; }

/* The deck's names of the model's ncomp unknowns (or of their conjugate tractions), NULL-terminated. */
int run_model_names(const RunProblem *rp, const MicaFieldModel *m, int traction, const char **names) {
  const int dim = run_model_dim(rp);
  const char *const *all = rp->axisymmetric ? (traction ? CYLINDRICAL_TRACTIONS : CYLINDRICAL_UNKNOWNS)
                           : traction       ? m->ops->traction_names(dim)
                                            : m->ops->component_names(dim);
  const int n = m->ops->ncomp(dim);
  for (int c = 0; c < n; c++) names[c] = all[c];
  names[n] = NULL;
  return n;
}

const char *run_unknown_name(const RunProblem *rp, int c) {
  const char *names[MICA_MAX_COMP + 1];
  run_model_names(rp, &rp->solid->opt.field, 0, names);
  return names[c];
}

/* Element i of a list of conditions (bcs.dirichlet, bcs.traction): its deck line (into where), its boundary set
 * and the components it gives, of the model's names (all: every name the schema knows). */
static int read_condition(const MicaDeck *deck, const MicaDiscretization *disc, const char *list, int i,
                          const char *const *names, const char *const *all, char (*where)[160], int *set,
                          MicaFunction **value, int *mask) {
  char element[64], path[96];
  snprintf(element, sizeof element, "%s.[%d]", list, i);
  snprintf(path, sizeof path, "%s.set", element);
  mica_deck_where(deck, path, *where, sizeof *where);
  MICA_CALL(find_set(deck, disc, path, set));
  return read_components(deck, element, names, all, value, mask);
}

int run_read_dirichlet(const MicaDeck *deck, const RunProblem *rp, const MicaFieldModel *m, int *count,
                       MicaDirichlet **out) {
  const char *names[MICA_MAX_COMP + 1];
  run_model_names(rp, m, 0, names);
  *count = mica_deck_list_length(deck, "bcs.dirichlet");
  MICA_CALL(MICA_CALLOC(*out, *count > 0 ? *count : 1));
  for (int i = 0; i < *count; i++) {
    MicaDirichlet *c = &(*out)[i];
    MICA_CALL(read_condition(deck, rp->disc, "bcs.dirichlet", i, names, ALL_UNKNOWNS, &c->where, &c->set, c->value,
                             &c->mask));
    MICA_CHECK(c->mask, MICA_ERR_INPUT, "%s: this condition prescribes nothing; give %s, %s, ...", c->where, names[0],
               names[1]);
  }
  return MICA_SUCCESS;
}

int run_read_tractions(const MicaDeck *deck, const RunProblem *rp, const MicaFieldModel *m, int *count,
                       MicaTraction **out) {
  const char *names[MICA_MAX_COMP + 1];
  run_model_names(rp, m, 1, names);
  *count = mica_deck_list_length(deck, "bcs.traction");
  MICA_CALL(MICA_CALLOC(*out, *count > 0 ? *count : 1));
  for (int i = 0, mask; i < *count; i++) {
    MicaTraction *c = &(*out)[i];
    MICA_CALL(read_condition(deck, rp->disc, "bcs.traction", i, names, ALL_TRACTIONS, &c->where, &c->set, c->value,
                             &mask));
  }
  return MICA_SUCCESS;
}

/* Body loads by unknown: loads.b<axis> for a displacement u<axis>, loads.c<axis> for a micro-rotation
 * phi<axis> (a body couple); <axis> is x, y, z or, axisymmetric, r, theta, z. */
int run_read_body_force(const MicaDeck *deck, const RunProblem *rp, const MicaFieldModel *m, MicaFunction **body) {
  const char *names[MICA_MAX_COMP + 1];
  const int ncomp = run_model_names(rp, m, 0, names);
  for (int c = 0; c < ncomp; c++) {
    char path[32];
    const int rotation = names[c][0] == 'p'; /* "phix": a couple; "ux": a force */
    snprintf(path, sizeof path, "loads.%c%s", rotation ? 'c' : 'b', names[c] + (rotation ? 3 : 1));
    if (mica_deck_has(deck, path)) MICA_CALL(mica_deck_function(deck, path, &body[c]));
  }
  return MICA_SUCCESS;
}

int run_read_bc_method(const MicaDeck *deck, MicaSolidOptions *opt) {
  MicaSettings settings;
  mica_deck_settings(deck, &settings);
  MICA_CALL(mica_bc_method_from_settings(&settings, opt)); /* bc.method, and its bc.alpha */
  MICA_CALL(mica_deck_bool(deck, "solver.ramp", &opt->ramp));
  return MICA_SUCCESS;
}

/* The exact solution, one expression per unknown of the model (exact.ux, exact.phiz, ...), and its
 * gradient by symbolic differentiation. */
int run_read_exact(const MicaDeck *deck, RunProblem *rp, const MicaFieldModel *m) {
  const int dim = rp->disc->dim;
  const char *names[MICA_MAX_COMP + 1];
  rp->ncomp = run_model_names(rp, m, 0, names);
  for (int c = 0; c < rp->ncomp; c++) {
    char path[32];
    snprintf(path, sizeof path, "exact.%s", names[c]);
    if (!mica_deck_has(deck, path)) continue;
    MICA_CALL(mica_deck_function(deck, path, &rp->exact[c]));
    for (int J = 0; J < dim; J++) MICA_CALL(mica_function_derivative(rp->exact[c], J, &rp->exact_grad[c][J]));
    rp->has_exact = 1;
  }
  if (rp->has_exact)
    for (int c = 0; c < rp->ncomp; c++) {
      char where[256];
      mica_deck_where(deck, "exact", where, sizeof where);
      MICA_CHECK(rp->exact[c], MICA_ERR_INPUT, "%s: an exact solution needs every unknown (%s is missing)", where,
                 names[c]);
    }
  return MICA_SUCCESS;
}
