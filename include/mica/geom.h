/* Geometry, particles and integration points (docs/theory.md §geometry).
 *
 * A body is either a built-in shape — a map X(ξ) from a parameter box [0,1]^dim onto the body, so that
 * particles, background cells and boundaries are laid out in parameter space and mapped exactly (cells
 * conform to curved boundaries) — or a Gmsh mesh (.msh 4.1 ASCII: nodes are particles, elements are
 * integration cells, physical groups are named boundary sets). Either way the result is a
 * MicaDiscretization: particles, volume quadrature points, and named boundary sets of quadrature points
 * with outward normals. Everything downstream works on these point lists and never sees a cell.
 */
#ifndef MICA_GEOM_H
#define MICA_GEOM_H

#include "mica/error.h"

/* ---- Gauss rules (src/geom/gauss.c) ----------------------------------------------------------------- */

/* n-point Gauss–Legendre rule on [−1, 1] (any n ≥ 1), exact for polynomials of degree 2n − 1. */
int mica_gauss_legendre(int n, double *x, double *w);
/* Rules on the reference triangle (0,0),(1,0),(0,1) and tetrahedron (0,0,0),(1,0,0),(0,1,0),(0,0,1) by
 * collapsed (Duffy) Gauss products with n points per direction: n² (n³) points, weights summing to the
 * reference area 1/2 (volume 1/6), exact for polynomials of degree 2n − 2 (and more). */
int mica_gauss_triangle(int n, double *xi /* [n*n*2] */, double *w /* [n*n] */);
int mica_gauss_tetrahedron(int n, double *xi /* [n*n*n*3] */, double *w /* [n*n*n] */);

/* ---- Specifications (filled from a deck by the caller) ---------------------------------------------- */

typedef enum {
  MICA_SHAPE_BOX = 0,        /* 2-D or 3-D axis-aligned box: lower, upper */
  MICA_SHAPE_POLYGON = 1,    /* 2-D quadrilateral (e.g. Cook's trapezoid): 4 vertices counterclockwise */
  MICA_SHAPE_PLATE_HOLE = 2, /* 2-D quarter plate [0,bx]×[0,by] minus the disk of radius a at the origin */
  MICA_SHAPE_ANNULUS = 3,    /* 2-D annulus sector: r_inner ≤ r ≤ r_outer, theta0 ≤ θ ≤ theta1 (radians) */
  MICA_SHAPE_CYLINDER = 4,   /* 3-D cylinder: radius, axis along z from 0 to height */
  MICA_SHAPE_GMSH = 5        /* a Gmsh mesh (2-D triangles/quads or 3-D tets/hexes): a .msh file (4.1 ASCII or
                                binary, 2.2 ASCII) or a .geo that the Gmsh library meshes */
} MicaShapeKind;

typedef struct MicaShapeSpec {
  MicaShapeKind kind;
  int dim;                 /* 2 or 3 (box: from lower/upper; gmsh: from the mesh) */
  double lower[3], upper[3];
  double vertices[4][2];   /* polygon */
  double hole_radius, plate_size[2]; /* plate_hole: a, (bx, by) */
  double r_inner, r_outer, theta0, theta1; /* annulus */
  double radius, height;   /* cylinder */
  const char *mesh_path;   /* gmsh: .msh, or .geo */
  double mesh_size_factor; /* gmsh .geo: multiplies its Mesh.MeshSizeFactor; 0 = as the .geo says */
} MicaShapeSpec;

typedef enum {
  MICA_LAYOUT_REGULAR = 0,   /* count[d] particles per parameter axis, evenly spaced in parameter space */
  MICA_LAYOUT_GRADED = 1,    /* spacing grows geometrically along each axis: last/first = grading[d] */
  MICA_LAYOUT_JITTERED = 2,  /* regular, interior particles shifted by ±jitter × spacing per axis */
  MICA_LAYOUT_IRREGULAR = 3  /* boundary particles regular; interior by Poisson-disk sampling in parameter
                                space with the regular spacing as minimum distance (seeded) */
} MicaLayoutKind;

typedef struct MicaLayoutSpec {
  MicaLayoutKind kind;
  long count[3];     /* particles per parameter axis (ignored for gmsh) */
  double jitter;     /* fraction of the spacing */
  double grading[3]; /* graded: ratio of the last spacing to the first per axis (1 = uniform) */
  long seed;
} MicaLayoutSpec;

typedef struct MicaCellSpec {
  long count[3];      /* background cells per parameter axis; 0 = count − 1 of the layout (cells between
                         particles) */
  int order;          /* Gauss points per direction in a cell (tri/tet: per collapsed direction) */
  int boundary_order; /* Gauss points per direction on boundary edges/faces; 0 = order */
} MicaCellSpec;

/* ---- The discretization ------------------------------------------------------------------------------ */

/* A named part of the boundary, as quadrature points, plus the boundary elements (edges in 2-D, faces in
 * 3-D) those points lie on — a multiplier field for Lagrange-multiplier constraints is interpolated on
 * them, linearly between their vertices (2 per edge; 4 per quad face, 3 per triangle face). */
typedef struct MicaBoundarySet {
  char name[64];
  long n;           /* quadrature points */
  double *x;        /* [n*dim] positions */
  double *w;        /* [n] weights (length or area element included) */
  double *normal;   /* [n*dim] outward unit normals */
  long *element;    /* [n] the boundary element of each point */
  double *lambda_N; /* [n*4] linear shape functions of the element's vertices at the point */
  long nvertices;   /* boundary vertices of this set (multiplier nodes) */
  double *vertex_x; /* [nvertices*dim] */
  long nelements;
  int element_size; /* vertices per element: 2 (2-D), 3 or 4 (3-D) */
  long *element_vertices; /* [nelements*element_size], indices into this set's vertices */
  long *cell;       /* [n] the volume cell (finite element) each point lies on, or NULL if not recorded */
  long *grid_cell;  /* [n] the background cell of a built-in shape's index grid the point lies on (axis 0
                       fastest; what parallel.data = "distributed" gives each point's owner by), or NULL */
  long *vertex_key; /* [nvertices] a built-in shape's vertex as its index in the grid of cell corners (axis 0
                       fastest), a Gmsh mesh's as its node's index in the whole mesh: the same on every rank, which
                       parallel.data = "distributed" names a multiplier node by; or NULL */
} MicaBoundarySet;

/* Nodal cells (mica_discretization_nodal): one cell Ω_I per particle, tiling the body, each given by Gauss
 * points on its boundary faces with weight × outward normal. Neighboring cells share faces (the same points,
 * opposite normals), which is what makes SCNI's smoothed gradients conforming (docs/theory.md §nodal). */
typedef struct MicaNodalCells {
  long n;          /* cells: one per particle, in particle order */
  long *ptr;       /* [n+1]: cell I's boundary points are ptr[I] .. ptr[I+1) */
  double *x;       /* [ptr[n]*dim] positions */
  double *wn;      /* [ptr[n]*dim] weight (length/area element included) × outward unit normal */
  double *moment;  /* [n*dim*dim] second moments ∫_Ω_I (x − x_I) ⊗ (x − x_I) dV about the particle (NSNI) */
} MicaNodalCells;

/* The background cells (or the mesh's elements) as a mesh for output (src/geom/cell_mesh.c): shared points
 * written once and cells as lists of them, so that a viewer can colour and contour fields over the cells. Only
 * the output uses it; the solver never sees a cell. Cell kinds are numbered as VTK numbers them (its cell type
 * ids), so the VTU writer passes them through; the nodes of a cell are in VTK's order (mica_cell_lattice). */
typedef enum {
  MICA_CELL_TRIANGLE = 5,
  MICA_CELL_QUAD = 9,
  MICA_CELL_TETRA = 10,
  MICA_CELL_HEXAHEDRON = 12,
  MICA_CELL_BIQUADRATIC_QUAD = 28,       /* 9 nodes: corners, edge midpoints, centre */
  MICA_CELL_TRIQUADRATIC_HEXAHEDRON = 29 /* 27 nodes: corners, edge midpoints, face centres, centre */
} MicaCellType;

typedef struct MicaCellMesh {
  int dim;
  long npoints;
  double *x;           /* [npoints*dim] */
  long ncells;
  long *offsets;       /* [ncells+1]: the nodes of cell c are conn[offsets[c] .. offsets[c+1]) */
  long *conn;          /* point indices */
  unsigned char *type; /* [ncells] MicaCellType */
} MicaCellMesh;

/* Nodes of a cell kind (0: not a kind mica writes). */
int mica_cell_nodes(int type);
/* The nodes of a quadrilateral or hexahedral kind in VTK's order as positions on the lattice {0, 1, 2}^dim of its
 * reference box [0, 1]^dim (lattice/2 is the position; linear kinds use 0 and 2): lattice[a*3 + d]. Returns the
 * node count, 0 for other kinds. */
int mica_cell_lattice(int type, int *lattice);
/* A mesh of npoints points (dim coordinates) and ncells cells with nconn nodes in all: the arrays are allocated,
 * offsets[0] = 0, and the caller fills x, offsets, conn and type. */
int mica_cell_mesh_create(int dim, long npoints, long ncells, long nconn, MicaCellMesh **mesh);
/* The same for ncells cells of one kind: offsets and types filled too. */
int mica_cell_mesh_create_uniform(int dim, long npoints, long ncells, int type, MicaCellMesh **mesh);
int mica_cell_mesh_destroy(MicaCellMesh **mesh);
/* Reverses the node order of every cell whose volume (area) comes out negative at its first corner, so that all
 * cells are positively oriented, as viewers' area, volume and integration filters assume. */
void mica_cell_mesh_orient(MicaCellMesh *mesh);

typedef struct MicaDiscretization {
  int dim;
  long nparticles;
  double *x;        /* [nparticles*dim] */
  double *x_grid;   /* jittered layout: the same particles before the jitter, [nparticles*dim]; irregular layout:
                       the regular layout of the same counts, [ngrid*dim]; the supports are sized on it (mls:
                       spacing_points); else NULL */
  long ngrid;       /* irregular layout: the points in x_grid; 0 when x_grid holds one point per particle */
  long *grid_index; /* irregular layout: [nparticles], the grid point nearest each particle in parameter space,
                       whose spacing it takes (mls: spacing_index); else NULL (particle I is grid point I) */
  long ncells;      /* background integration cells */
  long nquad;
  double *qx;       /* [nquad*dim] volume quadrature points */
  double *qw;       /* [nquad] weights (Jacobian included) */
  long *qcell;      /* [nquad] the cell (finite element) of each volume point, or NULL if not recorded */
  int nsets;
  MicaBoundarySet *sets;
  double volume;    /* Σ qw: the body's area (2-D) or volume (3-D) */
  long boundary_uncovered; /* boundary faces of a Gmsh mesh in no set or in several, plus set elements inside
                              the body; 0 when the sets cover the boundary exactly once (always, for the
                              built-in shapes), as VCI's boundary sums need */
  /* Nodal integration (mica_discretization_nodal): qx, qw are the particles and their nodal cells' volumes,
   * ncells = nparticles, and the background cells' Gauss points are kept here, for error norms that do not
   * share the nodal rule's blind spots. NULL / 0 otherwise. */
  MicaNodalCells *nodal;
  long ngauss;
  double *gauss_x;  /* [ngauss*dim] */
  double *gauss_w;  /* [ngauss] */
  /* The cells as a mesh for output: the background cells of a built-in shape (bilinear quadrilaterals and
   * trilinear hexahedra where the map is multilinear, biquadratic and triquadratic ones where it bends them),
   * a Gmsh mesh's elements, or the finite elements of problem.method = "fe"; NULL if none. */
  MicaCellMesh *mesh;
  /* A built-in shape with particles on an index grid (regular, graded, jittered layouts): particles per axis
   * (particle i0 + n0 (i1 + n1 i2)), background cells per axis (cell c0 + m0 (c1 + m1 c2), whose Gauss points
   * are qx[c·grid_points_per_cell ...]); 0 otherwise (Gmsh, irregular, nodal): what parallel.data =
   * "distributed" splits into blocks. */
  long grid_particles[3], grid_cells[3];
  long grid_points_per_cell;
} MicaDiscretization;

/* Builds particles, cells and quadrature points. Errors (MICA_ERR_INPUT): sizes, counts < 2, a polygon that
 * is not convex and counterclockwise, a hole larger than the plate, a Gmsh file that cannot be read or is
 * truncated (naming the file and line). */
int mica_discretization_create(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                               const MicaCellSpec *cells, MicaDiscretization **disc);
int mica_discretization_destroy(MicaDiscretization **disc);

/* A block of a built-in shape's index grids (regular, graded or jittered layout): boxes [lo, hi) of grid indices. */
typedef struct MicaGridBlock {
  long particle_lo[3], particle_hi[3]; /* the particles laid out (grid order, the whole layout's values) */
  long cell_lo[3], cell_hi[3];         /* the cells whose volume points are built (cell order) */
  long boundary_lo[3], boundary_hi[3]; /* the cells whose boundary faces' points are built */
  int mesh;                            /* 1: the output mesh of the cells [cell_lo, cell_hi) (disc->mesh) */
} MicaGridBlock;
/* Only the block's particles, volume points and boundary points (no output mesh; grid_* give the whole grids; the
 * sets' boundary vertices and elements are those of the block's faces, numbered per set; volume: the block's). What
 * an MPI rank builds with parallel.data = "distributed": nothing of the whole layout's size. */
int mica_discretization_create_block(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                                     const MicaCellSpec *cells, const MicaGridBlock *block, MicaDiscretization **disc);
/* The grids' sizes alone: particles and cells per axis (1 beyond the dimension), Gauss points per cell. */
int mica_discretization_grid(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                             long particles[3], long ncells[3], long *points_per_cell);
/* The particles of an irregular layout whose nearest point of the regular grid of the same counts lies in the grid
 * box [lo, hi) (lo 0 and hi the counts: the whole body's, as mica_discretization_create lays them out), in the
 * layout's order (x[n·dim]); each one's nearest grid point (grid_index[n], axis 0 fastest), whose spacing it takes,
 * and its key (key[n], ascending: the same particle has the same key whatever the box). Drawn from the layout's
 * tiles around the box only: what each rank of parallel.data = "distributed" draws of it. */
int mica_layout_irregular_box(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const long lo[3],
                              const long hi[3], long *n, double **x, long **grid_index, long **key);
/* Nodal integration: builds a nodal cell around every particle, the dual cells of the particles' logical
 * grid (corners at the averages of the 2^dim surrounding particles in parameter space, so boundary particles
 * get half and quarter cells; mapped by the shape's X, so curved boundaries are followed; split where the map
 * has a kink), and turns disc (made by mica_discretization_create from the same specifications) into a nodal
 * discretization: volume points = particles, weights = cell volumes (by the divergence theorem on the cell's
 * faces), boundary sets rebuilt on the cells' boundary faces (the same Gauss rule of cells->boundary_order
 * points, so that tractions, weak Dirichlet terms and SCNI's smoothing share their boundary points), and the
 * cells' boundary points in disc->nodal. Built-in shapes with the regular, graded and jittered layouts only:
 * MICA_ERR_INPUT for a Gmsh mesh, an irregular layout, or a cell that folds (volume ≤ 0). */
int mica_discretization_nodal(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                              MicaDiscretization *disc);
/* The nodal cells of the particles of one box [lo, hi) of a built-in shape's index grid (what a rank builds with
 * parallel.data = "distributed"): a new discretization of only those particles (x, grid order), their cells
 * (nodal: boundary points and second moments), qx = x, qw = the cells' volumes, and the boundary sets on their
 * faces, whose vertices are named (vertex_key) by the whole dual grid's corners, alike on every box. The cells are
 * the ones mica_discretization_nodal builds for the same particles; no Gauss points, no output mesh. */
int mica_discretization_nodal_block(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                                    const MicaCellSpec *cells, const long lo[3], const long hi[3],
                                    MicaDiscretization **block);
/* NSNI's points (docs/theory.md §NSNI): the volume points of a nodal discretization moved from the particles to
 * their cells' centroids x_I + S_I/|Ω_I| (S_I = ∫ (x − x_I) dV, by the divergence theorem on the cells' boundary
 * points), and the second moments taken about them (M − S Sᵀ/|Ω_I|), so that the first moments of the
 * expansion vanish exactly. */
int mica_discretization_nodal_centroids(MicaDiscretization *disc);
/* NSNI's points without a particle grid (irregular layouts, Gmsh meshes; src/geom/nodal_points.c): cell I is the
 * set of the background Gauss points nearest to particle I; its volume, centroid (the new volume point) and
 * central second moments are their weighted sums. The cells have no boundary points (not for SCNI); the Gauss
 * points are kept for the error norms. MICA_ERR_INPUT if a particle is the nearest to no Gauss point. */
int mica_discretization_nodal_points(MicaDiscretization *disc);
/* The same cells for the particles with mine[I] (NULL: all) of disc's, in particle order, from the ng Gauss points
 * gx, gw (NULL: disc's own volume points) of a region that holds every point whose nearest particle is one of them
 * (parallel.data = "distributed": a rank's owned particles and the Gauss points around its box); disc's own volume
 * points become its Gauss points (the error norms'). */
int mica_discretization_nodal_points_from(MicaDiscretization *disc, const char *mine, long ng, const double *gx,
                                          const double *gw);
/* The NSNI points of those cells: n of them, centroids qx, volumes qw, and the cells' central second moments. */
typedef struct MicaNodalPoints {
  long n;
  double *qx, *qw;
  MicaNodalCells *cells;
} MicaNodalPoints;
int mica_nodal_points_of(int dim, long np, const double *x, const char *mine, long ng, const double *gx,
                         const double *gw, MicaNodalPoints *out);
int mica_nodal_cells_destroy(MicaNodalCells **cells);
/* Turns a 2-D section in the (r, z) = (x, y) half-plane into the body of revolution it sweeps about the
 * y axis: every volume and boundary weight is multiplied by 2πr, so Σ qw is the body's volume and boundary
 * sums are integrals over surfaces of revolution. MICA_ERR_INPUT if the section is not 2-D or reaches r < 0. */
int mica_discretization_revolve(MicaDiscretization *disc);
/* Index of the boundary set with this name, or −1. */
int mica_discretization_find_set(const MicaDiscretization *disc, const char *name);
/* The names of the sets, comma-separated, for error messages ("left, right, bottom, top"). */
void mica_discretization_set_names(const MicaDiscretization *disc, char *buf, int size);

/* ---- A Gmsh mesh in parts (src/geom/mesh_part.c), for parallel.data = "distributed" ------------------------ */

/* The mesh of a shape specification (geometry.shape = "gmsh") as read, with its particles: the nodes of its volume
 * elements in the order mica_discretization_create numbers them. */
typedef struct MicaMesh MicaMesh;
int mica_mesh_read(const MicaShapeSpec *shape, MicaMesh **mesh);
int mica_mesh_destroy(MicaMesh **mesh);
int mica_mesh_dim(const MicaMesh *mesh);
long mica_mesh_num_particles(const MicaMesh *mesh); /* a part: 0 */
const double *mica_mesh_particles(const MicaMesh *mesh);
/* The largest distance between two nodes of one volume element (of the whole mesh, also for a part). */
double mica_mesh_element_size(const MicaMesh *mesh);
/* Accepts a volume element by its centroid (the mean of its nodes; 3 coordinates). */
typedef int (*MicaMeshKeep)(const double *centroid, void *ctx);
/* A part: the volume elements `keep` accepts, the boundary elements that are sides of them, their nodes; every
 * physical group (so the part's discretization names every set, with no points if it holds none of it), and as
 * its discretization's boundary_uncovered its share of the uncovered boundary faces, those whose centroids `keep`
 * accepts: over the parts of a split, with each face's elements in the mesh split, the shares add up to the whole
 * mesh's count. */
int mica_mesh_part(const MicaMesh *mesh, MicaMeshKeep keep, void *ctx, MicaMesh **part);
/* Each particle's key: its node's position in the whole mesh (a region's particles keep the whole mesh's). */
const long *mica_mesh_particle_keys(const MicaMesh *mesh);

/* A .geo (shape->mesh_path, with its mesh size factor) meshed by the Gmsh library and written to msh (binary MSH 4.1),
 * which mica reads as the .geo itself: so that one rank meshes and the others read their regions of the file. */
int mica_mesh_geo_write(const MicaShapeSpec *shape, const char *msh);
/* A name ending in .geo (any case): a script that mica has the Gmsh library mesh. */
int mica_mesh_is_geo(const char *path);
/* How many .geo files this process meshed with the Gmsh library. */
long mica_mesh_geo_sessions(void);

/* A Gmsh mesh read in parts: a .msh file in passes through a filter, never whole; a .geo meshed whole, once. Opening
 * reads the groups and the dimension (names: a mesh without elements, whose discretization names every set) and a
 * sample of at most 2^18 node coordinates, the same on every rank. */
typedef struct MicaMeshSource MicaMeshSource;
int mica_mesh_source_open(const MicaShapeSpec *shape, MicaMeshSource **source);
int mica_mesh_source_close(MicaMeshSource **source);
int mica_mesh_source_dim(const MicaMeshSource *source);
const MicaMesh *mica_mesh_source_names(const MicaMeshSource *source);
const double *mica_mesh_source_sample(const MicaMeshSource *source, long *n);
/* The counts the first pass saw: nodes, volume elements and boundary elements (a 2.2 file: an element once per
 * physical group it is in), for the cost estimate. */
void mica_mesh_source_counts(const MicaMeshSource *source, long *nodes, long *volume_elements,
                             long *boundary_elements);
/* The bounding box of the mesh's nodes. */
void mica_mesh_source_bounds(const MicaMeshSource *source, double lower[3], double upper[3]);
/* The region [lo, hi) of the mesh: its nodes there and the elements whose nodes all lie there, with the particles
 * among them (nodes of its volume elements) keyed as in the whole mesh. */
int mica_mesh_source_region(const MicaMeshSource *source, const double lo[3], const double hi[3], MicaMesh **region);
/* What mica_discretization_create builds from a Gmsh mesh, for a mesh or a part already read: particles (its
 * nodes), its elements' volume points, boundary sets (the output mesh of its elements if output_mesh). */
int mica_discretization_create_mesh(const MicaMesh *mesh, const MicaCellSpec *cells, int output_mesh,
                                    MicaDiscretization **disc);

/* ---- Inside the body (src/geom/inside.c) ------------------------------------------------------------- */

/* The body of a shape specification, for asking whether a point lies in it: a built-in shape by its exact
 * geometry, a Gmsh mesh by its volume elements (it reads the file). Points within MICA_BODY_TOLERANCE × the
 * diagonal of the body's bounding box of it count as inside, so points on the boundary do. */
#define MICA_BODY_TOLERANCE 1e-8
typedef struct MicaBody MicaBody;
int mica_body_create(const MicaShapeSpec *shape, MicaBody **body);
/* The body of a Gmsh shape's part (parallel.data = "distributed": a rank's elements; the part is not copied and must
 * outlive the body): a point lies in the whole body if it lies in some rank's part. Its bounds are the part's until
 * mica_body_set_bounds gives the whole body's (the tolerance follows them). */
int mica_body_create_part(const MicaShapeSpec *shape, const MicaMesh *part, MicaBody **body);
void mica_body_set_bounds(MicaBody *body, const double lower[3], const double upper[3]);
int mica_body_destroy(MicaBody **body);
int mica_body_dim(const MicaBody *body);
/* 1 if x (dim coordinates) lies in the body or within the tolerance of it, else 0. */
int mica_body_contains(const MicaBody *body, const double *x);
/* The bounding box (entries past dim are 0). */
void mica_body_bounds(const MicaBody *body, double lower[3], double upper[3]);
/* "the box", "the quarter plate with a hole of radius 1", "the elements of plate.msh", ... for messages. */
void mica_body_describe(const MicaBody *body, char *buf, int size);

#endif
