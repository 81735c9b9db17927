/* Dirichlet conditions by Nitsche's method, symmetric (docs/theory.md §boundary methods). For the set C of
 * prescribed components, r = u − ū on C, traction t = P n:
 *   Π_N = −∫ t·r dΓ + ½ ∫ β |r|² dΓ,   β = α E / h,
 * whose first variation gives the residual terms (test function v = N_k e_b)
 *   R_kb += −[b∈C] t_b N_k − Σ_{a∈C} A_aJbL N_k,L n_J r_a + β [b∈C] r_b N_k
 * and whose second variation the symmetric tangent
 *   K_kb,lc += −[b∈C] N_k A_bJcM n_J N_l,M − [c∈C] N_l A_cJbL n_J N_k,L + β [b∈C] δ_bc N_k N_l
 *              − N_k,L D_bLcM N_l,M,   D_bLcM = Σ_{a∈C} r_a n_J ∂A_aJbL/∂F_cM.
 * The last term is the consistent linearization at finite strain (it vanishes for linear models and as
 * r → 0); ∂A/∂F is taken by central differences of the model's tangent, dim² pairs of evaluations per
 * boundary point, so Newton keeps its quadratic convergence. */
#include <math.h>
#include <string.h>

#include "bc_private.h"

/* D_bLcM by central differences of A (step 1e-6): only finite-strain models need it. */
static int third_derivative(const MicaSolid *s, const MicaDirichlet *c, const BcPoint *bp, const double *F,
                            double *D) {
  const int dim = s->dim, d2 = dim * dim;
  const double step = 1e-6;
  double Fs[9], Ap[81], Am[81], W;
  for (int cM = 0; cM < d2; cM++) {
    memcpy(Fs, F, sizeof(double) * (size_t)d2);
    Fs[cM] += step;
    MICA_CALL(s->opt.field.classical->eval(&s->opt.field.material, dim, Fs, &W, NULL, Ap));
    Fs[cM] -= 2 * step;
    MICA_CALL(s->opt.field.classical->eval(&s->opt.field.material, dim, Fs, &W, NULL, Am));
    for (int bL = 0; bL < d2; bL++) {
      double sum = 0;
      for (int a = 0; a < dim; a++) {
        if (!(c->mask & (1 << a))) continue;
        for (int J = 0; J < dim; J++) {
          const int idx = (a * dim + J) * d2 + bL;
          sum += bp->residual[a] * bp->normal[J] * (Ap[idx] - Am[idx]) / (2 * step);
        }
      }
      D[bL * d2 + cM] = sum;
    }
  }
  return MICA_SUCCESS;
}

/* T_bc,L = Σ_J A_bJcL n_J: the traction's sensitivity to ∇u. */
static void traction_tangent(int dim, const double *A, const double *normal, double *T) {
  for (int b = 0; b < dim; b++)
    for (int c = 0; c < dim; c++)
      for (int L = 0; L < dim; L++) {
        double sum = 0;
        for (int J = 0; J < dim; J++) sum += A[((b * dim + J) * dim + c) * dim + L] * normal[J];
        T[(b * dim + c) * dim + L] = sum;
      }
}

static void nitsche_residual(int dim, int mask, const BcPoint *bp, const double *P, const double *T, double beta,
                             double *R) {
  double traction[3] = {0, 0, 0};
  for (int b = 0; b < dim; b++)
    for (int J = 0; J < dim; J++) traction[b] += P[b * dim + J] * bp->normal[J];
  for (long k = 0; k < bp->n; k++)
    for (int b = 0; b < dim; b++) {
      double r = 0;
      if (mask & (1 << b)) r += (beta * bp->residual[b] - traction[b]) * bp->N[k];
      /* Σ_{a∈C} A_aJbL n_J r_a N_k,L = Σ_a r_a T_ab,L N_k,L */
      for (int a = 0; a < dim; a++)
        if (mask & (1 << a))
          for (int L = 0; L < dim; L++) r -= bp->residual[a] * T[(a * dim + b) * dim + L] * bp->dN[k * dim + L];
      R[bp->index[k] * dim + b] += bp->w * r;
    }
}

/* The tangent block of a boundary point in O(n² dim²) multiply-adds, added to Ke (points sharing a support
 * share one scatter). First, per component b and supporting particle l, the traction in direction b of the
 * trial function N_l e_c, tN_b,lc = Σ_M T_bc,M N_l,M (stored b-major, so that row (k b)'s first term is one
 * contiguous axpy over (l c)), and at finite strain dD_k,b,cM = Σ_L N_k,L D_bLcM; then every row is an axpy,
 * an outer product and the diagonal β term. (The sums over M entry by entry were 38 % of a 3-D manufactured
 * NSNI solve.) tN holds n dim² and dD n dim³ doubles. */
static void nitsche_tangent(int dim, int mask, const BcPoint *bp, const double *T, const double *D, double beta,
                            double *Ke, double *tN, double *dD) {
  const long n = bp->n, m = n * dim;
  const int d2 = dim * dim;
  const double w = bp->w, *N = bp->N, *dN = bp->dN;
  for (int b = 0; b < dim; b++)
    for (long l = 0; l < n; l++)
      for (int c = 0; c < dim; c++) {
        double sum = 0;
        for (int M = 0; M < dim; M++) sum += T[(b * dim + c) * dim + M] * dN[l * dim + M];
        tN[b * m + l * dim + c] = sum;
      }
  if (D)
    for (long k = 0; k < n; k++)
      for (int b = 0; b < dim; b++)
        for (int cM = 0; cM < d2; cM++) {
          double sum = 0;
          for (int L = 0; L < dim; L++) sum += dN[k * dim + L] * D[(b * dim + L) * d2 + cM];
          dD[(k * dim + b) * d2 + cM] = sum;
        }
  for (long k = 0; k < n; k++)
    for (int b = 0; b < dim; b++) {
      double *row = Ke + (k * dim + b) * m;
      if (mask >> b & 1) { /* −[b∈C] N_k t_b(N_l e_c) + [b∈C] β δ_bc N_k N_l */
        const double wNk = w * N[k], *t = tN + b * m;
        for (long j = 0; j < m; j++) row[j] -= wNk * t[j];
        for (long l = 0; l < n; l++) row[l * dim + b] += beta * wNk * N[l];
      }
      double tk[3]; /* −[c∈C] N_l t_c(N_k e_b): an outer product of N and tk over (l c) */
      for (int c = 0; c < dim; c++) tk[c] = mask >> c & 1 ? w * tN[c * m + k * dim + b] : 0.0;
      for (long l = 0; l < n; l++)
        for (int c = 0; c < dim; c++) row[l * dim + c] -= N[l] * tk[c];
      if (D) { /* −N_k,L D_bLcM N_l,M */
        const double *dk = dD + (k * dim + b) * d2;
        for (long l = 0; l < n; l++)
          for (int c = 0; c < dim; c++) {
            double v = 0;
            for (int M = 0; M < dim; M++) v += dk[c * dim + M] * dN[l * dim + M];
            row[l * dim + c] -= w * v;
          }
      }
    }
}

static int same_support(long n, const long *index, const BcPoint *bp) {
  return n == bp->n && !memcmp(index, bp->index, sizeof(long) * (size_t)n);
}

/* Classical models through their kernel's P and A; other first-order field models through s and D
 * (nitsche_field.c). */
static int nitsche_add(MicaSolid *s, const MicaDirichlet *c, double t, const double *u, double *R, MicaSparse *K) {
  if (!mica_type_has(&s->opt.field.ops->type, MICA_FIELD_CLASSICAL)) return bc_nitsche_field_add(s, c, t, u, R, K);
  const int dim = s->dim;
  const MicaShapeCache *cache = s->boundary[c->set];
  double F[9], P[9], A[81], T[27], D[81], W;
  /* Consecutive points with the same support (those of one boundary cell, mostly) sum their blocks in Ke and
   * are scattered once: pending_n, pending_index name the support whose sum Ke holds. */
  long pending_n = 0;
  const long *pending_index = NULL;
  for (long p = 0; p < cache->npoints; p++) {
    BcPoint bp;
    MICA_CALL(bc_point(s, c, p, t, u, &bp));
    mica_solid_deformation_gradient(s, cache, p, u, F);
    int ierr = s->opt.field.classical->eval(&s->opt.field.material, dim, F, &W, P, A);
    if (ierr) {
      mica_error_prefix("boundary point %ld of set '%s'", p + 1, s->disc->sets[c->set].name);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
    traction_tangent(dim, A, bp.normal, T);
    const double beta = bc_beta(s, &bp);
    nitsche_residual(dim, c->mask, &bp, P, T, beta, R);
    if (!K) continue;
    const int consistent = mica_type_has(&s->opt.field.classical->type, MICA_MODEL_FINITE_STRAIN);
    if (consistent) MICA_CALL(third_derivative(s, c, &bp, F, D));
    /* s->work: Ke (m² for m = n dim), then tN (m dim) and dD (m dim²), within its m nq + 8 m ncomp spare */
    double *Ke = s->work, *tN = Ke + bp.n * dim * bp.n * dim, *dD = tN + bp.n * dim * dim;
    if (!same_support(pending_n, pending_index, &bp)) {
      if (pending_n) MICA_CALL(mica_sparse_add_clique(K, pending_n, pending_index, Ke));
      memset(Ke, 0, sizeof(double) * (size_t)(bp.n * dim * bp.n * dim));
      pending_n = bp.n;
      pending_index = bp.index;
    }
    nitsche_tangent(dim, c->mask, &bp, T, consistent ? D : NULL, beta, Ke, tN, dD);
  }
  if (K && pending_n) MICA_CALL(mica_sparse_add_clique(K, pending_n, pending_index, s->work));
  return MICA_SUCCESS;
}

static const MicaDeckKey nitsche_keys[] = {BC_ALPHA_KEY("100"), {0}};

const MicaBoundaryMethodOps mica_bc_nitsche = {
    {"nitsche", "symmetric Nitsche: consistent, stabilized by β = α E / h (first-order models)",
     MICA_BC_SYMMETRIC_DEFINITE | MICA_BC_MODEL_TRACTION, nitsche_keys, bc_alpha_from_settings},
    nitsche_add};
