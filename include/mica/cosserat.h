/* The small-strain Cosserat (micropolar) field model of Eringen (docs/theory.md §Cosserat).
 *
 * Unknowns: 3-D u and φ (ncomp = 6: ux, uy, uz, phix, phiy, phiz); 2-D plane strain u_1, u_2, φ_3 (ncomp = 3:
 * ux, uy, phiz). With e the permutation symbol and the fields' derivatives written ,k:
 *   strain      ε_kl = u_l,k + e_lkm φ_m,          curvature   κ_kl = φ_k,l,
 *   force       σ_kl = λ ε_rr δ_kl + (μ + κ) ε_kl + μ ε_lk,
 *   couple      m_kl = α κ_rr δ_kl + β κ_kl + γ κ_lk,
 *   energy      W = ½ σ_kl ε_kl + ½ m_kl κ_lk        (σ_kl = ∂W/∂ε_kl, m_kl = ∂W/∂κ_lk),
 * and the first index of σ and m is the one the normal contracts with: t_l = σ_kl n_k, m_l = m_kl n_k
 * (balance σ_kl,k + f_l = 0, m_kl,k + e_lmn σ_mn + c_l = 0). In 2-D only γ acts (W_couple = ½ γ |∇φ_3|²).
 *
 * MicaFieldModel.param layout: the MICA_COSSERAT_* slots below hold λ, μ, κ, α, β, γ (Eringen), the others
 * are 0. In 2-D α = β = 0 are stored (they do no work in plane strain). MicaFieldModel.material holds the classical part: G = μ + κ/2
 * as mu, ν, E = 2G(1 + ν), λ, the bulk modulus λ + 2G/3 as kappa, plane = MICA_PLANE_STRAIN in 2-D; the
 * solver scales its penalties by E. classical = NULL.
 */
#ifndef MICA_COSSERAT_H
#define MICA_COSSERAT_H

#include "mica/model.h"

/* The slots of MicaFieldModel.param of the Cosserat models (small strain and finite rotation). */
enum {
  MICA_COSSERAT_LAMBDA = 0, /* λ */
  MICA_COSSERAT_MU = 1,     /* μ */
  MICA_COSSERAT_KAPPA = 2,  /* κ */
  MICA_COSSERAT_ALPHA = 3,  /* α */
  MICA_COSSERAT_BETA = 4,   /* β */
  MICA_COSSERAT_GAMMA = 5   /* γ */
};

extern const MicaFieldModelOps mica_field_cosserat;

/* Eringen's constants (3-D: λ, μ, κ, α, β, γ; 2-D uses λ, μ, κ, γ and ignores α, β). MICA_ERR_INPUT unless
 * the energy is positive semi-definite (Eringen's conditions): 2μ + κ > 0, κ ≥ 0, 3λ + 2μ + κ > 0, and in 3-D
 * 3α + β + γ ≥ 0, γ + β ≥ 0, γ − β ≥ 0; in 2-D γ > 0. m is written only on success. */
int mica_cosserat_set_eringen(MicaFieldModel *m, int dim, double lambda, double mu, double kappa, double alpha,
                              double beta, double gamma);

/* Lakes' technical constants: shear modulus G, Poisson's ratio ν, coupling number N, torsion and bending
 * lengths l_t, l_b and polar ratio Ψ (2-D: one length, pass l_t = l_b = l; Ψ is ignored). Converted by
 *   κ = 2GN²/(1 − N²), μ = G − κ/2, λ = 2Gν/(1 − 2ν), γ = 4G l_b², β = 2G l_t² − γ, α = (β + γ)(1 − Ψ)/Ψ
 * (2-D: γ = 4G l², α = β = 0). MICA_ERR_INPUT naming the parameter if G ≤ 0, ν ∉ (−1, 0.5), N ∉ [0, 1),
 * l_t ≤ 0 or l_b ≤ 0, and in 3-D Ψ ∉ (0, 1.5] or l_t > 2 l_b (γ − β < 0); in 2-D if l_t ≠ l_b. */
int mica_cosserat_set_technical(MicaFieldModel *m, int dim, double G, double nu, double N, double l_t, double l_b,
                                double psi);

/* ---- Cosserat with finite rotations (src/models/cosserat_finite.c) ------------------------------------------
 *
 * Same unknowns, names and constants as the small-strain model, but φ is the total rotation vector Φ (2-D: the
 * angle φ_z) and the kinematics are finite: F = I + ∇u, R = exp(skew Φ) (mica/rotation.h), stretch
 * E = RᵀF − I, wryness Γ_kJ = T_km(Φ) Φ_m,J (Rᵀ ∂_J R = skew Γ_J), and W is the small-strain energy above with
 * ε_kl ← E_lk, κ_kl ← Γ_kl. Invariant under superposed rigid rotations (R → QR, F → QF); at q = 0 the tangent
 * is the small-strain one. order 1, finite = 1, uses_values = 1. The tangent is the exact Hessian: symmetric,
 * possibly indefinite away from equilibrium. In 3-D eval fails with MICA_ERR_NUMERIC at |Φ| ≥ 2π (T singular);
 * in 2-D every angle is allowed. stress() returns the force and couple stress per deformed area in the deformed
 * frame, face index first: σ = J⁻¹ F Sᵀ Rᵀ, m = J⁻¹ F Mᵀ Rᵀ (S = ∂W/∂E, M = ∂W/∂Γ). */
extern const MicaFieldModelOps mica_field_cosserat_finite;

/* Switches a model whose constants were set by mica_cosserat_set_eringen or mica_cosserat_set_technical (same
 * checks, same param layout) to finite rotations. MICA_ERR_ARGUMENT if m is not such a model. */
int mica_cosserat_finite_set(MicaFieldModel *m);

#endif
