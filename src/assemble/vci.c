/* Variationally consistent integration, VCI (docs/theory.md §VCI; Chen, Hillman & Rüter 2013, IJNME 95):
 * the test-function gradients at the volume quadrature points are corrected,
 *   ∇̃_d N_I(x) = ∇_d N_I(x) + Σ_β ξ_Iβd q_β(x),
 * with q_β the monomials of degree ≤ n − 1, so that each particle satisfies the discrete divergence
 * identity for every such monomial p_α:
 *   Σ_vol w (∇̃_d N_I p_α + N_I ∂_d p_α) = Σ_∂Ω w N_I p_α n_d.
 * Per particle this is one small SPD system A_I ξ_Id = r_Id for every direction d, with the Gram matrix
 * A_αβ = Σ_vol w q_α q_β over the volume points in the particle's support, factored once (Cholesky,
 * LAPACK) for all d. The monomials are taken in the particle's local coordinates s = (x − x_I)/ρ_I (its
 * support radii), which span the same space and keep A well conditioned. */
#include <lapacke.h> /* it includes complex.h, whose macro I rules out that name: particles are `part` */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mica/parallel.h"
#include "mica/solid.h"
#include "mica/sparse.h"

enum { VCI_MAX_TERMS = 10 }; /* monomials of degree ≤ 2 in 3-D (basis order 3) */

/* The monomials of total degree ≤ degree in dim variables, by their exponents. */
typedef struct {
  int dim, m;
  int exponent[VCI_MAX_TERMS][3];
} Monomials;

static int monomials_init(int dim, int degree, Monomials *b) {
  b->dim = dim, b->m = 0;
  for (int total = 0; total <= degree; total++)
    for (int i = total; i >= 0; i--)
      for (int j = total - i; j >= 0; j--) {
        const int k = total - i - j;
        if (dim == 2 && k > 0) continue;
        MICA_CHECK(b->m < VCI_MAX_TERMS, MICA_ERR_ARGUMENT, "VCI: degree %d in %d-D has too many monomials", degree,
                   dim);
        b->exponent[b->m][0] = i, b->exponent[b->m][1] = j, b->exponent[b->m][2] = k;
        b->m++;
      }
  return MICA_SUCCESS;
}

static double power(double x, int e) {
  double r = 1.0;
  while (e-- > 0) r *= x;
  return r;
}

/* q[a] = q_a(s) and, if dq, dq[d*m + a] = ∂q_a/∂s_d. */
static void monomials_eval(const Monomials *b, const double *s, double *q, double *dq) {
  for (int a = 0; a < b->m; a++) {
    const int *e = b->exponent[a];
    double f[3] = {1.0, 1.0, 1.0};
    for (int d = 0; d < b->dim; d++) f[d] = power(s[d], e[d]);
    q[a] = f[0] * f[1] * f[2];
    if (!dq) continue;
    for (int d = 0; d < b->dim; d++) {
      double g = e[d] ? e[d] * power(s[d], e[d] - 1) : 0.0;
      for (int k = 0; k < b->dim; k++)
        if (k != d) g *= f[k];
      dq[d * b->m + a] = g;
    }
  }
}

/* ∂²q_a/∂s_d∂s_f at s. */
static double monomial_second(const Monomials *b, const double *s, int a, int d, int f) {
  const int *e = b->exponent[a];
  int k_d = e[d], k_f = e[f];
  double c = 1.0;
  if (d == f) {
    if (k_d < 2) return 0.0;
    c = k_d * (k_d - 1), k_d -= 2;
  } else {
    if (!k_d || !k_f) return 0.0;
    c = k_d * k_f, k_d--, k_f--;
  }
  for (int k = 0; k < b->dim; k++) c *= power(s[k], k == d ? k_d : k == f ? k_f : e[k]);
  return c;
}

/* Particle I's local coordinates of x. */
static void local_coordinates(const MlsApprox *mls, long part, const double *x, double *s) {
  const int dim = mls_dim(mls);
  const double *xI = mls_particles(mls) + part * dim, *rho = mls_radii(mls) + part * dim;
  for (int d = 0; d < dim; d++) s[d] = (x[d] - xI[d]) / rho[d];
}

/* Per particle: the Gram matrix A (m × m), the right-hand sides r (m × dim, column d for direction d,
 * overwritten by ξ) and the number of volume points in the support. */
typedef struct {
  Monomials basis;
  double *A, *r;
  double *npoints; /* a count, as a double so that distributed data sums it with the others */
} Systems;

/* A_I += w q qᵀ and r_Id −= w (∂_d N_I q + N_I ∂_d q) at every volume point, for every supporting I. */
static void add_volume(const MicaDiscretization *disc, const MlsApprox *mls, const MicaShapeCache *c, Systems *sys) {
  const int dim = c->dim, m = sys->basis.m;
  const double *radii = mls_radii(mls);
  double s[3], q[VCI_MAX_TERMS], dq[3 * VCI_MAX_TERMS];
  for (long p = 0; p < c->npoints; p++) {
    const double w = disc->qw[p];
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
      const long part = c->index[e];
      double *A = sys->A + part * m * m, *r = sys->r + part * m * dim;
      local_coordinates(mls, part, disc->qx + p * dim, s);
      monomials_eval(&sys->basis, s, q, dq);
      for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++) A[a * m + b] += w * q[a] * q[b];
      for (int d = 0; d < dim; d++)
        for (int a = 0; a < m; a++)
          r[d * m + a] -= w * (c->dN[e * dim + d] * q[a] + c->N[e] * dq[d * m + a] / radii[part * dim + d]);
      sys->npoints[part]++;
    }
  }
}

/* NSNI's stabilization points (nsni.c) enter the Galerkin residual of test function I with the derivative of
 * the stress along their direction g: for σ_·d = q_α that term is w ∂_g∇_d N_I ∂_g q_α, and the body load's
 * expansion (assemble.c, add_body_derivative) w ∂_g N_I ∂_g b with b = −div σ, −w ∂_g N_I ∂_g ∂_d q_α: the
 * constraint must hold both (docs/theory.md §NSNI, "consistency"): r_Id −= w [(H_I g)_d ∂_g q_α + ∂_g N_I
 * ∂_g ∂_d q_α]. The second vanishes for monomials of degree ≤ 1 (a linear basis). No Gram term: the correction
 * lives at the volume points only. */
static void add_stabilization(const MlsApprox *mls, const MicaNsni *nsni, Systems *sys) {
  const MicaShapeCache *c = nsni->cache;
  const int dim = c->dim, m = sys->basis.m;
  const double *radii = mls_radii(mls);
  double s[3], q[VCI_MAX_TERMS], dq[3 * VCI_MAX_TERMS];
  for (long p = 0; p < c->npoints; p++) {
    const double w = nsni->w[p], *g = nsni->dir + p * dim;
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
      const long part = c->index[e];
      double *r = sys->r + part * m * dim, dgq[VCI_MAX_TERMS];
      local_coordinates(mls, part, c->x + p * dim, s);
      monomials_eval(&sys->basis, s, q, dq);
      for (int a = 0; a < m; a++) {
        dgq[a] = 0.0;
        for (int f = 0; f < dim; f++) dgq[a] += g[f] * dq[f * m + a] / radii[part * dim + f];
      }
      for (int d = 0; d < dim; d++)
        for (int a = 0; a < m; a++) {
          double dgdq = 0.0; /* ∂_g ∂_d q_a */
          for (int f = 0; f < dim; f++)
            dgdq += g[f] * monomial_second(&sys->basis, s, a, d, f) / (radii[part * dim + f] * radii[part * dim + d]);
          r[d * m + a] -= w * (c->dN[e * dim + d] * dgq[a] + c->N[e] * dgdq);
        }
    }
  }
}

/* r_Id += w N_I q n_d at every point of every boundary set (together: the whole boundary, once). */
static int add_boundary(const MicaDiscretization *disc, const MlsApprox *mls, Systems *sys) {
  const int dim = disc->dim, m = sys->basis.m;
  MlsShape *sh = NULL;
  int ierr = MICA_SUCCESS;
  double s[3], q[VCI_MAX_TERMS];
  MICA_CALL(mls_shape_create(mls, &sh));
  for (int k = 0; k < disc->nsets; k++) {
    const MicaBoundarySet *set = &disc->sets[k];
    for (long p = 0; p < set->n; p++) {
      ierr = mls_eval(mls, set->x + p * dim, MLS_VALUES, sh);
      if (ierr) {
        mica_error_prefix("VCI: boundary set '%s' point %ld of %ld", set->name, p + 1, set->n);
        goto cleanup;
      }
      for (long j = 0; j < sh->n; j++) {
        const long part = sh->index[j];
        double *r = sys->r + part * m * dim;
        local_coordinates(mls, part, set->x + p * dim, s);
        monomials_eval(&sys->basis, s, q, NULL);
        for (int d = 0; d < dim; d++)
          for (int a = 0; a < m; a++) r[d * m + a] += set->w[p] * sh->N[j] * q[a] * set->normal[p * dim + d];
      }
    }
  }
cleanup:
  mls_shape_destroy(&sh);
  return ierr;
}

/* ξ_I = A_I⁻¹ r_I by Cholesky, for every direction at once. A particle with no volume point in its support
 * has no volume term to correct (ξ = 0). */
static int solve_particle(const MlsApprox *mls, long part, Systems *sys) {
  const int dim = mls_dim(mls), m = sys->basis.m;
  double *A = sys->A + part * m * m, *r = sys->r + part * m * dim;
  if (sys->npoints[part] == 0) {
    memset(r, 0, sizeof(double) * (size_t)(m * dim));
    return MICA_SUCCESS;
  }
  lapack_int info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', m, A, m);
  if (info == 0) info = LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', m, dim, A, m, r, m);
  if (info != 0) {
    const double *x = mls_particles(mls) + part * dim;
    MICA_ERROR(MICA_ERR_NUMERIC,
               "VCI: particle %ld at (%g, %g, %g) has %ld volume quadrature points in its support, which do not "
               "determine its %d correction terms (LAPACK info %d); raise quadrature.order or mls.dilation",
               part + 1, x[0], x[1], dim == 3 ? x[2] : 0.0, (long)sys->npoints[part], m, (int)info);
  }
  return MICA_SUCCESS;
}

/* dN_test = dN + Σ_β ξ_Iβd q_β at every volume point. */
static void correct_gradients(const MicaDiscretization *disc, const MlsApprox *mls, const Systems *sys,
                              MicaShapeCache *c) {
  const int dim = c->dim, m = sys->basis.m;
  double s[3], q[VCI_MAX_TERMS];
  for (long p = 0; p < c->npoints; p++)
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
      const long part = c->index[e];
      const double *xi = sys->r + part * m * dim;
      local_coordinates(mls, part, disc->qx + p * dim, s);
      monomials_eval(&sys->basis, s, q, NULL);
      for (int d = 0; d < dim; d++) {
        double sum = 0.0;
        for (int a = 0; a < m; a++) sum += xi[d * m + a] * q[a];
        c->dN_test[e * dim + d] = c->dN[e * dim + d] + sum;
      }
    }
}

/* ---- NSNI with a linear basis: one correction for trial and test gradients (docs/theory.md §NSNI, "symmetric
 * VCI") ----
 * The Petrov–Galerkin correction above makes the test gradients satisfy the integration constraint and leaves
 * the trial gradients uncorrected; at one point per cell these violate the constraint by O(1) on jittered
 * cells, so the adjoint discretization is inconsistent and the L2 error loses its extra order. Here one
 * correction δ (∇̃N_J = ∇N_J + δ_J at every volume point) satisfies, for every direction d,
 *   (a) the integration constraint of every particle J:  Σ_p w_p q_α(x_p) δ_pJ = r_Jα   (α: degree ≤ 1),
 *   (b) reproduction at every point p:                    Σ_J δ_pJ P_γ(x_J) = 0      (γ: degree ≤ 1),
 * so the corrected gradients still reproduce linear fields and serve both slots (K symmetric). The
 * W-minimum-norm δ subject to (a) and (b) is δ = Π⊥ Q λ, Π⊥ the Euclidean projection per point onto (b), Q λ
 * the VCI form Σ_α λ_Jα q_α; λ solves S λ = r with S = Qᵀ W Π⊥ Q (sparse, symmetric, one clique per point). S
 * is singular: the combinations Σ_J P_γ(x_J) (a)_J are implied by (b), and r satisfies them because the one-point
 * rule at the centroid integrates the linear integrands ∂_d(P_γ q_α) exactly and the quadratic fit's Hessians
 * vanish on linear P_γ; δ does not depend on the null-space part of λ, which ε A (A: the VCI Gram blocks, ε =
 * 1e-10) fixes, and iterative refinement against S itself removes the regularization's bias. A quadratic basis
 * would need (a), (b) of degree 2, whose compatibility needs cubic integrands integrated exactly, which one point
 * and the second moments do not: it keeps the Petrov–Galerkin correction. */
typedef struct {
  const MicaShapeCache *c;
  const double *qw;
  int dim, m, mr;
  long np;
  double *Q;     /* [nnz*m] q_α at each entry, in the particle's local coordinates */
  double *P;     /* [nnz*mr] P_γ(x_J) about the point, in the point's first particle's radii */
  double *G;     /* [npoints*mr*mr] Cholesky factors of Σ_J P Pᵀ per point */
  double *delta; /* [nnz*dim] Π⊥ Q λ */
} Symmetric;

/* The row constraint (b) at point p: δ_p·d −= P G⁻¹ Pᵀ δ_p·d for every direction. */
static void project_point(const Symmetric *o, long p, double *delta) {
  const MicaShapeCache *c = o->c;
  const int dim = o->dim, mr = o->mr;
  double b[VCI_MAX_TERMS * 3] = {0};
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
    for (int d = 0; d < dim; d++)
      for (int g = 0; g < mr; g++) b[d * mr + g] += o->P[e * mr + g] * delta[e * dim + d];
  LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', mr, dim, o->G + p * mr * mr, mr, b, mr);
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
    for (int d = 0; d < dim; d++)
      for (int g = 0; g < mr; g++) delta[e * dim + d] -= b[d * mr + g] * o->P[e * mr + g];
}

/* y = S λ (λ, y: [np][dim][m]), leaving δ = Π⊥ Q λ in o->delta. */
static void symmetric_apply(Symmetric *o, const double *lam, double *y) {
  const MicaShapeCache *c = o->c;
  const int dim = o->dim, m = o->m;
  for (long p = 0; p < c->npoints; p++) {
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
      for (int d = 0; d < dim; d++) {
        double v = 0;
        for (int a = 0; a < m; a++) v += lam[(c->index[e] * dim + d) * m + a] * o->Q[e * m + a];
        o->delta[e * dim + d] = v;
      }
    project_point(o, p, o->delta);
  }
  memset(y, 0, sizeof(double) * (size_t)(o->np * m * dim));
  for (long p = 0; p < c->npoints; p++)
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
      for (int d = 0; d < dim; d++)
        for (int a = 0; a < m; a++)
          y[(c->index[e] * dim + d) * m + a] += o->qw[p] * o->Q[e * m + a] * o->delta[e * dim + d];
}

static int symmetric_setup(const MicaDiscretization *disc, const MlsApprox *mls, const Systems *sys, Symmetric *o) {
  const MicaShapeCache *c = o->c;
  const int dim = o->dim, m = o->m, mr = o->mr;
  const long nnz = c->ptr[c->npoints];
  const double *xp = mls_particles(mls), *radii = mls_radii(mls);
  Monomials rep;
  MICA_CALL(monomials_init(dim, 1, &rep));
  MICA_CALL(MICA_MALLOC(o->Q, nnz * m));
  MICA_CALL(MICA_MALLOC(o->P, nnz * mr));
  MICA_CALL(MICA_CALLOC(o->G, c->npoints * mr * mr));
  MICA_CALL(MICA_MALLOC(o->delta, nnz * dim));
  double s[3];
  for (long p = 0; p < c->npoints; p++) {
    const double *rho = radii + c->index[c->ptr[p]] * dim;
    double *G = o->G + p * mr * mr;
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
      const long part = c->index[e];
      local_coordinates(mls, part, disc->qx + p * dim, s);
      monomials_eval(&sys->basis, s, o->Q + e * m, NULL);
      for (int d = 0; d < dim; d++) s[d] = (xp[part * dim + d] - disc->qx[p * dim + d]) / rho[d];
      monomials_eval(&rep, s, o->P + e * mr, NULL);
      for (int a = 0; a < mr; a++)
        for (int b = 0; b < mr; b++) G[a * mr + b] += o->P[e * mr + a] * o->P[e * mr + b];
    }
    if (LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', mr, G, mr) != 0) {
      const double *x = disc->qx + p * dim;
      MICA_ERROR(MICA_ERR_NUMERIC,
                 "VCI (NSNI, symmetric): the %ld particles supporting the volume point at (%g, %g, %g) do not determine "
                 "a linear field; raise mls.dilation", c->ptr[p + 1] - c->ptr[p], x[0], x[1], dim == 3 ? x[2] : 0.0);
    }
  }
  return MICA_SUCCESS;
}

/* S + ε A assembled on the volume points' cliques (m unknowns per particle; S does not couple directions); with
 * distributed data (nowned < np) the rank's points' part, and ε A at its owned particles only, whose A the owners
 * hold summed (the distributed solver adds the ranks' parts). */
static int symmetric_matrix(const Symmetric *o, const Systems *sys, double eps, long nowned, MicaSparse **out) {
  const MicaShapeCache *c = o->c;
  const int m = o->m, mr = o->mr;
  MicaSparse *S = NULL;
  double *Ke = NULL, *Pi = NULL, *Y = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(mica_sparse_create(o->np, m, c->npoints, c->ptr, c->index, &S));
  long maxn = 0;
  for (long p = 0; p < c->npoints; p++) maxn = c->ptr[p + 1] - c->ptr[p] > maxn ? c->ptr[p + 1] - c->ptr[p] : maxn;
  MICA_CALL_CLEANUP(MICA_MALLOC(Ke, maxn * m * maxn * m + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(Pi, maxn * maxn + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(Y, maxn * mr + 1));
  for (long p = 0; p < c->npoints && !ierr; p++) {
    const long n = c->ptr[p + 1] - c->ptr[p], e0 = c->ptr[p];
    /* Π⊥ = I − P G⁻¹ Pᵀ; Y = G⁻¹ Pᵀ (mr × n, column b at Y + b·mr: the layout of P's rows) */
    memcpy(Y, o->P + e0 * mr, sizeof(double) * (size_t)(n * mr));
    LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', mr, (lapack_int)n, o->G + p * mr * mr, mr, Y, mr);
    for (long b = 0; b < n; b++)
      for (long a = 0; a < n; a++) {
        double v = a == b ? 1.0 : 0.0;
        for (int g = 0; g < mr; g++) v -= o->P[(e0 + a) * mr + g] * Y[b * mr + g];
        Pi[a * n + b] = v;
      }
    for (long a = 0; a < n; a++)
      for (int al = 0; al < m; al++)
        for (long b = 0; b < n; b++)
          for (int be = 0; be < m; be++)
            Ke[(a * m + al) * (n * m) + b * m + be] =
                o->qw[p] * o->Q[(e0 + a) * m + al] * Pi[a * n + b] * o->Q[(e0 + b) * m + be];
    ierr = mica_sparse_add_clique(S, n, c->index + e0, Ke);
  }
  for (long part = 0; part < nowned && !ierr; part++)
    for (int a = 0; a < m; a++)
      for (int b = 0; b < m; b++) {
        const double v = eps * sys->A[part * m * m + a * m + b];
        for (long t = S->colptr[part * m + b]; t < S->colptr[part * m + b + 1]; t++)
          if (S->rowind[t] == part * m + a) S->val[t] += v;
      }
cleanup:
  MICA_FREE(Ke);
  MICA_FREE(Pi);
  MICA_FREE(Y);
  if (ierr) mica_sparse_destroy(&S);
  *out = S;
  return ierr;
}

/* S's solver: CHOLMOD on the whole; with distributed data PETSc's MUMPS (Cholesky) over the ranks, whatever
 * solver.petsc the tangent takes (S + ε A is too ill-conditioned for an iterative method). */
static int symmetric_solver(MicaDistribution *dist, MicaLinearSolver **solver) {
  if (!dist) return mica_linear_solver_create(&mica_linear_cholmod, solver);
  MICA_CALL(mica_parallel_linear_create(dist, &mica_linear_petsc, solver));
  MicaKrylovOptions k = {.rtol = 1e-12, .max_iterations = 1, .spd = 1};
  snprintf(k.petsc_preset, sizeof k.petsc_preset, "mumps");
  return mica_linear_solver_set_krylov(*solver, &k);
}

/* The largest |v_i| over the particles this rank solves for (all, or the owned ones), over the ranks. */
static int owned_max(MicaDistribution *dist, const double *v, long nrows, double *out) {
  double mx = 0;
  for (long i = 0; i < nrows; i++) mx = fmax(mx, fabs(v[i]));
  if (dist) MICA_CALL(mica_parallel_max(MICA_SUCCESS, &mx, 1));
  *out = mx;
  return MICA_SUCCESS;
}

/* δ from sys->r (the constraint's right-hand sides, [np][dim][m]) into c->dN; c->dN_test freed (none: symmetric).
 * With distributed data (dist) sys holds the owners' sums (owned_sums): S λ's rows are summed at the owners
 * (mica_ghost_reduce), the violation is the largest over the ranks, and the solver returns λ at the ghosts too, so
 * every rank's points get the δ of the whole. */
static int symmetric_correct(const MicaDiscretization *disc, const MlsApprox *mls, MicaShapeCache *c, Systems *sys,
                             MicaDistribution *dist) {
  const int dim = c->dim, m = sys->basis.m;
  const long np = mls_num_particles(mls), n = np * m * dim, nnz = c->ptr[c->npoints];
  const long nowned = dist ? dist->nowned : np, nrows = nowned * m * dim;
  Symmetric o = {c, disc->qw, dim, m, dim + 1, np, NULL, NULL, NULL, NULL};
  MicaSparse *S = NULL;
  MicaLinearSolver *solver = NULL;
  double *lam = NULL, *res = NULL, *rhs = NULL, *x = NULL;
  int ierr = MICA_SUCCESS;
  for (long part = 0; part < nowned; part++) /* a particle with no volume point has no constraint */
    if (sys->npoints[part] == 0)
      for (int a = 0; a < m; a++) sys->A[part * m * m + a * m + a] = 1.0;
  ierr = symmetric_setup(disc, mls, sys, &o);
  if (!ierr) ierr = symmetric_matrix(&o, sys, 1e-10, nowned, &S);
  if (dist) MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(ierr);
  MICA_CALL_CLEANUP(symmetric_solver(dist, &solver));
  MICA_CALL_CLEANUP(mica_linear_solver_factor(solver, S));
  ierr = MICA_CALLOC(lam, n + 1);
  if (!ierr) ierr = MICA_MALLOC(res, n + 1);
  if (!ierr) ierr = MICA_MALLOC(rhs, np * m + 1);
  if (!ierr) ierr = MICA_MALLOC(x, np * m + 1);
  if (dist) MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(ierr);
  double scale = 0, viol = 0, previous = INFINITY;
  MICA_CALL_CLEANUP(owned_max(dist, sys->r, nrows, &scale));
  memcpy(res, sys->r, sizeof(double) * (size_t)n);
  /* λ += (S + ε A)⁻¹ (r − S λ), until the constraints hold or the violation stops falling: where r is not in
   * S's range (a regular grid, 0.34 relative at 81² after every sweep) the first sweeps already show it. */
  for (int sweep = 0; sweep < 6; sweep++) {
    for (int d = 0; d < dim; d++) {
      for (long part = 0; part < np; part++)
        for (int a = 0; a < m; a++) rhs[part * m + a] = res[(part * dim + d) * m + a];
      MICA_CALL_CLEANUP(mica_linear_solver_solve(solver, rhs, x));
      for (long part = 0; part < np; part++)
        for (int a = 0; a < m; a++) lam[(part * dim + d) * m + a] += x[part * m + a];
    }
    symmetric_apply(&o, lam, res);
    if (dist) MICA_CALL_CLEANUP(mica_ghost_reduce(dist, MICA_SUCCESS, res, m * dim)); /* S λ at the owners */
    for (long i = 0; i < nrows; i++) res[i] = sys->r[i] - res[i];
    MICA_CALL_CLEANUP(owned_max(dist, res, nrows, &viol));
    if (viol <= 1e-14 * fmax(scale, 1e-300) || viol > 0.5 * previous) break;
    previous = viol;
  }
  if (viol > 1e-10 * fmax(scale, 1e-300)) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_NUMERIC,
                          "VCI (NSNI, symmetric): the integration constraints hold only to %.3g relative", viol / scale);
    goto cleanup;
  }
  for (long i = 0; i < nnz * dim; i++) c->dN[i] += o.delta[i];
  MICA_FREE(c->dN_test);
cleanup:
  mica_linear_solver_destroy(&solver);
  mica_sparse_destroy(&S);
  MICA_FREE(lam);
  MICA_FREE(res);
  MICA_FREE(rhs);
  MICA_FREE(x);
  MICA_FREE(o.Q);
  MICA_FREE(o.P);
  MICA_FREE(o.G);
  MICA_FREE(o.delta);
  return ierr;
}

/* parallel.data = "distributed": a particle's sums span the ranks whose points its support reaches; they are added
 * at its owner, which solves, and its ξ is copied into its ghosts. */
static int owned_sums(MicaDistribution *dist, int ierr, Systems *sys, int dim) {
  const int m = sys->basis.m;
  MICA_CALL(mica_ghost_reduce(dist, ierr, sys->A, m * m));
  MICA_CALL(mica_ghost_reduce(dist, MICA_SUCCESS, sys->r, m * dim));
  return mica_ghost_reduce(dist, MICA_SUCCESS, sys->npoints, 1);
}

/* nsni: NSNI's stabilization points in the constraint (NULL: none); dist: distributed data (NULL: the whole). */
static int vci_correct(const MicaDiscretization *disc, const MlsApprox *mls, int n, MicaShapeCache *volume,
                       const MicaNsni *nsni, int symmetric, MicaDistribution *dist) {
  MICA_CHECK(volume->npoints == disc->nquad && volume->dim == disc->dim, MICA_ERR_ARGUMENT,
             "mica_vci_correct: the cache is not at the discretization's volume points");
  MICA_CHECK(disc->boundary_uncovered == 0, MICA_ERR_INPUT,
             "VCI needs boundary sets that cover the whole boundary once; %ld boundary faces are in no set or in "
             "several", disc->boundary_uncovered);
  const int dim = disc->dim;
  const long np = mls_num_particles(mls), nnz = volume->ptr[volume->npoints];
  Systems sys = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL(monomials_init(dim, (n > 1 ? n : 1) - 1, &sys.basis));
  const int m = sys.basis.m;
  ierr = MICA_CALLOC(sys.A, np * m * m);
  if (!ierr) ierr = MICA_CALLOC(sys.r, np * m * dim);
  if (!ierr) ierr = MICA_CALLOC(sys.npoints, np);
  if (!ierr) add_volume(disc, mls, volume, &sys);
  if (!ierr && nsni) add_stabilization(mls, nsni, &sys);
  if (!ierr) ierr = add_boundary(disc, mls, &sys);
  if (dist) MICA_CALL_CLEANUP(owned_sums(dist, ierr, &sys, dim));
  MICA_CALL_CLEANUP(ierr);
  if (symmetric) {
    ierr = symmetric_correct(disc, mls, volume, &sys, dist);
    goto cleanup;
  }
  const long nsolve = dist ? dist->nowned : np; /* distributed: at the owned particles */
  for (long part = 0; part < nsolve && !ierr; part++) ierr = solve_particle(mls, part, &sys);
  if (dist) MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(ierr);
  if (dist) MICA_CALL_CLEANUP(mica_ghost_update(dist, sys.r, m * dim)); /* ξ at the ghosts */
  MICA_FREE(volume->dN_test);
  MICA_CALL_CLEANUP(MICA_MALLOC(volume->dN_test, nnz * dim));
  correct_gradients(disc, mls, &sys, volume);
cleanup:
  MICA_FREE(sys.A);
  MICA_FREE(sys.r);
  MICA_FREE(sys.npoints);
  return ierr;
}

int mica_vci_correct(const MicaDiscretization *disc, const MlsApprox *mls, int n, MicaShapeCache *volume) {
  return vci_correct(disc, mls, n, volume, NULL, 0, NULL);
}

int mica_vci_correct_stabilized(const MicaDiscretization *disc, const MlsApprox *mls, int n, MicaShapeCache *volume,
                                const MicaNsni *nsni) {
  return vci_correct(disc, mls, n, volume, nsni, 0, NULL);
}

int mica_vci_correct_owned(const MicaDiscretization *disc, const MlsApprox *mls, int n, MicaShapeCache *volume,
                           const MicaNsni *nsni, MicaDistribution *dist) {
  return vci_correct(disc, mls, n, volume, nsni, 0, dist);
}

int mica_vci_correct_symmetric(const MicaDiscretization *disc, const MlsApprox *mls, MicaShapeCache *volume,
                               const MicaNsni *nsni, MicaDistribution *dist) {
  return vci_correct(disc, mls, 2, volume, nsni, 1, dist);
}
