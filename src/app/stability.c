/* `mica stability`: is the deck's discretization stable and consistent? (docs/theory.md §stability; seed
 * 000 §7.2). On the run deck as it stands:
 *   1. eigen-mode analysis of the tangent K at u = 0 with the deck's conditions: zero modes (|λ| ≤ zero_tol
 *      λ_max), how many of them the exact rigid-body motions span, spurious zero modes = zero − rigid,
 *      low-energy modes (nonzero modes below λ₁,ref, the lowest nonzero eigenvalue of the same deck integrated
 *      by an adequate Gauss rule, whose energy under the deck's rule is less than ρ times their energy under
 *      that rule: stability_reference.c), spurious = both, the lowest nonzero eigenvalue; dense LAPACK or
 *      sparse shift-invert;
 *   2. linear and quadratic patch tests (stability_patch.c);
 *   3. the numerical inf-sup test over a refinement series (stability_infsup.c);
 *   4. the condition number of the MLS moment matrix at every volume quadrature point.
 * Each part can be switched off in the deck's `stability` group. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/eigen.h"
#include "mica/timer.h"
#include "stability.h"

/* ---- options ------------------------------------------------------------------------------------------- */

int stability_read_options(const MicaDeck *deck, StabilityOptions *o) {
  const char *solver;
  int n;
  memset(o, 0, sizeof *o);
  MICA_CALL(mica_deck_bool(deck, "stability.eigen", &o->eigen));
  MICA_CALL(mica_deck_bool(deck, "stability.patch", &o->patch));
  MICA_CALL(mica_deck_bool(deck, "stability.inf_sup", &o->inf_sup));
  MICA_CALL(mica_deck_bool(deck, "stability.conditioning", &o->conditioning));
  MICA_CALL(mica_deck_bool(deck, "stability.chart", &o->chart));
  MICA_CALL(mica_deck_string(deck, "stability.solver", &solver));
  o->solver = !strcmp(solver, "sparse") ? STABILITY_SPARSE : !strcmp(solver, "auto") ? STABILITY_AUTO : STABILITY_DENSE;
  MICA_CALL(mica_deck_int(deck, "stability.dense_max_dofs", &o->dense_max_dofs));
  MICA_CALL(mica_deck_int(deck, "stability.modes", &o->modes));
  MICA_CALL(mica_deck_int(deck, "stability.max_iterations", &o->max_iterations));
  MICA_CALL(mica_deck_int(deck, "stability.vtu_modes", &o->vtu_modes));
  MICA_CALL(mica_deck_float(deck, "stability.zero_tol", &o->zero_tol));
  MICA_CALL(mica_deck_float(deck, "stability.shift", &o->shift));
  MICA_CALL(mica_deck_float(deck, "stability.tol", &o->tol));
  MICA_CALL(mica_deck_string(deck, "stability.reference", &solver));
  o->reference = !strcmp(solver, "gauss");
  MICA_CALL(mica_deck_int(deck, "stability.reference_order", &o->reference_order));
  MICA_CALL(mica_deck_float(deck, "stability.low_energy_ratio", &o->low_energy_ratio));
  /* as many levels as the deck lists; the default's three or a lone value when it lists none */
  int capacity = mica_deck_list_length(deck, "stability.inf_sup_counts");
  if (capacity < 3) capacity = 3;
  MICA_CALL(MICA_CALLOC(o->inf_sup_counts, capacity));
  MICA_CALL(mica_deck_ints(deck, "stability.inf_sup_counts", o->inf_sup_counts, capacity, &n));
  o->ninf_sup = n;
  return MICA_SUCCESS;
}

void stability_free_options(StabilityOptions *o) {
  MICA_FREE(o->inf_sup_counts);
  o->ninf_sup = 0;
}

/* ---- rigid-body motions -------------------------------------------------------------------------------- */

/* The exact rigid-body motions of the model's unknowns at the particles, as coefficient vectors (an MLS basis
 * of order ≥ 1 reproduces linear fields, so u_I = r(x_I) gives u_h = r exactly). Cartesian: translations
 * along each axis and infinitesimal rotations ω about each axis (one, z, in 2-D): u = ω × (x − c) and, for
 * models with micro-rotations, φ = ω (a rigid motion rotates the micro-structure with the body). Axisymmetric
 * sections: the axial translation u_z = 1 and the rotation about the axis u_θ = r (φ_z = 1). Returns the
 * number of motions in *nr; R is [ndof × 6], column-major. */
static int rigid_motions(RunProblem *rp, double *R, int *nr) {
  const MicaSolid *s = rp->solid;
  const int dim = rp->disc->dim, ncomp = s->ncomp;
  const long np = rp->disc->nparticles, ndof = s->ndof;
  const char *axes = "xyz";
  double center[3] = {0, 0, 0};
  for (long i = 0; i < np; i++)
    for (int d = 0; d < dim; d++) center[d] += rp->disc->x[i * dim + d] / (double)np;
  memset(R, 0, sizeof(double) * (size_t)ndof * 6);
  *nr = 0;
  /* motions: translations t_a (kind 0, axis a), rotations about axis b (kind 1) */
  int kinds[6][2], count = 0;
  if (rp->axisymmetric) {
    kinds[count][0] = 0, kinds[count++][1] = 2;
    kinds[count][0] = 1, kinds[count++][1] = 2;
  } else {
    for (int a = 0; a < dim; a++) kinds[count][0] = 0, kinds[count++][1] = a;
    if (dim == 2) kinds[count][0] = 1, kinds[count++][1] = 2;
    else
      for (int b = 0; b < 3; b++) kinds[count][0] = 1, kinds[count++][1] = b;
  }
  for (int m = 0; m < count; m++) {
    const int kind = kinds[m][0], axis = kinds[m][1];
    double *col = R + (size_t)m * ndof;
    for (long i = 0; i < np; i++) {
      double x[3] = {0, 0, 0};
      for (int d = 0; d < dim; d++) x[d] = rp->disc->x[i * dim + d] - center[d];
      for (int c = 0; c < ncomp; c++) {
        const char *name = run_unknown_name(rp, c);
        double v = 0;
        if (rp->axisymmetric) {
          if (kind == 0) v = !strcmp(name, "uz");
          else v = !strcmp(name, "utheta") ? rp->disc->x[i * dim] : !strcmp(name, "phiz");
        } else if (name[0] == 'u' && strlen(name) == 2) {
          const int a = (int)(strchr(axes, name[1]) - axes);
          if (kind == 0) v = a == axis;
          else { /* (e_axis × x)_a */
            const int b1 = (axis + 1) % 3, b2 = (axis + 2) % 3;
            v = a == b1 ? -x[b2] : a == b2 ? x[b1] : 0;
          }
        } else if (!strncmp(name, "phi", 3)) {
          v = kind == 1 && name[3] == axes[axis];
        }
        col[i * ncomp + c] = v;
      }
    }
  }
  *nr = count;
  return MICA_SUCCESS;
}

/* Orthonormal columns (modified Gram–Schmidt, twice) of the k columns of A (n each); columns that are
 * dependent on earlier ones are dropped. Returns the rank in *rank. */
static void orthonormal_columns(long n, int k, double *A, int *rank) {
  int r = 0;
  for (int j = 0; j < k; j++) {
    double *x = A + (size_t)j * n, before = 0, after = 0;
    for (long i = 0; i < n; i++) before += x[i] * x[i];
    for (int pass = 0; pass < 2; pass++)
      for (int q = 0; q < r; q++) {
        const double *e = A + (size_t)q * n;
        double c = 0;
        for (long i = 0; i < n; i++) c += e[i] * x[i];
        for (long i = 0; i < n; i++) x[i] -= c * e[i];
      }
    for (long i = 0; i < n; i++) after += x[i] * x[i];
    if (!(after > 1e-20 * before) || before == 0) continue;
    double *dst = A + (size_t)r * n;
    for (long i = 0; i < n; i++) dst[i] = x[i] / sqrt(after);
    r++;
  }
  *rank = r;
}

/* ---- the eigen-mode analysis ------------------------------------------------------------------------- */

static int check_eigen_input(const MicaDeck *deck, const MicaSolid *s) {
  char where[256];
  if (s->nmultiplier_nodes > 0) {
    mica_deck_where(deck, "bc.method", where, sizeof where);
    MICA_ERROR(MICA_ERR_INPUT,
               "%s: bc.method = \"lagrange\" makes the tangent an indefinite saddle-point matrix (%ld multiplier "
               "nodes), whose eigenvalues say nothing about zero-energy modes: use bc.method = \"penalty\" or "
               "\"nitsche\" for the eigen analysis, or set stability.eigen = false",
               where, s->nmultiplier_nodes);
  }
  if (s->opt.vci) {
    mica_deck_where(deck, "quadrature.vci", where, sizeof where);
    MICA_ERROR(MICA_ERR_INPUT,
               "%s: quadrature.vci = true gives an unsymmetric (Petrov–Galerkin) tangent, and the eigen analysis "
               "is for symmetric ones: set stability.eigen = false (the patch tests still use VCI) or "
               "quadrature.vci = false", where);
  }
  return MICA_SUCCESS;
}

static int choose_dense(const StabilityOptions *o, const MicaDeck *deck, long ndof, int *dense) {
  *dense = o->solver == STABILITY_DENSE || (o->solver == STABILITY_AUTO && ndof <= o->dense_max_dofs);
  if (*dense && ndof > o->dense_max_dofs) {
    char where[256];
    mica_deck_where(deck, "stability.solver", where, sizeof where);
    MICA_ERROR(MICA_ERR_INPUT,
               "%s: %ld unknowns are more than stability.dense_max_dofs = %ld allows the dense eigensolver: set "
               "stability.solver = \"sparse\" (shift-invert, the stability.modes lowest eigenvalues) or \"auto\", or "
               "raise stability.dense_max_dofs (memory 16 n² bytes, time ~ n³)",
               where, ndof, o->dense_max_dofs);
  }
  return MICA_SUCCESS;
}

/* All eigenpairs of the dense K. */
static int eigen_dense(const MicaSparse *K, EigenResult *r, double **vectors) {
  const long n = K->n;
  double *A = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_MALLOC(A, (size_t)n * n));
  MICA_CALL_CLEANUP(MICA_MALLOC(*vectors, (size_t)n * n));
  MICA_CALL_CLEANUP(MICA_MALLOC(r->lambda, n));
  MICA_CALL_CLEANUP(mica_sparse_to_dense(K, A));
  MICA_CALL_CLEANUP(mica_eigen_dense((int)n, A, r->lambda, *vectors));
  r->nvalues = (int)n;
  r->lambda_max = r->lambda[n - 1];
cleanup:
  free(A);
  return ierr;
}

/* The stability.modes lowest eigenpairs by shift-invert below the spectrum. */
static int eigen_sparse(const StabilityOptions *o, const MicaSparse *K, EigenResult *r, double **vectors,
                        MicaJson *summary) {
  const long n = K->n;
  MICA_CALL(mica_eigen_largest(K, 80, 11, &r->lambda_max));
  MICA_CHECK(r->lambda_max > 0, MICA_ERR_NUMERIC, "the tangent has no positive eigenvalue (λ_max ≈ %.3g)",
             r->lambda_max);
  MicaEigenOptions eo = {0};
  eo.nev = (int)(o->modes < n ? o->modes : n);
  eo.sigma = -o->shift * r->lambda_max;
  eo.tol = o->tol;
  eo.scale = r->lambda_max;
  eo.max_iterations = (int)o->max_iterations;
  eo.seed = 5;
  MicaEigenStats st;
  MICA_CALL(MICA_MALLOC(*vectors, (size_t)n * eo.nev));
  MICA_CALL(MICA_MALLOC(r->lambda, eo.nev));
  MICA_CALL(mica_eigen_shift_invert(K, &eo, r->lambda, *vectors, &st));
  r->nvalues = eo.nev;
  printf("shift-invert (σ = %.3g, %s, nnz(L) %ld): %d eigenpairs in %d restarts, %ld solves, residual %.2g λ_max, "
         "factor %.3g s, iterations %.3g s\n", eo.sigma, st.linear_name, st.nnz_factor, eo.nev, st.iterations,
         st.solves, st.max_residual, st.time_factor, st.time_iterate);
  MICA_CALL(mica_json_number(summary, "eigen_shift", eo.sigma));
  MICA_CALL(mica_json_int(summary, "eigen_restarts", st.iterations));
  MICA_CALL(mica_json_int(summary, "eigen_solves", st.solves));
  MICA_CALL(mica_json_number(summary, "eigen_residual", st.max_residual));
  MICA_CALL(mica_json_string(summary, "eigen_linear_solver", st.linear_name));
  MICA_CALL(mica_json_number(summary, "time_eigen_factor", st.time_factor));
  return MICA_SUCCESS;
}

/* How many independent rigid motions lie in the zero space Z (nz orthonormal columns): the cosines of the
 * principal angles between span R and span Z are the singular values of Zᵀ Q_R; a motion counts when its
 * cosine is at least 1 − 1e-6. On return the first nz − rigid columns of Zs hold an orthonormal basis of the
 * zero space orthogonal to the rigid motions (the spurious modes), least rigid first. */
static int classify_zero_space(long n, int nz, const double *Z, double *R, int nr, EigenResult *r, double *Zs) {
  int rank = 0, ierr = MICA_SUCCESS;
  orthonormal_columns(n, nr, R, &rank);
  double *P = NULL, *V = NULL, *cos2 = NULL, *M = NULL;
  MICA_CALL_CLEANUP(MICA_CALLOC(M, (size_t)nz * (rank > 0 ? rank : 1)));
  MICA_CALL_CLEANUP(MICA_CALLOC(P, (size_t)nz * nz));
  MICA_CALL_CLEANUP(MICA_CALLOC(V, (size_t)nz * nz));
  MICA_CALL_CLEANUP(MICA_CALLOC(cos2, nz));
  for (int a = 0; a < nz; a++)
    for (int b = 0; b < rank; b++) {
      double c = 0;
      for (long i = 0; i < n; i++) c += Z[(size_t)a * n + i] * R[(size_t)b * n + i];
      M[(size_t)b * nz + a] = c;
    }
  for (int a = 0; a < nz; a++) /* P = M Mᵀ: eigenvalues cos² of the principal angles (and zeros) */
    for (int b = 0; b < nz; b++) {
      double c = 0;
      for (int k = 0; k < rank; k++) c += M[(size_t)k * nz + a] * M[(size_t)k * nz + b];
      P[(size_t)b * nz + a] = c;
    }
  MICA_CALL_CLEANUP(mica_eigen_dense(nz, P, cos2, V));
  r->rigid = 0;
  r->rigid_cos_min = 1;
  for (int k = nz - 1; k >= 0 && k >= nz - rank; k--) {
    const double c = sqrt(fmax(cos2[k], 0));
    if (c >= 1 - 1e-6) r->rigid++;
    r->rigid_cos_min = fmin(r->rigid_cos_min, c);
  }
  if (rank > nz) r->rigid_cos_min = 0; /* some rigid motion is not a zero mode at all */
  memset(Zs, 0, sizeof(double) * (size_t)n * nz);
  for (int k = 0; k < nz; k++) /* Zs_k = Z V_k: ascending cos², the least rigid first */
    for (int a = 0; a < nz; a++) {
      const double v = V[(size_t)k * nz + a];
      for (long i = 0; i < n; i++) Zs[(size_t)k * n + i] += v * Z[(size_t)a * n + i];
    }
cleanup:
  free(M), free(P), free(V), free(cos2);
  return ierr;
}

static int write_modes(const StabilityOptions *o, RunProblem *rp, const EigenResult *r, const double *Zs,
                       const double *vectors, const char *outdir) {
  const long n = r->ndof;
  long written = 0;
  char name[64];
  for (int k = 0; k < r->spurious_zero && written < o->vtu_modes; k++, written++) {
    snprintf(name, sizeof name, "spurious_%02d.vtu", k + 1);
    MICA_CALL(stability_write_mode(rp, Zs + (size_t)k * n, outdir, name, 0.0));
  }
  for (int k = r->zero, low = 0; k < r->nvalues && written < o->vtu_modes; k++) /* low-energy modes next */
    if (r->kind[k] == MODE_LOW_ENERGY) {
      snprintf(name, sizeof name, "low_energy_%02d.vtu", ++low);
      MICA_CALL(stability_write_mode(rp, vectors + (size_t)k * n, outdir, name, r->lambda[k]));
      written++;
    }
  for (int k = r->zero; k < r->nvalues && written < o->vtu_modes; k++) {
    if (r->kind[k] == MODE_LOW_ENERGY) continue;
    written++;
    snprintf(name, sizeof name, "mode_%04d.vtu", k + 1);
    MICA_CALL(stability_write_mode(rp, vectors + (size_t)k * n, outdir, name, r->lambda[k]));
  }
  return MICA_SUCCESS;
}

static int eigen_summary(const EigenResult *r, int dense, MicaJson *summary) {
  MICA_CALL(mica_json_string(summary, "eigen_solver", dense ? "dense" : "sparse"));
  MICA_CALL(mica_json_int(summary, "eigen_dofs", r->ndof));
  MICA_CALL(mica_json_int(summary, "eigenvalues_computed", r->nvalues));
  MICA_CALL(mica_json_number(summary, "lambda_max", r->lambda_max));
  MICA_CALL(mica_json_int(summary, "zero_modes", r->zero));
  MICA_CALL(mica_json_int(summary, "rigid_modes", r->rigid));
  MICA_CALL(mica_json_int(summary, "spurious_zero_modes", r->spurious_zero));
  MICA_CALL(mica_json_int(summary, "low_energy_modes", r->low_energy));
  MICA_CALL(mica_json_int(summary, "spurious_modes", r->spurious));
  MICA_CALL(mica_json_number(summary, "rigid_cos_min", r->rigid_cos_min));
  if (r->zero < r->nvalues) {
    MICA_CALL(mica_json_number(summary, "lambda_min_nonzero", r->lambda[r->zero]));
    MICA_CALL(mica_json_number(summary, "lambda_min_nonzero_relative", r->lambda[r->zero] / r->lambda_max));
  }
  MICA_CALL(mica_json_open_array(summary, "lambda_lowest_nonzero"));
  for (int k = r->zero; k < r->nvalues && k < r->zero + 10; k++) MICA_CALL(mica_json_number(summary, NULL, r->lambda[k]));
  MICA_CALL(mica_json_close(summary));
  return MICA_SUCCESS;
}

static void eigen_print(const EigenResult *r) {
  printf("eigen: %ld unknowns, λ_max %.6g; %d zero modes (|λ| ≤ zero_tol λ_max): %d rigid, %d spurious; %d "
         "low-energy; %d spurious in all", r->ndof, r->lambda_max, r->zero, r->rigid, r->spurious_zero, r->low_energy,
         r->spurious);
  if (r->zero < r->nvalues) printf("; lowest nonzero λ %.10g", r->lambda[r->zero]);
  printf("\n");
  printf("lowest nonzero eigenvalues:");
  for (int k = r->zero; k < r->nvalues && k < r->zero + 6; k++) printf(" %.8g", r->lambda[k]);
  printf("\n");
}

/* Low-energy spurious modes (docs/theory.md §Stability studies): the nonzero modes v_k below λ₁,ref whose
 * energy under the deck's rule, λ_k, is less than ρ times their energy under the reference rule, v_kᵀ K_ref v_k
 * (|v_k| = 1). With the sparse solver, computed modes that all lie below λ₁,ref leave the count open: an error
 * asking for more modes. */
static int count_low_energy(const StabilityOptions *o, RunProblem *rp, int dense, int nr, const double *vectors,
                            EigenResult *r, MicaJson *summary) {
  StabilityReference ref;
  double *work = NULL;
  int ierr = MICA_SUCCESS;
  r->ratio_min = NAN;
  MICA_CALL(mica_json_string(summary, "reference", o->reference ? "gauss" : "none"));
  if (!o->reference || r->zero == r->nvalues) return MICA_SUCCESS;
  MICA_CALL_CLEANUP(stability_reference_create(o, rp, &ref));
  if (ref.self) ref.lambda1 = r->lambda[r->zero];
  else MICA_CALL_CLEANUP(stability_reference_spectrum(o, dense, nr, &ref));
  r->band = ref.lambda1;
  MICA_CALL_CLEANUP(MICA_MALLOC(work, r->ndof));
  for (int k = r->zero; k < r->nvalues && r->lambda[k] < r->band; k++, r->in_band++) {
    const double e = stability_reference_energy(&ref, vectors + (size_t)k * r->ndof, work);
    r->energy_ratio[k] = e > 0 ? r->lambda[k] / e : 0;
    r->ratio_min = r->in_band ? fmin(r->ratio_min, r->energy_ratio[k]) : r->energy_ratio[k];
    if (r->energy_ratio[k] < o->low_energy_ratio) r->kind[k] = MODE_LOW_ENERGY, r->low_energy++;
  }
  printf("reference (%s): lowest nonzero eigenvalue λ₁,ref %.6g; %d nonzero modes below it", ref.self
         ? "the deck's own Gauss rule" : "the deck's particles and MLS on Gauss cells", ref.lambda1, r->in_band);
  if (r->in_band > 0)
    printf(", energy ratios λ/(vᵀK_ref v) down to %.3g: %d below stability.low_energy_ratio = %.3g", r->ratio_min,
           r->low_energy, o->low_energy_ratio);
  printf("\n");
  if (!dense && r->zero + r->in_band == r->nvalues) {
    char where[256];
    mica_deck_where(rp->deck, "stability.modes", where, sizeof where);
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                          "%s: all %d eigenvalues computed lie below the reference's lowest nonzero one (%.6g), so "
                          "there may be more low-energy modes: raise stability.modes", where, r->nvalues, ref.lambda1);
    goto cleanup;
  }
  MICA_CALL_CLEANUP(mica_json_number(summary, "reference_lambda_min_nonzero", ref.lambda1));
  MICA_CALL_CLEANUP(mica_json_bool(summary, "reference_is_deck", ref.self));
  MICA_CALL_CLEANUP(mica_json_number(summary, "low_energy_ratio", o->low_energy_ratio));
  MICA_CALL_CLEANUP(mica_json_int(summary, "modes_below_reference", r->in_band));
  if (r->in_band > 0) MICA_CALL_CLEANUP(mica_json_number(summary, "energy_ratio_min", r->ratio_min));
cleanup:
  free(work);
  stability_reference_destroy(&ref);
  return ierr;
}

int stability_eigen(const StabilityOptions *o, RunProblem *rp, const char *outdir, MicaJson *summary) {
  MicaSolid *s = rp->solid;
  EigenResult r;
  double *u = NULL, *R = NULL, *vectors = NULL, *rigid = NULL, *Zs = NULL;
  int dense = 1, ierr = MICA_SUCCESS;
  memset(&r, 0, sizeof r);
  MICA_CALL(choose_dense(o, rp->deck, s->ndof, &dense));
  const long n = s->ndof;
  r.ndof = n;
  const double start = mica_wtime();
  MICA_CALL_CLEANUP(MICA_CALLOC(u, n));
  MICA_CALL_CLEANUP(MICA_CALLOC(R, n));
  MICA_CALL_CLEANUP(mica_solid_assemble(s, 1.0, u, R, s->K));
  const double asym = mica_sparse_asymmetry(s->K);
  if (!(asym <= 1e-10)) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_NUMERIC,
                          "the tangent at u = 0 is not symmetric (max |K − Kᵀ| / max |K| = %.3g): no symmetric "
                          "eigen analysis", asym);
    goto cleanup;
  }
  if (dense)
    MICA_CALL_CLEANUP(eigen_dense(s->K, &r, &vectors));
  else
    MICA_CALL_CLEANUP(eigen_sparse(o, s->K, &r, &vectors, summary));
  const double threshold = o->zero_tol * r.lambda_max;
  while (r.zero < r.nvalues && fabs(r.lambda[r.zero]) <= threshold) r.zero++;
  if (!dense && r.zero == r.nvalues) {
    char where[256];
    mica_deck_where(rp->deck, "stability.modes", where, sizeof where);
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                          "%s: all %d eigenvalues computed are zero modes, so there may be more: raise "
                          "stability.modes", where, r.nvalues);
    goto cleanup;
  }
  for (int k = r.zero; k < r.nvalues; k++) /* a negative eigenvalue beyond the threshold: an unstable tangent */
    if (r.lambda[k] < 0) printf("warning: eigenvalue %d is negative (%.6g): the tangent is indefinite\n", k + 1, r.lambda[k]);
  int nr = 0;
  MICA_CALL_CLEANUP(MICA_CALLOC(rigid, (size_t)n * 6));
  MICA_CALL_CLEANUP(rigid_motions(rp, rigid, &nr));
  MICA_CALL_CLEANUP(MICA_CALLOC(Zs, (size_t)n * (r.zero > 0 ? r.zero : 1)));
  if (r.zero > 0) MICA_CALL_CLEANUP(classify_zero_space(n, r.zero, vectors, rigid, nr, &r, Zs));
  else r.rigid_cos_min = 0;
  r.spurious_zero = r.zero - r.rigid;
  MICA_CALL_CLEANUP(MICA_MALLOC(r.kind, r.nvalues));
  MICA_CALL_CLEANUP(MICA_MALLOC(r.energy_ratio, r.nvalues));
  for (int k = 0; k < r.nvalues; k++) {
    r.kind[k] = k < r.rigid ? MODE_RIGID : k < r.zero ? MODE_SPURIOUS : MODE_NONZERO;
    r.energy_ratio[k] = NAN;
  }
  MICA_CALL_CLEANUP(count_low_energy(o, rp, dense, nr, vectors, &r, summary));
  r.spurious = r.spurious_zero + r.low_energy;
  eigen_print(&r);
  MICA_CALL_CLEANUP(eigen_summary(&r, dense, summary));
  MICA_CALL_CLEANUP(mica_json_number(summary, "time_eigen", mica_wtime() - start));
  MICA_CALL_CLEANUP(stability_write_eigenvalues(&r, o->zero_tol, outdir, o->chart));
  MICA_CALL_CLEANUP(write_modes(o, rp, &r, Zs, vectors, outdir));
cleanup:
  free(u), free(R), free(vectors), free(rigid), free(Zs), free(r.lambda), free(r.kind), free(r.energy_ratio);
  return ierr;
}

/* ---- moment-matrix conditioning ------------------------------------------------------------------------ */

static int compare_doubles(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int stability_conditioning(RunProblem *rp, MicaJson *summary) {
  const MicaDiscretization *disc = rp->disc;
  const int dim = disc->dim;
  const long n = disc->nquad;
  MlsShape *sh = NULL;
  double *cond = NULL;
  int ierr = MICA_SUCCESS;
  long worst = 0;
  MICA_CALL(MICA_MALLOC(cond, n > 0 ? n : 1));
  MICA_CALL_CLEANUP(mls_shape_create(rp->mls, &sh));
  for (long p = 0; p < n; p++) {
    MICA_CALL_CLEANUP(mls_moment_condition(rp->mls, disc->qx + p * dim, sh, &cond[p]));
    if (cond[p] > cond[worst]) worst = p;
  }
  const double *xw = disc->qx + worst * dim, cmax = cond[worst];
  qsort(cond, (size_t)n, sizeof *cond, compare_doubles);
  const double median = n % 2 ? cond[n / 2] : 0.5 * (cond[n / 2 - 1] + cond[n / 2]);
  char point[96];
  if (dim == 3) snprintf(point, sizeof point, "(%.6g, %.6g, %.6g)", xw[0], xw[1], xw[2]);
  else snprintf(point, sizeof point, "(%.6g, %.6g)", xw[0], xw[1]);
  printf("moment matrix condition (2-norm, equilibrated) over %ld volume points: min %.4g, median %.4g, max %.4g at "
         "%s\n", n, cond[0], median, cmax, point);
  MICA_CALL_CLEANUP(mica_json_number(summary, "cond_min", cond[0]));
  MICA_CALL_CLEANUP(mica_json_number(summary, "cond_median", median));
  MICA_CALL_CLEANUP(mica_json_number(summary, "cond_max", cmax));
  MICA_CALL_CLEANUP(mica_json_open_array(summary, "cond_max_point"));
  for (int d = 0; d < dim; d++) MICA_CALL_CLEANUP(mica_json_number(summary, NULL, xw[d]));
  MICA_CALL_CLEANUP(mica_json_close(summary));
cleanup:
  mls_shape_destroy(&sh);
  free(cond);
  return ierr;
}

/* ---- the command ------------------------------------------------------------------------------------------ */

static int stability_run(const MicaDeck *deck, const char *outdir, MicaJson *summary) {
  StabilityOptions o;
  RunProblem rp;
  int ierr = MICA_SUCCESS;
  memset(&rp, 0, sizeof rp);
  ierr = stability_read_options(deck, &o);
  if (ierr) {
    stability_free_options(&o);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  const int need_problem = o.eigen || o.patch || o.conditioning;
  if (need_problem) {
    MICA_CALL_CLEANUP(run_problem_build_symmetric(deck, &rp));
    printf("%ld particles, %ld volume quadrature points, %ld unknowns (%s, bc.method %s)\n", rp.disc->nparticles,
           rp.disc->nquad, rp.solid->ndof, rp.solid->opt.field.classical ? rp.solid->opt.field.classical->type.name
                                                                          : rp.solid->opt.field.ops->type.name,
           rp.solid->opt.bc_method->type.name);
    MICA_CALL_CLEANUP(mica_json_int(summary, "dim", rp.disc->dim));
    MICA_CALL_CLEANUP(mica_json_int(summary, "particles", rp.disc->nparticles));
    MICA_CALL_CLEANUP(mica_json_int(summary, "quadrature_points", rp.disc->nquad));
    MICA_CALL_CLEANUP(mica_json_int(summary, "dofs", rp.solid->ndof));
  }
  if (o.eigen) { /* refuse what the eigen analysis cannot do before anything runs */
    int dense;
    MICA_CALL_CLEANUP(check_eigen_input(deck, rp.solid));
    MICA_CALL_CLEANUP(choose_dense(&o, deck, rp.solid->ndof, &dense));
  }
  if (need_problem && rp.fe && (o.conditioning || o.inf_sup)) { /* FE: no moment matrix, nothing to refine */
    printf("problem.method = \"fe\": no MLS moment matrix to condition and no inf-sup series (EFG only)\n");
    o.conditioning = o.inf_sup = 0;
  }
  if (o.conditioning) MICA_CALL_CLEANUP(stability_conditioning(&rp, summary));
  if (o.eigen) MICA_CALL_CLEANUP(stability_eigen(&o, &rp, outdir, summary));
  if (o.patch) MICA_CALL_CLEANUP(stability_patch(&o, &rp, summary));
  if (o.inf_sup) MICA_CALL_CLEANUP(stability_inf_sup(&o, deck, outdir, summary));
cleanup:
  if (need_problem) run_problem_free(&rp);
  stability_free_options(&o);
  return ierr;
}

const MicaCommand mica_command_stability = {
    {"stability",
     "stability and consistency of a deck's discretization: tangent eigenmodes, patch tests, inf-sup, MLS conditioning",
     0, NULL, NULL},
    "On the run deck as it stands (its particles, MLS, quadrature, boundary method, VCI): (1) eigenvalues of the\n"
    "tangent at u = 0 with the deck's conditions (a free body without them): zero modes, rigid modes (the span of\n"
    "the exact rigid motions), spurious zero modes = zero − rigid, low-energy modes (below the lowest nonzero\n"
    "eigenvalue of the same particles and MLS on Gauss cells, with less than stability.low_energy_ratio of the\n"
    "energy that rule gives them), the lowest nonzero eigenvalue; eigenvalues.csv, spectrum.png and VTU files of\n"
    "the spurious, low-energy and lowest nonzero modes; (2) linear and quadratic patch tests with\n"
    "the exact field prescribed on the whole boundary; (3) the numerical inf-sup test of Chapelle & Bathe over\n"
    "stability.inf_sup_counts (inf_sup.csv, inf_sup.png); (4) the condition number of the MLS moment matrix at\n"
    "every volume quadrature point. Settings: the `stability` group (docs/input.md).",
    mica_run_schema,
    stability_run,
};
