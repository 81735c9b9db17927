/* Outputs of `mica run`: fields per load step at the particles and on the cells (VTU + PVD), relative error
 * norms against an exact solution, and probes. The particle parameters are not the displacements (MLS does not
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
#include "mica/vtk.h"
#include "run.h"

/* von Mises equivalent of a 3×3 Cauchy stress. */
static double von_mises(const double *s) {
  const double dxx = s[0] - s[4], dyy = s[4] - s[8], dzz = s[8] - s[0];
  return sqrt(0.5 * (dxx * dxx + dyy * dyy + dzz * dzz) + 3 * (s[1] * s[1] + s[5] * s[5] + s[2] * s[2]));
}

/* Force stress, couple stress and (classical models) strain, 3×3 each, at kinematics q. */
static int stresses(const RunProblem *rp, const double *q, double *sigma, double *couple, double *strain) {
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

/* The fields at point i of cache c (at x), into slot i of f: what a probe at x reports, in the file frame. */
static int fields_at(RunProblem *rp, const MicaShapeCache *c, long i, const double *x, const double *u,
                     PointFields *f) {
  const MicaSolid *s = rp->solid;
  const int mdim = s->model_dim, ncomp = s->ncomp;
  double q[128], qe[128], couple[9], v[3], sigma[9], strain[9];
  mica_solid_kinematics(s, c, i, u, q);
  for (int a = 0; a < 3; a++) v[a] = a < mdim ? q[a] : 0;
  to_file_frame(rp, v, 3, f->disp + i * 3);
  if (f->rotation) { /* 2-D: φ_z is the only micro-rotation */
    for (int a = 0; a < 3; a++) v[a] = 0;
    for (int k = mdim; k < ncomp; k++) v[ncomp - mdim == 1 ? 2 : k - mdim] = q[k];
    to_file_frame(rp, v, 3, f->rotation + i * 3);
  }
  MICA_CALL(stresses(rp, q, sigma, couple, strain));
  to_file_frame(rp, sigma, 9, f->stress + i * 9);
  to_file_frame(rp, strain, 9, f->strain + i * 9);
  if (f->couple) to_file_frame(rp, couple, 9, f->couple + i * 9);
  if (f->micro) {
    double chi[9];
    MICA_CALL(s->opt.field.ops->micro_deformation(&s->opt.field, mdim, q, chi));
    to_file_frame(rp, chi, 9, f->micro + i * 9);
  }
  f->mises[i] = von_mises(sigma);
  if (rp->has_exact) {
    MICA_CALL(exact_at(rp, x, qe));
    for (int a = 0; a < 3; a++) v[a] = a < mdim ? q[a] - qe[a] : 0;
    to_file_frame(rp, v, 3, f->error + i * 3);
  }
  return MICA_SUCCESS;
}

static int fields_compute(RunProblem *rp, const MicaShapeCache *c, const double *x, const double *u, PointFields *f) {
  const int dim = rp->disc->dim;
  MICA_CALL(fields_alloc(rp, c->npoints, f));
  for (long i = 0; i < c->npoints; i++) MICA_CALL(fields_at(rp, c, i, x + i * dim, u, f));
  return MICA_SUCCESS;
}

/* The derivative order of the output caches: the model's, as for probes. A cache kept from a run of another
 * model (a sweep reusing the geometry) is rebuilt. */
static int output_order(const RunProblem *rp) { return rp->solid->opt.field.ops->order >= 2 ? 2 : 1; }

static int particle_cache(RunProblem *rp) {
  if (rp->at_particles && rp->at_particles->order != output_order(rp)) mica_shape_cache_destroy(&rp->at_particles);
  if (!rp->at_particles) MICA_CALL(rp->approx.ops->particles(rp->approx.ctx, output_order(rp), &rp->at_particles));
  return MICA_SUCCESS;
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

/* step_NNNN.vtu: the fields at the particles, each a vertex cell. */
static int write_particles(RunOutput *out, int step, const double *u) {
  RunProblem *rp = out->rp;
  PointFields f = {0};
  MicaVtkField fields[9];
  char *path = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(particle_cache(rp));
  MICA_CALL_CLEANUP(fields_compute(rp, rp->at_particles, rp->disc->x, u, &f));
  char name[32];
  snprintf(name, sizeof name, "step_%04d.vtu", step);
  MICA_CALL_CLEANUP(mica_path_join(out->outdir, name, &path));
  MICA_CALL_CLEANUP(mica_vtu_write(path, rp->disc->dim, rp->disc->nparticles, rp->disc->x, field_list(rp, &f, fields),
                                   fields));
cleanup:
  free(path);
  fields_free(&f);
  return ierr;
}

/* mesh_NNNN.vtu: the same fields at the points of the cells (disc->mesh). */
static int write_mesh(RunOutput *out, int step, const double *u) {
  RunProblem *rp = out->rp;
  const MicaCellMesh *mesh = rp->disc->mesh;
  PointFields f = {0};
  MicaVtkField fields[9];
  char *path = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mesh_cache(rp));
  MICA_CALL_CLEANUP(fields_compute(rp, rp->at_mesh, mesh->x, u, &f));
  char name[32];
  snprintf(name, sizeof name, "mesh_%04d.vtu", step);
  MICA_CALL_CLEANUP(mica_path_join(out->outdir, name, &path));
  const MicaVtkCells cells = {mesh->ncells, mesh->offsets, mesh->conn, mesh->type};
  MICA_CALL_CLEANUP(mica_vtu_write_cells(path, mesh->dim, mesh->npoints, mesh->x, &cells, field_list(rp, &f, fields),
                                         fields));
cleanup:
  free(path);
  fields_free(&f);
  return ierr;
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
  if (!out->vtu || mica_parallel_rank() != 0) return MICA_SUCCESS; /* MPI: rank 0 writes */
  const double start = mica_wtime();
  MICA_CALL(output_grow(out));
  int ierr = write_particles(out, step, u);
  if (!ierr && out->mesh) ierr = write_mesh(out, step, u);
  if (!ierr) out->steps[out->nsteps] = step, out->times[out->nsteps++] = t;
  out->time_output += mica_wtime() - start;
  return ierr;
}

/* solution.pvd: per step the particles as part 0 and, with output.mesh, the mesh as part 1; ParaView shows the
 * two as blocks of one data set. */
int run_output_finish(RunOutput *out) {
  if (!out->vtu || out->nsteps == 0) return MICA_SUCCESS;
  static const char *const names[2] = {"particles", "mesh"};
  static const char *const patterns[2] = {"step_%04d.vtu", "mesh_%04d.vtu"};
  enum { NAME_SIZE = 32 };
  const int nparts = out->mesh ? 2 : 1;
  const size_t nfiles = (size_t)out->nsteps * (size_t)nparts;
  char *text = NULL, *path = NULL;
  const char **files = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(text, nfiles * NAME_SIZE));
  MICA_CALL_CLEANUP(MICA_MALLOC(files, nfiles));
  for (size_t i = 0; i < nfiles; i++) {
    files[i] = text + i * NAME_SIZE;
    snprintf(text + i * NAME_SIZE, NAME_SIZE, patterns[i % (size_t)nparts], out->steps[i / (size_t)nparts]);
  }
  MICA_CALL_CLEANUP(mica_path_join(out->outdir, "solution.pvd", &path));
  MICA_CALL_CLEANUP(mica_pvd_write_parts(path, out->nsteps, out->times, nparts, names, files));
cleanup:
  free(path);
  free(files);
  free(text);
  return ierr;
}

void run_output_free(RunOutput *out) {
  MICA_FREE(out->steps);
  MICA_FREE(out->times);
  out->nsteps = out->capacity = 0;
}

/* ---- error norms ----------------------------------------------------------------------------------------- */

/* Where the error norms are measured: the volume quadrature, or under nodal integration the background
 * Gauss points with the MLS shape functions themselves — the nodal points alone cannot see a spurious mode
 * whose gradients vanish there, and SCNI's smoothed gradients are not the gradients of the approximation. */
int run_error_points(RunProblem *rp, const MicaShapeCache **c, const double **x, const double **w, int *whole) {
  const MicaDiscretization *disc = rp->solid->disc; /* under MPI, this rank's points (nodal modes are serial) */
  *whole = 0;
  if (!rp->error_disc) MICA_CALL(run_error_discretization(rp, &rp->error_disc));
  if (rp->error_disc) { /* quadrature.error_order: every point on every rank (u is whole on each) */
    const MicaDiscretization *e = rp->error_disc;
    if (!rp->at_gauss)
      MICA_CALL(rp->approx.ops->points(rp->approx.ctx, e->nquad, e->qx, NULL, rp->solid->opt.field.ops->order,
                                       "error-norm Gauss", &rp->at_gauss));
    *c = rp->at_gauss, *x = e->qx, *w = e->qw, *whole = 1;
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

/* ---- probes ------------------------------------------------------------------------------------------------ */

/* The value of a named field at a point: an unknown by its name ("ux", "phiz"), a strain e.., a force
 * stress s.. or couple stress m.. component (first index the one contracted with the normal; axes x, y, z or,
 * axisymmetric, r, t = θ, z), or mises. */
static double probe_field(const RunProblem *rp, const char *field, const double *q, const double *strain,
                          const double *sigma, const double *couple) {
  const char *axes = rp->axisymmetric ? "rtz" : "xyz";
  for (int c = 0; c < rp->solid->ncomp; c++)
    if (!strcmp(field, run_unknown_name(rp, c))) return q[c];
  if (!strcmp(field, "mises")) return von_mises(sigma);
  const double *tensor = field[0] == 'e' ? strain : field[0] == 'm' ? couple : sigma;
  const int i = (int)(strchr(axes, field[1]) - axes), j = (int)(strchr(axes, field[2]) - axes);
  return tensor[i * 3 + j];
}

/* Does this model (in this dimension, plain or axisymmetric) have the probe's field? */
static int probe_field_exists(const RunProblem *rp, const char *field) {
  const char *axes = rp->axisymmetric ? "rtz" : "xyz";
  for (int c = 0; c < rp->solid->ncomp; c++)
    if (!strcmp(field, run_unknown_name(rp, c))) return 1;
  if (!strcmp(field, "mises")) return 1;
  return (field[0] == 's' || field[0] == 'e' || field[0] == 'm') && strlen(field) == 3 && strchr(axes, field[1]) &&
         strchr(axes, field[2]);
}

/* The strain energy of the whole body, Σ_p w_p W(q_p) over the volume quadrature (with 2πr if axisymmetric). */
static int strain_energy(const RunProblem *rp, const double *u, double *energy) {
  const MicaSolid *s = rp->solid;
  double q[128], W;
  int ierr = MICA_SUCCESS;
  *energy = 0;
  for (long p = 0; p < s->volume->npoints && !ierr; p++) {
    mica_solid_kinematics(s, s->volume, p, u, q);
    ierr = s->opt.field.ops->eval(&s->opt.field, s->model_dim, q, &W, NULL, NULL);
    *energy += s->disc->qw[p] * W; /* s->disc: under MPI, this rank's points, summed below */
  }
  if (rp->dist) MICA_CALL(mica_parallel_sum(ierr, energy, 1));
  return ierr;
}

/* Probe i's point (dim coordinates) and where the deck gives it ("deck.cfg:LINE"). */
static int probe_point(const RunProblem *rp, int i, const char *name, double point[3], char *where, size_t size) {
  char path[96];
  int n = 0;
  snprintf(path, sizeof path, "output.probes.[%d].point", i);
  mica_deck_where(rp->deck, path, where, size);
  if (!mica_deck_has(rp->deck, path)) {
    snprintf(path, sizeof path, "output.probes.[%d]", i);
    mica_deck_where(rp->deck, path, where, size);
    MICA_ERROR(MICA_ERR_INPUT, "%s: probe '%s' needs a point (only field = \"energy\" has none)", where, name);
  }
  point[0] = point[1] = point[2] = 0;
  MICA_CALL(mica_deck_floats(rp->deck, path, point, 3, &n));
  MICA_CHECK(n == rp->disc->dim, MICA_ERR_INPUT, "%s: probe '%s' needs a point with %d coordinates", where, name,
             rp->disc->dim);
  return MICA_SUCCESS;
}

/* The raw value of a point probe: the field at the deck's point. */
static int probe_at_point(RunProblem *rp, int i, const char *name, const char *field, const double *u, double *raw) {
  const MicaSolid *s = rp->solid;
  const int dim = rp->disc->dim;
  char where[256];
  double point[3];
  MICA_CALL(probe_point(rp, i, name, point, where, sizeof where));
  MICA_CHECK(probe_field_exists(rp, field), MICA_ERR_INPUT,
             "%s: probe '%s' asks for %s, which this model in %d-D%s does not have", where, name, field, dim,
             rp->axisymmetric ? " (axisymmetric: axes r, t, z)" : "");
  MICA_CHECK(!(field[0] == 'e' && strlen(field) == 3 && !s->opt.field.classical), MICA_ERR_INPUT,
             "%s: probe '%s': strains are reported for classical models only", where, name);
  MICA_CHECK(!rp->axisymmetric || point[0] > 0, MICA_ERR_INPUT,
             "%s: probe '%s': an axisymmetric probe needs r > 0 (the hoop terms divide by r)", where, name);
  /* the shape functions at the point: a cache of one point, from the approximation (it finds the element) */
  MicaShapeCache *c = NULL;
  int ierr = rp->approx.ops->points(rp->approx.ctx, 1, point, NULL, s->opt.field.ops->order, "probe", &c);
  if (ierr) {
    mica_error_prefix("%s: probe '%s'", where, name);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr == MICA_ERR_NUMERIC ? MICA_ERR_INPUT : ierr);
  }
  double q[128] = {0}, sigma[9], couple[9] = {0}, strain[9];
  mica_solid_kinematics(s, c, 0, u, q);
  mica_shape_cache_destroy(&c);
  MICA_CALL(stresses(rp, q, sigma, couple, strain));
  *raw = probe_field(rp, field, q, strain, sigma, couple);
  return MICA_SUCCESS;
}

static int probe_one(RunProblem *rp, int i, const double *u, MicaJson *summary) {
  const MicaDeck *deck = rp->deck;
  char path[96];
  const char *name, *field;
  double scale, raw;
  int inverse;
  snprintf(path, sizeof path, "output.probes.[%d].name", i);
  MICA_CALL(mica_deck_string(deck, path, &name));
  snprintf(path, sizeof path, "output.probes.[%d].field", i);
  MICA_CALL(mica_deck_string(deck, path, &field));
  snprintf(path, sizeof path, "output.probes.[%d].scale", i);
  MICA_CALL(mica_deck_float(deck, path, &scale));
  snprintf(path, sizeof path, "output.probes.[%d].inverse", i);
  MICA_CALL(mica_deck_bool(deck, path, &inverse));
  if (!strcmp(field, "energy"))
    MICA_CALL(strain_energy(rp, u, &raw));
  else
    MICA_CALL(probe_at_point(rp, i, name, field, u, &raw));
  MICA_CHECK(!inverse || raw != 0, MICA_ERR_NUMERIC, "probe '%s': %s is 0 at the point; it has no inverse", name, field);
  const double value = inverse ? scale / raw : scale * raw;
  MICA_CALL(mica_json_number(summary, name, value));
  printf("probe %s = %.10g\n", name, value);
  return MICA_SUCCESS;
}

/* "x in [0, 48], y in [-6, 6]" */
static void bounds_text(const MicaBody *body, char *buf, size_t size) {
  double lo[3], hi[3];
  size_t len = 0;
  mica_body_bounds(body, lo, hi);
  buf[0] = '\0';
  for (int d = 0; d < mica_body_dim(body) && len < size; d++)
    len += (size_t)snprintf(buf + len, size - len, "%s%c in [%g, %g]", d ? ", " : "", "xyz"[d], lo[d], hi[d]);
}

/* Probe i's point lies in the body (within MICA_BODY_TOLERANCE of its size), or the probe allows
 * extrapolation; extrapolate on a probe without a point, or with finite elements, is refused. */
static int check_probe_point(const RunProblem *rp, MicaBody *body, int i) {
  const char *name, *field;
  char path[96], where[256];
  int extrapolate;
  snprintf(path, sizeof path, "output.probes.[%d].name", i);
  MICA_CALL(mica_deck_string(rp->deck, path, &name));
  snprintf(path, sizeof path, "output.probes.[%d].field", i);
  MICA_CALL(mica_deck_string(rp->deck, path, &field));
  snprintf(path, sizeof path, "output.probes.[%d].extrapolate", i);
  MICA_CALL(mica_deck_bool(rp->deck, path, &extrapolate));
  mica_deck_where(rp->deck, path, where, sizeof where);
  if (!strcmp(field, "energy")) {
    MICA_CHECK(!extrapolate, MICA_ERR_INPUT,
               "%s: probe '%s': extrapolate is for a probe at a point; field = \"energy\" has none (remove it)", where,
               name);
    return MICA_SUCCESS;
  }
  MICA_CHECK(!(extrapolate && rp->fe), MICA_ERR_INPUT,
             "%s: probe '%s': extrapolate = true needs the MLS approximation; finite elements (problem.method = "
             "\"fe\") have no values outside their elements", where, name);
  double point[3];
  MICA_CALL(probe_point(rp, i, name, point, where, sizeof where));
  if (extrapolate || mica_body_contains(body, point)) return MICA_SUCCESS;
  char at[96], shape[600], bounds[256];
  if (rp->disc->dim == 3)
    snprintf(at, sizeof at, "(%g, %g, %g)", point[0], point[1], point[2]);
  else
    snprintf(at, sizeof at, "(%g, %g)", point[0], point[1]);
  mica_body_describe(body, shape, sizeof shape);
  bounds_text(body, bounds, sizeof bounds);
  MICA_ERROR(MICA_ERR_INPUT,
             "%s: probe '%s' at %s lies outside the body, %s (bounds %s); move it inside or onto the boundary, or "
             "set extrapolate = true in the probe to report the approximation's value there anyway",
             where, name, at, shape, bounds);
}

int run_check_probes(const RunProblem *rp) {
  const int count = mica_deck_list_length(rp->deck, "output.probes");
  if (count == 0) return MICA_SUCCESS;
  MicaBody *body = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(run_body_create(rp->deck, &body));
  for (int i = 0; i < count && !ierr; i++) ierr = check_probe_point(rp, body, i);
  mica_body_destroy(&body);
  return ierr;
}

int run_probes(RunProblem *rp, const double *u, MicaJson *summary) {
  const int count = mica_deck_list_length(rp->deck, "output.probes");
  if (count == 0) return MICA_SUCCESS;
  for (int i = 0; i < count; i++) MICA_CALL(probe_one(rp, i, u, summary));
  return MICA_SUCCESS;
}
