/* Outputs of `mica run`: fields at the particles per load step (VTU + PVD), relative error norms against
 * an exact solution, and probes. The particle parameters are not the displacements (MLS does not
 * interpolate): every field is the MLS approximation evaluated at the particles. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/files.h"
#include "mica/vtk.h"
#include "run.h"

/* von Mises equivalent of a 3×3 Cauchy stress. */
static double von_mises(const double *s) {
  const double dxx = s[0] - s[4], dyy = s[4] - s[8], dzz = s[8] - s[0];
  return sqrt(0.5 * (dxx * dxx + dyy * dyy + dzz * dzz) + 3 * (s[1] * s[1] + s[5] * s[5] + s[2] * s[2]));
}

/* Stress and strain (3×3) from ∇u_h at one point. */
static int stress_strain(const RunProblem *rp, const double *grad, double *sigma, double *strain) {
  const MicaSolid *s = rp->solid;
  const int dim = s->dim;
  double F[9];
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = (a == J) + grad[a * dim + J];
  return mica_model_stress_strain(s->opt.model, &s->opt.material, dim, F, sigma, strain);
}

static void exact_at(const RunProblem *rp, const double *x, double *u, double *grad) {
  const int dim = rp->disc->dim;
  double p[3] = {0, 0, 0};
  memcpy(p, x, sizeof(double) * (size_t)dim);
  for (int a = 0; a < dim; a++) {
    if (u) u[a] = mica_function_eval(rp->exact[a], p, 1.0);
    if (grad)
      for (int J = 0; J < dim; J++) grad[a * dim + J] = mica_function_eval(rp->exact_grad[a][J], p, 1.0);
  }
}

/* ---- fields at the particles ---------------------------------------------------------------------------- */

typedef struct {
  double *disp, *strain, *stress, *mises, *error;
} ParticleFields;

static void fields_free(ParticleFields *f) {
  free(f->disp), free(f->strain), free(f->stress), free(f->mises), free(f->error);
}

static int fields_compute(RunProblem *rp, const double *u, ParticleFields *f) {
  const int dim = rp->disc->dim;
  const long n = rp->disc->nparticles;
  double *uh = NULL, *grad = NULL;
  int ierr = MICA_SUCCESS;
  if (!rp->at_particles)
    MICA_CALL(mica_shape_cache_create(rp->mls, n, rp->disc->x, "output at particle", &rp->at_particles));
  MICA_CALL_CLEANUP(MICA_MALLOC(uh, n * dim));
  MICA_CALL_CLEANUP(MICA_MALLOC(grad, n * dim * dim));
  MICA_CALL_CLEANUP(MICA_CALLOC(f->disp, n * 3));
  MICA_CALL_CLEANUP(MICA_CALLOC(f->strain, n * 9));
  MICA_CALL_CLEANUP(MICA_CALLOC(f->stress, n * 9));
  MICA_CALL_CLEANUP(MICA_CALLOC(f->mises, n));
  if (rp->has_exact) MICA_CALL_CLEANUP(MICA_CALLOC(f->error, n * 3));
  mica_solid_interpolate(rp->solid, rp->at_particles, u, uh, grad);
  for (long i = 0; i < n; i++) {
    for (int a = 0; a < dim; a++) f->disp[i * 3 + a] = uh[i * dim + a];
    MICA_CALL_CLEANUP(stress_strain(rp, grad + i * dim * dim, f->stress + i * 9, f->strain + i * 9));
    f->mises[i] = von_mises(f->stress + i * 9);
    if (rp->has_exact) {
      double ue[3];
      exact_at(rp, rp->disc->x + i * dim, ue, NULL);
      for (int a = 0; a < dim; a++) f->error[i * 3 + a] = uh[i * dim + a] - ue[a];
    }
  }
cleanup:
  free(uh);
  free(grad);
  return ierr;
}

int run_output_step(void *ctx, int step, double t, const double *u) {
  RunOutput *out = ctx;
  if (!out->vtu || out->nsteps >= 1024) return MICA_SUCCESS;
  ParticleFields f = {0};
  char *path = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(fields_compute(out->rp, u, &f));
  snprintf(out->files[out->nsteps], sizeof out->files[0], "step_%04d.vtu", step);
  MICA_CALL_CLEANUP(mica_path_join(out->outdir, out->files[out->nsteps], &path));
  MicaVtkField fields[5] = {{"displacement", 3, f.disp}, {"strain", 9, f.strain}, {"stress", 9, f.stress},
                            {"von_mises", 1, f.mises}, {"error", 3, f.error}};
  MICA_CALL_CLEANUP(mica_vtu_write(path, out->rp->disc->dim, out->rp->disc->nparticles, out->rp->disc->x,
                                   out->rp->has_exact ? 5 : 4, fields));
  out->times[out->nsteps++] = t;
cleanup:
  free(path);
  fields_free(&f);
  return ierr;
}

int run_output_finish(RunOutput *out) {
  if (!out->vtu || out->nsteps == 0) return MICA_SUCCESS;
  const char *files[1024];
  for (int i = 0; i < out->nsteps; i++) files[i] = out->files[i];
  char *path = NULL;
  MICA_CALL(mica_path_join(out->outdir, "solution.pvd", &path));
  int ierr = mica_pvd_write(path, out->nsteps, out->times, files);
  free(path);
  return ierr;
}

/* ---- error norms ----------------------------------------------------------------------------------------- */

/* e:A0:e with A0 the model's tangent at the reference configuration (the elasticity tensor). */
static double energy_product(int dim, const double *A0, const double *e) {
  double sum = 0;
  const int d2 = dim * dim;
  for (int i = 0; i < d2; i++)
    for (int j = 0; j < d2; j++) sum += e[i] * A0[i * d2 + j] * e[j];
  return sum;
}

int run_error_norms(RunProblem *rp, const double *u, MicaJson *summary) {
  if (!rp->has_exact) return MICA_SUCCESS;
  const MicaSolid *s = rp->solid;
  const int dim = s->dim, d2 = dim * dim;
  const MicaShapeCache *c = s->volume;
  double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, F0[9], A0[81], P0[9], W0;
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F0[a * dim + J] = identity[a * 3 + J];
  MICA_CALL(s->opt.model->eval(&s->opt.material, dim, F0, &W0, P0, A0));
  double *uh = NULL, *grad = NULL;
  MICA_CALL(MICA_MALLOC(uh, c->npoints * dim));
  int ierr = MICA_MALLOC(grad, c->npoints * d2);
  if (ierr) {
    free(uh);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  mica_solid_interpolate(s, c, u, uh, grad);
  double l2[2] = {0, 0}, h1[2] = {0, 0}, en[2] = {0, 0};
  for (long p = 0; p < c->npoints; p++) {
    double ue[3], ge[9], eu[9];
    exact_at(rp, rp->disc->qx + p * dim, ue, ge);
    const double w = rp->disc->qw[p];
    for (int a = 0; a < dim; a++) {
      l2[0] += w * (uh[p * dim + a] - ue[a]) * (uh[p * dim + a] - ue[a]);
      l2[1] += w * ue[a] * ue[a];
    }
    for (int i = 0; i < d2; i++) {
      eu[i] = grad[p * d2 + i] - ge[i];
      h1[0] += w * eu[i] * eu[i];
      h1[1] += w * ge[i] * ge[i];
    }
    en[0] += w * energy_product(dim, A0, eu);
    en[1] += w * energy_product(dim, A0, ge);
  }
  free(uh);
  free(grad);
  const double el2 = sqrt(l2[0] / fmax(l2[1], 1e-300)), eh1 = sqrt(h1[0] / fmax(h1[1], 1e-300)),
               een = sqrt(en[0] / fmax(en[1], 1e-300));
  MICA_CALL(mica_json_number(summary, "error_l2", el2));
  MICA_CALL(mica_json_number(summary, "error_h1", eh1));
  MICA_CALL(mica_json_number(summary, "error_energy", een));
  printf("relative errors: L2 %.3e, H1 seminorm %.3e, energy %.3e\n", el2, eh1, een);
  return MICA_SUCCESS;
}

/* ---- probes ------------------------------------------------------------------------------------------------ */

/* The value of a named field ("ux", "sxy", "mises", ...) from u_h, the strain and the stress at a point. */
static double probe_field(const char *field, const double *uh, const double *strain, const double *sigma) {
  static const struct { const char *suffix; int i, j; } components[] = {
      {"xx", 0, 0}, {"yy", 1, 1}, {"zz", 2, 2}, {"xy", 0, 1}, {"yz", 1, 2}, {"xz", 0, 2}};
  if (field[0] == 'u') return uh[field[1] - 'x'];
  if (!strcmp(field, "mises")) return von_mises(sigma);
  const double *tensor = field[0] == 'e' ? strain : sigma;
  for (size_t k = 0; k < sizeof components / sizeof *components; k++)
    if (!strcmp(field + 1, components[k].suffix)) return tensor[components[k].i * 3 + components[k].j];
  return NAN; /* unreachable: the schema admits only the names above */
}

static int probe_one(RunProblem *rp, int i, const double *u, MlsShape *sh, MicaJson *summary) {
  const MicaDeck *deck = rp->deck;
  const int dim = rp->disc->dim;
  char path[96], where[256];
  const char *name, *field;
  double point[3] = {0, 0, 0}, scale;
  int n;
  snprintf(path, sizeof path, "output.probes.[%d].name", i);
  MICA_CALL(mica_deck_string(deck, path, &name));
  snprintf(path, sizeof path, "output.probes.[%d].field", i);
  MICA_CALL(mica_deck_string(deck, path, &field));
  snprintf(path, sizeof path, "output.probes.[%d].scale", i);
  MICA_CALL(mica_deck_float(deck, path, &scale));
  snprintf(path, sizeof path, "output.probes.[%d].point", i);
  MICA_CALL(mica_deck_floats(deck, path, point, 3, &n));
  mica_deck_where(deck, path, where, sizeof where);
  MICA_CHECK(n == dim, MICA_ERR_INPUT, "%s: probe '%s' needs a point with %d coordinates", where, name, dim);
  MICA_CHECK(!(field[0] == 'u' && field[1] - 'x' >= dim), MICA_ERR_INPUT, "%s: probe '%s' asks for %s in a %d-D problem",
             where, name, field, dim);
  int ierr = mls_eval(rp->mls, point, MLS_GRADIENT, sh);
  if (ierr) {
    mica_error_prefix("%s: probe '%s'", where, name);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr == MICA_ERR_NUMERIC ? MICA_ERR_INPUT : ierr);
  }
  double uh[3] = {0, 0, 0}, grad[9] = {0}, sigma[9], strain[9];
  for (long k = 0; k < sh->n; k++)
    for (int a = 0; a < dim; a++) {
      const double uk = u[sh->index[k] * dim + a];
      uh[a] += sh->N[k] * uk;
      for (int J = 0; J < dim; J++) grad[a * dim + J] += sh->dN[J * sh->n + k] * uk;
    }
  MICA_CALL(stress_strain(rp, grad, sigma, strain));
  const double value = scale * probe_field(field, uh, strain, sigma);
  MICA_CALL(mica_json_number(summary, name, value));
  printf("probe %s = %.10g\n", name, value);
  return MICA_SUCCESS;
}

int run_probes(RunProblem *rp, const double *u, MicaJson *summary) {
  const int count = mica_deck_list_length(rp->deck, "output.probes");
  if (count == 0) return MICA_SUCCESS;
  MlsShape *sh = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(mls_shape_create(rp->mls, &sh));
  for (int i = 0; i < count && !ierr; i++) ierr = probe_one(rp, i, u, sh, summary);
  mls_shape_destroy(&sh);
  return ierr;
}
