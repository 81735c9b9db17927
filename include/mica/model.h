/* Continuum models (an ops table; docs/theory.md §Continuum models): a point kernel that, given the deformation gradient F at a
 * quadrature point, returns the strain-energy density W, the first Piola–Kirchhoff stress P = ∂W/∂F and
 * the tangent A = ∂P/∂F. The assembly is the same for every model:
 *   R_Ia = ∫ P_aJ N_I,J dV − f_ext,     K_IaKb = ∫ N_I,J A_aJbL N_K,L dV     (total Lagrangian)
 * Models with linear kinematics (linear elasticity) are written in the same form with P = σ(ε), ε = sym ∇u
 * = sym(F − I), A = C: their residual is then linear in u and Newton converges in one iteration.
 *
 * Layouts, row-major with dim = 2 or 3: F[i*dim + J], P[i*dim + J], A[((i*dim + J)*dim + k)*dim + L].
 * In 2-D, plane strain embeds F in 3-D with F_33 = 1 (u_3 = 0); plane stress is for linear elasticity only.
 * docs/theory.md §models has every formula.
 */
#ifndef MICA_MODEL_H
#define MICA_MODEL_H

#include "mica/error.h"

typedef enum { MICA_PLANE_NONE = 0, MICA_PLANE_STRAIN = 1, MICA_PLANE_STRESS = 2 } MicaPlaneKind;

typedef struct MicaMaterial {
  double E, nu;        /* Young's modulus and Poisson's ratio: the inputs */
  double lambda, mu;   /* Lamé constants, derived by mica_material_set */
  double kappa;        /* bulk modulus E / (3 (1 − 2ν)) */
  MicaPlaneKind plane; /* in 2-D: plane strain or plane stress */
} MicaMaterial;

typedef struct MicaModelOps {
  const char *name;        /* "linear", "svk", "neohooke", "neohooke-cook" */
  const char *description; /* one line */
  int finite_strain;       /* 0: linear kinematics */
  int plane_stress;        /* 1 if MICA_PLANE_STRESS is supported */
  /* W, P, A at F; P or A may be NULL when not needed. Returns MICA_ERR_NUMERIC when F is inadmissible
   * (det F ≤ 0 for models with ln J), so Newton can cut the load step back. */
  int (*eval)(const MicaMaterial *mat, int dim, const double *F, double *W, double *P, double *A);
} MicaModelOps;

extern const MicaModelOps mica_model_linear, mica_model_svk, mica_model_neohooke, mica_model_neohooke_cook;
const MicaModelOps *const *mica_model_all(void); /* NULL-terminated */
const MicaModelOps *mica_model_find(const char *name);

/* Derives λ, μ, κ from E, ν. MICA_ERR_INPUT with a message (no location: the caller prefixes the deck
 * line) if E ≤ 0 or ν ∉ (−1, 0.5), or plane stress is asked of a model that does not support it. */
int mica_material_set(const MicaModelOps *model, double E, double nu, MicaPlaneKind plane, MicaMaterial *mat);

/* Cauchy stress σ = J⁻¹ P Fᵀ (3×3, with the out-of-plane σ_33 for plane strain / plane stress = 0) and the
 * small-strain or Green–Lagrange strain, for output. sigma and strain are [9], row-major 3×3. */
int mica_model_stress_strain(const MicaModelOps *model, const MicaMaterial *mat, int dim, const double *F,
                             double *sigma, double *strain);

/* ---- Generalized continua: models of generalized kinematics ------------------------------------------------
 *
 * A field model has ncomp unknown components per particle (classical: the dim displacements; 2-D Cosserat:
 * u_x, u_y, φ_z; 3-D Cosserat: u and φ) and an energy density W(q) of the generalized kinematics q at a
 * point, laid out as
 *   q = [ values (ncomp) | gradients (ncomp × dim): ∂_J v_c at c*dim + J | Hessians (ncomp × nh), if order 2 ]
 * with nh = dim(dim+1)/2 in the packed Voigt order of mica/mls.h. eval returns W, s = ∂W/∂q (nq) and
 * D = ∂s/∂q (nq × nq, row-major). The assembly is the same for every model:
 *   R_kc = Σ_q w Σ_j s_j B_j(k,c),  K_(kc)(ld) = Σ_q w Σ_ij B_i(k,c) D_ij B_j(l,d),
 * with B_j(k,c) = N_k, N_k,J or N_k,h in the slots of component c. */
typedef struct MicaFieldModel MicaFieldModel;

typedef struct MicaFieldModelOps {
  const char *name;         /* "cosserat", ... (the classical models appear under their own names) */
  int order;                /* derivatives of the unknowns the energy needs: 1 or 2 */
  int finite;               /* 1: W is not quadratic in q (Newton iterates) */
  int uses_values;          /* 1: W depends on the values of the unknowns (not only their derivatives) */
  int (*ncomp)(int dim);    /* unknowns per particle in dim dimensions */
  const char *const *(*component_names)(int dim); /* "ux", "uy", "phiz", ... ; the deck's Dirichlet keys */
  const char *const *(*traction_names)(int dim);  /* "tx", "ty", "mz", ... ; the deck's traction keys */
  int (*eval)(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D);
  /* Force stress (3×3, row-major) and, if present, couple stress (3×3) at q, for output and probes. */
  int (*stress)(const MicaFieldModel *m, int dim, const double *q, double *sigma, double *couple);
  /* The micro-deformation χ (3×3, row-major; in 2-D of the plane embedding) at q, for output; NULL for models
   * without one (the gradient micromorph kinds have χ = F, J^(−1/3) F, R(Φ)). */
  int (*micro_deformation)(const MicaFieldModel *m, int dim, const double *q, double *chi);
} MicaFieldModelOps;

struct MicaFieldModel {
  const MicaFieldModelOps *ops;
  MicaMaterial material;  /* E, ν and the Lamé constants (the classical part) */
  const MicaModelOps *classical; /* for classical models: the point kernel the field model adapts */
  double param[16];       /* model constants, documented per model (Cosserat: λ, μ, κ, α, β, γ, ...) */
};

/* Number of entries of q for a model in dim dimensions. */
int mica_field_model_nq(const MicaFieldModel *m, int dim);

/* The classical models as field models (src/models/classical_field.c): ncomp = dim, order 1, and
 * W(q) = W(F = I + ∇u) through the classical kernel, whose P and A fill the gradient slots of s and D. */
extern const MicaFieldModelOps mica_field_classical;
int mica_field_classical_set(MicaFieldModel *m, const MicaModelOps *classical, const MicaMaterial *material);

/* The gradient micromorph continuum with χ = F (src/models/micromorph.c): unknowns u, order 2, micro energy
 * micro_energy (a classical kernel: linear, svk, neohooke) averaged over a micro box with sizes[K] along
 * axis K (0: no extent along K; the micro-space dimension is the number of nonzero sizes). */
extern const MicaFieldModelOps mica_field_micromorph;
int mica_micromorph_set(MicaFieldModel *m, int dim, const MicaModelOps *micro_energy, const MicaMaterial *material,
                        const double *sizes);

/* Small-strain gradient elasticity (src/models/strain_gradient.c), unknowns u, order 2: first strain
 * gradient with one length l (couple_stress = 0) or the modified couple-stress theory (couple_stress = 1). */
extern const MicaFieldModelOps mica_field_strain_gradient;
int mica_strain_gradient_set(MicaFieldModel *m, const MicaMaterial *material, double l, int couple_stress);

#endif
