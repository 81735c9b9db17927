/* `mica run`: solve a solid-mechanics deck (the pipeline of docs/architecture.md: deck → discretization → MLS →
 * cache → assembly → Newton → output); `mica check`: build everything but the solve and print the cost. */
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "mica/timer.h"
#include "run.h"
#include "study_common.h"

/* ---- geometry ------------------------------------------------------------------------------------------ */

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

static int read_shape(const MicaDeck *deck, MicaShapeSpec *shape, char *mesh, size_t mesh_size) {
  const char *kind;
  memset(shape, 0, sizeof *shape);
  MICA_CALL(mica_deck_string(deck, "geometry.shape", &kind));
  shape->dim = 2;
  if (!strcmp(kind, "box")) {
    int nl, nu;
    MICA_CALL(require(deck, "geometry.lower", kind));
    MICA_CALL(require(deck, "geometry.upper", kind));
    MICA_CALL(mica_deck_floats(deck, "geometry.lower", shape->lower, 3, &nl));
    MICA_CALL(mica_deck_floats(deck, "geometry.upper", shape->upper, 3, &nu));
    char where[256];
    mica_deck_where(deck, "geometry.upper", where, sizeof where);
    MICA_CHECK(nl == nu, MICA_ERR_INPUT, "%s: geometry.upper has %d values, geometry.lower %d", where, nu, nl);
    shape->kind = MICA_SHAPE_BOX;
    shape->dim = nl;
  } else if (!strcmp(kind, "polygon")) {
    double v[8];
    MICA_CALL(require(deck, "geometry.vertices", kind));
    MICA_CALL(read_floats_exact(deck, "geometry.vertices", v, 8));
    shape->kind = MICA_SHAPE_POLYGON;
    for (int i = 0; i < 4; i++) shape->vertices[i][0] = v[2 * i], shape->vertices[i][1] = v[2 * i + 1];
  } else if (!strcmp(kind, "plate_hole")) {
    MICA_CALL(require(deck, "geometry.hole_radius", kind));
    MICA_CALL(require(deck, "geometry.plate_size", kind));
    shape->kind = MICA_SHAPE_PLATE_HOLE;
    MICA_CALL(mica_deck_float(deck, "geometry.hole_radius", &shape->hole_radius));
    MICA_CALL(read_floats_exact(deck, "geometry.plate_size", shape->plate_size, 2));
  } else if (!strcmp(kind, "annulus")) {
    double angles[2];
    MICA_CALL(require(deck, "geometry.r_inner", kind));
    MICA_CALL(require(deck, "geometry.r_outer", kind));
    shape->kind = MICA_SHAPE_ANNULUS;
    MICA_CALL(mica_deck_float(deck, "geometry.r_inner", &shape->r_inner));
    MICA_CALL(mica_deck_float(deck, "geometry.r_outer", &shape->r_outer));
    MICA_CALL(read_floats_exact(deck, "geometry.angles", angles, 2));
    const double degree = 3.14159265358979323846 / 180;
    shape->theta0 = angles[0] * degree;
    shape->theta1 = angles[1] * degree;
  } else if (!strcmp(kind, "cylinder")) {
    MICA_CALL(require(deck, "geometry.radius", kind));
    MICA_CALL(require(deck, "geometry.height", kind));
    shape->kind = MICA_SHAPE_CYLINDER;
    shape->dim = 3;
    MICA_CALL(mica_deck_float(deck, "geometry.radius", &shape->radius));
    MICA_CALL(mica_deck_float(deck, "geometry.height", &shape->height));
  } else {
    MICA_CALL(require(deck, "geometry.mesh", kind));
    shape->kind = MICA_SHAPE_GMSH;
    MICA_CALL(mesh_path(deck, mesh, mesh_size));
    MICA_CALL(run_mesh_file_check(deck, mesh));
    shape->mesh_path = mesh;
  }
  return read_size_factor(deck, shape);
}

static int read_layout(const MicaDeck *deck, int dim, int gmsh, MicaLayoutSpec *layout, MicaCellSpec *cells) {
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

/* ---- building the problem ------------------------------------------------------------------------------- */

/* Only first-order models of vector unknowns have an axisymmetric form here (Hessians in cylindrical
 * coordinates are not implemented). Checked before the conditions, whose names depend on it. */
static int check_axisymmetric_model(const MicaDeck *deck, const MicaFieldModel *m) {
  if (m->ops->order == 1 && m->ops->ncomp(3) % 3 == 0) return MICA_SUCCESS;
  char where[256];
  mica_deck_where(deck, "material.model", where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT, "%s: model '%s' has no axisymmetric form (it needs second derivatives in cylindrical "
             "coordinates): use a plane or 3-D run", where, m->ops->type.name);
}

/* Nitsche needs the model's traction s·n: first-order models (checked after the integration settings, whose
 * refusals of second-order models say more). */
static int check_nitsche_model(const MicaDeck *deck, const MicaSolidOptions *opt) {
  if (!mica_bc_method_has(opt->bc_method, MICA_BC_MODEL_TRACTION) || opt->field.ops->order == 1) return MICA_SUCCESS;
  char where[256];
  mica_deck_where(deck, "bc.method", where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT, "%s: bc.method = \"%s\" needs a classical model or a first-order field model; model "
             "'%s' uses second derivatives (its tractions include double tractions): use \"lagrange\" or "
             "\"penalty\"", where, opt->bc_method->type.name, opt->field.ops->type.name);
}

/* quadrature.vci: first-order models only, and boundary sets that cover the whole boundary once. */
static int read_vci(const MicaDeck *deck, const MicaDiscretization *disc, MicaSolidOptions *opt) {
  MICA_CALL(mica_deck_bool(deck, "quadrature.vci", &opt->vci));
  if (!opt->vci) return MICA_SUCCESS;
  char where[256];
  mica_deck_where(deck, "quadrature.vci", where, sizeof where);
  MICA_CHECK(opt->field.ops->order == 1, MICA_ERR_INPUT,
             "%s: quadrature.vci corrects first derivatives only, and model '%s' uses second derivatives", where,
             opt->field.ops->type.name);
  MICA_CHECK(!opt->axisymmetric, MICA_ERR_INPUT,
             "%s: quadrature.vci is not available for axisymmetric solids (the divergence identity would need the "
             "hoop terms and 2πr weights)", where);
  MICA_CHECK(disc->boundary_uncovered == 0, MICA_ERR_INPUT,
             "%s: quadrature.vci needs boundary sets (physical groups) that cover the whole boundary once; %ld "
             "boundary faces of the mesh are in no set or in several", where, disc->boundary_uncovered);
  return MICA_SUCCESS;
}

static int build_solid(const MicaDeck *deck, RunProblem *rp, const MicaSolid *donor) {
  MicaSolidOptions opt;
  memset(&opt, 0, sizeof opt);
  MicaDirichlet *dirichlet = NULL;
  MicaTraction *traction = NULL;
  int ndirichlet = 0, ntraction = 0, ierr = MICA_SUCCESS;
  opt.axisymmetric = rp->axisymmetric;
  MICA_CALL_CLEANUP(run_read_material(deck, run_model_dim(rp), &opt));
  MICA_CALL_CLEANUP(run_check_fe_model(deck, rp, &opt));
  if (rp->axisymmetric) MICA_CALL_CLEANUP(check_axisymmetric_model(deck, &opt.field));
  MICA_CALL_CLEANUP(run_read_bc_method(deck, &opt));
  if (rp->axisymmetric && mica_bc_method_has(opt.bc_method, MICA_BC_MODEL_TRACTION)) {
    char where[256];
    mica_deck_where(deck, "bc.method", where, sizeof where);
    MICA_ERROR(MICA_ERR_INPUT, "%s: bc.method = \"%s\" is not available for axisymmetric solids: use \"lagrange\" or "
               "\"penalty\"", where, opt.bc_method->type.name);
  }
  MICA_CALL_CLEANUP(run_read_body_force(deck, rp, &opt.field, opt.body));
  MICA_CALL_CLEANUP(run_read_dirichlet(deck, rp, &opt.field, &ndirichlet, &dirichlet));
  MICA_CALL_CLEANUP(run_read_tractions(deck, rp, &opt.field, &ntraction, &traction));
  MICA_CALL_CLEANUP(run_check_fe_multipliers(deck, rp, &opt, ndirichlet, dirichlet));
  long order;
  MICA_CALL_CLEANUP(mica_deck_int(deck, "mls.order", &order));
  opt.basis_order = (int)order;
  MICA_CALL_CLEANUP(read_vci(deck, rp->disc, &opt));
  MICA_CALL_CLEANUP(run_read_scni(deck, rp, &opt));
  MICA_CALL_CLEANUP(check_nitsche_model(deck, &opt));
  const MicaDiscretization *disc = rp->disc;
  if (mica_parallel_active()) { /* MPI: this rank's share of the quadrature points (run_parallel.c) */
    MICA_CALL_CLEANUP(run_check_serial_only(deck, rp));
    MICA_CALL_CLEANUP(run_parallel_distribute(deck, rp));
    opt.parallel = rp->dist;
    disc = rp->dist->local;
  }
  const double start = mica_wtime(), cpu = mica_cputime();
  ierr = mica_study_mls_input(mica_solid_create_sharing(disc, &rp->approx, &opt, ndirichlet, dirichlet, ntraction,
                                                        traction, donor, &rp->solid));
  rp->time_cache_pattern = mica_wtime() - start;
  rp->cpu_cache_pattern = mica_cputime() - cpu;
  return ierr; /* the solid owns the conditions now, whether or not it was built */
cleanup:
  for (int a = 0; a < MICA_MAX_COMP; a++) mica_function_destroy(&opt.body[a]);
  for (int c = 0; c < ndirichlet; c++)
    for (int a = 0; a < MICA_MAX_COMP; a++) mica_function_destroy(&dirichlet[c].value[a]);
  for (int c = 0; c < ntraction; c++)
    for (int a = 0; a < MICA_MAX_COMP; a++) mica_function_destroy(&traction[c].value[a]);
  free(dirichlet);
  free(traction);
  return ierr;
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

/* Discretization (revolved for an axisymmetric section) and MLS approximation. */
static int build_geometry(const MicaDeck *deck, RunProblem *rp) {
  MicaShapeSpec shape;
  MicaLayoutSpec layout;
  MicaCellSpec cells;
  MlsOptions mls_opt;
  char mesh[PATH_MAX];
  int fe = 0, fe_order = 0;
  MICA_CALL(read_shape(deck, &shape, mesh, sizeof mesh));
  MICA_CALL(read_layout(deck, shape.dim, shape.kind == MICA_SHAPE_GMSH, &layout, &cells));
  MICA_CALL(run_is_fe(deck, &fe));
  if (fe) MICA_CALL(run_check_fe_deck(deck, &shape, &layout, &cells, &fe_order));
  double start = mica_wtime();
  MICA_CALL(mica_discretization_create(&shape, &layout, &cells, &rp->disc));
  if (shape.kind == MICA_SHAPE_GMSH) { /* the counts are the mesh's: estimated once it is read */
    MICA_CALL(run_estimate(deck, &shape, &layout, &cells, rp->disc, &rp->estimate));
    MICA_CALL(run_estimate_guard(deck, NULL, rp->disc->dim, &rp->estimate));
  }
  if (fe) MICA_CALL(run_build_fe(&layout, &cells, fe_order, rp));
  MICA_CALL(run_read_integration(deck, &shape, &layout, &cells, rp));
  MICA_CALL(read_axisymmetric(deck, rp));
  rp->time_discretize = mica_wtime() - start - rp->time_mls;
  if (!fe) {
    MICA_CALL(mica_study_mls_options(deck, rp->disc->dim, &mls_opt));
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
  MICA_CALL(read_shape(rp->deck, &shape, mesh, sizeof mesh));
  MICA_CALL(read_layout(rp->deck, shape.dim, shape.kind == MICA_SHAPE_GMSH, &layout, &cells));
  cells.order = (int)order;
  MICA_CALL(mica_discretization_create(&shape, &layout, &cells, disc));
  const int ierr = rp->axisymmetric ? mica_discretization_revolve(*disc) : MICA_SUCCESS;
  if (ierr) mica_discretization_destroy(disc);
  return ierr;
}

int run_body_create(const MicaDeck *deck, MicaBody **body) {
  MicaShapeSpec shape;
  char mesh[PATH_MAX];
  MICA_CALL(read_shape(deck, &shape, mesh, sizeof mesh));
  return mica_body_create(&shape, body);
}

/* ---- reuse between runs ---------------------------------------------------------------------------------- */

/* What the discretization and the MLS approximation depend on: the deck file (Gmsh paths are relative to
 * it) and every setting of these groups. A run whose fingerprint equals the last one's reuses them. */
static const char *const geometry_scopes[] = {"geometry", "particles", "quadrature", "mls", "problem.method"};

struct RunReuse {
  char *key;                    /* fingerprint of the last discretization and MLS (NULL: none kept) */
  MicaDiscretization *disc;
  MlsApprox *mls;               /* or */
  MicaFe *fe;
  MicaApprox approx;
  MicaSolid *solid;             /* the last solid built on them: it lends its shape caches to the next */
  MicaShapeCache *at_particles; /* the output's shape functions at the particles */
  MicaShapeCache *at_mesh;      /* and at the output mesh's points */
};

static int reuse_key(const MicaDeck *deck, char **key) {
  char *settings = NULL;
  MICA_CALL(mica_deck_fingerprint(deck, (int)(sizeof geometry_scopes / sizeof *geometry_scopes), geometry_scopes,
                                  &settings));
  const size_t size = strlen(settings) + strlen(mica_deck_path(deck)) + 2;
  int ierr = MICA_MALLOC(*key, size);
  if (!ierr) snprintf(*key, size, "%s|%s", mica_deck_path(deck), settings);
  free(settings);
  return ierr;
}

/* Forgets everything kept: the solid first (it refers to the discretization and MLS). */
static void reuse_clear(RunReuse *reuse) {
  mica_solid_destroy(&reuse->solid);
  mica_shape_cache_destroy(&reuse->at_particles);
  mica_shape_cache_destroy(&reuse->at_mesh);
  mls_destroy(&reuse->mls);
  mica_fe_destroy(&reuse->fe);
  mica_discretization_destroy(&reuse->disc);
  free(reuse->key);
  reuse->key = NULL;
}

int run_reuse_create(RunReuse **reuse) { return MICA_CALLOC(*reuse, 1); }

int run_reuse_destroy(RunReuse **reuse) {
  if (!*reuse) return MICA_SUCCESS;
  reuse_clear(*reuse);
  MICA_FREE(*reuse);
  return MICA_SUCCESS;
}

/* The kept discretization and MLS if the deck's fingerprint matches (key is then freed), else new ones,
 * kept for the next run once they are built (key is then owned by reuse). */
static int take_or_build_geometry(const MicaDeck *deck, RunProblem *rp, RunReuse *reuse, char *key) {
  if (reuse->key && !strcmp(key, reuse->key)) {
    free(key);
    rp->disc = reuse->disc, rp->mls = reuse->mls, rp->fe = reuse->fe, rp->approx = reuse->approx;
    rp->at_particles = reuse->at_particles, reuse->at_particles = NULL;
    rp->at_mesh = reuse->at_mesh, reuse->at_mesh = NULL;
    rp->reused_geometry = 1;
    return MICA_SUCCESS;
  }
  reuse_clear(reuse);
  rp->owns_geometry = 1;
  int ierr = build_geometry(deck, rp);
  if (ierr) {
    free(key);
    return ierr;
  }
  reuse->key = key, reuse->disc = rp->disc, reuse->mls = rp->mls, reuse->fe = rp->fe, reuse->approx = rp->approx;
  rp->owns_geometry = 0;
  return MICA_SUCCESS;
}

/* The cost guard (estimate.c): a built-in shape's cost from its counts, before anything is allocated. */
static int guard_cost(const MicaDeck *deck, RunEstimate *est) {
  MicaShapeSpec shape;
  MicaLayoutSpec layout;
  MicaCellSpec cells;
  char mesh[PATH_MAX];
  MICA_CALL(read_shape(deck, &shape, mesh, sizeof mesh));
  if (shape.kind == MICA_SHAPE_GMSH) return MICA_SUCCESS; /* build_geometry, once the mesh is read */
  MICA_CALL(read_layout(deck, shape.dim, 0, &layout, &cells));
  MICA_CALL(run_estimate(deck, &shape, &layout, &cells, NULL, est));
  return run_estimate_guard(deck, &layout, shape.dim, est);
}

int run_problem_build_reusing(const MicaDeck *deck, RunProblem *rp, RunReuse *reuse) {
  memset(rp, 0, sizeof *rp);
  rp->deck = deck;
  rp->reuse = reuse;
  MICA_CALL(guard_cost(deck, &rp->estimate));
  if (reuse) {
    char *key = NULL;
    MICA_CALL(reuse_key(deck, &key));
    MICA_CALL(take_or_build_geometry(deck, rp, reuse, key));
  } else {
    rp->owns_geometry = 1;
    MICA_CALL(build_geometry(deck, rp));
  }
  MICA_CALL(build_solid(deck, rp, reuse ? reuse->solid : NULL));
  MICA_CALL(run_read_exact(deck, rp, &rp->solid->opt.field));
  return MICA_SUCCESS;
}

int run_problem_build(const MicaDeck *deck, RunProblem *rp) { return run_problem_build_reusing(deck, rp, NULL); }

/* With reuse, the solid and the output cache pass to it (a run that built no solid leaves the kept one). Under
 * MPI the solid lives on this run's distribution, which goes now: the next run builds its own caches. */
void run_problem_free(RunProblem *rp) {
  RunReuse *reuse = rp->reuse;
  if (reuse && rp->solid && !rp->dist) {
    mica_solid_destroy(&reuse->solid);
    reuse->solid = rp->solid, rp->solid = NULL;
  }
  if (reuse && !reuse->at_particles && !rp->owns_geometry)
    reuse->at_particles = rp->at_particles, rp->at_particles = NULL;
  if (reuse && !reuse->at_mesh && !rp->owns_geometry) reuse->at_mesh = rp->at_mesh, rp->at_mesh = NULL;
  mica_solid_destroy(&rp->solid);
  mica_distribution_destroy(&rp->dist);
  free(rp->near_null);
  rp->near_null = NULL;
  mica_shape_cache_destroy(&rp->at_particles);
  mica_shape_cache_destroy(&rp->at_mesh);
  if (rp->owns_geometry) {
    mls_destroy(&rp->mls);
    mica_fe_destroy(&rp->fe);
    mica_discretization_destroy(&rp->disc);
  }
  mica_shape_cache_destroy(&rp->at_gauss);
  mica_discretization_destroy(&rp->error_disc);
  for (int a = 0; a < MICA_MAX_COMP; a++) {
    mica_function_destroy(&rp->exact[a]);
    for (int J = 0; J < 3; J++) mica_function_destroy(&rp->exact_grad[a][J]);
  }
}

/* ---- summary of the discretization ---------------------------------------------------------------------- */

static long boundary_points(const MicaDiscretization *disc) {
  long n = 0;
  for (int i = 0; i < disc->nsets; i++) n += disc->sets[i].n;
  return n;
}

static size_t cache_bytes(const MicaSolid *s) {
  size_t bytes = mica_shape_cache_bytes(s->volume);
  for (int set = 0; set < s->disc->nsets; set++) bytes += mica_shape_cache_bytes(s->boundary[set]);
  return bytes;
}

/* The sizes of the problem; under MPI, totals over the ranks (run_parallel.c). */
static int count_totals(const RunProblem *rp, RunTotals *c) {
  const MicaSolid *s = rp->solid;
  c->nnz = s->K->nnz;
  c->support_entries = s->volume->ptr[s->volume->npoints];
  c->support_points = s->volume->npoints;
  c->max_support = s->volume->max_support;
  c->cache_bytes = (long)cache_bytes(s);
  if (rp->dist) MICA_CALL(run_parallel_totals(rp, c));
  return MICA_SUCCESS;
}

static int add_counts(RunProblem *rp, const RunTotals *c, MicaJson *summary) {
  const MicaSolid *s = rp->solid;
  if (!rp->error_disc) MICA_CALL(run_error_discretization(rp, &rp->error_disc)); /* NULL without error_order */
  MICA_CALL(mica_json_string(summary, "method", rp->approx.ops->type.name));
  if (rp->fe) MICA_CALL(mica_json_string(summary, "element", mica_fe_element_name(rp->fe->dim, rp->fe->order)));
  MICA_CALL(mica_json_int(summary, "dim", rp->disc->dim));
  MICA_CALL(mica_json_int(summary, "particles", rp->disc->nparticles));
  MICA_CALL(mica_json_int(summary, "cells", rp->disc->ncells));
  MICA_CALL(mica_json_string(summary, "integration", rp->integration));
  MICA_CALL(mica_json_int(summary, "quadrature_points", rp->disc->nquad));
  /* the error norms' points: quadrature.error_order's own, else the solve's (the Gauss points of the nodal cells
   * for the nodal modes) */
  const long error_points = rp->error_disc ? rp->error_disc->nquad : rp->disc->nodal ? rp->disc->ngauss : rp->disc->nquad;
  MICA_CALL(mica_json_int(summary, "error_points", error_points));
  MICA_CALL(mica_json_int(summary, "boundary_points", boundary_points(rp->disc)));
  MICA_CALL(mica_json_int(summary, "dofs", s->ndof));
  MICA_CALL(mica_json_int(summary, "multiplier_nodes", s->nmultiplier_nodes));
  MICA_CALL(mica_json_int(summary, "nnz", c->nnz));
  MICA_CALL(mica_json_int(summary, "support_max", c->max_support));
  MICA_CALL(mica_json_number(summary, "support_mean", (double)c->support_entries / (double)c->support_points));
  MICA_CALL(mica_json_int(summary, "cache_bytes", c->cache_bytes));
  MICA_CALL(mica_json_int(summary, "matrix_bytes", (long)(c->nnz * 16 + (s->ndof + 1) * 8)));
  MICA_CALL(mica_json_number(summary, "volume", rp->disc->volume));
  MICA_CALL(mica_json_string(summary, "model", mica_type_has(&s->opt.field.ops->type, MICA_FIELD_CLASSICAL)
                                                   ? s->opt.field.classical->type.name
                                                   : s->opt.field.ops->type.name));
  MICA_CALL(mica_json_int(summary, "unknowns_per_particle", s->ncomp));
  MICA_CALL(mica_json_string(summary, "bc_method", s->opt.bc_method->type.name));
  MICA_CALL(mica_json_number(summary, "bc_alpha", s->opt.bc_alpha));
  MICA_CALL(mica_json_number(summary, "time_discretize", rp->time_discretize));
  MICA_CALL(mica_json_number(summary, "time_mls_setup", rp->time_mls));
  MICA_CALL(mica_json_number(summary, "time_cache_and_pattern", rp->time_cache_pattern));
  MICA_CALL(mica_json_bool(summary, "vci", s->opt.vci));
  MICA_CALL(mica_json_number(summary, "time_vci", s->time_vci)); /* part of time_cache_and_pattern */
  /* the split of time_cache_and_pattern: shape functions (without their neighbor search), search, pattern */
  MICA_CALL(mica_json_number(summary, "time_search", s->time_search));
  MICA_CALL(mica_json_number(summary, "time_shape_functions", s->time_shape - s->time_search));
  MICA_CALL(mica_json_number(summary, "time_pattern", s->time_pattern));
  MICA_CALL(mica_json_bool(summary, "reused_discretization", rp->reused_geometry));
  MICA_CALL(mica_json_int(summary, "shape_caches_built", s->caches_built));
  MICA_CALL(mica_json_int(summary, "shape_caches_shared", s->caches_shared));
  return MICA_SUCCESS;
}

static void print_counts(const RunProblem *rp, const RunTotals *c) {
  const MicaSolid *s = rp->solid;
  printf("%ld particles, %ld %s cells, %ld quadrature points (+%ld on the boundary), %ld dofs, nnz %ld, support "
         "%.1f mean / %ld max, cache %.1f MB, matrix %.1f MB\n",
         rp->disc->nparticles, rp->disc->ncells, rp->disc->nodal ? "nodal" : "background", rp->disc->nquad,
         boundary_points(rp->disc), s->ndof, c->nnz, (double)c->support_entries / (double)c->support_points,
         c->max_support, (double)c->cache_bytes / 1e6, (double)(c->nnz * 16) / 1e6);
  if (s->opt.vci) printf("VCI: corrected test gradients in %.3g s\n", s->time_vci);
  if (rp->fe)
    printf("finite elements: %ld %s elements on the particles\n", rp->fe->nelements,
           mica_fe_element_name(rp->fe->dim, rp->fe->order));
  if (s->opt.scni) printf("SCNI: smoothed gradients on the nodal cells\n");
  fflush(stdout);
}

/* ---- the commands --------------------------------------------------------------------------------------- */

static int read_newton(const MicaDeck *deck, RunProblem *rp, MicaNewtonOptions *opt) {
  const MicaSolid *s = rp->solid;
  long steps, iterations, cuts;
  const char *linear;
  memset(opt, 0, sizeof *opt);
  MICA_CALL(mica_deck_int(deck, "solver.steps", &steps));
  MICA_CALL(mica_deck_int(deck, "solver.max_iterations", &iterations));
  MICA_CALL(mica_deck_int(deck, "solver.max_cuts", &cuts));
  MICA_CALL(mica_deck_float(deck, "solver.rtol", &opt->rtol));
  MICA_CALL(mica_deck_float(deck, "solver.atol", &opt->atol));
  MICA_CALL(mica_deck_bool(deck, "solver.line_search", &opt->line_search));
  MICA_CALL(mica_deck_bool(deck, "output.monitor", &opt->verbose));
  MICA_CALL(mica_deck_string(deck, "solver.linear", &linear));
  opt->steps = (int)steps, opt->max_iterations = (int)iterations, opt->max_cuts = (int)cuts;
  opt->linear = strcmp(linear, "auto") ? mica_linear_solver_find(linear) : NULL;
  char where[256];
  mica_deck_where(deck, "solver.linear", where, sizeof where);
  const int spd_only = opt->linear && mica_linear_solver_has(opt->linear, MICA_LINEAR_SPD_ONLY);
  MICA_CHECK(!(spd_only && !mica_solid_symmetric_definite(s)), MICA_ERR_INPUT,
             "%s: %s needs a symmetric positive definite tangent, which bc.method = \"%s\"%s does not give; "
             "use \"umfpack\" or \"auto\"", where,
             spd_only && mica_linear_solver_iterative(opt->linear) ? "cg" : "CHOLMOD",
             s->opt.bc_method->type.name, s->opt.vci ? " with quadrature.vci (unsymmetric: Petrov–Galerkin)" : "");
  return run_read_krylov(deck, rp, opt);
}

static int add_newton_stats(const MicaNewtonStats *st, MicaJson *summary) {
  MICA_CALL(mica_json_int(summary, "load_steps", st->steps_done));
  MICA_CALL(mica_json_number(summary, "load_factor_reached", st->load_factor));
  MICA_CALL(mica_json_int(summary, "step_cuts", st->cuts));
  MICA_CALL(mica_json_int(summary, "newton_iterations", st->iterations_total));
  MICA_CALL(mica_json_int(summary, "newton_iterations_last_step", st->last_iterations));
  MICA_CALL(mica_json_open_array(summary, "residual_history_last_step"));
  for (int i = 0; i < st->nhistory; i++) MICA_CALL(mica_json_number(summary, NULL, st->residual_history[i]));
  MICA_CALL(mica_json_close(summary));
  MICA_CALL(mica_json_open_array(summary, "increment_history_last_step"));
  for (int i = 0; i < st->nincrements; i++) MICA_CALL(mica_json_number(summary, NULL, st->increment_history[i]));
  MICA_CALL(mica_json_close(summary));
  MICA_CALL(mica_json_string(summary, "linear_solver", st->linear_name ? st->linear_name : "none"));
  MICA_CALL(mica_json_int(summary, "nnz_factor", st->linear.nnz_factor));
  MICA_CALL(mica_json_number(summary, "factor_flops", st->linear.flops));
  MICA_CALL(mica_json_int(summary, "symbolic_analyses", st->linear.analyses));
  MICA_CALL(mica_json_int(summary, "factorizations", st->linear.factorizations));
  MICA_CALL(mica_json_number(summary, "time_assemble", st->time_assemble));
  MICA_CALL(mica_json_int(summary, "assemblies", st->assemblies)); /* passes; of which with the tangent: */
  MICA_CALL(mica_json_int(summary, "tangent_assemblies", st->tangent_assemblies));
  MICA_CALL(mica_json_int(summary, "residual_updates", st->residual_updates)); /* linear: R + K du */
  MICA_CALL(mica_json_number(summary, "time_analyze", st->linear.time_analyze));
  MICA_CALL(mica_json_number(summary, "time_factor", st->time_factor));
  MICA_CALL(mica_json_number(summary, "time_solve", st->time_solve));
  return MICA_SUCCESS;
}

/* Memory per dof (docs/performance.md §memory): the shape-function caches (N, ∇N, ∇∇N, particle index, point
 * offsets), the tangent (values, row indices, column offsets) and its factor's values (8 bytes × nnz_factor;
 * CHOLMOD's supernodal indices and UMFPACK's pattern come on top). */
static int add_memory_per_dof(const RunProblem *rp, const RunTotals *c, const MicaNewtonStats *st, MicaJson *summary) {
  const double dofs = (double)rp->solid->ndof;
  MICA_CALL(mica_json_number(summary, "memory_cache_bytes_per_dof", (double)c->cache_bytes / dofs));
  const double matrix_bytes = (double)(c->nnz * 16 + (rp->solid->ndof + 1) * 8);
  MICA_CALL(mica_json_number(summary, "memory_matrix_bytes_per_dof", matrix_bytes / dofs));
  MICA_CALL(mica_json_number(summary, "memory_factor_bytes_per_dof", 8.0 * (double)st->linear.nnz_factor / dofs));
  return MICA_SUCCESS;
}

/* output.vtu and output.mesh. A deck that asks for mesh files (output.mesh = true) with output.vtu = false would
 * get none and is refused; output.mesh = false agrees with it (sweep and study points turn output.vtu off by
 * themselves, and a deck that turns the mesh off must still run there). */
static int read_vtu(const MicaDeck *deck, const RunProblem *rp, RunOutput *out) {
  MICA_CALL(mica_deck_bool(deck, "output.vtu", &out->vtu));
  MICA_CALL(mica_deck_bool(deck, "output.mesh", &out->mesh));
  char where[256];
  mica_deck_where(deck, "output.mesh", where, sizeof where);
  const int given = !strstr(where, " (default)"); /* in the deck or a --set, not the schema's default */
  MICA_CHECK(out->vtu || !out->mesh || !given, MICA_ERR_INPUT,
             "%s: output.mesh = true writes the fields on the cells with the VTU files, but output.vtu = false writes "
             "none; remove output.mesh or set output.vtu = true", where);
  MICA_CHECK(!out->mesh || rp->disc->mesh, MICA_ERR_ARGUMENT, "output.mesh: the discretization has no cells");
  out->mesh = out->mesh && out->vtu;
  return MICA_SUCCESS;
}

/* A body its conditions do not hold has a singular tangent: said before anything is assembled, with the motions
 * and the components to hold; on the whole discretization (an MPI rank's share holds part of each set). Not part
 * of building the problem: `mica stability` builds free bodies on purpose, to count their rigid modes. */
static int check_rigid_modes(const MicaDeck *deck, const RunProblem *rp) {
  const MicaSolid *s = rp->solid;
  const char *names[MICA_MAX_COMP + 1];
  const int ncomp = run_model_names(rp, &s->opt.field, 0, names);
  char where[256];
  mica_deck_where(deck, s->ndirichlet ? "bcs.dirichlet" : "bcs", where, sizeof where);
  return mica_dirichlet_check_rigid(rp->disc, rp->axisymmetric, ncomp, names, s->ndirichlet, s->dirichlet, where);
}

/* What every solve reports, converged or not: Newton's and the linear solvers' statistics and the memory
 * (collective under MPI). */
static int add_solve_stats(const RunProblem *rp, const RunTotals *totals, const MicaNewtonStats *stats,
                           double time_newton, MicaJson *summary) {
  MICA_CALL(mica_json_number(summary, "time_newton", time_newton));
  MICA_CALL(add_newton_stats(stats, summary));
  MICA_CALL(add_memory_per_dof(rp, totals, stats, summary));
  MICA_CALL(run_krylov_summary(rp, stats, summary));
  MICA_CALL(run_parallel_ranks(rp, stats, summary));
  MICA_CALL(run_parallel_solver_stats(rp, summary));
  MICA_CALL(run_parallel_memory(rp, summary));
  return MICA_SUCCESS;
}

/* Newton's message, and what in the deck may get a nonlinear solve further (a linear one fails alike at any
 * load step). */
static void failure_reason(const RunProblem *rp, const MicaNewtonOptions *nopt, char *reason, size_t size) {
  if (mica_solid_linear(rp->solid))
    snprintf(reason, size, "%s", mica_error_message());
  else
    snprintf(reason, size, "%s; more solver.steps, a larger solver.max_cuts%s may get further", mica_error_message(),
             nopt->line_search ? " or a smaller load" : " or solver.line_search = true");
}

/* A solve whose step failed after its cut-backs (stats->failed) still writes what it reached: the fields of
 * the converged steps and their PVD, the statistics, and status "failed" with the load factors and the
 * reason; no probes, error norms or quadrature fields, which belong to the full load. The command line
 * publishes these results (main.c); the failure is returned again. */
static int write_reached(const RunProblem *rp, RunOutput *out, const RunTotals *totals, const MicaNewtonOptions *nopt,
                         const MicaNewtonStats *stats, double time_newton, MicaJson *summary) {
  char reason[1536];
  failure_reason(rp, nopt, reason, sizeof reason);
  mica_error_clear(); /* every rank failed alike: the collectives below run as after a success */
  const double output_start = mica_wtime();
  MICA_CALL(add_solve_stats(rp, totals, stats, time_newton, summary));
  MICA_CALL(run_output_finish(out));
  MICA_CALL(mica_json_number(summary, "time_output", out->time_output + mica_wtime() - output_start));
  MICA_CALL(run_peak_memory(summary));
  MICA_CALL(mica_json_string(summary, "status", "failed"));
  MICA_CALL(mica_json_number(summary, "load_factor_failed", stats->load_factor_failed));
  MICA_CALL(mica_json_string(summary, "reason", reason));
  printf("failed at load factor %.6g after %d converged load step%s (load factor %.6g), %d cut-back%s\n",
         stats->load_factor_failed, stats->steps_done, stats->steps_done == 1 ? "" : "s", stats->load_factor,
         stats->cuts, stats->cuts == 1 ? "" : "s");
  MICA_ERROR(MICA_ERR_NUMERIC, "%s", reason);
}

int run_solve_reusing(const MicaDeck *deck, const char *outdir, MicaJson *summary, RunReuse *reuse) {
  RunProblem rp;
  MicaNewtonOptions nopt;
  MicaNewtonStats stats;
  RunOutput out;
  double *u = NULL;
  int ierr = MICA_SUCCESS;
  memset(&stats, 0, sizeof stats);
  memset(&out, 0, sizeof out);
  MICA_CALL_CLEANUP(run_problem_build_reusing(deck, &rp, reuse));
  MICA_CALL_CLEANUP(check_rigid_modes(deck, &rp));
  MICA_CALL_CLEANUP(run_quadrature_fields_check(deck, &rp));
  MICA_CALL_CLEANUP(run_check_probes(&rp));
  RunTotals totals;
  MICA_CALL_CLEANUP(count_totals(&rp, &totals));
  print_counts(&rp, &totals);
  MICA_CALL_CLEANUP(add_counts(&rp, &totals, summary));
  MICA_CALL_CLEANUP(run_parallel_counts(&rp, summary));
  MICA_CALL_CLEANUP(run_estimate_report(&rp.estimate, summary));
  MICA_CALL_CLEANUP(read_newton(deck, &rp, &nopt));
  out.rp = &rp, out.outdir = outdir;
  MICA_CALL_CLEANUP(read_vtu(deck, &rp, &out));
  MICA_CALL_CLEANUP(MICA_CALLOC(u, rp.solid->ndof));
  const double start = mica_wtime();
  ierr = mica_newton_solve(rp.solid, &nopt, u, run_output_step, &out, &stats);
  if (ierr && stats.failed) ierr = write_reached(&rp, &out, &totals, &nopt, &stats, mica_wtime() - start, summary);
  MICA_CALL_CLEANUP(ierr);
  MICA_CALL_CLEANUP(add_solve_stats(&rp, &totals, &stats, mica_wtime() - start, summary));
  const double output_start = mica_wtime();
  MICA_CALL_CLEANUP(run_output_finish(&out));
  MICA_CALL_CLEANUP(run_error_norms(&rp, u, summary));
  MICA_CALL_CLEANUP(run_probes(&rp, u, summary));
  MICA_CALL_CLEANUP(run_quadrature_fields(&rp, outdir, u, summary));
  /* fields per step (inside time_newton), the PVD, error norms and probes */
  MICA_CALL_CLEANUP(mica_json_number(summary, "time_output", out.time_output + mica_wtime() - output_start));
  MICA_CALL_CLEANUP(run_peak_memory(summary));
  printf("solved in %d load step%s, %d Newton iterations (%s)\n", stats.steps_done, stats.steps_done > 1 ? "s" : "",
         stats.iterations_total, stats.linear_name);
cleanup:
  free(u);
  run_output_free(&out);
  run_problem_free(&rp);
  return ierr;
}

static int run_solve(const MicaDeck *deck, const char *outdir, MicaJson *summary) {
  return run_solve_reusing(deck, outdir, summary, NULL);
}

static int run_check(const MicaDeck *deck, const char *outdir, MicaJson *summary) {
  (void)outdir;
  RunProblem rp;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(run_problem_build(deck, &rp));
  MICA_CALL_CLEANUP(check_rigid_modes(deck, &rp));
  MICA_CALL_CLEANUP(run_check_probes(&rp));
  RunTotals totals;
  MICA_CALL_CLEANUP(count_totals(&rp, &totals));
  print_counts(&rp, &totals);
  MICA_CALL_CLEANUP(add_counts(&rp, &totals, summary));
  MICA_CALL_CLEANUP(run_parallel_counts(&rp, summary));
  MICA_CALL_CLEANUP(run_estimate_report(&rp.estimate, summary));
  const double nnz = (double)totals.nnz;
  const char *size_class = nnz < 1e6 ? "small (seconds)" : nnz < 3e7 ? "medium (minutes)" : "large (hours, or use MPI)";
  MICA_CALL_CLEANUP(mica_json_string(summary, "cost_class", size_class));
  printf("deck is valid; cost class: %s\n", size_class);
cleanup:
  run_problem_free(&rp);
  return ierr;
}

const MicaCommand mica_command_run = {
    {"run",
     "solve a solid: EFG with MLS, background-cell quadrature, weak boundary conditions, Newton", 0, NULL, NULL},
    "Builds the body, particles and background cells, the MLS approximation, the model and the boundary\n"
    "conditions of the deck, and solves with Newton's method over load steps (CHOLMOD or UMFPACK). Writes\n"
    "fields per load step (VTU + PVD, at the particles and on the cells) and summary.json: counts, per-phase\n"
    "times, Newton iterations, error norms when an exact solution is given, and every probe. A solve that\n"
    "stops (a load step failing after solver.max_cuts halvings) writes what it reached, the converged steps\n"
    "and summary.json with \"status\": \"failed\", the load factor reached and the reason, and exits 3.",
    mica_run_schema,
    run_solve,
};

const MicaCommand mica_command_check = {
    {"check",
     "validate a run deck and print its cost (particles, quadrature points, dofs, nnz, memory) without solving",
     0, NULL, NULL},
    "Reads and checks the deck like `mica run`, builds the discretization, shape-function cache and sparsity\n"
    "pattern, and reports their sizes and a cost class. Nothing is solved.",
    mica_run_schema,
    run_check,
};
