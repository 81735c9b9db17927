/* Outputs of `mica run`: the registry of output types (mica/output.h; each type is its own file, output_*.c) and
 * the loop that drives the enabled ones, the fields at points they share, and the relative error norms against
 * an exact solution (numbers of the run's record, summary.json, not an output type: they have no setting). The particle parameters are not the displacements (MLS does not
 * interpolate): every field is the approximation evaluated at the particles, through the approximation's
 * ops (finite elements: the nodal values, gradients averaged over the elements around the node), and at the
 * points of the output mesh (disc->mesh) through the ops call a probe makes, so a vertex value is a probe's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/cosserat.h"
#include "mica/files.h"
#include "mica/timer.h"
#include "run.h"

/* von Mises equivalent of a 3×3 Cauchy stress. */
double run_von_mises(const double *s) {
  const double dxx = s[0] - s[4], dyy = s[4] - s[8], dzz = s[8] - s[0];
  return sqrt(0.5 * (dxx * dxx + dyy * dyy + dzz * dzz) + 3 * (s[1] * s[1] + s[5] * s[5] + s[2] * s[2]));
}

/* Force stress, couple stress and (classical models) strain, 3×3 each, at kinematics q. */
int run_stresses(const RunProblem *rp, const double *q, double *sigma, double *couple, double *strain) {
  const MicaSolid *s = rp->solid;
  const MicaFieldModel *m = &s->opt.field;
  memset(strain, 0, sizeof(double) * 9);
  MICA_CALL(m->ops->stress(m, s->model_dim, q, sigma, couple));
  if (m->classical) {
    double F[9], sig[9];
    const int dim = s->model_dim;
    for (int a = 0; a < dim; a++)
      for (int J = 0; J < dim; J++) F[a * dim + J] = (a == J) + q[s->ncomp + a * dim + J];
    MICA_CALL(mica_model_stress_strain(m->classical, &m->material, dim, F, sig, strain));
  }
  return MICA_SUCCESS;
}

/* Values and geometric gradients (q2: values, then ∂_J of each unknown in the geometry's dim) into the model's
 * layout q. The same unless the solid is axisymmetric: then the gradients go to columns r and z of the 3-D
 * gradient, and column θ gets the hoop terms of each vector, (∇v)_rθ = −v_θ/r, (∇v)_θθ = v_r/r (theory.md). */
static void to_model_layout(const RunProblem *rp, const double *x, const double *q2, double *q) {
  const int dim = rp->disc->dim, mdim = run_model_dim(rp), ncomp = rp->solid->ncomp;
  if (!rp->axisymmetric) {
    memcpy(q, q2, sizeof(double) * (size_t)(ncomp * (1 + dim)));
    return;
  }
  memset(q, 0, sizeof(double) * (size_t)(ncomp * (1 + mdim)));
  for (int c = 0; c < ncomp; c++) {
    q[c] = q2[c];
    q[ncomp + c * mdim + 0] = q2[ncomp + c * dim + 0];
    q[ncomp + c * mdim + 2] = q2[ncomp + c * dim + 1];
  }
  for (int first = 0; first < ncomp; first += 3) { /* on the axis v_r = v_θ = 0 and v/r tends to ∂v/∂r */
    const double r = x[0];
    q[ncomp + first * mdim + 1] = r > 0 ? -q2[first + 1] / r : -q2[ncomp + (first + 1) * dim];
    q[ncomp + (first + 1) * mdim + 1] = r > 0 ? q2[first] / r : q2[ncomp + first * dim];
  }
}

/* The exact unknowns and their gradients at x (q layout of the model: values, then gradients). An exact solution
 * (or a derivative of it) that is not finite at x is a deck error naming it, rather than a NaN error norm. */
static int exact_at(const RunProblem *rp, const double *x, double *q) {
  const int dim = rp->disc->dim, ncomp = rp->ncomp;
  double p[3] = {0, 0, 0}, q2[64];
  memcpy(p, x, sizeof(double) * (size_t)dim);
  for (int c = 0; c < ncomp; c++) {
    MICA_CALL(mica_function_eval_finite(rp->exact[c], "in the whole body", dim, p, 1.0, &q2[c]));
    for (int J = 0; J < dim; J++)
      MICA_CALL(mica_function_eval_finite(rp->exact_grad[c][J], "in the whole body", dim, p, 1.0,
                                          &q2[ncomp + c * dim + J]));
  }
  to_model_layout(rp, x, q2, q);
  return MICA_SUCCESS;
}

/* ---- fields at points: the particles and the vertices of the output mesh ------------------------------- */

typedef struct {
  double *disp, *rotation, *strain, *stress, *couple, *micro, *mises, *error;
} PointFields;

static void fields_free(PointFields *f) {
  free(f->disp), free(f->rotation), free(f->strain), free(f->stress), free(f->couple), free(f->micro), free(f->mises);
  free(f->error);
}

/* The Cosserat models report a couple stress; the micromorph kinds' stress op leaves it 0 (their double stress
 * is not reported), and a field of zeros would claim otherwise. */
static int reports_couple_stress(const RunProblem *rp) {
  return mica_type_has(&rp->solid->opt.field.ops->type, MICA_FIELD_COUPLE_STRESS);
}

static int fields_alloc(const RunProblem *rp, long n, PointFields *f) {
  MICA_CALL(MICA_CALLOC(f->disp, n * 3));
  MICA_CALL(MICA_CALLOC(f->strain, n * 9));
  MICA_CALL(MICA_CALLOC(f->stress, n * 9));
  MICA_CALL(MICA_CALLOC(f->mises, n));
  if (rp->solid->ncomp > rp->solid->model_dim) MICA_CALL(MICA_CALLOC(f->rotation, n * 3));
  if (reports_couple_stress(rp)) MICA_CALL(MICA_CALLOC(f->couple, n * 9));
  if (rp->solid->opt.field.ops->micro_deformation) MICA_CALL(MICA_CALLOC(f->micro, n * 9));
  if (rp->has_exact) MICA_CALL(MICA_CALLOC(f->error, n * 3));
  return MICA_SUCCESS;
}

/* For the files, an axisymmetric solid's (r, θ, z) components are written in the section's frame (r, z, θ):
 * x and y in the section, the third out of it. */
static void to_file_frame(const RunProblem *rp, const double *v, int n, double *out) {
  static const int section[3] = {0, 2, 1};
  if (n == 3)
    for (int a = 0; a < 3; a++) out[a] = v[rp->axisymmetric ? section[a] : a];
  else
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++)
        out[a * 3 + b] = rp->axisymmetric ? v[section[a] * 3 + section[b]] : v[a * 3 + b];
}

/* The fields at point i of cache c (at x), into slot j of f: what a probe at x reports, in the file frame. */
static int fields_at(RunProblem *rp, const MicaShapeCache *c, long i, long j, const double *x, const double *u,
                     PointFields *f) {
  const MicaSolid *s = rp->solid;
  const int mdim = s->model_dim, ncomp = s->ncomp;
  double q[128], qe[128], couple[9], v[3], sigma[9], strain[9];
  mica_solid_kinematics(s, c, i, u, q);
  for (int a = 0; a < 3; a++) v[a] = a < mdim ? q[a] : 0;
  to_file_frame(rp, v, 3, f->disp + j * 3);
  if (f->rotation) { /* 2-D: φ_z is the only micro-rotation */
    for (int a = 0; a < 3; a++) v[a] = 0;
    for (int k = mdim; k < ncomp; k++) v[ncomp - mdim == 1 ? 2 : k - mdim] = q[k];
    to_file_frame(rp, v, 3, f->rotation + j * 3);
  }
  MICA_CALL(run_stresses(rp, q, sigma, couple, strain));
  to_file_frame(rp, sigma, 9, f->stress + j * 9);
  to_file_frame(rp, strain, 9, f->strain + j * 9);
  if (f->couple) to_file_frame(rp, couple, 9, f->couple + j * 9);
  if (f->micro) {
    double chi[9];
    MICA_CALL(s->opt.field.ops->micro_deformation(&s->opt.field, mdim, q, chi));
    to_file_frame(rp, chi, 9, f->micro + j * 9);
  }
  f->mises[j] = run_von_mises(sigma);
  if (rp->has_exact) {
    MICA_CALL(exact_at(rp, x, qe));
    for (int a = 0; a < 3; a++) v[a] = a < mdim ? q[a] - qe[a] : 0;
    to_file_frame(rp, v, 3, f->error + j * 3);
  }
  return MICA_SUCCESS;
}

/* At the n points sel[] of cache c (sel NULL: all of them, n = c->npoints), into slots 0 .. n−1. */
static int fields_compute(RunProblem *rp, const MicaShapeCache *c, const double *x, const double *u, long n,
                          const long *sel, PointFields *f) {
  const int dim = rp->disc->dim;
  MICA_CALL(fields_alloc(rp, n, f));
  for (long j = 0; j < n; j++) {
    const long i = sel ? sel[j] : j;
    MICA_CALL(fields_at(rp, c, i, j, x + i * dim, u, f));
  }
  return MICA_SUCCESS;
}

/* The derivative order of the output caches: the model's, as for probes. A cache kept from a run of another
 * model (a sweep reusing the geometry) is rebuilt. */
static int output_order(const RunProblem *rp) { return rp->solid->opt.field.ops->order >= 2 ? 2 : 1; }

static int particle_cache(RunProblem *rp) {
  if (rp->at_particles && rp->at_particles->order != output_order(rp)) mica_shape_cache_destroy(&rp->at_particles);
  if (rp->at_particles) return MICA_SUCCESS;
  if (rp->owned_data) /* at the owned particles only (the first ones): the ghosts' own supports reach past the rank */
    return rp->approx.ops->points(rp->approx.ctx, rp->dist->nowned, rp->disc->x, NULL, output_order(rp),
                                  "output at particle", &rp->at_particles);
  return rp->approx.ops->particles(rp->approx.ctx, output_order(rp), &rp->at_particles);
}

/* The shape functions at the mesh's points through the same ops call as a probe's (the approximation finds the
 * cell), so a vertex value is the probe's value there. */
static int mesh_cache(RunProblem *rp) {
  const MicaCellMesh *mesh = rp->disc->mesh;
  if (rp->at_mesh && rp->at_mesh->order != output_order(rp)) mica_shape_cache_destroy(&rp->at_mesh);
  if (!rp->at_mesh)
    MICA_CALL(rp->approx.ops->points(rp->approx.ctx, mesh->npoints, mesh->x, NULL, output_order(rp),
                                     "output at mesh point", &rp->at_mesh));
  return MICA_SUCCESS;
}

/* Component names: the deck's axes, or for an axisymmetric section its frame (r, z, θ). */
static const char *const vector_xyz[] = {"x", "y", "z"}, *const vector_rzt[] = {"r", "z", "theta"};
static const char *const tensor_xyz[] = {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"};
static const char *const tensor_rzt[] = {"rr",     "rz",     "rtheta", "zr",        "zz",
                                         "ztheta", "thetar", "thetaz", "thetatheta"};

static int field_list(const RunProblem *rp, const PointFields *f, MicaVtkField *fields) {
  const char *const *vector = rp->axisymmetric ? vector_rzt : vector_xyz;
  const char *const *tensor = rp->axisymmetric ? tensor_rzt : tensor_xyz;
  int nf = 0;
  fields[nf++] = (MicaVtkField){"displacement", 3, f->disp, vector};
  if (f->rotation) fields[nf++] = (MicaVtkField){"microrotation", 3, f->rotation, vector};
  if (rp->solid->opt.field.classical) fields[nf++] = (MicaVtkField){"strain", 9, f->strain, tensor};
  fields[nf++] = (MicaVtkField){"stress", 9, f->stress, tensor};
  if (f->couple) fields[nf++] = (MicaVtkField){"couple_stress", 9, f->couple, tensor};
  if (f->micro) fields[nf++] = (MicaVtkField){"micro_deformation", 9, f->micro, tensor};
  fields[nf++] = (MicaVtkField){"von_mises", 1, f->mises, NULL};
  if (f->error) fields[nf++] = (MicaVtkField){"error", 3, f->error, vector};
  return nf;
}

/* ---- what the outputs read of the run (mica/output.h) --------------------------------------------------- */

const char *mica_output_dir(const MicaOutputRun *run) { return run->outdir; }

int mica_output_writer(const MicaOutputRun *run) {
  (void)run;
  return mica_parallel_rank() == 0;
}

/* The fields at the n points sel[] of cache c (sel NULL: all, and out->x is x itself; else a copy of theirs). */
static int fields_publish(RunProblem *rp, const MicaShapeCache *c, int dim, const double *x, const double *u, long n,
                          const long *sel, MicaOutputFields *out) {
  PointFields f = {0};
  double *xs = NULL;
  memset(out, 0, sizeof *out);
  int ierr = fields_compute(rp, c, x, u, n, sel, &f);
  if (!ierr && sel) ierr = MICA_MALLOC(xs, n * dim);
  if (ierr) {
    fields_free(&f);
    return ierr;
  }
  for (long j = 0; sel && j < n; j++) memcpy(xs + j * dim, x + sel[j] * dim, sizeof(double) * (size_t)dim);
  double *owned[9] = {f.disp, f.rotation, f.strain, f.stress, f.couple, f.micro, f.mises, f.error, xs};
  memcpy(out->storage, owned, sizeof owned); /* freed by mica_output_fields_free */
  out->dim = dim, out->npoints = n, out->x = sel ? xs : x;
  out->nfields = field_list(rp, &f, out->fields);
  return MICA_SUCCESS;
}

int mica_output_particle_fields(MicaOutputRun *run, const double *u, MicaOutputFields *fields) {
  RunProblem *rp = run->rp;
  MICA_CALL(particle_cache(rp));
  return fields_publish(rp, rp->at_particles, rp->disc->dim, rp->disc->x, u, rp->at_particles->npoints, NULL, fields);
}

int mica_output_mesh_fields(MicaOutputRun *run, const double *u, MicaOutputFields *fields) {
  RunProblem *rp = run->rp;
  MICA_CHECK(rp->disc->mesh, MICA_ERR_ARGUMENT, "mica_output_mesh_fields: the discretization has no cells");
  MICA_CALL(mesh_cache(rp));
  return fields_publish(rp, rp->at_mesh, rp->disc->mesh->dim, rp->disc->mesh->x, u, rp->at_mesh->npoints, NULL, fields);
}

/* ---- pieces under MPI: each rank's particles and cells ------------------------------------------------------ */

int run_output_particle_piece(RunOutput *out, const double *u, MicaOutputFields *fields) {
  RunProblem *rp = out->rp;
  const MicaPartition *partition = rp->dist->partition;
  const int rank = mica_parallel_rank();
  long *owned = NULL, n = 0;
  int ierr = MICA_SUCCESS;
  MICA_CALL(particle_cache(rp));
  MICA_CALL(MICA_MALLOC(owned, partition->n));
  for (long i = 0; i < partition->n; i++)
    if (partition->part[i] == rank) owned[n++] = i;
  ierr = fields_publish(rp, rp->at_particles, rp->disc->dim, rp->disc->x, u, n, owned, fields);
  free(owned);
  return ierr;
}

void run_mesh_piece_range(long ncells, int piece, int npieces, long *first, long *end) {
  *first = ncells * piece / npieces, *end = ncells * (piece + 1) / npieces;
  if (piece == npieces - 1) *end = ncells;
}

void run_mesh_piece_free(RunMeshPiece *piece) {
  free(piece->offsets), free(piece->conn), free(piece->type), free(piece->points);
  memset(piece, 0, sizeof *piece);
}

/* This rank's cells of the output mesh and the points they use (ascending), renumbered from 0. */
static int mesh_piece_create(const MicaCellMesh *mesh, int rank, int size, RunMeshPiece *piece) {
  long first, end, *map = NULL;
  int ierr = MICA_SUCCESS;
  memset(piece, 0, sizeof *piece);
  run_mesh_piece_range(mesh->ncells, rank, size, &first, &end);
  const long nconn = mesh->offsets[end] - mesh->offsets[first];
  piece->ncells = end - first;
  MICA_CALL_CLEANUP(MICA_MALLOC(map, mesh->npoints));
  MICA_CALL_CLEANUP(MICA_MALLOC(piece->offsets, piece->ncells + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(piece->conn, nconn));
  MICA_CALL_CLEANUP(MICA_MALLOC(piece->type, piece->ncells));
  for (long p = 0; p < mesh->npoints; p++) map[p] = -1;
  for (long k = mesh->offsets[first]; k < mesh->offsets[end]; k++) map[mesh->conn[k]] = 0;
  for (long p = 0; p < mesh->npoints; p++)
    if (map[p] == 0) map[p] = piece->npoints++; /* each point once, in ascending order */
  MICA_CALL_CLEANUP(MICA_MALLOC(piece->points, piece->npoints));
  for (long p = 0; p < mesh->npoints; p++)
    if (map[p] >= 0) piece->points[map[p]] = p;
  for (long c = first; c < end; c++) {
    piece->offsets[c - first] = mesh->offsets[c] - mesh->offsets[first];
    piece->type[c - first] = mesh->type[c];
  }
  piece->offsets[piece->ncells] = nconn;
  for (long k = 0; k < nconn; k++) piece->conn[k] = map[mesh->conn[mesh->offsets[first] + k]];
  piece->cells = (MicaVtkCells){piece->ncells, piece->offsets, piece->conn, piece->type};
cleanup:
  free(map);
  if (ierr) run_mesh_piece_free(piece);
  return ierr;
}

int run_output_mesh_piece(RunOutput *out, const double *u, MicaOutputFields *fields, RunMeshPiece *piece) {
  RunProblem *rp = out->rp;
  const MicaCellMesh *mesh = rp->disc->mesh;
  MICA_CALL(mesh_cache(rp));
  /* replicated data: the rank's range of the whole mesh; distributed: the mesh of its cells, all of it */
  if (rp->owned_data) MICA_CALL(mesh_piece_create(mesh, 0, 1, piece));
  else MICA_CALL(mesh_piece_create(mesh, mica_parallel_rank(), rp->dist->partition->nparts, piece));
  int ierr = fields_publish(rp, rp->at_mesh, mesh->dim, mesh->x, u, piece->npoints, piece->points, fields);
  if (ierr) run_mesh_piece_free(piece);
  return ierr;
}

const MicaVtkField *mica_output_field(const MicaOutputFields *fields, const char *name) {
  for (int i = 0; i < fields->nfields; i++)
    if (!strcmp(fields->fields[i].name, name)) return &fields->fields[i];
  return NULL;
}

void mica_output_fields_free(MicaOutputFields *fields) {
  for (int i = 0; i < 9; i++) free(fields->storage[i]);
  memset(fields, 0, sizeof *fields);
}

int run_output_pvtu(RunOutput *out, const char *name, const char *piece_pattern, int step, long ncells,
                    const MicaOutputFields *fields) {
  enum { NAME_SIZE = 64 };
  const int npieces = out->rp->dist->partition->nparts;
  char *text = NULL, *path = NULL;
  const char **pieces = NULL;
  int n = 0, ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(text, (size_t)npieces * NAME_SIZE));
  MICA_CALL_CLEANUP(MICA_MALLOC(pieces, npieces));
  for (int k = 0; k < npieces; k++) {
    long first = 0, end = 1;
    if (ncells) run_mesh_piece_range(ncells, k, npieces, &first, &end);
    if (end == first) continue; /* a rank without cells writes no piece */
    pieces[n] = text + (size_t)n * NAME_SIZE;
    snprintf(text + (size_t)n * NAME_SIZE, NAME_SIZE, piece_pattern, step, k);
    n++;
  }
  MICA_CALL_CLEANUP(mica_path_join(out->piece_dir, name, &path));
  MICA_CALL_CLEANUP(mica_pvtu_write(path, fields->nfields, fields->fields, n, pieces));
cleanup:
  free(path);
  free(pieces);
  free(text);
  return ierr;
}

static int copy_text(const char *text, char **copy) {
  const size_t n = strlen(text) + 1;
  MICA_CALL(MICA_MALLOC(*copy, n));
  memcpy(*copy, text, n);
  return MICA_SUCCESS;
}

/* ---- the registry and the loop ---------------------------------------------------------------------------- */

/* The order is the order of the settings in `mica help run` and of the summary members the outputs add. */
static const MicaType *const builtin_outputs[] = {
    &run_output_vtu.type,    &run_output_mesh.type,   &run_output_monitor.type, &run_output_pvd.type,
    &run_output_probes.type, &run_output_quadrature_fields.type, NULL};

/* No default: the deck enables outputs one by one, none of them is chosen instead of another. */
MicaRegistry mica_output_registry = {"output type", NULL, builtin_outputs, NULL, 0, NULL};

/* Whether this process calls the output's step and finish: rank 0 alone for RANK0 types. */
static int runs_here(const MicaOutput *o) {
  return o->enabled && (!mica_type_has(&o->ops->type, MICA_OUTPUT_RANK0) || mica_parallel_rank() == 0);
}

/* A type that needs the cells of the output mesh, enabled on a discretization without them. */
static int check_cells(const RunOutput *out, const MicaOutput *o) {
  MICA_CHECK(!mica_type_has(&o->ops->type, MICA_OUTPUT_CELLS) || out->rp->disc->mesh, MICA_ERR_ARGUMENT,
             "output %s: the discretization has no cells", o->ops->type.name);
  return MICA_SUCCESS;
}

int run_outputs_read(RunProblem *rp, const char *outdir, RunOutput *out) {
  MicaSettings settings;
  mica_deck_settings(rp->deck, &settings);
  memset(out, 0, sizeof *out);
  out->rp = rp, out->outdir = outdir;
  const int n = mica_registry_count(&mica_output_registry);
  MICA_CALL(MICA_CALLOC(out->outputs, n));
  out->noutputs = n;
  for (int i = 0; i < n; i++) {
    MicaOutput *o = &out->outputs[i];
    o->ops = mica_output_ops_of(mica_registry_type(&mica_output_registry, i));
    if (o->ops->size) {
      unsigned char *bytes; /* the type's own struct: calloc's alignment suits any */
      MICA_CALL(MICA_CALLOC(bytes, o->ops->size));
      o->ctx = bytes;
    }
    o->enabled = 1;
    if (o->ops->type.from_settings) MICA_CALL(o->ops->type.from_settings(&o->ops->type, &settings, "output", o));
  }
  if (rp->dist) { /* the pieces go into rank 0's directory, the one published (the others' is scratch) */
    int ierr = mica_parallel_rank() == 0 ? copy_text(outdir, &out->piece_dir) : MICA_SUCCESS;
    MICA_CALL(mica_parallel_broadcast_text(ierr, &out->piece_dir, 0));
  }
  for (int i = 0; i < n; i++) {
    MicaOutput *o = &out->outputs[i];
    if (!o->enabled) continue;
    MICA_CALL(check_cells(out, o));
    if (o->ops->check) MICA_CALL(o->ops->check(out, o->ctx));
  }
  return MICA_SUCCESS;
}

/* Room for one more step in out->steps and out->times. */
static int output_grow(RunOutput *out) {
  if (out->nsteps < out->capacity) return MICA_SUCCESS;
  const int grown = out->capacity ? 2 * out->capacity : 64;
  MICA_CALL(MICA_REALLOC(out->steps, grown));
  MICA_CALL(MICA_REALLOC(out->times, grown));
  out->capacity = grown;
  return MICA_SUCCESS;
}

int run_output_step(void *ctx, int step, double t, const double *u) {
  RunOutput *out = ctx;
  const double start = mica_wtime();
  int ierr = MICA_SUCCESS, parts = 0;
  for (int i = 0; i < out->noutputs && !ierr; i++) {
    MicaOutput *o = &out->outputs[i];
    if (!runs_here(o) || !mica_type_has(&o->ops->type, MICA_OUTPUT_PER_STEP)) continue;
    ierr = o->ops->step(out, o->ctx, step, t, u);
    parts += mica_type_has(&o->ops->type, MICA_OUTPUT_PVD_PART);
  }
  if (!ierr && parts) ierr = output_grow(out);
  if (!ierr && parts) out->steps[out->nsteps] = step, out->times[out->nsteps++] = t;
  /* MPI: every rank wrote its pieces; a failure on one is every rank's now, not at some later collective */
  if (out->rp->dist) ierr = mica_parallel_agree(ierr);
  out->time_output += mica_wtime() - start;
  return ierr;
}

int run_outputs_finish(RunOutput *out, int failed, const double *u, MicaJson *summary) {
  for (int i = 0; i < out->noutputs; i++) {
    MicaOutput *o = &out->outputs[i];
    const MicaType *type = &o->ops->type;
    if (!runs_here(o) || !mica_type_has(type, failed ? MICA_OUTPUT_REACHED : MICA_OUTPUT_AT_END)) continue;
    MICA_CALL(o->ops->finish(out, o->ctx, failed ? NULL : u, summary));
  }
  return MICA_SUCCESS;
}

void run_output_free(RunOutput *out) {
  for (int i = 0; i < out->noutputs; i++) {
    MicaOutput *o = &out->outputs[i];
    if (o->ctx && o->ops->destroy) o->ops->destroy(o->ctx);
    free(o->ctx);
  }
  MICA_FREE(out->outputs);
  MICA_FREE(out->piece_dir);
  MICA_FREE(out->steps);
  MICA_FREE(out->times);
  out->noutputs = out->nsteps = out->capacity = 0;
}

/* ---- error norms ----------------------------------------------------------------------------------------- */

/* Where the error norms are measured: the volume quadrature, or under nodal integration the background
 * Gauss points with the MLS shape functions themselves — the nodal points alone cannot see a spurious mode
 * whose gradients vanish there, and SCNI's smoothed gradients are not the gradients of the approximation. */
int run_error_points(RunProblem *rp, const MicaShapeCache **c, const double **x, const double **w, int *whole) {
  const MicaDiscretization *disc = rp->solid->disc; /* under MPI, this rank's points (nodal modes are serial) */
  *whole = 0;
  if (!rp->error_disc) MICA_CALL(run_error_discretization(rp, &rp->error_disc));
  if (rp->error_disc) { /* quadrature.error_order: every point on every rank (u is whole on each; with distributed
                           data, the points of the rank's cells) */
    const MicaDiscretization *e = rp->error_disc;
    if (!rp->at_gauss)
      MICA_CALL(rp->approx.ops->points(rp->approx.ctx, e->nquad, e->qx, NULL, rp->solid->opt.field.ops->order,
                                       "error-norm Gauss", &rp->at_gauss));
    *c = rp->at_gauss, *x = e->qx, *w = e->qw, *whole = !rp->owned_data; /* distributed: this rank's cells' */
    return MICA_SUCCESS;
  }
  *c = rp->solid->volume, *x = disc->qx, *w = disc->qw;
  if (!disc->nodal) return MICA_SUCCESS;
  if (!rp->at_gauss)
    MICA_CALL(mica_shape_cache_create(rp->mls, disc->ngauss, disc->gauss_x, rp->solid->opt.field.ops->order,
                                      "error-norm Gauss", &rp->at_gauss));
  *c = rp->at_gauss, *x = disc->gauss_x, *w = disc->gauss_w;
  return MICA_SUCCESS;
}

/* Relative errors over the volume quadrature points (run_error_points; with quadrature.error_order, points of their
 * own), of all unknowns: L2 of the values, H1 seminorm of the gradients, and the energy norm e·D₀·e with D₀ the
 * model's D at q = 0 (for classical models: ∇e:C:∇e). */
int run_error_values(RunProblem *rp, const double *u, double *rel_l2, double *rel_h1, double *rel_energy) {
  MICA_CHECK(rp->has_exact, MICA_ERR_ARGUMENT, "run_error_values: the problem has no exact solution");
  const MicaSolid *s = rp->solid;
  const int dim = s->dim, mdim = s->model_dim, ncomp = s->ncomp, nq = s->nq, nvg = ncomp * (1 + mdim);
  const MicaShapeCache *c = NULL;
  const double *qx = NULL, *qw = NULL;
  int whole = 0;
  MICA_CALL(run_error_points(rp, &c, &qx, &qw, &whole));
  double *D0 = NULL, q0[128] = {0}, W0, s0[128];
  MICA_CALL(MICA_MALLOC(D0, nq * nq));
  int ierr = s->opt.field.ops->eval(&s->opt.field, mdim, q0, &W0, s0, D0);
  double l2[2] = {0, 0}, h1[2] = {0, 0}, en[2] = {0, 0};
  for (long p = 0; p < c->npoints && !ierr; p++) {
    double q[128], qe[128] = {0}, e[128] = {0};
    mica_solid_kinematics(s, c, p, u, q);
    ierr = exact_at(rp, qx + p * dim, qe);
    if (ierr) break; /* after the collective sum below, which every rank must reach */
    const double w = qw[p];
    for (int i = 0; i < nvg; i++) e[i] = q[i] - qe[i]; /* Hessian slots: no exact second derivatives, left 0 */
    for (int i = 0; i < ncomp; i++) l2[0] += w * e[i] * e[i], l2[1] += w * qe[i] * qe[i];
    for (int i = ncomp; i < nvg; i++) h1[0] += w * e[i] * e[i], h1[1] += w * qe[i] * qe[i];
    for (int i = 0; i < nvg; i++)
      for (int j = 0; j < nvg; j++) en[0] += w * e[i] * D0[i * nq + j] * e[j], en[1] += w * qe[i] * D0[i * nq + j] * qe[j];
  }
  free(D0);
  if (rp->dist && !whole) { /* MPI: sums over every rank's points */
    double sums[6] = {l2[0], l2[1], h1[0], h1[1], en[0], en[1]};
    MICA_CALL(mica_parallel_sum(ierr, sums, 6));
    l2[0] = sums[0], l2[1] = sums[1], h1[0] = sums[2], h1[1] = sums[3], en[0] = sums[4], en[1] = sums[5];
  }
  MICA_CALL(ierr);
  *rel_l2 = sqrt(l2[0] / fmax(l2[1], 1e-300));
  *rel_h1 = sqrt(h1[0] / fmax(h1[1], 1e-300));
  *rel_energy = sqrt(fabs(en[0]) / fmax(en[1], 1e-300));
  return MICA_SUCCESS;
}


int run_error_norms(RunProblem *rp, const double *u, MicaJson *summary) {
  if (!rp->has_exact) return MICA_SUCCESS;
  double el2, eh1, een;
  MICA_CALL(run_error_values(rp, u, &el2, &eh1, &een));
  MICA_CALL(mica_json_number(summary, "error_l2", el2));
  MICA_CALL(mica_json_number(summary, "error_h1", eh1));
  MICA_CALL(mica_json_number(summary, "error_energy", een));
  printf("relative errors: L2 %.3e, H1 seminorm %.3e, energy %.3e\n", el2, eh1, een);
  return MICA_SUCCESS;
}

