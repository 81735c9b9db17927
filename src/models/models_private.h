/* Private to src/models: 3×3 tensor helpers shared by the kernels, the 2-D ↔ 3-D embedding, the builders
 * of the tangent A from its standard terms, and the argument/admissibility checks (docs/theory.md §models,
 * "Notation and the plane cases").
 *
 * Every kernel evaluates its 3-D law on the embedded F3 (F_33 = 1, F_i3 = F_3i = 0 in 2-D), so the plane
 * strain response is exactly the in-plane block of the 3-D one; the helpers below write only the
 * in-plane block (indices < dim) of P and A. 3×3 tensors are row-major, a[3*i + j]. Nothing allocates:
 * the kernels run at every quadrature point of every Newton iteration.
 */
#ifndef MICA_MODELS_PRIVATE_H
#define MICA_MODELS_PRIVATE_H

#include "mica/model.h"

static const double T3_IDENTITY[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

/* F3 = F in the leading dim×dim block, the identity elsewhere (plane strain: u_3 = 0, so F_33 = 1). */
static inline void t3_embed(int dim, const double *F, double F3[9]) {
  for (int a = 0; a < 9; a++) F3[a] = T3_IDENTITY[a];
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) F3[3 * i + j] = F[i * dim + j];
}

/* P = the leading dim×dim block of P3. */
static inline void t3_extract(int dim, const double P3[9], double *P) {
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) P[i * dim + j] = P3[3 * i + j];
}

static inline double t3_det(const double a[9]) {
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
         a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/* cof(a)_ij = ∂ det a / ∂a_ij, so that a⁻ᵀ = cof(a) / det a without a division per entry twice. */
static inline void t3_cofactor(const double a[9], double cof[9]) {
  cof[0] = a[4] * a[8] - a[5] * a[7];
  cof[1] = a[5] * a[6] - a[3] * a[8];
  cof[2] = a[3] * a[7] - a[4] * a[6];
  cof[3] = a[2] * a[7] - a[1] * a[8];
  cof[4] = a[0] * a[8] - a[2] * a[6];
  cof[5] = a[1] * a[6] - a[0] * a[7];
  cof[6] = a[1] * a[5] - a[2] * a[4];
  cof[7] = a[2] * a[3] - a[0] * a[5];
  cof[8] = a[0] * a[4] - a[1] * a[3];
}

/* a⁻ᵀ given det a (the caller has checked that it is positive). */
static inline void t3_inverse_transpose(const double a[9], double det, double inv_t[9]) {
  t3_cofactor(a, inv_t);
  double scale = 1.0 / det;
  for (int k = 0; k < 9; k++) inv_t[k] *= scale;
}

/* The small strain ε = sym(F3 − I). */
static inline void t3_small_strain(const double F3[9], double eps[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) eps[3 * i + j] = 0.5 * (F3[3 * i + j] + F3[3 * j + i]) - T3_IDENTITY[3 * i + j];
}

/* a : b = a_ij b_ij. */
static inline double t3_contract(const double a[9], const double b[9]) {
  double s = 0.0;
  for (int k = 0; k < 9; k++) s += a[k] * b[k];
  return s;
}

static inline double t3_trace(const double a[9]) { return a[0] + a[4] + a[8]; }

/* c = a b. */
static inline void t3_mul(const double a[9], const double b[9], double c[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

/* c = aᵀ b (right Cauchy–Green C = FᵀF). */
static inline void t3_mul_tn(const double a[9], const double b[9], double c[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) c[3 * i + j] = a[i] * b[j] + a[3 + i] * b[3 + j] + a[6 + i] * b[6 + j];
}

/* c = a bᵀ (left Cauchy–Green b = FFᵀ, Kirchhoff stress P Fᵀ). */
static inline void t3_mul_nt(const double a[9], const double b[9], double c[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      c[3 * i + j] = a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1] + a[3 * i + 2] * b[3 * j + 2];
}

/* ---- The tangent A_iJkL = ∂P_iJ/∂F_kL as a sum of standard terms, over the in-plane indices ----
 * Index of A in the dim⁴ layout of mica/model.h. */
static inline int a_index(int dim, int i, int J, int k, int L) { return ((i * dim + J) * dim + k) * dim + L; }

static inline void a_zero(int dim, double *A) {
  int n = dim * dim * dim * dim;
  for (int a = 0; a < n; a++) A[a] = 0.0;
}

/* A_iJkL += c X_iJ Y_kL  (dyadic product X ⊗ Y) */
static inline void a_add_dyad(int dim, double c, const double X[9], const double Y[9], double *A) {
  for (int i = 0; i < dim; i++)
    for (int J = 0; J < dim; J++) {
      double cx = c * X[3 * i + J];
      for (int k = 0; k < dim; k++)
        for (int L = 0; L < dim; L++) A[a_index(dim, i, J, k, L)] += cx * Y[3 * k + L];
    }
}

/* A_iJkL += c X_iL Y_kJ  (the "crossed" product that ∂F⁻ᵀ/∂F and ∂(F S)/∂F produce) */
static inline void a_add_cross(int dim, double c, const double X[9], const double Y[9], double *A) {
  for (int i = 0; i < dim; i++)
    for (int J = 0; J < dim; J++)
      for (int k = 0; k < dim; k++)
        for (int L = 0; L < dim; L++) A[a_index(dim, i, J, k, L)] += c * X[3 * i + L] * Y[3 * k + J];
}

/* A_iJkL += c X_ik Y_JL  (with X = Y = I: the identity on second-order tensors, ∂F/∂F) */
static inline void a_add_ik_jl(int dim, double c, const double X[9], const double Y[9], double *A) {
  for (int i = 0; i < dim; i++)
    for (int J = 0; J < dim; J++)
      for (int k = 0; k < dim; k++)
        for (int L = 0; L < dim; L++) A[a_index(dim, i, J, k, L)] += c * X[3 * i + k] * Y[3 * J + L];
}

/* ---- Unknowns of the models with rotations (cosserat.c) ----
 * Displacements and a rotation (small-strain or total): 2-D ux, uy, phiz (tractions tx, ty, mz); 3-D ux..uz,
 * phix..phiz (tx..tz, mx..mz). Shared by the Cosserat models and the micromorph kind χ = R(Φ). */
int mica_rotation_model_ncomp_(int dim);
const char *const *mica_rotation_model_components_(int dim);
const char *const *mica_rotation_model_tractions_(int dim);

/* ---- The readers of the field models' settings (settings.c): each a MicaType.from_settings, options a
 * MicaFieldModelRead ---- */
int mica_cosserat_from_settings_(const MicaType *type, const MicaSettings *s, const char *group, void *options);
int mica_cosserat_finite_from_settings_(const MicaType *type, const MicaSettings *s, const char *group,
                                        void *options);
int mica_micromorph_from_settings_(const MicaType *type, const MicaSettings *s, const char *group, void *options);
int mica_strain_gradient_from_settings_(const MicaType *type, const MicaSettings *s, const char *group,
                                        void *options);
int mica_couple_stress_from_settings_(const MicaType *type, const MicaSettings *s, const char *group, void *options);
extern const MicaFieldModelOps mica_field_couple_stress;

/* ---- Checks (model.c) ---- */

/* dim is 2 or 3; in 2-D, plane stress only for a model that supports it. MICA_ERR_ARGUMENT otherwise: a
 * caller that went around mica_material_set. */
int mica_model_check_args_(const MicaModelOps *model, const MicaMaterial *mat, int dim);
/* MICA_ERR_NUMERIC naming det F when J ≤ 0 (or NaN): ln J and J^(−2/3) do not exist there. */
int mica_model_check_jacobian_(const MicaModelOps *model, double J);

#endif
