/* Nodal cells of the built-in shapes (docs/theory.md §nodal integration, `mica_discretization_nodal`).
 *
 * The particles of the regular, graded and jittered layouts sit on a logical grid (n_d per parameter axis,
 * axis 0 fastest). Their dual grid has (n_d + 1) corners per axis; corner (a, b, c) is the average, in
 * parameter space, of the 2^dim particles with indices {a−1, a} × {b−1, b} × {c−1, c}, each clamped to the
 * grid. Clamping puts the corners of the outer layer on the faces of the parameter box (the layouts keep
 * face particles on their faces), so boundary particles get half and quarter cells and the cells tile the
 * parameter box exactly; on the regular and graded layouts they are the boxes between midpoints. Particle
 * (i, j, k)'s cell has the corners (i..i+1) × (j..j+1) × (k..k+1): a quadrilateral in 2-D, a hexahedron with
 * bilinear faces in 3-D. Its faces, mapped by X, are its boundary; a face shared by two cells is the same
 * parameter segment (bilinear quad), so the physical cells are conforming and follow curved boundaries.
 *
 * Every face carries the Gauss rule of `order` points per direction (Nanson, as boundary.c): weight × normal
 * is w (J ∂ξ/∂s)^⊥ in 2-D and w (J ∂ξ/∂s) × (J ∂ξ/∂t) in 3-D, times the map's orientation. A cell's volume is
 * (1/dim) Σ_b (x_b − x_I)·(w n)_b, the divergence theorem on its own boundary points: exact when the faces
 * are integrated exactly (box, polygon: polynomial integrands) and, either way, the volume that SCNI's
 * smoothing is consistent with. In 2-D a face that crosses a kink of the map (the plate's corner line) is
 * split there, so that no Gauss rule straddles it. Faces on the parameter box's faces become the elements of
 * the rebuilt boundary sets.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom_private.h"

enum { MAX_SPLITS = 2 * GEOM_KINKS_MAX + 1 }; /* sub-faces of a 2-D face: kinks along either axis */
enum { INTERIOR = -1, UNCOVERED = -2 };        /* NodalFace.set of faces in no boundary set */

/* One face of a cell in parameter space: a segment (2 vertices) or a bilinear quad (4), oriented so that the
 * mapped normal points out of the cell; set: the boundary set it belongs to, or INTERIOR, or UNCOVERED; key: each
 * vertex's name, the same on every block that builds it (vertex_keys). */
typedef struct {
  long cell;
  int set;
  double v[4][3];
  long key[4];
} NodalFace;

/* The dual grid of the cells of the particle box [lo, hi) (the whole grid, or one rank's block of it): its corners
 * [lo, hi] and the particles around them, [lo − 1, hi + 1) within the grid. Indices are the whole grid's. */
typedef struct {
  int dim;
  long n[3];           /* particles per axis (1 beyond the dimension) */
  long lo[3], hi[3];   /* the cells built */
  long xlo[3], xhi[3]; /* the particles xi holds */
  long ext[3];         /* corners per axis in the box: hi − lo + 1 (1 beyond the dimension) */
  double *xi;          /* [Π (xhi − xlo) × dim] parameter coordinates, grid order */
  double *corner;      /* [Π ext × dim] */
} DualGrid;

/* A corner's place in the box, and its name in the whole grid of (n_d + 1) corners per axis. */
static long corner_id(const DualGrid *g, long a, long b, long c) {
  return ((c - g->lo[2]) * g->ext[1] + (b - g->lo[1])) * g->ext[0] + (a - g->lo[0]);
}

static long corner_key(const DualGrid *g, const long k[3]) {
  return (k[2] * (g->n[1] + 1) + k[1]) * (g->n[0] + 1) + k[0];
}

/* Names of the points where a 2-D face is split at a kink: after every corner's, by edge and crossing. */
static long split_key(const DualGrid *g, long lower_corner, int axis, int crossing) {
  const long corners = (g->n[0] + 1) * (g->n[1] + 1);
  return corners + (2 * lower_corner + axis) * MAX_SPLITS + crossing;
}

static long clamp(long i, long n) { return i < 0 ? 0 : i >= n ? n - 1 : i; }

/* Corner (a, b, c): the average of the particles around it, indices clamped to the grid. */
static void corner_point(const DualGrid *g, const long k[3], double *out) {
  const int dim = g->dim;
  const int nsum = 1 << dim;
  for (int d = 0; d < dim; d++) out[d] = 0.0;
  for (int m = 0; m < nsum; m++) {
    long p = 0, stride = 1;
    for (int d = 0; d < dim; d++) {
      p += (clamp(k[d] - 1 + ((m >> d) & 1), g->n[d]) - g->xlo[d]) * stride;
      stride *= g->xhi[d] - g->xlo[d];
    }
    for (int d = 0; d < dim; d++) out[d] += g->xi[p * dim + d];
  }
  for (int d = 0; d < dim; d++) out[d] /= nsum;
}

static int dual_grid_create(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes, const long lo[3],
                            const long hi[3], DualGrid *g) {
  const int dim = map->dim;
  memset(g, 0, sizeof *g);
  g->dim = dim;
  for (int d = 0; d < 3; d++) {
    g->n[d] = d < dim ? axes->n[d] : 1;
    g->lo[d] = d < dim ? lo[d] : 0, g->hi[d] = d < dim ? hi[d] : 1;
    g->xlo[d] = g->lo[d] > 0 ? g->lo[d] - 1 : 0, g->xhi[d] = g->hi[d] < g->n[d] ? g->hi[d] + 1 : g->n[d];
    g->ext[d] = d < dim ? g->hi[d] - g->lo[d] + 1 : 1;
  }
  long np;
  MICA_CALL(geom_layout_box(map, layout, axes, g->xlo, g->xhi, &np, &g->xi));
  MICA_CALL(MICA_MALLOC(g->corner, g->ext[0] * g->ext[1] * g->ext[2] * dim + 1));
  for (long c = g->lo[2]; c < g->lo[2] + g->ext[2]; c++)
    for (long b = g->lo[1]; b < g->lo[1] + g->ext[1]; b++)
      for (long a = g->lo[0]; a < g->lo[0] + g->ext[0]; a++) {
        const long k[3] = {a, b, c};
        corner_point(g, k, &g->corner[corner_id(g, a, b, c) * dim]);
      }
  return MICA_SUCCESS;
}

static void dual_grid_destroy(DualGrid *g) {
  MICA_FREE(g->xi);
  MICA_FREE(g->corner);
}

/* Cells in the box, and cell (i, j, k)'s number among them (grid order). */
static long box_cells(const DualGrid *g) { return (g->hi[0] - g->lo[0]) * (g->hi[1] - g->lo[1]) * (g->hi[2] - g->lo[2]); }

static long box_cell(const DualGrid *g, const long idx[3]) {
  return ((idx[2] - g->lo[2]) * (g->hi[1] - g->lo[1]) + (idx[1] - g->lo[1])) * (g->hi[0] - g->lo[0]) + (idx[0] - g->lo[0]);
}

/* ---- faces ---------------------------------------------------------------------------------------------- */

/* The boundary set of a face on the parameter box's face (axis, side), by its parameter midpoint; UNCOVERED
 * if no set holds it (interior faces are INTERIOR). */
static int face_set(const GeomMap *map, int axis, int side, const double *mid) {
  for (int s = 0; s < map->nsets; s++)
    for (int k = 0; k < map->sets[s].npieces; k++) {
      const GeomFacePiece *p = &map->sets[s].pieces[k];
      if (p->axis != axis || p->side != side) continue;
      int inside = 1;
      for (int d = 0; d < map->dim; d++)
        if (d != axis && (mid[d] < p->lo[d] - 1e-12 || mid[d] > p->hi[d] + 1e-12)) inside = 0;
      if (inside) return s;
    }
  return UNCOVERED;
}

/* The points where segment a → b crosses a kink line of the map, ordered from a to b (at most MAX_SPLITS − 1).
 * Each is computed from the lexicographically smaller endpoint and put exactly on the kink, so the two cells
 * sharing the segment split it at the same point, bit for bit. */
static int kink_crossings(const GeomMap *map, const double *a, const double *b, double (*pts)[2]) {
  const int swap = a[0] > b[0] || (a[0] == b[0] && a[1] > b[1]);
  const double *p = swap ? b : a, *q = swap ? a : b;
  double t[MAX_SPLITS];
  int n = 0;
  for (int d = 0; d < 2; d++)
    for (int k = 0; k < map->nkinks[d]; k++) {
      const double kink = map->kinks[d][k];
      if (!((p[d] - kink) * (q[d] - kink) < 0)) continue;
      const double tc = (kink - p[d]) / (q[d] - p[d]);
      for (int e = 0; e < 2; e++) pts[n][e] = p[e] + tc * (q[e] - p[e]);
      pts[n][d] = kink;
      t[n++] = swap ? 1.0 - tc : tc; /* along a → b */
    }
  for (int i = 1; i < n; i++) /* a handful: insertion sort by t */
    for (int j = i; j > 0 && t[j] < t[j - 1]; j--) {
      const double tt = t[j], x0 = pts[j][0], x1 = pts[j][1];
      t[j] = t[j - 1], pts[j][0] = pts[j - 1][0], pts[j][1] = pts[j - 1][1];
      t[j - 1] = tt, pts[j - 1][0] = x0, pts[j - 1][1] = x1;
    }
  return n;
}

/* A 2-D edge of cell `cell` from corner ka to corner kb (whole-grid indices), split at kinks, appended to faces;
 * edge_axis: the axis it runs along, for the names of its split points. */
static void add_edge(const GeomMap *map, const DualGrid *g, long cell, const long ka[3], const long kb[3],
                     int edge_axis, int axis, int side, NodalFace *faces, long *nfaces) {
  const double *a = &g->corner[corner_id(g, ka[0], ka[1], 0) * 2], *b = &g->corner[corner_id(g, kb[0], kb[1], 0) * 2];
  const long key_a = corner_key(g, ka), key_b = corner_key(g, kb), lower = key_a < key_b ? key_a : key_b;
  double pts[MAX_SPLITS + 1][2];
  long keys[MAX_SPLITS + 1];
  memcpy(pts[0], a, sizeof pts[0]);
  keys[0] = key_a;
  const int ncross = kink_crossings(map, a, b, pts + 1);
  for (int k = 1; k <= ncross; k++) /* numbered from the lower corner, whichever way the cell runs */
    keys[k] = split_key(g, lower, edge_axis, key_a < key_b ? k - 1 : ncross - k);
  memcpy(pts[ncross + 1], b, sizeof pts[0]);
  keys[ncross + 1] = key_b;
  for (int k = 0; k <= ncross; k++) {
    NodalFace *f = &faces[(*nfaces)++];
    memset(f, 0, sizeof *f);
    f->cell = cell;
    memcpy(f->v[0], pts[k], sizeof pts[k]);
    memcpy(f->v[1], pts[k + 1], sizeof pts[k + 1]);
    f->key[0] = keys[k], f->key[1] = keys[k + 1];
    double mid[3] = {0.5 * (pts[k][0] + pts[k + 1][0]), 0.5 * (pts[k][1] + pts[k + 1][1]), 0};
    f->set = axis >= 0 ? face_set(map, axis, side, mid) : INTERIOR;
  }
}

/* The four edges of 2-D cell (i, j), counterclockwise in parameter space (the map's orientation is applied
 * to the normals later): bottom, right, top, left; an edge on the parameter box's boundary is tagged with
 * its face (axis, side). */
static void cell_faces_2d(const GeomMap *map, const DualGrid *g, long i, long j, NodalFace *faces, long *nfaces) {
  const long c00[3] = {i, j, 0}, c10[3] = {i + 1, j, 0}, c11[3] = {i + 1, j + 1, 0}, c01[3] = {i, j + 1, 0};
  const long idx[3] = {i, j, 0}, cell = box_cell(g, idx);
  add_edge(map, g, cell, c00, c10, 0, j == 0 ? 1 : -1, 0, faces, nfaces);
  add_edge(map, g, cell, c10, c11, 1, i == g->n[0] - 1 ? 0 : -1, 1, faces, nfaces);
  add_edge(map, g, cell, c11, c01, 0, j == g->n[1] - 1 ? 1 : -1, 1, faces, nfaces);
  add_edge(map, g, cell, c01, c00, 1, i == 0 ? 0 : -1, 0, faces, nfaces);
}

/* The six bilinear faces of 3-D cell (i, j, k). Face (axis a, side s) has tangential axes t0 = a+1, t1 = a+2
 * (cyclic, e_t0 × e_t1 = e_a); its vertices run along t0 then t1 on side 1 and the other way round on side 0,
 * so (∂ξ/∂s × ∂ξ/∂t) points out of the cell. */
static void cell_faces_3d(const GeomMap *map, const DualGrid *g, const long idx[3], NodalFace *faces, long *nfaces) {
  const long cell = box_cell(g, idx);
  for (int a = 0; a < 3; a++)
    for (int side = 0; side < 2; side++) {
      const int t0 = side ? (a + 1) % 3 : (a + 2) % 3, t1 = side ? (a + 2) % 3 : (a + 1) % 3;
      static const int step[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      NodalFace *f = &faces[(*nfaces)++];
      double mid[3] = {0, 0, 0};
      memset(f, 0, sizeof *f);
      f->cell = cell;
      for (int v = 0; v < 4; v++) {
        long k[3] = {idx[0], idx[1], idx[2]};
        k[a] += side, k[t0] += step[v][0], k[t1] += step[v][1];
        memcpy(f->v[v], &g->corner[corner_id(g, k[0], k[1], k[2]) * 3], 3 * sizeof(double));
        f->key[v] = corner_key(g, k);
        for (int d = 0; d < 3; d++) mid[d] += 0.25 * f->v[v][d];
      }
      const int on_boundary = side ? idx[a] == g->n[a] - 1 : idx[a] == 0;
      f->set = on_boundary ? face_set(map, a, side, mid) : INTERIOR;
    }
}

/* All faces of the box's cells, cell by cell (a cell's faces are contiguous); *faces allocated. */
static int collect_faces(const GeomMap *map, const DualGrid *g, long *nfaces, NodalFace **faces) {
  const int dim = g->dim;
  const long per_cell = dim == 2 ? 4 * (MAX_SPLITS) : 6;
  MICA_CALL(MICA_MALLOC(*faces, box_cells(g) * per_cell + 1));
  *nfaces = 0;
  for (long k = g->lo[2]; k < g->hi[2]; k++)
    for (long j = g->lo[1]; j < g->hi[1]; j++)
      for (long i = g->lo[0]; i < g->hi[0]; i++) {
        const long idx[3] = {i, j, k};
        if (dim == 2)
          cell_faces_2d(map, g, i, j, *faces, nfaces);
        else
          cell_faces_3d(map, g, idx, *faces, nfaces);
      }
  return MICA_SUCCESS;
}

/* ---- Gauss points of a face ------------------------------------------------------------------------------ */

typedef struct {
  int order;
  double u[GEOM_GAUSS_MAX], w[GEOM_GAUSS_MAX];
} Rule;

static long rule_points(const Rule *r, int dim) { return dim == 2 ? r->order : (long)r->order * r->order; }

/* Point g of face f: position x, weight × outward normal wn, and the face's vertex functions lam. */
static void face_point(const GeomMap *map, const Rule *r, const NodalFace *f, long g, double *x, double *wn,
                       double *lam) {
  const int dim = map->dim;
  const int gs = (int)(g % r->order), gt = (int)(g / r->order);
  const double s = r->u[gs], t = dim == 2 ? 0.0 : r->u[gt], w = r->w[gs] * (dim == 2 ? 1.0 : r->w[gt]);
  double xi[3] = {0, 0, 0}, dxs[3] = {0, 0, 0}, dxt[3] = {0, 0, 0}, jac[9];
  if (dim == 2) {
    lam[0] = 1.0 - s, lam[1] = s, lam[2] = lam[3] = 0.0;
    for (int d = 0; d < 2; d++) xi[d] = lam[0] * f->v[0][d] + lam[1] * f->v[1][d], dxs[d] = f->v[1][d] - f->v[0][d];
  } else {
    lam[0] = (1 - s) * (1 - t), lam[1] = s * (1 - t), lam[2] = s * t, lam[3] = (1 - s) * t;
    for (int d = 0; d < 3; d++) {
      for (int v = 0; v < 4; v++) xi[d] += lam[v] * f->v[v][d];
      dxs[d] = (1 - t) * (f->v[1][d] - f->v[0][d]) + t * (f->v[2][d] - f->v[3][d]);
      dxt[d] = (1 - s) * (f->v[3][d] - f->v[0][d]) + s * (f->v[2][d] - f->v[1][d]);
    }
  }
  geom_map_eval(map, xi, x, jac);
  double ts[3] = {0, 0, 0}, tt[3] = {0, 0, 0};
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) ts[i] += jac[i * dim + j] * dxs[j], tt[i] += jac[i * dim + j] * dxt[j];
  const double scale = w * map->orientation;
  if (dim == 2) {
    wn[0] = scale * ts[1], wn[1] = -scale * ts[0];
  } else {
    wn[0] = scale * (ts[1] * tt[2] - ts[2] * tt[1]);
    wn[1] = scale * (ts[2] * tt[0] - ts[0] * tt[2]);
    wn[2] = scale * (ts[0] * tt[1] - ts[1] * tt[0]);
  }
}

/* ---- cells ----------------------------------------------------------------------------------------------- */

static int nodal_cells_create(const GeomMap *map, const Rule *r, const NodalFace *faces, long nfaces, long ncells,
                              MicaNodalCells **out) {
  const int dim = map->dim;
  const long per_face = rule_points(r, dim);
  MicaNodalCells *c = NULL;
  MICA_CALL(MICA_CALLOC(c, 1));
  *out = c;
  c->n = ncells;
  MICA_CALL(MICA_CALLOC(c->ptr, ncells + 1));
  MICA_CALL(MICA_MALLOC(c->x, nfaces * per_face * dim));
  MICA_CALL(MICA_MALLOC(c->wn, nfaces * per_face * dim));
  for (long f = 0; f < nfaces; f++) c->ptr[faces[f].cell + 1] += per_face;
  for (long i = 0; i < ncells; i++) c->ptr[i + 1] += c->ptr[i];
  long q = 0; /* faces are grouped by cell, in cell order */
  for (long f = 0; f < nfaces; f++)
    for (long g = 0; g < per_face; g++, q++) {
      double lam[4];
      face_point(map, r, &faces[f], g, &c->x[q * dim], &c->wn[q * dim], lam);
    }
  return MICA_SUCCESS;
}

/* Volumes by the divergence theorem on each cell's boundary points, about the particle (round-off stays
 * relative to the cell, not to the body's position). A cell that folds has no positive volume. */
static int cell_volumes(const MicaNodalCells *c, int dim, const double *particles, double *volume) {
  for (long i = 0; i < c->n; i++) {
    double v = 0.0;
    for (long b = c->ptr[i]; b < c->ptr[i + 1]; b++)
      for (int d = 0; d < dim; d++) v += (c->x[b * dim + d] - particles[i * dim + d]) * c->wn[b * dim + d];
    volume[i] = v / dim;
    const double *x = particles + i * dim;
    MICA_CHECK(volume[i] > 0 && isfinite(volume[i]), MICA_ERR_INPUT,
               "nodal cells: the cell of particle %ld at (%g, %g, %g) has volume %g ≤ 0 (it folds): use less "
               "particles.jitter",
               i + 1, x[0], x[1], dim == 3 ? x[2] : 0.0, volume[i]);
  }
  return MICA_SUCCESS;
}

/* Second moments about the particle by the divergence theorem on the cell's boundary points (NSNI's
 * stabilization, docs/theory.md §NSNI): with y = x − x_I, div(y_d y_e y) = (dim + 2) y_d y_e, so
 *   M_I,de = ∫_Ω_I y_d y_e dV = (1/(dim + 2)) Σ_b y_d y_e (y · (w n)_b),
 * exact where the faces' integrands are polynomials of the rule's degree (straight 2-D faces: cubic in s). */
static int cell_moments(MicaNodalCells *c, int dim, const double *particles) {
  MICA_CALL(MICA_CALLOC(c->moment, c->n * dim * dim));
  for (long i = 0; i < c->n; i++) {
    double *M = c->moment + i * dim * dim;
    for (long b = c->ptr[i]; b < c->ptr[i + 1]; b++) {
      double y[3] = {0, 0, 0}, flux = 0.0;
      for (int d = 0; d < dim; d++) y[d] = c->x[b * dim + d] - particles[i * dim + d], flux += y[d] * c->wn[b * dim + d];
      for (int d = 0; d < dim; d++)
        for (int e = 0; e < dim; e++) M[d * dim + e] += y[d] * y[e] * flux / (dim + 2);
    }
  }
  return MICA_SUCCESS;
}

int mica_discretization_nodal_centroids(MicaDiscretization *disc) {
  MICA_CHECK(disc->nodal && disc->nodal->moment && disc->nquad == disc->nparticles, MICA_ERR_ARGUMENT,
             "mica_discretization_nodal_centroids: no nodal cells");
  const int dim = disc->dim;
  const MicaNodalCells *c = disc->nodal;
  for (long i = 0; i < c->n; i++) {
    double first[3] = {0, 0, 0}, *M = c->moment + i * dim * dim;
    for (long b = c->ptr[i]; b < c->ptr[i + 1]; b++) {
      double y[3] = {0, 0, 0}, flux = 0.0;
      for (int d = 0; d < dim; d++) y[d] = c->x[b * dim + d] - disc->x[i * dim + d], flux += y[d] * c->wn[b * dim + d];
      for (int d = 0; d < dim; d++) first[d] += y[d] * flux / (dim + 1); /* div(y_d y) = (dim + 1) y_d */
    }
    const double V = disc->qw[i];
    for (int d = 0; d < dim; d++) disc->qx[i * dim + d] = disc->x[i * dim + d] + first[d] / V;
    for (int d = 0; d < dim; d++) /* about the centroid: M − S Sᵀ / V */
      for (int e = 0; e < dim; e++) M[d * dim + e] -= first[d] * first[e] / V;
  }
  return MICA_SUCCESS;
}

/* ---- boundary sets on the cells' boundary faces ---------------------------------------------------------- */

/* A vertex of a set's faces: its name and parameter point. */
typedef struct {
  long key;
  double xi[3];
} SetVertex;

static int compare_vertex(const void *pa, const void *pb) {
  const long a = ((const SetVertex *)pa)->key, b = ((const SetVertex *)pb)->key;
  return (a > b) - (a < b);
}

/* The distinct vertices of the set's faces, by name (sorted), allocated in *verts. */
static int set_vertices(const NodalFace *faces, long nfaces, int set, int esize, SetVertex **verts, long *nverts) {
  long n = 0;
  for (long f = 0; f < nfaces; f++) n += faces[f].set == set ? esize : 0;
  MICA_CALL(MICA_MALLOC(*verts, n > 0 ? n : 1));
  n = 0;
  for (long f = 0; f < nfaces; f++)
    if (faces[f].set == set)
      for (int v = 0; v < esize; v++) {
        (*verts)[n].key = faces[f].key[v];
        memcpy((*verts)[n++].xi, faces[f].v[v], sizeof(double[3]));
      }
  qsort(*verts, (size_t)n, sizeof **verts, compare_vertex);
  long m = 0;
  for (long i = 0; i < n; i++)
    if (m == 0 || (*verts)[i].key != (*verts)[m - 1].key) (*verts)[m++] = (*verts)[i];
  *nverts = m;
  return MICA_SUCCESS;
}

/* Boundary set `set` from the faces in it: Gauss points, elements, and vertices named by their keys (vertex_key:
 * the same on every rank that builds a face with it, which distributed multipliers are named by). */
static int build_set(const GeomMap *map, const Rule *r, const NodalFace *faces, long nfaces, int set,
                     MicaBoundarySet *out) {
  const int dim = map->dim, esize = dim == 2 ? 2 : 4;
  const long per_face = rule_points(r, dim);
  SetVertex *verts = NULL;
  long nverts = 0, nelem = 0, q = 0;
  int ierr = MICA_SUCCESS;
  memcpy(out->name, map->sets[set].name, sizeof out->name);
  for (long f = 0; f < nfaces; f++) nelem += faces[f].set == set;
  MICA_CALL_CLEANUP(set_vertices(faces, nfaces, set, esize, &verts, &nverts));
  MICA_CALL_CLEANUP(geom_set_alloc(out, dim, nelem * per_face, nelem, esize, nverts));
  MICA_CALL_CLEANUP(MICA_MALLOC(out->vertex_key, nverts + 1));
  for (long v = 0; v < nverts; v++) {
    geom_map_eval(map, verts[v].xi, &out->vertex_x[v * dim], NULL);
    out->vertex_key[v] = verts[v].key;
  }
  for (long f = 0, e = 0; f < nfaces; f++) {
    if (faces[f].set != set) continue;
    for (int v = 0; v < esize; v++) {
      const SetVertex probe = {.key = faces[f].key[v]};
      const SetVertex *hit = bsearch(&probe, verts, (size_t)nverts, sizeof *verts, compare_vertex);
      out->element_vertices[e * esize + v] = hit - verts;
    }
    for (long g = 0; g < per_face; g++, q++) {
      double *wn = &out->normal[q * dim], len = 0.0;
      face_point(map, r, &faces[f], g, &out->x[q * dim], wn, &out->lambda_N[q * 4]);
      for (int d = 0; d < dim; d++) len += wn[d] * wn[d];
      len = sqrt(len);
      if (!(len > 0 && isfinite(len))) {
        ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                              "boundary set '%s': a nodal cell's face degenerates", out->name);
        goto cleanup;
      }
      out->w[q] = len;
      for (int d = 0; d < dim; d++) wn[d] /= len;
      out->element[q] = e;
    }
    e++;
  }
cleanup:
  MICA_FREE(verts);
  return ierr;
}

static int build_sets(const GeomMap *map, const Rule *r, const NodalFace *faces, long nfaces, MicaDiscretization *disc) {
  for (int s = 0; s < disc->nsets; s++) geom_set_free(&disc->sets[s]);
  MICA_FREE(disc->sets);
  disc->nsets = 0;
  MICA_CALL(MICA_CALLOC(disc->sets, map->nsets));
  disc->nsets = map->nsets;
  for (int s = 0; s < map->nsets; s++) MICA_CALL(build_set(map, r, faces, nfaces, s, &disc->sets[s]));
  disc->boundary_uncovered = 0;
  for (long f = 0; f < nfaces; f++) disc->boundary_uncovered += faces[f].set == UNCOVERED;
  return MICA_SUCCESS;
}

/* ---- the nodal discretization ---------------------------------------------------------------------------- */

/* Dual cells need the particles' logical grid, which a mesh and the irregular layout do not have. */
static int check_supported(const MicaShapeSpec *shape, const MicaLayoutSpec *layout) {
  MICA_CHECK(shape->kind != MICA_SHAPE_GMSH, MICA_ERR_INPUT,
             "nodal cells need a built-in shape (a Gmsh mesh has no particle grid to build dual cells on)");
  MICA_CHECK(layout->kind != MICA_LAYOUT_IRREGULAR, MICA_ERR_INPUT,
             "nodal cells need particles on a logical grid (regular, graded or jittered layout), not an irregular one");
  return MICA_SUCCESS;
}

/* qx, qw ← particles, cell volumes (taking ownership of *volume); the Gauss points are kept for error norms. */
static int use_particles(MicaDiscretization *disc, double **volume) {
  const int dim = disc->dim;
  double *qx = NULL;
  MICA_CALL(MICA_MALLOC(qx, disc->nparticles * dim));
  memcpy(qx, disc->x, sizeof(double) * (size_t)(disc->nparticles * dim));
  disc->ngauss = disc->nquad;
  disc->gauss_x = disc->qx, disc->gauss_w = disc->qw;
  disc->qx = qx, disc->qw = *volume;
  *volume = NULL;
  MICA_FREE(disc->qcell); /* the points are the particles now, in no background cell */
  disc->nquad = disc->ncells = disc->nparticles;
  disc->volume = 0.0;
  for (long p = 0; p < disc->nparticles; p++) disc->volume += disc->qw[p];
  return MICA_SUCCESS;
}

/* The nodal cells of the particles of the box [lo, hi) into disc, whose x holds those particles (grid order):
 * disc->nodal (boundary points, second moments about the particles), the boundary sets rebuilt on their faces,
 * and their volumes (*volume, allocated). */
static int build_cells(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                       const long lo[3], const long hi[3], MicaDiscretization *disc, double **volume) {
  int ierr = MICA_SUCCESS;
  GeomMap map;
  GeomAxes axes = {0};
  DualGrid grid = {0};
  NodalFace *faces = NULL;
  long nfaces = 0;
  Rule rule = {.order = cells->boundary_order ? cells->boundary_order : cells->order};
  MICA_CHECK(disc && !disc->nodal, MICA_ERR_ARGUMENT, "nodal cells: no discretization, or nodal already");
  MICA_CALL(check_supported(shape, layout));
  MICA_CALL(geom_map_init(shape, &map));
  for (int d = 0; d < map.dim; d++) /* no built-in 3-D shape has one: kinks are split in 2-D only */
    MICA_CHECK(map.dim == 2 || map.nkinks[d] == 0, MICA_ERR_ARGUMENT, "nodal cells: a 3-D map with a kink");
  MICA_CALL(geom_gauss_unit(rule.order, rule.u, rule.w));
  MICA_CALL_CLEANUP(geom_axes_create(layout, map.dim, &axes));
  MICA_CALL_CLEANUP(dual_grid_create(&map, layout, &axes, lo, hi, &grid));
  const long ncells = box_cells(&grid);
  if (ncells != disc->nparticles) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "nodal cells: %ld particles, not %ld",
                          disc->nparticles, ncells);
    goto cleanup;
  }
  MICA_CALL_CLEANUP(collect_faces(&map, &grid, &nfaces, &faces));
  MICA_CALL_CLEANUP(nodal_cells_create(&map, &rule, faces, nfaces, ncells, &disc->nodal));
  MICA_CALL_CLEANUP(MICA_MALLOC(*volume, ncells + 1));
  MICA_CALL_CLEANUP(cell_volumes(disc->nodal, map.dim, disc->x, *volume));
  MICA_CALL_CLEANUP(cell_moments(disc->nodal, map.dim, disc->x));
  MICA_CALL_CLEANUP(build_sets(&map, &rule, faces, nfaces, disc));
cleanup:
  MICA_FREE(faces);
  dual_grid_destroy(&grid);
  geom_axes_destroy(&axes);
  return ierr;
}

int mica_discretization_nodal(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                              MicaDiscretization *disc) {
  double *volume = NULL;
  const long lo[3] = {0, 0, 0};
  MICA_CHECK(disc, MICA_ERR_ARGUMENT, "mica_discretization_nodal: no discretization");
  int ierr = build_cells(shape, layout, cells, lo, disc->grid_particles, disc, &volume);
  if (!ierr) ierr = use_particles(disc, &volume);
  MICA_FREE(volume);
  return ierr;
}

int mica_discretization_nodal_block(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                                    const MicaCellSpec *cells, const long lo[3], const long hi[3],
                                    MicaDiscretization **block) {
  int ierr = MICA_SUCCESS;
  GeomMap map;
  GeomAxes axes = {0};
  MicaDiscretization *d = NULL;
  double *xi = NULL, *volume = NULL;
  *block = NULL;
  MICA_CALL(check_supported(shape, layout));
  MICA_CALL(geom_map_init(shape, &map));
  MICA_CALL_CLEANUP(MICA_CALLOC(d, 1));
  d->dim = map.dim;
  MICA_CALL_CLEANUP(geom_axes_create(layout, map.dim, &axes));
  MICA_CALL_CLEANUP(geom_layout_box(&map, layout, &axes, lo, hi, &d->nparticles, &xi));
  MICA_CALL_CLEANUP(MICA_MALLOC(d->x, d->nparticles * map.dim + 1));
  for (long p = 0; p < d->nparticles; p++) geom_map_eval(&map, &xi[p * map.dim], &d->x[p * map.dim], NULL);
  MICA_CALL_CLEANUP(build_cells(shape, layout, cells, lo, hi, d, &volume));
  MICA_CALL_CLEANUP(MICA_MALLOC(d->qx, d->nparticles * map.dim + 1));
  memcpy(d->qx, d->x, sizeof(double) * (size_t)(d->nparticles * map.dim));
  d->qw = volume, volume = NULL;
  d->nquad = d->ncells = d->nparticles;
  for (long p = 0; p < d->nparticles; p++) d->volume += d->qw[p];
  *block = d, d = NULL;
cleanup:
  MICA_FREE(xi);
  MICA_FREE(volume);
  geom_axes_destroy(&axes);
  mica_discretization_destroy(&d);
  return ierr;
}

int mica_nodal_cells_destroy(MicaNodalCells **cells) {
  if (!cells || !*cells) return MICA_SUCCESS;
  MICA_FREE((*cells)->ptr);
  MICA_FREE((*cells)->x);
  MICA_FREE((*cells)->wn);
  MICA_FREE((*cells)->moment);
  MICA_FREE(*cells);
  return MICA_SUCCESS;
}
