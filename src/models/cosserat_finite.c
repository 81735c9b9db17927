/* Cosserat (micropolar) elasticity with finite rotations (mica/cosserat.h, docs/theory.md §"Cosserat with
 * finite rotations"). The MLS approximates u and the total rotation vector Φ; at a quadrature point
 *   F = I + ∇u,   R = exp(skew Φ),   stretch E = RᵀF − I,   wryness Γ_kJ = T_km(Φ) Φ_m,J  (Rᵀ∂_J R = skew Γ_J),
 * and W is the small-strain Cosserat energy of cosserat.c with ε ← Eᵀ and κ ← Γ:
 *   ε_kl = u_l,k + e_lkm φ_m is the transpose of (I + ∇u − skew φ) − I, the linearization of RᵀF − I, and
 *   κ_kl = φ_k,l that of Γ_kl (T = I + O(Φ)). So at q = 0 the tangent is the small-strain one.
 * With y = [E | Γ] (18 numbers, W quadratic in y: ∂²W/∂y² = C constant) and the stresses
 *   S_aK = ∂W/∂E_aK = σ_Ka,   M_kJ = ∂W/∂Γ_kJ = m_Jk     (σ, m: the small-strain law at ε = Eᵀ, κ = Γ),
 * the kernel returns
 *   s = (∂y/∂q)ᵀ [S | M],     D = (∂y/∂q)ᵀ C (∂y/∂q) + Σ_a (∂W/∂y_a) ∂²y_a/∂q²,
 * both exact; D is symmetric (a Hessian) and may be indefinite far from equilibrium.
 *
 * 2-D (plane strain, ux uy phiz) is the 3-D kernel on the embedded q, as in cosserat.c, with R the rotation
 * by φ about z written out (no series needed at any φ: 2π is not special) and Γ_3J = φ,J, because
 * T(φ e_z) e_z = e_z for every φ: only that column of T, and none of its derivatives, reaches the 2-D slots.
 */
#include <math.h>
#include <string.h>

#include "mica/cosserat.h"
#include "mica/rotation.h"
#include "models_private.h"

#define NC3 6               /* 3-D components: u_1, u_2, u_3, Φ_1, Φ_2, Φ_3 */
#define NQ3 (NC3 * (1 + 3)) /* 3-D q: 6 values and 6 × 3 gradients */
#define PHI 3               /* Φ_m is 3-D component PHI + m */
#define NY 18               /* y = [E (9) | Γ (9)] */
#define GAM 9               /* Γ_kJ is y[GAM + 3k + J] */
#define TWO_PI 6.283185307179586

typedef struct {
  double lambda, mu, kappa, alpha, beta, gamma;
} Constants;

/* The kinematics at one point, with what the derivatives need. */
typedef struct {
  double F[9];      /* F_lK = δ_lK + u_l,K (plane strain: F_33 = 1) */
  double gphi[9];   /* Φ_m,J at [3m + J] */
  MicaRotation rot; /* R, T and their derivatives in Φ */
  double y[NY];     /* E_aK at [3a + K], then Γ_kJ */
} State;

/* ---- slots of q (the 3-D layout of cosserat.c; the 2-D slots are a subset) ---- */

static int ncomp_of(int dim) { return mica_rotation_model_ncomp_(dim); }
static int nq_of(int dim) { return ncomp_of(dim) * (1 + dim); }
static int grad3(int c, int J) { return NC3 + 3 * c + J; }

static const int comp2_to_3[3] = {0, 1, PHI + 2};

/* Slot of the 3-D q that holds entry j of the q in dim dimensions. */
static int slot_of(int dim, int j) {
  if (dim == 3) return j;
  if (j < 3) return comp2_to_3[j];
  return grad3(comp2_to_3[(j - 3) / 2], (j - 3) % 2);
}

/* ---- rotations ---- */

/* 2-D: Φ = φ e_z. R = rotation by φ about z, its first and second φ-derivatives in the z slots (packed index
 * 2 = zz of mls_hess_index); T = I stands for its column T e_z = e_z, the only one the 2-D slots read. */
static void rotation_about_z(double phi, MicaRotation *rot) {
  memset(rot, 0, sizeof *rot);
  const double c = cos(phi), s = sin(phi);
  const double R[9] = {c, -s, 0, s, c, 0, 0, 0, 1}, dR[9] = {-s, -c, 0, c, -s, 0, 0, 0, 0},
               ddR[9] = {-c, s, 0, -s, -c, 0, 0, 0, 0};
  memcpy(rot->R, R, sizeof R);
  memcpy(rot->dR[2], dR, sizeof dR);
  memcpy(rot->ddR[2], ddR, sizeof ddR);
  memcpy(rot->T, T3_IDENTITY, sizeof rot->T);
}

/* Packed index of the pair (i, j) in the order 00, 11, 22, 12, 02, 01 (mica/rotation.h). */
static int pair_index(int i, int j) {
  if (i == j) return i;
  return 6 - i - j; /* 12 → 3, 02 → 4, 01 → 5 */
}

/* ---- kinematics ---- */

/* F, ∇Φ, R and T (with derivatives up to nderiv), E = RᵀF − I and Γ_kJ = T_km Φ_m,J from the 3-D q. */
static void kinematics(int dim, const double q3[NQ3], int nderiv, State *st) {
  for (int l = 0; l < 3; l++)
    for (int K = 0; K < 3; K++) {
      st->F[3 * l + K] = T3_IDENTITY[3 * l + K] + q3[grad3(l, K)];
      st->gphi[3 * l + K] = q3[grad3(PHI + l, K)];
    }
  if (dim == 2)
    rotation_about_z(q3[PHI + 2], &st->rot);
  else
    mica_rotation_eval(q3 + PHI, nderiv, &st->rot);
  double RtF[9], Gam[9];
  t3_mul_tn(st->rot.R, st->F, RtF);
  t3_mul(st->rot.T, st->gphi, Gam);
  for (int a = 0; a < 9; a++) {
    st->y[a] = RtF[a] - T3_IDENTITY[a];
    st->y[GAM + a] = Gam[a];
  }
}

/* ---- the law: the small-strain Cosserat energy in y ---- */

/* [S | M] = ∂W/∂y: cosserat.c's σ_kl = λ ε_rr δ_kl + (μ + κ) ε_kl + μ ε_lk and m_kl = α κ_rr δ_kl + β κ_kl +
 * γ κ_lk at ε = Eᵀ, κ = Γ, transposed (S = σᵀ, M = mᵀ since m_kl = ∂W/∂κ_lk):
 *   S_aK = λ E_rr δ_aK + (μ + κ) E_aK + μ E_Ka,     M_kJ = α Γ_rr δ_kJ + β Γ_Jk + γ Γ_kJ.
 * Linear in y, so the same function maps a strain increment to its stress increment (C δy). */
static void stresses(const Constants *c, const double y[NY], double sm[NY]) {
  const double *E = y, *G = y + GAM;
  const double trE = t3_trace(E), trG = t3_trace(G);
  for (int a = 0; a < 3; a++)
    for (int K = 0; K < 3; K++) {
      const int aK = 3 * a + K, Ka = 3 * K + a;
      sm[aK] = c->lambda * trE * T3_IDENTITY[aK] + (c->mu + c->kappa) * E[aK] + c->mu * E[Ka];
      sm[GAM + aK] = c->alpha * trG * T3_IDENTITY[aK] + c->beta * G[Ka] + c->gamma * G[aK];
    }
}

/* W = ½ [S | M] · y (W is a quadratic form in y). */
static double energy(const double y[NY], const double sm[NY]) {
  double w = 0;
  for (int a = 0; a < NY; a++) w += sm[a] * y[a];
  return 0.5 * w;
}

/* ---- first derivatives of y ---- */

/* Jy[a][j] = ∂y_a/∂q3_j, dense 18 × 24:
 *   ∂E_aK/∂u_l,K' = R_la δ_KK',   ∂E_aK/∂Φ_i = (∂R/∂Φ_i)_la F_lK,
 *   ∂Γ_kJ/∂Φ_i = (∂T/∂Φ_i)_km Φ_m,J,   ∂Γ_kJ/∂Φ_m,J' = T_km δ_JJ'. */
static void y_jacobian(const State *st, double Jy[NY][NQ3]) {
  memset(Jy, 0, sizeof(double) * NY * NQ3);
  const MicaRotation *r = &st->rot;
  for (int a = 0; a < 3; a++)
    for (int K = 0; K < 3; K++) {
      double *rowE = Jy[3 * a + K], *rowG = Jy[GAM + 3 * a + K];
      for (int l = 0; l < 3; l++) {
        rowE[grad3(l, K)] = r->R[3 * l + a];
        rowG[grad3(PHI + l, K)] = r->T[3 * a + l];
      }
      for (int i = 0; i < 3; i++) {
        double dE = 0, dG = 0;
        for (int m = 0; m < 3; m++) {
          dE += r->dR[i][3 * m + a] * st->F[3 * m + K];
          dG += r->dT[i][3 * a + m] * st->gphi[3 * m + K];
        }
        rowE[PHI + i] = dE;
        rowG[PHI + i] = dG;
      }
    }
}

/* ---- second derivatives: Σ_a (∂W/∂y_a) ∂²y_a/∂q² (only pairs with a Φ value are nonzero) ---- */

/* H3 (24 × 24, symmetric) from S = sm[0..8] and M = sm[9..17]:
 *   ∂u_l,K ∂Φ_i:   (∂R/∂Φ_i)_la S_aK
 *   ∂Φ_i ∂Φ_j:     (∂²R/∂Φ_i∂Φ_j)_la F_lK S_aK + M_kJ (∂²T/∂Φ_i∂Φ_j)_km Φ_m,J
 *   ∂Φ_i ∂Φ_m,J:   M_kJ (∂T/∂Φ_i)_km */
static void geometric_hessian(const State *st, const double sm[NY], double H3[NQ3][NQ3]) {
  memset(H3, 0, sizeof(double) * NQ3 * NQ3);
  const MicaRotation *r = &st->rot;
  const double *S = sm, *M = sm + GAM;
  double RS[9], TdM[9];
  for (int i = 0; i < 3; i++) {
    t3_mul(r->dR[i], S, RS);   /* (∂R/∂Φ_i) S */
    t3_mul_tn(r->dT[i], M, TdM); /* (∂T/∂Φ_i)ᵀ M: [m][J] = Σ_k dT_i[k][m] M_kJ */
    for (int l = 0; l < 3; l++)
      for (int K = 0; K < 3; K++) {
        H3[grad3(l, K)][PHI + i] = H3[PHI + i][grad3(l, K)] = RS[3 * l + K];
        H3[grad3(PHI + l, K)][PHI + i] = H3[PHI + i][grad3(PHI + l, K)] = TdM[3 * l + K];
      }
    for (int j = 0; j <= i; j++) {
      const int h = pair_index(i, j);
      double FS[9], TG[9];
      t3_mul_nt(st->F, S, FS);         /* F Sᵀ: Σ_K F_lK S_aK at [l][a] */
      t3_mul(r->ddT[h], st->gphi, TG); /* (∂²T) ∇Φ */
      const double v = t3_contract(r->ddR[h], FS) + t3_contract(M, TG);
      H3[PHI + i][PHI + j] = H3[PHI + j][PHI + i] = v;
    }
  }
}

/* ---- the kernel ---- */

static Constants constants_of(const MicaFieldModel *m, int dim) {
  const double *p = m->param;
  Constants c = {p[MICA_COSSERAT_LAMBDA], p[MICA_COSSERAT_MU],   p[MICA_COSSERAT_KAPPA],
                 p[MICA_COSSERAT_ALPHA],  p[MICA_COSSERAT_BETA], p[MICA_COSSERAT_GAMMA]};
  if (dim == 2) c.alpha = c.beta = 0.0;
  return c;
}

/* q3 = the 2-D q embedded (u_3 = Φ_1 = Φ_2 = 0, no z-derivatives), a copy in 3-D. */
static void embed_q(int dim, const double *q, double q3[NQ3]) {
  memset(q3, 0, sizeof(double) * NQ3);
  for (int j = 0; j < nq_of(dim); j++) q3[slot_of(dim, j)] = q[j];
}

/* D = Jᵀ C J + H on the slots of dim, with C J built column by column as the stresses of J e_j. */
static void tangent(const Constants *c, int dim, const State *st, const double sm[NY], double *D) {
  const int nq = nq_of(dim);
  double Jy[NY][NQ3], H3[NQ3][NQ3], CJ[NQ3][NY], col[NY];
  y_jacobian(st, Jy);
  geometric_hessian(st, sm, H3);
  for (int j = 0; j < nq; j++) {
    const int sj = slot_of(dim, j);
    for (int a = 0; a < NY; a++) col[a] = Jy[a][sj];
    stresses(c, col, CJ[j]);
  }
  for (int i = 0; i < nq; i++) {
    const int si = slot_of(dim, i);
    for (int j = 0; j < nq; j++) {
      double sum = H3[si][slot_of(dim, j)];
      for (int a = 0; a < NY; a++) sum += Jy[a][si] * CJ[j][a];
      D[i * nq + j] = sum;
    }
  }
}

/* In 3-D, |Φ| = 2π is where T loses rank: the wryness no longer determines ∇Φ and the tangent is singular. */
static int check_rotation(int dim, const double q3[NQ3]) {
  if (dim == 2) return MICA_SUCCESS;
  const double theta = sqrt(q3[PHI] * q3[PHI] + q3[PHI + 1] * q3[PHI + 1] + q3[PHI + 2] * q3[PHI + 2]);
  MICA_CHECK(theta < TWO_PI, MICA_ERR_NUMERIC,
             "finite-rotation Cosserat: the rotation vector has |Φ| = %.6g ≥ 2π, where its parametrization is "
             "singular in 3-D; keep total rotations below 2π",
             theta);
  return MICA_SUCCESS;
}

static int check_args(const MicaFieldModel *m, int dim, const double *q) {
  MICA_CHECK(m && q, MICA_ERR_ARGUMENT, "finite-rotation Cosserat model: NULL model or q");
  MICA_CHECK(dim == 2 || dim == 3, MICA_ERR_ARGUMENT, "finite-rotation Cosserat model: dimension %d (must be 2 or 3)",
             dim);
  return MICA_SUCCESS;
}

/* What eval and stress both start from: the checked q in 3-D, the constants, the kinematics (derivatives up to
 * order) and the material stresses sm of the strain measures. */
static int finite_state(const MicaFieldModel *m, int dim, const double *q, int order, Constants *c, State *st,
                        double *sm) {
  MICA_CALL(check_args(m, dim, q));
  double q3[NQ3];
  embed_q(dim, q, q3);
  MICA_CALL(check_rotation(dim, q3));
  *c = constants_of(m, dim);
  kinematics(dim, q3, order, st);
  stresses(c, st->y, sm);
  return MICA_SUCCESS;
}

static int finite_eval(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D) {
  Constants c;
  State st;
  double sm[NY];
  MICA_CALL(finite_state(m, dim, q, D ? 2 : s ? 1 : 0, &c, &st, sm));
  if (W) *W = energy(st.y, sm);
  if (s) {
    double Jy[NY][NQ3];
    y_jacobian(&st, Jy);
    for (int j = 0; j < nq_of(dim); j++) {
      const int sj = slot_of(dim, j);
      double sum = 0;
      for (int a = 0; a < NY; a++) sum += Jy[a][sj] * sm[a];
      s[j] = sum;
    }
  }
  if (D) tangent(&c, dim, &st, sm, D);
  return MICA_SUCCESS;
}

/* Output: the force and couple stresses per deformed area, in the deformed frame, with the face index first as
 * in cosserat.c (t_l = σ_kl n_k, m_l = m_kl n_k on the deformed face with normal n):
 *   σ = J⁻¹ F Sᵀ Rᵀ   (the transpose of the Cauchy stress J⁻¹ P Fᵀ with P = R S, P_lK = ∂W/∂u_l,K),
 *   m = J⁻¹ F Mᵀ Rᵀ   (the material couple M rotated by R and pushed forward by F),
 * J = det F. At small strain these are the σ and m of cosserat.c. */
static int finite_stress(const MicaFieldModel *m, int dim, const double *q, double *sigma, double *couple) {
  Constants c;
  State st;
  double sm[NY];
  MICA_CALL(finite_state(m, dim, q, 0, &c, &st, sm));
  const double J = t3_det(st.F);
  MICA_CHECK(J > 0.0, MICA_ERR_NUMERIC, "finite-rotation Cosserat: det F = %.3g ≤ 0 at an output point", J);
  double FSt[9], FMt[9], out_s[9], out_m[9];
  t3_mul_nt(st.F, sm, FSt);       /* F Sᵀ */
  t3_mul_nt(st.F, sm + GAM, FMt); /* F Mᵀ */
  t3_mul_nt(FSt, st.rot.R, out_s);
  t3_mul_nt(FMt, st.rot.R, out_m);
  for (int a = 0; a < 9; a++) {
    if (sigma) sigma[a] = out_s[a] / J;
    if (couple) couple[a] = out_m[a] / J;
  }
  return MICA_SUCCESS;
}

const MicaFieldModelOps mica_field_cosserat_finite = {
    .type = {.name = "cosserat-finite",
             .description = "the Cosserat constants with finite rotations (u, total rotation vector Φ)",
             .flags = MICA_FIELD_FINITE | MICA_FIELD_USES_VALUES | MICA_FIELD_COUPLE_STRESS, /* R depends on Φ */
             .from_settings = mica_cosserat_finite_from_settings_},
    .order = 1,
    .ncomp = ncomp_of,
    .component_names = mica_rotation_model_components_,
    .traction_names = mica_rotation_model_tractions_,
    .eval = finite_eval,
    .stress = finite_stress,
};

int mica_cosserat_finite_set(MicaFieldModel *m) {
  MICA_CHECK(m && m->ops && mica_type_has(&m->ops->type, MICA_FIELD_FINITE_ROTATION_FORM), MICA_ERR_ARGUMENT,
             "mica_cosserat_finite_set: set the constants with mica_cosserat_set_eringen or _technical first");
  m->ops = &mica_field_cosserat_finite;
  return MICA_SUCCESS;
}
