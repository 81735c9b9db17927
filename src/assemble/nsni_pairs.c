/* NSNI's paired rule (docs/theory.md §NSNI, "the paired rule"), for a field model whose energy is not quadratic
 * and has no fixed linear form to stabilize with (finite-rotation Cosserat). NSNI integrates the energy over
 * particle I's nodal cell with the kinematics expanded to first order, q(x) ≈ q_I + (x − x_I)·∇q; along each of the
 * dim directions g_k of the cell's second moments (Σ_k w_k g_k ⊗ g_k = M_I, nsni.c), q_I ± h_k q̇_k with
 * q̇_k = ∂_g q are the expanded kinematics at x_I ± h_k g_k. The rule
 *   ∫_Ω_I W ≈ Σ_k c [W(q_I + h_k q̇_k) + W(q_I − h_k q̇_k)],   c = |Ω_I| / (2 dim),   h_k² = dim w_k / |Ω_I|,
 * has the right zeroth and second moments: its sum is 2 dim c W(q_I) + Σ_k c h_k² q̇_kᵀ ∂²W q̇_k + O(h⁴) =
 * |Ω_I| W(q_I) + ½ Σ_k w_k q̇_kᵀ ∂²W q̇_k, which for a quadratic W is NSNI's energy exactly (tests/unit/test_nsni.c
 * compares the two), and which for any W is that energy with the model's own second derivatives at q_I. Each point
 * is a state of the model, so its residual and tangent are the kernel's, exact, and an objective W stays objective
 * point by point. The points' shape functions are linear in the nodal and stabilization points' ones:
 *   N± = N_J(x_I) ± h ∂_g N_J,   ∇N± = ∇N_J(x_I) ± h H_J g   (test gradients: VCI's ∇̃N_J(x_I) ± h H_J g). */
#include <math.h>
#include <string.h>

#include "mica/solid.h"

/* Points 2p (+) and 2p + 1 (−) from stabilization point p of cell I: the stabilization point's supports, with the
 * nodal point's entries found by merging the two ascending index lists (a particle outside the nodal support has
 * N_J(x_I) = 0 and ∇N_J(x_I) = 0 there). */
static void fill_pair(const MicaShapeCache *vol, const MicaNsni *n, long p, long I, double h, MicaShapeCache *c) {
  const MicaShapeCache *st = n->cache;
  const int dim = vol->dim;
  const long start = st->ptr[p], count = st->ptr[p + 1] - start, plus = 2 * p, minus = 2 * p + 1;
  long e_vol = vol->ptr[I];
  const long end_vol = vol->ptr[I + 1];
  c->ptr[plus + 1] = c->ptr[plus] + count;
  c->ptr[minus] = c->ptr[plus + 1], c->ptr[minus + 1] = c->ptr[minus] + count;
  for (int d = 0; d < dim; d++) {
    c->x[plus * dim + d] = st->x[p * dim + d] + h * n->dir[p * dim + d];
    c->x[minus * dim + d] = st->x[p * dim + d] - h * n->dir[p * dim + d];
  }
  for (long j = 0; j < count; j++) {
    const long e = start + j, J = st->index[e], ep = c->ptr[plus] + j, em = c->ptr[minus] + j;
    while (e_vol < end_vol && vol->index[e_vol] < J) e_vol++;
    const int in_volume = e_vol < end_vol && vol->index[e_vol] == J;
    const double N = in_volume ? vol->N[e_vol] : 0.0;
    c->index[ep] = c->index[em] = J;
    c->N[ep] = N + h * st->N[e], c->N[em] = N - h * st->N[e];
    for (int d = 0; d < dim; d++) {
      const double g = in_volume ? vol->dN[e_vol * dim + d] : 0.0, hg = h * st->dN[e * dim + d];
      c->dN[ep * dim + d] = g + hg, c->dN[em * dim + d] = g - hg;
      if (c->dN_test) {
        const double t = in_volume ? vol->dN_test[e_vol * dim + d] : 0.0;
        c->dN_test[ep * dim + d] = t + hg, c->dN_test[em * dim + d] = t - hg;
      }
    }
  }
}

/* Every nodal entry must be among the stabilization point's (the Hessians' supports hold the nodal ones: the same
 * MLS, or a quadratic fit with wider radii, nsni.c), or its terms would fall outside the pattern. */
static int check_nested(const MicaShapeCache *vol, const MicaShapeCache *st, long p, long I) {
  long e = st->ptr[p];
  for (long v = vol->ptr[I]; v < vol->ptr[I + 1]; v++) {
    while (e < st->ptr[p + 1] && st->index[e] < vol->index[v]) e++;
    MICA_CHECK(e < st->ptr[p + 1] && st->index[e] == vol->index[v], MICA_ERR_NUMERIC,
               "NSNI's paired rule: particle %ld is in the support of nodal point %ld but not in its stabilization "
               "point's", vol->index[v] + 1, I + 1);
  }
  return MICA_SUCCESS;
}

int mica_nsni_pairs_create(MicaNsni *n, const MicaShapeCache *volume, const double *volume_w) {
  const MicaShapeCache *st = n->cache;
  const int dim = st->dim;
  MICA_CHECK(volume->npoints * dim == st->npoints && volume->dim == dim, MICA_ERR_ARGUMENT,
             "mica_nsni_pairs_create: %ld nodal points for %ld stabilization points", volume->npoints, st->npoints);
  MICA_CALL(mica_shape_cache_alloc(dim, 2 * st->npoints, 2 * st->ptr[st->npoints], volume->dN_test != NULL, &n->pairs));
  MICA_CALL(MICA_MALLOC(n->pair_w, 2 * st->npoints));
  for (long p = 0; p < st->npoints; p++) {
    const long I = p / dim;
    MICA_CHECK(volume_w[I] > 0, MICA_ERR_NUMERIC, "NSNI's paired rule: nodal cell %ld has no volume", I + 1);
    MICA_CALL(check_nested(volume, st, p, I));
    const double c = volume_w[I] / (2 * dim), h = sqrt(dim * n->w[p] / volume_w[I]);
    fill_pair(volume, n, p, I, h, n->pairs);
    n->pair_w[2 * p] = n->pair_w[2 * p + 1] = c;
  }
  n->pairs->max_support = st->max_support;
  n->pairs->rcond_min = st->rcond_min;
  return MICA_SUCCESS;
}
