/* The gradient micromorph kinds beyond χ = F (docs/theory.md §micromorph). Every macro point X
 * carries a micro box S (sizes[K] along axis K; 0: no extent), a micro point sits at x̂(X, Y) = x(X) + χ(X) Y,
 * its deformation gradient is F̂ = ∂x̂/∂X, i.e. F̂_aK = F_aK + (∂_K χ_aJ) Y_J, and
 *   W(X) = (1/|S|) ∫_S ψ(F̂(Y)) dY        (Gauss points in Y; ψ a classical kernel: linear, svk, neohooke, ...).
 * χ = F is mica_field_micromorph (mica/model.h). Here:
 *
 *   isochoric  χ = J^(−1/3) F (orientation and micro-shear, no micro-stretch of volume); unknowns u, order 2.
 *              In 2-D J = det F₃ of the plane-strain embedding (F_33 = 1) and the exponent stays −1/3, so the
 *              2-D kind is the 3-D kind restricted to plane fields.
 *   rotation   χ = R(Φ) with an independent rotation vector Φ (mica/rotation.h); unknowns u and Φ (2-D: ux, uy,
 *              phiz; 3-D: ux..uz, phix..phiz), order 1. F̂ = F − R Ŷ Γ with Ŷ = skew Y and Γ_iK = T_ik Φ_k,K,
 *              and W adds the Cosserat coupling ½ κ_c |skew(RᵀF)|², κ_c = 2 G N²/(1 − N²), G = μ of ψ.
 *              At small strain this is Eringen's Cosserat model with λ, μ − κ_c/2, κ_c and, for a micro cube
 *              (2-D: square) of side l, α = −μ l²/12, β = −λ l²/12, γ = (λ + 3μ) l²/12.
 */
#ifndef MICA_MICROMORPH_H
#define MICA_MICROMORPH_H

#include "mica/model.h"

extern const MicaFieldModelOps mica_field_micromorph_isochoric, mica_field_micromorph_rotation;

/* χ = J^(−1/3) F. MICA_ERR_INPUT if a size is negative or not finite. */
int mica_micromorph_isochoric_set(MicaFieldModel *m, int dim, const MicaModelOps *micro_energy,
                                  const MicaMaterial *material, const double *sizes);

/* χ = R(Φ) with coupling number N ∈ [0, 1). MICA_ERR_INPUT if a size is negative or not finite, if no size is
 * positive (without a micro space ∇Φ stores no energy: there is no size effect, use χ = F without micro axes
 * or material.model = "cosserat"), or N ∉ [0, 1). */
int mica_micromorph_rotation_set(MicaFieldModel *m, int dim, const MicaModelOps *micro_energy,
                                 const MicaMaterial *material, const double *sizes, double N);

#endif
