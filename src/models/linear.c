/* Linear elasticity, small strain, written in the total-Lagrangian form of mica/model.h
 * (docs/theory.md §models, "Linear elasticity"):
 *   ε = sym(F − I) = sym ∇u,   σ = λ' (tr ε) I + 2μ ε,   P = σ,   W = ½ σ : ε,
 *   A_iJkL = λ' δ_iJ δ_kL + μ (δ_ik δ_JL + δ_iL δ_Jk)   (C with its minor symmetries),
 * with λ' = λ in 3-D and plane strain (ε_33 = 0) and λ' = λ* = 2λμ/(λ + 2μ) in plane stress (σ_33 = 0
 * eliminates ε_33 = −λ/(λ + 2μ) tr ε). P is linear in F, so the residual is linear in u.
 */
#include "models_private.h"

/* The λ that multiplies tr ε over the in-plane strains. */
static double effective_lambda(const MicaMaterial *mat, int dim) {
  if (dim == 2 && mat->plane == MICA_PLANE_STRESS)
    return 2.0 * mat->lambda * mat->mu / (mat->lambda + 2.0 * mat->mu);
  return mat->lambda;
}

static int linear_eval(const MicaMaterial *mat, int dim, const double *F, double *W, double *P, double *A) {
  MICA_CALL(mica_model_check_args_(&mica_model_linear, mat, dim));
  double lambda = effective_lambda(mat, dim), mu = mat->mu;
  double F3[9], eps[9], sigma[9];
  t3_embed(dim, F, F3); /* F_33 = 1: ε_33 = 0, which the plane stress λ* already accounts for */
  t3_small_strain(F3, eps);
  double tr = t3_trace(eps);
  for (int a = 0; a < 9; a++) sigma[a] = lambda * tr * T3_IDENTITY[a] + 2.0 * mu * eps[a];
  if (W) *W = 0.5 * t3_contract(sigma, eps);
  if (P) t3_extract(dim, sigma, P);
  if (A) {
    a_zero(dim, A);
    a_add_dyad(dim, lambda, T3_IDENTITY, T3_IDENTITY, A); /* λ δ_iJ δ_kL */
    a_add_ik_jl(dim, mu, T3_IDENTITY, T3_IDENTITY, A);    /* μ δ_ik δ_JL */
    a_add_cross(dim, mu, T3_IDENTITY, T3_IDENTITY, A);    /* μ δ_iL δ_kJ */
  }
  return MICA_SUCCESS;
}

const MicaModelOps mica_model_linear = {
    .type = {.name = "linear",
             .description = "linear elasticity, small strain (3-D, plane strain, plane stress)",
             .flags = MICA_MODEL_PLANE_STRESS},
    .eval = linear_eval,
};
