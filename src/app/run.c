/* `mica run`: solve a solid-mechanics deck (the pipeline of docs/architecture.md: deck → discretization → MLS →
 * cache → assembly → Newton → output). Here: the solid built on the geometry (run_geometry.c) and the
 * conditions (run_conditions.c), what consecutive runs reuse, and the solve; `mica check` (check.c) shares
 * everything before the solve (run_counts.c). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/timer.h"
#include "run.h"
#include "study_common.h"

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

/* quadrature.vci as resolved (run_vci.c); an explicit true needs a first-order model, a plane or 3-D solid and
 * boundary sets that cover the whole boundary once ("auto" turns off where these fail, and says why). */
static int read_vci(const MicaDeck *deck, RunProblem *rp, MicaSolidOptions *opt) {
  const MicaDiscretization *disc = rp->disc;
  RunVciFacts facts = {.fe = rp->fe != NULL, .model_order = opt->field.ops->order,
                       .axisymmetric = opt->axisymmetric, .symmetric_only = rp->symmetric_only,
                       .boundary_uncovered = disc->boundary_uncovered};
  MICA_CALL(run_vci_replicated_parallel(deck, &facts.parallel));
  MICA_CALL(run_vci_choose(deck, &facts, &rp->vci));
  opt->vci = rp->vci.on;
  MICA_CALL(run_vci_report(&rp->vci, opt));
  if (!opt->vci || rp->vci.automatic) return MICA_SUCCESS;
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

/* parallel.data = "distributed": from now on the run's discretization and MLS are this rank's (the
 * distribution's); the whole ones are freed unless a reuse keeps them for the next run. */
static int take_local_geometry(RunProblem *rp) {
  if (rp->owns_geometry) {
    mls_destroy(&rp->mls);
    mica_discretization_destroy(&rp->disc);
    rp->owns_geometry = 0;
  }
  rp->disc = rp->dist->local;
  rp->mls = rp->dist->mls;
  rp->approx = (MicaApprox){&mica_approx_mls, rp->dist->mls};
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
  MICA_CALL_CLEANUP(read_vci(deck, rp, &opt));
  MICA_CALL_CLEANUP(run_read_scni(deck, rp, &opt));
  MICA_CALL_CLEANUP(run_read_pressure(deck, rp, &opt));
  MICA_CALL_CLEANUP(check_nitsche_model(deck, &opt));
  const MicaDiscretization *disc = rp->disc;
  const char *data;
  MICA_CALL_CLEANUP(mica_deck_string(deck, "parallel.data", &data));
  const int distributed = !strcmp(data, "distributed");
  /* a serial run of a distributed deck is its one-block case: the same refusals, so a deck means the same anywhere */
  if (distributed && !mica_parallel_active()) MICA_CALL_CLEANUP(run_parallel_owned_check(deck, rp));
  if (mica_parallel_active()) { /* MPI: this rank's share of the quadrature points (run_parallel.c) */
    MICA_CALL_CLEANUP(run_check_serial_only(deck, rp, distributed));
    rp->owned_data = distributed;
    if (rp->owned_data) MICA_CALL_CLEANUP(run_parallel_owned_check(deck, rp));
    MICA_CALL_CLEANUP(run_parallel_distribute(deck, rp));
    opt.parallel = rp->dist;
    disc = rp->dist->local;
    if (rp->owned_data) MICA_CALL_CLEANUP(take_local_geometry(rp));
  }
  rp->peak_build = mica_parallel_peak_memory();
  const double start = mica_wtime(), cpu = mica_cputime();
  ierr = mica_study_mls_input(mica_solid_create_sharing(disc, &rp->approx, &opt, ndirichlet, dirichlet, ntraction,
                                                        traction, donor, &rp->solid));
  rp->time_cache_pattern = mica_wtime() - start;
  rp->cpu_cache_pattern = mica_cputime() - cpu;
  if (!ierr && rp->solid->vci_symmetric && !mica_parallel_rank())
    printf("VCI: symmetric (NSNI, linear basis: trial and test gradients corrected alike, docs/theory.md §NSNI): "
           "the tangent is symmetric\n");
  return ierr; /* the solid owns the conditions now, whether or not it was built */
cleanup:
  mica_solid_conditions_free(opt.body, ndirichlet, &dirichlet, ntraction, &traction);
  return ierr;
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
  int ierr = run_build_geometry(deck, rp);
  if (ierr) {
    free(key);
    return ierr;
  }
  reuse->key = key, reuse->disc = rp->disc, reuse->mls = rp->mls, reuse->fe = rp->fe, reuse->approx = rp->approx;
  rp->owns_geometry = 0;
  return MICA_SUCCESS;
}


static int build_problem(const MicaDeck *deck, RunProblem *rp, RunReuse *reuse, int symmetric_only) {
  memset(rp, 0, sizeof *rp);
  rp->deck = deck;
  rp->symmetric_only = symmetric_only;
  rp->reuse = reuse;
  MICA_CALL(run_guard_cost(deck, &rp->estimate));
  if (reuse) {
    char *key = NULL;
    MICA_CALL(reuse_key(deck, &key));
    MICA_CALL(take_or_build_geometry(deck, rp, reuse, key));
  } else {
    rp->owns_geometry = 1;
    MICA_CALL(run_build_geometry(deck, rp));
  }
  MICA_CALL(build_solid(deck, rp, reuse ? reuse->solid : NULL));
  MICA_CALL(run_read_exact(deck, rp, &rp->solid->opt.field));
  return MICA_SUCCESS;
}

int run_problem_build_reusing(const MicaDeck *deck, RunProblem *rp, RunReuse *reuse) {
  return build_problem(deck, rp, reuse, 0);
}

int run_problem_build(const MicaDeck *deck, RunProblem *rp) { return build_problem(deck, rp, NULL, 0); }

int run_problem_build_symmetric(const MicaDeck *deck, RunProblem *rp) { return build_problem(deck, rp, NULL, 1); }

/* With reuse, the solid and the output cache pass to it (a run that built no solid leaves the kept one). Under
 * MPI the solid lives on this run's distribution, which goes now: the next run builds its own caches. */
void run_problem_free(RunProblem *rp) {
  RunReuse *reuse = rp->reuse;
  if (reuse && rp->solid && !rp->dist) {
    mica_solid_destroy(&reuse->solid);
    reuse->solid = rp->solid, rp->solid = NULL;
  }
  /* (distributed data: the caches are on this rank's particles, not the kept discretization's) */
  if (reuse && !reuse->at_particles && !rp->owns_geometry && !rp->owned_data)
    reuse->at_particles = rp->at_particles, rp->at_particles = NULL;
  if (reuse && !reuse->at_mesh && !rp->owns_geometry && !rp->owned_data)
    reuse->at_mesh = rp->at_mesh, rp->at_mesh = NULL;
  mica_solid_destroy(&rp->solid);
  mica_distribution_destroy(&rp->dist);
  mica_mesh_source_close(&rp->mesh_source);
  run_mesh_file_remove(rp);
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


/* ---- the commands --------------------------------------------------------------------------------------- */

/* solver.linear: "auto" (NULL) lets Newton take the problem's preferred one-process solver (CHOLMOD, cholmod-sym,
 * UMFPACK); under MPI (rp->dist) the tangent is distributed over the ranks, so "auto" is petsc (with its default
 * method, MUMPS) and a one-process solver is a deck error. */
static int choose_linear(const char *linear, const char *where, const RunProblem *rp, const MicaLinearSolverOps **ops) {
  *ops = strcmp(linear, "auto") ? mica_linear_solver_find(linear) : NULL;
  if (!rp->dist) return MICA_SUCCESS;
  if (!*ops) *ops = &mica_linear_petsc;
  MICA_CHECK(mica_linear_solver_has(*ops, MICA_LINEAR_DISTRIBUTED), MICA_ERR_INPUT,
             "%s: solver.linear = \"%s\" solves in one process, but this run has %d ranks; use \"auto\" or "
             "\"petsc\" (solver.petsc = \"mumps\" factors the distributed tangent, \"asm-cholmod\" gives each rank's "
             "subdomain to CHOLMOD), or run without mpirun",
             where, linear, mica_parallel_size());
  return MICA_SUCCESS;
}

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
  char where[256];
  mica_deck_where(deck, "solver.linear", where, sizeof where);
  MICA_CALL(choose_linear(linear, where, rp, &opt->linear));
  const int spd_only = opt->linear && mica_linear_solver_has(opt->linear, MICA_LINEAR_SPD_ONLY);
  MICA_CHECK(!(spd_only && !mica_solid_symmetric_definite(s)), MICA_ERR_INPUT,
             "%s: CHOLMOD needs a symmetric positive definite tangent, which bc.method = \"%s\"%s does not give; "
             "use \"umfpack\" or \"auto\"", where, s->opt.bc_method->type.name,
             s->opt.vci ? " with quadrature.vci (unsymmetric: Petrov–Galerkin)" : "");
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
  if (st->linear.ordering) MICA_CALL(mica_json_string(summary, "factor_ordering", st->linear.ordering));
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
static int add_memory_per_dof(const RunTotals *c, const MicaNewtonStats *st, MicaJson *summary) {
  const double dofs = (double)c->dofs;
  MICA_CALL(mica_json_number(summary, "memory_cache_bytes_per_dof", (double)c->cache_bytes / dofs));
  const double matrix_bytes = (double)(c->nnz * 16 + (c->dofs + 1) * 8);
  MICA_CALL(mica_json_number(summary, "memory_matrix_bytes_per_dof", matrix_bytes / dofs));
  MICA_CALL(mica_json_number(summary, "memory_factor_bytes_per_dof", 8.0 * (double)st->linear.nnz_factor / dofs));
  return MICA_SUCCESS;
}

/* What every solve reports, converged or not: Newton's and the linear solvers' statistics and the memory
 * (collective under MPI). */
static int add_solve_stats(const RunProblem *rp, const RunTotals *totals, const MicaNewtonStats *stats,
                           double time_newton, MicaJson *summary) {
  MICA_CALL(mica_json_number(summary, "time_newton", time_newton));
  MICA_CALL(add_newton_stats(stats, summary));
  MICA_CALL(add_memory_per_dof(totals, stats, summary));
  MICA_CALL(run_krylov_summary(rp, stats, summary));
  MICA_CALL(run_parallel_ranks(rp, stats, summary));
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
  MICA_CALL(run_outputs_finish(out, 1, NULL, summary));
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
  RunTotals totals;
  MICA_CALL_CLEANUP(run_problem_prepare(deck, &rp, reuse, outdir, &out, &totals, summary));
  MICA_CALL_CLEANUP(read_newton(deck, &rp, &nopt));
  MICA_CALL_CLEANUP(MICA_CALLOC(u, rp.solid->ndof));
  const double start = mica_wtime();
  ierr = mica_newton_solve(rp.solid, &nopt, u, run_output_step, &out, &stats);
  if (ierr && stats.failed) ierr = write_reached(&rp, &out, &totals, &nopt, &stats, mica_wtime() - start, summary);
  MICA_CALL_CLEANUP(ierr);
  MICA_CALL_CLEANUP(add_solve_stats(&rp, &totals, &stats, mica_wtime() - start, summary));
  const double output_start = mica_wtime();
  MICA_CALL_CLEANUP(run_error_norms(&rp, u, summary));
  MICA_CALL_CLEANUP(run_outputs_finish(&out, 0, u, summary));
  /* fields per step (inside time_newton), error norms, the PVD and probes */
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
