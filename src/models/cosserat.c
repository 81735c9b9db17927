/* The small-strain Cosserat (micropolar) field model, Eringen's linear theory (mica/cosserat.h,
 * docs/theory.md §Cosserat):
 *   ε_kl = u_l,k + e_lkm φ_m,       κ_kl = φ_k,l,
 *   σ_kl = λ ε_rr δ_kl + (μ + κ) ε_kl + μ ε_lk,       m_kl = α κ_rr δ_kl + β κ_kl + γ κ_lk,
 *   W = ½ σ_kl ε_kl + ½ m_kl κ_lk,
 * so σ_kl = ∂W/∂ε_kl and m_kl = ∂W/∂κ_lk = ∂W/∂φ_l,k: both stresses contract their first index with the
 * normal (t_l = σ_kl n_k, m_l = m_kl n_k) and the balance laws are Eringen's σ_kl,k + f_l = 0,
 * m_kl,k + e_lmn σ_mn + c_l = 0. Then
 *   s = ∂W/∂q:   ∂W/∂u_l,k = σ_kl,   ∂W/∂φ_m = e_lkm σ_kl,   ∂W/∂φ_l,k = m_kl,   ∂W/∂u_l = 0.
 *
 * 2-D plane strain is the 3-D law on the embedded kinematics (u_3 = 0, φ_1 = φ_2 = 0, ∂/∂x_3 = 0), the way
 * models_private.h embeds F: then ε_12 = u_2,1 − φ_3, ε_21 = u_1,2 + φ_3, ε_i3 = ε_3i = 0, and the only
 * curvatures are κ_31 = φ_3,1, κ_32 = φ_3,2. The α term needs κ_rr = φ_3,3 = 0 and the β term pairs κ_31
 * with κ_13 = φ_1,3 = 0, so only γ does work: W_couple = ½ γ |∇φ_3|², m_k3 = γ φ_3,k. α and β are set to 0
 * in 2-D so that the reported couple stress has no m_3k (which would do no work anyway).
 *
 * W is quadratic in q, so s is linear in q and D = ∂s/∂q is constant; D is built column by column as
 * s(e_j) with the same code as s (exact: s has no constant term).
 */
#include <math.h>
#include <stddef.h>

#include "mica/cosserat.h"
#include "models_private.h"

#define NC3 6                     /* 3-D components: u_1, u_2, u_3, φ_1, φ_2, φ_3 */
#define NQ3 (NC3 * (1 + 3))       /* 3-D q: 6 values and 6 × 3 gradients */
#define PHI 3                     /* φ_m is 3-D component PHI + m */

typedef struct {
  double lambda, mu, kappa, alpha, beta, gamma;
} Constants;

/* ---- slots of q ---- */

int mica_rotation_model_ncomp_(int dim) { return dim == 2 ? 3 : dim == 3 ? NC3 : 0; }
static int ncomp_of(int dim) { return mica_rotation_model_ncomp_(dim); }
static int nq_of(int dim) { return ncomp_of(dim) * (1 + dim); }

/* ∂_J v_c in the 3-D q. */
static int grad3(int c, int J) { return NC3 + 3 * c + J; }

/* e_ijk for i, j, k ∈ {0, 1, 2}. */
static int levi(int i, int j, int k) { return (i - j) * (j - k) * (k - i) / 2; }

/* The 2-D components ux, uy, phiz are the 3-D components 0, 1, 5. */
static const int comp2_to_3[3] = {0, 1, PHI + 2};

/* Slot of the 3-D q that holds entry j of the 2-D q (values, then ∂_x, ∂_y of each component). */
static int slot2_to_3(int j) {
  if (j < 3) return comp2_to_3[j];
  int c = (j - 3) / 2, J = (j - 3) % 2;
  return grad3(comp2_to_3[c], J);
}

/* q3 = the 2-D q with u_3 = φ_1 = φ_2 = 0 and no z-derivatives (plane strain); a copy in 3-D. */
static void embed_q(int dim, const double *q, double q3[NQ3]) {
  for (int j = 0; j < NQ3; j++) q3[j] = dim == 3 ? q[j] : 0.0;
  if (dim == 2)
    for (int j = 0; j < nq_of(2); j++) q3[slot2_to_3(j)] = q[j];
}

/* s = the 2-D entries of s3. The embedding is linear, q3 = P q, so ∂W/∂q = Pᵀ ∂W/∂q3 is this restriction. */
static void restrict_s(int dim, const double s3[NQ3], double *s) {
  for (int j = 0; j < nq_of(dim); j++) s[j] = dim == 3 ? s3[j] : s3[slot2_to_3(j)];
}

/* ---- the law ---- */

/* The constants the kernel uses; in 2-D α = β = 0 whatever param holds (one couple modulus). */
static Constants constants_of(const MicaFieldModel *m, int dim) {
  const double *p = m->param;
  Constants c = {p[MICA_COSSERAT_LAMBDA], p[MICA_COSSERAT_MU],   p[MICA_COSSERAT_KAPPA],
                 p[MICA_COSSERAT_ALPHA],  p[MICA_COSSERAT_BETA], p[MICA_COSSERAT_GAMMA]};
  if (dim == 2) c.alpha = c.beta = 0.0;
  return c;
}

/* ε_kl = u_l,k + e_lkm φ_m and κ_kl = φ_k,l, 3×3 row-major, from the 3-D q. */
static void kinematics(const double q3[NQ3], double eps[9], double curv[9]) {
  for (int k = 0; k < 3; k++)
    for (int l = 0; l < 3; l++) {
      double e = q3[grad3(l, k)];
      for (int m = 0; m < 3; m++) e += levi(l, k, m) * q3[PHI + m];
      eps[3 * k + l] = e;
      curv[3 * k + l] = q3[grad3(PHI + k, l)];
    }
}

/* σ_kl = λ ε_rr δ_kl + (μ + κ) ε_kl + μ ε_lk and m_kl = α κ_rr δ_kl + β κ_kl + γ κ_lk. */
static void stresses(const Constants *c, const double eps[9], const double curv[9], double sigma[9],
                     double couple[9]) {
  double tr_eps = t3_trace(eps), tr_curv = t3_trace(curv);
  for (int k = 0; k < 3; k++)
    for (int l = 0; l < 3; l++) {
      int kl = 3 * k + l, lk = 3 * l + k;
      sigma[kl] = c->lambda * tr_eps * T3_IDENTITY[kl] + (c->mu + c->kappa) * eps[kl] + c->mu * eps[lk];
      couple[kl] = c->alpha * tr_curv * T3_IDENTITY[kl] + c->beta * curv[kl] + c->gamma * curv[lk];
    }
}

/* W = ½ σ_kl ε_kl + ½ m_kl κ_lk (m pairs with the transpose of κ: m_kl works on φ_l,k). */
static double energy(const double eps[9], const double curv[9], const double sigma[9], const double couple[9]) {
  double w = t3_contract(sigma, eps);
  for (int k = 0; k < 3; k++)
    for (int l = 0; l < 3; l++) w += couple[3 * k + l] * curv[3 * l + k];
  return 0.5 * w;
}

/* s3 = ∂W/∂q3 from σ = ∂W/∂ε and m: the transpose of the kinematic map. */
static void pull_back(const double sigma[9], const double couple[9], double s3[NQ3]) {
  for (int j = 0; j < NQ3; j++) s3[j] = 0.0;
  for (int k = 0; k < 3; k++)
    for (int l = 0; l < 3; l++) {
      double skl = sigma[3 * k + l];
      s3[grad3(l, k)] += skl;                                           /* ∂ε_kl/∂u_l,k = 1 */
      for (int m = 0; m < 3; m++) s3[PHI + m] += levi(l, k, m) * skl;   /* ∂ε_kl/∂φ_m = e_lkm */
      s3[grad3(PHI + l, k)] += couple[3 * k + l];                       /* ∂W/∂φ_l,k = m_kl */
    }
}

/* W and s at q (either may be NULL). */
static void energy_and_gradient(const Constants *c, int dim, const double *q, double *W, double *s) {
  double q3[NQ3], s3[NQ3], eps[9], curv[9], sigma[9], couple[9];
  embed_q(dim, q, q3);
  kinematics(q3, eps, curv);
  stresses(c, eps, curv, sigma, couple);
  if (W) *W = energy(eps, curv, sigma, couple);
  if (s) {
    pull_back(sigma, couple, s3);
    restrict_s(dim, s3, s);
  }
}

/* D = ∂s/∂q, column j = s(e_j): exact because s is linear in q, and built by the code that builds s. */
static void tangent(const Constants *c, int dim, double *D) {
  int nq = nq_of(dim);
  double e[NQ3], col[NQ3];
  for (int j = 0; j < nq; j++) {
    for (int i = 0; i < nq; i++) e[i] = i == j ? 1.0 : 0.0;
    energy_and_gradient(c, dim, e, NULL, col);
    for (int i = 0; i < nq; i++) D[i * nq + j] = col[i];
  }
}

/* ---- the ops table ---- */

static int check_args(const MicaFieldModel *m, int dim, const double *q) {
  MICA_CHECK(m && q, MICA_ERR_ARGUMENT, "Cosserat model: NULL model or q");
  MICA_CHECK(dim == 2 || dim == 3, MICA_ERR_ARGUMENT, "Cosserat model: dimension %d (must be 2 or 3)", dim);
  return MICA_SUCCESS;
}

static int cosserat_eval(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D) {
  MICA_CALL(check_args(m, dim, q));
  Constants c = constants_of(m, dim);
  energy_and_gradient(&c, dim, q, W, s);
  if (D) tangent(&c, dim, D);
  return MICA_SUCCESS;
}

/* σ and m as 3×3 (either may be NULL). Plane strain: σ_33 = λ ε_rr from ε_33 = 0; m_13 = γ φ_3,1,
 * m_23 = γ φ_3,2 and every other m_kl = 0. */
static int cosserat_stress(const MicaFieldModel *m, int dim, const double *q, double *sigma, double *couple) {
  MICA_CALL(check_args(m, dim, q));
  Constants c = constants_of(m, dim);
  double q3[NQ3], eps[9], curv[9], sig[9], cpl[9];
  embed_q(dim, q, q3);
  kinematics(q3, eps, curv);
  stresses(&c, eps, curv, sig, cpl);
  for (int a = 0; a < 9; a++) {
    if (sigma) sigma[a] = sig[a];
    if (couple) couple[a] = cpl[a];
  }
  return MICA_SUCCESS;
}

/* NULL-terminated after the ncomp names; NULL for a dimension other than 2 or 3. */
static const char *const names2[] = {"ux", "uy", "phiz", NULL};
static const char *const names3[] = {"ux", "uy", "uz", "phix", "phiy", "phiz", NULL};
static const char *const tractions2[] = {"tx", "ty", "mz", NULL};
static const char *const tractions3[] = {"tx", "ty", "tz", "mx", "my", "mz", NULL};

const char *const *mica_rotation_model_components_(int dim) { return dim == 2 ? names2 : dim == 3 ? names3 : NULL; }
const char *const *mica_rotation_model_tractions_(int dim) {
  return dim == 2 ? tractions2 : dim == 3 ? tractions3 : NULL;
}

const MicaFieldModelOps mica_field_cosserat = {
    .type = {.name = "cosserat",
             .description = "small-strain micropolar continuum (u, φ)",
             .flags = MICA_FIELD_USES_VALUES | MICA_FIELD_COUPLE_STRESS | MICA_FIELD_FINITE_ROTATION_FORM, /* φ enters ε */
             .from_settings = mica_cosserat_from_settings_},
    .order = 1,
    .ncomp = ncomp_of,
    .component_names = mica_rotation_model_components_,
    .traction_names = mica_rotation_model_tractions_,
    .eval = cosserat_eval,
    .stress = cosserat_stress,
};

/* ---- constants ---- */

static int check_setter_args(const MicaFieldModel *m, int dim) {
  MICA_CHECK(m, MICA_ERR_ARGUMENT, "Cosserat constants: NULL model");
  MICA_CHECK(dim == 2 || dim == 3, MICA_ERR_ARGUMENT, "Cosserat constants: dimension %d (must be 2 or 3)", dim);
  return MICA_SUCCESS;
}

/* Eringen's conditions on the force part: W_force = ½ (3λ + 2μ + κ)/3 (tr ε)² + ½ (2μ + κ) |dev sym ε|²
 * + ½ κ |skew ε|², so each coefficient must be ≥ 0; 2μ + κ = 2G and 3λ + 2μ + κ = 3K are required > 0 so that
 * the classical part (E, ν) exists. */
static int check_force_constants(double lambda, double mu, double kappa) {
  MICA_CHECK(isfinite(lambda) && isfinite(mu) && isfinite(kappa), MICA_ERR_INPUT,
             "Cosserat constants λ = %g, μ = %g, κ = %g must be finite", lambda, mu, kappa);
  MICA_CHECK(kappa >= 0.0, MICA_ERR_INPUT,
             "Cosserat coupling modulus κ = %g must not be negative (the energy ½ κ |skew ε|² would be negative)",
             kappa);
  MICA_CHECK(2.0 * mu + kappa > 0.0, MICA_ERR_INPUT,
             "Cosserat constants: 2μ + κ = %g (twice the shear modulus G) must be positive (μ = %g, κ = %g)",
             2.0 * mu + kappa, mu, kappa);
  MICA_CHECK(3.0 * lambda + 2.0 * mu + kappa > 0.0, MICA_ERR_INPUT,
             "Cosserat constants: 3λ + 2μ + κ = %g (three times the bulk modulus) must be positive (λ = %g)",
             3.0 * lambda + 2.0 * mu + kappa, lambda);
  return MICA_SUCCESS;
}

/* Eringen's conditions on the couple part: W_couple = ½ (3α + β + γ)/3 (tr κ)² + ½ (β + γ) |dev sym κ|²
 * + ½ (γ − β) |skew κ|². Semi-definite is admissible, with a round-off allowance so that Ψ = 1.5 (where
 * 3α + β + γ = 0 exactly) passes. 2-D: W_couple = ½ γ |∇φ_3|² needs γ > 0 to fix φ_3. */
static int check_couple_constants(int dim, double alpha, double beta, double gamma) {
  if (dim == 2) {
    MICA_CHECK(gamma > 0.0 && isfinite(gamma), MICA_ERR_INPUT,
               "2-D Cosserat couple modulus γ = %g must be positive and finite (W = ½ γ |∇φ_z|²)", gamma);
    return MICA_SUCCESS;
  }
  MICA_CHECK(isfinite(alpha) && isfinite(beta) && isfinite(gamma), MICA_ERR_INPUT,
             "Cosserat constants α = %g, β = %g, γ = %g must be finite", alpha, beta, gamma);
  double tol = 1e-12 * (fabs(alpha) + fabs(beta) + fabs(gamma));
  MICA_CHECK(3.0 * alpha + beta + gamma >= -tol, MICA_ERR_INPUT,
             "Cosserat constants: 3α + β + γ = %g must not be negative (energy of tr κ; α = %g)",
             3.0 * alpha + beta + gamma, alpha);
  MICA_CHECK(gamma + beta >= -tol, MICA_ERR_INPUT,
             "Cosserat constants: γ + β = %g must not be negative (energy of sym κ; β = %g, γ = %g)", gamma + beta,
             beta, gamma);
  MICA_CHECK(gamma - beta >= -tol, MICA_ERR_INPUT,
             "Cosserat constants: γ − β = %g must not be negative (energy of skew κ; β = %g, γ = %g)", gamma - beta,
             beta, gamma);
  return MICA_SUCCESS;
}

/* The classical part: G = μ + κ/2, ν = λ / (2(λ + G)), E = 2G(1 + ν), bulk modulus λ + 2G/3. */
static MicaMaterial classical_part(int dim, const Constants *c) {
  MicaMaterial mat;
  double G = c->mu + 0.5 * c->kappa;
  mat.lambda = c->lambda;
  mat.mu = G;
  mat.nu = c->lambda / (2.0 * (c->lambda + G)); /* λ + G > G/3 > 0 by the checks */
  mat.E = 2.0 * G * (1.0 + mat.nu);
  mat.kappa = c->lambda + 2.0 * G / 3.0;
  mat.plane = dim == 2 ? MICA_PLANE_STRAIN : MICA_PLANE_NONE;
  return mat;
}

/* Checks c and writes the model (only on success). */
static int store(MicaFieldModel *m, int dim, Constants c) {
  MICA_CALL(check_force_constants(c.lambda, c.mu, c.kappa));
  MICA_CALL(check_couple_constants(dim, c.alpha, c.beta, c.gamma));
  if (dim == 2) c.alpha = c.beta = 0.0;
  m->ops = &mica_field_cosserat;
  m->material = classical_part(dim, &c);
  m->classical = NULL;
  for (int i = 0; i < MICA_FIELD_MODEL_NPARAM; i++) m->param[i] = 0.0;
  m->param[MICA_COSSERAT_LAMBDA] = c.lambda;
  m->param[MICA_COSSERAT_MU] = c.mu;
  m->param[MICA_COSSERAT_KAPPA] = c.kappa;
  m->param[MICA_COSSERAT_ALPHA] = c.alpha;
  m->param[MICA_COSSERAT_BETA] = c.beta;
  m->param[MICA_COSSERAT_GAMMA] = c.gamma;
  return MICA_SUCCESS;
}

int mica_cosserat_set_eringen(MicaFieldModel *m, int dim, double lambda, double mu, double kappa, double alpha,
                              double beta, double gamma) {
  MICA_CALL(check_setter_args(m, dim));
  Constants c = {lambda, mu, kappa, alpha, beta, gamma};
  MICA_CALL(store(m, dim, c));
  return MICA_SUCCESS;
}

/* G, ν, N: the comparisons are written so that NaN fails them. */
static int check_technical_moduli(double G, double nu, double N) {
  MICA_CHECK(G > 0.0 && isfinite(G), MICA_ERR_INPUT, "Cosserat shear modulus G = %g must be positive and finite", G);
  MICA_CHECK(nu > -1.0 && nu < 0.5, MICA_ERR_INPUT,
             "Cosserat Poisson's ratio ν = %g must be in (−1, 0.5) (λ = 2Gν/(1 − 2ν) is infinite at 0.5)", nu);
  MICA_CHECK(N >= 0.0 && N < 1.0, MICA_ERR_INPUT,
             "the coupling number N = %g must be in [0, 1) (κ = 2GN²/(1 − N²); N = 0 is classical, N → 1 the "
             "couple-stress limit κ → ∞)",
             N);
  return MICA_SUCCESS;
}

static int check_length(const char *name, double l) {
  MICA_CHECK(l > 0.0 && isfinite(l), MICA_ERR_INPUT,
             "the Cosserat %s = %g must be positive and finite (l → 0 is the classical limit: use the classical "
             "model)",
             name, l);
  return MICA_SUCCESS;
}

/* 2-D: one length. 3-D: l_t, l_b, Ψ, and γ − β = 2G(4 l_b² − l_t²) ≥ 0, i.e. l_t ≤ 2 l_b. */
static int check_technical_lengths(int dim, double l_t, double l_b, double psi) {
  if (dim == 2) {
    MICA_CALL(check_length("characteristic length l", l_b));
    MICA_CHECK(l_t == l_b, MICA_ERR_INPUT,
               "the 2-D Cosserat model has one characteristic length l (got l_t = %g, l_b = %g)", l_t, l_b);
    return MICA_SUCCESS;
  }
  MICA_CALL(check_length("torsion length l_t", l_t));
  MICA_CALL(check_length("bending length l_b", l_b));
  MICA_CHECK(psi > 0.0 && psi <= 1.5, MICA_ERR_INPUT,
             "the Cosserat polar ratio Ψ = %g must be in (0, 1.5] (α = (β + γ)(1 − Ψ)/Ψ; Ψ > 1.5 makes "
             "3α + β + γ negative)",
             psi);
  MICA_CHECK(l_t <= 2.0 * l_b, MICA_ERR_INPUT,
             "the Cosserat torsion length l_t = %g exceeds twice the bending length l_b = %g: then "
             "γ − β = 2G(4 l_b² − l_t²) < 0 and the energy of skew κ is negative",
             l_t, l_b);
  return MICA_SUCCESS;
}

/* Lakes' technical constants → Eringen's (docs/theory.md §Cosserat, "Constants"). */
static Constants from_technical(int dim, double G, double nu, double N, double l_t, double l_b, double psi) {
  Constants c;
  c.kappa = 2.0 * G * N * N / (1.0 - N * N);
  c.mu = G - 0.5 * c.kappa;
  c.lambda = 2.0 * G * nu / (1.0 - 2.0 * nu);
  c.gamma = 4.0 * G * l_b * l_b;
  if (dim == 2) {
    c.alpha = c.beta = 0.0;
  } else {
    c.beta = 2.0 * G * l_t * l_t - c.gamma;
    c.alpha = (c.beta + c.gamma) * (1.0 - psi) / psi;
  }
  return c;
}

int mica_cosserat_set_technical(MicaFieldModel *m, int dim, double G, double nu, double N, double l_t, double l_b,
                                double psi) {
  MICA_CALL(check_setter_args(m, dim));
  MICA_CALL(check_technical_moduli(G, nu, N));
  MICA_CALL(check_technical_lengths(dim, l_t, l_b, psi));
  MICA_CALL(store(m, dim, from_technical(dim, G, nu, N, l_t, l_b, psi)));
  return MICA_SUCCESS;
}
