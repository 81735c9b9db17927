/* Unit tests of the small-strain Cosserat field model (src/models/cosserat.c, mica/cosserat.h) and of
 * mica_field_model_nq (src/models/field.c).
 *
 * What is checked, and against what:
 * - s = ∂W/∂q against central differences of W, D = ∂s/∂q against central differences of s, at random q
 *   (entries in [−1, 1]) for seven constant sets in 2-D and 3-D; D symmetric; W = ½ qᵀDq and s = Dq.
 * - W against the energy written out here independently (explicit components of ε, and the split
 *   W = ½λ(tr ε)² + ½(2μ+κ)|sym ε|² + ½κ|skew ε|² + ½α(tr κ)² + ½(β+γ)|sym κ|² + ½(γ−β)|skew κ|²).
 * - Sign convention: a rigid motion u = c + ω × x, φ = ω (2-D: u = (c1 − ωy, c2 + ωx), φ_z = ω) has W = 0
 *   and s = 0; φ = −ω does not.
 * - W ≥ 0 at random q for admissible constants; each of Eringen's conditions is sharp: just past it, the
 *   mode it controls has W < 0 (and the setter refuses the constants).
 * - Limits: κ = 0 (N = 0) gives the classical σ of mica_model_linear for any φ; κ > 0 with φ = ½ curl u
 *   (the state that γ → 0 forces) gives it too, and in general σ − σ_classical = κ skew ε.
 * - stress() is consistent with s (σ_kl = ∂W/∂u_l,k, m_kl = ∂W/∂φ_l,k) and plane strain σ_33 = λ tr ε.
 * - The glide layer's exact solution (docs/theory.md), for equal and unequal curvature moduli, satisfies
 *   Eringen's balance laws with this kernel's stresses, and its values at y = 1.
 * - Conversions: the plate-with-a-hole example, Lakes' bone constants (ν is not given there: 0.3 used),
 *   technical → Eringen → technical by Lakes' definitions, the classical part (E, ν, G, bulk modulus).
 * - Input errors name the parameter and leave the model untouched.
 *
 * Tolerances. W is quadratic, so central differences have no truncation error: with h = 1e-6 on entries of
 * order 1 only rounding remains, ≈ 1e-16 max|W| / h ≈ 1e-10 relative; accepted at FD_TOL = 1e-7 relative
 * to max|s| (max|D|). Identities exact in exact arithmetic (symmetry, W = ½ qᵀDq, rigid motion, the limits,
 * conversions) are checked to EXACT_TOL = 1e-12 relative. The worst errors are printed.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "mica/cosserat.h"
#include "mica/model.h"
#include "mica/random.h"

#define FD_STEP 1e-6
#define FD_TOL 1e-7
#define EXACT_TOL 1e-12
#define NUM_RANDOM 20
#define NQ_MAX 24

/* ---- constant sets ---- */

typedef struct {
  const char *name;
  int dim;
  int technical; /* p = G, ν, N, l_t, l_b, Ψ; else p = λ, μ, κ, α, β, γ */
  double p[6];
} ConstCase;

static const ConstCase cases[] = {
    {"plate with a hole example, 2-D", 2, 1, {1000.0, 0.3, 0.93, 1.0 / 1.063, 1.0 / 1.063, 1.0}},
    {"plate example constants, 3-D, Ψ = 0.7", 3, 1, {1000.0, 0.3, 0.93, 1.0 / 1.063, 1.0 / 1.063, 0.7}},
    {"bone (Lakes, ν = 0.3), 3-D", 3, 1, {3.5e3, 0.3, 0.62, 0.22, 0.44, 1.5}},
    {"glide layer, 2-D", 2, 0, {1.0, -1.0, 6.0, 0.0, 0.0, 1.2}},
    {"glide layer force constants, 3-D", 3, 0, {1.0, -1.0, 6.0, 1.1, 0.6, 1.2}},
    {"generic, 3-D", 3, 0, {2.0, 3.0, 0.5, 0.3, 0.2, 0.7}},
    {"auxetic, 3-D", 3, 1, {5.0, -0.5, 0.3, 0.1, 0.15, 0.4}},
};
#define NUM_CASES (sizeof cases / sizeof cases[0])

static void fail_with_error(const char *what) {
  print_error("%s failed: %s\n", what, mica_error_message());
  fail();
}

static MicaFieldModel make_model(const ConstCase *c) {
  MicaFieldModel m;
  memset(&m, 0, sizeof m);
  const double *p = c->p;
  int ierr = c->technical ? mica_cosserat_set_technical(&m, c->dim, p[0], p[1], p[2], p[3], p[4], p[5])
                          : mica_cosserat_set_eringen(&m, c->dim, p[0], p[1], p[2], p[3], p[4], p[5]);
  if (ierr) fail_with_error(c->name);
  return m;
}

static int nq_of(const MicaFieldModel *m, int dim) {
  int nq = mica_field_model_nq(m, dim);
  assert_true(nq > 0 && nq <= NQ_MAX);
  return nq;
}

static void random_q(MicaRandom *r, int nq, double *q) {
  for (int j = 0; j < nq; j++) q[j] = 2.0 * mica_random_uniform(r) - 1.0;
}

static double eval_W(const MicaFieldModel *m, int dim, const double *q) {
  double W;
  if (m->ops->eval(m, dim, q, &W, NULL, NULL)) fail_with_error("eval");
  return W;
}

static void eval_s(const MicaFieldModel *m, int dim, const double *q, double *s) {
  if (m->ops->eval(m, dim, q, NULL, s, NULL)) fail_with_error("eval");
}

static void eval_all(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D) {
  if (m->ops->eval(m, dim, q, W, s, D)) fail_with_error("eval");
}

static double max_abs(const double *a, int n) {
  double v = 0.0;
  for (int i = 0; i < n; i++) v = fmax(v, fabs(a[i]));
  return v;
}

static void assert_relative(double got, double expected, double tol, const char *what) {
  double err = fabs(got - expected) / fmax(fabs(expected), 1e-300);
  if (err > tol) {
    print_error("%s: %.17g, expected %.17g (relative error %.3g)\n", what, got, expected, err);
    fail();
  }
}

/* Slot of ∂_J v_c in q. */
static int grad(int dim, int ncomp, int c, int J) { return ncomp + c * dim + J; }

/* ---- field.c ---- */

static void test_nq(void **state) {
  (void)state;
  MicaFieldModel m = make_model(&cases[0]);
  assert_int_equal(mica_field_model_nq(&m, 2), 9);  /* 3 (1 + 2) */
  assert_int_equal(mica_field_model_nq(&m, 3), 24); /* 6 (1 + 3) */
  assert_int_equal(mica_field_model_nq(&m, 1), 0);
  assert_int_equal(mica_field_model_nq(NULL, 2), 0);
  /* order 2 adds ncomp dim(dim+1)/2 Hessian entries */
  MicaFieldModelOps second = mica_field_cosserat;
  second.order = 2;
  m.ops = &second;
  assert_int_equal(mica_field_model_nq(&m, 2), 9 + 3 * 3);
  assert_int_equal(mica_field_model_nq(&m, 3), 24 + 6 * 6);
}

static void test_ops_table(void **state) {
  (void)state;
  const MicaFieldModelOps *ops = &mica_field_cosserat;
  assert_string_equal(ops->type.name, "cosserat");
  assert_int_equal(ops->order, 1);
  assert_int_equal(mica_type_has(&ops->type, MICA_FIELD_FINITE), 0);
  assert_int_equal(mica_type_has(&ops->type, MICA_FIELD_USES_VALUES), 1);
  assert_int_equal(ops->ncomp(2), 3);
  assert_int_equal(ops->ncomp(3), 6);
  const char *n2[] = {"ux", "uy", "phiz"}, *t2[] = {"tx", "ty", "mz"};
  const char *n3[] = {"ux", "uy", "uz", "phix", "phiy", "phiz"}, *t3[] = {"tx", "ty", "tz", "mx", "my", "mz"};
  for (int c = 0; c < 3; c++) {
    assert_string_equal(ops->component_names(2)[c], n2[c]);
    assert_string_equal(ops->traction_names(2)[c], t2[c]);
  }
  for (int c = 0; c < 6; c++) {
    assert_string_equal(ops->component_names(3)[c], n3[c]);
    assert_string_equal(ops->traction_names(3)[c], t3[c]);
  }
  assert_null(ops->component_names(2)[3]);
  assert_null(ops->traction_names(3)[6]);
}

/* ---- derivatives against finite differences ---- */

/* Worst relative error of s against central differences of W over NUM_RANDOM q's. */
static double s_vs_W(const MicaFieldModel *m, int dim, MicaRandom *r) {
  int nq = nq_of(m, dim);
  double worst = 0.0, q[NQ_MAX], s[NQ_MAX];
  for (int n = 0; n < NUM_RANDOM; n++) {
    random_q(r, nq, q);
    eval_s(m, dim, q, s);
    double err = 0.0, scale = max_abs(s, nq);
    for (int j = 0; j < nq; j++) {
      double qj = q[j];
      q[j] = qj + FD_STEP;
      double Wp = eval_W(m, dim, q);
      q[j] = qj - FD_STEP;
      double Wm = eval_W(m, dim, q);
      q[j] = qj;
      err = fmax(err, fabs(s[j] - (Wp - Wm) / (2.0 * FD_STEP)));
    }
    worst = fmax(worst, err / scale);
  }
  return worst;
}

/* Worst relative error of D against central differences of s. */
static double D_vs_s(const MicaFieldModel *m, int dim, MicaRandom *r) {
  int nq = nq_of(m, dim);
  double worst = 0.0, q[NQ_MAX], D[NQ_MAX * NQ_MAX], sp[NQ_MAX], sm[NQ_MAX];
  for (int n = 0; n < NUM_RANDOM; n++) {
    random_q(r, nq, q);
    eval_all(m, dim, q, NULL, NULL, D);
    double err = 0.0, scale = max_abs(D, nq * nq);
    for (int j = 0; j < nq; j++) {
      double qj = q[j];
      q[j] = qj + FD_STEP;
      eval_s(m, dim, q, sp);
      q[j] = qj - FD_STEP;
      eval_s(m, dim, q, sm);
      q[j] = qj;
      for (int i = 0; i < nq; i++) err = fmax(err, fabs(D[i * nq + j] - (sp[i] - sm[i]) / (2.0 * FD_STEP)));
    }
    worst = fmax(worst, err / scale);
  }
  return worst;
}

static void test_s_is_dW_dq(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(11);
  double worst = 0.0;
  for (size_t k = 0; k < NUM_CASES; k++) {
    MicaFieldModel m = make_model(&cases[k]);
    double err = s_vs_W(&m, cases[k].dim, &r);
    if (err > FD_TOL) print_error("%s: s vs differences of W: %.3g\n", cases[k].name, err);
    assert_true(err <= FD_TOL);
    worst = fmax(worst, err);
  }
  print_message("worst s vs central differences of W: %.3g (relative to max|s|)\n", worst);
}

static void test_D_is_ds_dq(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(12);
  double worst = 0.0;
  for (size_t k = 0; k < NUM_CASES; k++) {
    MicaFieldModel m = make_model(&cases[k]);
    double err = D_vs_s(&m, cases[k].dim, &r);
    if (err > FD_TOL) print_error("%s: D vs differences of s: %.3g\n", cases[k].name, err);
    assert_true(err <= FD_TOL);
    worst = fmax(worst, err);
  }
  print_message("worst D vs central differences of s: %.3g (relative to max|D|)\n", worst);
}

/* D = Dᵀ, W = ½ qᵀDq and s = Dq (W is a quadratic form without linear or constant part). */
static void test_D_symmetric_and_quadratic(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(13);
  double worst_sym = 0.0, worst_quad = 0.0;
  for (size_t k = 0; k < NUM_CASES; k++) {
    MicaFieldModel m = make_model(&cases[k]);
    int dim = cases[k].dim, nq = nq_of(&m, dim);
    double q[NQ_MAX], s[NQ_MAX], D[NQ_MAX * NQ_MAX], W;
    for (int n = 0; n < NUM_RANDOM; n++) {
      random_q(&r, nq, q);
      eval_all(&m, dim, q, &W, s, D);
      double scale = max_abs(D, nq * nq), qDq = 0.0, err_s = 0.0, err_sym = 0.0, sum_abs = 0.0;
      for (int i = 0; i < nq; i++) {
        double Dq = 0.0;
        for (int j = 0; j < nq; j++) {
          Dq += D[i * nq + j] * q[j];
          sum_abs += fabs(D[i * nq + j] * q[i] * q[j]);
          err_sym = fmax(err_sym, fabs(D[i * nq + j] - D[j * nq + i]));
        }
        qDq += q[i] * Dq;
        err_s = fmax(err_s, fabs(s[i] - Dq));
      }
      double err_quad = fmax(fabs(W - 0.5 * qDq) / sum_abs, err_s / scale);
      assert_true(err_sym <= EXACT_TOL * scale);
      assert_true(err_quad <= EXACT_TOL);
      worst_sym = fmax(worst_sym, err_sym / scale);
      worst_quad = fmax(worst_quad, err_quad);
    }
  }
  print_message("worst |D − Dᵀ| / max|D|: %.3g; worst W vs ½ qᵀDq and s vs Dq: %.3g\n", worst_sym, worst_quad);
}

/* ---- the energy written out independently ---- */

/* ε and κ from the 3-D q with every component of ε_kl = u_l,k + e_lkm φ_m written out (1-based in the
 * comments): ε_12 = u_2,1 − φ_3, ε_21 = u_1,2 + φ_3, ε_13 = u_3,1 + φ_2, ε_31 = u_1,3 − φ_2,
 * ε_23 = u_3,2 − φ_1, ε_32 = u_2,3 + φ_1. */
static void explicit_strains3(const double *q, double eps[3][3], double curv[3][3]) {
  const double *phi = q + 3;
#define DU(l, k) q[grad(3, 6, (l), (k))] /* u_l,k */
  for (int k = 0; k < 3; k++)
    for (int l = 0; l < 3; l++) {
      eps[k][l] = DU(l, k);
      curv[k][l] = q[grad(3, 6, 3 + k, l)]; /* φ_k,l */
    }
#undef DU
  eps[0][1] -= phi[2];
  eps[1][0] += phi[2];
  eps[0][2] += phi[1];
  eps[2][0] -= phi[1];
  eps[1][2] -= phi[0];
  eps[2][1] += phi[0];
}

/* ½ a (tr t)² + ½ b |sym t|² + ½ c |skew t|². */
static double split_energy(const double t[3][3], double a, double b, double c) {
  double tr = t[0][0] + t[1][1] + t[2][2], sym2 = 0.0, skew2 = 0.0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double sy = 0.5 * (t[i][j] + t[j][i]), sk = 0.5 * (t[i][j] - t[j][i]);
      sym2 += sy * sy;
      skew2 += sk * sk;
    }
  return 0.5 * (a * tr * tr + b * sym2 + c * skew2);
}

/* (μ+κ) ε:ε + μ ε:εᵀ = (2μ+κ)|sym ε|² + κ|skew ε|²; α(tr κ)² + β κ:κᵀ + γ κ:κ = α(tr κ)² + (β+γ)|sym κ|²
 * + (γ−β)|skew κ|². */
static double reference_W3(const double *p, const double *q) {
  double eps[3][3], curv[3][3];
  explicit_strains3(q, eps, curv);
  double lambda = p[0], mu = p[1], kappa = p[2], alpha = p[3], beta = p[4], gamma = p[5];
  return split_energy(eps, lambda, 2.0 * mu + kappa, kappa) + split_energy(curv, alpha, beta + gamma, gamma - beta);
}

/* 2-D q = (u_x, u_y, φ, u_x,x, u_x,y, u_y,x, u_y,y, φ,x, φ,y): ε_11 = u_1,1, ε_22 = u_2,2, ε_12 = u_2,1 − φ,
 * ε_21 = u_1,2 + φ; W = ½λ(tr ε)² + ½(μ+κ) Σ ε_kl² + ½μ (ε_11² + ε_22² + 2 ε_12 ε_21) + ½γ |∇φ|². */
static double reference_W2(const double *p, const double *q) {
  double e11 = q[3], e22 = q[6], e12 = q[5] - q[2], e21 = q[4] + q[2];
  double lambda = p[0], mu = p[1], kappa = p[2], gamma = p[5], tr = e11 + e22;
  return 0.5 * lambda * tr * tr + 0.5 * (mu + kappa) * (e11 * e11 + e22 * e22 + e12 * e12 + e21 * e21) +
         0.5 * mu * (e11 * e11 + e22 * e22 + 2.0 * e12 * e21) + 0.5 * gamma * (q[7] * q[7] + q[8] * q[8]);
}

static void test_energy_reference(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(14);
  double worst = 0.0;
  for (size_t k = 0; k < NUM_CASES; k++) {
    MicaFieldModel m = make_model(&cases[k]);
    int dim = cases[k].dim, nq = nq_of(&m, dim);
    double q[NQ_MAX];
    for (int n = 0; n < NUM_RANDOM; n++) {
      random_q(&r, nq, q);
      double W = eval_W(&m, dim, q);
      double ref = dim == 2 ? reference_W2(m.param, q) : reference_W3(m.param, q);
      /* relative to max|constant| nq ≥ the size of the terms of W at |q_j| ≤ 1, so cancellation between
       * terms of opposite sign (μ < 0, β < 0) does not inflate the measure */
      double err = fabs(W - ref) / (max_abs(m.param, 6) * nq);
      assert_true(err <= EXACT_TOL);
      worst = fmax(worst, err);
    }
  }
  print_message("worst W vs the independent formula: %.3g (relative to max|constant| nq)\n", worst);
}

/* ---- rigid motions: the sign convention ---- */

/* q of u = c + ω × x, φ = s ω at the point x (3-D). s = 1 is the rigid motion. */
static void rigid_q3(const double c[3], const double w[3], const double x[3], double s, double *q) {
  memset(q, 0, 24 * sizeof *q);
  q[0] = c[0] + w[1] * x[2] - w[2] * x[1];
  q[1] = c[1] + w[2] * x[0] - w[0] * x[2];
  q[2] = c[2] + w[0] * x[1] - w[1] * x[0];
  for (int i = 0; i < 3; i++) q[3 + i] = s * w[i];
  /* ∇(ω × x): u_1,2 = −ω_3, u_1,3 = ω_2, u_2,1 = ω_3, u_2,3 = −ω_1, u_3,1 = −ω_2, u_3,2 = ω_1 */
  q[grad(3, 6, 0, 1)] = -w[2];
  q[grad(3, 6, 0, 2)] = w[1];
  q[grad(3, 6, 1, 0)] = w[2];
  q[grad(3, 6, 1, 2)] = -w[0];
  q[grad(3, 6, 2, 0)] = -w[1];
  q[grad(3, 6, 2, 1)] = w[0];
}

/* u = (c1 − ωy, c2 + ωx), φ_z = s ω at (x, y). */
static void rigid_q2(const double c[2], double w, const double x[2], double s, double *q) {
  memset(q, 0, 9 * sizeof *q);
  q[0] = c[0] - w * x[1];
  q[1] = c[1] + w * x[0];
  q[2] = s * w;
  q[grad(2, 3, 0, 1)] = -w; /* u_x,y */
  q[grad(2, 3, 1, 0)] = w;  /* u_y,x */
}

static void test_rigid_motion(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(15);
  double worst = 0.0;
  for (size_t k = 0; k < NUM_CASES; k++) {
    MicaFieldModel m = make_model(&cases[k]);
    int dim = cases[k].dim, nq = nq_of(&m, dim);
    double scale = max_abs(m.param, 6);
    for (int n = 0; n < NUM_RANDOM; n++) {
      double c[3], w[3], x[3], q[NQ_MAX], s[NQ_MAX], W;
      random_q(&r, 3, c);
      random_q(&r, 3, w);
      random_q(&r, 3, x);
      if (dim == 3) rigid_q3(c, w, x, 1.0, q);
      else rigid_q2(c, w[2], x, 1.0, q);
      eval_all(&m, dim, q, &W, s, NULL);
      double err = fmax(fabs(W), max_abs(s, nq)) / scale;
      assert_true(err <= EXACT_TOL);
      worst = fmax(worst, err);
      /* φ = −ω is not rigid (the check can fail): ε = skew with entries ±2ω, W = ½κ |ε|² = 4κ |ω|² */
      double w2 = dim == 3 ? w[0] * w[0] + w[1] * w[1] + w[2] * w[2] : w[2] * w[2];
      if (dim == 3) rigid_q3(c, w, x, -1.0, q);
      else rigid_q2(c, w[2], x, -1.0, q);
      assert_relative(eval_W(&m, dim, q), 4.0 * m.param[MICA_COSSERAT_KAPPA] * w2, EXACT_TOL, "W at φ = −ω");
    }
  }
  print_message("worst |W|, |s| at rigid motions: %.3g (relative to max|constant|)\n", worst);
}

/* ---- positivity and Eringen's conditions ---- */

static void test_energy_nonnegative(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(16);
  double lowest = INFINITY;
  for (size_t k = 0; k < NUM_CASES; k++) {
    MicaFieldModel m = make_model(&cases[k]);
    int dim = cases[k].dim, nq = nq_of(&m, dim);
    double q[NQ_MAX], scale = max_abs(m.param, 6);
    for (int n = 0; n < 1000; n++) {
      random_q(&r, nq, q);
      double W = eval_W(&m, dim, q) / (scale * nq);
      assert_true(W >= -EXACT_TOL);
      lowest = fmin(lowest, W);
    }
  }
  print_message("lowest W / (max|constant| nq) at 7000 random q: %.3g\n", lowest);
}

/* A 3-D mode controlled by one of Eringen's conditions, and the constants that violate that condition by
 * 0.01 with the others admissible. */
typedef struct {
  const char *condition;
  double p[6];  /* λ, μ, κ, α, β, γ */
  int slot[3];  /* q entries set to value[] (−1: unused) */
  double value[3];
} Mode;

#define U(l, k) (6 + 3 * (l) + (k))       /* u_l,k */
#define PHI(k) (3 + (k))                  /* φ_k */
#define DPHI(k, l) (6 + 3 * (3 + (k)) + (l)) /* φ_k,l */
static const Mode modes[] = {
    {"κ ≥ 0", {1.0, 1.0, -0.01, 1.0, 0.0, 1.0}, {PHI(2), -1, -1}, {1.0, 0, 0}},             /* skew ε */
    {"2μ + κ > 0", {1.0, -0.505, 1.0, 1.0, 0.0, 1.0}, {U(0, 1), U(1, 0), -1}, {1, 1, 0}},  /* dev sym ε */
    {"3λ + 2μ + κ > 0", {-1.01, 1.0, 1.0, 1.0, 0.0, 1.0}, {U(0, 0), U(1, 1), U(2, 2)}, {1, 1, 1}},
    {"3α + β + γ ≥ 0", {1.0, 1.0, 1.0, -0.67, 0.0, 2.0}, {DPHI(0, 0), DPHI(1, 1), DPHI(2, 2)}, {1, 1, 1}},
    {"γ + β ≥ 0", {1.0, 1.0, 1.0, 1.0, -0.505, 0.495}, {DPHI(0, 1), DPHI(1, 0), -1}, {1, 1, 0}},
    {"γ − β ≥ 0", {1.0, 1.0, 1.0, 1.0, 0.505, 0.495}, {DPHI(0, 1), DPHI(1, 0), -1}, {1, -1, 0}},
};
#undef U
#undef PHI
#undef DPHI

/* Each condition is necessary: the setter refuses the constants, and the kernel, given them anyway, has
 * W < 0 in the mode the condition controls. With the condition restored (the same constants but the
 * violating one moved back to its boundary), that mode has W ≥ 0. */
static void test_eringen_conditions_sharp(void **state) {
  (void)state;
  for (size_t k = 0; k < sizeof modes / sizeof modes[0]; k++) {
    const Mode *md = &modes[k];
    MicaFieldModel m;
    memset(&m, 0, sizeof m);
    int ierr = mica_cosserat_set_eringen(&m, 3, md->p[0], md->p[1], md->p[2], md->p[3], md->p[4], md->p[5]);
    assert_int_equal(ierr, MICA_ERR_INPUT);
    print_message("%s: %s\n", md->condition, mica_error_message());
    mica_error_clear();
    assert_null(m.ops); /* untouched */
    m.ops = &mica_field_cosserat;
    for (int i = 0; i < 6; i++) m.param[i] = md->p[i];
    double q[24] = {0};
    for (int i = 0; i < 3; i++)
      if (md->slot[i] >= 0) q[md->slot[i]] = md->value[i];
    double W = eval_W(&m, 3, q);
    assert_true(W < 0.0);
  }
}

/* ---- the classical limits ---- */

/* Classical σ (3×3) of mica_model_linear with the model's E, ν at ∇u read from q (F = I + ∇u). */
static void classical_sigma(const MicaFieldModel *m, int dim, const double *q, double sigma[9]) {
  MicaMaterial mat;
  int ncomp = m->ops->ncomp(dim);
  if (mica_material_set(&mica_model_linear, m->material.E, m->material.nu, dim == 2 ? MICA_PLANE_STRAIN : MICA_PLANE_NONE,
                        &mat))
    fail_with_error("mica_material_set");
  double F[9], strain[9];
  for (int i = 0; i < dim; i++)
    for (int J = 0; J < dim; J++) F[i * dim + J] = (i == J) + q[grad(dim, ncomp, i, J)];
  if (mica_model_stress_strain(&mica_model_linear, &mat, dim, F, sigma, strain)) fail_with_error("stress_strain");
}

static double cosserat_sigma(const MicaFieldModel *m, int dim, const double *q, double sigma[9]) {
  if (m->ops->stress(m, dim, q, sigma, NULL)) fail_with_error("stress");
  return max_abs(sigma, 9);
}

/* φ = ½ curl u: φ_m = ½ e_mij u_j,i, which makes skew ε = 0. */
static void set_phi_half_curl(int dim, double *q) {
  int nc = dim == 2 ? 3 : 6;
#define D(j, i) q[grad(dim, nc, (j), (i))] /* u_j,i */
  if (dim == 2) {
    q[2] = 0.5 * (D(1, 0) - D(0, 1));
  } else {
    q[3] = 0.5 * (D(2, 1) - D(1, 2));
    q[4] = 0.5 * (D(0, 2) - D(2, 0));
    q[5] = 0.5 * (D(1, 0) - D(0, 1));
  }
#undef D
}

static double sigma_difference(const double a[9], const double b[9]) {
  double d = 0.0;
  for (int i = 0; i < 9; i++) d = fmax(d, fabs(a[i] - b[i]));
  return d / fmax(max_abs(b, 9), 1e-300);
}

/* N = 0: σ is classical for any φ (the rotation decouples). */
static void test_limit_no_coupling(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(17);
  double worst = 0.0;
  for (int dim = 2; dim <= 3; dim++) {
    MicaFieldModel m;
    if (mica_cosserat_set_technical(&m, dim, 1000.0, 0.3, 0.0, 0.5, 0.5, 1.0)) fail_with_error("N = 0");
    assert_true(m.param[MICA_COSSERAT_KAPPA] == 0.0);
    int nq = nq_of(&m, dim);
    for (int n = 0; n < NUM_RANDOM; n++) {
      double q[NQ_MAX], sc[9], sl[9];
      random_q(&r, nq, q);
      cosserat_sigma(&m, dim, q, sc);
      classical_sigma(&m, dim, q, sl);
      double err = sigma_difference(sc, sl);
      assert_true(err <= EXACT_TOL);
      worst = fmax(worst, err);
    }
  }
  print_message("N = 0: worst |σ − σ_classical| / max|σ_classical|: %.3g\n", worst);
}

/* κ > 0: σ = σ_classical(λ, G) + κ skew ε, so σ is classical where φ = ½ curl u — the state γ → 0 forces
 * through the moment balance (skew σ = 0). */
static void test_limit_no_length(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(18);
  double worst_curl = 0.0, worst_skew = 0.0;
  for (int dim = 2; dim <= 3; dim++) {
    MicaFieldModel m;
    /* 3-D: l → 0 is α = β = γ = 0, admissible (semi-definite); 2-D needs γ > 0 but σ does not involve it */
    if (mica_cosserat_set_eringen(&m, dim, 1500.0, -5401.9, 12803.8, 0.0, 0.0, dim == 2 ? 1e-9 : 0.0))
      fail_with_error("l → 0");
    int nq = nq_of(&m, dim), nc = m.ops->ncomp(dim);
    for (int n = 0; n < NUM_RANDOM; n++) {
      double q[NQ_MAX], sc[9], sl[9];
      random_q(&r, nq, q);
      /* general φ: skew σ_kl = κ skew ε_kl, with skew ε_kl = ½(u_l,k − u_k,l) + e_lkm φ_m (here in 2-D/3-D
       * for the (0, 1) entry: ½(u_1,0 − u_0,1) − φ_2) */
      cosserat_sigma(&m, dim, q, sc);
      double phi_z = q[dim == 2 ? 2 : 5];
      double skew01 = 0.5 * (q[grad(dim, nc, 1, 0)] - q[grad(dim, nc, 0, 1)]) - phi_z;
      double err_skew = fabs(0.5 * (sc[1] - sc[3]) - m.param[MICA_COSSERAT_KAPPA] * skew01) / max_abs(sc, 9);
      assert_true(err_skew <= EXACT_TOL);
      worst_skew = fmax(worst_skew, err_skew);
      set_phi_half_curl(dim, q);
      cosserat_sigma(&m, dim, q, sc);
      classical_sigma(&m, dim, q, sl);
      double err = sigma_difference(sc, sl);
      assert_true(err <= 1e-10); /* κ/G ≈ 13: a little cancellation in κ skew ε ≈ 0 */
      worst_curl = fmax(worst_curl, err);
    }
  }
  print_message("φ = ½ curl u: worst |σ − σ_classical| / max|σ|: %.3g; skew σ = κ skew ε: %.3g\n", worst_curl,
                worst_skew);
}

/* ---- stress() ---- */

/* σ_kl = ∂W/∂u_l,k and m_kl = ∂W/∂φ_l,k; in 2-D σ_33 = λ tr ε, σ_i3 = 0 and m has only m_13, m_23 = γ ∇φ_z. */
static void test_stress_matches_s(void **state) {
  (void)state;
  MicaRandom r = mica_random_seed(19);
  for (size_t k = 0; k < NUM_CASES; k++) {
    MicaFieldModel m = make_model(&cases[k]);
    int dim = cases[k].dim, nq = nq_of(&m, dim), nc = m.ops->ncomp(dim);
    double q[NQ_MAX], s[NQ_MAX], sigma[9], couple[9];
    random_q(&r, nq, q);
    eval_s(&m, dim, q, s);
    if (m.ops->stress(&m, dim, q, sigma, couple)) fail_with_error("stress");
    double scale = max_abs(s, nq), err = 0.0;
    for (int kk = 0; kk < dim; kk++)
      for (int l = 0; l < dim; l++) err = fmax(err, fabs(sigma[3 * kk + l] - s[grad(dim, nc, l, kk)]));
    if (dim == 3) {
      for (int kk = 0; kk < 3; kk++)
        for (int l = 0; l < 3; l++) err = fmax(err, fabs(couple[3 * kk + l] - s[grad(3, 6, 3 + l, kk)]));
    } else {
      double lambda = m.param[MICA_COSSERAT_LAMBDA], gamma = m.param[MICA_COSSERAT_GAMMA];
      err = fmax(err, fabs(sigma[8] - lambda * (q[3] + q[6])));
      err = fmax(err, fabs(sigma[2]) + fabs(sigma[5]) + fabs(sigma[6]) + fabs(sigma[7]));
      err = fmax(err, fabs(couple[2] - gamma * q[7]) + fabs(couple[5] - gamma * q[8]));
      err = fmax(err, fabs(couple[2] - s[7]) + fabs(couple[5] - s[8]));
      for (int a = 0; a < 9; a++)
        if (a != 2 && a != 5) err = fmax(err, fabs(couple[a]));
    }
    assert_true(err <= EXACT_TOL * scale);
  }
}

/* ---- the glide layer (docs/theory.md §Cosserat, "The glide layer") ---- */

/* Forest's σ = λ tr e I + 2μ sym e + 2μ_c skew e with λ = 1, μ = 2, μ_c = 3 is Eringen's with λ = 1,
 * μ = 2 − 3 = −1, κ = 2μ_c = 6 (the sym part carries 2μ + κ, the skew part κ), and his curvature moduli
 * β, γ of m = 2β sym k + 2γ skew k give the 2-D modulus γ_2D = β + γ (1.2 for β = γ = 0.6). The exact solution
 * holds for any γ_2D > 0 with w² = κ(2μ + κ)/(γ_2D (μ + κ)) = 24/(5 γ_2D) (w = 2 at 1.2). */
static double glide_w(double gamma2d) { return sqrt(24.0 / (5.0 * gamma2d)); }

static void glide_q(double gamma2d, double y, double *q) {
  const double B = 1.0, w = glide_w(gamma2d), muF = 2.0, muc = 3.0;
  memset(q, 0, 9 * sizeof *q);
  q[0] = 2.0 * muc * B / (w * (muF + muc)) * (1.0 - cosh(w * y)); /* u_x */
  q[2] = B * sinh(w * y);                                         /* φ_z */
  q[grad(2, 3, 0, 1)] = -2.0 * muc * B / (muF + muc) * sinh(w * y); /* u_x,y */
  q[grad(2, 3, 2, 1)] = B * w * cosh(w * y);                        /* φ_z,y */
}

static void glide_stresses(const MicaFieldModel *m, double gamma2d, double y, double sigma[9], double couple[9]) {
  double q[9];
  glide_q(gamma2d, y, q);
  if (m->ops->stress(m, 2, q, sigma, couple)) fail_with_error("stress");
}

/* Eringen's balance laws for fields of y only, σ_yl,y = 0 and m_yz,y + e_3mn σ_mn = m_yz,y + σ_xy − σ_yx = 0, by
 * central differences of the kernel's stresses (h = 1e-5: error ≈ h² |m'''| ≈ 1e-9), and σ_yx = 0 (no shear
 * traction on y = const); returns the worst residual / 20 (|σ| ≤ 17.4 at w = 2). */
static double glide_balance(double gamma2d) {
  MicaFieldModel m;
  if (mica_cosserat_set_eringen(&m, 2, 1.0, -1.0, 6.0, 0.0, 0.0, gamma2d)) fail_with_error("glide constants");
  const double h = 1e-5;
  double worst = 0.0;
  for (int i = 0; i <= 10; i++) {
    double y = 0.1 * i, sp[9], cp[9], sm[9], cm[9], s0[9], c0[9];
    glide_stresses(&m, gamma2d, y + h, sp, cp);
    glide_stresses(&m, gamma2d, y - h, sm, cm);
    glide_stresses(&m, gamma2d, y, s0, c0);
    double force_x = (sp[3] - sm[3]) / (2 * h), force_y = (sp[4] - sm[4]) / (2 * h);
    double moment = (cp[5] - cm[5]) / (2 * h) + s0[1] - s0[3];
    worst = fmax(worst, fmax(fmax(fabs(force_x), fabs(force_y)), fabs(moment)) / 20.0);
    assert_true(fabs(s0[3]) <= 1e-11);
  }
  return worst;
}

static void test_glide_layer(void **state) {
  (void)state;
  MicaFieldModel m;
  if (mica_cosserat_set_eringen(&m, 2, 1.0, -1.0, 6.0, 0.0, 0.0, 1.2)) fail_with_error("glide constants");
  double sigma[9], couple[9], q[9];
  assert_float_equal(glide_w(1.2), 2.0, 1e-15);
  glide_q(1.2, 1.0, q);
  assert_float_equal(q[2], 3.626860407847, 1e-11);
  assert_float_equal(q[0], -1.65731741465, 1e-10);
  glide_stresses(&m, 1.2, 1.0, sigma, couple);
  /* on y = 1 (n = e_y): t_x = σ_yx = 0 and the couple traction m_z = m_yz = (β + γ) B w cosh w; the shear stress
   * Forest quotes, −4μμ_c/(μ + μ_c) B sinh w, is σ_xy here (the face normal to x) */
  print_message("glide layer at y = 1: σ_yx = %.6g, σ_xy = %.10g, m_yz = %.10g\n", sigma[3], sigma[1], couple[5]);
  assert_true(fabs(sigma[3]) <= 1e-12);
  assert_float_equal(sigma[1], -4.0 * 2.0 * 3.0 / 5.0 * sinh(2.0), 1e-12);
  assert_float_equal(sigma[1], -17.40893, 1e-5);
  assert_float_equal(couple[5], 9.02927, 1e-5);
  /* the balance laws for β = γ = 0.6 (γ_2D = 1.2) and for β = 0.3, γ = 1.3 (γ_2D = 1.6, w = √3): the solution is
   * exact for unequal moduli too, with w from their sum */
  const double worst_equal = glide_balance(1.2), worst_unequal = glide_balance(1.6);
  assert_true(worst_equal <= 1e-8);
  assert_true(worst_unequal <= 1e-8);
  print_message("glide layer: worst balance-law residual / 20: %.3g (β = γ), %.3g (β ≠ γ)\n", worst_equal,
                worst_unequal);
}

/* ---- conversions ---- */

/* Kaloni & Ariman's example (docs/verification.md): G = 1000, ν = 0.3, N = 0.93, l = a/1.063 with a = 1 (2-D). Expected values by hand:
 * κ = 2000 · 0.8649 / 0.1351, μ = 1000 − κ/2, λ = 600/0.4 = 1500, γ = 4000/1.063². */
static void test_plate_example_constants(void **state) {
  (void)state;
  MicaFieldModel m;
  double l = 1.0 / 1.063;
  if (mica_cosserat_set_technical(&m, 2, 1000.0, 0.3, 0.93, l, l, 1.0)) fail_with_error("plate example");
  assert_relative(m.param[MICA_COSSERAT_LAMBDA], 1500.0, EXACT_TOL, "λ");
  assert_relative(m.param[MICA_COSSERAT_MU], -5401.9245003701, 1e-13, "μ");
  assert_relative(m.param[MICA_COSSERAT_KAPPA], 12803.849000740, 1e-13, "κ");
  assert_true(m.param[MICA_COSSERAT_ALPHA] == 0.0 && m.param[MICA_COSSERAT_BETA] == 0.0);
  assert_relative(m.param[MICA_COSSERAT_GAMMA], 3539.9201217025, 1e-13, "γ");
  /* the classical part */
  assert_relative(m.material.mu, 1000.0, EXACT_TOL, "G");
  assert_relative(m.material.nu, 0.3, EXACT_TOL, "ν");
  assert_relative(m.material.E, 2600.0, EXACT_TOL, "E");
  assert_relative(m.material.lambda, 1500.0, EXACT_TOL, "λ");
  assert_relative(m.material.kappa, 1500.0 + 2000.0 / 3.0, EXACT_TOL, "bulk modulus");
  assert_int_equal(m.material.plane, MICA_PLANE_STRAIN);
  assert_ptr_equal(m.ops, &mica_field_cosserat);
  assert_null(m.classical);
}

/* Lakes' human compact bone (Lakes 1995; ν is not given there, 0.3 is used): G = 3500 MPa, l_t = 0.22 mm,
 * l_b = 0.44 mm, Ψ = 1.5, N = 0.62. γ = 4 G l_b² = 2710.4, β = 2 G l_t² − γ = 338.8 − 2710.4 = −2371.6,
 * α = 338.8 (1 − 1.5)/1.5 = −112.933..., κ = 7000 · 0.3844 / 0.6156. Ψ = 1.5 is the edge: 3α + β + γ = 0. */
static void test_bone_constants(void **state) {
  (void)state;
  MicaFieldModel m;
  if (mica_cosserat_set_technical(&m, 3, 3.5e3, 0.3, 0.62, 0.22, 0.44, 1.5)) fail_with_error("bone");
  double kappa = 7000.0 * 0.3844 / 0.6156;
  assert_relative(m.param[MICA_COSSERAT_LAMBDA], 7000.0 * 0.3 / 0.4, EXACT_TOL, "λ");
  assert_relative(m.param[MICA_COSSERAT_MU], 3500.0 - kappa / 2.0, EXACT_TOL, "μ");
  assert_relative(m.param[MICA_COSSERAT_KAPPA], kappa, EXACT_TOL, "κ");
  assert_relative(m.param[MICA_COSSERAT_ALPHA], -338.8 / 3.0, EXACT_TOL, "α");
  assert_relative(m.param[MICA_COSSERAT_BETA], -2371.6, EXACT_TOL, "β");
  assert_relative(m.param[MICA_COSSERAT_GAMMA], 2710.4, EXACT_TOL, "γ");
  double a = m.param[MICA_COSSERAT_ALPHA], b = m.param[MICA_COSSERAT_BETA], g = m.param[MICA_COSSERAT_GAMMA];
  print_message("bone: λ %.6g μ %.6g κ %.6g α %.6g β %.6g γ %.6g; 3α+β+γ = %.3g, γ+β = %.6g, γ−β = %.6g\n",
                m.param[MICA_COSSERAT_LAMBDA], m.param[MICA_COSSERAT_MU], m.param[MICA_COSSERAT_KAPPA], a, b, g, 3 * a + b + g, g + b, g - b);
  assert_true(fabs(3 * a + b + g) <= 1e-12 * g);
  /* the Eringen setter accepts them back */
  MicaFieldModel e;
  if (mica_cosserat_set_eringen(&e, 3, m.param[MICA_COSSERAT_LAMBDA], m.param[MICA_COSSERAT_MU], m.param[MICA_COSSERAT_KAPPA], a, b, g)) fail_with_error("bone back");
  assert_relative(e.material.E, 9100.0, EXACT_TOL, "E = 2G(1 + ν)");
}

/* Ψ = 1.5 puts 3α + β + γ on its bound 0; these lengths (found by a search) make it −9.1e-13 in floating
 * point. The setter must accept them: the allowance is 1e-12 (|α| + |β| + |γ|). */
static void test_psi_edge_rounding(void **state) {
  (void)state;
  MicaFieldModel m;
  if (mica_cosserat_set_technical(&m, 3, 1000.0, 0.3, 0.5, 1.822865689181055, 1.356231221796456, 1.5))
    fail_with_error("Ψ = 1.5");
  double v = 3.0 * m.param[MICA_COSSERAT_ALPHA] + m.param[MICA_COSSERAT_BETA] + m.param[MICA_COSSERAT_GAMMA];
  print_message("Ψ = 1.5: 3α + β + γ = %.3g\n", v);
  assert_true(v < 0.0); /* otherwise this test no longer tests the allowance */
}

/* Lakes' definitions, written here: G = (2μ+κ)/2, ν = λ/(2λ+2μ+κ), N² = κ/(2(μ+κ)), l_t² = (β+γ)/(2μ+κ),
 * l_b² = γ/(2(2μ+κ)), Ψ = (β+γ)/(α+β+γ). */
static void lakes_technical(const double *p, double t[6]) {
  double lambda = p[0], mu = p[1], kappa = p[2], alpha = p[3], beta = p[4], gamma = p[5];
  t[0] = (2 * mu + kappa) / 2;
  t[1] = lambda / (2 * lambda + 2 * mu + kappa);
  t[2] = sqrt(kappa / (2 * (mu + kappa)));
  t[3] = sqrt((beta + gamma) / (2 * mu + kappa));
  t[4] = sqrt(gamma / (2 * (2 * mu + kappa)));
  t[5] = (beta + gamma) / (alpha + beta + gamma);
}

static void test_round_trip(void **state) {
  (void)state;
  const double technical[][6] = {{1000, 0.3, 0.93, 0.9, 0.7, 0.4}, {3.5e3, 0.3, 0.62, 0.22, 0.44, 1.5},
                                 {2.0, -0.7, 0.1, 3.0, 2.0, 1.2},  {1e5, 0.49, 0.999, 1e-3, 5e-4, 1.0}};
  double worst = 0.0;
  for (size_t k = 0; k < sizeof technical / sizeof technical[0]; k++) {
    const double *t = technical[k];
    MicaFieldModel m, e;
    if (mica_cosserat_set_technical(&m, 3, t[0], t[1], t[2], t[3], t[4], t[5])) fail_with_error("technical");
    double back[6];
    lakes_technical(m.param, back);
    for (int i = 0; i < 6; i++) worst = fmax(worst, fabs(back[i] - t[i]) / fabs(t[i]));
    /* Eringen in, the same model out */
    const double *p = m.param;
    if (mica_cosserat_set_eringen(&e, 3, p[0], p[1], p[2], p[3], p[4], p[5])) fail_with_error("eringen");
    assert_memory_equal(e.param, m.param, sizeof m.param);
    assert_relative(e.material.E, m.material.E, 0.0, "E");
    assert_relative(e.material.nu, t[1], 1e-12, "ν");
    assert_relative(e.material.E, 2 * t[0] * (1 + t[1]), 1e-12, "E");
  }
  print_message("technical → Eringen → technical: worst relative error %.3g\n", worst);
  /* N = 0.999 loses about 3 digits in 1 − N², and 2μ + κ cancels: still 1e-12 */
  assert_true(worst <= 1e-12);
}

/* 2-D: γ = 4 G l², α = β = 0 whatever is passed; Ψ ignored. */
static void test_two_d_constants(void **state) {
  (void)state;
  MicaFieldModel m;
  if (mica_cosserat_set_technical(&m, 2, 10.0, 0.25, 0.5, 0.3, 0.3, 7.0)) fail_with_error("2-D, Ψ ignored");
  assert_relative(m.param[MICA_COSSERAT_GAMMA], 4 * 10.0 * 0.09, EXACT_TOL, "γ");
  if (mica_cosserat_set_eringen(&m, 2, 1.0, 1.0, 1.0, -50.0, 9.0, 2.0)) fail_with_error("2-D, α and β ignored");
  assert_true(m.param[MICA_COSSERAT_ALPHA] == 0.0 && m.param[MICA_COSSERAT_BETA] == 0.0 && m.param[MICA_COSSERAT_GAMMA] == 2.0);
  for (int i = 6; i < 16; i++) assert_true(m.param[i] == 0.0);
}

/* ---- errors ---- */

static void expect_technical_error(int dim, double G, double nu, double N, double lt, double lb, double psi,
                                   const char *needle) {
  MicaFieldModel m;
  memset(&m, 0, sizeof m);
  int ierr = mica_cosserat_set_technical(&m, dim, G, nu, N, lt, lb, psi);
  if (ierr != MICA_ERR_INPUT || !strstr(mica_error_message(), needle)) {
    print_error("expected MICA_ERR_INPUT naming '%s', got %d: %s\n", needle, ierr, mica_error_message());
    fail();
  }
  print_message("%s\n", mica_error_message());
  mica_error_clear();
  assert_null(m.ops);
}

static void test_technical_errors(void **state) {
  (void)state;
  expect_technical_error(2, 1000, 0.3, 1.0, 1, 1, 1, "coupling number N");
  expect_technical_error(2, 1000, 0.3, -0.1, 1, 1, 1, "coupling number N");
  expect_technical_error(3, 1000, 0.3, 0.5, 1, 1, 2.0, "polar ratio Ψ");
  expect_technical_error(3, 1000, 0.3, 0.5, 1, 1, 0.0, "polar ratio Ψ");
  expect_technical_error(2, 1000, 0.3, 0.5, 0, 0, 1, "characteristic length l");
  expect_technical_error(3, 1000, 0.3, 0.5, 0, 1, 1, "torsion length l_t");
  expect_technical_error(3, 1000, 0.3, 0.5, 1, -1, 1, "bending length l_b");
  expect_technical_error(3, 1000, 0.3, 0.5, 2.1, 1, 1, "exceeds twice");
  expect_technical_error(2, 1000, 0.3, 0.5, 1, 2, 1, "one characteristic length");
  expect_technical_error(2, 0, 0.3, 0.5, 1, 1, 1, "shear modulus G");
  expect_technical_error(3, NAN, 0.3, 0.5, 1, 1, 1, "shear modulus G");
  expect_technical_error(2, 1000, 0.5, 0.5, 1, 1, 1, "Poisson's ratio ν");
  expect_technical_error(2, 1000, -1.0, 0.5, 1, 1, 1, "Poisson's ratio ν");
  expect_technical_error(3, 1000, 0.3, NAN, 1, 1, 1, "coupling number N");
}

static void expect_eringen_error(int dim, const double p[6], const char *needle) {
  MicaFieldModel m;
  memset(&m, 0, sizeof m);
  int ierr = mica_cosserat_set_eringen(&m, dim, p[0], p[1], p[2], p[3], p[4], p[5]);
  if (ierr != MICA_ERR_INPUT || !strstr(mica_error_message(), needle)) {
    print_error("expected MICA_ERR_INPUT naming '%s', got %d: %s\n", needle, ierr, mica_error_message());
    fail();
  }
  mica_error_clear();
  assert_null(m.ops);
}

static void test_eringen_errors(void **state) {
  (void)state;
  expect_eringen_error(3, (double[6]){1, 1, -0.1, 1, 0, 1}, "κ = -0.1");
  expect_eringen_error(2, (double[6]){1, -1, 2, 0, 0, 1}, "2μ + κ");
  expect_eringen_error(3, (double[6]){-1, 1, 0, 1, 0, 1}, "3λ + 2μ + κ");
  expect_eringen_error(3, (double[6]){1, 1, 1, -1, 0, 1}, "3α + β + γ");
  expect_eringen_error(3, (double[6]){1, 1, 1, 1, -2, 1}, "γ + β");
  expect_eringen_error(3, (double[6]){1, 1, 1, 1, 2, 1}, "γ − β");
  expect_eringen_error(2, (double[6]){1, 1, 1, 0, 0, 0}, "couple modulus γ");
  expect_eringen_error(3, (double[6]){INFINITY, 1, 1, 1, 0, 1}, "finite");
  /* 3-D semi-definite couple part (l → 0) is admissible */
  MicaFieldModel m;
  assert_int_equal(mica_cosserat_set_eringen(&m, 3, 1, 1, 1, 0, 0, 0), MICA_SUCCESS);
}

static void test_argument_errors(void **state) {
  (void)state;
  MicaFieldModel m;
  assert_int_equal(mica_cosserat_set_eringen(&m, 1, 1, 1, 1, 0, 0, 1), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_cosserat_set_technical(NULL, 2, 1, 0.3, 0.5, 1, 1, 1), MICA_ERR_ARGUMENT);
  if (mica_cosserat_set_eringen(&m, 3, 1, 1, 1, 0, 0, 1)) fail_with_error("set");
  double q[24] = {0}, W;
  assert_int_equal(m.ops->eval(&m, 4, q, &W, NULL, NULL), MICA_ERR_ARGUMENT);
  assert_int_equal(m.ops->eval(&m, 3, NULL, &W, NULL, NULL), MICA_ERR_ARGUMENT);
  assert_int_equal(m.ops->stress(&m, 1, q, NULL, NULL), MICA_ERR_ARGUMENT);
  assert_null(m.ops->component_names(4));
  assert_int_equal(m.ops->ncomp(1), 0);
  mica_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_nq),
      cmocka_unit_test(test_ops_table),
      cmocka_unit_test(test_s_is_dW_dq),
      cmocka_unit_test(test_D_is_ds_dq),
      cmocka_unit_test(test_D_symmetric_and_quadratic),
      cmocka_unit_test(test_energy_reference),
      cmocka_unit_test(test_rigid_motion),
      cmocka_unit_test(test_energy_nonnegative),
      cmocka_unit_test(test_eringen_conditions_sharp),
      cmocka_unit_test(test_limit_no_coupling),
      cmocka_unit_test(test_limit_no_length),
      cmocka_unit_test(test_stress_matches_s),
      cmocka_unit_test(test_glide_layer),
      cmocka_unit_test(test_plate_example_constants),
      cmocka_unit_test(test_bone_constants),
      cmocka_unit_test(test_psi_edge_rounding),
      cmocka_unit_test(test_round_trip),
      cmocka_unit_test(test_two_d_constants),
      cmocka_unit_test(test_technical_errors),
      cmocka_unit_test(test_eringen_errors),
      cmocka_unit_test(test_argument_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
