/* The approximation and the integration a run deck chooses, where they differ from EFG with Gauss cells:
 * problem.method = "fe" (the finite-element measuring stick: its deck checks, mesh and discretization) and
 * quadrature.mode = "nodal" | "scni" (nodal cells, SCNI's restrictions), and what neither does under MPI.
 * run.c calls these while it builds the problem. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mica/timer.h"
#include "run.h"

static const MicaType integration_gauss = {"gauss", "Gauss points of the background cells", 0, NULL, NULL};
static const MicaType integration_nodal = {
    "nodal", "direct nodal integration at the particles (inconsistent: fails the patch test; low-energy modes)",
    RUN_INTEGRATION_NODAL, NULL, NULL};
static const MicaType integration_scni = {
    "scni", "stabilized conforming nodal integration: smoothed gradients on the nodal cells",
    RUN_INTEGRATION_NODAL | RUN_INTEGRATION_SMOOTHED, NULL, NULL};
static const MicaType integration_nsni = {
    "nsni", "naturally stabilized nodal integration: one point per particle with the strain's gradient terms from "
    "the MLS Hessians, and VCI (quadrature.vci = auto) for the patch test of the basis order",
    RUN_INTEGRATION_NODAL | RUN_INTEGRATION_STABILIZED, NULL, NULL};
static const MicaType *const builtin_integrations[] = {&integration_gauss, &integration_nodal, &integration_scni,
                                                       &integration_nsni, NULL};

MicaRegistry run_integration_registry = {"integration mode", "gauss", builtin_integrations, NULL, 0, NULL};

int run_integration_flags(const MicaDeck *deck, unsigned *flags) {
  const char *mode;
  const MicaType *type;
  MICA_CALL(mica_deck_string(deck, "quadrature.mode", &mode));
  MICA_CALL(mica_registry_get(&run_integration_registry, mode, &type));
  *flags = type->flags;
  return MICA_SUCCESS;
}

int run_is_fe(const MicaDeck *deck, int *fe) {
  const char *method;
  const MicaType *type;
  MICA_CALL(mica_deck_string(deck, "problem.method", &method));
  MICA_CALL(mica_registry_get(&mica_approx_registry, method, &type));
  *fe = !mica_type_has(type, MICA_APPROX_MLS); /* the run builds an MLS approximation or elements */
  return MICA_SUCCESS;
}

/* problem.method = "fe" needs nodes on a logical grid (a built-in shape, a structured layout), elements of
 * order mls.order that fit the grid, and cells that are its elements. Refused with the deck line. */
int run_check_fe_deck(const MicaDeck *deck, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                         const MicaCellSpec *cells, int *order) {
  char where[256];
  long p;
  MICA_CALL(mica_deck_int(deck, "mls.order", &p));
  mica_deck_where(deck, "geometry.shape", where, sizeof where);
  MICA_CHECK(shape->kind != MICA_SHAPE_GMSH, MICA_ERR_INPUT,
             "%s: problem.method = \"fe\" puts its elements between the particles of a built-in shape; Gmsh meshes "
             "are not supported: use a built-in shape or problem.method = \"efg\"", where);
  mica_deck_where(deck, "particles.layout", where, sizeof where);
  MICA_CHECK(layout->kind != MICA_LAYOUT_IRREGULAR, MICA_ERR_INPUT,
             "%s: problem.method = \"fe\" needs the particles on a logical grid, which the irregular layout is not; "
             "use particles.layout = \"regular\", \"graded\" or \"jittered\"", where);
  mica_deck_where(deck, "mls.order", where, sizeof where);
  MICA_CHECK(p == 1 || p == 2, MICA_ERR_INPUT,
             "%s: problem.method = \"fe\" takes the element order from mls.order = %ld; use 1 (Q1, hex8) or 2 (Q2, "
             "hex27)", where, p);
  mica_deck_where(deck, "particles.count", where, sizeof where);
  for (int d = 0; d < shape->dim; d++)
    MICA_CHECK(p == 1 || layout->count[d] % 2 == 1, MICA_ERR_INPUT,
               "%s: elements of order 2 span 3 particles per axis, so particles.count needs odd entries (entry %d is "
               "%ld); use %ld", where, d + 1, layout->count[d], layout->count[d] + 1);
  MICA_CHECK(!(shape->kind == MICA_SHAPE_PLATE_HOLE && p == 2 && (layout->count[0] - 1) % 4 != 0), MICA_ERR_INPUT,
             "%s: the plate's corner must lie on an element edge: with elements of order 2, the first entry of "
             "particles.count minus 1 must be a multiple of 4 (it is %ld); use %ld", where, layout->count[0] - 1,
             4 * ((layout->count[0] - 1) / 4 + 1) + 1);
  if (cells->count[0] > 0) {
    mica_deck_where(deck, "quadrature.cells", where, sizeof where);
    for (int d = 0; d < shape->dim; d++)
      MICA_CHECK(cells->count[d] == (layout->count[d] - 1) / p, MICA_ERR_INPUT,
                 "%s: with problem.method = \"fe\" the cells are the elements, (particles.count − 1) / mls.order = "
                 "%ld along axis %d, not %ld; leave quadrature.cells out", where, (layout->count[d] - 1) / p, d + 1,
                 cells->count[d]);
  }
  *order = (int)p;
  return MICA_SUCCESS;
}

/* The finite-element mesh on the particles and its discretization, which replaces the shape's (the same
 * particles and boundary set names; element Gauss points and element faces). */
int run_build_fe(const MicaLayoutSpec *layout, const MicaCellSpec *cells, int order, RunProblem *rp) {
  MicaDiscretization *fe_disc = NULL;
  const double start = mica_wtime();
  MICA_CALL(mica_fe_create(rp->disc->dim, order, layout->count, rp->disc->nparticles, rp->disc->x, &rp->fe));
  rp->time_mls = mica_wtime() - start;
  MICA_CALL(mica_fe_discretize(rp->fe, rp->disc, cells->order, cells->boundary_order, &fe_disc));
  mica_discretization_destroy(&rp->disc);
  rp->disc = fe_disc;
  rp->approx = (MicaApprox){&mica_approx_fe, rp->fe};
  return MICA_SUCCESS;
}

/* Finite elements are C0 and interpolate: no second-gradient models, and nothing for VCI to correct. */
int run_check_fe_model(const MicaDeck *deck, const RunProblem *rp, const MicaSolidOptions *opt) {
  if (!rp->fe) return MICA_SUCCESS;
  char where[256];
  int vci;
  const char *word;
  mica_deck_where(deck, "material.model", where, sizeof where);
  MICA_CHECK(opt->field.ops->order <= rp->approx.ops->max_order, MICA_ERR_INPUT,
             "%s: model '%s' needs second derivatives of C1 shape functions; the finite elements of problem.method = "
             "\"fe\" are C0: use problem.method = \"efg\"", where, opt->field.ops->type.name);
  MICA_CALL(mica_deck_bool_or_word(deck, "quadrature.vci", &vci, &word)); /* "auto" is off here (run_vci.c) */
  mica_deck_where(deck, "quadrature.vci", where, sizeof where);
  MICA_CHECK(vci != 1, MICA_ERR_INPUT,
             "%s: quadrature.vci corrects MLS gradients; finite elements pass the patch test without it: use "
             "quadrature.vci = false", where);
  return MICA_SUCCESS;
}

/* Lagrange multipliers on Q1/hex8 elements live on the displacement nodes of the boundary: where two conditions
 * on the same component meet at a node, both constrain its value, the constraints are linearly dependent and
 * the saddle-point matrix is singular. Refused (Q2 has more trace nodes than multiplier nodes and is not
 * affected; neither are penalty and Nitsche). */
int run_check_fe_multipliers(const MicaDeck *deck, const RunProblem *rp, const MicaSolidOptions *opt, int n,
                                const MicaDirichlet *c) {
  if (!rp->fe || rp->fe->order != 1 || !mica_bc_method_has(opt->bc_method, MICA_BC_MULTIPLIERS)) return MICA_SUCCESS;
  const int dim = rp->disc->dim;
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++) {
      const MicaBoundarySet *a = &rp->disc->sets[c[i].set], *b = &rp->disc->sets[c[j].set];
      if (!(c[i].mask & c[j].mask)) continue;
      for (long va = 0; va < a->nvertices; va++)
        for (long vb = 0; vb < b->nvertices; vb++) {
          double r = 0;
          for (int d = 0; d < dim; d++) r = fmax(r, fabs(a->vertex_x[va * dim + d] - b->vertex_x[vb * dim + d]));
          if (r > 0) continue;
          char where[256];
          mica_deck_where(deck, "bc.method", where, sizeof where);
          MICA_ERROR(MICA_ERR_INPUT,
                     "%s: bc.method = \"lagrange\" with %s elements: the conditions on sets '%s' and '%s' meet at a "
                     "node and constrain the same component there twice (linearly dependent multipliers, a singular "
                     "saddle point); use \"nitsche\" or \"penalty\", or elements of order 2",
                     where, mica_fe_element_name(dim, 1), a->name, b->name);
        }
    }
  return MICA_SUCCESS;
}

/* quadrature.mode: "gauss" needs nothing; "nodal" and "scni" need dual cells of the particles' logical grid
 * (built-in shapes; regular, graded or jittered layouts) on a plane or 3-D body. Checked with the deck's line
 * before the cells are built. */
static int check_nodal_mode(const MicaDeck *deck, const char *mode, const MicaShapeSpec *shape,
                            const MicaLayoutSpec *layout, int from_points) {
  char where[256];
  int axisymmetric;
  mica_deck_where(deck, "quadrature.mode", where, sizeof where);
  MICA_CALL(mica_deck_bool(deck, "geometry.axisymmetric", &axisymmetric));
  MICA_CHECK(!axisymmetric, MICA_ERR_INPUT,
             "%s: quadrature.mode = \"%s\" needs a plane or 3-D body (axisymmetric sections have particles on the "
             "axis, where the nodal weight 2πr vanishes and the hoop strain u_r/r is not defined); use "
             "quadrature.mode = \"gauss\"", where, mode);
  if (from_points) return MICA_SUCCESS; /* NSNI: cells from the Gauss points where there is no grid */
  MICA_CHECK(shape->kind != MICA_SHAPE_GMSH, MICA_ERR_INPUT,
             "%s: quadrature.mode = \"%s\" needs a built-in shape (its nodal cells are the dual cells of the particle "
             "grid, which a Gmsh mesh does not have); use quadrature.mode = \"gauss\" with a mesh", where, mode);
  MICA_CHECK(layout->kind != MICA_LAYOUT_IRREGULAR, MICA_ERR_INPUT,
             "%s: quadrature.mode = \"%s\" needs particles on a logical grid for its nodal cells; use "
             "particles.layout = \"jittered\", \"regular\" or \"graded\" (or quadrature.mode = \"nsni\", whose cells "
             "may come from the Gauss points)", where, mode);
  return MICA_SUCCESS;
}

/* Nodal and SCNI modes turn the discretization into a nodal one (src/geom/nodal.c); a failure there (a folded
 * cell) is reported at the mode's line. */
int run_read_integration(const MicaDeck *deck, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                            const MicaCellSpec *cells, int build, RunProblem *rp) {
  unsigned flags;
  MICA_CALL(mica_deck_string(deck, "quadrature.mode", &rp->integration));
  MICA_CALL(run_integration_flags(deck, &flags));
  if (!(flags & RUN_INTEGRATION_NODAL)) return MICA_SUCCESS;
  if (rp->fe) {
    char where[256];
    mica_deck_where(deck, "quadrature.mode", where, sizeof where);
    MICA_ERROR(MICA_ERR_INPUT, "%s: quadrature.mode = \"%s\" integrates meshfree shape functions at the particles; "
               "problem.method = \"fe\" uses the elements' Gauss points: use quadrature.mode = \"gauss\"", where,
               rp->integration);
  }
  /* NSNI: the dual cells of the particle grid where there is one, else the Gauss points nearest to each particle */
  const int from_points = (flags & RUN_INTEGRATION_STABILIZED) &&
                          (shape->kind == MICA_SHAPE_GMSH || layout->kind == MICA_LAYOUT_IRREGULAR);
  MICA_CALL(check_nodal_mode(deck, rp->integration, shape, layout, from_points));
  if (!build) return MICA_SUCCESS;
  int ierr;
  if (from_points) {
    ierr = mica_discretization_nodal_points(rp->disc);
  } else {
    ierr = mica_discretization_nodal(shape, layout, cells, rp->disc);
    if (!ierr && (flags & RUN_INTEGRATION_STABILIZED)) ierr = mica_discretization_nodal_centroids(rp->disc);
  }
  if (ierr) {
    char where[256];
    mica_deck_where(deck, "quadrature.mode", where, sizeof where);
    mica_error_prefix("%s: quadrature.mode = \"%s\"", where, rp->integration);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  return MICA_SUCCESS;
}

/* NSNI (docs/theory.md §NSNI) expands first-order kinematics over the nodal cells: a second-order model would
 * need third derivatives of the shape functions. Refused with the deck line. (A finite model other than a
 * classical one takes the paired rule, src/assemble/nsni_pairs.c.) */
static int check_nsni(const MicaDeck *deck, const MicaSolidOptions *opt) {
  char where[256];
  const MicaFieldModel *m = &opt->field;
  mica_deck_where(deck, "quadrature.mode", where, sizeof where);
  MICA_CHECK(m->ops->order == 1, MICA_ERR_INPUT,
             "%s: quadrature.mode = \"nsni\" expands the kinematics to first order over each nodal cell, and model "
             "'%s' uses second derivatives: its expansion needs third derivatives of the MLS shape functions, which "
             "mica does not compute; use quadrature.mode = \"gauss\" (or \"nodal\")", where, m->ops->type.name);
  return MICA_SUCCESS;
}

/* SCNI smooths first derivatives: second-gradient models need "nodal" (MLS Hessians) or "gauss". VCI is
 * refused with it: SCNI's trial gradients are cell averages, not the MLS gradients at x_I that VCI's
 * consistency argument assumes (a quadratic patch stays inexact, docs/verification.md), and for a linear basis
 * SCNI already satisfies the linear integration constraint that VCI would impose. */
int run_read_scni(const MicaDeck *deck, RunProblem *rp, MicaSolidOptions *opt) {
  unsigned flags;
  MICA_CALL(mica_deck_string(deck, "quadrature.mode", &rp->integration));
  MICA_CALL(run_integration_flags(deck, &flags));
  opt->scni = (flags & RUN_INTEGRATION_SMOOTHED) != 0;
  opt->nsni = (flags & RUN_INTEGRATION_STABILIZED) != 0;
  if (opt->nsni) return check_nsni(deck, opt);
  if (!opt->scni) return MICA_SUCCESS;
  char where[256];
  mica_deck_where(deck, "quadrature.vci", where, sizeof where);
  MICA_CHECK(!opt->vci, MICA_ERR_INPUT,
             "%s: quadrature.vci does not combine with quadrature.mode = \"scni\" (SCNI's smoothed gradients already "
             "pass the linear patch test, and VCI cannot raise them to quadratic consistency); use quadrature.mode = "
             "\"scni\" without vci, or \"nodal\" or \"gauss\" with vci", where);
  if (opt->field.ops->order == 1) return MICA_SUCCESS;
  mica_deck_where(deck, "quadrature.mode", where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT,
             "%s: quadrature.mode = \"scni\" smooths first derivatives only, and model '%s' uses second derivatives; "
             "use quadrature.mode = \"nodal\" (MLS Hessians at the particles) or \"gauss\"", where,
             opt->field.ops->type.name);
}

/* The FE baseline and the nodal integration modes keep per-point data (elements, nodal cells) that replicated
 * data's distribution of the quadrature points does not carry; with parallel.data = "distributed" each rank builds
 * the nodal cells of its own particles (own.c), and the FE baseline stays a one-process measuring stick. */
int run_check_serial_only(const MicaDeck *deck, const RunProblem *rp, int distributed) {
  unsigned flags;
  MICA_CALL(run_integration_flags(deck, &flags));
  const int nodal = (flags & RUN_INTEGRATION_NODAL) && !distributed;
  const char *path = rp->fe ? "problem.method" : nodal ? "quadrature.mode" : NULL;
  if (!path) return MICA_SUCCESS;
  char where[256];
  const char *value;
  mica_deck_where(deck, path, where, sizeof where);
  MICA_CALL(mica_deck_string(deck, path, &value));
  if (rp->fe)
    MICA_ERROR(MICA_ERR_INPUT, "%s: %s = \"%s\" runs on one process (it is a measuring stick, not distributed); run "
               "without mpirun, or use problem.method = \"efg\"", where, path, value);
  MICA_ERROR(MICA_ERR_INPUT, "%s: %s = \"%s\" under mpirun needs parallel.data = \"distributed\" (each rank builds its "
             "particles' nodal cells; replicated data distributes Gauss points only); set it, or use quadrature.mode = "
             "\"gauss\"", where, path, value);
}
