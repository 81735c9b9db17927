/* MicaDiscretization: create (dispatching to the shape maps or to a Gmsh mesh, with the cells as an output
 * mesh), destroy, and the lookups of boundary sets by name. */
#include <stdio.h>
#include <math.h>
#include <string.h>

#include "geom_private.h"

/* Particles of a mapped shape: laid out in parameter space, then mapped by X into *x. */
/* The layout's particles mapped into x; for an irregular layout also each one's nearest grid point (*index). */
static int layout_mapped(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes, long *n,
                         double **x, long **index) {
  int ierr = MICA_SUCCESS;
  double *xi = NULL;
  MICA_CALL(geom_layout_particles(map, layout, axes, n, &xi));
  MICA_CALL_CLEANUP(MICA_MALLOC(*x, *n * map->dim));
  for (long p = 0; p < *n; p++) geom_map_eval(map, &xi[p * map->dim], &(*x)[p * map->dim], NULL);
  if (layout->kind == MICA_LAYOUT_IRREGULAR) MICA_CALL_CLEANUP(geom_layout_grid_index(axes, *n, xi, index));
cleanup:
  MICA_FREE(xi);
  return ierr;
}

/* The grids' sizes into disc (a regular, graded or jittered layout; 0 for the irregular one). */
static void set_grid(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes, const GeomGrid *grid,
                     const MicaCellSpec *cells, MicaDiscretization *disc) {
  if (layout->kind == MICA_LAYOUT_IRREGULAR) return;
  disc->grid_points_per_cell = 1;
  for (int d = 0; d < 3; d++) {
    disc->grid_particles[d] = d < map->dim ? axes->n[d] : 1;
    disc->grid_cells[d] = d < map->dim ? grid->n[d] : 1;
    if (d < map->dim) disc->grid_points_per_cell *= cells->order;
  }
}

/* The particles, and for a jittered or irregular layout the regular grid of the same counts (x_grid), on which the
 * supports are sized (docs/theory.md §supports). Jittered: the same particles before the jitter, in the same order
 * (the jitter moves particles in place); the nearer neighbor of a jittered particle can be as close as
 * (1 − 2 jitter) spacings, which at jitter 0.3 and dilation 2 leaves points near the boundary covered by one row
 * of particles only (a singular moment matrix). Irregular: each particle takes its nearest grid point's spacing
 * (grid_index); measured on the Poisson-disk particles themselves, the axis rule finds the nearest of scattered
 * neighbors, often well inside one spacing, and the supports come out small and uneven. */
static int mapped_particles(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes,
                            MicaDiscretization *disc) {
  MICA_CALL(layout_mapped(map, layout, axes, &disc->nparticles, &disc->x, &disc->grid_index));
  if (layout->kind != MICA_LAYOUT_JITTERED && layout->kind != MICA_LAYOUT_IRREGULAR) return MICA_SUCCESS;
  MicaLayoutSpec grid = *layout;
  long n;
  grid.kind = MICA_LAYOUT_REGULAR;
  MICA_CALL(layout_mapped(map, &grid, axes, &n, &disc->x_grid, NULL));
  if (layout->kind == MICA_LAYOUT_IRREGULAR) disc->ngrid = n;
  MICA_CHECK(n == disc->nparticles || disc->ngrid, MICA_ERR_ARGUMENT, "jittered layout: %ld particles, %ld on "
             "its grid", disc->nparticles, n);
  return MICA_SUCCESS;
}

static int boundary_order(const MicaCellSpec *cells) {
  return cells->boundary_order == 0 ? cells->order : cells->boundary_order;
}

static int create_mapped(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                         MicaDiscretization *disc) {
  int ierr = MICA_SUCCESS;
  GeomMap map;
  GeomAxes axes = {0};
  GeomGrid grid = {0};
  MICA_CALL(geom_map_init(shape, &map));
  disc->dim = map.dim;
  MICA_CALL_CLEANUP(geom_axes_create(layout, map.dim, &axes));
  MICA_CALL_CLEANUP(geom_grid_create(&map, &axes, cells, &grid));
  MICA_CALL_CLEANUP(geom_grid_quadrature(&map, &grid, cells->order, disc));
  MICA_CALL_CLEANUP(geom_grid_boundary(&map, &grid, boundary_order(cells), disc));
  MICA_CALL_CLEANUP(mapped_particles(&map, layout, &axes, disc));
  MICA_CALL_CLEANUP(geom_grid_mesh(&map, &grid, &disc->mesh));
  set_grid(&map, layout, &axes, &grid, cells, disc); /* particles on the index grid, cells on theirs */
cleanup:
  geom_axes_destroy(&axes);
  geom_grid_destroy(&grid);
  return ierr;
}

/* A jittered block's particles before the jitter (x_grid, as mapped_particles keeps for the whole layout: the
 * supports are sized on it), in the order of geom_layout_box's. */
static int block_grid_particles(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes,
                                const MicaGridBlock *block, MicaDiscretization *disc) {
  int ierr = MICA_SUCCESS;
  if (layout->kind != MICA_LAYOUT_JITTERED) return MICA_SUCCESS;
  MicaLayoutSpec grid = *layout;
  grid.kind = MICA_LAYOUT_REGULAR;
  double *xi = NULL;
  long n;
  MICA_CALL(geom_layout_box(map, &grid, axes, block->particle_lo, block->particle_hi, &n, &xi));
  if (n != disc->nparticles) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "jittered block: %ld particles, %ld on "
                          "its grid", disc->nparticles, n);
    goto cleanup;
  }
  MICA_CALL_CLEANUP(MICA_MALLOC(disc->x_grid, n * map->dim + 1));
  for (long p = 0; p < n; p++) geom_map_eval(map, &xi[p * map->dim], &disc->x_grid[p * map->dim], NULL);
cleanup:
  MICA_FREE(xi);
  return ierr;
}

static int create_block(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                        const MicaGridBlock *block, MicaDiscretization *disc) {
  int ierr = MICA_SUCCESS;
  GeomMap map;
  GeomAxes axes = {0};
  GeomGrid grid = {0};
  double *xi = NULL;
  MICA_CHECK(shape->kind != MICA_SHAPE_GMSH && layout->kind != MICA_LAYOUT_IRREGULAR, MICA_ERR_ARGUMENT,
             "mica_discretization_create_block: a Gmsh mesh or an irregular layout has no index grid");
  MICA_CALL(geom_map_init(shape, &map));
  disc->dim = map.dim;
  MICA_CALL_CLEANUP(geom_axes_create(layout, map.dim, &axes));
  MICA_CALL_CLEANUP(geom_grid_create(&map, &axes, cells, &grid));
  set_grid(&map, layout, &axes, &grid, cells, disc);
  MICA_CALL_CLEANUP(geom_grid_quadrature_box(&map, &grid, cells->order, block->cell_lo, block->cell_hi, disc));
  MICA_CALL_CLEANUP(
      geom_grid_boundary_box(&map, &grid, boundary_order(cells), block->boundary_lo, block->boundary_hi, disc));
  MICA_CALL_CLEANUP(geom_layout_box(&map, layout, &axes, block->particle_lo, block->particle_hi, &disc->nparticles, &xi));
  MICA_CALL_CLEANUP(MICA_MALLOC(disc->x, disc->nparticles * map.dim + 1));
  for (long p = 0; p < disc->nparticles; p++) geom_map_eval(&map, &xi[p * map.dim], &disc->x[p * map.dim], NULL);
  MICA_CALL_CLEANUP(block_grid_particles(&map, layout, &axes, block, disc));
  if (block->mesh) MICA_CALL_CLEANUP(geom_grid_mesh_box(&map, &grid, block->cell_lo, block->cell_hi, &disc->mesh));
cleanup:
  MICA_FREE(xi);
  geom_axes_destroy(&axes);
  geom_grid_destroy(&grid);
  return ierr;
}

int mica_discretization_create_block(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                                     const MicaCellSpec *cells, const MicaGridBlock *block, MicaDiscretization **disc) {
  int ierr = MICA_SUCCESS;
  MicaDiscretization *d = NULL;
  *disc = NULL;
  MICA_CALL(MICA_CALLOC(d, 1));
  MICA_CALL_CLEANUP(create_block(shape, layout, cells, block, d));
  *disc = d;
  return MICA_SUCCESS;
cleanup:
  mica_discretization_destroy(&d);
  return ierr;
}

int mica_discretization_grid(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                             long particles[3], long ncells[3], long *points_per_cell) {
  int ierr = MICA_SUCCESS;
  GeomMap map;
  GeomAxes axes = {0};
  GeomGrid grid = {0};
  MicaDiscretization d;
  memset(&d, 0, sizeof d);
  MICA_CHECK(shape->kind != MICA_SHAPE_GMSH && layout->kind != MICA_LAYOUT_IRREGULAR, MICA_ERR_ARGUMENT,
             "mica_discretization_grid: a Gmsh mesh or an irregular layout has no index grid");
  MICA_CALL(geom_map_init(shape, &map));
  MICA_CALL_CLEANUP(geom_axes_create(layout, map.dim, &axes));
  MICA_CALL_CLEANUP(geom_grid_create(&map, &axes, cells, &grid));
  set_grid(&map, layout, &axes, &grid, cells, &d);
  memcpy(particles, d.grid_particles, sizeof d.grid_particles);
  memcpy(ncells, d.grid_cells, sizeof d.grid_cells);
  *points_per_cell = d.grid_points_per_cell;
cleanup:
  geom_axes_destroy(&axes);
  geom_grid_destroy(&grid);
  return ierr;
}

static int create_from_mesh(const MicaShapeSpec *shape, const MicaCellSpec *cells, MicaDiscretization *disc) {
  int ierr = MICA_SUCCESS;
  GmshMesh mesh;
  MICA_CHECK(shape->mesh_path && shape->mesh_path[0], MICA_ERR_INPUT, "gmsh: no mesh file given");
  MICA_CALL(gmsh_read(shape->mesh_path, shape->mesh_size_factor, &mesh));
  MICA_CALL_CLEANUP(geom_mesh_discretize(&mesh, cells->order, boundary_order(cells), disc));
  MICA_CALL_CLEANUP(geom_mesh_cells(&mesh, disc->dim, &disc->mesh));
cleanup:
  gmsh_free(&mesh);
  return ierr;
}

int mica_discretization_create(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                               const MicaCellSpec *cells, MicaDiscretization **disc) {
  int ierr = MICA_SUCCESS;
  MICA_CHECK(shape && layout && cells && disc, MICA_ERR_ARGUMENT,
             "mica_discretization_create: NULL argument");
  *disc = NULL;
  MICA_CHECK(cells->order >= 1 && cells->order <= GEOM_GAUSS_MAX, MICA_ERR_INPUT,
             "cells: order = %d outside [1, %d]", cells->order, GEOM_GAUSS_MAX);
  MICA_CHECK(cells->boundary_order >= 0 && cells->boundary_order <= GEOM_GAUSS_MAX, MICA_ERR_INPUT,
             "cells: boundary_order = %d outside [0, %d] (0: the same as order)", cells->boundary_order,
             GEOM_GAUSS_MAX);
  MicaDiscretization *d = NULL;
  MICA_CALL(MICA_CALLOC(d, 1));
  if (shape->kind == MICA_SHAPE_GMSH)
    MICA_CALL_CLEANUP(create_from_mesh(shape, cells, d));
  else
    MICA_CALL_CLEANUP(create_mapped(shape, layout, cells, d));
  *disc = d;
  return MICA_SUCCESS;
cleanup:
  mica_discretization_destroy(&d);
  return ierr;
}

int mica_discretization_destroy(MicaDiscretization **disc) {
  if (!disc || !*disc) return MICA_SUCCESS;
  MicaDiscretization *d = *disc;
  for (int s = 0; s < d->nsets; s++) geom_set_free(&d->sets[s]);
  MICA_FREE(d->sets);
  MICA_FREE(d->x);
  MICA_FREE(d->x_grid);
  MICA_FREE(d->grid_index);
  MICA_FREE(d->qx);
  MICA_FREE(d->qw);
  MICA_FREE(d->qcell);
  MICA_FREE(d->gauss_x);
  MICA_FREE(d->gauss_w);
  mica_nodal_cells_destroy(&d->nodal);
  mica_cell_mesh_destroy(&d->mesh);
  MICA_FREE(*disc);
  return MICA_SUCCESS;
}

int mica_discretization_revolve(MicaDiscretization *d) {
  const double two_pi = 8 * atan(1.0);
  MICA_CHECK(d->dim == 2, MICA_ERR_INPUT, "an axisymmetric body needs a 2-D (r, z) section; this geometry is %d-D",
             d->dim);
  for (long p = 0; p < d->nparticles; p++)
    MICA_CHECK(d->x[p * 2] >= 0, MICA_ERR_INPUT,
               "an axisymmetric section lies in x = r ≥ 0; particle %ld is at r = %g", p + 1, d->x[p * 2]);
  d->volume = 0;
  for (long p = 0; p < d->nquad; p++) {
    d->qw[p] *= two_pi * d->qx[p * 2];
    d->volume += d->qw[p];
  }
  for (int s = 0; s < d->nsets; s++)
    for (long p = 0; p < d->sets[s].n; p++) d->sets[s].w[p] *= two_pi * d->sets[s].x[p * 2];
  return MICA_SUCCESS;
}

int mica_discretization_find_set(const MicaDiscretization *disc, const char *name) {
  for (int s = 0; s < disc->nsets; s++)
    if (strcmp(disc->sets[s].name, name) == 0) return s;
  return -1;
}

void mica_discretization_set_names(const MicaDiscretization *disc, char *buf, int size) {
  int used = 0;
  if (size <= 0) return;
  buf[0] = '\0';
  for (int s = 0; s < disc->nsets && used < size; s++) {
    const int n = snprintf(buf + used, (size_t)(size - used), "%s%s", s ? ", " : "", disc->sets[s].name);
    if (n < 0) break;
    used += n;
  }
}

int mica_layout_irregular_box(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const long lo[3],
                              const long hi[3], long *n, double **x, long **grid_index, long **key) {
  GeomMap map;
  GeomAxes axes = {0};
  double *xi = NULL;
  *n = 0, *x = NULL, *grid_index = NULL, *key = NULL;
  MICA_CHECK(shape->kind != MICA_SHAPE_GMSH && layout->kind == MICA_LAYOUT_IRREGULAR, MICA_ERR_ARGUMENT,
             "mica_layout_irregular_box: a built-in shape with an irregular layout");
  MICA_CALL(geom_map_init(shape, &map));
  int ierr = geom_axes_create(layout, map.dim, &axes);
  if (!ierr) ierr = geom_layout_irregular_box(&axes, (uint64_t)layout->seed, lo, hi, n, &xi, key);
  if (!ierr) ierr = MICA_MALLOC(*x, *n * map.dim + 1);
  for (long p = 0; !ierr && p < *n; p++) geom_map_eval(&map, &xi[p * map.dim], &(*x)[p * map.dim], NULL);
  if (!ierr) ierr = geom_layout_grid_index(&axes, *n, xi, grid_index);
  geom_axes_destroy(&axes);
  MICA_FREE(xi);
  if (ierr) {
    MICA_FREE(*x);
    MICA_FREE(*grid_index);
    MICA_FREE(*key);
    *n = 0;
  }
  return ierr;
}
