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

int mica_nodal_points_of(int dim, long np, const double *x, const char *mine, long ng, const double *gx,
                         const double *gw, MicaNodalPoints *out) {
  Buckets B = {0};
  MicaNodalCells *c = NULL;
  double *qx = NULL, *qw = NULL, *first = NULL;
  long *slot = NULL, n = 0;
  int ierr = MICA_SUCCESS;
  memset(out, 0, sizeof *out);
  MICA_CALL_CLEANUP(MICA_MALLOC(slot, np + 1)); /* particle I's cell, or −1 */
  for (long I = 0; I < np; I++) slot[I] = !mine || mine[I] ? n++ : -1;
  MICA_CALL_CLEANUP(buckets_create(dim, np, x, &B));
  MICA_CALL_CLEANUP(MICA_CALLOC(c, 1));
  c->n = n;
  MICA_CALL_CLEANUP(MICA_CALLOC(c->ptr, n + 1)); /* no boundary points */
  MICA_CALL_CLEANUP(MICA_CALLOC(c->moment, n * dim * dim + 1));
  MICA_CALL_CLEANUP(MICA_CALLOC(qw, n + 1));
  MICA_CALL_CLEANUP(MICA_CALLOC(first, n * dim + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(qx, n * dim + 1));
  for (long g = 0; g < ng; g++) {
    const double *xg = gx + g * dim, w = gw[g];
    const long I = nearest(&B, x, xg), k = slot[I];
    if (k < 0) continue;
    double y[3];
    for (int d = 0; d < dim; d++) y[d] = xg[d] - x[I * dim + d];
    qw[k] += w;
    for (int d = 0; d < dim; d++) {
      first[k * dim + d] += w * y[d];
      for (int e = 0; e < dim; e++) c->moment[(k * dim + d) * dim + e] += w * y[d] * y[e];
    }
  }
  for (long I = 0; I < np; I++) {
    const long k = slot[I];
    if (k < 0) continue;
    const double *xi = x + I * dim;
    if (!(qw[k] > 0)) {
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                            "nodal cells from the Gauss points: the particle at (%g, %g, %g) is the nearest to no "
                            "background Gauss point; raise quadrature.order or quadrature.cells",
                            xi[0], xi[1], dim == 3 ? xi[2] : 0.0);
      goto cleanup;
    }
    for (int d = 0; d < dim; d++) qx[k * dim + d] = xi[d] + first[k * dim + d] / qw[k];
    for (int d = 0; d < dim; d++) /* about the centroid */
      for (int e = 0; e < dim; e++) c->moment[(k * dim + d) * dim + e] -= first[k * dim + d] * first[k * dim + e] / qw[k];
  }
  *out = (MicaNodalPoints){n, qx, qw, c};
  qx = qw = NULL, c = NULL;
cleanup:
  mica_nodal_cells_destroy(&c);
  MICA_FREE(qx);
  MICA_FREE(qw);
  MICA_FREE(first);
  MICA_FREE(slot);
  MICA_FREE(B.start);
  MICA_FREE(B.member);
  return ierr;
}

int mica_discretization_nodal_points_from(MicaDiscretization *disc, const char *mine, long ng, const double *gx,
                                          const double *gw) {
  MICA_CHECK(disc && !disc->nodal && disc->nquad > 0, MICA_ERR_ARGUMENT,
             "mica_discretization_nodal_points: no volume points, or nodal already");
  MicaNodalPoints cells;
  MICA_CALL(mica_nodal_points_of(disc->dim, disc->nparticles, disc->x, mine, ng, gx ? gx : disc->qx,
                                 gw ? gw : disc->qw, &cells));
  disc->ngauss = disc->nquad;
  disc->gauss_x = disc->qx, disc->gauss_w = disc->qw;
  disc->qx = cells.qx, disc->qw = cells.qw;
  MICA_FREE(disc->qcell);
  disc->nquad = disc->ncells = cells.n;
  disc->nodal = cells.cells;
  return MICA_SUCCESS;
}

int mica_discretization_nodal_points(MicaDiscretization *disc) {
  return mica_discretization_nodal_points_from(disc, NULL, disc ? disc->nquad : 0, NULL, NULL);
}
