/* Compressible Neo-Hooke models (docs/theory.md §models, "Neo-Hooke" and "Neo-Hooke, Cook's membrane form").
 * Notation: J = det F, G = F⁻ᵀ (so ∂J/∂F = J G, ∂G_iJ/∂F_kL = −G_iL G_kJ), I₁ = tr(FᵀF).
 *
 * neohooke:       W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²
 *                 P = μ (F − G) + λ ln J G
 *                 A_iJkL = μ δ_ik δ_JL + (μ − λ ln J) G_iL G_kJ + λ G_iJ G_kL
 *
 * neohooke-cook:  W = μ/2 (Ī₁ − 3) + κ/4 (J² − 1 − 2 ln J),   Ī₁ = a I₁,  a = J^(−2/3)
 *                 P = μ a (F − I₁/3 G) + κ/2 (J² − 1) G
 *                 A_iJkL = μ a [δ_ik δ_JL − 2/3 (F_iJ G_kL + G_iJ F_kL) + 2/9 I₁ G_iJ G_kL + 1/3 I₁ G_iL G_kJ]
 *                          + κ J² G_iJ G_kL − κ/2 (J² − 1) G_iL G_kJ
 *
 * Both in 3-D and plane strain, where everything is the 3-D expression at F_33 = 1: J is the 3×3
 * determinant (= the 2×2 one) and I₁ includes the 1 from F_33. det F ≤ 0 is MICA_ERR_NUMERIC.
 */
#include <math.h>

#include "models_private.h"

/* The kinematics both models share: F embedded in 3-D, J, G = F⁻ᵀ, I₁. */
typedef struct {
  double F[9], G[9], J, I1;
} Kinematics;

static int kinematics(const MicaModelOps *model, int dim, const double *F, Kinematics *kin) {
  t3_embed(dim, F, kin->F);
  kin->J = t3_det(kin->F);
  MICA_CALL(mica_model_check_jacobian_(model, kin->J));
  t3_inverse_transpose(kin->F, kin->J, kin->G);
  kin->I1 = t3_contract(kin->F, kin->F);
  return MICA_SUCCESS;
}

/* ---- neohooke ---- */

static int neohooke_eval(const MicaMaterial *mat, int dim, const double *F, double *W, double *P, double *A) {
  MICA_CALL(mica_model_check_args_(&mica_model_neohooke, mat, dim));
  Kinematics kin;
  MICA_CALL(kinematics(&mica_model_neohooke, dim, F, &kin));
  double lambda = mat->lambda, mu = mat->mu, lnJ = log(kin.J);
  if (W) *W = 0.5 * mu * (kin.I1 - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ;
  if (P) {
    double P3[9];
    for (int a = 0; a < 9; a++) P3[a] = mu * (kin.F[a] - kin.G[a]) + lambda * lnJ * kin.G[a];
    t3_extract(dim, P3, P);
  }
  if (A) {
    a_zero(dim, A);
    a_add_ik_jl(dim, mu, T3_IDENTITY, T3_IDENTITY, A);    /* μ ∂F/∂F */
    a_add_cross(dim, mu - lambda * lnJ, kin.G, kin.G, A); /* −(μ − λ ln J) ∂G/∂F */
    a_add_dyad(dim, lambda, kin.G, kin.G, A);             /* λ G ⊗ ∂ln J/∂F */
  }
  return MICA_SUCCESS;
}

const MicaModelOps mica_model_neohooke = {
    .type = {.name = "neohooke",
             .description = "compressible Neo-Hooke, W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2 "
                            "(3-D, plane strain)",
             .flags = MICA_MODEL_FINITE_STRAIN},
    .eval = neohooke_eval,
};

/* ---- neohooke-cook ---- */

static int neohooke_cook_eval(const MicaMaterial *mat, int dim, const double *F, double *W, double *P, double *A) {
  MICA_CALL(mica_model_check_args_(&mica_model_neohooke_cook, mat, dim));
  Kinematics kin;
  MICA_CALL(kinematics(&mica_model_neohooke_cook, dim, F, &kin));
  double mu = mat->mu, kappa = mat->kappa, J = kin.J, I1 = kin.I1;
  double a = pow(J, -2.0 / 3.0), J2 = J * J;
  if (W) *W = 0.5 * mu * (a * I1 - 3.0) + 0.25 * kappa * (J2 - 1.0 - 2.0 * log(J));
  if (P) {
    double P3[9], g = -mu * a * I1 / 3.0 + 0.5 * kappa * (J2 - 1.0); /* the coefficient of G */
    for (int m = 0; m < 9; m++) P3[m] = mu * a * kin.F[m] + g * kin.G[m];
    t3_extract(dim, P3, P);
  }
  if (A) {
    double mua = mu * a;
    a_zero(dim, A);
    a_add_ik_jl(dim, mua, T3_IDENTITY, T3_IDENTITY, A);
    a_add_dyad(dim, -2.0 / 3.0 * mua, kin.F, kin.G, A);
    a_add_dyad(dim, -2.0 / 3.0 * mua, kin.G, kin.F, A);
    a_add_dyad(dim, 2.0 / 9.0 * mua * I1 + kappa * J2, kin.G, kin.G, A);
    a_add_cross(dim, mua * I1 / 3.0 - 0.5 * kappa * (J2 - 1.0), kin.G, kin.G, A);
  }
  return MICA_SUCCESS;
}

const MicaModelOps mica_model_neohooke_cook = {
    .type = {.name = "neohooke-cook",
             .description = "Neo-Hooke of Cook's membrane, W = mu/2 (J^(-2/3) I1 - 3) + kappa/4 (J^2 - 1 - 2 ln J) "
                   "(3-D, plane strain)",
             .flags = MICA_MODEL_FINITE_STRAIN},
    .eval = neohooke_cook_eval,
};
