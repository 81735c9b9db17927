/* The gradient micromorph continuum with χ = R(Φ): a generalized Cosserat continuum (docs/theory.md
 * §micromorph, "χ = R(Φ)").
 *
 * Unknowns u and an independent rotation vector Φ (2-D: ux, uy, phiz; 3-D: ux..uz, phix..phiz), order 1. The micro
 * placement x̂ = x + R(Φ) Y has the deformation gradient F̂ = ∂x̂/∂X:
 *   F̂_aK = F_aK + (∂_K R Y)_a = F_aK + (R (Γ_K × Y))_a,   Γ_K = T(Φ) ∂_K Φ   (Rᵀ ∂_K R = skew Γ_K, mica/rotation.h)
 * i.e. F̂ = F + R Z with Z = −Ŷ Γ (Ŷ = skew Y, Γ_iK = T_ik Φ_k,K). The energy density is
 *   W = Σ_g w_g ψ(F̂_g) + ½ κ_c |skew(RᵀF)|²,
 * the second term coupling Φ to the macro rotation (without it a uniform Φ would cost nothing). Both parts are
 * objective (x → Q x, R → Q R leaves F̂ᵀF̂ and RᵀF unchanged). The kernel works in 3-D (F₃, three Φ, 3 × 3 ∇Φ) and
 * keeps the derivatives with respect to the entries of q: in 2-D F₃ = [F 0; 0 1], Φ = φ e_z, ∇Φ = e_z ⊗ ∇φ, and
 * F̂ stays plane (R turns about e_z, Γ_K × Y lies in the plane).
 * With z = [F₃ | Φ | ∇Φ] and B = ∂F̂/∂z:  s = Σ_g w_g Bᵀ P + ∂W_c/∂z,  D = Σ_g w_g (Bᵀ A B + ∂²(P̄ : F̂)/∂z²) + ∂²W_c/∂z².
 */
#include <math.h>
#include <string.h>

#include "mica/micromorph.h"
#include "mica/rotation.h"
#include "micromorph_private.h"
#include "models_private.h"

enum { NZ = 21, Z_PHI = 9, Z_GRAD = 12 }; /* z = [F₃ (9) | Φ (3) | Φ_k,L at 12 + 3k + L] */

typedef struct {
  int dim;
  double F[9], phi[3], gradphi[9], Gamma[9]; /* 3 × 3 row-major; gradphi[3k + L] = Φ_k,L */
  MicaRotation rot;
} State;

static void mat_mul(const double *a, const double *b, double *c) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

/* c = aᵀ b */
static void mat_mul_tn(const double *a, const double *b, double *c) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) c[3 * i + j] = a[i] * b[j] + a[3 + i] * b[3 + j] + a[6 + i] * b[6 + j];
}

static void skew_part(const double *a, double *s) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) s[3 * i + j] = 0.5 * (a[3 * i + j] - a[3 * j + i]);
}

static double contract(const double *a, const double *b) {
  double s = 0;
  for (int k = 0; k < 9; k++) s += a[k] * b[k];
  return s;
}

/* The q slot of each z, or −1 for the entries a 2-D state holds fixed. */
static void z_to_q(int dim, int *slot) {
  const int ncomp = dim == 2 ? 3 : 6;
  for (int k = 0; k < NZ; k++) slot[k] = -1;
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) slot[3 * a + J] = ncomp + a * dim + J;
  for (int i = 3 - (ncomp - dim); i < 3; i++) {
    const int c = dim + i - (3 - (ncomp - dim)); /* the component index of Φ_i */
    slot[Z_PHI + i] = c;
    for (int L = 0; L < dim; L++) slot[Z_GRAD + 3 * i + L] = ncomp + c * dim + L;
  }
}

static void state_from_q(int dim, const double *q, int nderiv, State *st) {
  int slot[NZ];
  double z[NZ] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  z_to_q(dim, slot);
  for (int k = 0; k < NZ; k++)
    if (slot[k] >= 0) z[k] = (k < 9 && k / 3 == k % 3) + q[slot[k]];
  st->dim = dim;
  memcpy(st->F, z, sizeof st->F);
  memcpy(st->phi, z + Z_PHI, sizeof st->phi);
  memcpy(st->gradphi, z + Z_GRAD, sizeof st->gradphi);
  mica_rotation_eval(st->phi, nderiv, &st->rot);
  mat_mul(st->rot.T, st->gradphi, st->Gamma);
}

static void skew_of(const double *Y, double *Yhat) { /* Ŷ v = Y × v */
  const double s[9] = {0, -Y[2], Y[1], Y[2], 0, -Y[0], -Y[1], Y[0], 0};
  memcpy(Yhat, s, sizeof s);
}

/* F̂ = F + R Z, Z = −Ŷ Γ; Yhat and Z are returned for the derivatives. */
static void micro_deformation(const State *st, const double *Y, double *Yhat, double *Z, double *Fhat) {
  double RZ[9];
  skew_of(Y, Yhat);
  mat_mul(Yhat, st->Gamma, Z);
  for (int k = 0; k < 9; k++) Z[k] = -Z[k];
  mat_mul(st->rot.R, Z, RZ);
  for (int k = 0; k < 9; k++) Fhat[k] = st->F[k] + RZ[k];
}

/* ∂Z/∂Φ_i = −Ŷ (∂_i T) ∇Φ (dZ[i]); the same with ∂²T for the packed pair h. */
static void z_derivative(const double *Yhat, const double *dT, const double *gradphi, double *dZ) {
  double t[9];
  mat_mul(dT, gradphi, t);
  mat_mul(Yhat, t, dZ);
  for (int k = 0; k < 9; k++) dZ[k] = -dZ[k];
}

/* B (dim² rows: the in-plane F̂_aK; NZ columns):
 *   ∂F̂/∂F = identity,  ∂F̂/∂Φ_i = (∂_i R) Z + R ∂_i Z,  ∂F̂_aK/∂Φ_k,L = −(R Ŷ T)_ak δ_KL. */
static void micro_jacobian(const State *st, const double *Yhat, const double *Z, const double (*dZ)[9], double *B) {
  const int dim = st->dim;
  double RYT[9], t[9], d[3][9];
  mat_mul(Yhat, st->rot.T, t);
  mat_mul(st->rot.R, t, RYT);
  for (int i = 0; i < 3; i++) {
    double a[9], b[9];
    mat_mul(st->rot.dR[i], Z, a);
    mat_mul(st->rot.R, dZ[i], b);
    for (int k = 0; k < 9; k++) d[i][k] = a[k] + b[k];
  }
  memset(B, 0, sizeof(double) * (size_t)(dim * dim * NZ));
  for (int a = 0; a < dim; a++)
    for (int K = 0; K < dim; K++) {
      double *row = B + (a * dim + K) * NZ;
      row[3 * a + K] = 1;
      for (int i = 0; i < 3; i++) row[Z_PHI + i] = d[i][3 * a + K];
      for (int k = 0; k < 3; k++) row[Z_GRAD + 3 * k + K] = -RYT[3 * a + k];
    }
}

/* H += c ∂²(P̄ : F̂)/∂z² (P̄ 3 × 3, zero out of plane): the Φ–Φ block
 *   P̄ : [(∂_ij R) Z + ∂_i R ∂_j Z + ∂_j R ∂_i Z + R ∂_ij Z],
 * the Φ–∇Φ block ∂²/∂Φ_i∂Φ_k,L = −Σ_a P̄_aL [(∂_i R) Ŷ T + R Ŷ ∂_i T]_ak; F enters linearly. */
static void add_second_derivative(const State *st, const double *Yhat, const double *Z, const double (*dZ)[9],
                                  const double *Pb, double c, double *H) {
  const MicaRotation *r = &st->rot;
  for (int i = 0; i < 3; i++)
    for (int j = i; j < 3; j++) {
      const int h = micro_hess_index(3, i, j);
      double ddZ[9], a[9], value;
      z_derivative(Yhat, r->ddT[h], st->gradphi, ddZ);
      mat_mul(r->ddR[h], Z, a), value = contract(Pb, a);
      mat_mul(r->dR[i], dZ[j], a), value += contract(Pb, a);
      mat_mul(r->dR[j], dZ[i], a), value += contract(Pb, a);
      mat_mul(r->R, ddZ, a), value += contract(Pb, a);
      H[(Z_PHI + i) * NZ + Z_PHI + j] += c * value;
      if (i != j) H[(Z_PHI + j) * NZ + Z_PHI + i] += c * value;
    }
  double YT[9];
  mat_mul(Yhat, r->T, YT);
  for (int i = 0; i < 3; i++) {
    double M[9], a[9], YdT[9], b[9];
    mat_mul(r->dR[i], YT, M);
    mat_mul(Yhat, r->dT[i], YdT);
    mat_mul(r->R, YdT, b);
    for (int k = 0; k < 9; k++) a[k] = M[k] + b[k];
    for (int k = 0; k < 3; k++)
      for (int L = 0; L < 3; L++) {
        double value = 0;
        for (int aa = 0; aa < 3; aa++) value -= Pb[3 * aa + L] * a[3 * aa + k];
        H[(Z_PHI + i) * NZ + Z_GRAD + 3 * k + L] += c * value;
        H[(Z_GRAD + 3 * k + L) * NZ + Z_PHI + i] += c * value;
      }
  }
}

/* The coupling W_c = ½ κ_c |skew(RᵀF)|² and its derivatives in z (s, D may be NULL):
 *   ∂/∂F = κ_c R A,  ∂/∂Φ_i = κ_c A : (∂_i R)ᵀF,  with A = skew(RᵀF);
 *   ∂²/∂F_cL∂F_dM = ½ κ_c (δ_cd δ_LM − R_cM R_dL),  ∂²/∂F∂Φ_i = κ_c [(∂_i R) A + R skew((∂_i R)ᵀF)],
 *   ∂²/∂Φ_i∂Φ_j = κ_c [skew((∂_j R)ᵀF) : (∂_i R)ᵀF + A : (∂_ij R)ᵀF]. */
static double coupling(const State *st, double kappa_c, double *sz, double *Dz) {
  const MicaRotation *r = &st->rot;
  double U[9], A[9], RA[9], dU[3][9], dA[3][9];
  mat_mul_tn(r->R, st->F, U);
  skew_part(U, A);
  const double Wc = 0.5 * kappa_c * contract(A, A);
  if (!sz && !Dz) return Wc;
  mat_mul(r->R, A, RA);
  for (int i = 0; i < 3; i++) {
    mat_mul_tn(r->dR[i], st->F, dU[i]);
    skew_part(dU[i], dA[i]);
  }
  if (sz) {
    for (int k = 0; k < 9; k++) sz[k] += kappa_c * RA[k];
    for (int i = 0; i < 3; i++) sz[Z_PHI + i] += kappa_c * contract(A, dU[i]);
  }
  if (!Dz) return Wc;
  for (int cc = 0; cc < 3; cc++)
    for (int L = 0; L < 3; L++)
      for (int d = 0; d < 3; d++)
        for (int M = 0; M < 3; M++)
          Dz[(3 * cc + L) * NZ + 3 * d + M] += 0.5 * kappa_c * ((cc == d && L == M) - r->R[3 * cc + M] * r->R[3 * d + L]);
  for (int i = 0; i < 3; i++) {
    double a[9], b[9];
    mat_mul(r->dR[i], A, a);
    mat_mul(r->R, dA[i], b);
    for (int k = 0; k < 9; k++) {
      Dz[k * NZ + Z_PHI + i] += kappa_c * (a[k] + b[k]);
      Dz[(Z_PHI + i) * NZ + k] += kappa_c * (a[k] + b[k]);
    }
    for (int j = 0; j < 3; j++) {
      double ddU[9];
      mat_mul_tn(r->ddR[micro_hess_index(3, i, j)], st->F, ddU);
      Dz[(Z_PHI + i) * NZ + Z_PHI + j] += kappa_c * (contract(dA[j], dU[i]) + contract(A, ddU));
    }
  }
  return Wc;
}

static int rotation_eval(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D) {
  const int d2 = dim * dim, nq = mica_field_model_nq(m, dim);
  double Y[MICRO_MAX_POINTS][3], wg[MICRO_MAX_POINTS], Yhat[9], Z[9], dZ[3][9], Fhat[9], Fin[9], P[9], A[81], P3[9];
  double psi, B[9 * NZ], sz[NZ], Dz[NZ * NZ];
  int slot[NZ];
  State st;
  state_from_q(dim, q, D ? 2 : s ? 1 : 0, &st);
  const int n = mica_micromorph_points_(m, dim, Y, wg);
  memset(sz, 0, sizeof sz);
  memset(Dz, 0, sizeof Dz);
  double Wsum = coupling(&st, m->param[MICRO_COUPLING], s ? sz : NULL, D ? Dz : NULL);
  for (int g = 0; g < n; g++) {
    micro_deformation(&st, Y[g], Yhat, Z, Fhat);
    for (int a = 0; a < dim; a++)
      for (int K = 0; K < dim; K++) Fin[a * dim + K] = Fhat[3 * a + K];
    MICA_CALL(m->classical->eval(&m->material, dim, Fin, &psi, P, D ? A : NULL));
    Wsum += wg[g] * psi;
    if (!s && !D) continue;
    for (int i = 0; i < 3; i++) z_derivative(Yhat, st.rot.dT[i], st.gradphi, dZ[i]);
    micro_jacobian(&st, Yhat, Z, (const double(*)[9])dZ, B);
    for (int i = 0; i < d2; i++)
      for (int k = 0; k < NZ; k++) sz[k] += wg[g] * B[i * NZ + k] * P[i];
    if (!D) continue;
    for (int i = 0; i < d2; i++) { /* Dz += w Bᵀ A B */
      double AB[NZ];
      for (int k = 0; k < NZ; k++) {
        double sum = 0;
        for (int l = 0; l < d2; l++) sum += A[i * d2 + l] * B[l * NZ + k];
        AB[k] = sum;
      }
      for (int r = 0; r < NZ; r++) {
        const double br = wg[g] * B[i * NZ + r];
        if (br != 0)
          for (int k = 0; k < NZ; k++) Dz[r * NZ + k] += br * AB[k];
      }
    }
    memset(P3, 0, sizeof P3);
    for (int a = 0; a < dim; a++)
      for (int K = 0; K < dim; K++) P3[3 * a + K] = P[a * dim + K];
    add_second_derivative(&st, Yhat, Z, (const double(*)[9])dZ, P3, wg[g], Dz);
  }
  if (W) *W = Wsum;
  z_to_q(dim, slot);
  if (s) {
    memset(s, 0, sizeof(double) * (size_t)nq);
    for (int k = 0; k < NZ; k++)
      if (slot[k] >= 0) s[slot[k]] += sz[k];
  }
  if (D) {
    memset(D, 0, sizeof(double) * (size_t)(nq * nq));
    for (int r = 0; r < NZ; r++)
      for (int k = 0; k < NZ; k++)
        if (slot[r] >= 0 && slot[k] >= 0) D[slot[r] * nq + slot[k]] += Dz[r * NZ + k];
  }
  return MICA_SUCCESS;
}

static int rotation_ncomp(int dim) { return mica_rotation_model_ncomp_(dim); }

/* Output: the Cauchy stress of ψ at the macro F (the micro-space centre); the couple stress is not reported. */
static int rotation_stress(const MicaFieldModel *m, int dim, const double *q, double *sigma, double *couple) {
  const int ncomp = rotation_ncomp(dim);
  double F[9], strain[9];
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = (a == J) + q[ncomp + a * dim + J];
  if (couple) memset(couple, 0, sizeof(double) * 9);
  return mica_model_stress_strain(m->classical, &m->material, dim, F, sigma, strain);
}

/* Output: χ = R(Φ). */
static int rotation_chi(const MicaFieldModel *m, int dim, const double *q, double *chi) {
  State st;
  (void)m;
  state_from_q(dim, q, 0, &st);
  memcpy(chi, st.rot.R, sizeof st.rot.R);
  return MICA_SUCCESS;
}

const MicaFieldModelOps mica_field_micromorph_rotation = {
    .type = {.name = "micromorph-rotation",
             .description = "micromorph with χ = R(Φ), an independent rotation field",
             .flags = MICA_FIELD_FINITE | MICA_FIELD_USES_VALUES}, /* Φ enters R */
    .order = 1,
    .ncomp = rotation_ncomp,
    .component_names = mica_rotation_model_components_,
    .traction_names = mica_rotation_model_tractions_,
    .eval = rotation_eval,
    .stress = rotation_stress,
    .micro_deformation = rotation_chi,
};

int mica_micromorph_rotation_set(MicaFieldModel *m, int dim, const MicaModelOps *micro_energy,
                                 const MicaMaterial *material, const double *sizes, double N) {
  MicaFieldModel built;
  MICA_CALL(mica_micromorph_init_(&built, &mica_field_micromorph_rotation, dim, micro_energy, material, sizes));
  int naxes = 0;
  for (int K = 0; K < dim; K++) naxes += sizes[K] > 0;
  MICA_CHECK(naxes > 0, MICA_ERR_INPUT,
             "the rotation kind needs a micro space (at least one micro axis with a positive size): without one ∇Φ "
             "stores no energy and there is no size effect; for that use the kind \"F\" without micro axes (classical) "
             "or material.model = \"cosserat\"");
  MICA_CHECK(N >= 0 && N < 1, MICA_ERR_INPUT, "the coupling number N must be in [0, 1), not %g", N);
  built.param[MICRO_COUPLING] = 2 * material->mu * N * N / (1 - N * N);
  built.param[MICRO_COUPLING_N] = N;
  *m = built;
  return MICA_SUCCESS;
}
