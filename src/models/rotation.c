/* Finite rotations: R = exp(skew Φ), the right tangent T(Φ) and their first and second derivatives in Φ
 * (mica/rotation.h; docs/theory.md §finite rotations).
 *
 * Every entry of R and T is a polynomial in Φ times one of the coefficient functions a, b, c of s = θ² = Φ·Φ,
 * which are smooth (entire) in s. So the derivatives are computed by carrying each scalar as a second-order
 * jet in the three components of Φ — value, gradient and packed Hessian — through products and through the
 * coefficient functions (chain rule with da/ds, d²a/ds²). No formula for ∂²R/∂Φ² is written by hand, and
 * the result is exact to round-off at every θ, including θ = 0. */
#include <math.h>
#include <string.h>

#include "mica/mls.h"
#include "mica/rotation.h"

/* A scalar function of Φ with its gradient and packed Hessian (mls_hess_index(3, i, j) order). */
typedef struct {
  double v, g[3], h[6];
} Jet;

static Jet jet_constant(double v) {
  Jet r = {v, {0, 0, 0}, {0, 0, 0, 0, 0, 0}};
  return r;
}

static Jet jet_variable(const double phi[3], int k) {
  Jet r = jet_constant(phi[k]);
  r.g[k] = 1;
  return r;
}

static Jet jet_mul(Jet a, Jet b) {
  Jet r;
  r.v = a.v * b.v;
  for (int i = 0; i < 3; i++) r.g[i] = a.v * b.g[i] + b.v * a.g[i];
  for (int i = 0; i < 3; i++)
    for (int j = i; j < 3; j++) {
      const int h = mls_hess_index(3, i, j);
      r.h[h] = a.v * b.h[h] + b.v * a.h[h] + a.g[i] * b.g[j] + a.g[j] * b.g[i];
    }
  return r;
}

/* α a + β b */
static Jet jet_axpby(double alpha, Jet a, double beta, Jet b) {
  Jet r;
  r.v = alpha * a.v + beta * b.v;
  for (int i = 0; i < 3; i++) r.g[i] = alpha * a.g[i] + beta * b.g[i];
  for (int h = 0; h < 6; h++) r.h[h] = alpha * a.h[h] + beta * b.h[h];
  return r;
}

/* f(x) for a jet x, given f, f', f'' at x.v. */
static Jet jet_compose(Jet x, double f, double df, double ddf) {
  Jet r;
  r.v = f;
  for (int i = 0; i < 3; i++) r.g[i] = df * x.g[i];
  for (int i = 0; i < 3; i++)
    for (int j = i; j < 3; j++) {
      const int h = mls_hess_index(3, i, j);
      r.h[h] = df * x.h[h] + ddf * x.g[i] * x.g[j];
    }
  return r;
}

/* ---- coefficient functions of s = θ² --------------------------------------------------------------------
 *   a = sin θ/θ = Σ (−s)^k/(2k+1)!,  b = (1 − cos θ)/θ² = Σ (−s)^k/(2k+2)!,  c = (θ − sin θ)/θ³ = Σ (−s)^k/(2k+3)!
 * Below s = 1 the series (16 terms: the next is < 1e-30) avoid the cancellation of the closed forms; above,
 * the closed forms and their s-derivatives
 *   a' = (cos θ − a)/(2s), a'' = −(a + 6a')/(4s), b' = (a − 2b)/(2s), b'' = (a' − 4b')/(2s),
 *   c = (1 − a)/s, c' = −(a' + c)/s, c'' = −(a'' + 2c')/s. */
enum { SERIES_TERMS = 16 };

typedef struct {
  double f, df, ddf;
} Coefficient;

/* Σ_k (−s)^k/(2k+shift)! with its first two s-derivatives. */
static Coefficient series(double s, int shift) {
  double term_factor[SERIES_TERMS]; /* 1/(2k+shift)! */
  double fact = 1;
  for (int n = 2; n <= shift; n++) fact *= n;
  term_factor[0] = 1 / fact;
  for (int k = 1; k < SERIES_TERMS; k++)
    term_factor[k] = term_factor[k - 1] / ((2.0 * k + shift - 1) * (2.0 * k + shift));
  Coefficient c = {0, 0, 0};
  double power = 1, prev = 0, prev2 = 0; /* (−s)^k, (−s)^(k−1), (−s)^(k−2) */
  for (int k = 0; k < SERIES_TERMS; k++) {
    c.f += power * term_factor[k];
    if (k >= 1) c.df += -k * prev * term_factor[k];              /* d(−s)^k/ds = −k (−s)^(k−1) */
    if (k >= 2) c.ddf += k * (k - 1) * prev2 * term_factor[k];   /* d²(−s)^k/ds² = k(k−1) (−s)^(k−2) */
    prev2 = prev, prev = power, power *= -s;
  }
  return c;
}

static void coefficients(double s, Coefficient *a, Coefficient *b, Coefficient *c) {
  if (s < 1) {
    *a = series(s, 1), *b = series(s, 2), *c = series(s, 3);
    return;
  }
  const double theta = sqrt(s), sn = sin(theta), cs = cos(theta);
  a->f = sn / theta;
  a->df = (cs - a->f) / (2 * s);
  a->ddf = -(a->f + 6 * a->df) / (4 * s);
  b->f = (1 - cs) / s;
  b->df = (a->f - 2 * b->f) / (2 * s);
  b->ddf = (a->df - 4 * b->df) / (2 * s);
  c->f = (1 - a->f) / s;
  c->df = -(a->df + c->f) / s;
  c->ddf = -(a->ddf + 2 * c->df) / s;
}

/* ---- R and T ------------------------------------------------------------------------------------------------ */

/* M_ij = δ_ij + p Φ̂_ij + q (Φ_i Φ_j − s δ_ij), with Φ̂ = skew Φ (Φ̂_ij = −e_ijk Φ_k) and Φ̂² = ΦΦᵀ − s I. */
static void matrix_jets(const Jet phi[3], Jet s, Jet p, Jet q, Jet M[9]) {
  static const int skew_index[9] = {-1, 2, 1, 2, -1, 0, 1, 0, -1}; /* which Φ_k sits in Φ̂_ij */
  static const double skew_sign[9] = {0, -1, 1, 1, 0, -1, -1, 1, 0};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      Jet square = jet_mul(phi[i], phi[j]);
      if (i == j) square = jet_axpby(1, square, -1, s);
      Jet m = jet_mul(q, square);
      if (i != j) m = jet_axpby(1, m, skew_sign[i * 3 + j], jet_mul(p, phi[skew_index[i * 3 + j]]));
      if (i == j) m.v += 1;
      M[i * 3 + j] = m;
    }
}

static void unpack(const Jet M[9], int nderiv, double *value, double (*d)[9], double (*dd)[9]) {
  for (int e = 0; e < 9; e++) {
    value[e] = M[e].v;
    if (nderiv >= 1)
      for (int i = 0; i < 3; i++) d[i][e] = M[e].g[i];
    if (nderiv >= 2)
      for (int h = 0; h < 6; h++) dd[h][e] = M[e].h[h];
  }
}

void mica_rotation_eval(const double phi[3], int nderiv, MicaRotation *rot) {
  Jet v[3] = {jet_variable(phi, 0), jet_variable(phi, 1), jet_variable(phi, 2)};
  Jet s = jet_constant(0);
  for (int k = 0; k < 3; k++) s = jet_axpby(1, s, 1, jet_mul(v[k], v[k]));
  Coefficient a, b, c;
  coefficients(s.v, &a, &b, &c);
  const Jet ja = jet_compose(s, a.f, a.df, a.ddf), jb = jet_compose(s, b.f, b.df, b.ddf),
            jc = jet_compose(s, c.f, c.df, c.ddf);
  Jet M[9];
  matrix_jets(v, s, ja, jb, M); /* R = I + a Φ̂ + b Φ̂² */
  unpack(M, nderiv, rot->R, rot->dR, rot->ddR);
  matrix_jets(v, s, jet_axpby(-1, jb, 0, jb), jc, M); /* T = I − b Φ̂ + c Φ̂² */
  unpack(M, nderiv, rot->T, rot->dT, rot->ddT);
}

/* θ from cos θ = (tr R − 1)/2; the axis from the skew part sin θ n = axl(R − Rᵀ)/2 or, near θ = π where
 * sin θ vanishes, from the symmetric part (R + Rᵀ)/2 − cos θ I = (1 − cos θ) n nᵀ. */
void mica_rotation_log(const double R[9], double phi[3]) {
  const double cs = fmax(-1.0, fmin(1.0, 0.5 * (R[0] + R[4] + R[8] - 1)));
  const double theta = acos(cs);
  const double axial[3] = {0.5 * (R[7] - R[5]), 0.5 * (R[2] - R[6]), 0.5 * (R[3] - R[1])}; /* sin θ n */
  if (theta < 3.0) { /* sin θ ≥ 0.14: dividing by it is safe */
    const double s = theta < 1e-4 ? 1 - theta * theta / 6 : sin(theta) / theta; /* sin θ/θ */
    for (int i = 0; i < 3; i++) phi[i] = axial[i] / s;
    return;
  }
  int col = 0;
  for (int i = 1; i < 3; i++)
    if (R[i * 4] > R[col * 4]) col = i;
  double n[3];
  for (int i = 0; i < 3; i++) n[i] = 0.5 * (R[i * 3 + col] + R[col * 3 + i]) - (i == col ? cs : 0);
  const double norm = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double dot = n[0] * axial[0] + n[1] * axial[1] + n[2] * axial[2];
  const double sign = dot < 0 ? -1.0 : 1.0; /* n and −n are both axes; sin θ n fixes which */
  for (int i = 0; i < 3; i++) phi[i] = sign * theta * n[i] / norm;
}
