/* Setting up an MLS approximation: options, particles, supports and their radii (docs/theory.md §MLS).
 * The evaluation at a point is in shape.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mls_private.h"

/* ---- options and setup ---------------------------------------------------------------------------- */

void mls_options_default(MlsOptions *opt) {
  memset(opt, 0, sizeof *opt);
  opt->basis = mls_basis_of(mica_registry_default(&mls_basis_registry));
  opt->order = (int)mica_schema_default_number(mls_keys, "order");
  opt->weight = mls_weight_of(mica_registry_default(&mls_weight_registry));
  opt->support = (MlsSupportKind)mls_kind_value(mica_registry_default(&mls_support_registry));
  opt->dilation = mls_default_dilation(opt->order);
  opt->alpha = mica_schema_default_number(mls_weight_exponential.type.keys, "alpha");
  opt->rcond_min = mica_schema_default_number(mls_keys, "rcond_min");
  opt->search = (MlsSearchKind)mls_kind_value(mica_registry_default(&mls_search_registry));
  opt->spacing = (MlsSpacingRule)mls_kind_value(mica_registry_default(&mls_spacing_registry));
}

static int check_options(int dim, long n, const MlsOptions *opt) {
  MICA_CHECK(dim >= 1 && dim <= MLS_MAX_DIM, MICA_ERR_ARGUMENT, "MLS dimension %d is not 1, 2 or 3", dim);
  MICA_CHECK(n >= 1, MICA_ERR_ARGUMENT, "MLS needs at least one particle");
  MICA_CHECK(opt->basis && opt->weight, MICA_ERR_ARGUMENT, "MLS options need a basis and a weight");
  MICA_CHECK(opt->order >= opt->basis->min_order && opt->order <= opt->basis->max_order, MICA_ERR_INPUT,
             "the %s basis has orders %d to %d, not %d", opt->basis->type.name, opt->basis->min_order,
             opt->basis->max_order, opt->order);
  MICA_CHECK(opt->basis->size(dim, opt->order) <= MLS_MAX_TERMS, MICA_ERR_ARGUMENT, "basis too large");
  MICA_CHECK(opt->support == MLS_SUPPORT_BOX || opt->support == MLS_SUPPORT_BALL, MICA_ERR_ARGUMENT,
             "unknown support kind %d", (int)opt->support);
  if (opt->dilation <= 0)
    MICA_CHECK(opt->radius[0] > 0, MICA_ERR_INPUT, "MLS support radius must be positive, not %g",
               opt->radius[0]);
  if (opt->dilation > 0 || mica_type_has(&opt->weight->type, MLS_WEIGHT_ADAPTIVE))
    MICA_CHECK(n >= 2, MICA_ERR_INPUT,
               "a radius given as a dilation of the local spacing needs at least two particles");
  MICA_CHECK(!mica_type_has(&opt->weight->type, MLS_WEIGHT_ADAPTIVE) || opt->alpha > 0, MICA_ERR_INPUT,
             "the exponential weight needs alpha > 0, not %g", opt->alpha);
  return MICA_SUCCESS;
}

/* ρ_id from the options: absolute per axis (an unset axis repeats axis 0), or dilation × spacing. */
static void set_radii_from_options(MlsApprox *mls) {
  const int dim = mls->dim;
  for (long i = 0; i < mls->n; i++) {
    const double *h = mls->spacing + i * dim;
    double hmax = 0;
    for (int d = 0; d < dim; d++) hmax = fmax(hmax, h[d]);
    for (int d = 0; d < dim; d++) {
      double r;
      if (mls->opt.dilation > 0)
        r = mls->opt.dilation * (mls->opt.support == MLS_SUPPORT_BALL ? hmax : h[d]);
      else
        r = (mls->opt.support == MLS_SUPPORT_BOX && mls->opt.radius[d] > 0) ? mls->opt.radius[d]
                                                                             : mls->opt.radius[0];
      mls->radii[i * dim + d] = r;
    }
  }
}

/* The exponential weight's shape parameter ρ_id / c_i (eqs 3.33-3.36). Eq 3.35 takes c_i as the largest
 * distance from x_i to the particles J whose supports contain x_i and the evaluation point x; we drop the
 * dependence on x (which would make w jump as x moves) and use all J whose supports contain x_i, times α
 * (eq 3.34). Needs the supports to be set in the search. */
static int set_weight_params(MlsApprox *mls) {
  const int dim = mls->dim;
  if (!mica_type_has(&mls->opt.weight->type, MLS_WEIGHT_ADAPTIVE)) {
    for (long i = 0; i < mls->n * dim; i++) mls->wparam[i] = 1.0;
    return MICA_SUCCESS;
  }
  long *index = NULL, count = 0, cap = 0;
  for (long i = 0; i < mls->n; i++) {
    const double *xi = mls->x + i * dim;
    int ierr = mls_search_query(mls->search, xi, &index, &count, &cap);
    if (ierr) {
      free(index);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
    double cmax = 0;
    for (long k = 0; k < count; k++) {
      double dist2 = 0;
      for (int d = 0; d < dim; d++) dist2 += (mls->x[index[k] * dim + d] - xi[d]) * (mls->x[index[k] * dim + d] - xi[d]);
      cmax = fmax(cmax, sqrt(dist2));
    }
    if (cmax == 0)
      for (int d = 0; d < dim; d++) cmax = fmax(cmax, mls->radii[i * dim + d]);
    const double c = mls->opt.alpha * cmax;
    for (int d = 0; d < dim; d++) mls->wparam[i * dim + d] = mls->radii[i * dim + d] / c;
  }
  free(index);
  return MICA_SUCCESS;
}

/* The local spacing by the rule, on the particles or on opt->spacing_points (a search of its own); with
 * opt->spacing_index, particle I takes the spacing of point spacing_index[I]. */
static int local_spacing(MlsApprox *mls, const MlsOptions *opt) {
  if (!opt->spacing_points) return mls_search_local_spacing_rule(mls->search, opt->spacing, mls->spacing);
  const int dim = mls->dim;
  const long count = opt->spacing_count > 0 ? opt->spacing_count : mls->n;
  MICA_CHECK(opt->spacing_index || count == mls->n, MICA_ERR_ARGUMENT,
             "mls_create: %ld spacing points for %ld particles and no spacing_index", count, mls->n);
  MICA_CHECK(count >= 2, MICA_ERR_INPUT, "local spacing: %ld spacing points, need at least two", count);
  for (long i = 0; opt->spacing_index && i < mls->n; i++)
    MICA_CHECK(opt->spacing_index[i] >= 0 && opt->spacing_index[i] < count, MICA_ERR_ARGUMENT,
               "mls_create: spacing_index[%ld] = %ld is not in [0, %ld)", i, opt->spacing_index[i], count);
  MlsSearch *grid = NULL;
  double *h = mls->spacing;
  int ierr = MICA_SUCCESS;
  if (opt->spacing_index) MICA_CALL(MICA_MALLOC(h, count * dim));
  MICA_CALL_CLEANUP(mls_search_create(dim, count, opt->spacing_points, opt->search, &grid));
  MICA_CALL_CLEANUP(mls_search_local_spacing_rule(grid, opt->spacing, h));
  if (opt->spacing_index)
    for (long i = 0; i < mls->n; i++)
      for (int d = 0; d < dim; d++) mls->spacing[i * dim + d] = h[opt->spacing_index[i] * dim + d];
cleanup:
  mls_search_destroy(&grid);
  if (h != mls->spacing) MICA_FREE(h);
  return ierr;
}

int mls_create(int dim, long n, const double *x, const MlsOptions *opt, MlsApprox **out) {
  *out = NULL;
  MICA_CALL(check_options(dim, n, opt));
  MlsApprox *mls;
  MICA_CALL(MICA_CALLOC(mls, 1));
  int ierr = MICA_SUCCESS;
  mls->dim = dim;
  mls->n = n;
  mls->opt = *opt;
  mls->opt.spacing_points = NULL; /* not kept: the caller's arrays */
  mls->opt.spacing_index = NULL;
  mls->m = opt->basis->size(dim, opt->order);
  MICA_CALL_CLEANUP(MICA_MALLOC(mls->x, n * dim));
  MICA_CALL_CLEANUP(MICA_CALLOC(mls->radii, n * dim));
  MICA_CALL_CLEANUP(MICA_CALLOC(mls->spacing, n * dim));
  MICA_CALL_CLEANUP(MICA_CALLOC(mls->wparam, n * dim));
  memcpy(mls->x, x, sizeof(double) * (size_t)(n * dim));
  double zero[MLS_MAX_DIM] = {0};
  opt->basis->eval(dim, opt->order, zero, mls->p0, mls->dp0, mls->ddp0);
  MICA_CALL_CLEANUP(mls_search_create(dim, n, x, opt->search, &mls->search));
  if (n >= 2) MICA_CALL_CLEANUP(local_spacing(mls, opt));
  set_radii_from_options(mls);
  MICA_CALL_CLEANUP(mls_set_radii(mls, mls->radii));
  *out = mls;
  return MICA_SUCCESS;
cleanup:
  mls_destroy(&mls);
  return ierr;
}

int mls_destroy(MlsApprox **mls) {
  if (!*mls) return MICA_SUCCESS;
  mls_search_destroy(&(*mls)->search);
  MICA_FREE((*mls)->x);
  MICA_FREE((*mls)->radii);
  MICA_FREE((*mls)->spacing);
  MICA_FREE((*mls)->wparam);
  MICA_FREE(*mls);
  return MICA_SUCCESS;
}

const MlsSearch *mls_search(const MlsApprox *mls) { return mls->search; }
MlsSupportKind mls_support_kind(const MlsApprox *mls) { return mls->opt.support; }

int mls_set_radii(MlsApprox *mls, const double *radii) {
  const long count = mls->n * mls->dim;
  for (long i = 0; i < count; i++)
    MICA_CHECK(radii[i] > 0 && isfinite(radii[i]), MICA_ERR_INPUT,
               "support radius of particle %ld is %g; radii must be positive", i / mls->dim, radii[i]);
  if (radii != mls->radii) memcpy(mls->radii, radii, sizeof(double) * (size_t)count);
  MICA_CALL(mls_search_set_supports(mls->search, mls->opt.support, mls->radii));
  MICA_CALL(set_weight_params(mls));
  return MICA_SUCCESS;
}

int mls_set_spacing(MlsApprox *mls, const double *spacing) {
  const long count = mls->n * mls->dim;
  for (long i = 0; i < count; i++)
    MICA_CHECK(spacing[i] >= 0 && isfinite(spacing[i]), MICA_ERR_ARGUMENT, "spacing of particle %ld is %g",
               i / mls->dim, spacing[i]);
  memcpy(mls->spacing, spacing, sizeof(double) * (size_t)count);
  return MICA_SUCCESS;
}

int mls_set_weight_params(MlsApprox *mls, const double *wparam) {
  const long count = mls->n * mls->dim;
  for (long i = 0; i < count; i++)
    MICA_CHECK(wparam[i] > 0 && isfinite(wparam[i]), MICA_ERR_ARGUMENT, "weight parameter of particle %ld is %g",
               i / mls->dim, wparam[i]);
  memcpy(mls->wparam, wparam, sizeof(double) * (size_t)count);
  return MICA_SUCCESS;
}

const double *mls_weight_params(const MlsApprox *mls) { return mls->wparam; }

int mls_dim(const MlsApprox *mls) { return mls->dim; }
long mls_num_particles(const MlsApprox *mls) { return mls->n; }
int mls_num_terms(const MlsApprox *mls) { return mls->m; }
const double *mls_particles(const MlsApprox *mls) { return mls->x; }
const double *mls_radii(const MlsApprox *mls) { return mls->radii; }
const MlsOptions *mls_options(const MlsApprox *mls) { return &mls->opt; }
const double *mls_spacing(const MlsApprox *mls) { return mls->spacing; }

