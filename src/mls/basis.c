/* MLS polynomial bases P(s) at the scaled, shifted coordinate s (mostly in [−1, 1]^dim; any s is valid),
 * with their first and second derivatives (docs/theory.md §MLS, seed 001):
 *   pascal     complete monomials of total degree ≤ order (eq 3.37), ordered by total degree with
 *              the constant first, so that P(0) = e₁ (used by N = P(0)ᵀ M⁻¹ P Φ);
 *   lagrange   tensor products of the 1-D Lagrange polynomials on the order + 1 equally spaced nodes
 *              −1 + 2k/order (eqs 3.38, 3.39);
 *   bernstein  tensor products of the 1-D Bernstein polynomials C(n,k) tᵏ (1 − t)ⁿ⁻ᵏ in t = (s + 1)/2
 *              (eq 3.40, reading x^I for the misprinted x).
 * Every basis term is a product over the axes of a 1-D polynomial in s_d, so each basis first tabulates
 * its 1-D values and two derivatives per axis (AxisFactors) and one routine combines them.
 * This runs per particle per evaluation point: no allocation and no pow().
 */
#include "mica/mls.h"

#define MAX_ORDER 3
#define MAX_1D (MAX_ORDER + 1) /* 1-D polynomials per axis */

/* f[d][n][k]: the n-th derivative (n = 0, 1, 2) of the k-th 1-D polynomial along axis d. (A struct, so
 * that it passes as const without C11's qualified-array-pointer pitfall.) */
typedef struct {
  double f[MLS_MAX_DIM][3][MAX_1D];
} AxisFactors;

/* Term a = Π_d f[d][0][k[d]] at slot a of p, with its gradient in dp and packed Hessian in ddp (m terms
 * in all; dp, ddp may be NULL). A derivative differentiates, per axis, the factor as often as that axis
 * occurs in it. Written out per dimension, in the Voigt order of mls_hess_index, so that the compiler sees
 * straight-line code: a loop over a runtime dim was six times slower (3-D, with Hessian). */
static inline void store_term_1d(int m, int a, const int *k, const AxisFactors *ax, double *p, double *dp,
                                 double *ddp) {
  (void)m;
  p[a] = ax->f[0][0][k[0]];
  if (dp) dp[a] = ax->f[0][1][k[0]];
  if (ddp) ddp[a] = ax->f[0][2][k[0]];
}

static inline void store_term_2d(int m, int a, const int *k, const AxisFactors *ax, double *p, double *dp,
                                 double *ddp) {
  double x = ax->f[0][0][k[0]], dx = ax->f[0][1][k[0]], ddx = ax->f[0][2][k[0]];
  double y = ax->f[1][0][k[1]], dy = ax->f[1][1][k[1]], ddy = ax->f[1][2][k[1]];
  p[a] = x * y;
  if (dp) {
    dp[a] = dx * y;
    dp[m + a] = x * dy;
  }
  if (ddp) {
    ddp[a] = ddx * y;         /* xx */
    ddp[m + a] = x * ddy;     /* yy */
    ddp[2 * m + a] = dx * dy; /* xy */
  }
}

static inline void store_term_3d(int m, int a, const int *k, const AxisFactors *ax, double *p, double *dp,
                                 double *ddp) {
  double x = ax->f[0][0][k[0]], dx = ax->f[0][1][k[0]], ddx = ax->f[0][2][k[0]];
  double y = ax->f[1][0][k[1]], dy = ax->f[1][1][k[1]], ddy = ax->f[1][2][k[1]];
  double z = ax->f[2][0][k[2]], dz = ax->f[2][1][k[2]], ddz = ax->f[2][2][k[2]];
  double yz = y * z;
  p[a] = x * yz;
  if (dp) {
    dp[a] = dx * yz;
    dp[m + a] = x * dy * z;
    dp[2 * m + a] = x * y * dz;
  }
  if (ddp) {
    ddp[a] = ddx * yz;            /* xx */
    ddp[m + a] = x * ddy * z;     /* yy */
    ddp[2 * m + a] = x * y * ddz; /* zz */
    ddp[3 * m + a] = x * dy * dz; /* yz */
    ddp[4 * m + a] = dx * y * dz; /* xz */
    ddp[5 * m + a] = dx * dy * z; /* xy */
  }
}

/* ---- Pascal ---- */

/* Exponents of the complete cubic in 1, 2, 3 dimensions, by total degree and then lexicographically
 * (x before y before z). Lower orders use the leading C(order + dim, dim) rows. */
static const int pascal_exp1[4][1] = {{0}, {1}, {2}, {3}};
static const int pascal_exp2[10][2] = {
    {0, 0},                         /* 1 */
    {1, 0}, {0, 1},                 /* x y */
    {2, 0}, {1, 1}, {0, 2},         /* x² xy y² */
    {3, 0}, {2, 1}, {1, 2}, {0, 3}, /* x³ x²y xy² y³ */
};
static const int pascal_exp3[20][3] = {
    {0, 0, 0},                                                       /* 1 */
    {1, 0, 0}, {0, 1, 0}, {0, 0, 1},                                 /* x y z */
    {2, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 2, 0}, {0, 1, 1}, {0, 0, 2}, /* x² xy xz y² yz z² */
    {3, 0, 0}, {2, 1, 0}, {2, 0, 1}, {1, 2, 0}, {1, 1, 1},           /* x³ x²y x²z xy² xyz */
    {1, 0, 2}, {0, 3, 0}, {0, 2, 1}, {0, 1, 2}, {0, 0, 3},           /* xz² y³ y²z yz² z³ */
};

static int pascal_size(int dim, int order) {
  int m = 1; /* C(order + dim, dim), built up as Π_{i=1..dim} (order + i)/i, exact at each step */
  for (int i = 1; i <= dim; i++) m = m * (order + i) / i;
  return m;
}

/* Powers sᵉ and their derivatives e sᵉ⁻¹, e(e − 1) sᵉ⁻², e = 0..3. */
static void monomials_1d(double s, double f[3][MAX_1D]) {
  double s2 = s * s;
  f[0][0] = 1.0, f[0][1] = s, f[0][2] = s2, f[0][3] = s2 * s;
  f[1][0] = 0.0, f[1][1] = 1.0, f[1][2] = 2.0 * s, f[1][3] = 3.0 * s2;
  f[2][0] = 0.0, f[2][1] = 0.0, f[2][2] = 2.0, f[2][3] = 6.0 * s;
}

/* Values only (the shape functions' q_k, once per supporting particle): the powers and the products of
 * store_term_*d in the same order, so the same bits, without the derivative tables. */
static void pascal_values(int dim, int order, const double *s, double *p) {
  double pw[MLS_MAX_DIM][MAX_1D];
  for (int d = 0; d < dim; d++) {
    const double s2 = s[d] * s[d];
    pw[d][0] = 1.0, pw[d][1] = s[d], pw[d][2] = s2, pw[d][3] = s2 * s[d];
  }
  const int m = pascal_size(dim, order);
  switch (dim) {
    case 1:
      for (int a = 0; a < m; a++) p[a] = pw[0][pascal_exp1[a][0]];
      break;
    case 2:
      for (int a = 0; a < m; a++) p[a] = pw[0][pascal_exp2[a][0]] * pw[1][pascal_exp2[a][1]];
      break;
    default:
      for (int a = 0; a < m; a++)
        p[a] = pw[0][pascal_exp3[a][0]] * (pw[1][pascal_exp3[a][1]] * pw[2][pascal_exp3[a][2]]);
  }
}

static void pascal_eval(int dim, int order, const double *s, double *p, double *dp, double *ddp) {
  if (!dp && !ddp) {
    pascal_values(dim, order, s, p);
    return;
  }
  AxisFactors ax;
  for (int d = 0; d < dim; d++) monomials_1d(s[d], ax.f[d]);
  int m = pascal_size(dim, order);
  switch (dim) {
    case 1:
      for (int a = 0; a < m; a++) store_term_1d(m, a, pascal_exp1[a], &ax, p, dp, ddp);
      break;
    case 2:
      for (int a = 0; a < m; a++) store_term_2d(m, a, pascal_exp2[a], &ax, p, dp, ddp);
      break;
    default:
      for (int a = 0; a < m; a++) store_term_3d(m, a, pascal_exp3[a], &ax, p, dp, ddp);
  }
}

/* ---- Tensor-product bases (Lagrange, Bernstein) ---- */

static int tensor_size(int dim, int order) {
  int m = 1;
  for (int d = 0; d < dim; d++) m *= order + 1;
  return m;
}

/* Term a = k0 + n k1 + n² k2 (axis 0 fastest) for n = order + 1 polynomials per axis. */
static void tensor_combine(int dim, int order, const AxisFactors *ax, double *p, double *dp, double *ddp) {
  int n = order + 1, m = tensor_size(dim, order), a = 0, k[3];
  switch (dim) {
    case 1:
      for (k[0] = 0; k[0] < n; k[0]++) store_term_1d(m, a++, k, ax, p, dp, ddp);
      break;
    case 2:
      for (k[1] = 0; k[1] < n; k[1]++)
        for (k[0] = 0; k[0] < n; k[0]++) store_term_2d(m, a++, k, ax, p, dp, ddp);
      break;
    default:
      for (k[2] = 0; k[2] < n; k[2]++)
        for (k[1] = 0; k[1] < n; k[1]++)
          for (k[0] = 0; k[0] < n; k[0]++) store_term_3d(m, a++, k, ax, p, dp, ddp);
  }
}

/* Lagrange polynomials L_k on the nodes −1 + 2j/order. L_k is the product over j ≠ k of the linear
 * factors (s − x_j)/(x_k − x_j); the product rule is applied one factor at a time. */
static void lagrange_1d(int order, double s, double f[3][MAX_1D]) {
  double h = 2.0 / order;
  for (int k = 0; k <= order; k++) {
    double v = 1.0, dv = 0.0, ddv = 0.0, denom = 1.0;
    for (int j = 0; j <= order; j++) {
      if (j == k) continue;
      double q = s - (-1.0 + h * j); /* q' = 1 */
      ddv = ddv * q + 2.0 * dv;
      dv = dv * q + v;
      v *= q;
      denom *= h * (k - j);
    }
    double inv = 1.0 / denom;
    f[0][k] = v * inv, f[1][k] = dv * inv, f[2][k] = ddv * inv;
  }
}

/* Bernstein polynomials of degree n in t = (s + 1)/2 and their s-derivatives. The degrees 0..n come from
 * the recurrence B^j_k = (1 − t) B^{j−1}_k + t B^{j−1}_{k−1}; the derivatives from the lower degrees:
 *   dB^n_k/dt = n (B^{n−1}_{k−1} − B^{n−1}_k),
 *   d²B^n_k/dt² = n(n−1) (B^{n−2}_{k−2} − 2B^{n−2}_{k−1} + B^{n−2}_k),
 * times dt/ds = 1/2 per derivative. Row j is stored shifted by two (B[j][k + 2]) so that the k − 1 and
 * k − 2 neighbours, and entries above degree j, read as zero. */
static void bernstein_1d(int n, double s, double f[3][MAX_1D]) {
  double t = 0.5 * (s + 1.0), u = 1.0 - t;
  double B[MAX_ORDER + 1][MAX_1D + 2] = {{0.0}};
  B[0][2] = 1.0;
  for (int j = 1; j <= n; j++)
    for (int k = 0; k <= j; k++) B[j][k + 2] = u * B[j - 1][k + 2] + t * B[j - 1][k + 1];
  for (int k = 0; k <= n; k++) {
    f[0][k] = B[n][k + 2];
    f[1][k] = 0.5 * n * (B[n - 1][k + 1] - B[n - 1][k + 2]);
    f[2][k] = n < 2 ? 0.0 : 0.25 * n * (n - 1) * (B[n - 2][k] - 2.0 * B[n - 2][k + 1] + B[n - 2][k + 2]);
  }
}

static void lagrange_eval(int dim, int order, const double *s, double *p, double *dp, double *ddp) {
  AxisFactors ax;
  for (int d = 0; d < dim; d++) lagrange_1d(order, s[d], ax.f[d]);
  tensor_combine(dim, order, &ax, p, dp, ddp);
}

static void bernstein_eval(int dim, int order, const double *s, double *p, double *dp, double *ddp) {
  AxisFactors ax;
  for (int d = 0; d < dim; d++) bernstein_1d(order, s[d], ax.f[d]);
  tensor_combine(dim, order, &ax, p, dp, ddp);
}

/* ---- Registry ---- */

const MlsBasisOps mls_basis_pascal = {
    {"pascal", "complete polynomials of total degree <= order (eq 3.37), orders 0-3", 0, NULL, NULL}, 0, 3,
    pascal_size, pascal_eval};
const MlsBasisOps mls_basis_lagrange = {
    {"lagrange", "tensor product of Lagrange polynomials on equally spaced nodes (eqs 3.38, 3.39), orders 1-3", 0,
     NULL, NULL},
    1, 3, tensor_size, lagrange_eval};
const MlsBasisOps mls_basis_bernstein = {
    {"bernstein", "tensor product of Bernstein polynomials (eq 3.40), orders 1-3", 0, NULL, NULL}, 1, 3,
    tensor_size, bernstein_eval};

static const MicaType *const builtin_bases[] = {
    &mls_basis_pascal.type, &mls_basis_lagrange.type, &mls_basis_bernstein.type, NULL,
};

MicaRegistry mls_basis_registry = {"polynomial basis", "pascal", builtin_bases, NULL, 0, NULL};

const MlsBasisOps *mls_basis_at(int i) {
  const MicaType *type = mica_registry_type(&mls_basis_registry, i);
  return type ? mls_basis_of(type) : NULL;
}

const MlsBasisOps *mls_basis_find(const char *name) {
  const MicaType *type = mica_registry_find(&mls_basis_registry, name);
  return type ? mls_basis_of(type) : NULL;
}
