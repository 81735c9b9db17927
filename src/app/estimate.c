/* The cost guard of `mica run`, `check`, `sweep`, `study` and `stability` (docs/performance.md §the cost
 * estimate): peak memory and time of a run from its deck's counts, before anything is allocated, and the
 * refusal of a deck beyond limits.memory_gb (default: this machine's physical memory); the checks of a mesh
 * file before it is read (limits.mesh_mb). Everything is in double: counts like 10^15 must not wrap. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "run.h"

/* Calibrated against measured peaks (docs/performance.md §the cost estimate): the factor's entries per
 * matrix row, a log2 n − b in 2-D and c n^(1/3) in 3-D (nested dissection), and the bytes a factor entry costs
 * with its indices and workspace (UMFPACK twice CHOLMOD's, §linear solvers). */
enum { ESTIMATE_SAFETY_PERCENT = 125 };
static const double FILL_2D_SLOPE = 0.6, FILL_2D_OFFSET = 4.0, FILL_3D = 0.13;
static const double CHOLMOD_BYTES = 12.0, UMFPACK_BYTES = 24.0;
/* Conservative rates for the time: seconds per (point × support) of shape functions, per (point × support² ×
 * unknowns²) of assembly, and the factor's flop rate. */
static const double SECONDS_SHAPE = 3e-7, SECONDS_ASSEMBLE = 1e-9, FLOP_RATE = 1e10;
/* The process before any of it: the program, its libraries, the deck. */
static const double BASE_BYTES = 32e6;

/* ---- counts from the deck --------------------------------------------------------------------------------- */

/* The extent of the shape along each parameter axis, for an absolute mls.radius. */
static void shape_extent(const MicaShapeSpec *s, double *extent) {
  for (int d = 0; d < 3; d++) extent[d] = 1.0;
  switch (s->kind) {
  case MICA_SHAPE_BOX:
    for (int d = 0; d < s->dim; d++) extent[d] = s->upper[d] - s->lower[d];
    break;
  case MICA_SHAPE_POLYGON:
    for (int d = 0; d < 2; d++) {
      double lo = s->vertices[0][d], hi = lo;
      for (int v = 1; v < 4; v++) lo = fmin(lo, s->vertices[v][d]), hi = fmax(hi, s->vertices[v][d]);
      extent[d] = hi - lo;
    }
    break;
  case MICA_SHAPE_PLATE_HOLE: extent[0] = s->plate_size[0], extent[1] = s->plate_size[1]; break;
  case MICA_SHAPE_ANNULUS:
    extent[0] = s->r_outer - s->r_inner, extent[1] = s->r_inner * fabs(s->theta1 - s->theta0);
    break;
  case MICA_SHAPE_CYLINDER: extent[0] = extent[1] = s->radius, extent[2] = s->height; break;
  case MICA_SHAPE_GMSH: break;
  }
}

/* Unknowns per particle and derivative order of material.model (the registry's ncomp, without building it). */
static int model_unknowns(const MicaDeck *deck, int dim, int *ncomp, int *second) {
  const char *model, *kind;
  MICA_CALL(mica_deck_string(deck, "material.model", &model));
  MICA_CALL(mica_deck_string(deck, "material.micro_kind", &kind));
  const int rotations = dim == 2 ? 1 : 3;
  *second = !strcmp(model, "strain-gradient") || !strcmp(model, "couple-stress") ||
            (!strcmp(model, "micromorph") && strcmp(kind, "rotation"));
  const int rotating = !strncmp(model, "cosserat", 8) || (!strcmp(model, "micromorph") && !strcmp(kind, "rotation"));
  *ncomp = rotating ? dim + rotations : dim;
  return MICA_SUCCESS;
}

/* Particles per support (mean) and particles coupled to one particle, from the dilation (or radius) δ in
 * spacings: 2δ per axis for a box, the ball's volume for a ball; coupled: closer than 2δ spacings per axis,
 * 2 ceil(2δ) − 1 of them (a ball: the ball of radius 2δ). */
static int support_counts(const MicaDeck *deck, const MicaShapeSpec *shape, const double *count, int dim,
                          double *support, double *coupled) {
  const char *kind;
  long order;
  int fe;
  MICA_CALL(mica_deck_string(deck, "mls.support", &kind));
  MICA_CALL(run_is_fe(deck, &fe));
  MICA_CALL(mica_deck_int(deck, "mls.order", &order));
  double delta[3] = {(double)order + 1, (double)order + 1, (double)order + 1};
  if (fe) { /* Lagrange elements: (order + 1)^dim nodes, (2 order + 1)^dim coupled */
    *support = pow((double)order + 1, dim), *coupled = pow(2.0 * (double)order + 1, dim);
    return MICA_SUCCESS;
  }
  if (mica_deck_has(deck, "mls.dilation")) {
    MICA_CALL(mica_deck_float(deck, "mls.dilation", &delta[0]));
    delta[1] = delta[2] = delta[0];
  } else if (mica_deck_has(deck, "mls.radius")) {
    double radius[3], extent[3];
    int n;
    MICA_CALL(mica_deck_floats(deck, "mls.radius", radius, 3, &n));
    shape_extent(shape, extent);
    for (int d = 0; d < dim; d++) delta[d] = radius[n == 1 ? 0 : d] * (count[d] - 1) / fmax(extent[d], 1e-300);
  }
  const int ball = !strcmp(kind, "ball");
  double box = 1, box2 = 1, mean = 1;
  for (int d = 0; d < dim; d++) {
    box *= fmin(2 * delta[d], count[d]);
    box2 *= fmin(2 * ceil(2 * delta[d]) - 1, count[d]);
    mean *= delta[d];
  }
  const double pi = 3.14159265358979323846, ball_volume = dim == 2 ? pi : 4 * pi / 3; /* of the unit ball */
  *support = ball ? fmin(ball_volume * pow(pow(mean, 1.0 / dim) + 0.25, dim), box) : box;
  *coupled = ball ? fmin(ball_volume * pow(2 * pow(mean, 1.0 / dim) + 0.5, dim), box2) : box2;
  return MICA_SUCCESS;
}

void run_mesh_counts(const MicaDiscretization *disc, RunMeshCounts *c) {
  *c = (RunMeshCounts){disc->dim, (double)disc->nparticles, (double)disc->ncells, (double)disc->nquad, 0};
  for (int s = 0; s < disc->nsets; s++) c->boundary_points += (double)disc->sets[s].n;
}

/* Particles, volume and boundary points of a built-in shape from its counts (mesh == NULL), or of a Gmsh mesh's
 * (the file's size is bounded by limits.mesh_mb). */
static int point_counts(const MicaDeck *deck, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                        const RunMeshCounts *mesh, int dim, double *count, RunEstimate *est) {
  long error_order;
  MICA_CALL(mica_deck_int(deck, "quadrature.error_order", &error_order));
  const int border = cells->boundary_order > 0 ? cells->boundary_order : cells->order;
  if (mesh) {
    est->particles = mesh->particles, est->points = mesh->points, est->boundary_points = mesh->boundary_points;
    const double side = pow(est->particles, 1.0 / dim);
    for (int d = 0; d < dim; d++) count[d] = side;
    est->points += mesh->cells * pow((double)error_order, dim);
    return MICA_SUCCESS;
  }
  double particles = 1, ncells = 1, faces = 0;
  for (int d = 0; d < dim; d++) {
    count[d] = (double)layout->count[d];
    const double c = cells->count[d] > 0 ? (double)cells->count[d] : count[d] - 1;
    particles *= count[d], ncells *= c;
    faces += 2 / fmax(c, 1); /* boundary cells: the cells of the faces normal to axis d */
  }
  est->particles = particles;
  est->points = ncells * (pow(cells->order, dim) + pow((double)error_order, dim));
  est->boundary_points = ncells * faces * pow(border, dim - 1);
  return MICA_SUCCESS;
}

/* The linear solver solver.linear = "auto" picks: CHOLMOD unless Lagrange multipliers make the tangent
 * indefinite (UMFPACK) or VCI unsymmetric (cholmod-sym: CHOLMOD on the symmetric part; estimated as CHOLMOD). */
static int read_solver(const MicaDeck *deck, RunEstimate *est) {
  const char *linear, *bc, *method_name;
  int fe, axisymmetric;
  MICA_CALL(mica_deck_string(deck, "solver.linear", &linear));
  MICA_CALL(mica_deck_string(deck, "bc.method", &bc));
  MICA_CALL(mica_deck_string(deck, "problem.method", &method_name));
  MICA_CALL(mica_deck_bool(deck, "geometry.axisymmetric", &axisymmetric));
  fe = !strcmp(method_name, "fe");
  /* before the model and the mesh are read: a first-order model and covering sets assumed */
  RunVciFacts facts = {.fe = fe, .axisymmetric = axisymmetric};
  MICA_CALL(run_vci_replicated_parallel(deck, &facts.parallel));
  RunVciChoice vci;
  MICA_CALL(run_vci_choose(deck, &facts, &vci));
  const MicaType *method;
  MICA_CALL(mica_registry_get(&mica_bc_method_registry, bc, &method));
  const int spd = mica_type_has(method, MICA_BC_SYMMETRIC_DEFINITE);
  est->solver = strcmp(linear, "auto") ? linear : spd && !vci.on ? "cholmod" : spd ? "cholmod-sym" : "umfpack";
  if (!strcmp(linear, "petsc")) { /* its own copy of the matrix; a factor only with a direct method */
    const char *method, *options;
    MICA_CALL(mica_deck_string(deck, "solver.petsc", &method));
    MICA_CALL(mica_deck_string(deck, "solver.petsc_options", &options));
    est->petsc_copy = 1;
    est->solver = mica_petsc_method_factors(method, options) ? "petsc" : "petsc-iterative";
  }
  return MICA_SUCCESS;
}

/* The memory of each part (bytes) and the time. */
static void estimate_cost(int dim, int ncomp, int second, double coupled, RunEstimate *est) {
  const double P = est->particles, Q = est->points + est->boundary_points, S = est->support;
  const double slots = 1 + dim + (second ? dim * (dim + 1) / 2 : 0); /* N, ∇N, ∇∇N per entry */
  est->dofs = P * ncomp;
  est->nnz = P * coupled * ncomp * ncomp;
  est->cache_bytes = (Q + P) * S * (8 + 8 * slots) + Q * (8.0 * (dim + 3)); /* + at the particles; x, w, cell */
  est->matrix_bytes = est->nnz * 16 + est->dofs * 8;
  const double n = est->dofs, per_row = est->nnz / fmax(n, 1);
  est->factor_entries = 0;
  if (strcmp(est->solver, "petsc-iterative") != 0)
    est->factor_entries = fmin(n * per_row * (dim == 3 ? FILL_3D * cbrt(n) : fmax(FILL_2D_SLOPE * log2(fmax(n, 2)) - FILL_2D_OFFSET, 1)), n * (n + 1) / 2);
  const double per_entry = !strcmp(est->solver, "umfpack") ? UMFPACK_BYTES : CHOLMOD_BYTES;
  /* PETSc's AIJ copy (8-byte values, 4-byte column indices) and, for multigrid, about half that again */
  est->factor_bytes = est->factor_entries * per_entry + (est->petsc_copy ? est->nnz * 12 * 1.5 : 0);
  const double vectors = est->dofs * 8 * 16 + P * 8 * (dim + 8); /* Newton's vectors, particles, search */
  est->bytes = BASE_BYTES + (est->cache_bytes + est->matrix_bytes + est->factor_bytes + vectors) *
                                ESTIMATE_SAFETY_PERCENT / 100;
  const double flops = est->factor_entries * est->factor_entries / fmax(n, 1);
  est->seconds = Q * S * SECONDS_SHAPE + Q * S * S * ncomp * ncomp * SECONDS_ASSEMBLE + flops / FLOP_RATE;
}

int run_estimate(const MicaDeck *deck, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                 const MicaCellSpec *cells, const RunMeshCounts *mesh, RunEstimate *est) {
  memset(est, 0, sizeof *est);
  const int dim = mesh ? mesh->dim : shape->dim;
  double count[3] = {1, 1, 1}, coupled = 0;
  int axisymmetric = 0, second = 0, ncomp = 0;
  MICA_CALL(point_counts(deck, layout, cells, mesh, dim, count, est));
  MICA_CALL(support_counts(deck, shape, count, dim, &est->support, &coupled));
  MICA_CALL(mica_deck_bool(deck, "geometry.axisymmetric", &axisymmetric));
  MICA_CALL(model_unknowns(deck, axisymmetric ? 3 : dim, &ncomp, &second));
  MICA_CALL(read_solver(deck, est));
  estimate_cost(dim, ncomp, second, coupled, est);
  est->valid = 1;
  return MICA_SUCCESS;
}

/* ---- the limits ----------------------------------------------------------------------------------------- */

double run_physical_memory(void) {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? (double)pages * (double)page : 0;
}

/* "particles.count = [3000, 3000]" or "geometry.mesh = \"part.msh\"": what the user would change. */
static void cause(const MicaDeck *deck, const MicaLayoutSpec *layout, int dim, char *path, size_t psize,
                  char *text, size_t tsize) {
  if (!mica_deck_has(deck, "particles.count") || !layout) {
    const char *mesh = "";
    if (mica_deck_has(deck, "geometry.mesh")) mica_deck_string(deck, "geometry.mesh", &mesh);
    snprintf(path, psize, "%s", "geometry.mesh");
    snprintf(text, tsize, "geometry.mesh = \"%s\"", mesh);
    return;
  }
  snprintf(path, psize, "%s", "particles.count");
  int used = snprintf(text, tsize, "particles.count = [");
  for (int d = 0; d < dim && used > 0 && (size_t)used < tsize; d++)
    used += snprintf(text + used, tsize - (size_t)used, "%s%ld", d ? ", " : "", layout->count[d]);
  if (used > 0 && (size_t)used < tsize) snprintf(text + used, tsize - (size_t)used, "]");
}

int run_estimate_guard(const MicaDeck *deck, const MicaLayoutSpec *layout, int dim, const RunEstimate *est) {
  const double physical = run_physical_memory();
  double limit_gb = physical / 1e9;
  const int given = mica_deck_has(deck, "limits.memory_gb");
  if (given) MICA_CALL(mica_deck_float(deck, "limits.memory_gb", &limit_gb));
  if (est->bytes <= limit_gb * 1e9) return MICA_SUCCESS;
  char path[32], text[160], where[256], limit[96];
  cause(deck, layout, dim, path, sizeof path, text, sizeof text);
  mica_deck_where(deck, path, where, sizeof where);
  if (given)
    snprintf(limit, sizeof limit, "limits.memory_gb = %g (this machine has %.1f GB)", limit_gb, physical / 1e9);
  else
    snprintf(limit, sizeof limit, "this machine's %.1f GB (limits.memory_gb)", physical / 1e9);
  MICA_ERROR(MICA_ERR_INPUT,
             "%s: %s needs about %.3g GB (estimate: %.3g particles, %.3g quadrature points, %.3g dofs, %.3g matrix "
             "entries, %.3g factor entries with %s), more than %s; lower %s or raise limits.memory_gb",
             where, text, est->bytes / 1e9, est->particles, est->points + est->boundary_points, est->dofs, est->nnz,
             est->factor_entries, est->solver, limit, path);
}

int run_estimate_report(const RunEstimate *est, MicaJson *summary) {
  if (!est->valid) return MICA_SUCCESS;
  printf("estimate: %.3g GB peak memory (cache %.3g, matrix %.3g, factor %.3g GB with %s), roughly %.2g s; "
         "support %.1f\n",
         est->bytes / 1e9, est->cache_bytes / 1e9, est->matrix_bytes / 1e9, est->factor_bytes / 1e9, est->solver,
         est->seconds, est->support);
  MICA_CALL(mica_json_number(summary, "estimate_memory", est->bytes));
  MICA_CALL(mica_json_number(summary, "estimate_seconds", est->seconds));
  MICA_CALL(mica_json_number(summary, "estimate_factor_entries", est->factor_entries));
  return MICA_SUCCESS;
}

int run_mesh_file_check(const MicaDeck *deck, const char *path) {
  struct stat st;
  char where[256];
  double limit_mb;
  mica_deck_where(deck, "geometry.mesh", where, sizeof where);
  MICA_CALL(mica_deck_float(deck, "limits.mesh_mb", &limit_mb));
  MICA_CHECK(stat(path, &st) == 0, MICA_ERR_INPUT, "%s: cannot read the mesh %s: %s", where, path, strerror(errno));
  MICA_CHECK(S_ISREG(st.st_mode), MICA_ERR_INPUT,
             "%s: the mesh %s is not a regular file (a directory, device or pipe); give a .msh file", where, path);
  MICA_CHECK((double)st.st_size <= limit_mb * 1e6, MICA_ERR_INPUT,
             "%s: the mesh %s has %.1f MB, more than limits.mesh_mb = %g; use a coarser mesh or raise limits.mesh_mb",
             where, path, (double)st.st_size / 1e6, limit_mb);
  return MICA_SUCCESS;
}
