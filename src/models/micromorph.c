/* The gradient micromorph continuum with χ = F (docs/theory.md §micromorph).
 *
 * Every macro point X carries a micro-continuum S: a line, rectangle or box with sizes l_i along chosen axes
 * (its dimension 0-3 is the number of axes). A micro point sits at x̂(X, Y) = x(X) + χ(X) Y with χ = F, so its
 * deformation gradient is F̂(Y) = F + (Grad F) Y, i.e. F̂_aJ = F_aJ + u_a,JK Y_K, and the energy density is the
 * micro-space average of a classical micro energy ψ (SVK, Neo-Hooke or linear elasticity):
 *   W(X) = (1/|S|) ∫_S ψ(F̂(Y)) dY ≈ Σ_g w_g ψ(F̂(Y_g))   (Gauss points in Y, weights summing to 1).
 * F̂ is affine in the kinematics q = [u | ∇u | ∇∇u]: F̂_g = I + M_g q, so
 *   s = Σ_g w_g M_gᵀ P(F̂_g),   D = Σ_g w_g M_gᵀ A(F̂_g) M_g,
 * with P, A from the classical kernel. At small strain with a linear micro energy this is first
 * strain-gradient elasticity with l_K²/12 per micro axis: W = ½ ε:C:ε + ½ Σ_K (l_K²/12) ∂_K ε:C:∂_K ε.
 * The micro-space dimension is the smallest that carries a scene's size effect: a beam bent across its
 * thickness needs one micro axis along the thickness.
 *
 * param[] layout: MICRO_* of src/models/micromorph_private.h. The other kinds: micromorph_isochoric.c, micromorph_rotation.c.
 */
#include <math.h>
#include <string.h>

#include "mica/geom.h"
#include "mica/model.h"
#include "micromorph_private.h"
#include "models_private.h"

static int micromorph_ncomp(int dim) { return dim; }

static const char *const *micromorph_components(int dim) {
  static const char *const names[] = {"ux", "uy", "uz", NULL};
  (void)dim;
  return names;
}

static const char *const *micromorph_tractions(int dim) {
  static const char *const names[] = {"tx", "ty", "tz", NULL};
  (void)dim;
  return names;
}

/* Micro Gauss points Y_g (dim components) and weights w_g summing to 1 over the micro box. 3 points per micro
 * axis integrate a micro energy quartic in Y (SVK with F̂ affine in Y) exactly. */
int mica_micromorph_points_(const MicaFieldModel *m, int dim, double (*Y)[3], double *w) {
  double x[MICRO_GAUSS], wx[MICRO_GAUSS];
  mica_gauss_legendre(MICRO_GAUSS, x, wx);
  int axes[3], naxes = 0;
  for (int K = 0; K < dim; K++)
    if (m->param[MICRO_SIZE + K] > 0) axes[naxes++] = K;
  int n = 1;
  for (int i = 0; i < naxes; i++) n *= MICRO_GAUSS;
  for (int g = 0; g < n; g++) {
    int rest = g;
    w[g] = 1;
    memset(Y[g], 0, sizeof Y[g]);
    for (int i = 0; i < naxes; i++) {
      const int k = rest % MICRO_GAUSS;
      rest /= MICRO_GAUSS;
      Y[g][axes[i]] = 0.5 * m->param[MICRO_SIZE + axes[i]] * x[k]; /* [−l/2, l/2] */
      w[g] *= 0.5 * wx[k];                             /* weights of [−1, 1] sum to 2 */
    }
  }
  return n;
}

/* M_g: ∂F̂_aJ/∂q_j, dense (dim² × nq). Gradient slots give δ; Hessian slot (a, h(J,K)) gives Y_K in F̂_aJ and,
 * for J ≠ K, Y_J in F̂_aK (u_a,JK = u_a,KJ is one unknown of the packed Hessian). */
static void micro_map(int dim, const double *Y, int nq, double *M) {
  const int nh = dim * (dim + 1) / 2, hess0 = dim * (1 + dim);
  memset(M, 0, sizeof(double) * (size_t)(dim * dim * nq));
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) M[(a * dim + J) * nq + dim + a * dim + J] = 1.0;
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++)
      for (int K = J; K < dim; K++) {
        const int h = J == K ? J : (dim == 2 ? 2 : 6 - J - K); /* mls_hess_index */
        const int slot = hess0 + a * nh + h;
        M[(a * dim + J) * nq + slot] += Y[K];
        if (J != K) M[(a * dim + K) * nq + slot] += Y[J];
      }
}

static int micromorph_eval(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D) {
  const int d2 = dim * dim, nq = mica_field_model_nq(m, dim);
  double Y[MICRO_MAX_POINTS][3], w[MICRO_MAX_POINTS], M[9 * 48], F[9], P[9], A[81], psi;
  const int n = mica_micromorph_points_(m, dim, Y, w);
  if (W) *W = 0;
  if (s) memset(s, 0, sizeof(double) * (size_t)nq);
  if (D) memset(D, 0, sizeof(double) * (size_t)(nq * nq));
  for (int g = 0; g < n; g++) {
    micro_map(dim, Y[g], nq, M);
    for (int i = 0; i < d2; i++) {
      double f = (i / dim == i % dim) ? 1.0 : 0.0;
      for (int j = 0; j < nq; j++) f += M[i * nq + j] * q[j];
      F[i] = f;
    }
    MICA_CALL(m->classical->eval(&m->material, dim, F, &psi, P, D ? A : NULL));
    if (W) *W += w[g] * psi;
    if (s)
      for (int j = 0; j < nq; j++)
        for (int i = 0; i < d2; i++) s[j] += w[g] * M[i * nq + j] * P[i];
    if (!D) continue;
    double AM[9 * 48]; /* A M_g: d² × nq */
    for (int i = 0; i < d2; i++)
      for (int j = 0; j < nq; j++) {
        double sum = 0;
        for (int k = 0; k < d2; k++) sum += A[i * d2 + k] * M[k * nq + j];
        AM[i * nq + j] = sum;
      }
    for (int r = 0; r < nq; r++)
      for (int c = 0; c < nq; c++) {
        double sum = 0;
        for (int i = 0; i < d2; i++) sum += M[i * nq + r] * AM[i * nq + c];
        D[r * nq + c] += w[g] * sum;
      }
  }
  return MICA_SUCCESS;
}

/* Output: the macro Cauchy stress from the micro-space average of P (the force stress of the gradient
 * continuum; the double stress is not reported). */
static int micromorph_stress(const MicaFieldModel *m, int dim, const double *q, double *sigma, double *couple) {
  double F[9], strain[9];
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = (a == J) + q[dim + a * dim + J];
  if (couple) memset(couple, 0, sizeof(double) * 9);
  return mica_model_stress_strain(m->classical, &m->material, dim, F, sigma, strain);
}

/* Output: χ = F (the plane embedding F₃ in 2-D). */
static int micromorph_chi(const MicaFieldModel *m, int dim, const double *q, double *chi) {
  (void)m;
  for (int a = 0; a < 3; a++)
    for (int J = 0; J < 3; J++) chi[a * 3 + J] = (a == J) + (a < dim && J < dim ? q[dim + a * dim + J] : 0);
  return MICA_SUCCESS;
}

const MicaFieldModelOps mica_field_micromorph = {
    {"micromorph", "gradient micromorph, χ = F, J^(−1/3) F or R(Φ) (material.micro_kind)", MICA_FIELD_FINITE, NULL,
     mica_micromorph_from_settings_},
    2, micromorph_ncomp, micromorph_components, micromorph_tractions, micromorph_eval,
    micromorph_stress, micromorph_chi,
};

int mica_micromorph_init_(MicaFieldModel *m, const MicaFieldModelOps *ops, int dim, const MicaModelOps *micro_energy,
                          const MicaMaterial *material, const double *sizes) {
  for (int K = 0; K < dim; K++)
    MICA_CHECK(sizes[K] >= 0 && isfinite(sizes[K]), MICA_ERR_INPUT,
               "micro-space size along %c is %g; sizes must be positive (0: no micro extent along that axis)", 'x' + K,
               sizes[K]);
  memset(m, 0, sizeof *m);
  m->ops = ops;
  m->classical = micro_energy;
  m->material = *material;
  for (int K = 0; K < dim; K++) m->param[MICRO_SIZE + K] = sizes[K];
  m->param[MICRO_POINTS] = MICRO_GAUSS;
  return MICA_SUCCESS;
}

int mica_micromorph_set(MicaFieldModel *m, int dim, const MicaModelOps *micro_energy, const MicaMaterial *material,
                        const double *sizes) {
  return mica_micromorph_init_(m, &mica_field_micromorph, dim, micro_energy, material, sizes);
}
