/* The deck's geometry for `mica run` and `mica check` (and every command that builds a run's problem): the
 * shape (geometry.*), the particle layout (particles.*) and the background cells (quadrature.cells, .order,
 * .boundary_order), checked against each other; from them the discretization (revolved for an axisymmetric
 * section) and the MLS approximation, the cost guard's estimate, the error norms' own discretization and the
 * body that probes are tested against. */
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "mica/files.h"
#include "mica/timer.h"
#include "run.h"
#include "study_common.h"

static int read_floats_exact(const MicaDeck *deck, const char *path, double *v, int want) {
  int n;
  MICA_CALL(mica_deck_floats(deck, path, v, want, &n));
  char where[256];
  mica_deck_where(deck, path, where, sizeof where);
  MICA_CHECK(n == want, MICA_ERR_INPUT, "%s: %s needs %d values, not %d", where, path, want, n);
  return MICA_SUCCESS;
}

static int require(const MicaDeck *deck, const char *path, const char *shape) {
  if (mica_deck_has(deck, path)) return MICA_SUCCESS;
  char where[256];
  mica_deck_where(deck, "geometry.shape", where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT, "%s: geometry.shape = \"%s\" needs %s", where, shape, path);
}

/* Gmsh paths are relative to the deck's directory, so a deck runs from anywhere. */
static int mesh_path(const MicaDeck *deck, char *buf, size_t size) {
  const char *name;
  MICA_CALL(mica_deck_string(deck, "geometry.mesh", &name));
  char deck_path[PATH_MAX];
  snprintf(deck_path, sizeof deck_path, "%s", mica_deck_path(deck));
  const int n = name[0] == '/' ? snprintf(buf, size, "%s", name) : snprintf(buf, size, "%s/%s", dirname(deck_path), name);
  if (n >= 0 && (size_t)n < size) return MICA_SUCCESS;
  char where[256];
  mica_deck_where(deck, "geometry.mesh", where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT, "%s: the mesh's path, beside the deck, is %d bytes long; at most %zu are allowed: move the "
             "deck or the mesh to a shorter path", where, n, size - 1);
}

/* geometry.mesh_size_factor scales the sizes Gmsh meshes a .geo with; for anything else it would do nothing. */
static int read_size_factor(const MicaDeck *deck, MicaShapeSpec *shape) {
  if (!mica_deck_has(deck, "geometry.mesh_size_factor")) return MICA_SUCCESS;
  const char *p = shape->mesh_path;
  const size_t n = p ? strlen(p) : 0;
  char where[256];
  mica_deck_where(deck, "geometry.mesh_size_factor", where, sizeof where);
  MICA_CHECK(n > 4 && !strcasecmp(p + n - 4, ".geo"), MICA_ERR_INPUT,
             "%s: geometry.mesh_size_factor scales the mesh of a .geo that mica meshes; %s", where,
             p ? "geometry.mesh names a mesh file, which is meshed already (re-mesh it: gmsh -clscale)"
               : "this shape is not a Gmsh geometry");
  return mica_deck_float(deck, "geometry.mesh_size_factor", &shape->mesh_size_factor);
}

/* One reader per geometry.shape: its own settings, required ones first (a missing one names the shape). */
static int read_box(const MicaDeck *deck, const char *kind, MicaShapeSpec *shape) {
  int nl, nu;
  MICA_CALL(require(deck, "geometry.lower", kind));
  MICA_CALL(require(deck, "geometry.upper", kind));
  MICA_CALL(mica_deck_floats(deck, "geometry.lower", shape->lower, 3, &nl));
  MICA_CALL(mica_deck_floats(deck, "geometry.upper", shape->upper, 3, &nu));
  char where[256];
  mica_deck_where(deck, "geometry.upper", where, sizeof where);
  MICA_CHECK(nl == nu, MICA_ERR_INPUT, "%s: geometry.upper has %d values, geometry.lower %d", where, nu, nl);
  shape->dim = nl;
  return MICA_SUCCESS;
}

static int read_polygon(const MicaDeck *deck, const char *kind, MicaShapeSpec *shape) {
  double v[8];
  MICA_CALL(require(deck, "geometry.vertices", kind));
  MICA_CALL(read_floats_exact(deck, "geometry.vertices", v, 8));
  for (int i = 0; i < 4; i++) shape->vertices[i][0] = v[2 * i], shape->vertices[i][1] = v[2 * i + 1];
  return MICA_SUCCESS;
}

static int read_plate_hole(const MicaDeck *deck, const char *kind, MicaShapeSpec *shape) {
  MICA_CALL(require(deck, "geometry.hole_radius", kind));
  MICA_CALL(require(deck, "geometry.plate_size", kind));
  MICA_CALL(mica_deck_float(deck, "geometry.hole_radius", &shape->hole_radius));
  return read_floats_exact(deck, "geometry.plate_size", shape->plate_size, 2);
}

static int read_annulus(const MicaDeck *deck, const char *kind, MicaShapeSpec *shape) {
  double angles[2];
  MICA_CALL(require(deck, "geometry.r_inner", kind));
  MICA_CALL(require(deck, "geometry.r_outer", kind));
  MICA_CALL(mica_deck_float(deck, "geometry.r_inner", &shape->r_inner));
  MICA_CALL(mica_deck_float(deck, "geometry.r_outer", &shape->r_outer));
  MICA_CALL(read_floats_exact(deck, "geometry.angles", angles, 2));
  const double degree = 3.14159265358979323846 / 180;
  shape->theta0 = angles[0] * degree;
  shape->theta1 = angles[1] * degree;
  return MICA_SUCCESS;
}

static int read_cylinder(const MicaDeck *deck, const char *kind, MicaShapeSpec *shape) {
  MICA_CALL(require(deck, "geometry.radius", kind));
  MICA_CALL(require(deck, "geometry.height", kind));
  MICA_CALL(mica_deck_float(deck, "geometry.radius", &shape->radius));
  return mica_deck_float(deck, "geometry.height", &shape->height);
}

/* The shapes geometry.shape chooses among (its schema lists the same words), each with its reader and the
 * dimension it has unless the reader says otherwise (a box: its corners' length). gmsh, last, reads its mesh
 * path itself (read_shape), since the path lives in the caller's buffer. */
static const struct {
  const char *name;
  MicaShapeKind kind;
  int dim;
  int (*read)(const MicaDeck *deck, const char *kind, MicaShapeSpec *shape);
} shape_types[] = {
    {"box", MICA_SHAPE_BOX, 2, read_box},
    {"polygon", MICA_SHAPE_POLYGON, 2, read_polygon},
    {"plate_hole", MICA_SHAPE_PLATE_HOLE, 2, read_plate_hole},
    {"annulus", MICA_SHAPE_ANNULUS, 2, read_annulus},
    {"cylinder", MICA_SHAPE_CYLINDER, 3, read_cylinder},
};

int run_read_shape(const MicaDeck *deck, MicaShapeSpec *shape, char *mesh, size_t mesh_size) {
  const char *kind;
  memset(shape, 0, sizeof *shape);
  MICA_CALL(mica_deck_string(deck, "geometry.shape", &kind));
  shape->dim = 2;
  for (size_t i = 0; i < sizeof shape_types / sizeof *shape_types; i++) {
    if (strcmp(kind, shape_types[i].name)) continue;
    shape->kind = shape_types[i].kind;
    shape->dim = shape_types[i].dim;
    MICA_CALL(shape_types[i].read(deck, kind, shape));
    return read_size_factor(deck, shape);
  }
  MICA_CALL(require(deck, "geometry.mesh", kind)); /* gmsh */
  shape->kind = MICA_SHAPE_GMSH;
  MICA_CALL(mesh_path(deck, mesh, mesh_size));
  MICA_CALL(run_mesh_file_check(deck, mesh));
  shape->mesh_path = mesh;
  return read_size_factor(deck, shape);
}

int run_read_layout(const MicaDeck *deck, int dim, int gmsh, MicaLayoutSpec *layout, MicaCellSpec *cells) {
  const char *kind;
  memset(layout, 0, sizeof *layout);
  memset(cells, 0, sizeof *cells);
  MICA_CALL(mica_deck_string(deck, "particles.layout", &kind));
  layout->kind = !strcmp(kind, "graded")     ? MICA_LAYOUT_GRADED
                 : !strcmp(kind, "jittered") ? MICA_LAYOUT_JITTERED
                 : !strcmp(kind, "irregular") ? MICA_LAYOUT_IRREGULAR
                                              : MICA_LAYOUT_REGULAR;
  MICA_CALL(mica_deck_float(deck, "particles.jitter", &layout->jitter));
  MICA_CALL(mica_deck_int(deck, "particles.seed", &layout->seed));
  double grading[3];
  int ng;
  MICA_CALL(mica_deck_floats(deck, "particles.grading", grading, 3, &ng));
  for (int d = 0; d < 3; d++) layout->grading[d] = grading[ng == 1 ? 0 : (d < ng ? d : ng - 1)];
  char where[256];
  if (!gmsh) {
    int nc;
    MICA_CALL(require(deck, "particles.count", "any built-in shape"));
    MICA_CALL(mica_deck_ints(deck, "particles.count", layout->count, 3, &nc));
    mica_deck_where(deck, "particles.count", where, sizeof where);
    MICA_CHECK(nc == dim, MICA_ERR_INPUT, "%s: particles.count needs %d entries for this %d-D shape, not %d", where,
               dim, dim, nc);
  }
  long order, border;
  MICA_CALL(mica_deck_int(deck, "quadrature.order", &order));
  MICA_CALL(mica_deck_int(deck, "quadrature.boundary_order", &border));
  cells->order = (int)order, cells->boundary_order = (int)border;
  if (mica_deck_has(deck, "quadrature.cells")) {
    int nc;
    MICA_CALL(mica_deck_ints(deck, "quadrature.cells", cells->count, 3, &nc));
    mica_deck_where(deck, "quadrature.cells", where, sizeof where);
    MICA_CHECK(nc == dim, MICA_ERR_INPUT, "%s: quadrature.cells needs %d entries, not %d", where, dim, nc);
  }
  return MICA_SUCCESS;
}

/* geometry.axisymmetric: the 2-D section in (x, y) = (r, z) is revolved about the y axis. */
static int read_axisymmetric(const MicaDeck *deck, RunProblem *rp) {
  MICA_CALL(mica_deck_bool(deck, "geometry.axisymmetric", &rp->axisymmetric));
  if (!rp->axisymmetric) return MICA_SUCCESS;
  int ierr = mica_discretization_revolve(rp->disc);
  if (ierr) {
    char where[256];
    mica_deck_where(deck, "geometry.axisymmetric", where, sizeof where);
    mica_error_prefix("%s", where);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  return MICA_SUCCESS;
}

/* parallel.data = "distributed" under MPI, for what it covers (what it does not is refused later, with the deck
 * line: run_parallel_owned_check, on the whole discretization built as usual): each rank builds its own block
 * once the run is distributed (run_parallel_distribute), so here only the boundary sets' names, for the checks of
 * the conditions, and the grids' sizes (a Gmsh mesh: its groups and a sample of its nodes, for the cuts). */
static int names_only(const MicaDeck *deck, int fe, int *yes) {
  const char *data;
  *yes = 0;
  if (!mica_parallel_active() || fe) return MICA_SUCCESS;
  MICA_CALL(mica_deck_string(deck, "parallel.data", &data));
  *yes = !strcmp(data, "distributed");
  return MICA_SUCCESS;
}

/* A .geo under MPI is meshed once: rank 0 has Gmsh write it as a .msh file into the command's shared directory (rank
 * 0's staging directory, which the ranks' VTU pieces need too), and every rank reads its regions of that file as of
 * any mesh file (same particles, same answers); rank 0 removes it once the ranks hold their parts. Without a shared
 * directory (a program calling the library itself) every rank meshes the .geo. */
static int geo_meshed_once(const MicaShapeSpec *shape, RunProblem *rp, MicaShapeSpec *source) {
  const char *dir = mica_parallel_shared_dir();
  *source = *shape;
  if (!mica_mesh_is_geo(shape->mesh_path) || !mica_parallel_active() || !dir) return MICA_SUCCESS;
  char name[64];
  snprintf(name, sizeof name, ".mesh-of-geo-%d.msh", mica_parallel_world_rank());
  int ierr = mica_parallel_rank() == 0 ? mica_path_join(dir, name, &rp->mesh_file) : MICA_SUCCESS;
  if (!ierr && mica_parallel_rank() == 0) ierr = mica_mesh_geo_write(shape, rp->mesh_file);
  MICA_CALL(mica_parallel_broadcast_text(ierr, &rp->mesh_file, 0));
  source->mesh_path = rp->mesh_file, source->mesh_size_factor = 0;
  return MICA_SUCCESS;
}

void run_mesh_file_remove(RunProblem *rp) {
  if (rp->mesh_file && mica_parallel_rank() == 0) remove(rp->mesh_file);
  MICA_FREE(rp->mesh_file);
}

/* A Gmsh mesh: its reader's first pass (groups, dimension, sample), kept for the distribution (rp->mesh_source), and
 * the sets' names. */
static int mesh_names_only(const MicaDeck *deck, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                           const MicaCellSpec *cells, RunProblem *rp) {
  MicaShapeSpec source;
  MICA_CALL(geo_meshed_once(shape, rp, &source));
  MICA_CALL(mica_mesh_source_open(&source, &rp->mesh_source));
  MICA_CALL(mica_discretization_create_mesh(mica_mesh_source_names(rp->mesh_source), cells, 0, &rp->disc));
  /* the cost guard from the first pass's counts: every node a particle, order^dim points per element */
  long nodes, volume, boundary;
  const int dim = rp->disc->dim, border = cells->boundary_order > 0 ? cells->boundary_order : cells->order;
  mica_mesh_source_counts(rp->mesh_source, &nodes, &volume, &boundary);
  const RunMeshCounts counts = {dim, (double)nodes, (double)volume, (double)volume * pow(cells->order, dim),
                                (double)boundary * pow(border, dim - 1)};
  MICA_CALL(run_estimate(deck, shape, layout, cells, &counts, &rp->estimate));
  return run_estimate_guard(deck, NULL, dim, &rp->estimate);
}

/* The empty block: the grids' sizes and the boundary sets' names, no particle, cell or point (nothing of the body's
 * size; the checks that need the sets' points sum the ranks' shares later: run_check_rigid). */
static int build_names_only(const MicaDeck *deck, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                            const MicaCellSpec *cells, RunProblem *rp) {
  if (shape->kind == MICA_SHAPE_GMSH) return mesh_names_only(deck, shape, layout, cells, rp);
  MicaGridBlock block;
  MicaLayoutSpec grid = *layout; /* an irregular layout: the sets of the regular one of the same counts */
  if (grid.kind == MICA_LAYOUT_IRREGULAR) grid.kind = MICA_LAYOUT_REGULAR;
  memset(&block, 0, sizeof block);
  return mica_discretization_create_block(shape, &grid, cells, &block, &rp->disc);
}

/* Discretization (revolved for an axisymmetric section) and MLS approximation. */
int run_build_geometry(const MicaDeck *deck, RunProblem *rp) {
  MicaShapeSpec shape;
  MicaLayoutSpec layout;
  MicaCellSpec cells;
  MlsOptions mls_opt;
  char mesh[PATH_MAX];
  int fe = 0, fe_order = 0;
  MICA_CALL(run_read_shape(deck, &shape, mesh, sizeof mesh));
  MICA_CALL(run_read_layout(deck, shape.dim, shape.kind == MICA_SHAPE_GMSH, &layout, &cells));
  MICA_CALL(run_is_fe(deck, &fe));
  if (fe) MICA_CALL(run_check_fe_deck(deck, &shape, &layout, &cells, &fe_order));
  double start = mica_wtime();
  int only_names;
  MICA_CALL(names_only(deck, fe, &only_names));
  if (only_names) {
    MICA_CALL(build_names_only(deck, &shape, &layout, &cells, rp));
    MICA_CALL(run_read_integration(deck, &shape, &layout, &cells, 0, rp));
    MICA_CALL(read_axisymmetric(deck, rp)); /* the flag (and the section's dimension); the ranks revolve their points */
    rp->time_discretize = mica_wtime() - start;
    return MICA_SUCCESS;
  }
  MICA_CALL(mica_discretization_create(&shape, &layout, &cells, &rp->disc));
  if (shape.kind == MICA_SHAPE_GMSH) { /* the counts are the mesh's: estimated once it is read */
    RunMeshCounts counts;
    run_mesh_counts(rp->disc, &counts);
    MICA_CALL(run_estimate(deck, &shape, &layout, &cells, &counts, &rp->estimate));
    MICA_CALL(run_estimate_guard(deck, NULL, rp->disc->dim, &rp->estimate));
  }
  if (fe) MICA_CALL(run_build_fe(&layout, &cells, fe_order, rp));
  MICA_CALL(run_read_integration(deck, &shape, &layout, &cells, 1, rp));
  MICA_CALL(read_axisymmetric(deck, rp));
  rp->time_discretize = mica_wtime() - start - rp->time_mls;
  if (!fe) {
    MICA_CALL(mica_study_mls_options(deck, rp->disc->dim, &mls_opt));
    mls_opt.spacing_points = rp->disc->x_grid; /* a jittered or irregular layout's supports are sized on its grid */
    mls_opt.spacing_count = rp->disc->ngrid;
    mls_opt.spacing_index = rp->disc->grid_index;
    start = mica_wtime();
    MICA_CALL(mica_study_mls_input(mls_create(rp->disc->dim, rp->disc->nparticles, rp->disc->x, &mls_opt, &rp->mls)));
    rp->time_mls = mica_wtime() - start;
    rp->approx = (MicaApprox){&mica_approx_mls, rp->mls};
  }
  return MICA_SUCCESS;
}

int run_error_discretization(const RunProblem *rp, MicaDiscretization **disc) {
  long order;
  *disc = NULL;
  MICA_CALL(mica_deck_int(rp->deck, "quadrature.error_order", &order));
  if (order <= 0) return MICA_SUCCESS;
  MicaShapeSpec shape;
  MicaLayoutSpec layout;
  MicaCellSpec cells;
  char mesh[PATH_MAX];
  MICA_CALL(run_read_shape(rp->deck, &shape, mesh, sizeof mesh));
  MICA_CALL(run_read_layout(rp->deck, shape.dim, shape.kind == MICA_SHAPE_GMSH, &layout, &cells));
  if (rp->owned_data) /* the points in this rank's cells (the distribution holds their supports) */
    MICA_CALL(mica_owned_cell_points(&shape, &layout, &cells, rp->dist, (int)order, disc));
  else {
    cells.order = (int)order;
    MICA_CALL(mica_discretization_create(&shape, &layout, &cells, disc));
  }
  const int ierr = rp->axisymmetric ? mica_discretization_revolve(*disc) : MICA_SUCCESS;
  if (ierr) mica_discretization_destroy(disc);
  return ierr;
}

int run_body_create(const MicaDeck *deck, MicaBody **body) {
  MicaShapeSpec shape;
  char mesh[PATH_MAX];
  MICA_CALL(run_read_shape(deck, &shape, mesh, sizeof mesh));
  return mica_body_create(&shape, body);
}

/* The cost guard (estimate.c): a built-in shape's cost from its counts, before anything is allocated. */
int run_guard_cost(const MicaDeck *deck, RunEstimate *est) {
  MicaShapeSpec shape;
  MicaLayoutSpec layout;
  MicaCellSpec cells;
  char mesh[PATH_MAX];
  MICA_CALL(run_read_shape(deck, &shape, mesh, sizeof mesh));
  if (shape.kind == MICA_SHAPE_GMSH) return MICA_SUCCESS; /* run_build_geometry, once the mesh is read */
  MICA_CALL(run_read_layout(deck, shape.dim, 0, &layout, &cells));
  MICA_CALL(run_estimate(deck, &shape, &layout, &cells, NULL, est));
  return run_estimate_guard(deck, &layout, shape.dim, est);
}
