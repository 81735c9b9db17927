/* MLS shape functions and their first and second derivatives at a point (docs/theory.md §MLS).
 *
 * At the evaluation point x the basis is centered at c = x and scaled per axis by s, and the center is
 * held fixed while differentiating: q_k = P((x_k − c)/s) is then a constant and only the weights and
 * p(x) = P((x − c)/s) vary with x (eqs 3.11-3.14 in local coordinates):
 *   M = Σ_k Φ_k q_k q_kᵀ,   M b = p,   N_k = Φ_k (b·q_k)
 *   M b,i  = p,i  − M,i b                          M,i b = Σ_k Φ_k,i g_k q_k,    g_k = q_k·b
 *   M b,ij = p,ij − M,ij b − M,i b,j − M,j b,i     M,i b,j = Σ_k Φ_k,i c_kj q_k,  c_kj = q_k·b,j
 * evaluated at x = c, where p = P(0), p,i = P,i(0)/s_i, p,ij = P,ij(0)/(s_i s_j). M is equilibrated and
 * factored once (Cholesky and its condition estimate written out below: LAPACK's algorithms without its call
 * overhead); every right-hand side is a sum of vectors q_k, never a matrix M,i.
 * Cost per point: O(n m²) for M, O(n m) per derivative, with n supporting particles and m basis terms; the
 * basis is evaluated only for values at the particles, its derivatives only at the center.
 */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/timer.h"
#include "mls_private.h"

/* Small bases get their own compiled copy of the evaluation (mls_eval below): with m and dim constants the
 * loops over basis terms have fixed trip counts, which the compiler unrolls and keeps in registers. The
 * arithmetic and its order are the same in every copy, so every copy gives the same bits. */
#define MLS_INLINE static inline __attribute__((always_inline))
#define MLS_UNROLL _Pragma("GCC unroll 10")
enum { MLS_FIXED_MAX_TERMS = 10 };

/* Per-point scratch, sized for m basis terms and `cap` supporting particles. */
typedef struct {
  double *Q;                  /* [cap][m]: q_k */
  double *phi, *dphi, *ddphi; /* [cap], [cap][dim], [cap][nh]: weights and their derivatives */
  double *G;                  /* [cap]: g_k = q_k·b */
  double *C;                  /* [cap][dim]: c_kj = q_k·b,j */
  double *DD;                 /* [cap][nh]: d_kh = q_k·b,h */
  double *M;                  /* [m*m]: equilibrated D M D, then its Cholesky factor */
  double *D;                  /* [m]: Jacobi scaling 1/sqrt(M_aa) */
  double *b, *bd, *bdd;       /* [m], [dim][m], [nh][m] */
  double *cond_x;             /* [m] the condition estimate's vector */
  int *cond_sign;             /* [m] and its sign vector */
} ShapeWork;

/* ---- workspace ------------------------------------------------------------------------------------ */

static void work_free(ShapeWork *w) {
  double **arrays[] = {&w->Q, &w->phi, &w->dphi, &w->ddphi, &w->G, &w->C, &w->DD,
                       &w->M, &w->D, &w->b, &w->bd, &w->bdd, &w->cond_x};
  for (size_t i = 0; i < sizeof arrays / sizeof *arrays; i++) MICA_FREE(*arrays[i]);
  MICA_FREE(w->cond_sign);
}

/* Grows the per-particle arrays of the shape and its workspace to hold cap supporting particles. */
static int shape_reserve(MlsShape *sh, int m, long cap) {
  if (cap <= sh->cap) return MICA_SUCCESS;
  const int dim = sh->dim, nh = mls_num_hess(dim);
  ShapeWork *w = sh->work;
  MICA_CALL(MICA_REALLOC(sh->index, cap));
  MICA_CALL(MICA_REALLOC(sh->N, cap));
  MICA_CALL(MICA_REALLOC(sh->dN, cap * dim));
  MICA_CALL(MICA_REALLOC(sh->ddN, cap * nh));
  MICA_CALL(MICA_REALLOC(w->Q, cap * m));
  MICA_CALL(MICA_REALLOC(w->phi, cap));
  MICA_CALL(MICA_REALLOC(w->dphi, cap * dim));
  MICA_CALL(MICA_REALLOC(w->ddphi, cap * nh));
  MICA_CALL(MICA_REALLOC(w->G, cap));
  MICA_CALL(MICA_REALLOC(w->C, cap * dim));
  MICA_CALL(MICA_REALLOC(w->DD, cap * nh));
  sh->cap = cap;
  return MICA_SUCCESS;
}

int mls_shape_create(const MlsApprox *mls, MlsShape **out) {
  *out = NULL;
  MlsShape *sh;
  MICA_CALL(MICA_CALLOC(sh, 1));
  int ierr = MICA_SUCCESS;
  const int m = mls->m, dim = mls->dim, nh = mls_num_hess(dim);
  sh->dim = dim;
  ShapeWork *w;
  MICA_CALL_CLEANUP(MICA_CALLOC(w, 1));
  sh->work = w;
  MICA_CALL_CLEANUP(MICA_MALLOC(w->M, m * m));
  MICA_CALL_CLEANUP(MICA_MALLOC(w->D, m));
  MICA_CALL_CLEANUP(MICA_MALLOC(w->b, m));
  MICA_CALL_CLEANUP(MICA_MALLOC(w->bd, dim * m));
  MICA_CALL_CLEANUP(MICA_MALLOC(w->bdd, nh * m));
  MICA_CALL_CLEANUP(MICA_MALLOC(w->cond_x, m));
  MICA_CALL_CLEANUP(MICA_MALLOC(w->cond_sign, m));
  MICA_CALL_CLEANUP(shape_reserve(sh, m, 4 * m + 16));
  *out = sh;
  return MICA_SUCCESS;
cleanup:
  mls_shape_destroy(&sh);
  return ierr;
}

int mls_shape_destroy(MlsShape **shape) {
  if (!*shape) return MICA_SUCCESS;
  if ((*shape)->work) work_free((*shape)->work);
  MICA_FREE((*shape)->work);
  MICA_FREE((*shape)->index);
  MICA_FREE((*shape)->N);
  MICA_FREE((*shape)->dN);
  MICA_FREE((*shape)->ddN);
  MICA_FREE(*shape);
  return MICA_SUCCESS;
}

/* ---- weights at a point --------------------------------------------------------------------------- */

/* Box support: Φ = Π_d w(r_d), r_d = |x_d − x_kd|/ρ_kd (eq 3.29). */
static void weight_box(const MlsApprox *mls, long k, const double *x, int nderiv, double *phi, double *dphi,
                       double *ddphi) {
  const int dim = mls->dim;
  double w[MLS_MAX_DIM][3]; /* w, dw/dx, d²w/dx² per axis, in physical x */
  for (int d = 0; d < dim; d++) {
    const double rho = mls->radii[k * dim + d], delta = x[d] - mls->x[k * dim + d];
    mls->opt.weight->eval(fabs(delta) / rho, mls->wparam[k * dim + d], w[d]);
    const double sign = delta < 0 ? -1.0 : 1.0;
    w[d][1] *= sign / rho;
    w[d][2] /= rho * rho;
  }
  double value = 1;
  for (int d = 0; d < dim; d++) value *= w[d][0];
  *phi = value;
  if (nderiv < 1) return;
  /* Products with one or two factors replaced by a derivative; no division, since w may vanish. */
  for (int i = 0; i < dim; i++) {
    double p = w[i][1];
    for (int d = 0; d < dim; d++)
      if (d != i) p *= w[d][0];
    dphi[i] = p;
  }
  if (nderiv < 2) return;
  for (int i = 0; i < dim; i++)
    for (int j = i; j < dim; j++) {
      double p = i == j ? w[i][2] : w[i][1] * w[j][1];
      for (int d = 0; d < dim; d++)
        if (d != i && d != j) p *= w[d][0];
      ddphi[mls_hess_index(dim, i, j)] = p;
    }
}

/* Ball support: Φ = w(r), r = |x − x_k|/ρ_k; ∇∇Φ = w''/ρ² n nᵀ + w'/(ρ² r)(I − n nᵀ). */
static void weight_ball(const MlsApprox *mls, long k, const double *x, int nderiv, double *phi, double *dphi,
                        double *ddphi) {
  const int dim = mls->dim;
  const double rho = mls->radii[k * dim];
  double delta[MLS_MAX_DIM], dist2 = 0;
  for (int d = 0; d < dim; d++) {
    delta[d] = x[d] - mls->x[k * dim + d];
    dist2 += delta[d] * delta[d];
  }
  const double dist = sqrt(dist2), r = dist / rho;
  double w[3];
  mls->opt.weight->eval(r, mls->wparam[k * dim], w);
  *phi = w[0];
  if (nderiv < 1) return;
  /* At the particle itself n is undefined; w'(0) = 0 for every even kernel, and w'(r)/r → w''(0). */
  const int at_center = r < 1e-10;
  double n[MLS_MAX_DIM];
  for (int d = 0; d < dim; d++) n[d] = at_center ? 0.0 : delta[d] / dist;
  for (int d = 0; d < dim; d++) dphi[d] = w[1] / rho * n[d];
  if (nderiv < 2) return;
  const double radial = w[2] / (rho * rho), tangential = at_center ? radial : w[1] / (rho * rho * r);
  for (int i = 0; i < dim; i++)
    for (int j = i; j < dim; j++)
      ddphi[mls_hess_index(dim, i, j)] = (radial - tangential) * n[i] * n[j] + (i == j ? tangential : 0.0);
}

static void eval_weights(const MlsApprox *mls, const double *x, int nderiv, MlsShape *sh) {
  ShapeWork *w = sh->work;
  const int dim = mls->dim, nh = mls_num_hess(dim);
  for (long k = 0; k < sh->n; k++) {
    if (mls->opt.support == MLS_SUPPORT_BOX)
      weight_box(mls, sh->index[k], x, nderiv, w->phi + k, w->dphi + k * dim, w->ddphi + k * nh);
    else
      weight_ball(mls, sh->index[k], x, nderiv, w->phi + k, w->dphi + k * dim, w->ddphi + k * nh);
  }
}

/* ---- basis ---------------------------------------------------------------------------------------- */

/* The basis scale per axis. N does not depend on it (every basis spans a space invariant under per-axis
 * affine maps), so it is chosen to condition M: SCALE_SPREAD times the weighted spread of the supporting
 * particles, sqrt(Σ Φ_k Δ_kd² / Σ Φ_k), which maps the particles that carry weight to about [−1, 1] (and
 * Bernstein's t to about [0, 1]) whatever the kernel's shape. 2σ is measured: factors 1 and 3-4 leave
 * some order-3 tensor configurations above the 1e-10 derivative tolerance of the unit tests. */
static const double SCALE_SPREAD = 2.0;

static void basis_scale(const MlsApprox *mls, const double *x, const MlsShape *sh, double *scale) {
  const ShapeWork *w = sh->work;
  const int dim = mls->dim;
  double sum_w = 0, moment[MLS_MAX_DIM] = {0}, radius[MLS_MAX_DIM] = {0};
  for (long k = 0; k < sh->n; k++) {
    const long p = sh->index[k];
    sum_w += w->phi[k];
    for (int d = 0; d < dim; d++) {
      const double delta = x[d] - mls->x[p * dim + d];
      moment[d] += w->phi[k] * delta * delta;
      radius[d] = fmax(radius[d], mls->radii[p * dim + d]);
    }
  }
  for (int d = 0; d < dim; d++) {
    const double spread = sum_w > 0 ? SCALE_SPREAD * sqrt(moment[d] / sum_w) : 0;
    scale[d] = spread > 1e-3 * radius[d] ? spread : radius[d]; /* a lone particle: fall back to ρ */
  }
}

/* q_k = P((x_k − x)/s) for every supporting particle: values only, the center is fixed. */
static void eval_basis(const MlsApprox *mls, const double *x, const double *scale, MlsShape *sh) {
  ShapeWork *w = sh->work;
  const int dim = mls->dim, m = mls->m;
  double inv[MLS_MAX_DIM];
  for (int d = 0; d < dim; d++) inv[d] = 1.0 / scale[d];
  for (long k = 0; k < sh->n; k++) {
    const double *xk = mls->x + sh->index[k] * dim;
    double s[MLS_MAX_DIM];
    for (int d = 0; d < dim; d++) s[d] = (xk[d] - x[d]) * inv[d];
    mls->opt.basis->eval(dim, mls->opt.order, s, w->Q + k * m, NULL, NULL);
  }
}

/* ---- moment matrix -------------------------------------------------------------------------------- */

/* M = Σ Φ_k q_k q_kᵀ, equilibrated to D M D with D = diag(M_aa^(−1/2)) so that its condition estimate
 * measures the geometry of the supports, not the scaling of the basis. Returns the 1-norm of D M D, or
 * −1 if a diagonal entry vanishes (a basis term that no supporting particle sees). */
MLS_INLINE double assemble_moment(const ShapeWork *w, long n, int m) {
  double *M = w->M;
  if (m <= MLS_FIXED_MAX_TERMS) {
    /* The upper triangle packed row by row in a local array, which the compiler knows no q_k aliases, two
     * particles per pass: each sum is loaded and stored once per pair and receives particle k's term, then
     * k + 1's — the additions of the loop below in the same order, so the same bits. */
    double acc[MLS_FIXED_MAX_TERMS * (MLS_FIXED_MAX_TERMS + 1) / 2] = {0};
    long k = 0;
    for (; k + 2 <= n; k += 2) {
      const double *q0 = w->Q + k * m, *q1 = q0 + m, phi0 = w->phi[k], phi1 = w->phi[k + 1];
      int e = 0;
      MLS_UNROLL
      for (int a = 0; a < m; a++) {
        const double p0 = phi0 * q0[a], p1 = phi1 * q1[a];
        MLS_UNROLL
        for (int c = a; c < m; c++, e++) acc[e] = acc[e] + p0 * q0[c] + p1 * q1[c];
      }
    }
    for (; k < n; k++) {
      const double *q = w->Q + k * m, phi = w->phi[k];
      int e = 0;
      for (int a = 0; a < m; a++) {
        const double pa = phi * q[a];
        for (int c = a; c < m; c++, e++) acc[e] += pa * q[c];
      }
    }
    int e = 0;
    for (int a = 0; a < m; a++)
      for (int c = a; c < m; c++) M[a * m + c] = acc[e++];
  } else {
    memset(M, 0, sizeof(double) * (size_t)(m * m));
    for (long k = 0; k < n; k++) {
      const double *q = w->Q + k * m, phi = w->phi[k];
      for (int a = 0; a < m; a++) {
        const double pa = phi * q[a];
        for (int c = a; c < m; c++) M[a * m + c] += pa * q[c];
      }
    }
  }
  for (int a = 0; a < m; a++) {
    if (!(M[a * m + a] > 0)) return -1;
    w->D[a] = 1.0 / sqrt(M[a * m + a]);
  }
  for (int a = 0; a < m; a++)
    for (int c = a; c < m; c++) M[a * m + c] *= w->D[a] * w->D[c];
  for (int a = 0; a < m; a++)
    for (int c = 0; c < a; c++) M[a * m + c] = M[c * m + a];
  double norm = 0;
  for (int c = 0; c < m; c++) {
    double col = 0;
    for (int a = 0; a < m; a++) col += fabs(M[a * m + c]);
    norm = fmax(norm, col);
  }
  return norm;
}

static void format_point(int dim, const double *x, char *buf, size_t size) {
  int len = snprintf(buf, size, "(%.6g", x[0]);
  for (int d = 1; d < dim; d++) len += snprintf(buf + len, size - (size_t)len, ", %.6g", x[d]);
  snprintf(buf + len, size - (size_t)len, ")");
}

static int report_singular(const MlsApprox *mls, const double *x, long n, double rcond) {
  char where[128];
  format_point(mls->dim, x, where, sizeof where);
  const int order = mls->opt.order > 0 ? mls->opt.order : 1;
  MICA_ERROR(MICA_ERR_NUMERIC,
             "MLS moment matrix is singular or ill-conditioned at point %s: %ld supporting particles for %d "
             "basis terms (%s order %d, %s support), reciprocal condition %.3g (limit %.3g). Remedy: enlarge "
             "the supports (mls.radius or mls.dilation; on a regular grid the radius must exceed %d particle "
             "spacing%s along every axis, and more is safer) or lower mls.order",
             where, n, mls->m, mls->opt.basis->type.name, mls->opt.order,
             mls->opt.support == MLS_SUPPORT_BOX ? "box" : "ball", rcond, mls->opt.rcond_min, order,
             order > 1 ? "s" : "");
}

/* ---- small dense Cholesky -------------------------------------------------------------------------------
 * M has at most MLS_MAX_TERMS rows (usually 3 to 20): LAPACK's dpotrf, dpotrs and dpocon cost more in call
 * overhead, argument checks and the BLAS's locking than in arithmetic at that size (half the shape-function
 * time with a quadratic basis; docs/performance.md §shape functions). These are the same algorithms written
 * for column-major upper factors, A = UᵀU, U[i + j m] (i ≤ j): results agree with LAPACK's to round-off. */

/* Unblocked Cholesky (dpotf2's order). Returns 0, or j + 1 if the leading minor of order j + 1 is not positive. */
MLS_INLINE int cholesky_upper(int m, double *U) {
  for (int j = 0; j < m; j++) {
    double *uj = U + j * m;
    for (int i = 0; i < j; i++) {
      const double *ui = U + i * m;
      double s = uj[i];
      for (int k = 0; k < i; k++) s -= ui[k] * uj[k];
      uj[i] = s / ui[i];
    }
    double d = uj[j];
    for (int k = 0; k < j; k++) d -= uj[k] * uj[k];
    if (!(d > 0)) return j + 1;
    uj[j] = sqrt(d);
  }
  return 0;
}

/* x ← (UᵀU)⁻¹ x: Uᵀ y = x forward, then U x = y backward. */
MLS_INLINE void cholesky_solve(int m, const double *U, double *x) {
  for (int i = 0; i < m; i++) {
    const double *ui = U + i * m;
    double s = x[i];
    for (int k = 0; k < i; k++) s -= ui[k] * x[k];
    x[i] = s / ui[i];
  }
  for (int i = m - 1; i >= 0; i--) {
    x[i] /= U[i + i * m];
    const double xi = x[i], *ui = U + i * m;
    for (int k = 0; k < i; k++) x[k] -= ui[k] * xi;
  }
}

MLS_INLINE int index_of_max_abs(int m, const double *x) {
  int best = 0;
  for (int i = 1; i < m; i++)
    if (fabs(x[i]) > fabs(x[best])) best = i;
  return best;
}

MLS_INLINE double sum_abs(int m, const double *x) {
  double s = 0;
  for (int i = 0; i < m; i++) s += fabs(x[i]);
  return s;
}

/* ‖A⁻¹‖₁ estimated by Higham's method as LAPACK's dlacn2 runs it inside dpocon (A symmetric, so A⁻ᵀ = A⁻¹):
 * x = e/m; then alternate sign vectors and unit vectors, at most 5 iterations; finally the alternating vector
 * (1 + i/(m−1)) (−1)^i as a lower bound. */
MLS_INLINE double inverse_norm_estimate(int m, const double *U, double *x, int *sign) {
  for (int i = 0; i < m; i++) x[i] = 1.0 / m;
  cholesky_solve(m, U, x);
  if (m == 1) return fabs(x[0]);
  double est = sum_abs(m, x), estold;
  for (int i = 0; i < m; i++) x[i] = x[i] >= 0 ? 1.0 : -1.0, sign[i] = (int)x[i];
  cholesky_solve(m, U, x);
  int j = index_of_max_abs(m, x), iteration = 2;
  for (;;) {
    for (int i = 0; i < m; i++) x[i] = i == j ? 1.0 : 0.0;
    cholesky_solve(m, U, x);
    estold = est;
    est = sum_abs(m, x);
    int same = 1;
    for (int i = 0; i < m; i++) same &= (x[i] >= 0 ? 1 : -1) == sign[i];
    if (same || est <= estold) break; /* a repeated sign vector, or no growth: converged */
    for (int i = 0; i < m; i++) x[i] = x[i] >= 0 ? 1.0 : -1.0, sign[i] = (int)x[i];
    cholesky_solve(m, U, x);
    const int jlast = j;
    j = index_of_max_abs(m, x);
    if (!(x[jlast] != fabs(x[j]) && iteration < 5)) break;
    iteration++;
  }
  double alt = 1.0;
  for (int i = 0; i < m; i++) x[i] = alt * (1.0 + (double)i / (double)(m - 1)), alt = -alt;
  cholesky_solve(m, U, x);
  const double bound = 2.0 * sum_abs(m, x) / (3.0 * m);
  return bound > est ? bound : est;
}

/* Factors D M D (Cholesky, upper) and estimates its reciprocal condition number (as dpocon: 1/(‖A‖₁ est‖A⁻¹‖₁)). */
MLS_INLINE int factor_moment(const MlsApprox *mls, int m, const double *x, MlsShape *sh) {
  ShapeWork *w = sh->work;
  const double norm = assemble_moment(w, sh->n, m);
  sh->rcond = 0;
  if (norm < 0) return report_singular(mls, x, sh->n, 0.0);
  if (cholesky_upper(m, w->M) != 0) return report_singular(mls, x, sh->n, 0.0);
  const double inverse_norm = inverse_norm_estimate(m, w->M, w->cond_x, w->cond_sign);
  sh->rcond = inverse_norm > 0 && norm > 0 ? 1.0 / inverse_norm / norm : 0.0;
  if (!(sh->rcond >= mls->opt.rcond_min)) return report_singular(mls, x, sh->n, sh->rcond);
  return MICA_SUCCESS;
}

/* Solves M X = B for nrhs columns of B (m each) with the equilibrated factor: X = D (D M D)⁻¹ D B. */
MLS_INLINE int solve_moment(int m, const ShapeWork *w, int nrhs, double *rhs) {
  for (int r = 0; r < nrhs; r++) {
    double *b = rhs + r * m;
    for (int a = 0; a < m; a++) b[a] *= w->D[a];
    cholesky_solve(m, w->M, b);
    for (int a = 0; a < m; a++) b[a] *= w->D[a];
  }
  return MICA_SUCCESS;
}

/* ---- projections and right-hand sides ------------------------------------------------------------- */

/* out[k] = q_k · v for every supporting particle, four at a time: their sums are independent, so they
 * advance together instead of each waiting on its own previous addition. */
MLS_INLINE void project_one(int m, long n, const double *Q, const double *v, double *out) {
  long k = 0;
  for (; k + 4 <= n; k += 4) {
    const double *q0 = Q + k * m, *q1 = q0 + m, *q2 = q1 + m, *q3 = q2 + m;
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    MLS_UNROLL
    for (int a = 0; a < m; a++) s0 += q0[a] * v[a], s1 += q1[a] * v[a], s2 += q2[a] * v[a], s3 += q3[a] * v[a];
    out[k] = s0, out[k + 1] = s1, out[k + 2] = s2, out[k + 3] = s3;
  }
  for (; k < n; k++) {
    double s0 = 0;
    for (int a = 0; a < m; a++) s0 += Q[k * m + a] * v[a];
    out[k] = s0;
  }
}

/* out[k*nv + j] = q_k · v_j for nv ≤ MLS_MAX_HESS vectors v_j of length m, stored one after another. */
MLS_INLINE void project_many(int m, long n, const double *Q, int nv, const double *v, double *out) {
  for (long k = 0; k < n; k++) {
    const double *q = Q + k * m;
    double acc[MLS_MAX_HESS] = {0};
    MLS_UNROLL
    for (int a = 0; a < m; a++)
      for (int j = 0; j < nv; j++) acc[j] += q[a] * v[j * m + a];
    for (int j = 0; j < nv; j++) out[k * nv + j] = acc[j];
  }
}

/* rhs_j −= Σ_k coef[k*nv + j] q_k for nv right-hand sides of length m. */
MLS_INLINE void subtract_combination(int m, long n, const double *Q, int nv, const double *coef, double *rhs) {
  if (m <= MLS_FIXED_MAX_TERMS) { /* in a local copy, as the moment matrix: same operations, same bits */
    double acc[MLS_MAX_HESS * MLS_FIXED_MAX_TERMS];
    for (int a = 0; a < nv * m; a++) acc[a] = rhs[a];
    for (long k = 0; k < n; k++) {
      const double *q = Q + k * m, *c = coef + k * nv;
      for (int j = 0; j < nv; j++) {
        MLS_UNROLL
        for (int a = 0; a < m; a++) acc[j * m + a] -= c[j] * q[a];
      }
    }
    for (int a = 0; a < nv * m; a++) rhs[a] = acc[a];
    return;
  }
  for (long k = 0; k < n; k++) {
    const double *q = Q + k * m, *c = coef + k * nv;
    for (int j = 0; j < nv; j++)
      for (int a = 0; a < m; a++) rhs[j * m + a] -= c[j] * q[a];
  }
}

/* b,i from M b,i = p,i − M,i b, M,i b = Σ_k Φ_k,i g_k q_k; then c_kj = q_k·b,j. The coefficients Φ_k,i g_k
 * are staged in C, which the projection then overwrites. */
MLS_INLINE int solve_gradient(const MlsApprox *mls, int m, int dim, const double *scale, MlsShape *sh) {
  ShapeWork *w = sh->work;
  for (int i = 0; i < dim; i++)
    for (int a = 0; a < m; a++) w->bd[i * m + a] = mls->dp0[i * m + a] / scale[i];
  for (long k = 0; k < sh->n; k++)
    for (int i = 0; i < dim; i++) w->C[k * dim + i] = w->dphi[k * dim + i] * w->G[k];
  subtract_combination(m, sh->n, w->Q, dim, w->C, w->bd);
  MICA_CALL(solve_moment(m, w, dim, w->bd));
  project_many(m, sh->n, w->Q, dim, w->bd, w->C);
  return MICA_SUCCESS;
}

/* b,ij from M b,ij = p,ij − Σ_k (Φ,ij g + Φ,i c_j + Φ,j c_i) q_k; then d_kh = q_k·b,h. */
MLS_INLINE int solve_hessian(const MlsApprox *mls, int m, int dim, const double *scale, MlsShape *sh) {
  ShapeWork *w = sh->work;
  const int nh = mls_num_hess(dim);
  for (int i = 0; i < dim; i++)
    for (int j = i; j < dim; j++) {
      const int h = mls_hess_index(dim, i, j);
      for (int a = 0; a < m; a++) w->bdd[h * m + a] = mls->ddp0[h * m + a] / (scale[i] * scale[j]);
    }
  for (long k = 0; k < sh->n; k++) {
    const double g = w->G[k], *dphi = w->dphi + k * dim, *c = w->C + k * dim;
    for (int i = 0; i < dim; i++)
      for (int j = i; j < dim; j++) {
        const int h = mls_hess_index(dim, i, j);
        w->DD[k * nh + h] = w->ddphi[k * nh + h] * g + dphi[i] * c[j] + dphi[j] * c[i];
      }
  }
  subtract_combination(m, sh->n, w->Q, nh, w->DD, w->bdd);
  MICA_CALL(solve_moment(m, w, nh, w->bdd));
  project_many(m, sh->n, w->Q, nh, w->bdd, w->DD);
  return MICA_SUCCESS;
}

/* N_k = Φ g;  N_k,i = Φ,i g + Φ c_i;  N_k,ij = Φ,ij g + Φ,i c_j + Φ,j c_i + Φ d_ij. */
static void assemble_shape(const MlsApprox *mls, int nderiv, MlsShape *sh) {
  const ShapeWork *w = sh->work;
  const int dim = mls->dim, nh = mls_num_hess(dim);
  const long n = sh->n;
  for (long k = 0; k < n; k++) {
    const double phi = w->phi[k], g = w->G[k];
    sh->N[k] = phi * g;
    if (nderiv < 1) continue;
    const double *dphi = w->dphi + k * dim, *c = w->C + k * dim;
    for (int i = 0; i < dim; i++) sh->dN[i * n + k] = dphi[i] * g + phi * c[i];
    if (nderiv < 2) continue;
    for (int i = 0; i < dim; i++)
      for (int j = i; j < dim; j++) {
        const int h = mls_hess_index(dim, i, j);
        sh->ddN[h * n + k] = w->ddphi[k * nh + h] * g + dphi[i] * c[j] + dphi[j] * c[i] + phi * w->DD[k * nh + h];
      }
  }
}

/* ---- evaluation ----------------------------------------------------------------------------------- */

static int report_no_support(const MlsApprox *mls, const double *x) {
  char where[128];
  format_point(mls->dim, x, where, sizeof where);
  MICA_ERROR(MICA_ERR_NUMERIC,
             "no particle supports the point %s: it lies outside every particle's support. Remedy: check "
             "that the point is inside the particle cloud, or enlarge mls.radius / mls.dilation",
             where);
}

/* From the weights on: the moment matrix, its factor and the shape functions, with m basis terms in dim
 * dimensions (constants in the fixed-size copies below). */
MLS_INLINE int eval_supported(const MlsApprox *mls, const double *x, int nderiv, MlsShape *sh, int m, int dim) {
  ShapeWork *w = sh->work;
  double scale[MLS_MAX_DIM];
  eval_weights(mls, x, nderiv, sh);
  basis_scale(mls, x, sh, scale);
  eval_basis(mls, x, scale, sh);
  MICA_CALL(factor_moment(mls, m, x, sh));
  memcpy(w->b, mls->p0, sizeof(double) * (size_t)m);
  MICA_CALL(solve_moment(m, w, 1, w->b));
  project_one(m, sh->n, w->Q, w->b, w->G);
  if (nderiv >= 1) MICA_CALL(solve_gradient(mls, m, dim, scale, sh));
  if (nderiv >= 2) MICA_CALL(solve_hessian(mls, m, dim, scale, sh));
  assemble_shape(mls, nderiv, sh);
  return MICA_SUCCESS;
}

/* The complete linear and quadratic bases in 2-D and 3-D (and any basis of as many terms), then any other. */
static int eval_m3_d2(const MlsApprox *mls, const double *x, int nderiv, MlsShape *sh) {
  return eval_supported(mls, x, nderiv, sh, 3, 2);
}
static int eval_m4_d3(const MlsApprox *mls, const double *x, int nderiv, MlsShape *sh) {
  return eval_supported(mls, x, nderiv, sh, 4, 3);
}
static int eval_m6_d2(const MlsApprox *mls, const double *x, int nderiv, MlsShape *sh) {
  return eval_supported(mls, x, nderiv, sh, 6, 2);
}
static int eval_m10_d3(const MlsApprox *mls, const double *x, int nderiv, MlsShape *sh) {
  return eval_supported(mls, x, nderiv, sh, 10, 3);
}
static int eval_any(const MlsApprox *mls, const double *x, int nderiv, MlsShape *sh) {
  return eval_supported(mls, x, nderiv, sh, mls->m, mls->dim);
}

int mls_eval(const MlsApprox *mls, const double *x, int nderiv, MlsShape *sh) {
  MICA_CHECK(nderiv >= MLS_VALUES && nderiv <= MLS_HESSIAN, MICA_ERR_ARGUMENT, "nderiv must be 0, 1 or 2, not %d",
             nderiv);
  MICA_CHECK(sh->dim == mls->dim, MICA_ERR_ARGUMENT, "shape of dimension %d used with a %d-D MLS", sh->dim,
             mls->dim);
  long count = 0, cap = sh->cap;
  const double start = mica_wtime();
  MICA_CALL(mls_search_query(mls->search, x, &sh->index, &count, &cap));
  sh->time_search += mica_wtime() - start;
  /* the query grows the index array itself when a point has more support than any before it */
  if (cap > sh->cap) MICA_CALL(shape_reserve(sh, mls->m, cap));
  sh->n = count;
  sh->nderiv = nderiv;
  if (count == 0) return report_no_support(mls, x);
  const int m = mls->m, dim = mls->dim;
  if (m == 3 && dim == 2) return eval_m3_d2(mls, x, nderiv, sh);
  if (m == 4 && dim == 3) return eval_m4_d3(mls, x, nderiv, sh);
  if (m == 6 && dim == 2) return eval_m6_d2(mls, x, nderiv, sh);
  if (m == 10 && dim == 3) return eval_m10_d3(mls, x, nderiv, sh);
  return eval_any(mls, x, nderiv, sh);
}

/* The 2-norm condition number of the equilibrated moment matrix D M D at x — the matrix mls_eval factors —
 * as the ratio of its extreme eigenvalues (LAPACK dsyev on the m×m matrix). */
int mls_moment_condition(const MlsApprox *mls, const double *x, MlsShape *sh, double *cond) {
  MICA_CHECK(sh->dim == mls->dim && cond, MICA_ERR_ARGUMENT, "mls_moment_condition: shape of dimension %d used with a "
             "%d-D MLS", sh->dim, mls->dim);
  long count = 0, cap = sh->cap;
  MICA_CALL(mls_search_query(mls->search, x, &sh->index, &count, &cap));
  if (cap > sh->cap) MICA_CALL(shape_reserve(sh, mls->m, cap));
  sh->n = count;
  sh->nderiv = MLS_VALUES;
  if (count == 0) return report_no_support(mls, x);
  ShapeWork *w = sh->work;
  const int m = mls->m;
  double scale[MLS_MAX_DIM], eig[MLS_MAX_TERMS];
  eval_weights(mls, x, MLS_VALUES, sh);
  basis_scale(mls, x, sh, scale);
  eval_basis(mls, x, scale, sh);
  if (assemble_moment(w, sh->n, m) < 0) return report_singular(mls, x, sh->n, 0.0);
  const lapack_int info = LAPACKE_dsyev(LAPACK_COL_MAJOR, 'N', 'U', m, w->M, m, eig);
  MICA_CHECK(info == 0, MICA_ERR_LIBRARY, "LAPACK dsyev failed on the moment matrix (info %d)", (int)info);
  if (!(eig[0] > 0)) return report_singular(mls, x, sh->n, 0.0);
  *cond = eig[m - 1] / eig[0];
  return MICA_SUCCESS;
}

void mls_shape_apply(const MlsShape *sh, const double *u, double *uh, double *grad, double *hess) {
  const int dim = sh->dim, nh = mls_num_hess(dim);
  const long n = sh->n;
  double value = 0;
  for (long k = 0; k < n; k++) value += sh->N[k] * u[sh->index[k]];
  if (uh) *uh = value;
  if (grad && sh->nderiv >= 1)
    for (int d = 0; d < dim; d++) {
      double s = 0;
      for (long k = 0; k < n; k++) s += sh->dN[d * n + k] * u[sh->index[k]];
      grad[d] = s;
    }
  if (hess && sh->nderiv >= 2)
    for (int h = 0; h < nh; h++) {
      double s = 0;
      for (long k = 0; k < n; k++) s += sh->ddN[h * n + k] * u[sh->index[k]];
      hess[h] = s;
    }
}
