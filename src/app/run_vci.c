/* quadrature.vci = "auto" | true | false (docs/theory.md §VCI, "The default"): the one place where the default
 * is decided. Gauss cells integrate the MLS products well enough on a regular or graded grid (the patch error
 * is 1e-5 – 1e-6 and the rates are optimal), but off a grid the integration error stops the convergence
 * (manufactured.cfg, jittered: H1 rate 0.63 against 1.3 regular, docs/verification.md §VCI by default). So
 * "auto" corrects the test gradients on jittered, irregular and Gmsh particles, and leaves the grids, and
 * every setting VCI does not combine with, alone. An explicit true keeps its refusals (run.c: read_vci); an
 * explicit false is today's uncorrected rule. */
#include <stdio.h>
#include <string.h>

#include "run.h"

/* Why auto leaves VCI off where it cannot or need not apply, before looking at the layout; NULL: it may. */
static const char *unavailable(const RunVciFacts *f, unsigned mode, const char *linear) {
  if (f->fe) return "finite elements pass the patch test without it";
  if (f->model_order > 1) return "a second-order model: VCI corrects first derivatives only";
  if (f->axisymmetric) return "axisymmetric solid: no VCI for the hoop terms";
  if (mode & RUN_INTEGRATION_SMOOTHED) return "quadrature.mode = \"scni\" passes the linear patch test itself";
  if ((mode & RUN_INTEGRATION_NODAL) && !(mode & RUN_INTEGRATION_STABILIZED))
    return "direct nodal integration is shown as it is";
  if (f->parallel) return "VCI is not available in parallel runs with parallel.data = replicated";
  if (f->boundary_uncovered > 0) return "the mesh's boundary sets do not cover the boundary once";
  if (f->symmetric_only) return "this analysis needs the symmetric Galerkin tangent";
  const MicaLinearSolverOps *solver = strcmp(linear, "auto") ? mica_linear_solver_find(linear) : NULL;
  if (solver && mica_linear_solver_has(solver, MICA_LINEAR_SPD_ONLY))
    return "solver.linear needs a symmetric positive definite tangent";
  return NULL;
}

/* The layout's verdict: on off a grid, off on one. */
static int by_layout(const MicaDeck *deck, RunVciChoice *c) {
  const char *shape, *layout;
  MICA_CALL(mica_deck_string(deck, "geometry.shape", &shape));
  MICA_CALL(mica_deck_string(deck, "particles.layout", &layout));
  const int gmsh = !strcmp(shape, "gmsh"), grid = !gmsh && (!strcmp(layout, "regular") || !strcmp(layout, "graded"));
  c->on = !grid;
  snprintf(c->reason, sizeof c->reason, "%s", gmsh ? "Gmsh mesh nodes" : grid ? "particles on a grid"
                                                   : !strcmp(layout, "jittered") ? "jittered layout"
                                                                                 : "irregular layout");
  return MICA_SUCCESS;
}

int run_vci_replicated_parallel(const MicaDeck *deck, int *replicated) {
  const char *data;
  MICA_CALL(mica_deck_string(deck, "parallel.data", &data));
  *replicated = mica_parallel_active() && strcmp(data, "distributed") != 0;
  return MICA_SUCCESS;
}

int run_vci_choose(const MicaDeck *deck, const RunVciFacts *facts, RunVciChoice *c) {
  const char *word;
  int value;
  memset(c, 0, sizeof *c);
  MICA_CALL(mica_deck_bool_or_word(deck, "quadrature.vci", &value, &word));
  if (!word) {
    c->on = value;
    return MICA_SUCCESS;
  }
  c->automatic = 1; /* the only word the schema lets through */
  unsigned mode;
  const char *linear;
  MICA_CALL(run_integration_flags(deck, &mode));
  MICA_CALL(mica_deck_string(deck, "solver.linear", &linear));
  const char *why = unavailable(facts, mode, linear);
  if (why) {
    snprintf(c->reason, sizeof c->reason, "%s", why);
    return MICA_SUCCESS;
  }
  if (mode & RUN_INTEGRATION_STABILIZED) { /* one point per particle misses the patch test on any layout */
    c->on = c->nodal = 1;
    snprintf(c->reason, sizeof c->reason, "quadrature.mode = \"nsni\": nodal integration is consistent only with it");
    return MICA_SUCCESS;
  }
  return by_layout(deck, c);
}

int run_vci_report(const RunVciChoice *c, const MicaSolidOptions *opt) {
  if (!c->automatic) return MICA_SUCCESS;
  if (!c->on) {
    printf("quadrature.vci = auto: off (%s)\n", c->reason);
    return MICA_SUCCESS;
  }
  const int spd = mica_bc_method_has(opt->bc_method, MICA_BC_SYMMETRIC_DEFINITE);
  /* the figures: docs/verification.md §"VCI by default", docs/performance.md (the Petrov–Galerkin kernel) */
  const char *solve = !mica_parallel_active() ? (spd ? "in one process solver.linear = auto factors its symmetric part with "
                                              "CHOLMOD and refines (cholmod-sym: 1.4-1.6× CHOLMOD's factorization "
                                              "time without VCI, UMFPACK's LU 2.7-4.1×)"
                                            : "factored by UMFPACK as the multipliers' tangent is anyway")
                                             : "under mpirun PETSc takes MUMPS's LU (or GMRES with the iterative presets)";
  printf("quadrature.vci = auto: on (%s): %s; VCI corrects the test gradients (Petrov–Galerkin): the tangent is "
         "unsymmetric, %s, and its assembly takes about 1.2× the symmetric one's; quadrature.vci = false keeps "
         "the uncorrected rule\n",
         c->reason,
         c->nodal ? "one point per particle fails the patch test on any layout"
                  : "Gauss cells off a grid lose the patch test and the rates",
         solve);
  fflush(stdout);
  return MICA_SUCCESS;
}

int run_vci_summary(const RunVciChoice *c, MicaJson *summary) {
  MICA_CALL(mica_json_string(summary, "vci_setting", c->automatic ? "auto" : c->on ? "true" : "false"));
  if (c->automatic) MICA_CALL(mica_json_string(summary, "vci_reason", c->reason));
  return MICA_SUCCESS;
}
