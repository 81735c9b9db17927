/* Finite rotations by a rotation vector Φ (docs/theory.md §finite rotations).
 *
 * With θ = |Φ| and Φ̂ = skew Φ (Φ̂ v = Φ × v):
 *   R(Φ) = exp(Φ̂) = I + a(θ) Φ̂ + b(θ) Φ̂²,          a = sin θ / θ,  b = (1 − cos θ) / θ²,
 *   T(Φ) = I − b(θ) Φ̂ + c(θ) Φ̂²,                    c = (θ − sin θ) / θ³,
 * T is the right tangent of the exponential map: exp(Φ + δΦ) = exp(Φ) exp(skew(T(Φ) δΦ)) to first order, so
 *   Rᵀ ∂R/∂Φ_i = skew(T e_i),   and the material curvature (wryness) of a rotation field is
 *   Rᵀ ∂_J R = skew(Γ_J),  Γ_iJ = T_ik(Φ) Φ_k,J.
 * The coefficient functions use Taylor series below a small θ, so every entry and derivative is smooth and
 * exact to round-off at Φ = 0. The parametrization is singular at θ = 2π k (k ≥ 1: T loses rank 2): a
 * total-rotation-vector field must stay below 2π in magnitude in 3-D (in 2-D, Φ = φ e_z, it need not).
 *
 * Layouts: 3×3 matrices row-major [a*3 + b]; first derivatives d[i][.] = ∂/∂Φ_i; second derivatives
 * dd[h][.] = ∂²/∂Φ_i∂Φ_j with h = mls_hess_index(3, i, j) (packed: 00, 11, 22, 12, 02, 01).
 */
#ifndef MICA_ROTATION_H
#define MICA_ROTATION_H

typedef struct MicaRotation {
  double R[9], dR[3][9], ddR[6][9]; /* R and its first and second derivatives with respect to Φ */
  double T[9], dT[3][9], ddT[6][9]; /* T and its first and second derivatives with respect to Φ */
} MicaRotation;

/* R, T and their derivatives up to order nderiv (0, 1 or 2; the others are left untouched). */
void mica_rotation_eval(const double phi[3], int nderiv, MicaRotation *rot);

/* The rotation vector of a rotation matrix (θ ∈ [0, π]), for output and tests. */
void mica_rotation_log(const double R[9], double phi[3]);

#endif
