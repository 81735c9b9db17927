/* The gradient micromorph continuum with χ = J^(−1/3) F (docs/theory.md §micromorph, "χ = J^(−1/3) F").
 *
 * The micro placement x̂ = x + χ Y follows the macro orientation and shear but not the macro volume change. Its
 * deformation gradient F̂ = ∂x̂/∂X is
 *   F̂_aK = F_aK + (∂_K χ_aJ) Y_J,   ∂_K χ_aJ = J^(−1/3) (G_aJK − ⅓ F_aJ t_K),   G_aJK = u_a,JK,  t_K = F⁻¹_Jb G_bJK,
 * (t = ∇ ln J), i.e. F̂ = F + j Z with j = J^(−1/3), Z_aK = H_aK − ⅓ v_a t_K, H_aK = G_aJK Y_J, v = F Y.
 * F̂ is not affine in q: with z = [F | G (unpacked)] and B = ∂F̂/∂z,
 *   s = Σ_g w_g Bᵀ P(F̂_g),   D = Σ_g w_g (Bᵀ A(F̂_g) B + ∂²(P̄ : F̂)/∂z² at P̄ = P(F̂_g)),
 * and the map q → z is a selection (G_bJK and G_bKJ are one packed Hessian entry), so s_q and D_q are sums over
 * the z that share a slot. Every derivative below is written out in docs/theory.md.
 * In 2-D: J = det F₃ of the plane-strain embedding (= det F), exponent −1/3, indices in-plane — exactly the 3-D
 * kind on plane fields (F̂_33 = 1 because Y_3 = 0 and ∂_3 = 0).
 */
#include <math.h>
#include <string.h>

#include "mica/micromorph.h"
#include "micromorph_private.h"

enum { NZ_MAX = 36 }; /* z = [F (dim²) | G (dim³)] */

/* The macro quantities of one quadrature point, in dim layouts: F[a*dim + J], Finv[L*dim + c] = (F⁻¹)_Lc,
 * G[(b*dim + J)*dim + K], Q[K][L*dim + c] = (F⁻¹ G_K F⁻¹)_Lc = −∂t_K/∂F_cL with (G_K)_bJ = G_bJK. */
typedef struct {
  int dim, nz;
  double F[9], Finv[9], G[27], Q[3][9];
  double t[3], j; /* t_K = ∂_K ln J, j = J^(−1/3) */
} Macro;

static int z_of_G(int dim, int b, int J, int K) { return dim * dim + (b * dim + J) * dim + K; }

/* det F and F⁻¹ for dim = 2 or 3; MICA_ERR_NUMERIC if det F ≤ 0 (J^(−1/3) and ln J do not exist). */
static int invert(int dim, const double *F, double *Finv, double *detF) {
  if (dim == 2) {
    *detF = F[0] * F[3] - F[1] * F[2];
  } else {
    *detF = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
  }
  MICA_CHECK(*detF > 0, MICA_ERR_NUMERIC, "micromorph (isochoric): det F = %g <= 0", *detF);
  const double r = 1.0 / *detF;
  if (dim == 2) {
    Finv[0] = F[3] * r, Finv[1] = -F[1] * r, Finv[2] = -F[2] * r, Finv[3] = F[0] * r;
    return MICA_SUCCESS;
  }
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) { /* (F⁻¹)_ik = cof(F)_ki / det F */
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      Finv[i * 3 + k] = (F[k1 * 3 + i1] * F[k2 * 3 + i2] - F[k1 * 3 + i2] * F[k2 * 3 + i1]) * r;
    }
  return MICA_SUCCESS;
}

static int macro_from_q(int dim, const double *q, Macro *mc) {
  const int nh = dim * (dim + 1) / 2, hess0 = dim * (1 + dim);
  double detF;
  mc->dim = dim, mc->nz = dim * dim + dim * dim * dim;
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) mc->F[a * dim + J] = (a == J) + q[dim + a * dim + J];
  for (int b = 0; b < dim; b++)
    for (int J = 0; J < dim; J++)
      for (int K = 0; K < dim; K++) mc->G[(b * dim + J) * dim + K] = q[hess0 + b * nh + micro_hess_index(dim, J, K)];
  MICA_CALL(invert(dim, mc->F, mc->Finv, &detF));
  mc->j = pow(detF, -1.0 / 3.0);
  for (int K = 0; K < dim; K++) {
    double t = 0;
    for (int J = 0; J < dim; J++)
      for (int b = 0; b < dim; b++) t += mc->Finv[J * dim + b] * mc->G[(b * dim + J) * dim + K];
    mc->t[K] = t;
    for (int L = 0; L < dim; L++)
      for (int c = 0; c < dim; c++) {
        double sum = 0;
        for (int b = 0; b < dim; b++)
          for (int J = 0; J < dim; J++) sum += mc->Finv[L * dim + b] * mc->G[(b * dim + J) * dim + K] * mc->Finv[J * dim + c];
        mc->Q[K][L * dim + c] = sum;
      }
  }
  return MICA_SUCCESS;
}

/* F̂ = F + j Z at the micro point Y; v = F Y and Z are returned for the derivatives. */
static void micro_deformation(const Macro *mc, const double *Y, double *v, double *Z, double *Fhat) {
  const int dim = mc->dim;
  for (int a = 0; a < dim; a++) {
    v[a] = 0;
    for (int J = 0; J < dim; J++) v[a] += mc->F[a * dim + J] * Y[J];
  }
  for (int a = 0; a < dim; a++)
    for (int K = 0; K < dim; K++) {
      double H = 0;
      for (int J = 0; J < dim; J++) H += mc->G[(a * dim + J) * dim + K] * Y[J];
      Z[a * dim + K] = H - v[a] * mc->t[K] / 3;
      Fhat[a * dim + K] = mc->F[a * dim + K] + mc->j * Z[a * dim + K];
    }
}

/* B = ∂F̂/∂z (dim² × nz): ∂F̂_aK/∂F_cL = δ_ac δ_KL + Z_aK ∂j/∂F_cL − (j/3)(δ_ac Y_L t_K − v_a Q_K,Lc) with
 * ∂j/∂F_cL = −(j/3) F⁻¹_Lc, and ∂F̂_aK/∂G_bJK' = j δ_KK' (δ_ab Y_J − ⅓ v_a F⁻¹_Jb). */
static void micro_jacobian(const Macro *mc, const double *Y, const double *v, const double *Z, double *B) {
  const int dim = mc->dim, nz = mc->nz;
  const double j = mc->j;
  memset(B, 0, sizeof(double) * (size_t)(dim * dim * nz));
  for (int a = 0; a < dim; a++)
    for (int K = 0; K < dim; K++) {
      double *row = B + (a * dim + K) * nz;
      for (int c = 0; c < dim; c++)
        for (int L = 0; L < dim; L++)
          row[c * dim + L] = (a == c && K == L) - Z[a * dim + K] * j / 3 * mc->Finv[L * dim + c] -
                             j / 3 * ((a == c) * Y[L] * mc->t[K] - v[a] * mc->Q[K][L * dim + c]);
      for (int b = 0; b < dim; b++)
        for (int J = 0; J < dim; J++) row[z_of_G(dim, b, J, K)] = j * ((a == b) * Y[J] - v[a] * mc->Finv[J * dim + b] / 3);
    }
}

/* H += c ∂²(P̄ : F̂)/∂z². With ψ = P̄ : Z, P̄ : F̂ = P̄ : F + j ψ, and j depends on F only:
 *   ∂² = ψ ∂²j + ∂j ⊗ ∂ψ + ∂ψ ⊗ ∂j + j ∂²ψ,   ∂²ψ/∂G² = 0,
 * with w = P̄ᵀ v and P̄t as in docs/theory.md. */
static void add_second_derivative(const Macro *mc, const double *Y, const double *v, const double *Z, const double *Pb,
                                  double c, double *H) {
  const int dim = mc->dim, nz = mc->nz, d2 = dim * dim;
  const double j = mc->j;
  const double *Fi = mc->Finv;
  double w[3] = {0, 0, 0}, pt[3] = {0, 0, 0}, psi = 0, jF[9], psiF[9], psiG[27];
  for (int a = 0; a < dim; a++)
    for (int K = 0; K < dim; K++) {
      w[K] += Pb[a * dim + K] * v[a];
      pt[a] += Pb[a * dim + K] * mc->t[K];
      psi += Pb[a * dim + K] * Z[a * dim + K];
    }
  for (int cc = 0; cc < dim; cc++)
    for (int L = 0; L < dim; L++) {
      double sum = -pt[cc] * Y[L] / 3;
      for (int K = 0; K < dim; K++) sum += w[K] * mc->Q[K][L * dim + cc] / 3;
      psiF[cc * dim + L] = sum;
      jF[cc * dim + L] = -j / 3 * Fi[L * dim + cc];
    }
  for (int b = 0; b < dim; b++)
    for (int J = 0; J < dim; J++)
      for (int K = 0; K < dim; K++)
        psiG[(b * dim + J) * dim + K] = Pb[b * dim + K] * Y[J] - w[K] * Fi[J * dim + b] / 3;
  for (int cc = 0; cc < dim; cc++)
    for (int L = 0; L < dim; L++) {
      const int r = cc * dim + L;
      for (int d = 0; d < dim; d++)
        for (int M = 0; M < dim; M++) {
          const int s = d * dim + M;
          double psiFF = 0;
          for (int K = 0; K < dim; K++)
            psiFF += (Pb[cc * dim + K] * Y[L] * mc->Q[K][M * dim + d] + Pb[d * dim + K] * Y[M] * mc->Q[K][L * dim + cc] -
                      w[K] * (Fi[L * dim + d] * mc->Q[K][M * dim + cc] + mc->Q[K][L * dim + d] * Fi[M * dim + cc])) / 3;
          const double jFF = j * (Fi[L * dim + cc] * Fi[M * dim + d] / 9 + Fi[L * dim + d] * Fi[M * dim + cc] / 3);
          H[r * nz + s] += c * (psi * jFF + jF[r] * psiF[s] + psiF[r] * jF[s] + j * psiFF);
        }
      for (int b = 0; b < dim; b++)
        for (int J = 0; J < dim; J++)
          for (int K = 0; K < dim; K++) {
            const int g = z_of_G(dim, b, J, K);
            const double psiFG = -(Pb[cc * dim + K] * Y[L] * Fi[J * dim + b] - w[K] * Fi[L * dim + b] * Fi[J * dim + cc]) / 3;
            const double value = c * (jF[r] * psiG[g - d2] + j * psiFG);
            H[r * nz + g] += value;
            H[g * nz + r] += value;
          }
    }
}

/* The q slot of each z: F_cL → ∂_L u_c, G_bJK → the packed Hessian entry u_b,JK. */
static void z_to_q(int dim, int *slot) {
  const int nh = dim * (dim + 1) / 2, hess0 = dim * (1 + dim);
  for (int a = 0; a < dim * dim; a++) slot[a] = dim + a;
  for (int b = 0; b < dim; b++)
    for (int J = 0; J < dim; J++)
      for (int K = 0; K < dim; K++) slot[z_of_G(dim, b, J, K)] = hess0 + b * nh + micro_hess_index(dim, J, K);
}

static int isochoric_eval(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D) {
  const int d2 = dim * dim, nq = mica_field_model_nq(m, dim);
  double Y[MICRO_MAX_POINTS][3], wg[MICRO_MAX_POINTS], v[3], Z[9], Fhat[9], P[9], A[81], psi;
  double B[9 * NZ_MAX], sz[NZ_MAX], Dz[NZ_MAX * NZ_MAX];
  int slot[NZ_MAX];
  Macro mc;
  MICA_CALL(macro_from_q(dim, q, &mc));
  const int n = mica_micromorph_points_(m, dim, Y, wg), nz = mc.nz;
  if (W) *W = 0;
  memset(sz, 0, sizeof sz);
  memset(Dz, 0, sizeof(double) * (size_t)(nz * nz));
  for (int g = 0; g < n; g++) {
    micro_deformation(&mc, Y[g], v, Z, Fhat);
    MICA_CALL(m->classical->eval(&m->material, dim, Fhat, &psi, P, D ? A : NULL));
    if (W) *W += wg[g] * psi;
    if (!s && !D) continue;
    micro_jacobian(&mc, Y[g], v, Z, B);
    for (int i = 0; i < d2; i++)
      for (int k = 0; k < nz; k++) sz[k] += wg[g] * B[i * nz + k] * P[i];
    if (!D) continue;
    for (int i = 0; i < d2; i++) { /* Dz += w Bᵀ A B, one row of A B at a time */
      double AB[NZ_MAX];
      for (int k = 0; k < nz; k++) {
        double sum = 0;
        for (int l = 0; l < d2; l++) sum += A[i * d2 + l] * B[l * nz + k];
        AB[k] = sum;
      }
      for (int r = 0; r < nz; r++) {
        const double br = wg[g] * B[i * nz + r];
        if (br != 0)
          for (int k = 0; k < nz; k++) Dz[r * nz + k] += br * AB[k];
      }
    }
    add_second_derivative(&mc, Y[g], v, Z, P, wg[g], Dz);
  }
  z_to_q(dim, slot);
  if (s) {
    memset(s, 0, sizeof(double) * (size_t)nq);
    for (int k = 0; k < nz; k++) s[slot[k]] += sz[k];
  }
  if (D) {
    memset(D, 0, sizeof(double) * (size_t)(nq * nq));
    for (int r = 0; r < nz; r++)
      for (int k = 0; k < nz; k++) D[slot[r] * nq + slot[k]] += Dz[r * nz + k];
  }
  return MICA_SUCCESS;
}

static int isochoric_ncomp(int dim) { return dim; }

static const char *const *isochoric_components(int dim) {
  static const char *const names[] = {"ux", "uy", "uz", NULL};
  (void)dim;
  return names;
}

static const char *const *isochoric_tractions(int dim) {
  static const char *const names[] = {"tx", "ty", "tz", NULL};
  (void)dim;
  return names;
}

/* Output: the Cauchy stress of ψ at the macro F (the micro-space centre), as for χ = F. */
static int isochoric_stress(const MicaFieldModel *m, int dim, const double *q, double *sigma, double *couple) {
  double F[9], strain[9];
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = (a == J) + q[dim + a * dim + J];
  if (couple) memset(couple, 0, sizeof(double) * 9);
  return mica_model_stress_strain(m->classical, &m->material, dim, F, sigma, strain);
}

/* Output: χ = J^(−1/3) F₃ (in 2-D of the plane embedding, so χ_33 = J^(−1/3)); MICA_ERR_NUMERIC if det F ≤ 0. */
static int isochoric_chi(const MicaFieldModel *m, int dim, const double *q, double *chi) {
  Macro mc;
  (void)m;
  MICA_CALL(macro_from_q(dim, q, &mc));
  for (int a = 0; a < 3; a++)
    for (int J = 0; J < 3; J++) chi[a * 3 + J] = mc.j * (a < dim && J < dim ? mc.F[a * dim + J] : a == J);
  return MICA_SUCCESS;
}

const MicaFieldModelOps mica_field_micromorph_isochoric = {
    {"micromorph-isochoric", "gradient micromorph with χ = J^(−1/3) F", MICA_FIELD_FINITE, NULL, NULL},
    2, isochoric_ncomp, isochoric_components, isochoric_tractions, isochoric_eval,
    isochoric_stress, isochoric_chi,
};

int mica_micromorph_isochoric_set(MicaFieldModel *m, int dim, const MicaModelOps *micro_energy,
                                  const MicaMaterial *material, const double *sizes) {
  return mica_micromorph_init_(m, &mica_field_micromorph_isochoric, dim, micro_energy, material, sizes);
}
