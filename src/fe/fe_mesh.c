/* The finite-element mesh on the logical grid of a structured particle layout, point location, and the
 * finite-element discretization (element Gauss points; boundary sets on element faces). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/fe.h"
#include "mica/sort.h"

/* ---- the mesh ---- */

/* Global node of local node a of element (e_0, e_1, e_2). */
static long element_node(const MicaFe *fe, const long e[3], int a) {
  long g = 0, stride = 1;
  for (int d = 0; d < fe->dim; d++, a /= fe->order + 1) {
    g += (e[d] * fe->order + a % (fe->order + 1)) * stride;
    stride *= fe->count[d];
  }
  return g;
}

static void element_index(const MicaFe *fe, long el, long e[3]) {
  e[0] = e[1] = e[2] = 0;
  for (int d = 0; d < fe->dim; d++) {
    e[d] = el % fe->nel[d];
    el /= fe->nel[d];
  }
}

static void element_coordinates(const MicaFe *fe, long el, double *xe) {
  for (int a = 0; a < fe->nen; a++)
    memcpy(xe + a * fe->dim, fe->x + fe->conn[el * fe->nen + a] * fe->dim, sizeof(double) * (size_t)fe->dim);
}

/* Bounding boxes padded by a quarter of their size (a Q2 element bulges past its nodes), and the spacing. */
static void boxes_and_spacing(MicaFe *fe) {
  const int dim = fe->dim;
  for (long i = 0; i < fe->nnodes * dim; i++) fe->spacing[i] = 0;
  for (long el = 0; el < fe->nelements; el++) {
    double *lo = fe->box + el * 2 * dim, *hi = lo + dim;
    for (int d = 0; d < dim; d++) lo[d] = INFINITY, hi[d] = -INFINITY;
    for (int a = 0; a < fe->nen; a++) {
      const double *xa = fe->x + fe->conn[el * fe->nen + a] * dim;
      for (int d = 0; d < dim; d++) lo[d] = fmin(lo[d], xa[d]), hi[d] = fmax(hi[d], xa[d]);
    }
    for (int d = 0; d < dim; d++) {
      const double width = hi[d] - lo[d];
      for (int a = 0; a < fe->nen; a++) {
        double *h = fe->spacing + fe->conn[el * fe->nen + a] * dim + d;
        *h = fmax(*h, width / fe->order);
      }
      lo[d] -= 0.25 * width, hi[d] += 0.25 * width;
    }
  }
}

int mica_fe_create(int dim, int order, const long count[3], long nnodes, const double *x, MicaFe **out) {
  *out = NULL;
  MICA_CHECK((dim == 2 || dim == 3) && (order == 1 || order == 2), MICA_ERR_ARGUMENT,
             "finite elements: dim %d, order %d (need 2 or 3, and 1 or 2)", dim, order);
  long total = 1;
  for (int d = 0; d < dim; d++) {
    MICA_CHECK(count[d] >= 2, MICA_ERR_INPUT, "finite elements: %ld nodes along axis %d, need at least 2", count[d],
               d);
    MICA_CHECK(order == 1 || count[d] % 2 == 1, MICA_ERR_INPUT,
               "finite elements of order 2 need an odd number of nodes per axis (elements of 3 nodes); axis %d has "
               "%ld", d, count[d]);
    total *= count[d];
  }
  MICA_CHECK(total == nnodes, MICA_ERR_INPUT,
             "finite elements need the particles on a logical grid of %ld nodes; there are %ld particles", total,
             nnodes);
  MicaFe *fe = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(fe, 1));
  fe->dim = dim, fe->order = order, fe->nen = mica_fe_element_nodes(dim, order);
  fe->nnodes = nnodes;
  fe->nelements = 1;
  for (int d = 0; d < 3; d++) {
    fe->count[d] = d < dim ? count[d] : 1;
    fe->nel[d] = d < dim ? (count[d] - 1) / order : 1;
    fe->nelements *= fe->nel[d];
  }
  MICA_CALL_CLEANUP(MICA_MALLOC(fe->x, nnodes * dim));
  memcpy(fe->x, x, sizeof(double) * (size_t)(nnodes * dim));
  MICA_CALL_CLEANUP(MICA_MALLOC(fe->conn, fe->nelements * fe->nen));
  MICA_CALL_CLEANUP(MICA_MALLOC(fe->box, fe->nelements * 2 * dim));
  MICA_CALL_CLEANUP(MICA_MALLOC(fe->spacing, nnodes * dim));
  for (long el = 0; el < fe->nelements; el++) {
    long e[3];
    element_index(fe, el, e);
    for (int a = 0; a < fe->nen; a++) fe->conn[el * fe->nen + a] = element_node(fe, e, a);
  }
  boxes_and_spacing(fe);
  *out = fe;
  return MICA_SUCCESS;
cleanup:
  mica_fe_destroy(&fe);
  return ierr;
}

int mica_fe_destroy(MicaFe **fe) {
  if (!fe || !*fe) return MICA_SUCCESS;
  MICA_FREE((*fe)->x);
  MICA_FREE((*fe)->conn);
  MICA_FREE((*fe)->box);
  MICA_FREE((*fe)->spacing);
  MICA_FREE(*fe);
  return MICA_SUCCESS;
}

/* ---- point location ---- */

/* Residual r = x(ξ) − x and its max norm. */
static double map_residual(const MicaFe *fe, const double *xe, const double *xi, const double *x, double *r,
                           double *dN) {
  double N[MICA_FE_MAX_NODES], norm = 0;
  mica_fe_reference_eval(fe->dim, fe->order, xi, N, dN);
  for (int d = 0; d < fe->dim; d++) {
    r[d] = -x[d];
    for (int a = 0; a < fe->nen; a++) r[d] += N[a] * xe[a * fe->dim + d];
    norm = fmax(norm, fabs(r[d]));
  }
  return norm;
}

/* Damped Newton on x(ξ) = x from the start in xi; returns the final residual norm in *norm. */
static int newton(const MicaFe *fe, const double *xe, const double *x, double scale, double *xi, double *norm) {
  const int dim = fe->dim, nen = fe->nen;
  double dN[MICA_FE_MAX_NODES * 3], J[9], dNdx[MICA_FE_MAX_NODES * 3], r[3];
  *norm = map_residual(fe, xe, xi, x, r, dN);
  for (int it = 0; it < 50 && *norm > 1e-14 * scale; it++) {
    double det, step[3] = {0, 0, 0}, col[3];
    if (mica_fe_gradients(dim, nen, xe, dN, J, &det, dNdx)) { /* a singular point of the map: give up here */
      mica_error_clear();
      return MICA_SUCCESS;
    }
    for (int j = 0; j < dim; j++) { /* Δξ = −J⁻¹ r, (J⁻¹)_jd = cof(J)_dj / det */
      mica_fe_cofactor_column(dim, J, j, col);
      for (int d = 0; d < dim; d++) step[j] -= col[d] * r[d] / det;
    }
    /* backtracking: halve the step until the residual decreases */
    double trial[3], rt[3], dNt[MICA_FE_MAX_NODES * 3], tnorm = INFINITY, lambda = 1;
    for (int cut = 0; cut < 30; cut++, lambda *= 0.5) {
      for (int d = 0; d < dim; d++) trial[d] = xi[d] + lambda * step[d];
      tnorm = map_residual(fe, xe, trial, x, rt, dNt);
      if (tnorm < *norm) break;
    }
    if (!(tnorm < *norm)) break; /* stalled at round-off */
    memcpy(xi, trial, sizeof(double) * (size_t)dim);
    memcpy(r, rt, sizeof r);
    memcpy(dN, dNt, sizeof(double) * (size_t)(dim * nen));
    *norm = tnorm;
  }
  return MICA_SUCCESS;
}

static double outside(int dim, const double *xi) {
  double e = 0;
  for (int d = 0; d < dim; d++) e = fmax(e, fabs(xi[d]) - 1);
  return e;
}

int mica_fe_inverse_map(const MicaFe *fe, long el, const double *x, double *xi, double *excess) {
  const int dim = fe->dim, nen = fe->nen;
  double xe[MICA_FE_MAX_NODES * 3], xin[MICA_FE_MAX_NODES * 3];
  element_coordinates(fe, el, xe);
  double scale = 0;
  for (int d = 0; d < dim; d++) scale = fmax(scale, fe->box[el * 2 * dim + dim + d] - fe->box[el * 2 * dim + d]);
  mica_fe_reference_nodes(dim, fe->order, xin);
  /* Starts: the node nearest to x, the center, then every node. A curved Q2 element's map is not injective
   * beyond [−1, 1]^dim, and Newton may find a preimage outside; another start finds the one inside. */
  int order_of_starts[MICA_FE_MAX_NODES + 2], nstarts = 0, nearest = 0;
  double best_r2 = INFINITY;
  for (int a = 0; a < nen; a++) {
    double r2 = 0;
    for (int d = 0; d < dim; d++) r2 += (xe[a * dim + d] - x[d]) * (xe[a * dim + d] - x[d]);
    if (r2 < best_r2) best_r2 = r2, nearest = a;
  }
  order_of_starts[nstarts++] = nearest;
  order_of_starts[nstarts++] = -1;
  for (int a = 0; a < nen; a++)
    if (a != nearest) order_of_starts[nstarts++] = a;
  double best = INFINITY;
  for (int k = 0; k < nstarts; k++) {
    double trial[3] = {0, 0, 0}, norm;
    if (order_of_starts[k] >= 0) memcpy(trial, xin + order_of_starts[k] * dim, sizeof(double) * (size_t)dim);
    MICA_CALL(newton(fe, xe, x, scale, trial, &norm));
    const double e = norm > 1e-10 * scale ? INFINITY : outside(dim, trial);
    if (e < best) best = e, memcpy(xi, trial, sizeof(double) * (size_t)dim);
    if (best <= 1e-12) break;
  }
  if (best == INFINITY) memset(xi, 0, sizeof(double) * (size_t)dim);
  *excess = best;
  return MICA_SUCCESS;
}

int mica_fe_locate(const MicaFe *fe, const double *x, long *element, double *xi) {
  const int dim = fe->dim;
  double best = INFINITY, trial[3];
  *element = -1;
  for (long el = 0; el < fe->nelements; el++) {
    const double *lo = fe->box + el * 2 * dim, *hi = lo + dim;
    int inside = 1;
    for (int d = 0; d < dim; d++) inside &= x[d] >= lo[d] && x[d] <= hi[d];
    if (!inside) continue;
    double excess;
    if (mica_fe_inverse_map(fe, el, x, trial, &excess)) {
      mica_error_clear();
      continue;
    }
    if (excess < best) {
      best = excess, *element = el;
      memcpy(xi, trial, sizeof(double) * (size_t)dim);
    }
    if (excess <= 1e-10) break;
  }
  MICA_CHECK(*element >= 0 && best <= MICA_FE_OUTSIDE, MICA_ERR_INPUT,
             "the point (%g, %g, %g) lies in no finite element", x[0], x[1], dim == 3 ? x[2] : 0.0);
  return MICA_SUCCESS;
}

/* ---- the discretization: volume ---- */

static int volume_points(const MicaFe *fe, int order, MicaDiscretization *disc) {
  const int dim = fe->dim, nen = fe->nen;
  double g[64], gw[64], xe[MICA_FE_MAX_NODES * 3], N[MICA_FE_MAX_NODES], dN[MICA_FE_MAX_NODES * 3],
      dNdx[MICA_FE_MAX_NODES * 3];
  MICA_CHECK(order >= 1 && order <= 64, MICA_ERR_INPUT, "quadrature.order = %d outside [1, 64]", order);
  MICA_CALL(mica_gauss_legendre(order, g, gw));
  long per = 1;
  for (int d = 0; d < dim; d++) per *= order;
  disc->ncells = fe->nelements;
  disc->nquad = fe->nelements * per;
  MICA_CALL(MICA_MALLOC(disc->qx, disc->nquad * dim));
  MICA_CALL(MICA_MALLOC(disc->qw, disc->nquad));
  MICA_CALL(MICA_MALLOC(disc->qcell, disc->nquad));
  double orientation = 0;
  disc->volume = 0;
  for (long el = 0, q = 0; el < fe->nelements; el++) {
    element_coordinates(fe, el, xe);
    for (long k = 0; k < per; k++, q++) {
      double xi[3] = {0, 0, 0}, w = 1, det;
      for (int d = 0, rest = (int)k; d < dim; d++, rest /= order) xi[d] = g[rest % order], w *= gw[rest % order];
      mica_fe_reference_eval(dim, fe->order, xi, N, dN);
      int ierr = mica_fe_gradients(dim, nen, xe, dN, NULL, &det, dNdx);
      if (orientation == 0) orientation = det > 0 ? 1 : -1;
      if (ierr || !(det * orientation > 0)) {
        mica_error_clear();
        MICA_ERROR(MICA_ERR_INPUT,
                   "finite element %ld is inverted or degenerate at a Gauss point (det J = %g): lower particles.jitter "
                   "or the grading", el + 1, det);
      }
      for (int d = 0; d < dim; d++) {
        double s = 0;
        for (int a = 0; a < nen; a++) s += N[a] * xe[a * dim + d];
        disc->qx[q * dim + d] = s;
      }
      disc->qw[q] = w * fabs(det);
      disc->qcell[q] = el;
      disc->volume += disc->qw[q];
    }
  }
  return MICA_SUCCESS;
}

/* ---- the discretization: boundary faces ---- */

/* A boundary face: element el, face axis a, side 0 (ξ_a = −1) or 1 (ξ_a = +1). */
typedef struct {
  long el;
  int axis, side, set;
} Face;

/* The tangential axes of a face, cyclic in 3-D so that ∂x/∂ξ_t0 × ∂x/∂ξ_t1 ∥ cof(J) e_a (as src/geom). */
static void tangent_axes(int dim, int a, int t[2]) {
  if (dim == 2) t[0] = 1 - a, t[1] = -1;
  else t[0] = (a + 1) % 3, t[1] = (a + 2) % 3;
}

static long count_faces(const MicaFe *fe) {
  long n = 0;
  for (int a = 0; a < fe->dim; a++) n += 2 * fe->nelements / fe->nel[a];
  return n;
}

static void list_faces(const MicaFe *fe, Face *faces) {
  long n = 0;
  for (int a = 0; a < fe->dim; a++)
    for (int side = 0; side < 2; side++)
      for (long el = 0; el < fe->nelements; el++) {
        long e[3];
        element_index(fe, el, e);
        if (e[a] == (side ? fe->nel[a] - 1 : 0)) faces[n++] = (Face){el, a, side, -1};
      }
}

/* Position x (and J) at reference point xi of element el. */
static void map_point(const MicaFe *fe, long el, const double *xi, double *x, double *J) {
  const int dim = fe->dim, nen = fe->nen;
  double xe[MICA_FE_MAX_NODES * 3], N[MICA_FE_MAX_NODES], dN[MICA_FE_MAX_NODES * 3];
  element_coordinates(fe, el, xe);
  mica_fe_reference_eval(dim, fe->order, xi, N, dN);
  for (int i = 0; i < dim; i++) {
    x[i] = 0;
    for (int a = 0; a < nen; a++) x[i] += N[a] * xe[a * dim + i];
    if (J)
      for (int j = 0; j < dim; j++) {
        double s = 0;
        for (int a = 0; a < nen; a++) s += xe[a * dim + i] * dN[j * nen + a];
        J[i * dim + j] = s;
      }
  }
}

static void face_center(const MicaFe *fe, const Face *f, double *x) {
  double xi[3] = {0, 0, 0};
  xi[f->axis] = f->side ? 1 : -1;
  map_point(fe, f->el, xi, x, NULL);
}

/* Each face goes to the set of `like` whose boundary element (center of its points) is nearest. */
static int assign_faces(const MicaFe *fe, const MicaDiscretization *like, long nfaces, Face *faces) {
  const int dim = fe->dim;
  long ncenters = 0;
  for (int s = 0; s < like->nsets; s++) ncenters += like->sets[s].nelements;
  double *center = NULL, *count = NULL;
  int *owner = NULL, ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(center, ncenters * dim + 1));
  MICA_CALL_CLEANUP(MICA_CALLOC(count, ncenters + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(owner, ncenters + 1));
  for (int s = 0, base = 0; s < like->nsets; base += (int)like->sets[s].nelements, s++) {
    const MicaBoundarySet *set = &like->sets[s];
    for (long e = 0; e < set->nelements; e++) owner[base + e] = s;
    for (long p = 0; p < set->n; p++) {
      const long e = base + set->element[p];
      for (int d = 0; d < dim; d++) center[e * dim + d] += set->x[p * dim + d];
      count[e] += 1;
    }
  }
  for (long e = 0; e < ncenters; e++)
    for (int d = 0; d < dim; d++) center[e * dim + d] /= count[e] > 0 ? count[e] : 1;
  for (long f = 0; f < nfaces; f++) {
    double x[3], best = INFINITY;
    face_center(fe, &faces[f], x);
    for (long e = 0; e < ncenters; e++) {
      double r2 = 0;
      for (int d = 0; d < dim; d++) r2 += (x[d] - center[e * dim + d]) * (x[d] - center[e * dim + d]);
      if (r2 < best) best = r2, faces[f].set = owner[e];
    }
  }
cleanup:
  MICA_FREE(center);
  MICA_FREE(count);
  MICA_FREE(owner);
  return ierr;
}

/* Corner k of a face (2-D: (0), (1) along t0; 3-D: (0,0), (1,0), (1,1), (0,1) in (t0, t1)): its global node. */
static long face_corner(const MicaFe *fe, const Face *f, int k) {
  static const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
  int t[2], local[3] = {0, 0, 0};
  tangent_axes(fe->dim, f->axis, t);
  local[f->axis] = f->side ? fe->order : 0;
  local[t[0]] = di[k] * fe->order;
  if (t[1] >= 0) local[t[1]] = dj[k] * fe->order;
  const int n1 = fe->order + 1, a = local[0] + n1 * (local[1] + n1 * local[2]);
  return fe->conn[f->el * fe->nen + a];
}

/* Gauss points of one face into set (from point *q on), Nanson's formula for weights and normals. */
static void face_points(const MicaFe *fe, const Face *f, long element, int order, const double *g, const double *gw,
                        double orientation, MicaBoundarySet *set, long *q) {
  const int dim = fe->dim;
  int t[2];
  tangent_axes(dim, f->axis, t);
  const long npts = dim == 2 ? order : (long)order * order;
  for (long k = 0; k < npts; k++, (*q)++) {
    const int gs = (int)(k % order), gt = (int)(k / order);
    double xi[3] = {0, 0, 0}, J[9], c[3];
    xi[f->axis] = f->side ? 1 : -1;
    xi[t[0]] = g[gs];
    if (t[1] >= 0) xi[t[1]] = g[gt];
    map_point(fe, f->el, xi, set->x + *q * dim, J);
    mica_fe_cofactor_column(dim, J, f->axis, c);
    double len = 0;
    for (int d = 0; d < dim; d++) len += c[d] * c[d];
    len = sqrt(len);
    set->w[*q] = gw[gs] * (dim == 2 ? 1.0 : gw[gt]) * len;
    const double sign = (f->side ? 1.0 : -1.0) * orientation;
    for (int d = 0; d < dim; d++) set->normal[*q * dim + d] = sign * c[d] / len;
    set->element[*q] = element;
    set->cell[*q] = f->el;
    const double s = 0.5 * (xi[t[0]] + 1), tt = dim == 2 ? 0 : 0.5 * (xi[t[1]] + 1);
    double *lam = set->lambda_N + *q * 4;
    if (dim == 2) lam[0] = 1 - s, lam[1] = s;
    else lam[0] = (1 - s) * (1 - tt), lam[1] = s * (1 - tt), lam[2] = s * tt, lam[3] = (1 - s) * tt;
  }
}

static int build_set(const MicaFe *fe, const Face *faces, long nfaces, int which, int order, double orientation,
                     MicaBoundarySet *set) {
  const int dim = fe->dim, esize = dim == 2 ? 2 : 4;
  double g[64], gw[64];
  MICA_CHECK(order >= 1 && order <= 64, MICA_ERR_INPUT, "quadrature.boundary_order = %d outside [1, 64]", order);
  MICA_CALL(mica_gauss_legendre(order, g, gw));
  long n = 0;
  for (long f = 0; f < nfaces; f++) n += faces[f].set == which;
  const long per = dim == 2 ? order : (long)order * order;
  set->n = n * per, set->nelements = n, set->element_size = esize;
  MICA_CALL(MICA_CALLOC(set->x, set->n * dim + 1));
  MICA_CALL(MICA_CALLOC(set->w, set->n + 1));
  MICA_CALL(MICA_CALLOC(set->normal, set->n * dim + 1));
  MICA_CALL(MICA_CALLOC(set->element, set->n + 1));
  MICA_CALL(MICA_CALLOC(set->cell, set->n + 1));
  MICA_CALL(MICA_CALLOC(set->lambda_N, set->n * 4 + 1));
  MICA_CALL(MICA_CALLOC(set->element_vertices, n * esize + 1));
  /* vertices: the distinct corner nodes, ascending */
  long *keys = NULL, nkeys = 0;
  MICA_CALL(MICA_MALLOC(keys, n * esize + 1));
  for (long f = 0; f < nfaces; f++)
    if (faces[f].set == which)
      for (int k = 0; k < esize; k++) keys[nkeys++] = face_corner(fe, &faces[f], k);
  qsort(keys, (size_t)nkeys, sizeof *keys, mica_compare_long);
  long nv = 0;
  for (long i = 0; i < nkeys; i++)
    if (nv == 0 || keys[i] != keys[nv - 1]) keys[nv++] = keys[i];
  set->nvertices = nv;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(set->vertex_x, nv * dim + 1));
  for (long v = 0; v < nv; v++) memcpy(set->vertex_x + v * dim, fe->x + keys[v] * dim, sizeof(double) * (size_t)dim);
  long element = 0, q = 0;
  for (long f = 0; f < nfaces; f++) {
    if (faces[f].set != which) continue;
    for (int k = 0; k < esize; k++) {
      const long key = face_corner(fe, &faces[f], k);
      const long *hit = bsearch(&key, keys, (size_t)nv, sizeof *keys, mica_compare_long);
      set->element_vertices[element * esize + k] = hit - keys;
    }
    face_points(fe, &faces[f], element, order, g, gw, orientation, set, &q);
    element++;
  }
cleanup:
  MICA_FREE(keys);
  return ierr;
}

static int boundary_sets(const MicaFe *fe, const MicaDiscretization *like, int order, MicaDiscretization *disc) {
  const long nfaces = count_faces(fe);
  Face *faces = NULL;
  int ierr = MICA_SUCCESS;
  /* the orientation of the map (the sign of det J), from the first volume point */
  double xi[3] = {0, 0, 0}, x[3], J[9], orientation;
  map_point(fe, 0, xi, x, J);
  orientation = (fe->dim == 2 ? J[0] * J[3] - J[1] * J[2]
                              : J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) +
                                    J[2] * (J[3] * J[7] - J[4] * J[6])) > 0
                    ? 1.0
                    : -1.0;
  MICA_CALL(MICA_MALLOC(faces, nfaces));
  list_faces(fe, faces);
  MICA_CALL_CLEANUP(assign_faces(fe, like, nfaces, faces));
  MICA_CALL_CLEANUP(MICA_CALLOC(disc->sets, like->nsets > 0 ? like->nsets : 1));
  disc->nsets = like->nsets;
  for (int s = 0; s < like->nsets; s++) {
    memcpy(disc->sets[s].name, like->sets[s].name, sizeof disc->sets[s].name);
    MICA_CALL_CLEANUP(build_set(fe, faces, nfaces, s, order, orientation, &disc->sets[s]));
  }
cleanup:
  MICA_FREE(faces);
  return ierr;
}

/* The elements as an output mesh on the nodes: Q1 / hex8 as VTK's quadrilaterals and hexahedra, Q2 / hex27 as its
 * biquadratic and triquadratic kinds, whose lattice positions (mica_cell_lattice) are the local nodes' indices
 * per axis (order 1: lattice / 2). */
static int element_mesh(const MicaFe *fe, MicaCellMesh **out) {
  const int dim = fe->dim, p = fe->order;
  const int type = p == 1 ? (dim == 2 ? MICA_CELL_QUAD : MICA_CELL_HEXAHEDRON)
                          : (dim == 2 ? MICA_CELL_BIQUADRATIC_QUAD : MICA_CELL_TRIQUADRATIC_HEXAHEDRON);
  MicaCellMesh *m = NULL;
  MICA_CALL(mica_cell_mesh_create_uniform(dim, fe->nnodes, fe->nelements, type, &m));
  memcpy(m->x, fe->x, sizeof(double) * (size_t)(fe->nnodes * dim));
  int lattice[MICA_FE_MAX_NODES * 3];
  const int nodes = mica_cell_lattice(type, lattice);
  for (long e = 0; e < fe->nelements; e++)
    for (int a = 0; a < nodes; a++) {
      int local = 0;
      for (int d = dim - 1; d >= 0; d--) local = local * (p + 1) + lattice[a * 3 + d] * p / 2;
      m->conn[e * nodes + a] = fe->conn[e * fe->nen + local];
    }
  mica_cell_mesh_orient(m);
  *out = m;
  return MICA_SUCCESS;
}

int mica_fe_discretize(const MicaFe *fe, const MicaDiscretization *like, int order, int boundary_order,
                       MicaDiscretization **out) {
  *out = NULL;
  MICA_CHECK(like->dim == fe->dim && like->nparticles == fe->nnodes, MICA_ERR_ARGUMENT,
             "mica_fe_discretize: the discretization does not match the mesh");
  MicaDiscretization *disc = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(disc, 1));
  disc->dim = fe->dim;
  disc->nparticles = fe->nnodes;
  MICA_CALL_CLEANUP(MICA_MALLOC(disc->x, fe->nnodes * fe->dim));
  memcpy(disc->x, fe->x, sizeof(double) * (size_t)(fe->nnodes * fe->dim));
  MICA_CALL_CLEANUP(volume_points(fe, order, disc));
  MICA_CALL_CLEANUP(boundary_sets(fe, like, boundary_order > 0 ? boundary_order : order, disc));
  disc->boundary_uncovered = 0; /* every boundary face is in exactly one set */
  MICA_CALL_CLEANUP(element_mesh(fe, &disc->mesh));
  *out = disc;
  return MICA_SUCCESS;
cleanup:
  mica_discretization_destroy(&disc);
  return ierr;
}
