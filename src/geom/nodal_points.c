/* Nodal cells without a particle grid (irregular layouts, Gmsh meshes), for NSNI (docs/theory.md §NSNI, "cells
 * from the Gauss points"): cell I is the set of background Gauss points whose nearest particle is I — a
 * Voronoi cell sampled by the background rule — so its volume and moments are the rule's sums,
 *   |Ω_I| = Σ_{g∈I} w_g,  S_I = Σ w_g (x_g − x_I),  M_I = Σ w_g (x_g − x_I) ⊗ (x_g − x_I),
 * exact for the sampled cell and tiling the body exactly (Σ_I |Ω_I| = Σ_g w_g). The cells have no boundary
 * points: SCNI cannot use them; NSNI needs only the volume, the centroid and the central second moments. The
 * nearest particle comes from a bucket grid of about one particle per bucket, searched in growing rings. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom_private.h"

typedef struct {
  int dim;
  long n[3], *start, *member; /* bucket b's particles: member[start[b] .. start[b+1]) */
  double lo[3], size[3];
} Buckets;

static long bucket_coord(const Buckets *B, int d, double x) {
  long k = (long)floor((x - B->lo[d]) / B->size[d]);
  return k < 0 ? 0 : k >= B->n[d] ? B->n[d] - 1 : k;
}

static long bucket_of(const Buckets *B, const double *x) {
  long b = 0;
  for (int d = B->dim - 1; d >= 0; d--) b = b * B->n[d] + bucket_coord(B, d, x[d]);
  return b;
}

static int buckets_create(int dim, long np, const double *x, Buckets *B) {
  double hi[3] = {0, 0, 0};
  *B = (Buckets){.dim = dim, .n = {1, 1, 1}};
  for (int d = 0; d < dim; d++) B->lo[d] = hi[d] = x[d];
  for (long i = 0; i < np; i++)
    for (int d = 0; d < dim; d++) B->lo[d] = fmin(B->lo[d], x[i * dim + d]), hi[d] = fmax(hi[d], x[i * dim + d]);
  const long per_axis = (long)ceil(pow((double)np, 1.0 / dim));
  long total = 1;
  for (int d = 0; d < dim; d++) {
    B->n[d] = per_axis;
    B->size[d] = (hi[d] - B->lo[d]) / per_axis;
    if (!(B->size[d] > 0)) B->size[d] = 1.0, B->n[d] = 1;
    total *= B->n[d];
  }
  MICA_CALL(MICA_CALLOC(B->start, total + 1));
  MICA_CALL(MICA_MALLOC(B->member, np));
  for (long i = 0; i < np; i++) B->start[bucket_of(B, x + i * dim) + 1]++;
  for (long b = 0; b < total; b++) B->start[b + 1] += B->start[b];
  long *fill = NULL;
  MICA_CALL(MICA_MALLOC(fill, total));
  memcpy(fill, B->start, sizeof(long) * (size_t)total);
  for (long i = 0; i < np; i++) B->member[fill[bucket_of(B, x + i * dim)]++] = i;
  free(fill);
  return MICA_SUCCESS;
}

/* The nearest particle to q: rings of buckets around q's until the ring lies beyond the best distance. */
static long nearest(const Buckets *B, const double *x, const double *q) {
  const int dim = B->dim;
  long c[3] = {0, 0, 0}, best = -1;
  double best2 = INFINITY, hmin = INFINITY;
  for (int d = 0; d < dim; d++) c[d] = bucket_coord(B, d, q[d]), hmin = fmin(hmin, B->size[d]);
  for (long r = 0;; r++) {
    const long lo[3] = {c[0] - r, c[1] - r, dim > 2 ? c[2] - r : 0}, hi[3] = {c[0] + r, c[1] + r, dim > 2 ? c[2] + r : 0};
    int any = 0;
    for (long k = lo[2]; k <= hi[2]; k++)
      for (long j = lo[1]; j <= hi[1]; j++)
        for (long i = lo[0]; i <= hi[0]; i++) {
          const long idx[3] = {i, j, k};
          int ring = 0, inside = 1;
          for (int d = 0; d < dim; d++) {
            ring |= idx[d] == lo[d] || idx[d] == hi[d];
            inside &= idx[d] >= 0 && idx[d] < B->n[d];
          }
          if (!ring || !inside) continue;
          any = 1;
          long b = 0;
          for (int d = dim - 1; d >= 0; d--) b = b * B->n[d] + idx[d];
          for (long m = B->start[b]; m < B->start[b + 1]; m++) {
            const long p = B->member[m];
            double d2 = 0;
            for (int d = 0; d < dim; d++) d2 += (x[p * dim + d] - q[d]) * (x[p * dim + d] - q[d]);
            if (d2 < best2 || (d2 == best2 && p < best)) best2 = d2, best = p;
          }
        }
    /* every bucket of a later ring is at least r·hmin away from q */
    if ((best >= 0 && r * hmin >= sqrt(best2)) || !any) return best;
  }
}

int mica_discretization_nodal_points(MicaDiscretization *disc) {
  MICA_CHECK(disc && !disc->nodal && disc->nquad > 0, MICA_ERR_ARGUMENT,
             "mica_discretization_nodal_points: no volume points, or nodal already");
  const int dim = disc->dim;
  const long np = disc->nparticles;
  Buckets B = {0};
  MicaNodalCells *c = NULL;
  double *qx = NULL, *qw = NULL, *first = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(buckets_create(dim, np, disc->x, &B));
  MICA_CALL_CLEANUP(MICA_CALLOC(c, 1));
  c->n = np;
  MICA_CALL_CLEANUP(MICA_CALLOC(c->ptr, np + 1)); /* no boundary points */
  MICA_CALL_CLEANUP(MICA_CALLOC(c->moment, np * dim * dim));
  MICA_CALL_CLEANUP(MICA_CALLOC(qw, np));
  MICA_CALL_CLEANUP(MICA_CALLOC(first, np * dim));
  MICA_CALL_CLEANUP(MICA_MALLOC(qx, np * dim));
  for (long g = 0; g < disc->nquad; g++) {
    const double *xg = disc->qx + g * dim, w = disc->qw[g];
    const long I = nearest(&B, disc->x, xg);
    double y[3];
    for (int d = 0; d < dim; d++) y[d] = xg[d] - disc->x[I * dim + d];
    qw[I] += w;
    for (int d = 0; d < dim; d++) {
      first[I * dim + d] += w * y[d];
      for (int e = 0; e < dim; e++) c->moment[(I * dim + d) * dim + e] += w * y[d] * y[e];
    }
  }
  for (long I = 0; I < np; I++) {
    const double *x = disc->x + I * dim;
    if (!(qw[I] > 0)) {
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                            "nodal cells from the Gauss points: particle %ld at (%g, %g, %g) is the nearest to no "
                            "background Gauss point; raise quadrature.order or quadrature.cells",
                            I + 1, x[0], x[1], dim == 3 ? x[2] : 0.0);
      goto cleanup;
    }
    for (int d = 0; d < dim; d++) qx[I * dim + d] = x[d] + first[I * dim + d] / qw[I];
    for (int d = 0; d < dim; d++) /* about the centroid */
      for (int e = 0; e < dim; e++) c->moment[(I * dim + d) * dim + e] -= first[I * dim + d] * first[I * dim + e] / qw[I];
  }
  disc->ngauss = disc->nquad;
  disc->gauss_x = disc->qx, disc->gauss_w = disc->qw;
  disc->qx = qx, disc->qw = qw, qx = qw = NULL;
  MICA_FREE(disc->qcell);
  disc->nquad = disc->ncells = np;
  disc->nodal = c, c = NULL;
cleanup:
  mica_nodal_cells_destroy(&c);
  MICA_FREE(qx);
  MICA_FREE(qw);
  MICA_FREE(first);
  MICA_FREE(B.start);
  MICA_FREE(B.member);
  return ierr;
}
