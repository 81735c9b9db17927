/* Background cells of the built-in shapes and their volume quadrature (docs/theory.md §geometry,
 * "Volume quadrature"). Cells are boxes of a tensor grid in parameter space: by default one cell between
 * neighboring particle lines (count − 1 per axis, following a graded layout), otherwise count[d] cells placed
 * along the particle lines (equal cells for a uniform layout, graded with a graded one). A kink of the map must
 * fall on a cell edge. Each cell carries the tensor Gauss rule of `order` points per axis, mapped by X:
 * weight = w_ref × (cell volume in parameter space) × |det ∂X/∂ξ|.
 */
#include <math.h>
#include <string.h>

#include "geom_private.h"

static int axis_edges(const GeomAxes *axes, long requested, int d, long *n, double **edges) {
  const long ncells = requested == 0 ? axes->n[d] - 1 : requested;
  MICA_CHECK(ncells >= 1, MICA_ERR_INPUT, "cells: count[%d] = %ld, need at least 1 (or 0 for the default)", d,
             requested);
  MICA_CALL(MICA_MALLOC(*edges, ncells + 1));
  *n = ncells;
  if (ncells == axes->n[d] - 1) {
    /* cells between particle lines, graded or not */
    memcpy(*edges, axes->t[d], (size_t)(ncells + 1) * sizeof **edges);
    return MICA_SUCCESS;
  }
  /* Other counts follow the particle lines too: edge i sits at the fractional line index i (n − 1)/ncells,
   * interpolated linearly between the lines, so k cells per spacing split each spacing into k equal parts and
   * a graded layout keeps its grading (equal cells in parameter space would put the same number of cells
   * where the particles are 40 times sparser). A uniform layout gives equal cells, as before. */
  const long nlines = axes->n[d];
  for (long i = 0; i <= ncells; i++) {
    const double position = (double)i * (double)(nlines - 1) / (double)ncells;
    long line = (long)floor(position);
    if (line >= nlines - 1) line = nlines - 2;
    const double frac = position - (double)line, *t = axes->t[d];
    (*edges)[i] = nlines < 2 ? (double)i / (double)ncells : t[line] + frac * (t[line + 1] - t[line]);
  }
  (*edges)[0] = 0.0, (*edges)[ncells] = 1.0;
  return MICA_SUCCESS;
}

/* Each kink of the map must be a cell edge (snapped exactly onto it), or cells would straddle it. */
static int check_kinks(const GeomMap *map, GeomGrid *grid) {
  for (int d = 0; d < grid->dim; d++)
    for (int k = 0; k < map->nkinks[d]; k++) {
      const double kink = map->kinks[d][k];
      long hit = -1;
      for (long i = 0; i <= grid->n[d]; i++)
        if (fabs(grid->edges[d][i] - kink) < 1e-9) hit = i;
      MICA_CHECK(
          hit >= 0, MICA_ERR_INPUT,
          "cells: the map has a kink at parameter %g along axis %d (the plate's corner), which must be a "
          "cell edge: use an even number of cells along that axis (%ld now; by default, an odd "
          "particle count) and no grading along it",
          kink, d, grid->n[d]);
      grid->edges[d][hit] = kink;
    }
  return MICA_SUCCESS;
}

int geom_grid_create(const GeomMap *map, const GeomAxes *axes, const MicaCellSpec *cells, GeomGrid *grid) {
  int ierr = MICA_SUCCESS;
  *grid = (GeomGrid){.dim = map->dim, .n = {1, 1, 1}};
  for (int d = 0; d < map->dim; d++)
    MICA_CALL_CLEANUP(axis_edges(axes, cells->count[d], d, &grid->n[d], &grid->edges[d]));
  MICA_CALL_CLEANUP(check_kinks(map, grid));
  return MICA_SUCCESS;
cleanup:
  geom_grid_destroy(grid);
  return ierr;
}

void geom_grid_destroy(GeomGrid *grid) {
  for (int d = 0; d < 3; d++) MICA_FREE(grid->edges[d]);
}

static const char *shape_name(MicaShapeKind kind) {
  static const char *names[] = {"box", "polygon", "plate_hole", "annulus", "cylinder", "gmsh"};
  return kind >= MICA_SHAPE_BOX && kind <= MICA_SHAPE_GMSH ? names[kind] : "shape";
}

/* One mapped Gauss point: position, weight; MICA_ERR_INPUT where the map folds or degenerates. */
static int mapped_point(const GeomMap *map, const double *xi, double wref, double *x, double *w) {
  double jac[9];
  geom_map_eval(map, xi, x, jac);
  const double det = geom_det(map->dim, jac) * map->orientation;
  MICA_CHECK(det > 0 && isfinite(det), MICA_ERR_INPUT,
             "%s: the map from parameter space is degenerate at ξ = (%g, %g, %g) (det ∂X/∂ξ = %g)",
             shape_name(map->shape.kind), xi[0], xi[1], map->dim == 3 ? xi[2] : 0.0, det * map->orientation);
  *w = wref * det;
  return MICA_SUCCESS;
}

int geom_grid_quadrature(const GeomMap *map, const GeomGrid *grid, int order, MicaDiscretization *disc) {
  const long lo[3] = {0, 0, 0};
  return geom_grid_quadrature_box(map, grid, order, lo, grid->n, disc);
}

static int in_cell_box(const long cell[3], const long lo[3], const long hi[3]) {
  for (int d = 0; d < 3; d++)
    if (cell[d] < lo[d] || cell[d] >= hi[d]) return 0;
  return 1;
}

int geom_grid_quadrature_box(const GeomMap *map, const GeomGrid *grid, int order, const long lo_box[3],
                             const long hi_box[3], MicaDiscretization *disc) {
  const int dim = map->dim;
  double u[GEOM_GAUSS_MAX], wu[GEOM_GAUSS_MAX];
  MICA_CHECK(order >= 1 && order <= GEOM_GAUSS_MAX, MICA_ERR_INPUT, "cells: order = %d outside [1, %d]",
             order, GEOM_GAUSS_MAX);
  MICA_CALL(geom_gauss_unit(order, u, wu));
  long ncells = 1, per_cell = 1, mine = 1;
  for (int d = 0; d < dim; d++) ncells *= grid->n[d], per_cell *= order;
  for (int d = 0; d < 3; d++) mine *= hi_box[d] > lo_box[d] ? hi_box[d] - lo_box[d] : 0;
  disc->ncells = mine;
  disc->nquad = mine * per_cell;
  MICA_CALL(MICA_MALLOC(disc->qx, disc->nquad * dim + 1));
  MICA_CALL(MICA_MALLOC(disc->qw, disc->nquad + 1));
  MICA_CALL(MICA_MALLOC(disc->qcell, disc->nquad + 1)); /* a cell pressure (material.pressure) groups by it */
  disc->volume = 0.0;
  long q = 0;
  for (long c = 0; c < ncells && mine > 0; c++) {
    long cell[3] = {0, 0, 0}, rest = c;
    for (int d = 0; d < dim; d++) cell[d] = rest % grid->n[d], rest /= grid->n[d];
    if (!in_cell_box(cell, lo_box, hi_box)) continue;
    rest = c;
    double lo[3] = {0, 0, 0}, width[3] = {1, 1, 1}, vol = 1.0;
    for (int d = 0; d < dim; d++) {
      cell[d] = rest % grid->n[d], rest /= grid->n[d];
      lo[d] = grid->edges[d][cell[d]];
      width[d] = grid->edges[d][cell[d] + 1] - lo[d];
      vol *= width[d];
    }
    for (long g = 0; g < per_cell; g++, q++) {
      double xi[3] = {0, 0, 0}, wref = vol;
      long k = g;
      for (int d = 0; d < dim; d++, k /= order) {
        xi[d] = lo[d] + u[k % order] * width[d];
        wref *= wu[k % order];
      }
      MICA_CALL(mapped_point(map, xi, wref, &disc->qx[q * dim], &disc->qw[q]));
      disc->qcell[q] = c;
      disc->volume += disc->qw[q];
    }
  }
  return MICA_SUCCESS;
}
