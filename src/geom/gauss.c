/* Gauss rules: Gauss–Legendre on [−1, 1] for any number of points, and collapsed (Duffy) product rules on
 * the reference triangle and tetrahedron (docs/theory.md §geometry, "Gauss rules").
 *
 * Nodes are the roots of a Jacobi polynomial P_n^(α,0) (α = 0: Legendre), found by Newton's method with
 * the roots already found divided out, so every start converges to a new root; weights follow from the
 * derivative at the root, w_i = 2^(α+1) / ((1 − x_i²) P_n'(x_i)²). The simplex rules collapse the unit
 * square (cube) onto the triangle (tetrahedron); the Jacobian of the collapse, (1 − u) or (1 − u)²(1 − v),
 * is absorbed into Gauss–Jacobi weights, so the n-point product rule is exact for total degree 2n − 1.
 */
#include <math.h>

#include "geom_private.h"
#include "mica/geom.h"

enum { NEWTON_MAX = 100 };

/* P_n^(α,0)(x) and P_{n−1}^(α,0)(x) by the three-term recurrence (β = 0). */
static void jacobi_eval(int n, double alpha, double x, double *pn, double *pn1) {
  double p_prev = 1.0, p = 0.5 * ((alpha + 2.0) * x + alpha);
  if (n == 0) {
    *pn = 1.0, *pn1 = 0.0;
    return;
  }
  for (int k = 2; k <= n; k++) {
    const double s = 2.0 * k + alpha; /* 2k + α + β */
    const double a = 2.0 * k * (k + alpha) * (s - 2.0);
    const double b = (s - 1.0) * (s * (s - 2.0) * x + alpha * alpha);
    const double c = 2.0 * (k + alpha - 1.0) * (k - 1.0) * s;
    const double next = (b * p - c * p_prev) / a;
    p_prev = p;
    p = next;
  }
  *pn = p;
  *pn1 = p_prev;
}

/* dP_n/dx from P_n and P_{n−1}: (2n + α)(1 − x²) P_n' = n(α − (2n + α) x) P_n + 2(n + α) n P_{n−1}. */
static double jacobi_derivative(int n, double alpha, double x, double pn, double pn1) {
  const double s = 2.0 * n + alpha;
  return (n * (alpha - s * x) * pn + 2.0 * (n + alpha) * n * pn1) / (s * (1.0 - x * x));
}

/* The n roots of P_n^(α,0), ascending, and their Gauss–Jacobi weights for the weight (1 − x)^α on
 * [−1, 1]. Newton on P_n(x) / Π_j (x − x_j) over the roots x_j found so far ("root suppression"): the
 * step is P_n / (P_n' − P_n Σ_j 1/(x − x_j)). Starts are the Chebyshev-like estimates of the Legendre
 * roots, from the right; they need not be accurate because found roots repel the iterate. */
static int gauss_jacobi(int n, double alpha, double *x, double *w) {
  MICA_CHECK(n >= 1, MICA_ERR_ARGUMENT, "a Gauss rule needs n >= 1 points (got %d)", n);
  for (int i = 0; i < n; i++) {
    double r = cos(GEOM_PI * (i + 0.75) / (n + 0.5));
    if (i > 0 && r >= x[i - 1]) r = x[i - 1] - 1e-3; /* stay left of the last root found */
    for (int it = 0; it < NEWTON_MAX; it++) {
      double pn, pn1, suppress = 0.0;
      jacobi_eval(n, alpha, r, &pn, &pn1);
      for (int j = 0; j < i; j++) suppress += 1.0 / (r - x[j]);
      const double step = pn / (jacobi_derivative(n, alpha, r, pn, pn1) - pn * suppress);
      r -= step;
      if (fabs(step) <= 4e-16 * (1.0 + fabs(r))) break;
    }
    x[i] = r;
  }
  for (int i = 0; i < n; i++) {
    /* one more plain Newton step on P_n itself polishes the root to full precision */
    double pn, pn1;
    jacobi_eval(n, alpha, x[i], &pn, &pn1);
    x[i] -= pn / jacobi_derivative(n, alpha, x[i], pn, pn1);
    jacobi_eval(n, alpha, x[i], &pn, &pn1);
    const double d = jacobi_derivative(n, alpha, x[i], pn, pn1);
    w[i] = pow(2.0, alpha + 1.0) / ((1.0 - x[i] * x[i]) * d * d);
  }
  /* roots were found from the right: reverse to ascending order */
  for (int i = 0, j = n - 1; i < j; i++, j--) {
    double t = x[i];
    x[i] = x[j], x[j] = t;
    t = w[i];
    w[i] = w[j], w[j] = t;
  }
  return MICA_SUCCESS;
}

int mica_gauss_legendre(int n, double *x, double *w) {
  MICA_CALL(gauss_jacobi(n, 0.0, x, w));
  /* the Legendre rule is symmetric: make it exactly so (and the middle node exactly 0) */
  for (int i = 0, j = n - 1; i <= j; i++, j--) {
    const double xs = 0.5 * (x[j] - x[i]), ws = 0.5 * (w[i] + w[j]);
    x[i] = -xs, x[j] = xs;
    w[i] = w[j] = ws;
  }
  return MICA_SUCCESS;
}

/* An n-point rule on [0, 1] for ∫ f(u) (1 − u)^α du, α = 0, 1, 2. */
static int gauss_unit(int n, int alpha, double *u, double *w) {
  MICA_CALL(alpha == 0 ? mica_gauss_legendre(n, u, w) : gauss_jacobi(n, alpha, u, w));
  const double scale = 1.0 / (double)(2 << alpha); /* (du/dx) × ((1 − u)/(1 − x))^α = 2^−(α+1) */
  for (int i = 0; i < n; i++) {
    u[i] = 0.5 * (1.0 + u[i]);
    w[i] *= scale;
  }
  return MICA_SUCCESS;
}

int geom_gauss_unit(int n, double *u, double *w) { return gauss_unit(n, 0, u, w); }

/* Collapse (u, v) ∈ [0,1]² → (ξ, η) = (u, v(1 − u)); dξ dη = (1 − u) du dv. */
int mica_gauss_triangle(int n, double *xi, double *w) {
  double u[GEOM_GAUSS_MAX], wu[GEOM_GAUSS_MAX], v[GEOM_GAUSS_MAX], wv[GEOM_GAUSS_MAX];
  MICA_CHECK(n >= 1 && n <= GEOM_GAUSS_MAX, MICA_ERR_ARGUMENT, "triangle rule: n = %d outside [1, %d]", n,
             GEOM_GAUSS_MAX);
  MICA_CALL(gauss_unit(n, 1, u, wu));
  MICA_CALL(gauss_unit(n, 0, v, wv));
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      const int q = i * n + j;
      xi[2 * q] = u[i];
      xi[2 * q + 1] = v[j] * (1.0 - u[i]);
      w[q] = wu[i] * wv[j];
    }
  return MICA_SUCCESS;
}

/* Collapse (u, v, t) ∈ [0,1]³ → (u, v(1 − u), t(1 − u)(1 − v)); dV = (1 − u)²(1 − v) du dv dt. */
int mica_gauss_tetrahedron(int n, double *xi, double *w) {
  double u[GEOM_GAUSS_MAX], wu[GEOM_GAUSS_MAX], v[GEOM_GAUSS_MAX], wv[GEOM_GAUSS_MAX];
  double t[GEOM_GAUSS_MAX], wt[GEOM_GAUSS_MAX];
  MICA_CHECK(n >= 1 && n <= GEOM_GAUSS_MAX, MICA_ERR_ARGUMENT, "tetrahedron rule: n = %d outside [1, %d]", n,
             GEOM_GAUSS_MAX);
  MICA_CALL(gauss_unit(n, 2, u, wu));
  MICA_CALL(gauss_unit(n, 1, v, wv));
  MICA_CALL(gauss_unit(n, 0, t, wt));
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++)
      for (int k = 0; k < n; k++) {
        const int q = (i * n + j) * n + k;
        xi[3 * q] = u[i];
        xi[3 * q + 1] = v[j] * (1.0 - u[i]);
        xi[3 * q + 2] = t[k] * (1.0 - u[i]) * (1.0 - v[j]);
        w[q] = wu[i] * wv[j] * wt[k];
      }
  return MICA_SUCCESS;
}
