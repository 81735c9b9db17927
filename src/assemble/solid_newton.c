/* The solid as a nonlinear problem for Newton (mica/newton.h): what Newton must not know about a solid — how
 * it assembles, whether it is affine, which linear solver suits its tangent, how a run on several ranks solves,
 * and what a singular first tangent means for a deck — is given here through the problem's callbacks. */
#include <stdio.h>

#include "mica/parallel.h"
#include "mica/solid.h"

static int solid_residual(void *ctx, double t, const double *u, double *R, MicaSparse *K) {
  return mica_solid_assemble(ctx, t, u, R, K);
}

/* A parallel run solves through the distributed solver, with ops on rank 0 or in the subdomains. */
static int solid_linear_create(void *ctx, const MicaLinearSolverOps *ops, MicaLinearSolver **solver) {
  MicaSolid *s = ctx;
  if (s->opt.parallel) return mica_parallel_linear_create(s->opt.parallel, ops, solver);
  return mica_linear_solver_create(ops, solver);
}

/* A first tangent (at the reference state, before any load has deformed the body) that CHOLMOD finds not positive
 * definite or UMFPACK singular is the deck's doing: some motion costs no energy there and nothing holds it. The
 * rigid motions of the whole body were checked before assembly (mica_dirichlet_check_rigid), so it is part of the
 * body, spurious zero-energy modes of too low a quadrature, or a Nitsche stabilization too small to keep the
 * tangent definite: a deck error (exit 2), not a numerical failure. */
static int first_tangent_singular(void *ctx) {
  (void)ctx;
  char cause[512];
  snprintf(cause, sizeof cause, "%s", mica_error_message());
  MICA_ERROR(MICA_ERR_INPUT, "the body can move freely or part of it can: the first tangent, at the undeformed "
             "state, is singular or indefinite (%s); add Dirichlet conditions that hold every part of the body, "
             "raise quadrature.order if the quadrature leaves zero-energy modes, or raise bc.alpha with Nitsche",
             cause);
}

/* parallel.data = "distributed": R, u and Δu hold the rank's particles, owned ones first; the norm is over every
 * rank's owned entries. */
static int solid_owned_norm(void *ctx, const double *v, double *norm) {
  const MicaSolid *s = ctx;
  return mica_owned_norm(s->opt.parallel, v, s->ncomp, norm);
}

void mica_solid_nonlinear_problem(MicaSolid *s, MicaNonlinearProblem *problem) {
  /* CHOLMOD refuses an indefinite tangent (it may become one under load): UMFPACK takes over then. VCI's
   * tangent with an SPD boundary method: CHOLMOD on its symmetric part and refinement (cholmod-sym), UMFPACK if
   * that part is not positive definite. */
  const int spd = mica_solid_symmetric_definite(s), near = mica_solid_nearly_symmetric(s);
  *problem = (MicaNonlinearProblem){
      .n = s->ndof,
      .ctx = s,
      .residual = solid_residual,
      .K = s->K,
      .affine = mica_solid_linear(s),
      .linear_create = solid_linear_create,
      .linear_preferred = spd ? &mica_linear_cholmod : near ? &mica_linear_cholmod_sym : &mica_linear_umfpack,
      .linear_fallback = spd || near ? &mica_linear_umfpack : NULL,
      .fallback_note = near ? "the symmetric part of the tangent is not positive definite"
                            : "the tangent is not positive definite",
      .first_factor_failed = first_tangent_singular,
      .norm = s->opt.parallel && s->opt.parallel->owned ? solid_owned_norm : NULL,
  };
}

int mica_newton_solve(MicaSolid *s, const MicaNewtonOptions *opt, double *u,
                      int (*on_step)(void *ctx, int step, double t, const double *u), void *ctx,
                      MicaNewtonStats *stats) {
  MicaNonlinearProblem problem;
  mica_solid_nonlinear_problem(s, &problem);
  return mica_nonlinear_solve(&problem, opt, u, on_step, ctx, stats);
}
