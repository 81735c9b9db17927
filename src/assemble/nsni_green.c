/* NSNI's stabilization at finite strain, frame-invariant (docs/theory.md §NSNI, "frame-invariant stabilization").
 * The small-strain stabilization energy ½ w (∂_g ∇u) : C : (∂_g ∇u) of a stabilization point (nsni.c) changes
 * under a rigid rotation of the cell that varies over it (∂_g ∇u = ∂_g R ≠ 0), which stiffened a bending elastica
 * by 12 % (docs/verification.md §NSNI). Expanding the Green strain E = ½(FᵀF − I) over the cell instead,
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

/* B[(j·dim + a)·dim² + i·dim + k] = ∂Ḣ_ik/∂u_(j a) for the point's j-th entry and component a. */
static void rate_derivatives(const MicaNsni *n, long p, int dim, const double *F, const double *G, double *B) {
  const MicaShapeCache *c = n->cache;
  const int d2 = dim * dim;
  for (long j = 0, e = c->ptr[p]; e < c->ptr[p + 1]; j++, e++) {
    const double *grad = n->grad + e * dim, *hg = c->dN + e * dim;
    for (int a = 0; a < dim; a++) {
      double *b = B + (j * dim + a) * d2;
      for (int i = 0; i < dim; i++)
        for (int k = 0; k < dim; k++) b[i * dim + k] = grad[i] * G[a * dim + k] + F[a * dim + i] * hg[k];
    }
  }
}

/* Ke (m × m, m = n·dim) = w [Bᵀ D B + the geometric term]; T (m × dim²) scratch for B D. */
static void point_tangent(const MicaNsni *n, long p, int dim, int nq, const double *D, const double *S,
                          const double *B, double w, double *T, double *Ke) {
  const MicaShapeCache *c = n->cache;
  const long first = c->ptr[p], np = c->ptr[p + 1] - first, m = np * dim;
  const int d2 = dim * dim;
  for (long r = 0; r < m; r++)
    for (int kl = 0; kl < d2; kl++) {
      double sum = 0.0;
      for (int ij = 0; ij < d2; ij++) sum += B[r * d2 + ij] * D[(dim + ij) * nq + dim + kl];
      T[r * d2 + kl] = sum;
    }
  for (long r = 0; r < m; r++)
    for (long col = r; col < m; col++) {
      double sum = 0.0;
      for (int kl = 0; kl < d2; kl++) sum += T[r * d2 + kl] * B[col * d2 + kl];
      Ke[r * m + col] = w * sum;
    }
  for (long j = 0; j < np; j++) /* the geometric term, δ_ab (a_Jᵀ S b_K + a_Kᵀ S b_J) */
    for (long k = j; k < np; k++) {
      const double *aj = n->grad + (first + j) * dim, *bj = c->dN + (first + j) * dim;
      const double *ak = n->grad + (first + k) * dim, *bk = c->dN + (first + k) * dim;
      double sum = 0.0;
      for (int i = 0; i < dim; i++)
        for (int l = 0; l < dim; l++) sum += S[i * dim + l] * (aj[i] * bk[l] + ak[i] * bj[l]);
      for (int a = 0; a < dim; a++) Ke[(j * dim + a) * m + k * dim + a] += w * sum;
    }
  for (long r = 0; r < m; r++)
    for (long col = 0; col < r; col++) Ke[r * m + col] = Ke[col * m + r];
}

int mica_nsni_green_assemble(MicaSolid *s, const double *u, double *R, MicaSparse *K) {
  const MicaNsni *n = s->nsni;
  const MicaShapeCache *c = n->cache;
  const int dim = s->dim, nq = s->nq, d2 = dim * dim;
  MICA_CHECK(n->grad && s->ncomp == dim, MICA_ERR_ARGUMENT,
             "mica_nsni_green_assemble: NSNI built without gradients, or a model that is not classical");
  double q[128], sq[128], F[9], G[9];
  for (long p = 0; p < c->npoints; p++) {
    /* s->work, sized by solid.c for the largest support (stab_green): D (nq²), Ke (m²), B and T (m·dim² each) */
    const long first = c->ptr[p], np = c->ptr[p + 1] - first, m = np * dim;
    double *D = s->work, *Ke = D + nq * nq, *B = Ke + m * m, *T = B + m * d2;
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
    const double *S = sq + dim, w = n->w[p];
    rate_derivatives(n, p, dim, F, G, B);
    for (long r = 0; r < m; r++) { /* R = w S : ∂Ḣ/∂u */
      double f = 0.0;
      for (int ik = 0; ik < d2; ik++) f += S[ik] * B[r * d2 + ik];
      R[c->index[first + r / dim] * dim + r % dim] += w * f;
    }
    if (!K) continue;
    point_tangent(n, p, dim, nq, D, S, B, w, T, Ke);
    MICA_CALL(mica_sparse_add_clique(K, np, c->index + first, Ke));
  }
  return MICA_SUCCESS;
}
