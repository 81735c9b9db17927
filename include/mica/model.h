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
#include "mica/registry.h"

typedef enum { MICA_PLANE_NONE = 0, MICA_PLANE_STRAIN = 1, MICA_PLANE_STRESS = 2 } MicaPlaneKind;

typedef struct MicaMaterial {
  double E, nu;        /* Young's modulus and Poisson's ratio: the inputs */
  double lambda, mu;   /* Lamé constants, derived by mica_material_set */
  double kappa;        /* bulk modulus E / (3 (1 − 2ν)) */
  MicaPlaneKind plane; /* in 2-D: plane strain or plane stress */
} MicaMaterial;

/* Capability flags of a classical model (MicaType.flags). */
enum {
  MICA_MODEL_FINITE_STRAIN = 1u << 0, /* finite kinematics (else small strain: σ = P, ε = sym ∇u) */
  MICA_MODEL_PLANE_STRESS = 1u << 1   /* supports MICA_PLANE_STRESS in 2-D */
};

typedef struct MicaModelOps {
  MicaType type; /* "linear", "svk", "neohooke", "neohooke-cook"; MICA_MODEL_* flags */
  /* W, P, A at F; P or A may be NULL when not needed. Returns MICA_ERR_NUMERIC when F is inadmissible
   * (det F ≤ 0 for models with ln J), so Newton can cut the load step back. */
  int (*eval)(const MicaMaterial *mat, int dim, const double *F, double *W, double *P, double *A);
} MicaModelOps;

extern const MicaModelOps mica_model_linear, mica_model_svk, mica_model_neohooke, mica_model_neohooke_cook;
/* The classical models: `material.micro_model` chooses one, and they come first among the continuum models
 * of `material.model` (mica_field_model_registry); the default is named here only. */
extern MicaRegistry mica_model_registry;
static inline const MicaModelOps *mica_model_of(const MicaType *type) { return (const MicaModelOps *)type; }
/* The i-th registered classical model (NULL past the last), and lookup by name (NULL if unknown). */
const MicaModelOps *mica_model_at(int i);
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

/* Capability flags of a field model (MicaType.flags). */
enum {
  MICA_FIELD_FINITE = 1u << 0,        /* W is not quadratic in q (Newton iterates) */
  MICA_FIELD_USES_VALUES = 1u << 1,   /* W depends on the values of the unknowns, not only their derivatives */
  MICA_FIELD_CLASSICAL = 1u << 2,     /* the adapter of a classical kernel (m->classical: its P and A) */
  MICA_FIELD_COUPLE_STRESS = 1u << 3, /* stress() reports a couple stress (the Cosserat models) */
  MICA_FIELD_FINITE_ROTATION_FORM = 1u << 4 /* a small-rotation model whose constants (param) the finite-rotation
                                               Cosserat model takes as they are (mica_cosserat_finite_set) */
};

typedef struct MicaFieldModelOps {
  /* name ("cosserat", ...; the classical models appear under their own names), description, MICA_FIELD_*
   * flags, and from_settings: reads the model's constants from the material.* settings into a
   * MicaFieldModelRead. */
  MicaType type;
  int order;                /* derivatives of the unknowns the energy needs: 1 or 2 (a number, like a basis order) */
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

enum { MICA_FIELD_MODEL_NPARAM = 16 }; /* slots of MicaFieldModel.param */

struct MicaFieldModel {
  const MicaFieldModelOps *ops;
  MicaMaterial material;  /* E, ν and the Lamé constants (the classical part) */
  const MicaModelOps *classical; /* for classical models: the point kernel the field model adapts */
  /* Model constants; each field model names its slots (MICA_COSSERAT_* in mica/cosserat.h, MICRO_* in
   * src/models/micromorph_private.h, GRADIENT_* in src/models/strain_gradient.c); unused slots are 0. */
  double param[MICA_FIELD_MODEL_NPARAM];
};

/* Number of entries of q for a model in dim dimensions. */
int mica_field_model_nq(const MicaFieldModel *m, int dim);
/* 1 if W is quadratic in q (linear equations: Newton converges in one step): a classical model of small
 * strain, or a field model without MICA_FIELD_FINITE. */
int mica_field_model_quadratic(const MicaFieldModel *m);

/* ---- The continuum models of a deck (`material.model`) ----
 * The registry lists the classical models first (its base, mica_model_registry: each is read by
 * mica_model_classical_read and lifted by mica_field_classical), then the field models (cosserat,
 * cosserat-finite, micromorph, strain-gradient, couple-stress). A field model's from_settings reads its
 * constants (group "material") into a MicaFieldModelRead; the caller sets dim. */
typedef struct MicaFieldModelRead {
  int dim;               /* of the body: 2 (plane) or 3 */
  MicaFieldModel *model; /* written on success */
} MicaFieldModelRead;

extern MicaRegistry mica_field_model_registry;
/* The model that `name` names (a classical one adapted, or a field model), its settings read from group. */
int mica_field_model_from_settings(const char *name, const MicaSettings *settings, const char *group, int dim,
                                   MicaFieldModel *model);
/* A classical model's material: E and ν, plane strain or stress in 2-D (group.plane), each checked with the
 * setting's line. */
int mica_model_material_from_settings(const MicaModelOps *model, const MicaSettings *settings, const char *group,
                                      int dim, MicaMaterial *material);

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
