/* Shape-function evaluations per second in 3-D: mica's fused evaluation (one Cholesky factor of M per
 * point, derivative right-hand sides formed as vectors) beside a straightforward reference that forms
 * M⁻¹ explicitly (LU + inverse) together with the derivative matrices M,i and M,ij, the textbook EFG
 * recipe (M⁻¹),i = −M⁻¹ M,i M⁻¹. Both use the same neighbor search, basis and weight, so the ratio measures
 * the linear algebra only. The largest difference between the two is printed as a check of both.
 *
 * Prints rates and ratios; never fails on time. Configurations: Pascal order 1 and 2, box and ball
 * supports, dilation 2 and 3, gradients only and gradients + Hessians; 21³ particles, random points.
 *
 * Flop rate of the fused evaluation (issue 7, item 5): the useful floating-point operations of the method per
 * point, a multiply-add counting 2, with n supporting particles, m basis terms, d = 3, h = 6 Hessian entries
 * (0 without), r = 1 + d + h right-hand sides:
 *   moment matrix M = Σ Φ q qᵀ (upper triangle)       n m (m + 1) + n m
 *   Cholesky m³/3; condition estimate 5 solves          m³/3 + 5 · 2 m²
 *   r solves with the factor                            r · 2 m²
 *   projections q_k · b (r vectors)                     2 n m r
 *   derivative right-hand sides Σ coef q_k              2 n m (d + h)
 *   combinations into N, ∇N, ∇∇N                        n (1 + 4 d + 12 h)
 * The weights, the basis values and the neighbor search are not counted (no flops to speak of, but time).
 * Printed beside DGEMM of the same BLAS on the same core, at the moment matrix's shape (m × n)·(n × m) and at
 * 500 × 500 × 500. */
#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/mls.h"
#include "mica/random.h"
#include "mica/timer.h"
#include <time.h>

enum { DIM = 3, NH = 6, GRID = 21, MAXM = 10 };

typedef struct {
  const MlsApprox *mls;
  const MlsOptions *opt;
  MlsSearch *search; /* the same supports as mls's own search */
  long *index;
  long count, cap;
  double *P, *dP, *ddP; /* basis at each supporting particle, physical coordinates */
  double *w, *dw, *ddw; /* weights */
} Reference;

/* Weight and derivatives of particle k at x (box: product of 1-D kernels; ball: radial). */
static void ref_weight(const Reference *r, long k, const double *x, double *w, double *dw, double *ddw) {
  const double *xk = mls_particles(r->mls) + k * DIM, *rho = mls_radii(r->mls) + k * DIM;
  if (r->opt->support == MLS_SUPPORT_BOX) {
    double f[DIM][3];
    for (int d = 0; d < DIM; d++) {
      const double delta = x[d] - xk[d];
      r->opt->weight->eval(fabs(delta) / rho[d], 0, f[d]);
      f[d][1] *= (delta < 0 ? -1 : 1) / rho[d];
      f[d][2] /= rho[d] * rho[d];
    }
    *w = f[0][0] * f[1][0] * f[2][0];
    for (int i = 0; i < DIM; i++) dw[i] = f[i][1] * f[(i + 1) % 3][0] * f[(i + 2) % 3][0];
    for (int i = 0; i < DIM; i++)
      for (int j = i; j < DIM; j++) {
        double p = i == j ? f[i][2] : f[i][1] * f[j][1];
        for (int d = 0; d < DIM; d++)
          if (d != i && d != j) p *= f[d][0];
        ddw[mls_hess_index(DIM, i, j)] = p;
      }
    return;
  }
  double delta[DIM], dist = 0;
  for (int d = 0; d < DIM; d++) delta[d] = x[d] - xk[d], dist += delta[d] * delta[d];
  dist = sqrt(dist);
  double f[3];
  r->opt->weight->eval(dist / rho[0], 0, f);
  *w = f[0];
  const double a = f[2] / (rho[0] * rho[0]), b = dist > 1e-12 ? f[1] / (rho[0] * dist) : a;
  for (int i = 0; i < DIM; i++) dw[i] = dist > 1e-12 ? f[1] / rho[0] * delta[i] / dist : 0;
  for (int i = 0; i < DIM; i++)
    for (int j = i; j < DIM; j++) {
      const double ni = dist > 1e-12 ? delta[i] / dist : 0, nj = dist > 1e-12 ? delta[j] / dist : 0;
      ddw[mls_hess_index(DIM, i, j)] = (a - b) * ni * nj + (i == j ? b : 0);
    }
}

static void matmul(int m, const double *A, const double *B, double *C) {
  for (int i = 0; i < m; i++)
    for (int j = 0; j < m; j++) {
      double s = 0;
      for (int k = 0; k < m; k++) s += A[i * m + k] * B[k * m + j];
      C[i * m + j] = s;
    }
}

/* The textbook recipe, unshifted basis P(x) in coordinates scaled by a fixed length L. */
static int ref_eval(Reference *r, const double *x, int hess, double *N, double *dN, double *ddN) {
  const int m = mls_num_terms(r->mls);
  const double L = 5.0;
  MICA_CALL(mls_search_query(r->search, x, &r->index, &r->count, &r->cap));
  const long n = r->count;
  double M[MAXM * MAXM] = {0}, dM[DIM][MAXM * MAXM] = {{0}}, ddM[NH][MAXM * MAXM] = {{0}};
  for (long k = 0; k < n; k++) {
    const double *xk = mls_particles(r->mls) + r->index[k] * DIM;
    double s[DIM] = {xk[0] / L, xk[1] / L, xk[2] / L};
    r->opt->basis->eval(DIM, r->opt->order, s, r->P + k * m, NULL, NULL);
    ref_weight(r, r->index[k], x, r->w + k, r->dw + k * DIM, r->ddw + k * NH);
    for (int a = 0; a < m; a++)
      for (int b = 0; b < m; b++) {
        const double pp = r->P[k * m + a] * r->P[k * m + b];
        M[a * m + b] += r->w[k] * pp;
        for (int i = 0; i < DIM; i++) dM[i][a * m + b] += r->dw[k * DIM + i] * pp;
        if (hess)
          for (int h = 0; h < NH; h++) ddM[h][a * m + b] += r->ddw[k * NH + h] * pp;
      }
  }
  /* explicit inverse */
  lapack_int ipiv[MAXM];
  double Minv[MAXM * MAXM];
  memcpy(Minv, M, sizeof M);
  if (LAPACKE_dgetrf(LAPACK_ROW_MAJOR, m, m, Minv, m, ipiv) || LAPACKE_dgetri(LAPACK_ROW_MAJOR, m, Minv, m, ipiv))
    return MICA_ERR_NUMERIC;
  double dMinv[DIM][MAXM * MAXM], ddMinv[NH][MAXM * MAXM], T[MAXM * MAXM], U[MAXM * MAXM];
  for (int i = 0; i < DIM; i++) { /* (M⁻¹),i = −M⁻¹ M,i M⁻¹ */
    matmul(m, dM[i], Minv, T);
    matmul(m, Minv, T, dMinv[i]);
    for (int a = 0; a < m * m; a++) dMinv[i][a] = -dMinv[i][a];
  }
  if (hess)
    for (int i = 0; i < DIM; i++)
      for (int j = i; j < DIM; j++) { /* (M⁻¹),ij = −M⁻¹ (M,ij M⁻¹ + M,i (M⁻¹),j + M,j (M⁻¹),i) */
        const int h = mls_hess_index(DIM, i, j);
        matmul(m, ddM[h], Minv, T);
        matmul(m, dM[i], dMinv[j], U);
        for (int a = 0; a < m * m; a++) T[a] += U[a];
        matmul(m, dM[j], dMinv[i], U);
        for (int a = 0; a < m * m; a++) T[a] += U[a];
        matmul(m, Minv, T, ddMinv[h]);
        for (int a = 0; a < m * m; a++) ddMinv[h][a] = -ddMinv[h][a];
      }
  /* P(x) and its derivatives */
  double s[DIM] = {x[0] / L, x[1] / L, x[2] / L}, p[MAXM], dp[DIM * MAXM], ddp[NH * MAXM];
  r->opt->basis->eval(DIM, r->opt->order, s, p, dp, ddp);
  for (int a = 0; a < DIM * m; a++) dp[a] /= L;
  for (int a = 0; a < NH * m; a++) ddp[a] /= L * L;
  /* γ = M⁻¹ᵀ P and derivatives, then N_k = γ·P_k w_k etc. */
  double g[MAXM], dg[DIM][MAXM], ddg[NH][MAXM];
  for (int a = 0; a < m; a++) {
    g[a] = 0;
    for (int b = 0; b < m; b++) g[a] += Minv[b * m + a] * p[b];
    for (int i = 0; i < DIM; i++) {
      dg[i][a] = 0;
      for (int b = 0; b < m; b++) dg[i][a] += dMinv[i][b * m + a] * p[b] + Minv[b * m + a] * dp[i * m + b];
    }
    if (hess)
      for (int i = 0; i < DIM; i++)
        for (int j = i; j < DIM; j++) {
          const int h = mls_hess_index(DIM, i, j);
          ddg[h][a] = 0;
          for (int b = 0; b < m; b++)
            ddg[h][a] += ddMinv[h][b * m + a] * p[b] + dMinv[i][b * m + a] * dp[j * m + b] +
                         dMinv[j][b * m + a] * dp[i * m + b] + Minv[b * m + a] * ddp[h * m + b];
        }
  }
  for (long k = 0; k < n; k++) {
    const double *Pk = r->P + k * m, wk = r->w[k];
    double gp = 0, dgp[DIM] = {0};
    for (int a = 0; a < m; a++) gp += g[a] * Pk[a];
    for (int i = 0; i < DIM; i++)
      for (int a = 0; a < m; a++) dgp[i] += dg[i][a] * Pk[a];
    N[k] = gp * wk;
    for (int i = 0; i < DIM; i++) dN[i * n + k] = dgp[i] * wk + gp * r->dw[k * DIM + i];
    if (hess)
      for (int i = 0; i < DIM; i++)
        for (int j = i; j < DIM; j++) {
          const int h = mls_hess_index(DIM, i, j);
          double ddgp = 0;
          for (int a = 0; a < m; a++) ddgp += ddg[h][a] * Pk[a];
          ddN[h * n + k] = ddgp * wk + dgp[i] * r->dw[k * DIM + j] + dgp[j] * r->dw[k * DIM + i] +
                           gp * r->ddw[k * NH + h];
        }
  }
  return MICA_SUCCESS;
}

/* ---- driver ---------------------------------------------------------------------------------------- */

typedef struct {
  int order, hess;
  MlsSupportKind support;
  double dilation;
} Case;

static double *grid_particles(long *n) {
  *n = (long)GRID * GRID * GRID;
  double *x = malloc(sizeof(double) * (size_t)(*n * DIM));
  for (long i = 0; i < *n; i++) {
    x[i * DIM + 0] = -5 + 10.0 * (double)(i % GRID) / (GRID - 1);
    x[i * DIM + 1] = -5 + 10.0 * (double)((i / GRID) % GRID) / (GRID - 1);
    x[i * DIM + 2] = -5 + 10.0 * (double)(i / (GRID * GRID)) / (GRID - 1);
  }
  return x;
}

/* The fused evaluation's flops per point (the formula above); n the mean support. */
static double fused_flops(int m, double n, int hess) {
  const int d = DIM, h = hess ? NH : 0, r = 1 + d + h;
  return n * m * (m + 1) + n * m + m * m * m / 3.0 + 10.0 * m * m + 2.0 * r * m * m + 2.0 * n * m * r +
         2.0 * n * m * (d + h) + n * (1 + 4 * d + 12 * h);
}

static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* DGEMM rate (GFLOP/s) of (a × k)·(k × b), CPU time, best of 3 runs of ≥ 0.05 s. */
static double dgemm_rate(int a, int k, int b) {
  double *A = malloc(sizeof(double) * (size_t)(a * k)), *B = malloc(sizeof(double) * (size_t)(k * b));
  double *C = malloc(sizeof(double) * (size_t)(a * b));
  for (long i = 0; i < (long)a * k; i++) A[i] = 1.0 / (double)(i + 1);
  for (long i = 0; i < (long)k * b; i++) B[i] = 1.0 / (double)(i + 2);
  long reps = 1;
  for (;;) {
    const double t0 = cpu_now();
    for (long r = 0; r < reps; r++)
      cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, a, b, k, 1.0, A, k, B, b, 0.0, C, b);
    if (cpu_now() - t0 > 0.05) break;
    reps *= 2;
  }
  double best = INFINITY;
  for (int t = 0; t < 3; t++) {
    const double t0 = cpu_now();
    for (long r = 0; r < reps; r++)
      cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, a, b, k, 1.0, A, k, B, b, 0.0, C, b);
    best = fmin(best, (cpu_now() - t0) / (double)reps);
  }
  free(A), free(B), free(C);
  return 2.0 * a * k * b / best * 1e-9;
}

static int run_case(const Case *c, const double *x, long n, const double *points, long npoints) {
  MlsOptions opt;
  mls_options_default(&opt);
  opt.order = c->order;
  opt.support = c->support;
  opt.dilation = c->dilation;
  MlsApprox *mls;
  MlsShape *sh;
  MICA_CALL(mls_create(DIM, n, x, &opt, &mls));
  MICA_CALL(mls_shape_create(mls, &sh));
  Reference ref = {mls, &opt, NULL, NULL, 0, 0, NULL, NULL, NULL, NULL, NULL, NULL};
  MICA_CALL(mls_search_create(DIM, n, x, MLS_SEARCH_KDTREE, &ref.search));
  MICA_CALL(mls_search_set_supports(ref.search, opt.support, mls_radii(mls)));
  const int m = mls_num_terms(mls);
  ref.P = malloc(sizeof(double) * (size_t)(n * m));
  ref.w = malloc(sizeof(double) * (size_t)n);
  ref.dw = malloc(sizeof(double) * (size_t)(n * DIM));
  ref.ddw = malloc(sizeof(double) * (size_t)(n * NH));
  double *N = malloc(sizeof(double) * (size_t)n), *dN = malloc(sizeof(double) * (size_t)(n * DIM));
  double *ddN = malloc(sizeof(double) * (size_t)(n * NH));
  const int nderiv = c->hess ? MLS_HESSIAN : MLS_GRADIENT;
  /* agreement of the two implementations, relative to the largest entry */
  double diff = 0, scale = 0;
  long support_sum = 0;
  for (long p = 0; p < npoints; p += 97) {
    MICA_CALL(mls_eval(mls, points + p * DIM, nderiv, sh));
    MICA_CALL(ref_eval(&ref, points + p * DIM, c->hess, N, dN, ddN));
    for (long k = 0; k < sh->n; k++) {
      diff = fmax(diff, fabs(N[k] - sh->N[k]));
      scale = fmax(scale, fabs(sh->N[k]));
      for (int d = 0; d < DIM; d++) diff = fmax(diff, fabs(dN[d * sh->n + k] - sh->dN[d * sh->n + k]) * 0.1);
    }
  }
  double best_fused = INFINITY, best_ref = INFINITY;
  for (int rep = 0; rep < 3; rep++) {
    double t0 = cpu_now();
    for (long p = 0; p < npoints; p++) {
      MICA_CALL(mls_eval(mls, points + p * DIM, nderiv, sh));
      support_sum += sh->n;
    }
    best_fused = fmin(best_fused, cpu_now() - t0);
    t0 = cpu_now();
    for (long p = 0; p < npoints / 4; p++) MICA_CALL(ref_eval(&ref, points + p * DIM, c->hess, N, dN, ddN));
    best_ref = fmin(best_ref, (cpu_now() - t0) * 4);
  }
  const double rate = (double)npoints / best_fused, ref_rate = (double)npoints / best_ref;
  const double support = (double)support_sum / (3.0 * (double)npoints), flops = fused_flops(m, support, c->hess);
  printf("pascal %d  %-4s dilation %.0f  %-9s  support %5.1f  fused %9.0f /s  reference %9.0f /s  ratio %5.2f"
         "  max diff %.1e  flops/pt %6.0f  %5.2f GF/s  dgemm(%dx%.0fx%d) %5.2f GF/s\n",
         c->order, c->support == MLS_SUPPORT_BOX ? "box" : "ball", c->dilation, c->hess ? "+hessian" : "gradient",
         support, rate, ref_rate, rate / ref_rate, diff / scale, flops, flops * rate * 1e-9, m, support, m,
         dgemm_rate(m, (int)lround(support), m));
  free(N), free(dN), free(ddN), free(ref.P), free(ref.w), free(ref.dw), free(ref.ddw), free(ref.index);
  mls_search_destroy(&ref.search);
  mls_shape_destroy(&sh);
  mls_destroy(&mls);
  return MICA_SUCCESS;
}

int main(int argc, char **argv) {
  long npoints = argc > 1 ? atol(argv[1]) : 20000, n;
  double *x = grid_particles(&n), *points = malloc(sizeof(double) * (size_t)(npoints * DIM));
  MicaRandom rng = mica_random_seed(42);
  for (long p = 0; p < npoints * DIM; p++) points[p] = -4.5 + 9 * mica_random_uniform(&rng);
  printf("MLS shape functions in 3-D: %ld particles (21^3, spacing 0.5), %ld random points, best of 3 (CPU time)\n", n,
         npoints);
  printf("fused: mica (Cholesky of M once, derivative RHS as vectors); reference: explicit M^-1, M,i, M,ij\n");
  printf("flops/pt: the fused method's (bench/bench_mls.c header); GF/s = flops/pt x fused rate; dgemm at the\n"
         "moment matrix's shape (m x n x m), one core. DGEMM 500 x 500 x 500 on this core: %.2f GF/s\n",
         dgemm_rate(500, 500, 500));
  const int orders[] = {1, 2};
  const MlsSupportKind supports[] = {MLS_SUPPORT_BOX, MLS_SUPPORT_BALL};
  const double dilations[] = {2, 3};
  for (int o = 0; o < 2; o++)
    for (int s = 0; s < 2; s++)
      for (int d = 0; d < 2; d++)
        for (int h = 0; h < 2; h++) {
          Case c = {orders[o], h, supports[s], dilations[d]};
          if (run_case(&c, x, n, points, npoints)) {
            fprintf(stderr, "bench_mls: %s\n", mica_error_message());
            return 1;
          }
        }
  free(x);
  free(points);
  return 0;
}
