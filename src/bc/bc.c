/* Boundary methods: the registry, and gathering a boundary quadrature point for them. */
#include <string.h>

#include "bc_private.h"

static const MicaType *const builtin_methods[] = {&mica_bc_penalty.type, &mica_bc_nitsche.type,
                                                  &mica_bc_lagrange.type, &mica_bc_collocation.type, NULL};

/* docs/verification.md says why nitsche is the default */
MicaRegistry mica_bc_method_registry = {"boundary method", "nitsche", builtin_methods, NULL, 0, NULL};

const MicaBoundaryMethodOps *mica_bc_method_find(const char *name) {
  return (const MicaBoundaryMethodOps *)mica_registry_find(&mica_bc_method_registry, name);
}

int bc_alpha_from_settings(const MicaType *type, const MicaSettings *settings, const char *group, void *options) {
  return mica_type_float(type, settings, group, "alpha", &((MicaSolidOptions *)options)->bc_alpha);
}

int mica_bc_method_from_settings(const MicaSettings *settings, MicaSolidOptions *opt) {
  const char *name;
  const MicaType *type;
  MICA_CALL(mica_settings_string(settings, "bc", "method", &name));
  MICA_CALL(mica_registry_get(&mica_bc_method_registry, name, &type));
  opt->bc_method = (const MicaBoundaryMethodOps *)type;
  opt->bc_alpha = 0.0;
  if (type->from_settings) MICA_CALL(type->from_settings(type, settings, "bc", opt));
  return MICA_SUCCESS;
}

int bc_point(const MicaSolid *s, const MicaDirichlet *c, long p, double t, const double *u, BcPoint *bp) {
  const int dim = s->dim, ncomp = s->ncomp;
  const MicaBoundarySet *set = &s->disc->sets[c->set];
  const MicaShapeCache *cache = s->boundary[c->set];
  const long start = cache->ptr[p];
  bp->n = cache->ptr[p + 1] - start;
  bp->index = cache->index + start;
  bp->N = cache->N + start;
  bp->dN = cache->dN + start * dim;
  bp->w = set->w[p];
  bp->h = s->boundary_h[c->set][p];
  memset(bp->x, 0, sizeof bp->x);
  memset(bp->normal, 0, sizeof bp->normal);
  memcpy(bp->x, set->x + p * dim, sizeof(double) * (size_t)dim);
  memcpy(bp->normal, set->normal + p * dim, sizeof(double) * (size_t)dim);
  const double scale = s->opt.ramp ? t : 1.0;
  for (int a = 0; a < MICA_MAX_COMP; a++) bp->uh[a] = bp->residual[a] = 0;
  for (long k = 0; k < bp->n; k++)
    for (int a = 0; a < ncomp; a++) bp->uh[a] += bp->N[k] * u[bp->index[k] * ncomp + a];
  for (int a = 0; a < ncomp; a++) {
    if (!(c->mask & (1 << a))) continue;
    double value;
    MICA_CALL(mica_function_eval_finite(c->value[a], "on the whole set", dim, bp->x, t, &value));
    bp->residual[a] = bp->uh[a] - scale * value;
  }
  return MICA_SUCCESS;
}
