/* Stabilized conforming nodal integration, SCNI (docs/theory.md §nodal integration; Chen, Wu, Yoon & You
 * 2001, IJNME 50): the gradient used in particle I's nodal cell Ω_I is the cell average of the MLS gradient,
 * turned into a boundary integral by the divergence theorem,
 *   ∇̃N_J(x_I) = (1/|Ω_I|) ∫_∂Ω_I N_J n dΓ ≈ (1/|Ω_I|) Σ_b N_J(x_b) (w n)_b,
 * over the Gauss points b of the cell's faces (disc->nodal). No derivative of N is taken. Because neighboring
 * cells share their faces' points with opposite normals, Σ_I |Ω_I| ∇̃N_J(x_I) telescopes to the boundary sum
 * Σ_∂Ω w N_J n, the discrete divergence identity that the linear patch test needs. The cache's supports at x_I
 * are the union of the supports of x_I and of the cell's boundary points; N is N_J(x_I). */
#include <stdlib.h>
#include <string.h>

#include "mica/solid.h"
#include "mica/sort.h"

/* One cell's union of supports, accumulated: slot[J] is J's position in the list or −1. */
typedef struct {
  long n, cap;
  long *index;   /* [cap] particles in the union */
  double *N;     /* [cap] N_J(x_I) (0 where x_I is outside J's support) */
  double *g;     /* [cap*dim] Σ_b N_J(x_b) (w n)_b, then divided by |Ω_I| */
  long *slot;    /* [nparticles] */
} Union;

static int union_grow(Union *u, int dim, long need) {
  if (need <= u->cap) return MICA_SUCCESS;
  long cap = u->cap ? 2 * u->cap : 64;
  while (cap < need) cap *= 2;
  MICA_CALL(MICA_REALLOC(u->index, cap));
  MICA_CALL(MICA_REALLOC(u->N, cap));
  MICA_CALL(MICA_REALLOC(u->g, cap * dim));
  u->cap = cap;
  return MICA_SUCCESS;
}

/* Adds the support of one evaluation: N_J at x_I (wn == NULL) or N_J (w n)_b at a boundary point. */
static int union_add(Union *u, int dim, const MlsShape *sh, const double *wn) {
  MICA_CALL(union_grow(u, dim, u->n + sh->n));
  for (long k = 0; k < sh->n; k++) {
    const long J = sh->index[k];
    if (u->slot[J] < 0) {
      u->slot[J] = u->n;
      u->index[u->n] = J;
      u->N[u->n] = 0.0;
      memset(&u->g[u->n * dim], 0, sizeof(double) * (size_t)dim);
      u->n++;
    }
    const long e = u->slot[J];
    if (!wn)
      u->N[e] = sh->N[k];
    else
      for (int d = 0; d < dim; d++) u->g[e * dim + d] += sh->N[k] * wn[d];
  }
  return MICA_SUCCESS;
}

/* Appends the union as point I of the cache (ascending particle indices), scaled by 1/|Ω_I|, and clears the
 * slots for the next cell. */
static int append_cell(MicaShapeCache *c, Union *u, long I, double volume, long *cap) {
  const int dim = c->dim;
  const long start = c->ptr[I], need = start + u->n;
  if (need > *cap) {
    long grown = *cap ? 2 * *cap : 1024;
    while (grown < need) grown *= 2;
    MICA_CALL(MICA_REALLOC(c->index, grown));
    MICA_CALL(MICA_REALLOC(c->N, grown));
    MICA_CALL(MICA_REALLOC(c->dN, grown * dim));
    *cap = grown;
  }
  memcpy(c->index + start, u->index, sizeof(long) * (size_t)u->n);
  qsort(c->index + start, (size_t)u->n, sizeof(long), mica_compare_long);
  for (long k = 0; k < u->n; k++) {
    const long e = u->slot[c->index[start + k]];
    c->N[start + k] = u->N[e];
    for (int d = 0; d < dim; d++) c->dN[(start + k) * dim + d] = u->g[e * dim + d] / volume;
  }
  for (long k = 0; k < u->n; k++) u->slot[u->index[k]] = -1;
  c->ptr[I + 1] = need;
  if (u->n > c->max_support) c->max_support = u->n;
  u->n = 0;
  return MICA_SUCCESS;
}

/* The smoothing of one cell: MLS values at x_I and at each of its boundary points. */
static int smooth_cell(const MicaDiscretization *disc, const MlsApprox *mls, long I, MlsShape *sh, Union *u) {
  const int dim = disc->dim;
  const MicaNodalCells *cells = disc->nodal;
  int ierr = mls_eval(mls, disc->qx + I * dim, MLS_VALUES, sh);
  if (ierr) {
    mica_error_prefix("SCNI: particle %ld", I + 1);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  MICA_CALL(union_add(u, dim, sh, NULL));
  for (long b = cells->ptr[I]; b < cells->ptr[I + 1]; b++) {
    ierr = mls_eval(mls, cells->x + b * dim, MLS_VALUES, sh);
    if (ierr) {
      mica_error_prefix("SCNI: boundary point %ld of the nodal cell of particle %ld", b - cells->ptr[I] + 1, I + 1);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
    MICA_CALL(union_add(u, dim, sh, cells->wn + b * dim));
  }
  return MICA_SUCCESS;
}

int mica_scni_cache_create(const MicaDiscretization *disc, const MlsApprox *mls, MicaShapeCache **out) {
  *out = NULL;
  MICA_CHECK(disc->nodal && disc->nodal->n == disc->nquad, MICA_ERR_ARGUMENT,
             "mica_scni_cache_create: the discretization has no nodal cells (mica_discretization_nodal)");
  const int dim = disc->dim;
  const long np = disc->nquad;
  MicaShapeCache *c = NULL;
  MlsShape *sh = NULL;
  Union u = {0};
  long cap = 0;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(c, 1));
  c->dim = dim, c->order = 1, c->npoints = np;
  MICA_CALL_CLEANUP(MICA_CALLOC(c->ptr, np + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(c->x, np * dim + 1));
  memcpy(c->x, disc->qx, sizeof(double) * (size_t)(np * dim));
  MICA_CALL_CLEANUP(MICA_MALLOC(u.slot, mls_num_particles(mls)));
  for (long J = 0; J < mls_num_particles(mls); J++) u.slot[J] = -1;
  MICA_CALL_CLEANUP(mls_shape_create(mls, &sh));
  for (long I = 0; I < np; I++) {
    MICA_CALL_CLEANUP(smooth_cell(disc, mls, I, sh, &u));
    MICA_CALL_CLEANUP(append_cell(c, &u, I, disc->qw[I], &cap));
  }
  *out = c;
  c = NULL;
cleanup:
  mls_shape_destroy(&sh);
  mica_shape_cache_destroy(&c);
  MICA_FREE(u.index);
  MICA_FREE(u.N);
  MICA_FREE(u.g);
  MICA_FREE(u.slot);
  return ierr;
}
