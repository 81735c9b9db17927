/* Newton–Raphson with load steps on a problem given by callbacks (after PETSc's SNES): the solver knows
 * residuals, tangents and linear solvers, never what the problem is (a solid: mica_solid_nonlinear_problem in
 * mica/solid.h). The linear solver is created through the problem's hook, so a distributed backend plugs in
 * there without Newton knowing it.
 */
#ifndef MICA_NEWTON_H
#define MICA_NEWTON_H

#include "mica/sparse.h"

typedef struct MicaNewtonOptions {
  int steps;           /* load steps (load factor t = s / steps) */
  int max_iterations;  /* per step */
  double rtol, atol;   /* converged when |R| ≤ max(rtol |R_0|, atol), or |Δu| ≤ rtol |u|, after ≥ 1 iteration */
  int line_search;     /* backtracking on |R| */
  int max_cuts;        /* times a failing step may be halved */
  const MicaLinearSolverOps *linear; /* NULL: auto — the problem's preferred solver, and its fallback if the
                                        preferred one's factorization fails numerically */
  int verbose;         /* one monitor line per iteration */
  MicaKrylovOptions krylov; /* the iterative linear solvers' settings (petsc, cholmod-sym) */
} MicaNewtonOptions;

typedef struct MicaNewtonStats {
  int steps_done, cuts, iterations_total;
  int last_iterations;
  double residual_history[64]; /* |R| per iteration of the last step */
  double increment_history[64]; /* |Δu| per iteration of the last step (quadratic convergence evidence) */
  int nhistory, nincrements;
  double time_assemble, time_factor, time_solve;
  int assemblies, tangent_assemblies; /* assembly passes (all; of which with the tangent) */
  int residual_updates; /* residuals of an affine problem taken as R + K du instead of an assembly */
  double cpu_assemble; /* thread CPU time of the assemblies (mica_cputime) */
  const char *linear_name;
  MicaLinearSolverStats linear;
  double load_factor;        /* the last converged load factor: 1 when solved, 0 before any step converged */
  double load_factor_failed; /* the load factor of the step that failed for good (0: none did) */
  int failed;                /* 1: a step failed after its cut-backs; u is the last converged state */
} MicaNewtonStats;

/* R(u; t) = 0 for n unknowns, t the load factor in (0, 1]. */
typedef struct MicaNonlinearProblem {
  long n;
  void *ctx; /* passed to every callback */
  /* R(u; t) into R, and, when K != NULL, the tangent dR/du into K (zeroed first) in the same pass. */
  int (*residual)(void *ctx, double t, const double *u, double *R, MicaSparse *K);
  MicaSparse *K; /* the tangent the residual assembles into; its pattern is fixed, so analyses are reused */
  /* 1: R(u + Δu) = R(u) + K Δu exactly, so Newton takes the residual after a solve from K, and a failed
   * step is not halved (the tangent does not depend on the load) */
  int affine;
  /* Creates the linear solver with ops (NULL: mica_linear_solver_create), e.g. a distributed one. */
  int (*linear_create)(void *ctx, const MicaLinearSolverOps *ops, MicaLinearSolver **solver);
  /* Auto mode (MicaNewtonOptions.linear NULL): the preferred solver, and the one that replaces it for the rest
   * of the run when its factorization or a solve fails numerically (NULL: none); the note says why (a solve's
   * failure: its error message) and that the fallback takes over. */
  const MicaLinearSolverOps *linear_preferred, *linear_fallback;
  const char *fallback_note;
  /* Called when the first factorization of a direct solver fails numerically (no load step has changed the
   * tangent yet): returns the error to report instead (NULL: the solver's own error). */
  int (*first_factor_failed)(void *ctx);
  /* The norm of R, u and Δu (NULL: the 2-norm of the n entries). A problem whose vectors are split over ranks
   * (each holding its owned entries and ghost copies of others') gives the 2-norm over every rank's owned
   * entries, the same on every rank, so that all ranks take the same decisions (after PETSc's VecNorm). */
  int (*norm)(void *ctx, const double *v, double *norm);
} MicaNonlinearProblem;

/* Solves from u (initial guess, updated in place) to load factor 1; on_step (may be NULL) is called after
 * every converged step with the load factor. A step that fails numerically even after its cut-backs ends
 * the solve with MICA_ERR_NUMERIC, stats->failed = 1, u back at the last converged state (stats->load_factor)
 * and a message that says how far the solve got; any other error leaves stats->failed = 0. */
int mica_nonlinear_solve(const MicaNonlinearProblem *problem, const MicaNewtonOptions *opt, double *u,
                         int (*on_step)(void *ctx, int step, double t, const double *u), void *ctx,
                         MicaNewtonStats *stats);

#endif
