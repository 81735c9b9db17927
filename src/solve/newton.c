/* Newton–Raphson with load steps, automatic step cut-back and optional backtracking line search
 * (docs/theory.md §solids). One monitor line per iteration: step, load factor, iteration, |R|, |Δu|, and the
 * convergence rate log(|R_i|/|R_i−1|) / log(|R_i−1|/|R_i−2|), which tends to 2 when Newton is quadratic.
 * The tangent's pattern is fixed, so the linear solver's symbolic analysis is done once and reused.
 *
 * No assembly pass repeats another (docs/performance.md §profiles):
 *   - the first iteration of a step assembles the residual and the tangent in one pass (the tangent is
 *     needed unless the step starts converged, which only |R| ≤ atol allows);
 *   - a line search that accepts a step has assembled R(u + α Δu): the next iteration uses it;
 *   - for an affine problem (MicaNonlinearProblem.affine: R(u) = K u − f exactly) the residual after a solve
 *     is R + K Δu, one product with the assembled tangent instead of an assembly: the convergence check and
 *     the log then show the true residual of the new u up to round-off, marked "(R + K du)".
 * The problem comes through callbacks (mica/newton.h): this file knows no solid and no MPI. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/newton.h"
#include "mica/timer.h"

typedef struct {
  const MicaNonlinearProblem *p;
  const MicaNewtonOptions *opt;
  MicaNewtonStats *stats;
  MicaLinearSolver *linear;
  const MicaLinearSolverOps *fallback; /* auto mode: replaces the solver whose factorization failed */
  int factored;    /* a tangent has been factored: a singular one is no longer the reference state's */
  double *R, *du, *trial, *saved; /* trial: line search; saved: u at the start of a step, for cut-back */
} Newton;

static double norm2(long n, const double *v) {
  double s = 0;
  for (long i = 0; i < n; i++) s += v[i] * v[i];
  return sqrt(s);
}

/* The problem's norm, or the 2-norm (serial runs: bit-identical to before the hook). */
static int vec_norm(const Newton *nw, const double *v, double *out) {
  if (nw->p->norm) return nw->p->norm(nw->p->ctx, v, out);
  *out = norm2(nw->p->n, v);
  return MICA_SUCCESS;
}

static int assemble(Newton *nw, double t, const double *u, int with_tangent) {
  const double start = mica_wtime(), cpu = mica_cputime();
  int ierr = nw->p->residual(nw->p->ctx, t, u, nw->R, with_tangent ? nw->p->K : NULL);
  nw->stats->time_assemble += mica_wtime() - start;
  nw->stats->assemblies++;
  if (with_tangent) nw->stats->tangent_assemblies++;
  nw->stats->cpu_assemble += mica_cputime() - cpu;
  return ierr;
}

/* Affine problem: R(u + Δu) = R(u) + K Δu. solve_linear left −R(u) in R; the product goes through trial. */
static void linear_residual_update(Newton *nw) {
  const long n = nw->p->n;
  mica_sparse_matvec(nw->p->K, nw->du, nw->trial);
  for (long i = 0; i < n; i++) nw->R[i] = nw->trial[i] - nw->R[i];
  nw->stats->residual_updates++;
}

/* Through the problem's hook when it has one (a distributed solver, say). */
static int create_linear(Newton *nw, const MicaLinearSolverOps *ops) {
  if (nw->p->linear_create) MICA_CALL(nw->p->linear_create(nw->p->ctx, ops, &nw->linear));
  else MICA_CALL(mica_linear_solver_create(ops, &nw->linear));
  MicaKrylovOptions krylov = nw->opt->krylov;
  /* K's values are read by nothing between a factorization and the next assembly, unless an affine problem's
   * residual update (R + K Δu) or a fallback solver refactoring them comes: a solver that copied them may give
   * their memory back */
  krylov.discardable = !nw->p->affine && !nw->fallback ? nw->p->K : NULL;
  MICA_CALL(mica_linear_solver_set_krylov(nw->linear, &krylov));
  nw->stats->linear_name = ops->type.name;
  return MICA_SUCCESS;
}

/* The options' solver, or in auto mode the problem's preferred one with its fallback. */
static int choose_linear_solver(Newton *nw) {
  const MicaLinearSolverOps *ops = nw->opt->linear;
  nw->fallback = NULL;
  if (!ops) {
    ops = nw->p->linear_preferred;
    nw->fallback = nw->p->linear_fallback;
  }
  if (!ops) MICA_ERROR(MICA_ERR_ARGUMENT, "the nonlinear problem names no linear solver");
  return create_linear(nw, ops);
}

/* Auto mode: the rest of the run on the problem's fallback, with a note in the log saying why. */
static int move_to_fallback(Newton *nw, const char *why) {
  if (nw->opt->verbose) printf("  note: %s; switching to %s\n", why, nw->fallback->type.name);
  mica_error_clear();
  mica_linear_solver_destroy(&nw->linear);
  const MicaLinearSolverOps *fallback = nw->fallback;
  nw->fallback = NULL; /* the last solver of the run */
  return create_linear(nw, fallback);
}

/* Factor and solve K du = −R. In auto mode a factorization that fails numerically (CHOLMOD refuses an
 * indefinite tangent) moves the solve to the problem's fallback for the rest of the run, with a note in the log;
 * so does a solve that fails numerically (cholmod-sym's refinement stops contracting when the tangent's skew part
 * is large against its symmetric part: NSNI's Petrov–Galerkin tangent with a quadratic basis on jittered
 * particles, |b − A x| / |b| = 8.6 on the 6³ cube). A direct solver's failure at the first factorization is the
 * problem's to explain (first_factor_failed). */
static int solve_linear(Newton *nw) {
  const long n = nw->p->n;
  double start = mica_wtime();
  int ierr = mica_linear_solver_factor(nw->linear, nw->p->K);
  if (ierr == MICA_ERR_NUMERIC && nw->fallback) {
    MICA_CALL(move_to_fallback(nw, nw->p->fallback_note ? nw->p->fallback_note : "the factorization failed"));
    ierr = mica_linear_solver_factor(nw->linear, nw->p->K);
  }
  nw->stats->time_factor += mica_wtime() - start;
  if (ierr == MICA_ERR_NUMERIC && !nw->factored && nw->p->first_factor_failed)
    return nw->p->first_factor_failed(nw->p->ctx);
  MICA_CALL(ierr);
  nw->factored = 1;
  for (long i = 0; i < n; i++) nw->R[i] = -nw->R[i];
  start = mica_wtime();
  ierr = mica_linear_solver_solve(nw->linear, nw->R, nw->du);
  nw->stats->time_solve += mica_wtime() - start;
  if (ierr == MICA_ERR_NUMERIC && nw->fallback) { /* the fallback's factorization, then its solve */
    char why[512];
    snprintf(why, sizeof why, "%s", mica_error_message());
    MICA_CALL(move_to_fallback(nw, why));
    start = mica_wtime();
    MICA_CALL(mica_linear_solver_factor(nw->linear, nw->p->K));
    nw->stats->time_factor += mica_wtime() - start;
    start = mica_wtime();
    ierr = mica_linear_solver_solve(nw->linear, nw->R, nw->du);
    nw->stats->time_solve += mica_wtime() - start;
  }
  MICA_CALL(ierr);
  return MICA_SUCCESS;
}

/* Backtracking on |R|: halve the step until the residual decreases (at most 6 halvings). *have_residual = 1
 * when a step was accepted: R then holds R(u + α Δu), which the next iteration need not assemble again. */
static int line_search(Newton *nw, double t, double *u, double rnorm, double *alpha_out, int *have_residual) {
  const long n = nw->p->n;
  double alpha = 1.0;
  *have_residual = 0;
  for (int k = 0; k < 7; k++, alpha *= 0.5) {
    for (long i = 0; i < n; i++) nw->trial[i] = u[i] + alpha * nw->du[i];
    int ierr = assemble(nw, t, nw->trial, 0);
    double trial_norm = 0;
    if (ierr == MICA_SUCCESS) MICA_CALL(vec_norm(nw, nw->R, &trial_norm));
    if (ierr == MICA_SUCCESS && trial_norm < (1 - 1e-4 * alpha) * rnorm) {
      *have_residual = 1;
      break;
    }
    if (ierr && ierr != MICA_ERR_NUMERIC) return ierr;
    mica_error_clear();
  }
  *alpha_out = alpha;
  return MICA_SUCCESS;
}

static void monitor(const Newton *nw, int step, double t, int it, double rnorm, double dunorm, int updated) {
  if (!nw->opt->verbose) return;
  const double *h = nw->stats->increment_history;
  const int nh = nw->stats->nincrements;
  char rate[32] = "-";
  if (nh >= 3 && h[nh - 1] > 0 && h[nh - 2] > 0 && h[nh - 3] > 0 && h[nh - 2] != h[nh - 3])
    snprintf(rate, sizeof rate, "%.2f", log(h[nh - 1] / h[nh - 2]) / log(h[nh - 2] / h[nh - 3]));
  char increment[32] = "-"; /* no increment before the first solve */
  if (it > 0) snprintf(increment, sizeof increment, "%.3e", dunorm);
  printf("  step %d t %.4g  it %d  |R| %.3e  |du| %s  rate %s%s\n", step, t, it, rnorm, increment, rate,
         updated ? "  (R + K du)" : "");
  fflush(stdout);
}

/* Newton iterations at load factor t. Returns MICA_SUCCESS when converged, MICA_ERR_NUMERIC otherwise. */
static int newton_step(Newton *nw, int step, double t, double *u) {
  const long n = nw->p->n;
  double r0 = 0, dunorm = 0;
  int have_residual = 0, updated = 0; /* R already holds R(u): from the line search, or R + K Δu */
  const int linear = nw->p->affine;
  nw->stats->nhistory = nw->stats->nincrements = 0;
  for (int it = 0;; it++) {
    if (!have_residual) MICA_CALL(assemble(nw, t, u, it == 0));
    double rnorm, unorm;
    MICA_CALL(vec_norm(nw, nw->R, &rnorm));
    if (!isfinite(rnorm)) MICA_ERROR(MICA_ERR_NUMERIC, "the residual is not finite at load factor %g", t);
    if (it == 0) r0 = rnorm;
    if (nw->stats->nhistory < 64) nw->stats->residual_history[nw->stats->nhistory++] = rnorm;
    monitor(nw, step, t, it, rnorm, dunorm, updated);
    MICA_CALL(vec_norm(nw, u, &unorm));
    /* the increment test ends stiff linear problems whose residual stalls at round-off just above rtol |R₀| */
    const int converged = rnorm <= nw->opt->atol || (it > 0 && rnorm <= nw->opt->rtol * r0) ||
                          (it > 0 && dunorm <= nw->opt->rtol * (unorm > 0 ? unorm : 1.0));
    if (converged) {
      nw->stats->last_iterations = it;
      nw->stats->iterations_total += it;
      return MICA_SUCCESS;
    }
    if (it >= nw->opt->max_iterations)
      MICA_ERROR(MICA_ERR_NUMERIC, "Newton did not converge in %d iterations at load factor %g (|R| %.3e from %.3e)",
                 it, t, rnorm, r0);
    if (it > 0) MICA_CALL(assemble(nw, t, u, 1)); /* the first iteration assembled K with R */
    MICA_CALL(solve_linear(nw));
    double alpha = 1.0;
    have_residual = updated = 0;
    if (nw->opt->line_search) MICA_CALL(line_search(nw, t, u, rnorm, &alpha, &have_residual));
    if (linear && !have_residual && alpha == 1.0) {
      linear_residual_update(nw);
      have_residual = updated = 1;
    }
    for (long i = 0; i < n; i++) u[i] += alpha * nw->du[i];
    MICA_CALL(vec_norm(nw, nw->du, &dunorm));
    dunorm *= alpha;
    if (nw->stats->nincrements < 64) nw->stats->increment_history[nw->stats->nincrements++] = dunorm;
  }
}

/* The end of a solve whose step at load factor target failed for good: u goes back to the last converged
 * state, which the caller may still write, and the message says how far the solve got and why it stopped
 * cutting (the caller adds what to change). */
static int give_up(Newton *nw, double *u, double target, int may_cut) {
  MicaNewtonStats *st = nw->stats;
  char cause[1024], why[128], reached[128];
  snprintf(cause, sizeof cause, "%s", mica_error_message());
  memcpy(u, nw->saved, sizeof(double) * (size_t)nw->p->n);
  st->failed = 1;
  st->load_factor_failed = target;
  if (!may_cut)
    snprintf(why, sizeof why, "a linear problem's load step is not halved: its tangent does not depend on the load");
  else
    snprintf(why, sizeof why, "after %d cut-back%s (%s)", st->cuts, st->cuts == 1 ? "" : "s",
             st->cuts < nw->opt->max_cuts ? "the step cannot be halved again" : "the most allowed");
  if (st->steps_done)
    snprintf(reached, sizeof reached, "the last converged load factor is %.6g (load step %d)", st->load_factor,
             st->steps_done);
  else
    snprintf(reached, sizeof reached, "no load step converged (load factor 0 reached)");
  MICA_ERROR(MICA_ERR_NUMERIC, "%s; %s; %s", cause, why, reached);
}

/* Load factors are exact fractions k / den, den = steps · 2^cuts, so the last is 1 (a sum of increments 1/steps
 * ends at 0.9999999999999999, and the outputs would say so). k and den are integers held exactly in doubles while
 * den ≤ 2^53, so no cut goes beyond that (a step of 1e-16 of the load would not be a step anyway). */
static int run_steps(Newton *nw, double *u, int (*on_step)(void *, int, double, const double *), void *ctx) {
  const long n = nw->p->n;
  double k = 0, den = nw->opt->steps, t = 0;
  int step = 0;
  /* a linear problem's tangent does not depend on the load: a smaller step cannot cure a failed solve */
  const int may_cut = !nw->p->affine;
  while (k < den) {
    const double target = (k + 1) / den;
    memcpy(nw->saved, u, sizeof(double) * (size_t)n);
    int ierr = newton_step(nw, step + 1, target, u);
    if (ierr == MICA_ERR_NUMERIC && may_cut && nw->stats->cuts < nw->opt->max_cuts && den <= 0x1p52) {
      if (nw->opt->verbose) printf("  cut back: %s\n", mica_error_message());
      mica_error_clear();
      memcpy(u, nw->saved, sizeof(double) * (size_t)n);
      k *= 2, den *= 2; /* the same t, half the step */
      nw->stats->cuts++;
      continue;
    }
    if (ierr == MICA_ERR_NUMERIC) return give_up(nw, u, target, may_cut);
    if (ierr) return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    k += 1;
    t = target;
    step++;
    nw->stats->steps_done = step;
    nw->stats->load_factor = t;
    if (on_step) MICA_CALL(on_step(ctx, step, t, u));
  }
  return MICA_SUCCESS;
}

int mica_nonlinear_solve(const MicaNonlinearProblem *problem, const MicaNewtonOptions *opt, double *u,
                         int (*on_step)(void *ctx, int step, double t, const double *u), void *ctx,
                         MicaNewtonStats *stats) {
  memset(stats, 0, sizeof *stats);
  Newton nw = {problem, opt, stats, NULL, NULL, 0, NULL, NULL, NULL, NULL};
  const long n = problem->n;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(nw.R, n));
  MICA_CALL_CLEANUP(MICA_MALLOC(nw.du, n));
  MICA_CALL_CLEANUP(MICA_MALLOC(nw.trial, n));
  MICA_CALL_CLEANUP(MICA_MALLOC(nw.saved, n));
  MICA_CALL_CLEANUP(choose_linear_solver(&nw));
  MICA_CALL_CLEANUP(run_steps(&nw, u, on_step, ctx));
cleanup:
  if (nw.linear) stats->linear = nw.linear->stats;
  mica_linear_solver_destroy(&nw.linear);
  free(nw.R);
  free(nw.du);
  free(nw.trial);
  free(nw.saved);
  return ierr;
}
