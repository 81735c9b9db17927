/* Symmetric Nitsche for first-order field models (Cosserat, cosserat-finite; docs/theory.md §boundary
 * methods). The model's point kernel gives s = ∂W/∂q and D = ∂s/∂q with q = [values | gradients]; the
 * generalized traction conjugate to component b on a boundary with outward normal n is the gradient slots of
 * s contracted with n,
 *   t_b = Σ_J s_(b,J) n_J        (force traction σ·n on a displacement, couple traction m·n on a rotation),
 * which is the boundary term of ∫ s·δq when it is integrated by parts. For the set C of prescribed
 * components, r = v_h − v̄ on C:
 *   Π_N = −∫ Σ_{b∈C} t_b r_b dΓ + ½ ∫ Σ_{b∈C} β_b r_b² dΓ,     β_b = α k_b / h,
 * k_b the largest diagonal modulus of component b's gradient slots in D at q = 0 (Cosserat 2-D: max(λ + 2G,
 * G + κ/2) for u, γ = 4 G l² for φ: the stabilization of each component scales with the modulus of its own
 * traction, which is what the coercivity estimate asks for). With T_b(l,d) = ∂t_b/∂v_(l,d) =
 * Σ_j G_bj B_j(l,d), G_bj = Σ_J n_J D_(b,J),j:
 *   R_kb += −[b∈C] t_b N_k − Σ_{a∈C} r_a T_a(k,b) + [b∈C] β_b r_b N_k
 *   K_(kb)(ld) += −[b∈C] N_k T_b(l,d) − [d∈C] N_l T_d(k,b) + [b∈C] δ_bd β_b N_k N_l − B(k,b)·H·B(l,d)
 * with H_ij = Σ_{a∈C} r_a Σ_J n_J ∂D_(a,J),i/∂q_j, taken by central differences of D for models that are not
 * quadratic (zero otherwise). The tangent is symmetric; it is positive definite for α large enough. */
#include <math.h>
#include <string.h>

#include "bc_private.h"

enum { NQ_MAX = MICA_MAX_COMP * 4 }; /* a first-order model: values and up to 3 gradients per component */

typedef struct {
  int ncomp, dim, nq, mask;
  double alpha_k[MICA_MAX_COMP];           /* α k_b per component */
  double beta[MICA_MAX_COMP];              /* β_b = α k_b / h at the current point */
  double traction[MICA_MAX_COMP];          /* t_b */
  double G[MICA_MAX_COMP * NQ_MAX];        /* G_bj */
} FieldPoint;

static int grad_slot(const FieldPoint *fp, int b, int J) { return fp->ncomp + b * fp->dim + J; }

/* α k_b from the model's D at q = 0. A component without gradient stiffness at q = 0 (no traction to be
 * consistent with) takes the largest k, so that its condition is still imposed (as a penalty). */
static int stabilization(const MicaSolid *s, FieldPoint *fp) {
  double q0[NQ_MAX] = {0}, s0[NQ_MAX], D0[NQ_MAX * NQ_MAX], W, k[MICA_MAX_COMP], kmax = 0;
  MICA_CALL(s->opt.field.ops->eval(&s->opt.field, s->dim, q0, &W, s0, D0));
  for (int b = 0; b < fp->ncomp; b++) {
    k[b] = 0;
    for (int J = 0; J < fp->dim; J++) {
      const int j = grad_slot(fp, b, J);
      k[b] = fmax(k[b], D0[j * fp->nq + j]);
    }
    kmax = fmax(kmax, k[b]);
  }
  for (int b = 0; b < fp->ncomp; b++) fp->alpha_k[b] = s->opt.bc_alpha * (k[b] > 1e-12 * kmax ? k[b] : kmax);
  return MICA_SUCCESS;
}

/* t_b and G_bj at the point from s and D. */
static void tractions(const double *normal, const double *sq, const double *D, FieldPoint *fp) {
  for (int b = 0; b < fp->ncomp; b++) {
    fp->traction[b] = 0;
    for (int j = 0; j < fp->nq; j++) fp->G[b * NQ_MAX + j] = 0;
    for (int J = 0; J < fp->dim; J++) {
      const int row = grad_slot(fp, b, J);
      fp->traction[b] += sq[row] * normal[J];
      for (int j = 0; j < fp->nq; j++) fp->G[b * NQ_MAX + j] += normal[J] * D[row * fp->nq + j];
    }
  }
}

/* T_b(k,d) = G_b,(d value) N_k + Σ_M G_b,(d,M) N_k,M. */
static double traction_sensitivity(const FieldPoint *fp, const BcPoint *bp, int b, long k, int d) {
  const double *g = fp->G + b * NQ_MAX;
  double v = g[d] * bp->N[k];
  for (int M = 0; M < fp->dim; M++) v += g[grad_slot(fp, d, M)] * bp->dN[k * fp->dim + M];
  return v;
}

static void field_residual(const FieldPoint *fp, const BcPoint *bp, double *R) {
  for (long k = 0; k < bp->n; k++)
    for (int b = 0; b < fp->ncomp; b++) {
      double r = 0;
      if (fp->mask & (1 << b)) r += (fp->beta[b] * bp->residual[b] - fp->traction[b]) * bp->N[k];
      for (int a = 0; a < fp->ncomp; a++)
        if (fp->mask & (1 << a)) r -= bp->residual[a] * traction_sensitivity(fp, bp, a, k, b);
      R[bp->index[k] * fp->ncomp + b] += bp->w * r;
    }
}

/* B(k,b)·H·B(l,d) with B(k,b) the q-slots of N_k e_b: the value slot b and the gradient slots (b, L). */
static double second_variation(const FieldPoint *fp, const BcPoint *bp, const double *H, long k, int b, long l,
                               int d) {
  double bk[4], bl[4];
  int sk[4], sl[4];
  const int n = 1 + fp->dim;
  sk[0] = b, sl[0] = d, bk[0] = bp->N[k], bl[0] = bp->N[l];
  for (int L = 0; L < fp->dim; L++) {
    sk[1 + L] = grad_slot(fp, b, L), bk[1 + L] = bp->dN[k * fp->dim + L];
    sl[1 + L] = grad_slot(fp, d, L), bl[1 + L] = bp->dN[l * fp->dim + L];
  }
  double v = 0;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) v += bk[i] * H[sk[i] * fp->nq + sl[j]] * bl[j];
  return v;
}

/* T[(a·n + l)·nc + d] = T_a(l,d) for the prescribed components a (the only ones the tangent uses), computed once
 * per point instead of once per entry of Ke. */
static void sensitivities(const FieldPoint *fp, const BcPoint *bp, double *T) {
  const int nc = fp->ncomp;
  for (int a = 0; a < nc; a++)
    if (fp->mask & (1 << a))
      for (long l = 0; l < bp->n; l++)
        for (int d = 0; d < nc; d++) T[(a * bp->n + l) * nc + d] = traction_sensitivity(fp, bp, a, l, d);
}

/* Ke (m × m, m = n·nc) with T from sensitivities(). */
static void field_tangent(const FieldPoint *fp, const BcPoint *bp, const double *H, const double *T, double *Ke) {
  const int nc = fp->ncomp;
  const long n = bp->n, m = n * nc;
  for (long k = 0; k < n; k++)
    for (int b = 0; b < nc; b++)
      for (long l = 0; l < n; l++)
        for (int d = 0; d < nc; d++) {
          double v = 0;
          if (fp->mask & (1 << b)) {
            v -= bp->N[k] * T[(b * n + l) * nc + d];
            if (b == d) v += fp->beta[b] * bp->N[k] * bp->N[l];
          }
          if (fp->mask & (1 << d)) v -= bp->N[l] * T[(d * n + k) * nc + b];
          if (H) v -= second_variation(fp, bp, H, k, b, l, d);
          Ke[(k * nc + b) * m + l * nc + d] = bp->w * v;
        }
}

/* H_ij = Σ_{a∈C} r_a Σ_J n_J ∂D_(a,J),i/∂q_j by central differences of D (models that are not quadratic). */
static int residual_curvature(const MicaSolid *s, const FieldPoint *fp, const BcPoint *bp, const double *q,
                              double *H) {
  const int nq = fp->nq;
  double qs[NQ_MAX], Dp[NQ_MAX * NQ_MAX], Dm[NQ_MAX * NQ_MAX], sp[NQ_MAX], W;
  for (int j = 0; j < nq; j++) {
    const double step = 1e-6 * fmax(1.0, fabs(q[j]));
    memcpy(qs, q, sizeof(double) * (size_t)nq);
    qs[j] += step;
    MICA_CALL(s->opt.field.ops->eval(&s->opt.field, fp->dim, qs, &W, sp, Dp));
    qs[j] -= 2 * step;
    MICA_CALL(s->opt.field.ops->eval(&s->opt.field, fp->dim, qs, &W, sp, Dm));
    for (int i = 0; i < nq; i++) {
      double sum = 0;
      for (int a = 0; a < fp->ncomp; a++) {
        if (!(fp->mask & (1 << a))) continue;
        for (int J = 0; J < fp->dim; J++) {
          const int row = grad_slot(fp, a, J);
          sum += bp->residual[a] * bp->normal[J] * (Dp[row * nq + i] - Dm[row * nq + i]) / (2 * step);
        }
      }
      H[i * nq + j] = sum;
    }
  }
  return MICA_SUCCESS;
}

static int field_point(MicaSolid *s, const MicaDirichlet *c, long p, double t, const double *u, double *R,
                       MicaSparse *K, FieldPoint *fp) {
  const MicaShapeCache *cache = s->boundary[c->set];
  double q[NQ_MAX], sq[NQ_MAX], D[NQ_MAX * NQ_MAX], H[NQ_MAX * NQ_MAX], W;
  BcPoint bp;
  MICA_CALL(bc_point(s, c, p, t, u, &bp));
  mica_solid_kinematics(s, cache, p, u, q);
  int ierr = s->opt.field.ops->eval(&s->opt.field, fp->dim, q, &W, sq, D);
  if (ierr) {
    mica_error_prefix("boundary point %ld of set '%s'", p + 1, s->disc->sets[c->set].name);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  for (int b = 0; b < fp->ncomp; b++) fp->beta[b] = fp->alpha_k[b] / bp.h;
  tractions(bp.normal, sq, D, fp);
  field_residual(fp, &bp, R);
  if (K) {
    const int curved = mica_type_has(&s->opt.field.ops->type, MICA_FIELD_FINITE);
    if (curved) MICA_CALL(residual_curvature(s, fp, &bp, q, H));
    /* s->work holds Ke (m × m) and then at least m·nq ≥ m·nc doubles (solid.c), for T */
    double *Ke = s->work, *T = Ke + (bp.n * fp->ncomp) * (bp.n * fp->ncomp);
    sensitivities(fp, &bp, T);
    field_tangent(fp, &bp, curved ? H : NULL, T, Ke);
    MICA_CALL(mica_sparse_add_clique(K, bp.n, bp.index, Ke));
  }
  return MICA_SUCCESS;
}

int bc_nitsche_field_add(MicaSolid *s, const MicaDirichlet *c, double t, const double *u, double *R, MicaSparse *K) {
  FieldPoint fp = {.ncomp = s->ncomp, .dim = s->dim, .nq = s->nq, .mask = c->mask};
  MICA_CHECK(s->opt.field.ops->order == 1 && fp.nq == fp.ncomp * (1 + fp.dim) && fp.nq <= NQ_MAX,
             MICA_ERR_ARGUMENT, "Nitsche's method: model '%s' is not a first-order field model",
             s->opt.field.ops->type.name);
  MICA_CALL(stabilization(s, &fp));
  const long npoints = s->boundary[c->set]->npoints;
  for (long p = 0; p < npoints; p++) MICA_CALL(field_point(s, c, p, t, u, R, K, &fp));
  return MICA_SUCCESS;
}
