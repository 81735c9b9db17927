/* Naturally stabilized nodal integration, NSNI (docs/theory.md §NSNI; Hillman & Chen, IJNME 107 (2016)): the
 * kinematics q of every field are expanded to first order over particle I's nodal cell,
 *   q(x) ≈ q(x_I) + (x − x_I) · ∇q(x_I),
 * and the cell's energy of a quadratic W(q) = ½ qᵀ D q integrated with the cell's moments about x_I, the first
 * ones dropped (Hillman–Chen: x_I near the centroid), the second ones M_I = ∫_Ω_I (x − x_I) ⊗ (x − x_I) dV kept:
 *   ∫_Ω_I W ≈ |Ω_I| W(q(x_I)) + ½ Σ_de M_I,de q_,dᵀ D q_,e.
 * With M_I = L Lᵀ (Cholesky) the second term is Σ_k w_k W(g_k · ∇q), g_k = L_·k / |L_·k|, w_k = |L_·k|²: dim
 * stabilization points per particle whose "shape functions" are the directional derivatives of the MLS ones,
 *   N ← g_k · ∇N_J(x_I),   ∇N ← ∇(g_k · ∇N_J)(x_I) = H_J(x_I) g_k   (H: the MLS Hessian),
 * so the assembly's generic loop gives their residual and tangent exactly (no body load there). */
#include <lapacke.h> /* it includes complex.h, whose macro I rules out that name: particles are `part` */
#include <math.h>
#include <string.h>

#include "mica/solid.h"

/* M = L Lᵀ (LAPACK, lower, row-major) for the cell's SPD second moments; a cell whose M is not positive definite is
 * an error. */
static int cholesky_small(int dim, const double *M, double *L, long particle) {
  memcpy(L, M, sizeof(double) * (size_t)(dim * dim));
  const lapack_int info = LAPACKE_dpotrf_work(LAPACK_ROW_MAJOR, 'L', dim, L, dim);
  MICA_CHECK(info == 0, MICA_ERR_INPUT,
             "NSNI: the nodal cell of particle %ld has second moments that are not positive definite (a cell sampled "
             "by too few background Gauss points: raise quadrature.order or quadrature.cells)", particle + 1);
  for (int i = 0; i < dim; i++)
    for (int j = i + 1; j < dim; j++) L[i * dim + j] = 0.0; /* the upper part is M's */
  return MICA_SUCCESS;
}

/* The directions and weights of particle I's dim stabilization points from its cell's second moments. */
static int particle_directions(const MicaNodalCells *cells, int dim, long part, double *dir, double *w) {
  double L[9];
  MICA_CALL(cholesky_small(dim, cells->moment + part * dim * dim, L, part));
  for (int k = 0; k < dim; k++) {
    double len2 = 0.0;
    for (int d = 0; d < dim; d++) len2 += L[d * dim + k] * L[d * dim + k];
    w[k] = len2;
    for (int d = 0; d < dim; d++) dir[k * dim + d] = L[d * dim + k] / sqrt(len2);
  }
  return MICA_SUCCESS;
}

static int nsni_alloc(MicaNsni *n, int dim, long np, long nnz, int with_gradients) {
  MICA_CALL(mica_shape_cache_alloc(dim, np * dim, nnz * dim, 0, &n->cache));
  MICA_CALL(MICA_MALLOC(n->w, np * dim));
  MICA_CALL(MICA_MALLOC(n->dir, np * dim * dim));
  if (with_gradients) MICA_CALL(MICA_MALLOC(n->grad, nnz * dim * dim + 1));
  return MICA_SUCCESS;
}

/* Point I·dim + k from the MLS values at x_I (cache h, order 2): the entries of every supporting J (and, for the
 * frame-invariant form, their gradients ∇N_J(x_I) from the same fit as the Hessians). */
static void fill_point(const MicaShapeCache *h, long part, int k, const double *g, MicaNsni *nsni) {
  MicaShapeCache *c = nsni->cache;
  const int dim = h->dim, nh = mls_num_hess(dim);
  const long p = part * dim + k, start = c->ptr[p], n = h->ptr[part + 1] - h->ptr[part];
  memcpy(c->x + p * dim, h->x + part * dim, sizeof(double) * (size_t)dim);
  for (long j = 0; j < n; j++) {
    const long e = h->ptr[part] + j, out = start + j;
    c->index[out] = h->index[e];
    double N = 0.0;
    for (int d = 0; d < dim; d++) N += g[d] * h->dN[e * dim + d];
    c->N[out] = N;
    if (nsni->grad) memcpy(nsni->grad + out * dim, h->dN + e * dim, sizeof(double) * (size_t)dim);
    for (int d = 0; d < dim; d++) {
      double v = 0.0;
      for (int f = 0; f < dim; f++) v += h->ddN[e * nh + mls_hess_index(dim, d, f)] * g[f];
      c->dN[out * dim + d] = v;
    }
  }
  c->ptr[p + 1] = start + n;
}

/* The Hessians the stabilization points take: the MLS ones for a basis of order ≥ 2; for order 1 those of a
 * quadratic basis on the same particles and weight, with the radii 3/2 as wide (the default dilations' ratio,
 * 3 : 2: a quadratic fit needs six particles in 2-D, which a linear basis's supports do not always hold on
 * irregular particles). A linear basis's own second derivatives do not converge (order 2 of an order-1
 * approximation) and on jittered particles they left an L2 floor (7e-4 on manufactured.cfg, docs/verification.md
 * §NSNI); the quadratic fit's is consistent, and zero on linear fields as the linear basis's is, so the linear
 * patch test is unaffected. Its supports are wider than the volume points': the solid's pattern includes them. */
double mica_nsni_hessian_reach(int basis_order) { return basis_order >= 2 ? 1.0 : 1.5; }

static int hessian_cache(const MicaDiscretization *disc, const MlsApprox *mls, MicaShapeCache **h) {
  if (mls_options(mls)->order >= 2) return mica_shape_cache_create(mls, disc->nquad, disc->qx, 2, "NSNI", h);
  MlsOptions opt = *mls_options(mls);
  MlsApprox *quadratic = NULL;
  opt.order = 2;
  MICA_CALL(mls_create(disc->dim, mls_num_particles(mls), mls_particles(mls), &opt, &quadratic));
  const long n = mls_num_particles(mls) * disc->dim;
  double *radii = NULL;
  int ierr = MICA_MALLOC(radii, n);
  for (long i = 0; !ierr && i < n; i++) radii[i] = mica_nsni_hessian_reach(1) * mls_radii(mls)[i];
  if (!ierr) ierr = mls_set_radii(quadratic, radii);
  if (!ierr) ierr = mls_set_spacing(quadratic, mls_spacing(mls));
  if (!ierr) ierr = mica_shape_cache_create(quadratic, disc->nquad, disc->qx, 2, "NSNI (quadratic Hessians)", h);
  MICA_FREE(radii);
  mls_destroy(&quadratic);
  return ierr;
}

int mica_nsni_create(const MicaDiscretization *disc, const MlsApprox *mls, int with_gradients, MicaNsni **out) {
  *out = NULL;
  MICA_CHECK(disc->nodal && disc->nodal->moment && disc->nquad == disc->nodal->n, MICA_ERR_ARGUMENT,
             "mica_nsni_create: the discretization has no nodal cells (mica_discretization_nodal)");
  const int dim = disc->dim;
  const long np = disc->nquad; /* cells: with distributed data the rank's, not its ghosts */
  MicaShapeCache *h = NULL;
  MicaNsni *n = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(hessian_cache(disc, mls, &h));
  MICA_CALL_CLEANUP(MICA_CALLOC(n, 1));
  MICA_CALL_CLEANUP(nsni_alloc(n, dim, np, h->ptr[np], with_gradients));
  for (long part = 0; part < np; part++) {
    MICA_CALL_CLEANUP(particle_directions(disc->nodal, dim, part, n->dir + part * dim * dim, n->w + part * dim));
    for (int k = 0; k < dim; k++) fill_point(h, part, k, n->dir + (part * dim + k) * dim, n);
  }
  n->cache->max_support = h->max_support;
  n->cache->rcond_min = h->rcond_min;
  n->cache->time_search = h->time_search;
  *out = n;
  n = NULL;
cleanup:
  mica_shape_cache_destroy(&h);
  mica_nsni_destroy(&n);
  return ierr;
}

int mica_nsni_destroy(MicaNsni **nsni) {
  if (!nsni || !*nsni) return MICA_SUCCESS;
  mica_shape_cache_destroy(&(*nsni)->cache);
  MICA_FREE((*nsni)->w);
  MICA_FREE((*nsni)->dir);
  MICA_FREE((*nsni)->grad);
  mica_shape_cache_destroy(&(*nsni)->pairs);
  MICA_FREE((*nsni)->pair_w);
  MICA_FREE(*nsni);
  return MICA_SUCCESS;
}
