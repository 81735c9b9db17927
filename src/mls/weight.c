/* MLS weight functions: 1-D kernels w(r) of the normalized distance r = |x − x_I|/ρ ≥ 0, with dw/dr and
 * d²w/dr², all zero for r ≥ 1 (docs/theory.md §MLS, seed 001):
 *   cubic        eq 3.30, C²: the cubic spline, 2/3 − 4r² + 4r³ (r ≤ 1/2), 4/3 − 4r + 4r² − 4/3 r³ (r < 1);
 *   quartic      eq 3.31, C²: 1 − 6r² + 8r³ − 3r⁴;
 *   quartic-c3   C³: the uniform quartic B-spline on five equal knot spans of [−1, 1], scaled to w(0) = 1;
 *   gauss        eq 3.32: the truncated Gaussian exp(−(r/0.4)²), which jumps to zero at r = 1;
 *   exponential  eqs 3.33-3.36 (adaptive EFG, k = 1): (exp(−(r c')²) − exp(−c'²)) / (1 − exp(−c'²)) with
 *                the particle's shape parameter c' = ρ/c passed as param; it vanishes at r = 1 with nonzero
 *                slope.
 * The kernels are not normalized to unit integral: MLS shape functions do not change when Φ is scaled.
 * Piecewise polynomials are evaluated by Horner's rule with their derivatives in the same pass.
 */
#include <math.h>
#include <string.h>

#include "mica/mls.h"

/* f(x) = Σ_i c[i] xⁱ (degree 4) and its first two derivatives: out = {f, f', f''}. Each Horner step
 * p ← p x + c_i is differentiated alongside: p' ← p' x + p, p'' ← p'' x + 2 p'. */
static void poly4_eval(const double c[5], double x, double out[3]) {
  double f = c[4], df = 0.0, ddf = 0.0;
  for (int i = 3; i >= 0; i--) {
    ddf = ddf * x + 2.0 * df;
    df = df * x + f;
    f = f * x + c[i];
  }
  out[0] = f;
  out[1] = df;
  out[2] = ddf;
}

static void set_zero(double w[3]) { w[0] = w[1] = w[2] = 0.0; }

/* ---- cubic spline (eq 3.30) ---- */
static void cubic_eval(double r, double param, double w[3]) {
  static const double inner[5] = {2.0 / 3.0, 0.0, -4.0, 4.0, 0.0};        /* r ≤ 1/2 */
  static const double outer[5] = {4.0 / 3.0, -4.0, 4.0, -4.0 / 3.0, 0.0}; /* 1/2 < r < 1 */
  (void)param;
  if (r >= 1.0) {
    set_zero(w);
    return;
  }
  poly4_eval(r <= 0.5 ? inner : outer, r, w);
}

/* ---- quartic spline (eq 3.31) ---- */
static void quartic_eval(double r, double param, double w[3]) {
  static const double coef[5] = {1.0, 0.0, -6.0, 8.0, -3.0};
  (void)param;
  if (r >= 1.0) {
    set_zero(w);
    return;
  }
  poly4_eval(coef, r, w);
}

/* ---- C³ quartic B-spline ----
 * The cardinal quartic B-spline B(u) on integer knots 0..5, times 24, on its left half (it is symmetric
 * about u = 2.5). The support r ∈ [0, 1) maps to u = 2.5 (1 − r) ∈ (0, 2.5], so the interior knots sit
 * at r = 0.6 (u = 1) and r = 0.2 (u = 2). B(2.5) = 115/192 is the peak that is scaled to 1. */
static const double bspline4_times24[3][5] = {
    {0.0, 0.0, 0.0, 0.0, 1.0},          /* u ∈ [0, 1]   */
    {-5.0, 20.0, -30.0, 20.0, -4.0},    /* u ∈ [1, 2]   */
    {155.0, -300.0, 210.0, -60.0, 6.0}, /* u ∈ [2, 2.5] */
};

static void quartic_c3_eval(double r, double param, double w[3]) {
  const double du_dr = -2.5;
  const double scale = 1.0 / (24.0 * (115.0 / 192.0)); /* undoes the ×24 and normalizes w(0) = 1 */
  (void)param;
  if (r >= 1.0) {
    set_zero(w);
    return;
  }
  double u = 2.5 * (1.0 - r);
  int piece = u < 1.0 ? 0 : (u < 2.0 ? 1 : 2);
  double b[3];
  poly4_eval(bspline4_times24[piece], u, b);
  w[0] = scale * b[0];
  w[1] = scale * du_dr * b[1];
  w[2] = scale * du_dr * du_dr * b[2];
}

/* ---- truncated Gaussian (eq 3.32) ---- */
static void gauss_eval(double r, double param, double w[3]) {
  const double a = 1.0 / (0.4 * 0.4); /* w = exp(−a r²) */
  (void)param;
  if (r >= 1.0) {
    set_zero(w);
    return;
  }
  double e = exp(-a * r * r);
  double g = -2.0 * a * r; /* w'/w */
  w[0] = e;
  w[1] = g * e;
  w[2] = (g * g - 2.0 * a) * e;
}

/* ---- adaptive exponential (eqs 3.33-3.36, k = 1) ----
 * With q = param² and D = 1 − exp(−q): w = (exp(−q r²) − exp(−q)) / D. The numerator is written as
 * −exp(−q r²) expm1(−q (1 − r²)) and D as −expm1(−q) so that small q loses no digits to cancellation.
 * As q → 0 (c ≫ ρ) the kernel tends to 1 − r²; param ≤ 0 (outside the contract, which wants ρ/c > 0)
 * and a q that underflows take that limit instead of dividing by zero. */
static void exponential_eval(double r, double param, double w[3]) {
  if (r >= 1.0) {
    set_zero(w);
    return;
  }
  double q = param * param;
  if (param <= 0.0 || q == 0.0) {
    w[0] = 1.0 - r * r;
    w[1] = -2.0 * r;
    w[2] = -2.0;
    return;
  }
  double inv_d = -1.0 / expm1(-q);
  double e = exp(-q * r * r) * inv_d; /* exp(−q r²) / D: the part that carries the derivatives */
  double g = -2.0 * q * r;            /* d/dr of −q r² */
  w[0] = -e * expm1(-q * (1.0 - r * r));
  w[1] = g * e;
  w[2] = (g * g - 2.0 * q) * e;
}

/* The exponential weight's own setting: α of eq 3.34 (mls.alpha). */
static const MicaDeckKey exponential_keys[] = {
    {.path = "alpha", .type = MICA_KEY_FLOAT, .def = "1.0", .min = 1e-3, .max = 1e3,
     .help = "c = alpha × the largest distance to particles whose supports reach it (eqs 3.34-3.36: 1 to 2)"},
    {0},
};

static int exponential_from_settings(const MicaType *type, const MicaSettings *settings, const char *group,
                                     void *options) {
  (void)type;
  return mica_settings_float(settings, group, "alpha", &((MlsOptions *)options)->alpha);
}

const MlsWeightOps mls_weight_cubic = {{"cubic", "cubic spline (eq 3.30), C²", 0, NULL, NULL}, 2, cubic_eval};
const MlsWeightOps mls_weight_quartic = {{"quartic", "quartic spline (eq 3.31), C²", 0, NULL, NULL}, 2, quartic_eval};
const MlsWeightOps mls_weight_quartic_c3 = {
    {"quartic-c3", "the uniform quartic B-spline, C³", 0, NULL, NULL}, 3, quartic_c3_eval};
const MlsWeightOps mls_weight_gauss = {
    {"gauss", "truncated Gaussian exp(−(r/0.4)²) (eq 3.32), discontinuous at r = 1", 0, NULL, NULL}, -1, gauss_eval};
const MlsWeightOps mls_weight_exponential = {
    {"exponential", "adaptive exponential weight (eqs 3.33-3.36), C⁰", MLS_WEIGHT_ADAPTIVE, exponential_keys,
     exponential_from_settings},
    0, exponential_eval};

static const MicaType *const builtin_weights[] = {
    &mls_weight_cubic.type, &mls_weight_quartic.type, &mls_weight_quartic_c3.type, &mls_weight_gauss.type,
    &mls_weight_exponential.type, NULL,
};

MicaRegistry mls_weight_registry = {"weight function", "quartic-c3", builtin_weights, NULL, 0, NULL};

const MlsWeightOps *mls_weight_at(int i) {
  const MicaType *type = mica_registry_type(&mls_weight_registry, i);
  return type ? mls_weight_of(type) : NULL;
}

const MlsWeightOps *mls_weight_find(const char *name) {
  const MicaType *type = mica_registry_find(&mls_weight_registry, name);
  return type ? mls_weight_of(type) : NULL;
}
