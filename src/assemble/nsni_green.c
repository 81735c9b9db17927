/* NSNI's stabilization at finite strain, frame-invariant (docs/theory.md §NSNI, "frame-invariant stabilization").
 * The small-strain stabilization energy ½ w (∂_g ∇u) : C : (∂_g ∇u) of a stabilization point (nsni.c) changes
 * under a rigid rotation of the cell that varies over it (∂_g ∇u = ∂_g R ≠ 0): its stiffness faded as the
 * rotation grew, and a bending elastica came out 12.5 % too flexible (docs/verification.md §NSNI). Expanding the Green strain E = ½(FᵀF − I) over the cell instead,
 * E(x) ≈ E(x_I) + (x − x_I)·∇E, its directional derivative along g is
 *   Ė = ∂_g E = sym(Fᵀ G),   F = I + Σ_J u_J ⊗ ∇N_J(x_I),   G = ∂_g F = Σ_J u_J ⊗ H_J(x_I) g,
 * unchanged by any superposed rigid rotation, and the point's energy is W_s = ½ w Ė : C : Ė, C the material's
 * linear form (its tangent at E = 0: the stabilization of the linear NSNI applied to E, which drops the terms
 * with S : ∂_g∂_g E as the linear form drops σ : ∂_g∂_g ε). With Ḣ = Fᵀ G (Ė = sym Ḣ) the linear model's point
 * kernel gives S = C : sym Ḣ and D = ∂²W/∂Ḣ² when handed Ḣ as its displacement gradient, and
 *   ∂Ḣ_ik/∂u_Ja = a_i G_ak + F_ai b_k      (a = ∇N_J(x_I), b = H_J g),
 *   R_Ja = w S : ∂Ḣ/∂u_Ja,
 *   K_Ja,Kb = w [ ∂Ḣ/∂u_Ja : D : ∂Ḣ/∂u_Kb + δ_ab (a_Jᵀ S b_K + a_Kᵀ S b_J) ].
 * At u = 0 (F = I, G = ∂_g ∇u) this is the small-strain form and its tangent. */
#include <string.h>

#include "mica/solid.h"

/* F and G of stabilization point p at u (dim × dim, row-major: F[a·dim + i] = δ_ai + ∂u_a/∂X_i). */
static void point_kinematics(const MicaNsni *n, long p, int dim, const double *u, double *F, double *G) {
  const MicaShapeCache *c = n->cache;
  for (int a = 0; a < dim * dim; a++) F[a] = 0.0, G[a] = 0.0;
  for (int a = 0; a < dim; a++) F[a * dim + a] = 1.0;
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
    const double *ue = u + c->index[e] * dim, *grad = n->grad + e * dim, *hg = c->dN + e * dim;
    for (int a = 0; a < dim; a++)
      for (int i = 0; i < dim; i++) F[a * dim + i] += ue[a] * grad[i], G[a * dim + i] += ue[a] * hg[i];
  }
}

/* The point's tangent in the entries β_J = (a_J, b_J) (2·dim of them): ∂Ḣ/∂u_Jc = M_c β_J with the dim² × 2dim
 * matrix M_c[(i k), i'] = δ_ii' G_ck, M_c[(i k), dim + k'] = F_ci δ_kk', so
 *   K_Jc,Kd = β_Jᵀ A_cd β_K,   A_cd = w (M_cᵀ D M_d + δ_cd [[0, S], [S, 0]]),
 * and R_Jc = β_J · r_c, r_c = w M_cᵀ S. A (dim² blocks of (2 dim)²) and r once per point; then per pair of entries
 * 2·dim³ products instead of the dim⁴ of ∂Ḣ : D : ∂Ḣ. */
typedef struct {
  int dim, nb; /* nb = 2 dim */
  double A[3][3][36], r[3][6];
} PointForm;

static void point_form(int dim, int nq, const double *F, const double *G, const double *S, const double *D, double w,
                       int with_tangent, PointForm *f) {
  const int nb = 2 * dim, d2 = dim * dim;
  double M[3][9][6]; /* M[c][(i k)][β] */
  f->dim = dim, f->nb = nb;
  for (int c = 0; c < dim; c++)
    for (int i = 0; i < dim; i++)
      for (int k = 0; k < dim; k++)
        for (int b = 0; b < nb; b++)
          M[c][i * dim + k][b] = b < dim ? (b == i ? G[c * dim + k] : 0.0) : (b - dim == k ? F[c * dim + i] : 0.0);
  for (int c = 0; c < dim; c++)
    for (int b = 0; b < nb; b++) {
      double sum = 0.0;
      for (int ik = 0; ik < d2; ik++) sum += M[c][ik][b] * S[ik];
      f->r[c][b] = w * sum;
    }
  if (!with_tangent) return;
  double E[3][9][6]; /* E_d = D_g M_d */
  for (int d = 0; d < dim; d++)
    for (int ik = 0; ik < d2; ik++)
      for (int b = 0; b < nb; b++) {
        double sum = 0.0;
        for (int jl = 0; jl < d2; jl++) sum += D[(dim + ik) * nq + dim + jl] * M[d][jl][b];
        E[d][ik][b] = sum;
      }
  for (int c = 0; c < dim; c++)
    for (int d = 0; d < dim; d++)
      for (int a = 0; a < nb; a++)
        for (int b = 0; b < nb; b++) {
          double sum = 0.0;
          for (int ik = 0; ik < d2; ik++) sum += M[c][ik][a] * E[d][ik][b];
          if (c == d && a < dim && b >= dim) sum += S[a * dim + b - dim]; /* the geometric term: [[0, S], [S, 0]] */
          if (c == d && a >= dim && b < dim) sum += S[(a - dim) * dim + b];
          f->A[c][d][a * nb + b] = w * sum;
        }
}

/* β_e = (∇N_J(x_I), H_J g) of entry e. */
static void entry_beta(const MicaNsni *n, long e, int dim, double *beta) {
  memcpy(beta, n->grad + e * dim, sizeof(double) * (size_t)dim);
  memcpy(beta + dim, n->cache->dN + e * dim, sizeof(double) * (size_t)dim);
}

/* The upper blocks (J ≤ K) of [β_Jᵀ A_cd β_K] into Ke (m × m, m = n·dim) in mica_sparse_add_clique_upper's planar
 * layout; P (n × dim² × 2 dim) scratch for β_J A. Inlined with dim a constant (the short loops over 2·dim entries
 * unrolled). */
static inline __attribute__((always_inline)) void point_tangent_dim(const MicaNsni *n, long p, const PointForm *f,
                                                                    double *P, double *Ke, const int dim) {
  const MicaShapeCache *c = n->cache;
  const int nb = 2 * dim, stride = dim * dim * nb;
  const long first = c->ptr[p], np = c->ptr[p + 1] - first, m = np * dim;
  double beta[6];
  for (long j = 0; j < np; j++) {
    entry_beta(n, first + j, dim, beta);
    double *Pj = P + j * stride;
    for (int cc = 0; cc < dim; cc++)
      for (int d = 0; d < dim; d++)
        for (int b = 0; b < nb; b++) {
          double sum = 0.0;
          for (int a = 0; a < nb; a++) sum += beta[a] * f->A[cc][d][a * nb + b];
          Pj[(cc * dim + d) * nb + b] = sum;
        }
  }
  for (long k = 0; k < np; k++) {
    entry_beta(n, first + k, dim, beta);
    for (long j = 0; j <= k; j++) {
      const double *Pj = P + j * stride;
      for (int cc = 0; cc < dim; cc++)
        for (int d = 0; d < dim; d++) {
          double sum = 0.0;
          for (int b = 0; b < nb; b++) sum += Pj[(cc * dim + d) * nb + b] * beta[b];
          Ke[(k * dim + d) * m + cc * np + j] = sum; /* add_clique_upper's planar layout, transposed */
        }
    }
  }
}

static void point_tangent(const MicaNsni *n, long p, const PointForm *f, double *P, double *Ke) {
  if (f->dim == 2) point_tangent_dim(n, p, f, P, Ke, 2);
  else point_tangent_dim(n, p, f, P, Ke, 3);
}

int mica_nsni_green_assemble(MicaSolid *s, const double *u, double *R, MicaSparse *K) {
  const MicaNsni *n = s->nsni;
  const MicaShapeCache *c = n->cache;
  const int dim = s->dim, nq = s->nq;
  MICA_CHECK(n->grad && s->ncomp == dim, MICA_ERR_ARGUMENT,
             "mica_nsni_green_assemble: NSNI built without gradients, or a model that is not classical");
  double q[128], sq[128], F[9], G[9], beta[6];
  PointForm f;
  for (long p = 0; p < c->npoints; p++) {
    /* s->work, sized by solid.c for the largest support: D (nq²), Ke (m²), P (m · 2 dim² ≤ m (nq + 8 ncomp)) */
    const long first = c->ptr[p], np = c->ptr[p + 1] - first, m = np * dim;
    double *D = s->work, *Ke = D + nq * nq, *P = Ke + m * m;
    point_kinematics(n, p, dim, u, F, G);
    memset(q, 0, sizeof(double) * (size_t)nq);
    for (int i = 0; i < dim; i++) /* Ḣ = Fᵀ G in the gradient slots of the linear model */
      for (int k = 0; k < dim; k++)
        for (int a = 0; a < dim; a++) q[dim + i * dim + k] += F[a * dim + i] * G[a * dim + k];
    double W;
    const int ierr = s->stab_model.ops->eval(&s->stab_model, dim, q, &W, sq, K ? D : NULL);
    if (ierr) {
      mica_error_prefix("NSNI stabilization point %ld", p + 1);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
    point_form(dim, nq, F, G, sq + dim, D, n->w[p], K != NULL, &f);
    for (long j = 0; j < np; j++) {
      entry_beta(n, first + j, dim, beta);
      double *Rj = R + c->index[first + j] * dim;
      for (int cc = 0; cc < dim; cc++)
        for (int b = 0; b < f.nb; b++) Rj[cc] += beta[b] * f.r[cc][b];
    }
    if (!K) continue;
    point_tangent(n, p, &f, P, Ke);
    MICA_CALL(mica_sparse_add_clique_upper(K, np, c->index + first, Ke, np));
  }
  if (K) mica_sparse_mirror_upper(K);
  return MICA_SUCCESS;
}
