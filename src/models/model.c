/* Continuum models: the registry, the material constants and the output stress and strain
 * (docs/theory.md §models):
 *   Lamé constants   λ = E ν / ((1 + ν)(1 − 2ν)),  μ = E / (2 (1 + ν)),  bulk modulus κ = E / (3 (1 − 2ν));
 *   Cauchy stress    σ = J⁻¹ P Fᵀ (finite strain), σ = P (linear kinematics), as 3×3 with σ_33 from the
 *                    3-D law at F_33 = 1 in plane strain and σ_33 = 0 in plane stress;
 *   strain           Green–Lagrange E = ½ (FᵀF − I) (finite strain) or ε = sym(F − I), with
 *                    ε_33 = −ν/(1 − ν) (ε_11 + ε_22) in plane stress.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "models_private.h"

static const MicaType *const builtin_models[] = {&mica_model_linear.type, &mica_model_svk.type,
                                                 &mica_model_neohooke.type, &mica_model_neohooke_cook.type, NULL};

MicaRegistry mica_model_registry = {"classical model", "linear", builtin_models, NULL, 0, NULL};

const MicaModelOps *mica_model_at(int i) {
  const MicaType *type = mica_registry_type(&mica_model_registry, i);
  return type ? mica_model_of(type) : NULL;
}

const MicaModelOps *mica_model_find(const char *name) {
  const MicaType *type = mica_registry_find(&mica_model_registry, name);
  return type ? mica_model_of(type) : NULL;
}

/* ---- checks shared by the kernels ---- */

int mica_model_check_args_(const MicaModelOps *model, const MicaMaterial *mat, int dim) {
  MICA_CHECK(dim == 2 || dim == 3, MICA_ERR_ARGUMENT, "model '%s': dimension %d (must be 2 or 3)", model->type.name,
             dim);
  MICA_CHECK(dim == 3 || mat->plane != MICA_PLANE_STRESS || mica_type_has(&model->type, MICA_MODEL_PLANE_STRESS),
             MICA_ERR_ARGUMENT,
             "model '%s' does not support plane stress (the material was not set by mica_material_set)",
             model->type.name);
  return MICA_SUCCESS;
}

int mica_model_check_jacobian_(const MicaModelOps *model, double J) {
  /* Written as !(J > 0) so that a NaN determinant is caught too. */
  MICA_CHECK(J > 0.0, MICA_ERR_NUMERIC,
             "det F = %.3g at a quadrature point: model '%s' needs det F > 0 (the material is inverted); "
             "the load step is too large",
             J, model->type.name);
  return MICA_SUCCESS;
}

/* ---- material constants ---- */

/* "'linear'" or "'linear', 'xyz'": the models that support plane stress, for the error message. */
static void list_plane_stress_models(char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  for (int i = 0; mica_model_at(i) && used < size; i++) {
    const MicaType *type = &mica_model_at(i)->type;
    if (!mica_type_has(type, MICA_MODEL_PLANE_STRESS)) continue;
    int n = snprintf(buf + used, size - used, "%s'%s'", used ? ", " : "", type->name);
    if (n < 0) break;
    used += (size_t)n;
  }
}

static int check_poisson(const MicaModelOps *model, double nu) {
  MICA_CHECK(!(nu >= 0.5), MICA_ERR_INPUT,
             "Poisson's ratio ν = %g makes the compressible model '%s' %s; use ν < 0.5", nu, model->type.name,
             nu == 0.5 ? "singular (λ = ∞)" : "unstable (λ < 0 and κ < 0)");
  MICA_CHECK(nu > -1.0, MICA_ERR_INPUT,
             "Poisson's ratio ν = %g is not above −1: the shear modulus μ = E/(2(1 + ν)) of model '%s' %s; "
             "use −1 < ν < 0.5",
             nu, model->type.name, nu == -1.0 ? "is infinite" : "is negative");
  return MICA_SUCCESS;
}

int mica_material_set(const MicaModelOps *model, double E, double nu, MicaPlaneKind plane, MicaMaterial *mat) {
  MICA_CHECK(model && mat, MICA_ERR_ARGUMENT, "mica_material_set: model and mat must not be NULL");
  MICA_CHECK(E > 0.0, MICA_ERR_INPUT, "Young's modulus E = %g must be positive", E);
  MICA_CHECK(isfinite(E), MICA_ERR_INPUT, "Young's modulus E = %g must be finite", E);
  MICA_CHECK(isfinite(nu), MICA_ERR_INPUT, "Poisson's ratio ν = %g must be a number in (−1, 0.5)", nu);
  MICA_CALL(check_poisson(model, nu));
  if (plane == MICA_PLANE_STRESS && !mica_type_has(&model->type, MICA_MODEL_PLANE_STRESS)) {
    char supported[256];
    list_plane_stress_models(supported, sizeof supported);
    MICA_ERROR(MICA_ERR_INPUT, "model '%s' does not support plane stress (only %s do%s); use plane strain or 3-D",
               model->type.name, supported, strchr(supported, ',') ? "" : "es");
  }
  MICA_CHECK(plane == MICA_PLANE_NONE || plane == MICA_PLANE_STRAIN || plane == MICA_PLANE_STRESS,
             MICA_ERR_ARGUMENT, "mica_material_set: unknown plane kind %d", (int)plane);
  mat->E = E;
  mat->nu = nu;
  mat->lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  mat->mu = E / (2.0 * (1.0 + nu));
  mat->kappa = E / (3.0 * (1.0 - 2.0 * nu));
  mat->plane = plane;
  return MICA_SUCCESS;
}

/* ---- output stress and strain ---- */

/* Plane stress (linear elasticity only): the 2-D law gives the in-plane σ with σ_33 = 0; ε_33 follows
 * from σ_33 = λ (tr ε) + 2μ ε_33 = 0, i.e. ε_33 = −λ/(λ + 2μ) (ε_11 + ε_22) = −ν/(1 − ν) (ε_11 + ε_22). */
static int stress_strain_plane_stress(const MicaModelOps *model, const MicaMaterial *mat, const double *F,
                                      double sigma[9], double strain[9]) {
  double W, P[4], F3[9];
  MICA_CALL(model->eval(mat, 2, F, &W, P, NULL));
  t3_embed(2, P, sigma);
  sigma[8] = 0.0;
  t3_embed(2, F, F3);
  t3_small_strain(F3, strain);
  strain[8] = -mat->nu / (1.0 - mat->nu) * (strain[0] + strain[4]);
  return MICA_SUCCESS;
}

int mica_model_stress_strain(const MicaModelOps *model, const MicaMaterial *mat, int dim, const double *F,
                             double *sigma, double *strain) {
  MICA_CHECK(model && mat && F && sigma && strain, MICA_ERR_ARGUMENT, "mica_model_stress_strain: NULL argument");
  MICA_CALL(mica_model_check_args_(model, mat, dim));
  if (dim == 2 && mat->plane == MICA_PLANE_STRESS) return stress_strain_plane_stress(model, mat, F, sigma, strain);

  /* 3-D, and plane strain as the 3-D law at F_33 = 1, which also yields σ_33. */
  double F3[9], P3[9], W;
  t3_embed(dim, F, F3);
  MICA_CALL(model->eval(mat, 3, F3, &W, P3, NULL));
  if (mica_type_has(&model->type, MICA_MODEL_FINITE_STRAIN)) {
    double J = t3_det(F3), tau[9], C[9];
    MICA_CALL(mica_model_check_jacobian_(model, J));
    t3_mul_nt(P3, F3, tau); /* Kirchhoff stress τ = P Fᵀ = J σ */
    t3_mul_tn(F3, F3, C);
    for (int a = 0; a < 9; a++) {
      sigma[a] = tau[a] / J;
      strain[a] = 0.5 * (C[a] - T3_IDENTITY[a]);
    }
  } else {
    for (int a = 0; a < 9; a++) sigma[a] = P3[a]; /* small strain: σ = P */
    t3_small_strain(F3, strain);
  }
  return MICA_SUCCESS;
}
