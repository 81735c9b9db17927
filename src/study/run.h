/* Internal interface of `mica run` and `mica check` (src/study/run*.c). */
#ifndef MICA_RUN_H
#define MICA_RUN_H

#include "mica/command.h"
#include "mica/solid.h"

extern const MicaDeckKey mica_run_schema[];

/* Everything a run builds from its deck, and the times of the phases that built it. */
typedef struct RunProblem {
  const MicaDeck *deck;
  MicaDiscretization *disc;
  MlsApprox *mls;
  MicaSolid *solid;
  MicaFunction *exact[MICA_MAX_COMP];      /* exact unknowns (displacements, micro-rotations), or NULL */
  MicaFunction *exact_grad[MICA_MAX_COMP][3]; /* their gradients ∂v_c/∂X_J */
  int has_exact, ncomp;
  int axisymmetric;             /* geometry.axisymmetric: a 2-D (r, z) section, 3-D model, cylindrical components */
  MicaShapeCache *at_particles; /* shape functions at the particles, for output (built on first use) */
  double time_discretize, time_mls, time_cache_pattern;
} RunProblem;

/* The dimension of the model's kinematics (3 for an axisymmetric section) and the deck's name of unknown c
 * ("ux", "phiz"; axisymmetric "ur", "utheta", ...). */
int run_model_dim(const RunProblem *rp);
const char *run_unknown_name(const RunProblem *rp, int c);

/* The model and its constants from material.* (run_material.c). */
int run_read_material(const MicaDeck *deck, int dim, MicaSolidOptions *opt);

/* Builds discretization, MLS, model, conditions and the solid from the deck. */
int run_problem_build(const MicaDeck *deck, RunProblem *rp);
void run_problem_free(RunProblem *rp);

/* Output: per-step VTU files and the PVD collection, error norms, probes, summary members. */
typedef struct RunOutput {
  RunProblem *rp;
  const char *outdir;
  int vtu;
  int nsteps;
  double times[1024];
  char files[1024][32];
} RunOutput;

int run_output_step(void *ctx, int step, double t, const double *u);
int run_output_finish(RunOutput *out);
int run_error_norms(RunProblem *rp, const double *u, MicaJson *summary);
/* The relative errors run_error_norms reports (L2 of the values, H1 seminorm, energy), without writing them. */
int run_error_values(RunProblem *rp, const double *u, double *rel_l2, double *rel_h1, double *rel_energy);
int run_probes(RunProblem *rp, const double *u, MicaJson *summary);

#endif
