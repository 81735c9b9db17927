/* The numerical inf-sup test of `mica stability` (Chapelle & Bathe 1993; seed 000 §7.2.5; docs/theory.md
 * §stability).
 *
 * For each particle count N of stability.inf_sup_counts the deck is loaded again with particles.count scaled
 * to N along the first axis, and its discretization (particles, MLS, quadrature points and weights, the
 * solid's volume cache — whatever the deck's quadrature is) gives, for the displacement space U_h = (span of
 * the MLS shape functions)^dim with u_h = 0 collocated at the boundary vertices,
 *   G = Σ_q w_q (div N)ᵀ(div N)      (‖div u_h‖² over the quadrature: the pressure space of a pure
 *                                      displacement formulation is the space of its divergences)
 *   S = Σ_q w_q ∇N : ∇N              (the H1 seminorm, a norm on U_h with u_h = 0 on the boundary)
 * and β_h = sqrt(λ_k), λ_k the smallest nonzero eigenvalue of G v = λ S v. The boundary collocation is
 * built into the basis: Z spans the null space of C (C_vJ = N_J(x_v) at the boundary vertices), from a QR
 * factorization of Cᵀ, and the reduced pencil is (Zᵀ G Z, Zᵀ S Z).
 */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/eigen.h"
#include "mica/timer.h"
#include "stability.h"

typedef int fint;
extern void dgemm_(const char *transa, const char *transb, const fint *m, const fint *n, const fint *k,
                   const double *alpha, const double *a, const fint *lda, const double *b, const fint *ldb,
                   const double *beta, double *c, const fint *ldc, size_t ltransa, size_t ltransb);

/* ---- the refined deck ------------------------------------------------------------------------------------ */

static int refined_deck(const MicaDeck *deck, long N, long *count, MicaDeck **out) {
  char where[256], text[2][256];
  const char *shape;
  MICA_CALL(mica_deck_string(deck, "geometry.shape", &shape));
  mica_deck_where(deck, "stability.inf_sup", where, sizeof where);
  MICA_CHECK(strcmp(shape, "gmsh") && mica_deck_has(deck, "particles.count"), MICA_ERR_INPUT,
             "%s: the inf-sup test refines particles.count, and a Gmsh mesh has none: set stability.inf_sup = false",
             where);
  long base[3], cells[3];
  int n, nc = 0;
  MICA_CALL(mica_deck_ints(deck, "particles.count", base, 3, &n));
  count[0] = N;
  int len = snprintf(text[0], sizeof text[0], "particles.count=[%ld", N);
  for (int d = 1; d < n; d++) {
    const long c = lround((double)(N - 1) * (double)(base[d] - 1) / (double)(base[0] - 1)) + 1;
    count[d] = c < 2 ? 2 : c;
    len += snprintf(text[0] + len, sizeof text[0] - (size_t)len, ", %ld", count[d]);
  }
  snprintf(text[0] + len, sizeof text[0] - (size_t)len, "]");
  if (mica_deck_has(deck, "quadrature.cells")) { /* the deck's cells per particle spacing, kept */
    MICA_CALL(mica_deck_ints(deck, "quadrature.cells", cells, 3, &nc));
    len = snprintf(text[1], sizeof text[1], "quadrature.cells=[");
    for (int d = 0; d < nc; d++) {
      const long c = lround((double)cells[d] * (double)(count[d] - 1) / (double)(base[d] - 1));
      len += snprintf(text[1] + len, sizeof text[1] - (size_t)len, "%s%ld", d ? ", " : "", c < 1 ? 1 : c);
    }
    snprintf(text[1] + len, sizeof text[1] - (size_t)len, "]");
  }
  const int nuser = mica_deck_override_count(deck), total = nuser + 1 + (nc > 0);
  const char **all = NULL;
  MICA_CALL(MICA_MALLOC(all, total));
  for (int i = 0; i < nuser; i++) all[i] = mica_deck_override_text(deck, i);
  all[nuser] = text[0];
  if (nc > 0) all[nuser + 1] = text[1];
  const int ierr = mica_deck_load(mica_deck_path(deck), mica_run_schema, total, all, out);
  free(all);
  return ierr;
}

/* ---- matrices -------------------------------------------------------------------------------------------- */

/* G and S over the volume cache (trial gradients: the inf-sup condition concerns the spaces, not VCI's test
 * functions), dense (dim·np)², unknown (I, a) at I·dim + a. */
static void assemble_g_s(const RunProblem *rp, double *G, double *S) {
  const MicaShapeCache *c = rp->solid->volume;
  const int dim = rp->disc->dim;
  const long nu = rp->disc->nparticles * dim;
  for (long p = 0; p < c->npoints; p++) {
    const double w = rp->disc->qw[p];
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
      for (long f = c->ptr[p]; f < c->ptr[p + 1]; f++) {
        const long pi = c->index[e], pj = c->index[f];
        const double *gi = c->dN + e * dim, *gj = c->dN + f * dim;
        double grad = 0;
        for (int d = 0; d < dim; d++) grad += gi[d] * gj[d];
        for (int a = 0; a < dim; a++) {
          S[(pj * dim + a) * nu + pi * dim + a] += w * grad;
          for (int b = 0; b < dim; b++) G[(pj * dim + b) * nu + pi * dim + a] += w * gi[a] * gj[b];
        }
      }
  }
}

/* G = Bᵀ M_p⁻¹ B for a cell pressure (material.pressure = cell-constant | cell-linear): the pressure space is
 * the polynomials ψ_k of each background cell, B_c,k(I a) = Σ_{q∈c} w_q ψ_k(x_q) N_I,a(x_q) (the cell's
 * divergence moments) and M_c = Σ_q w_q ψ ψᵀ, so G = Σ_c B_cᵀ M_c⁻¹ B_c = ‖Π_P div u_h‖², Π_P the L2
 * projection onto the cells' polynomials; then the mean pressure is taken out (L2_0): with u_h ≈ 0 on the whole
 * boundary, ∫ div u_h = ∮ u_h·n is the residue of the collocation between the vertices, which shrinks with h
 * and would be counted as a falling β. b: scratch of (2·4 + 1)·nu doubles; psi, mpsi of 4 × points per cell. */
static int assemble_g_cells(const RunProblem *rp, double *G, double *b, double *psi, double *mpsi) {
  MicaSolid *s = rp->solid;
  const MicaShapeCache *c = s->volume;
  const int dim = rp->disc->dim;
  const long nu = rp->disc->nparticles * dim;
  double *Bm = b, *MBm = b + 4 * nu, *total = b + 8 * nu, Vtotal = 0;
  memset(total, 0, sizeof(double) * (size_t)nu);
  for (long k = 0; k < s->npcells; k++) {
    int m;
    MICA_CALL(mica_pressure_cell_basis(s, k, psi, mpsi, &m));
    memset(Bm, 0, sizeof(double) * (size_t)(8 * nu));
    for (long i = s->pcell_ptr[k]; i < s->pcell_ptr[k + 1]; i++) {
      const long p = s->pcell_point[i], local = i - s->pcell_ptr[k];
      const double w = rp->disc->qw[p];
      Vtotal += w;
      for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
        for (int a = 0; a < dim; a++) {
          const long j = c->index[e] * dim + a;
          const double div = w * c->dN[e * dim + a];
          total[j] += div;
          for (int l = 0; l < m; l++) Bm[l * nu + j] += psi[local * m + l] * div, MBm[l * nu + j] += mpsi[local * m + l] * div;
        }
    }
    for (long j = 0; j < nu; j++) {
      int touched = 0; /* the columns outside the cell's supports add nothing */
      for (int l = 0; l < m; l++) touched |= Bm[l * nu + j] != 0.0;
      if (!touched) continue;
      for (long i = 0; i < nu; i++) {
        double v = 0;
        for (int l = 0; l < m; l++) v += Bm[l * nu + i] * MBm[l * nu + j];
        G[j * nu + i] += v;
      }
    }
  }
  for (long j = 0; j < nu; j++)
    for (long i = 0; i < nu; i++) G[j * nu + i] -= total[i] * total[j] / Vtotal;
  return MICA_SUCCESS;
}

/* The boundary vertices of every set, each once. */
static int boundary_vertices(const MicaDiscretization *disc, double **xv, long *nv) {
  const int dim = disc->dim;
  long total = 0;
  for (int s = 0; s < disc->nsets; s++) total += disc->sets[s].nvertices;
  MICA_CALL(MICA_MALLOC(*xv, (total > 0 ? total : 1) * dim));
  double lo = INFINITY, hi = -INFINITY;
  for (long i = 0; i < disc->nparticles * dim; i++) lo = fmin(lo, disc->x[i]), hi = fmax(hi, disc->x[i]);
  const double tol = 1e-9 * (hi - lo);
  *nv = 0;
  for (int s = 0; s < disc->nsets; s++)
    for (long v = 0; v < disc->sets[s].nvertices; v++) {
      const double *x = disc->sets[s].vertex_x + v * dim;
      int seen = 0;
      for (long k = 0; k < *nv && !seen; k++) {
        double d2 = 0;
        for (int d = 0; d < dim; d++) d2 += pow((*xv)[k * dim + d] - x[d], 2);
        seen = sqrt(d2) <= tol;
      }
      if (!seen) memcpy(*xv + (*nv)++ * dim, x, sizeof(double) * (size_t)dim);
    }
  return MICA_SUCCESS;
}

/* Z1 (np × (np − nv), column-major): an orthonormal basis of {U : Σ_J N_J(x_v) U_J = 0 at every vertex}. */
static int null_space(const RunProblem *rp, const double *xv, long nv, double **Z1) {
  const long np = rp->disc->nparticles;
  MlsShape *sh = NULL;
  double *Q = NULL, *tau = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CHECK(nv < np, MICA_ERR_INPUT, "inf-sup: %ld boundary vertices constrain all %ld particles: refine further "
             "(stability.inf_sup_counts)", nv, np);
  MICA_CALL_CLEANUP(MICA_CALLOC(Q, (size_t)np * np));
  MICA_CALL_CLEANUP(MICA_MALLOC(tau, nv));
  MICA_CALL_CLEANUP(mls_shape_create(rp->mls, &sh));
  for (long v = 0; v < nv; v++) {
    MICA_CALL_CLEANUP(mls_eval(rp->mls, xv + v * rp->disc->dim, MLS_VALUES, sh));
    for (long k = 0; k < sh->n; k++) Q[v * np + sh->index[k]] = sh->N[k];
  }
  lapack_int info = LAPACKE_dgeqrf(LAPACK_COL_MAJOR, (lapack_int)np, (lapack_int)nv, Q, (lapack_int)np, tau);
  double rmax = 0, rmin = INFINITY;
  for (long v = 0; v < nv && info == 0; v++) rmax = fmax(rmax, fabs(Q[v * np + v])), rmin = fmin(rmin, fabs(Q[v * np + v]));
  if (info == 0 && !(rmin > 1e-10 * rmax)) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_NUMERIC,
                          "inf-sup: the boundary collocation constraints are dependent (|R_ii| ratio %.3g)", rmin / rmax);
    goto cleanup;
  }
  if (info == 0) info = LAPACKE_dorgqr(LAPACK_COL_MAJOR, (lapack_int)np, (lapack_int)np, (lapack_int)nv, Q, (lapack_int)np, tau);
  if (info != 0) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_LIBRARY, "LAPACK QR failed (info %d)", (int)info);
    goto cleanup;
  }
  MICA_CALL_CLEANUP(MICA_MALLOC(*Z1, (size_t)np * (np - nv)));
  memcpy(*Z1, Q + nv * np, sizeof(double) * (size_t)np * (size_t)(np - nv));
cleanup:
  mls_shape_destroy(&sh);
  free(Q), free(tau);
  return ierr;
}

/* out = Zᵀ A Z (nr × nr) for Z (nu × nr). */
static int project(long nu, long nr, const double *A, const double *Z, double *out) {
  double *W = NULL;
  MICA_CALL(MICA_MALLOC(W, (size_t)nu * nr));
  const fint m = (fint)nu, n = (fint)nr;
  const double one = 1, zero = 0;
  dgemm_("N", "N", &m, &n, &m, &one, A, &m, Z, &m, &zero, W, &m, 1, 1);
  dgemm_("T", "N", &n, &n, &m, &one, Z, &m, W, &m, &zero, out, &n, 1, 1);
  free(W);
  return MICA_SUCCESS;
}

/* β for one discretization. */
static int inf_sup_one(const StabilityOptions *o, const RunProblem *rp, InfSupRow *row) {
  const int dim = rp->disc->dim;
  const long np = rp->disc->nparticles, nu = np * dim;
  double *G = NULL, *S = NULL, *xv = NULL, *Z1 = NULL, *Z = NULL, *Gr = NULL, *Sr = NULL, *lambda = NULL;
  long nv = 0;
  int ierr = MICA_SUCCESS;
  if (nu > o->dense_max_dofs) { /* dense (n_u)² matrices and an O(n_u³) eigenproblem */
    char where[256];
    mica_deck_where(rp->deck, "stability.inf_sup_counts", where, sizeof where);
    MICA_ERROR(MICA_ERR_INPUT, "%s: the inf-sup eigenproblem is dense, and N = %ld gives %ld displacement unknowns, more "
               "than stability.dense_max_dofs = %ld: lower the largest of stability.inf_sup_counts or raise "
               "stability.dense_max_dofs", where, row->count[0], nu, o->dense_max_dofs);
  }
  MICA_CALL_CLEANUP(MICA_CALLOC(G, (size_t)nu * nu));
  MICA_CALL_CLEANUP(MICA_CALLOC(S, (size_t)nu * nu));
  assemble_g_s(rp, G, S);
  const int cells = mica_solid_pressure_cells(rp->solid);
  if (cells) { /* the cells' pressure space replaces the pointwise divergence */
    memset(G, 0, sizeof(double) * (size_t)nu * (size_t)nu);
    double *b = NULL, *psi = NULL, *mpsi = NULL;
    const long per = 4 * (rp->solid->pcell_maxpoints + 1);
    ierr = MICA_MALLOC(b, 9 * nu);
    if (!ierr) ierr = MICA_MALLOC(psi, per);
    if (!ierr) ierr = MICA_MALLOC(mpsi, per);
    if (!ierr) ierr = assemble_g_cells(rp, G, b, psi, mpsi);
    free(b), free(psi), free(mpsi);
    MICA_CALL_CLEANUP(ierr);
  }
  MICA_CALL_CLEANUP(boundary_vertices(rp->disc, &xv, &nv));
  MICA_CALL_CLEANUP(null_space(rp, xv, nv, &Z1));
  const long nfree = np - nv, nr = nfree * dim;
  MICA_CALL_CLEANUP(MICA_CALLOC(Z, (size_t)nu * nr));
  for (long j = 0; j < nfree; j++)
    for (int b = 0; b < dim; b++)
      for (long k = 0; k < np; k++) Z[(j * dim + b) * nu + k * dim + b] = Z1[j * np + k];
  MICA_CALL_CLEANUP(MICA_MALLOC(Gr, (size_t)nr * nr));
  MICA_CALL_CLEANUP(MICA_MALLOC(Sr, (size_t)nr * nr));
  MICA_CALL_CLEANUP(MICA_MALLOC(lambda, nr));
  MICA_CALL_CLEANUP(project(nu, nr, G, Z, Gr));
  MICA_CALL_CLEANUP(project(nu, nr, S, Z, Sr));
  ierr = mica_eigen_dense_generalized((int)nr, Gr, Sr, lambda);
  if (ierr == MICA_ERR_NUMERIC) {
    mica_error_prefix("inf-sup: the H1 seminorm matrix S over this quadrature is singular — some displacement "
                      "has zero gradient at every quadrature point (too low a quadrature rule)");
  }
  MICA_CALL_CLEANUP(ierr);
  row->particles = np, row->constrained = nv, row->nfree = nr;
  /* n_p, the pressure unknowns: 1 + degree·dim per cell, or one per quadrature point */
  row->nquad = cells ? rp->solid->npcells * (1 + rp->solid->opt.pressure->degree * dim) : rp->solid->volume->npoints;
  row->lambda_max = lambda[nr - 1];
  row->zero = 0;
  while (row->zero < nr && lambda[row->zero] <= o->zero_tol * row->lambda_max) row->zero++;
  row->beta = row->zero < nr ? sqrt(fmax(lambda[row->zero], 0)) : 0;
  row->pressure_modes = row->zero - nr + row->nquad; /* k − (n_u − n_p + 1), k − 1 zero eigenvalues */
  if (row->pressure_modes < 0) row->pressure_modes = 0;
cleanup:
  free(G), free(S), free(xv), free(Z1), free(Z), free(Gr), free(Sr), free(lambda);
  return ierr;
}

static double log_slope(const InfSupRow *rows, int n) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int i = 0; i < n; i++) {
    const double x = log((double)rows[i].count[0]), y = log(rows[i].beta);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

/* The row's numbers in summary.json, keyed by its particle count. */
static int record_row(const InfSupRow *row, MicaJson *summary) {
  char key[64];
  snprintf(key, sizeof key, "inf_sup_beta_N%ld", row->count[0]);
  MICA_CALL(mica_json_number(summary, key, row->beta));
  snprintf(key, sizeof key, "inf_sup_zero_N%ld", row->count[0]);
  MICA_CALL(mica_json_int(summary, key, row->zero));
  snprintf(key, sizeof key, "inf_sup_pressure_modes_N%ld", row->count[0]);
  MICA_CALL(mica_json_int(summary, key, row->pressure_modes));
  return MICA_SUCCESS;
}

int stability_inf_sup(const StabilityOptions *o, const MicaDeck *deck, const char *outdir, MicaJson *summary) {
  InfSupRow *rows = NULL;
  int ierr = MICA_SUCCESS, nrows = 0;
  int axisymmetric;
  MICA_CALL(mica_deck_bool(deck, "geometry.axisymmetric", &axisymmetric));
  if (axisymmetric) {
    printf("inf-sup test skipped: the divergence of an axisymmetric section has the hoop term u_r/r\n");
    MICA_CALL(mica_json_string(summary, "inf_sup_skipped", "axisymmetric"));
    return MICA_SUCCESS;
  }
  MICA_CALL(MICA_CALLOC(rows, o->ninf_sup > 0 ? o->ninf_sup : 1));
  const double start = mica_wtime();
  for (int i = 0; i < o->ninf_sup; i++) {
    MicaDeck *refined = NULL;
    RunProblem rp;
    memset(&rp, 0, sizeof rp);
    InfSupRow *row = &rows[nrows];
    ierr = refined_deck(deck, o->inf_sup_counts[i], row->count, &refined);
    if (!ierr) ierr = run_problem_build_symmetric(refined, &rp);
    if (!ierr) ierr = inf_sup_one(o, &rp, row);
    const int cells = !ierr && mica_solid_pressure_cells(rp.solid);
    run_problem_free(&rp);
    mica_deck_destroy(&refined);
    if (ierr) {
      mica_error_prefix("inf-sup test at N = %ld", o->inf_sup_counts[i]);
      mica_error_trace(__FILE__, __LINE__, __func__, ierr);
      goto cleanup;
    }
    printf("inf-sup N = %ld: %ld particles (%ld on the boundary), %ld free unknowns, %ld %s: %d zero eigenvalues, "
           "β = %.6g\n", row->count[0], row->particles, row->constrained, row->nfree, row->nquad,
           cells ? "cell pressures" : "quadrature points", row->zero, row->beta);
    fflush(stdout);
    MICA_CALL_CLEANUP(record_row(row, summary));
    nrows++;
  }
  int positive = nrows >= 2;
  for (int i = 0; i < nrows; i++) positive &= rows[i].beta > 0;
  if (positive) {
    const double slope = log_slope(rows, nrows);
    printf("inf-sup: d log β / d log N = %.3f (bounded below: ≈ 0; Q1P0-type locking: ≈ −1)\n", slope);
    MICA_CALL_CLEANUP(mica_json_number(summary, "inf_sup_slope", slope));
  }
  MICA_CALL_CLEANUP(mica_json_number(summary, "time_inf_sup", mica_wtime() - start));
  MICA_CALL_CLEANUP(stability_write_inf_sup(rows, nrows, outdir, o->chart));
cleanup:
  free(rows);
  return ierr;
}
