/* Boundary sets: their storage, and the sets of the built-in shapes (docs/theory.md §geometry, "Boundary
 * quadrature"). A set is a list of faces (or parts of faces) of the parameter box. Its boundary elements
 * are the faces of the background cells on it; its vertices are their corners, shared between the
 * elements of the set. Each element carries the tensor Gauss rule of `order` points per tangential axis,
 * mapped by X, with
 *   weight  = w_ref × (face size in parameter space) × |cof(J) e_a|   (Nanson's formula: the length
 *             |∂X/∂s| in 2-D, the area |∂X/∂s × ∂X/∂t| in 3-D),
 *   normal  = ± cof(J) e_a / |cof(J) e_a|, + on the face ξ_a = 1 and − on ξ_a = 0, times the map's
 *             orientation: cof(J) = det(J) J^−T turns the parameter-space normal e_a into the physical one.
 * lambda_N holds the linear (2-D edge: 1 − s, s) or bilinear (3-D face) functions of the element's
 * vertices at the point.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom_private.h"
#include "mica/sort.h"

/* ---- storage ---- */

int geom_set_alloc(MicaBoundarySet *set, int dim, long npoints, long nelements, int element_size,
                   long nvertices) {
  set->n = npoints;
  set->nelements = nelements;
  set->element_size = element_size;
  set->nvertices = nvertices;
  MICA_CALL(MICA_CALLOC(set->x, npoints * dim));
  MICA_CALL(MICA_CALLOC(set->w, npoints));
  MICA_CALL(MICA_CALLOC(set->normal, npoints * dim));
  MICA_CALL(MICA_CALLOC(set->element, npoints));
  MICA_CALL(MICA_CALLOC(set->lambda_N, npoints * 4));
  MICA_CALL(MICA_CALLOC(set->vertex_x, nvertices * dim));
  MICA_CALL(MICA_CALLOC(set->element_vertices, nelements * element_size));
  return MICA_SUCCESS;
}

void geom_set_free(MicaBoundarySet *set) {
  MICA_FREE(set->x);
  MICA_FREE(set->w);
  MICA_FREE(set->normal);
  MICA_FREE(set->element);
  MICA_FREE(set->lambda_N);
  MICA_FREE(set->vertex_x);
  MICA_FREE(set->element_vertices);
  MICA_FREE(set->cell);
  MICA_FREE(set->grid_cell);
  MICA_FREE(set->vertex_key);
}

/* ---- faces of the grid on a set ---- */

/* The tangential axes of face axis a: cyclic in 3-D, so that (∂X/∂ξ_t0 × ∂X/∂ξ_t1) ∥ cof(J) e_a. */
static void tangent_axes(int dim, int a, int t[2]) {
  if (dim == 2) {
    t[0] = 1 - a, t[1] = -1;
  } else {
    t[0] = (a + 1) % 3, t[1] = (a + 2) % 3;
  }
}

/* Range [first, last) of cells along axis d whose middle lies in [lo, hi]. */
static void cell_range(const GeomGrid *grid, int d, double lo, double hi, long *first, long *last) {
  *first = grid->n[d], *last = 0;
  for (long i = 0; i < grid->n[d]; i++) {
    const double mid = 0.5 * (grid->edges[d][i] + grid->edges[d][i + 1]);
    if (mid < lo || mid > hi) continue;
    if (i < *first) *first = i;
    *last = i + 1;
  }
  if (*last < *first) *first = *last = 0;
}

/* A boundary element: the face of cell (i along t0, j along t1) on piece p. */
typedef struct {
  const GeomFacePiece *piece;
  long i, j;
} FaceRef;

/* The background cell a face lies on (its index in the cell grid, axis 0 fastest). */
static void face_cell(const GeomGrid *grid, const FaceRef *f, long cell[3]) {
  int t[2];
  tangent_axes(grid->dim, f->piece->axis, t);
  cell[0] = cell[1] = cell[2] = 0;
  cell[f->piece->axis] = f->piece->side ? grid->n[f->piece->axis] - 1 : 0;
  cell[t[0]] = f->i;
  if (t[1] >= 0) cell[t[1]] = f->j;
}

/* The cell ranges of a piece along its tangential axes and the number of faces it holds. */
static long piece_faces(const GeomGrid *grid, const GeomFacePiece *p, long first[2], long last[2]) {
  int t[2];
  tangent_axes(grid->dim, p->axis, t);
  long count = 1;
  for (int k = 0; k < 2; k++) {
    first[k] = 0, last[k] = 1;
    if (t[k] < 0) continue;
    cell_range(grid, t[k], p->lo[t[k]], p->hi[t[k]], &first[k], &last[k]);
    count *= last[k] - first[k];
  }
  return count;
}

/* Node-grid key of the corner (di, dj) ∈ {0,1}² of a face: nodes numbered axis 0 fastest. */
static long corner_key(const GeomGrid *grid, const FaceRef *f, int di, int dj) {
  long node[3] = {0, 0, 0};
  int t[2];
  tangent_axes(grid->dim, f->piece->axis, t);
  node[f->piece->axis] = f->piece->side ? grid->n[f->piece->axis] : 0;
  node[t[0]] = f->i + di;
  if (t[1] >= 0) node[t[1]] = f->j + dj;
  return (node[2] * (grid->n[1] + 1) + node[1]) * (grid->n[0] + 1) + node[0];
}

static void key_to_parameter(const GeomGrid *grid, long key, double *xi) {
  for (int d = 0; d < grid->dim; d++) {
    xi[d] = grid->edges[d][key % (grid->n[d] + 1)];
    key /= grid->n[d] + 1;
  }
}

/* ---- one set ---- */

/* Corner order of an element: (0,0), (1,0) in 2-D; (0,0), (1,0), (1,1), (0,1) in 3-D. */
static const int corner_di[4] = {0, 1, 1, 0}, corner_dj[4] = {0, 0, 1, 1};

/* Gauss points of one face: x, w, normal, lambda_N, element number. */
static int face_points(const GeomMap *map, const GeomGrid *grid, const FaceRef *f, int order, const double *u,
                       const double *wu, long element, MicaBoundarySet *set, long *q) {
  const int dim = map->dim;
  const GeomFacePiece *p = f->piece;
  int t[2];
  tangent_axes(dim, p->axis, t);
  const double lo0 = grid->edges[t[0]][f->i], w0 = grid->edges[t[0]][f->i + 1] - lo0;
  const double lo1 = t[1] >= 0 ? grid->edges[t[1]][f->j] : 0.0;
  const double w1 = t[1] >= 0 ? grid->edges[t[1]][f->j + 1] - lo1 : 1.0;
  const long npts = dim == 2 ? order : (long)order * order;
  const double sign = (p->side ? 1.0 : -1.0) * map->orientation;
  for (long g = 0; g < npts; g++, (*q)++) {
    const int gs = (int)(g % order), gt = (int)(g / order);
    const double s = u[gs], tt = dim == 2 ? 0.0 : u[gt];
    double xi[3] = {0, 0, 0}, jac[9], c[3];
    xi[p->axis] = p->side;
    xi[t[0]] = lo0 + s * w0;
    if (t[1] >= 0) xi[t[1]] = lo1 + tt * w1;
    geom_map_eval(map, xi, &set->x[*q * dim], jac);
    geom_cofactor_column(dim, jac, p->axis, c);
    double len = 0.0;
    for (int d = 0; d < dim; d++) len += c[d] * c[d];
    len = sqrt(len);
    MICA_CHECK(len > 0 && isfinite(len), MICA_ERR_INPUT,
               "boundary set '%s': the map degenerates on the boundary at ξ = (%g, %g, %g)", set->name, xi[0],
               xi[1], xi[2]);
    set->w[*q] = wu[gs] * (dim == 2 ? 1.0 : wu[gt]) * w0 * w1 * len;
    for (int d = 0; d < dim; d++) set->normal[*q * dim + d] = sign * c[d] / len;
    set->element[*q] = element;
    long cell[3];
    face_cell(grid, f, cell);
    set->grid_cell[*q] = (cell[2] * grid->n[1] + cell[1]) * grid->n[0] + cell[0];
    double *lam = &set->lambda_N[*q * 4];
    if (dim == 2) {
      lam[0] = 1.0 - s, lam[1] = s;
    } else {
      lam[0] = (1.0 - s) * (1.0 - tt), lam[1] = s * (1.0 - tt), lam[2] = s * tt, lam[3] = (1.0 - s) * tt;
    }
  }
  return MICA_SUCCESS;
}

static int face_in_box(const GeomGrid *grid, const FaceRef *f, const long lo[3], const long hi[3]) {
  long cell[3];
  face_cell(grid, f, cell);
  for (int d = 0; d < 3; d++)
    if (cell[d] < lo[d] || cell[d] >= hi[d]) return 0;
  return 1;
}

/* The faces of all pieces of a set on the cells of the box [lo, hi), in order; *faces is allocated. */
static int collect_faces(const GeomGrid *grid, const GeomSetSpec *spec, const long lo[3], const long hi[3],
                         long *nfaces, FaceRef **faces) {
  long count = 0;
  for (int k = 0; k < spec->npieces; k++) {
    long first[2], last[2];
    count += piece_faces(grid, &spec->pieces[k], first, last);
  }
  MICA_CALL(MICA_MALLOC(*faces, count + 1));
  *nfaces = 0;
  for (int k = 0; k < spec->npieces; k++) {
    long first[2], last[2];
    piece_faces(grid, &spec->pieces[k], first, last);
    for (long j = first[1]; j < last[1]; j++)
      for (long i = first[0]; i < last[0]; i++) {
        const FaceRef f = {&spec->pieces[k], i, j};
        if (face_in_box(grid, &f, lo, hi)) (*faces)[(*nfaces)++] = f;
      }
  }
  return MICA_SUCCESS;
}

/* Vertices: the distinct corner keys (sorted), their positions, and each element's vertex indices. */
static int set_vertices(const GeomGrid *grid, const FaceRef *faces, long nfaces, int esize, long **keys,
                        long *nkeys) {
  MICA_CALL(MICA_MALLOC(*keys, nfaces * esize));
  for (long e = 0; e < nfaces; e++)
    for (int k = 0; k < esize; k++)
      (*keys)[e * esize + k] = corner_key(grid, &faces[e], corner_di[k], corner_dj[k]);
  qsort(*keys, (size_t)(nfaces * esize), sizeof **keys, mica_compare_long);
  long n = 0;
  for (long i = 0; i < nfaces * esize; i++)
    if (n == 0 || (*keys)[i] != (*keys)[n - 1]) (*keys)[n++] = (*keys)[i];
  *nkeys = n;
  return MICA_SUCCESS;
}

static int build_set(const GeomMap *map, const GeomGrid *grid, const GeomSetSpec *spec, int order,
                     const double *u, const double *wu, const long lo[3], const long hi[3], MicaBoundarySet *set) {
  int ierr = MICA_SUCCESS;
  const int dim = map->dim, esize = dim == 2 ? 2 : 4;
  FaceRef *faces = NULL;
  long *keys = NULL, nfaces = 0, nkeys = 0, q = 0;
  memcpy(set->name, spec->name, sizeof set->name);
  MICA_CALL_CLEANUP(collect_faces(grid, spec, lo, hi, &nfaces, &faces));
  MICA_CALL_CLEANUP(set_vertices(grid, faces, nfaces, esize, &keys, &nkeys));
  const long per_face = dim == 2 ? order : (long)order * order;
  MICA_CALL_CLEANUP(geom_set_alloc(set, dim, nfaces * per_face, nfaces, esize, nkeys));
  MICA_CALL_CLEANUP(MICA_CALLOC(set->grid_cell, nfaces * per_face + 1));
  for (long v = 0; v < nkeys; v++) {
    double xi[3];
    key_to_parameter(grid, keys[v], xi);
    geom_map_eval(map, xi, &set->vertex_x[v * dim], NULL);
  }
  for (long e = 0; e < nfaces; e++) {
    for (int k = 0; k < esize; k++) {
      const long key = corner_key(grid, &faces[e], corner_di[k], corner_dj[k]);
      const long *hit = bsearch(&key, keys, (size_t)nkeys, sizeof *keys, mica_compare_long);
      set->element_vertices[e * esize + k] = hit - keys;
    }
    MICA_CALL_CLEANUP(face_points(map, grid, &faces[e], order, u, wu, e, set, &q));
  }
  set->vertex_key = keys; /* the set's vertices in key order: vertex v is keys[v] */
  keys = NULL;
cleanup:
  MICA_FREE(faces);
  MICA_FREE(keys);
  return ierr;
}

int geom_grid_boundary(const GeomMap *map, const GeomGrid *grid, int order, MicaDiscretization *disc) {
  const long lo[3] = {0, 0, 0}, hi[3] = {grid->n[0], grid->n[1], grid->n[2]};
  return geom_grid_boundary_box(map, grid, order, lo, hi, disc);
}

int geom_grid_boundary_box(const GeomMap *map, const GeomGrid *grid, int order, const long lo[3], const long hi[3],
                           MicaDiscretization *disc) {
  double u[GEOM_GAUSS_MAX], wu[GEOM_GAUSS_MAX];
  MICA_CHECK(order >= 1 && order <= GEOM_GAUSS_MAX, MICA_ERR_INPUT,
             "cells: boundary_order = %d outside [1, %d]", order, GEOM_GAUSS_MAX);
  MICA_CALL(geom_gauss_unit(order, u, wu));
  MICA_CALL(MICA_CALLOC(disc->sets, map->nsets));
  disc->nsets = map->nsets;
  for (int s = 0; s < map->nsets; s++)
    MICA_CALL(build_set(map, grid, &map->sets[s], order, u, wu, lo, hi, &disc->sets[s]));
  return MICA_SUCCESS;
}
