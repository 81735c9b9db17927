/* Finite elements as an approximation (the ops table of mica/solid.h): shape caches whose supports are the
 * element's nodes, N and ∇N from the reference element and the isoparametric map. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mica/fe.h"

static int cache_alloc(int dim, long npoints, long nnz, const double *x, MicaShapeCache **out) {
  MicaShapeCache *c = NULL;
  const int ierr = mica_shape_cache_alloc(dim, npoints, nnz, 0, &c);
  if (ierr) {
    mica_shape_cache_destroy(&c);
    return ierr;
  }
  memcpy(c->x, x, sizeof(double) * (size_t)(npoints * dim));
  *out = c;
  return MICA_SUCCESS;
}

static int check_order(int order) {
  MICA_CHECK(order <= 1, MICA_ERR_INPUT,
             "finite elements are C0: they have no second derivatives for a second-gradient model; use problem.method "
             "= \"efg\"");
  return MICA_SUCCESS;
}

/* One point: its element (given or found), reference coordinates, N and ∇N of the element's nodes. */
static int point_shape(const MicaFe *fe, const double *x, long given, long p, MicaShapeCache *c) {
  const int dim = fe->dim, nen = fe->nen;
  double xi[3], excess = 0, det, N[MICA_FE_MAX_NODES], dN[MICA_FE_MAX_NODES * 3], xe[MICA_FE_MAX_NODES * 3];
  long el = given;
  if (el < 0)
    MICA_CALL(mica_fe_locate(fe, x, &el, xi));
  else
    MICA_CALL(mica_fe_inverse_map(fe, el, x, xi, &excess));
  MICA_CHECK(excess <= 1e-8, MICA_ERR_ARGUMENT,
             "the point (%g, %g, %g) does not lie in its element %ld (ξ off by %g)", x[0], x[1],
             dim == 3 ? x[2] : 0.0, el + 1, excess);
  const long *nodes = fe->conn + el * nen;
  for (int a = 0; a < nen; a++) memcpy(xe + a * dim, fe->x + nodes[a] * dim, sizeof(double) * (size_t)dim);
  mica_fe_reference_eval(dim, fe->order, xi, N, dN);
  const long start = p * nen;
  MICA_CALL(mica_fe_gradients(dim, nen, xe, dN, NULL, &det, c->dN + start * dim));
  for (int a = 0; a < nen; a++) c->index[start + a] = nodes[a], c->N[start + a] = N[a];
  c->ptr[p + 1] = start + nen;
  return MICA_SUCCESS;
}

static int fe_points(const void *ctx, long npoints, const double *x, const long *cell, int order, const char *label,
                     MicaShapeCache **out) {
  const MicaFe *fe = ctx;
  MicaShapeCache *c = NULL;
  int ierr = MICA_SUCCESS;
  *out = NULL;
  MICA_CALL(check_order(order));
  MICA_CALL(cache_alloc(fe->dim, npoints, npoints * fe->nen, x, &c));
  c->max_support = fe->nen;
  for (long p = 0; p < npoints; p++) {
    ierr = point_shape(fe, x + p * fe->dim, cell ? cell[p] : -1, p, c);
    if (ierr) {
      mica_error_prefix("%s point %ld of %ld", label, p + 1, npoints);
      goto cleanup;
    }
  }
  *out = c;
  c = NULL;
cleanup:
  mica_shape_cache_destroy(&c);
  return ierr;
}

/* ---- at the nodes: N = δ, ∇N averaged over the elements around the node ---- */

typedef struct {
  long node;
  double g[3];
} Entry;

static int compare_entry(const void *a, const void *b) {
  const long x = ((const Entry *)a)->node, y = ((const Entry *)b)->node;
  return (x > y) - (x < y);
}

/* The entries of node i: the union of its elements' nodes with the averaged gradients, ascending. */
static int node_entries(const MicaFe *fe, long i, Entry *entries, int *nentries) {
  const int dim = fe->dim, nen = fe->nen, p = fe->order;
  long idx[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, rest = i;
  for (int d = 0; d < dim; d++) {
    idx[d] = rest % fe->count[d], rest /= fe->count[d];
    lo[d] = idx[d] >= p ? (idx[d] - 1) / p : 0; /* elements e with e p ≤ idx ≤ e p + p */
    hi[d] = idx[d] / p < fe->nel[d] ? idx[d] / p : fe->nel[d] - 1;
  }
  int n = 0, nadj = 0;
  for (long e2 = lo[2]; e2 <= hi[2]; e2++)
    for (long e1 = lo[1]; e1 <= hi[1]; e1++)
      for (long e0 = lo[0]; e0 <= hi[0]; e0++) {
        const long e[3] = {e0, e1, e2}, el = e0 + fe->nel[0] * (e1 + fe->nel[1] * e2);
        double xi[3] = {0, 0, 0}, N[MICA_FE_MAX_NODES], dN[MICA_FE_MAX_NODES * 3], dNdx[MICA_FE_MAX_NODES * 3],
               xe[MICA_FE_MAX_NODES * 3], det;
        for (int d = 0; d < dim; d++) xi[d] = -1 + 2.0 * (double)(idx[d] - e[d] * p) / p;
        const long *nodes = fe->conn + el * nen;
        for (int a = 0; a < nen; a++) memcpy(xe + a * dim, fe->x + nodes[a] * dim, sizeof(double) * (size_t)dim);
        mica_fe_reference_eval(dim, p, xi, N, dN);
        MICA_CALL(mica_fe_gradients(dim, nen, xe, dN, NULL, &det, dNdx));
        nadj++;
        for (int a = 0; a < nen; a++) {
          int k = 0;
          while (k < n && entries[k].node != nodes[a]) k++;
          if (k == n) entries[n++] = (Entry){nodes[a], {0, 0, 0}};
          for (int d = 0; d < dim; d++) entries[k].g[d] += dNdx[a * dim + d];
        }
      }
  for (int k = 0; k < n; k++)
    for (int d = 0; d < dim; d++) entries[k].g[d] /= nadj;
  qsort(entries, (size_t)n, sizeof *entries, compare_entry);
  *nentries = n;
  return MICA_SUCCESS;
}

static int fe_particles(const void *ctx, int order, MicaShapeCache **out) {
  const MicaFe *fe = ctx;
  const int dim = fe->dim;
  Entry entries[8 * MICA_FE_MAX_NODES];
  MicaShapeCache *c = NULL;
  int ierr = MICA_SUCCESS;
  *out = NULL;
  MICA_CALL(check_order(order));
  long nnz = 0; /* counted first */
  for (long i = 0; i < fe->nnodes; i++) {
    int n;
    MICA_CALL(node_entries(fe, i, entries, &n));
    nnz += n;
  }
  MICA_CALL(cache_alloc(dim, fe->nnodes, nnz, fe->x, &c));
  for (long i = 0; i < fe->nnodes; i++) {
    int n;
    MICA_CALL_CLEANUP(node_entries(fe, i, entries, &n));
    const long start = c->ptr[i];
    for (int k = 0; k < n; k++) {
      c->index[start + k] = entries[k].node;
      c->N[start + k] = entries[k].node == i; /* interpolation: N_I(x_J) = δ_IJ */
      for (int d = 0; d < dim; d++) c->dN[(start + k) * dim + d] = entries[k].g[d];
    }
    c->ptr[i + 1] = start + n;
    if (n > c->max_support) c->max_support = n;
  }
  *out = c;
  return MICA_SUCCESS;
cleanup:
  mica_shape_cache_destroy(&c);
  return ierr;
}

static const double *fe_spacing(const void *ctx) { return ((const MicaFe *)ctx)->spacing; }

const MicaApproxOps mica_approx_fe = {
    {"fe", "Lagrange finite elements (Q1 / hex8, Q2 / hex27) on the particles, C⁰: the baseline",
     MICA_APPROX_INTERPOLATING, NULL, NULL},
    1, fe_points, fe_particles, fe_spacing};

/* The registry lists both built-in approximations, so it lives in the higher of their folders: src/fe uses
 * src/assemble (the shape cache), never the reverse (tests/cli/layering.sh). */
static const MicaType *const builtin_approximations[] = {&mica_approx_mls.type, &mica_approx_fe.type, NULL};

MicaRegistry mica_approx_registry = {"approximation", "efg", builtin_approximations, NULL, 0, NULL};
