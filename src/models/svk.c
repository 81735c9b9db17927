/* St. Venant–Kirchhoff: linear elasticity in the Green–Lagrange strain (docs/theory.md §models, "St.
 * Venant–Kirchhoff"):
 *   E = ½ (FᵀF − I),   S = λ (tr E) I + 2μ E,   P = F S,   W = λ/2 (tr E)² + μ E : E,
 *   A_iJkL = δ_ik S_JL + F_iM C_MJNL F_kN
 *          = δ_ik S_JL + λ F_iJ F_kL + μ (b_ik δ_JL + F_iL F_kJ),   b = F Fᵀ,
 * the geometric (initial-stress) term plus the material term with the isotropic C. 3-D and plane strain
 * (the 3-D law at F_33 = 1, so E_33 = 0). Defined for any F, including det F ≤ 0.
 */
#include "models_private.h"

static int svk_eval(const MicaMaterial *mat, int dim, const double *F, double *W, double *P, double *A) {
  MICA_CALL(mica_model_check_args_(&mica_model_svk, mat, dim));
  double lambda = mat->lambda, mu = mat->mu;
  double F3[9], C[9], E[9], S[9];
  t3_embed(dim, F, F3);
  t3_mul_tn(F3, F3, C);
  for (int a = 0; a < 9; a++) E[a] = 0.5 * (C[a] - T3_IDENTITY[a]);
  double trE = t3_trace(E);
  for (int a = 0; a < 9; a++) S[a] = lambda * trE * T3_IDENTITY[a] + 2.0 * mu * E[a];
  if (W) *W = 0.5 * lambda * trE * trE + mu * t3_contract(E, E);
  if (P) {
    double P3[9];
    t3_mul(F3, S, P3);
    t3_extract(dim, P3, P);
  }
  if (A) {
    double b[9];
    t3_mul_nt(F3, F3, b);
    a_zero(dim, A);
    a_add_ik_jl(dim, 1.0, T3_IDENTITY, S, A); /* geometric: δ_ik S_JL */
    a_add_dyad(dim, lambda, F3, F3, A);       /* λ F_iJ F_kL */
    a_add_ik_jl(dim, mu, b, T3_IDENTITY, A);  /* μ b_ik δ_JL */
    a_add_cross(dim, mu, F3, F3, A);          /* μ F_iL F_kJ */
  }
  return MICA_SUCCESS;
}

const MicaModelOps mica_model_svk = {
    .type = {.name = "svk",
             .description = "St. Venant-Kirchhoff, S = lambda tr(E) I + 2 mu E in the Green strain (3-D, plane strain)",
             .flags = MICA_MODEL_FINITE_STRAIN},
    .eval = svk_eval,
};
