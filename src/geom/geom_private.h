/* Internal interfaces of src/geom: the shape maps (shapes.c), particle layouts (layout.c), background
 * cells and volume quadrature (cells.c), boundary sets of mapped shapes and the set storage (boundary.c),
 * the Gmsh reader (gmsh.c), the discretization of a mesh (mesh.c) and the cells as an output mesh
 * (cell_mesh.c). */
#ifndef MICA_GEOM_PRIVATE_H
#define MICA_GEOM_PRIVATE_H

#include <stdint.h>

#include "mica/geom.h"

#define GEOM_PI 3.14159265358979323846

enum {
  GEOM_GAUSS_MAX = 64, /* points per direction of any rule built on the stack */
  GEOM_SETS_MAX = 6,   /* boundary sets of a built-in shape */
  GEOM_PIECES_MAX = 4, /* parameter-box faces (or parts of faces) in one set */
  GEOM_KINKS_MAX = 2   /* parameter values per axis where a map is only continuous */
};

/* n-point Gauss–Legendre rule on [0, 1] (weights sum to 1). */
int geom_gauss_unit(int n, double *u, double *w);

/* ---- shape maps X(ξ): [0,1]^dim → body ---------------------------------------------------------------- */

/* A part of a face of the parameter box: ξ_axis = side (0 or 1), and lo ≤ ξ_d ≤ hi along the other axes. */
typedef struct {
  int axis, side;
  double lo[3], hi[3];
} GeomFacePiece;

typedef struct {
  char name[64];
  int npieces;
  GeomFacePiece pieces[GEOM_PIECES_MAX];
} GeomSetSpec;

typedef struct GeomMap {
  MicaShapeSpec shape; /* a copy of the parameters */
  int dim;
  double orientation; /* sign of det ∂X/∂ξ (constant over a valid map) */
  int nsets;
  GeomSetSpec sets[GEOM_SETS_MAX];
  /* parameter values where the map has a kink: cells must have an edge there, and jitter must not move
   * particles across it */
  int nkinks[3];
  double kinks[3][GEOM_KINKS_MAX];
} GeomMap;

/* Checks the shape's parameters and fills map (MICA_ERR_INPUT for bad shapes). Not for MICA_SHAPE_GMSH. */
int geom_map_init(const MicaShapeSpec *shape, GeomMap *map);
/* x = X(ξ) and jac[i*dim + j] = ∂x_i/∂ξ_j (jac may be NULL). */
void geom_map_eval(const GeomMap *map, const double *xi, double *x, double *jac);
/* det of a dim×dim matrix (row-major), and column a of its cofactor matrix (Nanson: n da = cof(J) N dA). */
double geom_det(int dim, const double *jac);
void geom_cofactor_column(int dim, const double *jac, int a, double *col);

/* ---- particle layouts and cells (parameter space) ------------------------------------------------------ */

/* 1-D parameter coordinates per axis: count[d] values from 0 to 1 (uniform or graded). */
typedef struct {
  int dim;
  long n[3];
  double *t[3];
} GeomAxes;

int geom_axes_create(const MicaLayoutSpec *layout, int dim, GeomAxes *axes);
void geom_axes_destroy(GeomAxes *axes);
/* Parameter coordinates of the particles ([*n × dim]) for any layout kind; allocates *xi. */
int geom_layout_particles(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes, long *n,
                          double **xi);
/* The particles of an irregular layout whose nearest grid point lies in the grid box [lo, hi), in the layout's order
 * (parameter coordinates [*n × dim]), and their keys, ascending: a boundary particle's its grid point's index, a
 * dart's above all of those, from its tile, its tile's colour and its place in the tile's draw (the same particle
 * the same key whatever the box). Drawn from the tiles around the box only; allocates *xi and *key. */
int geom_layout_irregular_box(const GeomAxes *axes, uint64_t seed, const long lo[3], const long hi[3], long *n,
                              double **xi, long **key);
/* For each of the n parameter points xi of an irregular layout, the index (axis 0 fastest) of the nearest point of
 * the regular layout of the same counts; allocates *index. */
int geom_layout_grid_index(const GeomAxes *axes, long n, const double *xi, long **index);
/* The particles of the grid box [lo, hi) of a regular, graded or jittered layout, the same values (grid order). */
int geom_layout_box(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes, const long lo[3],
                    const long hi[3], long *n, double **xi);

/* Background cells: a tensor grid in parameter space; edges[d] holds n[d] + 1 ascending values. */
typedef struct {
  int dim;
  long n[3];
  double *edges[3];
} GeomGrid;

int geom_grid_create(const GeomMap *map, const GeomAxes *axes, const MicaCellSpec *cells, GeomGrid *grid);
void geom_grid_destroy(GeomGrid *grid);
/* Volume quadrature points of the mapped cells into disc (qx, qw, nquad, ncells, volume). */
int geom_grid_quadrature(const GeomMap *map, const GeomGrid *grid, int order, MicaDiscretization *disc);
/* ... of the cells in the index box [lo, hi) only (cell order kept). */
int geom_grid_quadrature_box(const GeomMap *map, const GeomGrid *grid, int order, const long lo[3], const long hi[3],
                             MicaDiscretization *disc);
/* The mapped cells as an output mesh (cell_mesh.c): linear cells where the map is multilinear, biquadratic and
 * triquadratic ones where it bends them. */
int geom_grid_mesh(const GeomMap *map, const GeomGrid *grid, MicaCellMesh **mesh);
/* The same for the cells of the index box [lo, hi) (a distributed rank's block), points numbered within it. */
int geom_grid_mesh_box(const GeomMap *map, const GeomGrid *grid, const long lo[3], const long hi[3],
                       MicaCellMesh **mesh);

/* ---- boundary sets ------------------------------------------------------------------------------------- */

/* Allocates the arrays of a set (zeroed); geom_set_free releases them (safe on a zeroed set). */
int geom_set_alloc(MicaBoundarySet *set, int dim, long npoints, long nelements, int element_size,
                   long nvertices);
void geom_set_free(MicaBoundarySet *set);
/* The boundary sets of a mapped shape, integrated on the faces of the grid's cells; fills disc->sets. */
int geom_grid_boundary(const GeomMap *map, const GeomGrid *grid, int order, MicaDiscretization *disc);
/* ... on the faces of the cells in the index box [lo, hi) only (their vertices and elements numbered per set). */
int geom_grid_boundary_box(const GeomMap *map, const GeomGrid *grid, int order, const long lo[3], const long hi[3],
                           MicaDiscretization *disc);

/* ---- Gmsh meshes ------------------------------------------------------------------------------------- */

typedef enum {
  GMSH_LINE2 = 1,
  GMSH_TRI3 = 2,
  GMSH_QUAD4 = 3,
  GMSH_TET4 = 4,
  GMSH_HEX8 = 5,
  GMSH_POINT = 15
} GmshElementType;

typedef struct {
  char name[64];
  int dim, tag;
} GmshPhysical;

/* An entry of an entity index: an entity's tag and its position in the tables of its dimension. */
typedef struct {
  int tag;
  long entity;
} GmshEntityKey;

/* A mesh as read from a .msh file (4.1 ASCII or binary, 2.2 ASCII) or made from a .geo by the Gmsh library:
 * nodes, elements with their entity and source line, physical groups. */
typedef struct {
  char path[512];
  long nnodes;
  double *x; /* [nnodes*3] */
  long nelements;
  int *type; /* GmshElementType */
  int *entity_dim;
  int *entity_tag;
  long *tag;        /* the element tag in the file */
  long *line;       /* the line of the element in the file (0: meshed from a .geo, no line) */
  long *node_start; /* [nelements + 1]: offsets into node */
  long *node;       /* node indices (0-based into x) */
  int nphysicals;
  GmshPhysical *physicals;
  /* entity (dim, tag) → physical tags: entity_phys_start[dim] offsets over the entities of that dim */
  long nentities[4];
  int *entity_tags[4];
  long *entity_phys_start[4];
  int *entity_phys[4];
  /* the entities of each dimension sorted by (tag, position), built once the mesh is read, so that finding an
   * element's entity is a binary search rather than a scan of them all (gmsh_entity_physicals) */
  GmshEntityKey *entity_index[4];
  /* a part of a mesh (mesh_part.c, parallel.data = "distributed"): its dimension and the whole mesh's count of
   * uncovered boundary faces (a part's cut faces would look uncovered); 0 / unused for a whole mesh */
  int part_dim;
  long part_uncovered;
  long *node_key; /* a part: [nnodes] each node's index in the whole mesh, which names a boundary vertex alike on
                     every rank (MicaBoundarySet.vertex_key); NULL: the node's own index */
} GmshMesh;

/* What gmsh_read_filtered keeps: the nodes keep(x, ctx) accepts and the elements whose nodes it keeps all. */
typedef struct {
  int (*keep)(const double x[3], void *ctx);
  void *ctx;
  int max_dim; /* out: the largest dimension of the file's elements, kept or not */
  long nodes_read, elements_of_dim[4]; /* out: the file's nodes and elements (of each dimension), kept or not */
} GmshFilter;
/* A .msh file read through a filter (not a .geo): the kept nodes keep their positions in $Nodes as node_key; every
 * physical group is named (a 2.2 file: an entity for each) whether or not its elements are kept; the file is mapped,
 * not copied. */
int gmsh_read_filtered(const char *path, GmshFilter *filter, GmshMesh *mesh);
/* A name ending in .geo (any case): a script the Gmsh library meshes (whole). */
int gmsh_is_geo(const char *path);
/* Reads a .msh file, or meshes a .geo (a name ending in .geo) with the Gmsh library: size_factor > 0
 * multiplies its Mesh.MeshSizeFactor (0: as the .geo says; must be 0 for a .msh file). */
int gmsh_read(const char *path, double size_factor, GmshMesh *mesh);
/* The .geo path (gmsh_geo.c): checks the script (gmsh_geo_check), loads the library, meshes in the .geo's
 * dimension and copies nodes, elements and physical groups into mesh as a .msh file of it would hold them. */
int gmsh_geo_mesh(const char *path, double size_factor, GmshMesh *mesh);
/* The same mesh written by Gmsh to the file msh (binary MSH 4.1), which gmsh_read gives as gmsh_geo_mesh does. */
int gmsh_geo_write(const char *path, double size_factor, const char *msh);
/* How many Gmsh sessions this process ran (each meshes a .geo once). */
long gmsh_geo_sessions(void);
/* Refuses a .geo (or a file it includes or merges) that would run a program, end the process or write
 * files: MICA_ERR_INPUT "file:LINE: ..." (gmsh_geo_check.c). */
int gmsh_geo_check(const char *path);
void gmsh_free(GmshMesh *mesh);
/* "file:LINE" of element e, or "file (as meshed by Gmsh)" for a .geo, for messages. */
void gmsh_where(const GmshMesh *mesh, long e, char *out, size_t size);
/* Number of nodes and dimension of a supported element type (0 nodes: unsupported). */
int gmsh_element_nodes(int type);
int gmsh_element_dim(int type);
/* Physical tags of the entity (dim, tag): count, and *phys pointing into the mesh. When several entities share
 * the tag, the first one read. O(log entities). */
long gmsh_entity_physicals(const GmshMesh *mesh, int dim, int tag, const int **phys);

/* The discretization of a mesh: particles, element quadrature, boundary sets from physical groups. */
int geom_mesh_discretize(const GmshMesh *mesh, int order, int boundary_order, MicaDiscretization *disc);
/* (uncovered != NULL) The mesh's boundary faces in no set or several, plus set elements inside
 * (disc->boundary_uncovered), and (side_of != NULL) for each element of dimension dim − 1 the volume element it is a side of (−1: none). */
int geom_mesh_faces(const GmshMesh *mesh, int dim, long *uncovered, long *side_of);
/* The same with the uncovered faces counted only where mine(face centroid, ctx) holds. */
int geom_mesh_faces_where(const GmshMesh *mesh, int dim, int (*mine)(const double *, void *), void *mine_ctx,
                          long *uncovered, long *side_of);
/* The dimension of the mesh's volume elements (a part's: its own, even with no element). */
int geom_mesh_dimension(const GmshMesh *mesh);
/* MICA_ERR_INPUT unless the mesh has 2-D or 3-D elements (naming the physical-group pitfall). */
int geom_mesh_check_dimension(const GmshMesh *mesh);
/* Centroid of element e (the mean of its nodes). */
void geom_mesh_centroid(const GmshMesh *mesh, long e, double c[3]);
/* The per-element arrays (type, entities, tag, line, node_start) grown to `capacity` elements (node_start[0] = 0
 * the first time). */
int gmsh_mesh_grow_elements(GmshMesh *mesh, long capacity);
/* A MicaMesh's elements (mesh_part.c). */
const GmshMesh *geom_mesh_of(const MicaMesh *mesh);
/* The mesh's elements of dimension dim as an output mesh on the particles (cell_mesh.c). */
int geom_mesh_cells(const GmshMesh *mesh, int dim, MicaCellMesh **cells);

#endif
