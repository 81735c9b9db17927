/* The cells as a mesh for output (mica/geom.h, MicaCellMesh): the background cells of a built-in shape and
 * the elements of a Gmsh mesh, as points shared between neighbouring cells and cells that list them in VTK's
 * node order (docs/architecture.md, "Outputs").
 *
 * A built-in shape's cells are the boxes of its parameter grid mapped by X. Where X is multilinear on a cell
 * (box: affine; polygon: bilinear) the cell's image is exactly the bilinear quadrilateral or trilinear
 * hexahedron through its mapped corners. Elsewhere (plate_hole, annulus, cylinder) X bends the cells: they
 * are written as biquadratic quadrilaterals and triquadratic hexahedra (VTK 28, 29), their nodes the mapped
 * corners, edge midpoints, face centres and centre in parameter space, which follow an arc to O(h³) and carry
 * the fields at nine (27) points per cell. All nodes lie on the grid refined by two in parameter space, so a
 * node shared by neighbouring cells is one point.
 */
#include <math.h>
#include <string.h>

#include "geom_private.h"

/* ---- cell kinds ------------------------------------------------------------------------------------------ */

/* VTK's node order of the quadratic hexahedral kinds: the corners, then the midpoints of the edges (0,1), (1,2),
 * (3,2), (0,3), (4,5), (5,6), (7,6), (4,7), (0,4), (1,5), (2,6), (3,7), the centres of the faces x = 0, x = 1,
 * y = 0, y = 1, z = 0, z = 1 and the centre (vtkTriQuadraticHexahedron); the quadrilateral kinds are its
 * z = 0 face (corners, edge midpoints, centre: vtkBiQuadraticQuad). */
static const int hex_lattice[27][3] = {
    {0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}, /* corners */
    {1, 0, 0}, {2, 1, 0}, {1, 2, 0}, {0, 1, 0}, {1, 0, 2}, {2, 1, 2}, {1, 2, 2}, {0, 1, 2}, /* edges */
    {0, 0, 1}, {2, 0, 1}, {2, 2, 1}, {0, 2, 1},                                             /* vertical edges */
    {0, 1, 1}, {2, 1, 1}, {1, 0, 1}, {1, 2, 1}, {1, 1, 0}, {1, 1, 2},                       /* faces */
    {1, 1, 1}};
static const int quad_lattice[9][2] = {{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 0}, {2, 1}, {1, 2}, {0, 1}, {1, 1}};

int mica_cell_nodes(int type) {
  switch (type) {
  case MICA_CELL_TRIANGLE: return 3;
  case MICA_CELL_QUAD: return 4;
  case MICA_CELL_TETRA: return 4;
  case MICA_CELL_HEXAHEDRON: return 8;
  case MICA_CELL_BIQUADRATIC_QUAD: return 9;
  case MICA_CELL_TRIQUADRATIC_HEXAHEDRON: return 27;
  default: return 0;
  }
}

int mica_cell_lattice(int type, int *lattice) {
  const int n = mica_cell_nodes(type);
  const int hex = type == MICA_CELL_HEXAHEDRON || type == MICA_CELL_TRIQUADRATIC_HEXAHEDRON;
  if (!hex && type != MICA_CELL_QUAD && type != MICA_CELL_BIQUADRATIC_QUAD) return 0;
  for (int a = 0; a < n; a++)
    for (int d = 0; d < 3; d++) lattice[a * 3 + d] = hex ? hex_lattice[a][d] : d < 2 ? quad_lattice[a][d] : 0;
  return n;
}

static int cell_dim(int type) {
  return type == MICA_CELL_TETRA || type == MICA_CELL_HEXAHEDRON || type == MICA_CELL_TRIQUADRATIC_HEXAHEDRON ? 3 : 2;
}

/* ---- the mesh object ------------------------------------------------------------------------------------- */

int mica_cell_mesh_create(int dim, long npoints, long ncells, long nconn, MicaCellMesh **mesh) {
  MICA_CHECK(mesh && (dim == 2 || dim == 3) && npoints >= 0 && ncells >= 0 && nconn >= 0, MICA_ERR_ARGUMENT,
             "mica_cell_mesh_create: bad arguments (dim %d, %ld points, %ld cells)", dim, npoints, ncells);
  MicaCellMesh *m = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(m, 1));
  m->dim = dim, m->npoints = npoints, m->ncells = ncells;
  MICA_CALL_CLEANUP(MICA_MALLOC(m->x, npoints * dim + 1));
  MICA_CALL_CLEANUP(MICA_CALLOC(m->offsets, ncells + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(m->conn, nconn + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(m->type, ncells + 1));
  *mesh = m;
  return MICA_SUCCESS;
cleanup:
  mica_cell_mesh_destroy(&m);
  return ierr;
}

int mica_cell_mesh_create_uniform(int dim, long npoints, long ncells, int type, MicaCellMesh **mesh) {
  const int nodes = mica_cell_nodes(type);
  MICA_CHECK(nodes > 0, MICA_ERR_ARGUMENT, "mica_cell_mesh_create_uniform: unknown cell kind %d", type);
  MICA_CALL(mica_cell_mesh_create(dim, npoints, ncells, ncells * nodes, mesh));
  for (long c = 0; c < ncells; c++) {
    (*mesh)->offsets[c + 1] = (c + 1) * nodes;
    (*mesh)->type[c] = (unsigned char)type;
  }
  return MICA_SUCCESS;
}

int mica_cell_mesh_destroy(MicaCellMesh **mesh) {
  if (!mesh || !*mesh) return MICA_SUCCESS;
  MICA_FREE((*mesh)->x);
  MICA_FREE((*mesh)->offsets);
  MICA_FREE((*mesh)->conn);
  MICA_FREE((*mesh)->type);
  MICA_FREE(*mesh);
  return MICA_SUCCESS;
}

/* ---- orientation ------------------------------------------------------------------------------------------ */

/* The signed volume (area) spanned at node 0 by the edges to nodes e[0..dim-1]. */
static double corner_volume(const MicaCellMesh *m, const long *conn, const int *e) {
  const int dim = m->dim;
  double j[9];
  for (int k = 0; k < dim; k++)
    for (int i = 0; i < dim; i++) j[i * dim + k] = m->x[conn[e[k]] * dim + i] - m->x[conn[0] * dim + i];
  return geom_det(dim, j);
}

/* Cell c reversed if it is negatively oriented: a simplex by swapping nodes 1 and 2; a quadrilateral or
 * hexahedral kind by exchanging the reference axes 0 and 1, which maps VTK's node order onto itself. */
static void orient_cell(MicaCellMesh *m, long c) {
  static const int quad_edges[2] = {1, 3}, hex_edges[3] = {1, 3, 4}, simplex_edges[3] = {1, 2, 3};
  const int type = m->type[c];
  long *conn = m->conn + m->offsets[c];
  const int simplex = type == MICA_CELL_TRIANGLE || type == MICA_CELL_TETRA;
  const int *edges = simplex ? simplex_edges : cell_dim(type) == 3 ? hex_edges : quad_edges;
  if (cell_dim(type) != m->dim || corner_volume(m, conn, edges) >= 0) return;
  if (simplex) {
    const long swap = conn[1];
    conn[1] = conn[2], conn[2] = swap;
    return;
  }
  int lattice[27 * 3];
  long old[27];
  const int n = mica_cell_lattice(type, lattice);
  memcpy(old, conn, sizeof(long) * (size_t)n);
  for (int a = 0; a < n; a++)
    for (int b = 0; b < n; b++)
      if (lattice[b * 3] == lattice[a * 3 + 1] && lattice[b * 3 + 1] == lattice[a * 3] &&
          lattice[b * 3 + 2] == lattice[a * 3 + 2])
        conn[a] = old[b];
}

void mica_cell_mesh_orient(MicaCellMesh *mesh) {
  for (long c = 0; c < mesh->ncells; c++) orient_cell(mesh, c);
}

/* ---- a built-in shape's cells ---------------------------------------------------------------------------- */

/* X is multilinear on every cell of these shapes, so linear cells are their exact images. */
static int map_is_multilinear(const GeomMap *map) {
  return map->shape.kind == MICA_SHAPE_BOX || map->shape.kind == MICA_SHAPE_POLYGON;
}

int geom_grid_mesh_box(const GeomMap *map, const GeomGrid *grid, const long lo[3], const long hi[3],
                       MicaCellMesh **out) {
  const int dim = map->dim, refine = map_is_multilinear(map) ? 1 : 2;
  const int type = refine == 1 ? (dim == 2 ? MICA_CELL_QUAD : MICA_CELL_HEXAHEDRON)
                               : (dim == 2 ? MICA_CELL_BIQUADRATIC_QUAD : MICA_CELL_TRIQUADRATIC_HEXAHEDRON);
  long n[3] = {1, 1, 1}, w[3] = {1, 1, 1}, ncells = 1, npoints = 1; /* points and cells per axis in the box */
  for (int d = 0; d < dim; d++) w[d] = hi[d] - lo[d], n[d] = refine * w[d] + 1, ncells *= w[d], npoints *= n[d];
  MicaCellMesh *m = NULL;
  MICA_CALL(mica_cell_mesh_create_uniform(dim, npoints, ncells, type, &m));
  for (long p = 0; p < npoints; p++) { /* lexicographic, axis 0 fastest; midpoints halve the parameter cell */
    double xi[3] = {0, 0, 0};
    long rest = p;
    for (int d = 0; d < dim; d++) {
      const long i = rest % n[d], e = lo[d] + i / refine;
      rest /= n[d];
      xi[d] = i % refine ? 0.5 * (grid->edges[d][e] + grid->edges[d][e + 1]) : grid->edges[d][e];
    }
    geom_map_eval(map, xi, m->x + p * dim, NULL);
  }
  int lattice[27 * 3];
  const int nodes = mica_cell_lattice(type, lattice);
  for (long c = 0; c < ncells; c++) {
    long cell[3] = {0, 0, 0}, rest = c;
    for (int d = 0; d < dim; d++) cell[d] = rest % w[d], rest /= w[d];
    for (int a = 0; a < nodes; a++) {
      long point = 0;
      for (int d = dim - 1; d >= 0; d--) point = point * n[d] + refine * cell[d] + lattice[a * 3 + d] * refine / 2;
      m->conn[c * nodes + a] = point;
    }
  }
  mica_cell_mesh_orient(m);
  *out = m;
  return MICA_SUCCESS;
}

int geom_grid_mesh(const GeomMap *map, const GeomGrid *grid, MicaCellMesh **out) {
  const long lo[3] = {0, 0, 0}, hi[3] = {grid->n[0], grid->n[1], grid->n[2]};
  return geom_grid_mesh_box(map, grid, lo, hi, out);
}

/* ---- a Gmsh mesh's elements ------------------------------------------------------------------------------- */

/* Gmsh numbers the nodes of its linear elements as VTK does. */
static int gmsh_cell_type(int type) {
  switch (type) {
  case GMSH_TRI3: return MICA_CELL_TRIANGLE;
  case GMSH_QUAD4: return MICA_CELL_QUAD;
  case GMSH_TET4: return MICA_CELL_TETRA;
  case GMSH_HEX8: return MICA_CELL_HEXAHEDRON;
  default: return 0;
  }
}

/* The volume elements of the mesh; points are the particles (the nodes of volume elements, in node order, as
 * geom_mesh_discretize numbers them). */
int geom_mesh_cells(const GmshMesh *mesh, int dim, MicaCellMesh **out) {
  long *particle = NULL, ncells = 0, nconn = 0, npoints = 0;
  MicaCellMesh *m = NULL;
  int ierr = MICA_SUCCESS;
  for (long e = 0; e < mesh->nelements; e++) {
    if (gmsh_element_dim(mesh->type[e]) != dim) continue;
    MICA_CHECK(gmsh_cell_type(mesh->type[e]), MICA_ERR_ARGUMENT,
               "%s:%ld: element type %d has no output cell kind (src/geom/cell_mesh.c)", mesh->path, mesh->line[e],
               mesh->type[e]);
    ncells++, nconn += mesh->node_start[e + 1] - mesh->node_start[e];
  }
  MICA_CALL(MICA_MALLOC(particle, mesh->nnodes + 1));
  for (long i = 0; i < mesh->nnodes; i++) particle[i] = -1;
  for (long e = 0; e < mesh->nelements; e++)
    if (gmsh_element_dim(mesh->type[e]) == dim)
      for (long j = mesh->node_start[e]; j < mesh->node_start[e + 1]; j++) particle[mesh->node[j]] = 0;
  for (long i = 0; i < mesh->nnodes; i++)
    if (particle[i] == 0) particle[i] = npoints++;
  MICA_CALL_CLEANUP(mica_cell_mesh_create(dim, npoints, ncells, nconn, &m));
  for (long i = 0; i < mesh->nnodes; i++)
    if (particle[i] >= 0)
      for (int d = 0; d < dim; d++) m->x[particle[i] * dim + d] = mesh->x[i * 3 + d];
  long c = 0;
  for (long e = 0; e < mesh->nelements; e++) {
    if (gmsh_element_dim(mesh->type[e]) != dim) continue;
    m->type[c] = (unsigned char)gmsh_cell_type(mesh->type[e]);
    m->offsets[c + 1] = m->offsets[c] + mesh->node_start[e + 1] - mesh->node_start[e];
    for (long j = mesh->node_start[e]; j < mesh->node_start[e + 1]; j++)
      m->conn[m->offsets[c] + j - mesh->node_start[e]] = particle[mesh->node[j]];
    c++;
  }
  mica_cell_mesh_orient(m);
  *out = m;
cleanup:
  MICA_FREE(particle);
  return ierr;
}
