/* `mica run`: the iterative linear solvers' settings (petsc, cholmod-sym) and their figures, and the peak memory
 * of the process, in the summary. */
#include <stdio.h>
#include <string.h>

#include "run.h"

/* A distributed solver's (petsc) near-null space: the rigid motions of the model's unknowns at the particles
 * (src/bc/rigid.c), for GAMG; and the particles' coordinates, for geometric multigrid. Finite elements keep
 * PETSc's default (neither). */
static int read_near_null(RunProblem *rp, MicaKrylovOptions *k) {
  const MicaSolid *s = rp->solid;
  if (rp->fe || s->nparticles != rp->disc->nparticles) return MICA_SUCCESS;
  const char *names[MICA_MAX_COMP + 1];
  const int ncomp = run_model_names(rp, &s->opt.field, 0, names);
  free(rp->near_null);
  rp->near_null = NULL;
  MICA_CALL(mica_rigid_motions(rp->disc->x, rp->disc->nparticles, rp->disc->dim, rp->axisymmetric, ncomp, names,
                               s->ndof, &k->near_null_count, &rp->near_null));
  k->near_null = rp->near_null;
  k->coords = rp->disc->x, k->coord_dim = rp->disc->dim, k->coord_nodes = rp->disc->nparticles;
  return MICA_SUCCESS;
}

int run_read_krylov(const MicaDeck *deck, RunProblem *rp, MicaNewtonOptions *opt) {
  long iterations;
  const MicaSolid *s = rp->solid;
  MICA_CALL(mica_deck_float(deck, "solver.linear_rtol", &opt->krylov.rtol));
  MICA_CALL(mica_deck_int(deck, "solver.linear_max_iterations", &iterations));
  opt->krylov.max_iterations = (int)iterations;
  /* what a solver that chooses its method by the matrix (petsc) must know of it */
  opt->krylov.spd = mica_solid_symmetric_definite(s);
  opt->krylov.saddle = s->nmultiplier_nodes > 0;
  /* the chosen solver's own settings (petsc: solver.petsc); "auto" (NULL) chooses a direct solver */
  const MicaType *type = opt->linear ? &opt->linear->type : NULL;
  if (type && type->from_settings) {
    MicaSettings settings;
    mica_deck_settings(deck, &settings);
    MICA_CALL(type->from_settings(type, &settings, "solver", &opt->krylov));
  }
  if (opt->linear && mica_linear_solver_has(opt->linear, MICA_LINEAR_DISTRIBUTED))
    MICA_CALL(read_near_null(rp, &opt->krylov));
  opt->krylov.verbose = opt->verbose;
  return MICA_SUCCESS;
}

/* The iterative solvers' iterations (petsc's Krylov methods, cholmod-sym's refinement). */
int run_krylov_summary(const RunProblem *rp, const MicaNewtonStats *st, MicaJson *summary) {
  const MicaLinearSolverOps *ops = mica_linear_solver_find(st->linear_name);
  if (!ops || !(mica_linear_solver_has(ops, MICA_LINEAR_DISTRIBUTED) || mica_linear_solver_has(ops, MICA_LINEAR_REFINES)))
    return MICA_SUCCESS;
  const MicaLinearSolverStats *ls = &st->linear;
  if (mica_linear_solver_has(ops, MICA_LINEAR_DISTRIBUTED)) {
    const char *method;
    MICA_CALL(mica_deck_string(rp->deck, "solver.petsc", &method));
    MICA_CALL(mica_json_string(summary, "petsc_method", method));
  }
  MICA_CALL(mica_json_int(summary, "krylov_solves", ls->solves));
  MICA_CALL(mica_json_int(summary, "krylov_iterations", ls->krylov_iterations));
  MICA_CALL(mica_json_int(summary, "krylov_iterations_max", ls->krylov_iterations_max));
  MICA_CALL(mica_json_number(summary, "krylov_last_residual", ls->krylov_residual));
  MICA_CALL(mica_json_number(summary, "cpu_krylov", ls->krylov_cpu));
  if (rp->dist && mica_linear_solver_has(ops, MICA_LINEAR_DISTRIBUTED)) { /* collective: every rank is here */
    MICA_CALL(mica_json_int(summary, "halo_dofs_max", mica_parallel_max_long(ls->halo_dofs)));
    MICA_CALL(mica_json_int(summary, "halo_dofs_sum", mica_parallel_sum_long(ls->halo_dofs)));
  }
  char levels[48] = "";
  if (ls->multigrid_levels) { /* petsc's gmg */
    MICA_CALL(mica_json_int(summary, "multigrid_levels", ls->multigrid_levels));
    snprintf(levels, sizeof levels, ", %d multigrid levels", ls->multigrid_levels);
  }
  printf("%s: %ld solves, %ld iterations (at most %ld), last |b - Ax| / |b| %.3e%s\n", st->linear_name, ls->solves,
         ls->krylov_iterations, ls->krylov_iterations_max, ls->krylov_residual, levels);
  return MICA_SUCCESS;
}

/* getrusage's peak resident memory of this process (rank 0 under MPI; run_parallel_memory has the ranks'). */
int run_peak_memory(MicaJson *summary) {
  const long peak = mica_parallel_peak_memory();
  MICA_CALL(mica_json_int(summary, "peak_memory", peak));
  printf("peak memory %.1f MB\n", (double)peak / 1e6);
  return MICA_SUCCESS;
}
