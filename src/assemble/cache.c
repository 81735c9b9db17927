/* The shape-function cache of a total-Lagrangian analysis: N, ∇N and, for second-gradient models, ∇∇N of
 * the supporting particles at every quadrature point, computed once (docs/architecture.md). Stored in CSR form so
 * that assembly streams through it. */
#include <stdlib.h>
#include <string.h>

#include "mica/solid.h"

/* Appends one point's shape functions, growing the arrays geometrically. */
static int append_point(MicaShapeCache *c, const MlsShape *sh, long p, long *cap) {
  const long start = c->ptr[p], need = start + sh->n;
  if (need > *cap) {
    long grown = *cap ? 2 * *cap : 1024;
    while (grown < need) grown *= 2;
    MICA_CALL(MICA_REALLOC(c->index, grown));
    MICA_CALL(MICA_REALLOC(c->N, grown));
    MICA_CALL(MICA_REALLOC(c->dN, grown * c->dim));
    if (c->order >= 2) MICA_CALL(MICA_REALLOC(c->ddN, grown * mls_num_hess(c->dim)));
    *cap = grown;
  }
  for (long k = 0; k < sh->n; k++) {
    c->index[start + k] = sh->index[k];
    c->N[start + k] = sh->N[k];
    for (int d = 0; d < c->dim; d++) c->dN[(start + k) * c->dim + d] = sh->dN[d * sh->n + k];
    if (c->order >= 2)
      for (int h = 0, nh = mls_num_hess(c->dim); h < nh; h++) c->ddN[(start + k) * nh + h] = sh->ddN[h * sh->n + k];
  }
  c->ptr[p + 1] = need;
  if (sh->n > c->max_support) c->max_support = sh->n;
  if (p == 0 || sh->rcond < c->rcond_min) c->rcond_min = sh->rcond;
  return MICA_SUCCESS;
}

int mica_shape_cache_create(const MlsApprox *mls, long npoints, const double *x, int order, const char *label,
                            MicaShapeCache **out) {
  *out = NULL;
  MicaShapeCache *c = NULL;
  MlsShape *sh = NULL;
  int ierr = MICA_SUCCESS;
  long cap = 0;
  MICA_CALL(MICA_CALLOC(c, 1));
  c->dim = mls_dim(mls);
  c->order = order >= 2 ? 2 : 1;
  c->npoints = npoints;
  MICA_CALL_CLEANUP(MICA_CALLOC(c->ptr, npoints + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(c->x, npoints * c->dim + 1));
  memcpy(c->x, x, sizeof(double) * (size_t)(npoints * c->dim));
  MICA_CALL_CLEANUP(mls_shape_create(mls, &sh));
  for (long p = 0; p < npoints; p++) {
    ierr = mls_eval(mls, x + p * c->dim, c->order >= 2 ? MLS_HESSIAN : MLS_GRADIENT, sh);
    if (ierr) {
      mica_error_prefix("%s point %ld of %ld", label, p + 1, npoints);
      goto cleanup;
    }
    MICA_CALL_CLEANUP(append_point(c, sh, p, &cap));
  }
  c->time_search = sh->time_search;
  *out = c;
  c = NULL;
cleanup:
  mls_shape_destroy(&sh);
  mica_shape_cache_destroy(&c);
  return ierr;
}

MicaShapeCache *mica_shape_cache_share(MicaShapeCache *cache) {
  cache->shares++;
  return cache;
}

int mica_shape_cache_alloc(int dim, long npoints, long nnz, int with_test, MicaShapeCache **cache) {
  MicaShapeCache *c = NULL;
  MICA_CALL(MICA_CALLOC(c, 1));
  *cache = c;
  c->dim = dim, c->order = 1, c->npoints = npoints;
  MICA_CALL(MICA_CALLOC(c->ptr, npoints + 1));
  MICA_CALL(MICA_MALLOC(c->x, npoints * dim + 1));
  MICA_CALL(MICA_MALLOC(c->index, nnz + 1));
  MICA_CALL(MICA_MALLOC(c->N, nnz + 1));
  MICA_CALL(MICA_MALLOC(c->dN, nnz * dim + 1));
  if (with_test) MICA_CALL(MICA_MALLOC(c->dN_test, nnz * dim + 1));
  return MICA_SUCCESS;
}

int mica_shape_cache_destroy(MicaShapeCache **cache) {
  if (!*cache) return MICA_SUCCESS;
  if ((*cache)->shares > 0) { /* another holder still uses it */
    (*cache)->shares--;
    *cache = NULL;
    return MICA_SUCCESS;
  }
  MICA_FREE((*cache)->ptr);
  MICA_FREE((*cache)->x);
  MICA_FREE((*cache)->index);
  MICA_FREE((*cache)->N);
  MICA_FREE((*cache)->dN);
  MICA_FREE((*cache)->ddN);
  MICA_FREE((*cache)->dN_test);
  MICA_FREE(*cache);
  return MICA_SUCCESS;
}

size_t mica_shape_cache_bytes(const MicaShapeCache *c) {
  if (!c) return 0;
  const size_t entries = (size_t)c->ptr[c->npoints];
  const size_t per_entry =
      (size_t)(1 + c->dim + (c->order >= 2 ? mls_num_hess(c->dim) : 0) + (c->dN_test ? c->dim : 0));
  return (sizeof(long) + sizeof(double) * (size_t)c->dim) * (size_t)(c->npoints + 1) +
         entries * (sizeof(long) + sizeof(double) * per_entry);
}

/* ---- MLS as an approximation (EFG) ---- */

static int mls_points(const void *ctx, long npoints, const double *x, const long *cell, int order, const char *label,
                      MicaShapeCache **cache) {
  (void)cell; /* MLS needs no cell: supports come from the neighbor search */
  return mica_shape_cache_create(ctx, npoints, x, order, label, cache);
}

static int mls_at_particles(const void *ctx, int order, MicaShapeCache **cache) {
  const MlsApprox *mls = ctx;
  return mica_shape_cache_create(mls, mls_num_particles(mls), mls_particles(mls), order, "output at particle", cache);
}

static const double *mls_particle_spacing(const void *ctx) { return mls_spacing(ctx); }

const MicaApproxOps mica_approx_mls = {
    {"efg", "MLS shape functions (element-free Galerkin), C¹ and smoother: Hessians", MICA_APPROX_MLS, NULL, NULL},
    2, mls_points, mls_at_particles, mls_particle_spacing};
