/* Patch tests of `mica stability` (docs/theory.md §stability; seed 000 §7.2.2, after Chen et al. 2013).
 *
 * On the deck's particles, MLS, quadrature, boundary method and VCI setting, a linear-elastic body with the
 * deck's E and ν is given an exact polynomial displacement u* on every boundary set (all components), and
 * the body force b = −div σ(u*) (zero for a linear u*); mica's own solid and Newton solve it and the relative
 * L2 and H1-seminorm errors against u* are the result. The polynomials are those of the seed in the
 * normalized coordinates ξ = (x − c)/L (c the centre of the particles' bounding box, L its largest half
 * extent), so that u* = O(1) whatever the body's size; in 3-D they are extended with the coefficients below.
 * A method passes the linear test if the error is at round-off; the quadratic test needs a basis of order ≥ 2
 * (and, with it, exact or variationally consistent integration).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "stability.h"

/* u_c = Σ_d A[c][d] ξ_d + Σ_{d≤e} Q[c][d][e] ξ_d ξ_e. 2-D: seed eqs 7.1 and 7.4. */
static const double LINEAR2[2][3] = {{0.1, 0.3, 0}, {0.2, 0.4, 0}};
static const double QUADRATIC2_A[2][3] = {{0.12, 0.14, 0}, {0.11, 0.13, 0}};
static const double QUADRATIC2_Q[2][3][3] = {{{0.16, 0.18, 0}, {0, 0.2, 0}, {0, 0, 0}},
                                             {{0.15, 0.1, 0}, {0, 0.21, 0}, {0, 0, 0}}};
static const double LINEAR3[3][3] = {{0.1, 0.3, 0.2}, {0.2, 0.4, 0.1}, {0.15, 0.05, 0.25}};
static const double QUADRATIC3_A[3][3] = {{0.12, 0.14, 0.1}, {0.11, 0.13, 0.07}, {0.09, 0.05, 0.12}};
static const double QUADRATIC3_Q[3][3][3] = {{{0.16, 0.18, 0.06}, {0, 0.2, 0}, {0, 0, 0.08}},
                                             {{0.15, 0.1, 0}, {0, 0.21, 0.09}, {0, 0, 0.05}},
                                             {{0.04, 0.03, 0.07}, {0, 0, 0.06}, {0, 0, 0.11}}};

typedef struct {
  int dim, degree;
  double A[3][3], Q[3][3][3];
  double center[3], L;
} Polynomial;

static void polynomial_make(const RunProblem *rp, int degree, Polynomial *p) {
  const MicaDiscretization *disc = rp->disc;
  const int dim = disc->dim;
  memset(p, 0, sizeof *p);
  p->dim = dim, p->degree = degree;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (long i = 0; i < disc->nparticles; i++)
    for (int d = 0; d < dim; d++) lo[d] = fmin(lo[d], disc->x[i * dim + d]), hi[d] = fmax(hi[d], disc->x[i * dim + d]);
  for (int d = 0; d < dim; d++) p->center[d] = 0.5 * (lo[d] + hi[d]), p->L = fmax(p->L, 0.5 * (hi[d] - lo[d]));
  for (int c = 0; c < dim; c++)
    for (int d = 0; d < dim; d++) {
      p->A[c][d] = degree == 1 ? (dim == 2 ? LINEAR2[c][d] : LINEAR3[c][d])
                               : (dim == 2 ? QUADRATIC2_A[c][d] : QUADRATIC3_A[c][d]);
      for (int e = 0; e < dim && degree == 2; e++) p->Q[c][d][e] = dim == 2 ? QUADRATIC2_Q[c][d][e] : QUADRATIC3_Q[c][d][e];
    }
}

/* The expression of u_c in x, y, z. */
static void polynomial_text(const Polynomial *p, int c, char *buf, size_t size) {
  static const char var[3] = {'x', 'y', 'z'};
  char xi[3][96];
  size_t len = 0;
  for (int d = 0; d < p->dim; d++) snprintf(xi[d], sizeof xi[d], "((%c - (%.17g))/%.17g)", var[d], p->center[d], p->L);
  len += (size_t)snprintf(buf + len, size - len, "0");
  for (int d = 0; d < p->dim; d++)
    if (p->A[c][d] != 0) len += (size_t)snprintf(buf + len, size - len, " + %.17g*%s", p->A[c][d], xi[d]);
  for (int d = 0; d < p->dim; d++)
    for (int e = d; e < p->dim; e++)
      if (p->Q[c][d][e] != 0) len += (size_t)snprintf(buf + len, size - len, " + %.17g*%s*%s", p->Q[c][d][e], xi[d], xi[e]);
}

/* ∇u* at x: F = I + ∇u*, row-major. */
static void polynomial_F(const Polynomial *p, const double *x, double *F) {
  const int dim = p->dim;
  double xi[3];
  for (int d = 0; d < dim; d++) xi[d] = (x[d] - p->center[d]) / p->L;
  for (int c = 0; c < dim; c++)
    for (int J = 0; J < dim; J++) {
      double g = p->A[c][J];
      for (int d = 0; d < dim; d++)
        for (int e = d; e < dim; e++) g += p->Q[c][d][e] * ((d == J) * xi[e] + (e == J) * xi[d]);
      F[c * dim + J] = (c == J) + g / p->L;
    }
}

/* The body force b = −div σ(u*), constant for a quadratic u* and linear elasticity: σ is affine in x, so the
 * central difference over ±L is exact up to round-off. The kernel itself gives σ, so plane stress and strain
 * and 3-D need no formula of their own. */
static int body_force(const Polynomial *p, const MicaMaterial *mat, double *b) {
  const int dim = p->dim;
  for (int c = 0; c < dim; c++) b[c] = 0;
  for (int J = 0; J < dim; J++) {
    double xp[3], xm[3], F[9], Pp[9], Pm[9], W;
    for (int d = 0; d < dim; d++) xp[d] = xm[d] = p->center[d];
    xp[J] += p->L, xm[J] -= p->L;
    polynomial_F(p, xp, F);
    MICA_CALL(mica_model_linear.eval(mat, dim, F, &W, Pp, NULL));
    polynomial_F(p, xm, F);
    MICA_CALL(mica_model_linear.eval(mat, dim, F, &W, Pm, NULL));
    for (int c = 0; c < dim; c++) b[c] -= (Pp[c * dim + J] - Pm[c * dim + J]) / (2 * p->L);
  }
  return MICA_SUCCESS;
}

static int make_function(const char *text, MicaFunction **f) { return mica_function_create(text, 0, NULL, NULL, f); }

/* The patch problem: the deck's discretization and MLS, a linear-elastic model, u* on every boundary set. */
static int patch_solid(const RunProblem *rp, const Polynomial *p, const MicaMaterial *mat, MicaSolid **solid) {
  const MicaDiscretization *disc = rp->disc;
  const MicaSolid *deck_solid = rp->solid;
  const int dim = disc->dim;
  MicaSolidOptions opt;
  MicaDirichlet *dirichlet = NULL;
  MicaTraction *traction = NULL;
  int ierr = MICA_SUCCESS;
  char text[2048];
  memset(&opt, 0, sizeof opt);
  MICA_CALL(mica_field_classical_set(&opt.field, &mica_model_linear, mat));
  opt.bc_method = deck_solid->opt.bc_method;
  opt.bc_alpha = deck_solid->opt.bc_alpha;
  opt.basis_order = deck_solid->opt.basis_order;
  opt.vci = deck_solid->opt.vci;
  opt.scni = deck_solid->opt.scni;
  opt.nsni = deck_solid->opt.nsni;
  opt.ramp = 0;
  MICA_CALL_CLEANUP(MICA_CALLOC(dirichlet, disc->nsets));
  MICA_CALL_CLEANUP(MICA_CALLOC(traction, 1));
  for (int set = 0; set < disc->nsets; set++) {
    MicaDirichlet *c = &dirichlet[set];
    c->set = set;
    c->mask = (1 << dim) - 1;
    snprintf(c->where, sizeof c->where, "stability patch test (degree %d), boundary set '%s'", p->degree,
             disc->sets[set].name);
    for (int a = 0; a < dim; a++) {
      polynomial_text(p, a, text, sizeof text);
      MICA_CALL_CLEANUP(make_function(text, &c->value[a]));
    }
  }
  if (p->degree == 2) {
    double b[3];
    MICA_CALL_CLEANUP(body_force(p, mat, b));
    for (int a = 0; a < dim; a++) {
      snprintf(text, sizeof text, "%.17g", b[a]);
      MICA_CALL_CLEANUP(make_function(text, &opt.body[a]));
    }
  }
  return mica_solid_create(disc, &rp->approx, &opt, disc->nsets, dirichlet, 0, traction, solid);
cleanup:
  mica_solid_conditions_free(opt.body, disc->nsets, &dirichlet, 0, &traction);
  return ierr;
}

/* One patch test: solve, then the relative errors against u*. */
static int patch_one(RunProblem *rp, int degree, const MicaMaterial *mat, double *l2, double *h1) {
  Polynomial p;
  RunProblem patch;
  MicaNewtonOptions nopt;
  MicaNewtonStats stats;
  double *u = NULL, energy;
  char text[2048];
  int ierr = MICA_SUCCESS;
  polynomial_make(rp, degree, &p);
  memset(&patch, 0, sizeof patch);
  patch.deck = rp->deck, patch.disc = rp->disc, patch.mls = rp->mls, patch.fe = rp->fe, patch.approx = rp->approx;
  patch.ncomp = rp->disc->dim, patch.has_exact = 1;
  MICA_CALL_CLEANUP(patch_solid(rp, &p, mat, &patch.solid));
  for (int c = 0; c < patch.ncomp; c++) {
    polynomial_text(&p, c, text, sizeof text);
    MICA_CALL_CLEANUP(make_function(text, &patch.exact[c]));
    for (int J = 0; J < rp->disc->dim; J++) MICA_CALL_CLEANUP(mica_function_derivative(patch.exact[c], J, &patch.exact_grad[c][J]));
  }
  memset(&nopt, 0, sizeof nopt);
  /* a linear problem: one solve, a second to mop up; 1e-10 (not tighter) because saddle points that are
   * nearly singular (Lagrange multipliers meeting at a corner with a linear basis: docs/verification.md)
   * stall near 1e-11 |R_0|, and the error is what the test reports */
  nopt.steps = 1, nopt.max_iterations = 4, nopt.rtol = 1e-10, nopt.atol = 0, nopt.max_cuts = 0;
  MICA_CALL_CLEANUP(MICA_CALLOC(u, patch.solid->ndof));
  MICA_CALL_CLEANUP(mica_newton_solve(patch.solid, &nopt, u, NULL, NULL, &stats));
  MICA_CALL_CLEANUP(run_error_values(&patch, u, l2, h1, &energy));
  printf("patch test, degree %d (%s, %s): relative L2 error %.3e, H1 seminorm %.3e\n", degree, stats.linear_name,
         patch.solid->opt.bc_method->type.name, *l2, *h1);
cleanup:
  if (ierr) mica_error_prefix("stability patch test of degree %d", degree);
  free(u);
  mica_solid_destroy(&patch.solid);
  mica_shape_cache_destroy(&patch.at_gauss);         /* made by run_error_points under nodal and scni */
  mica_discretization_destroy(&patch.error_disc);    /* and with quadrature.error_order */
  for (int c = 0; c < MICA_MAX_COMP; c++) {
    mica_function_destroy(&patch.exact[c]);
    for (int J = 0; J < 3; J++) mica_function_destroy(&patch.exact_grad[c][J]);
  }
  return ierr;
}

int stability_patch(const StabilityOptions *o, RunProblem *rp, MicaJson *summary) {
  (void)o;
  const MicaSolid *s = rp->solid;
  const char *skip = rp->axisymmetric             ? "axisymmetric sections have no polynomial patch test here"
                     : !s->opt.field.classical    ? "the patch tests are for classical (displacement) models"
                     : rp->disc->nsets == 0       ? "the body has no boundary sets to prescribe the field on"
                                                  : NULL;
  if (skip) {
    printf("patch tests skipped: %s\n", skip);
    MICA_CALL(mica_json_string(summary, "patch_skipped", skip));
    return MICA_SUCCESS;
  }
  MicaMaterial mat;
  const MicaMaterial *deck_mat = &s->opt.field.material;
  MICA_CALL(mica_material_set(&mica_model_linear, deck_mat->E, deck_mat->nu, deck_mat->plane, &mat));
  if (mica_type_has(&s->opt.field.classical->type, MICA_MODEL_FINITE_STRAIN))
    printf("patch tests use the linear-elastic kernel with the deck's E and ν (the tangent of '%s' at u = 0)\n",
           s->opt.field.classical->type.name);
  double l2, h1;
  MICA_CALL(patch_one(rp, 1, &mat, &l2, &h1));
  MICA_CALL(mica_json_number(summary, "patch_linear_l2", l2));
  MICA_CALL(mica_json_number(summary, "patch_linear_h1", h1));
  MICA_CALL(patch_one(rp, 2, &mat, &l2, &h1));
  MICA_CALL(mica_json_number(summary, "patch_quadratic_l2", l2));
  MICA_CALL(mica_json_number(summary, "patch_quadratic_h1", h1));
  return MICA_SUCCESS;
}
