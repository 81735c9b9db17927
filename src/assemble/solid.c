/* The solid problem: shape-function caches, multiplier nodes, local spacing at boundary points, and the
 * sparsity pattern, built once (docs/architecture.md). Assembly is in assemble.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/kernel.h"
#include "mica/parallel.h"
#include "mica/solid.h"
#include "mica/timer.h"

/* Does any condition use boundary set `set`? */
static int set_is_used(const MicaSolid *s, int set) {
  for (int c = 0; c < s->ndirichlet; c++)
    if (s->dirichlet[c].set == set) return 1;
  for (int c = 0; c < s->ntraction; c++)
    if (s->traction[c].set == set) return 1;
  return 0;
}

/* h at a boundary point: the particles' local spacing (largest axis), averaged with weights |N|. Penalty
 * and Nitsche scale their parameter as α E / h. */
static int boundary_spacing(MicaSolid *s, int set) {
  const MicaShapeCache *c = s->boundary[set];
  const double *spacing = s->approx.ops->spacing(s->approx.ctx);
  MICA_CALL(MICA_MALLOC(s->boundary_h[set], c->npoints));
  for (long p = 0; p < c->npoints; p++) {
    double sum_w = 0, sum_h = 0;
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
      double h = 0;
      for (int d = 0; d < s->dim; d++) h = fmax(h, spacing[c->index[e] * s->dim + d]);
      sum_w += fabs(c->N[e]);
      sum_h += fabs(c->N[e]) * h;
    }
    s->boundary_h[set][p] = sum_h / sum_w;
  }
  return MICA_SUCCESS;
}

/* Can the donor's caches serve s? Built on the same discretization and approximation. */
static int same_approximation(const MicaSolid *s, const MicaSolid *donor) {
  return donor && donor->disc == s->disc && donor->approx.ops == s->approx.ops && donor->approx.ctx == s->approx.ctx;
}

/* The donor's cache of boundary set `set`, if it can serve s: same approximation and derivative order. */
static MicaShapeCache *donor_boundary(const MicaSolid *s, const MicaSolid *donor, int set) {
  if (!same_approximation(s, donor) || !donor->boundary[set]) return NULL;
  return donor->boundary[set]->order == s->volume->order ? donor->boundary[set] : NULL;
}

static int build_boundary_caches(MicaSolid *s, const MicaSolid *donor) {
  const MicaDiscretization *disc = s->disc;
  MICA_CALL(MICA_CALLOC(s->boundary, disc->nsets));
  MICA_CALL(MICA_CALLOC(s->boundary_h, disc->nsets));
  for (int set = 0; set < disc->nsets; set++) {
    if (!set_is_used(s, set)) continue;
    MicaShapeCache *shared = donor_boundary(s, donor, set);
    if (shared) {
      s->boundary[set] = mica_shape_cache_share(shared);
      s->caches_shared++;
    } else {
      char label[96];
      snprintf(label, sizeof label, "boundary set '%s'", disc->sets[set].name);
      const double start = mica_wtime();
      MICA_CALL(s->approx.ops->points(s->approx.ctx, disc->sets[set].n, disc->sets[set].x, disc->sets[set].cell,
                                      s->opt.field.ops->order, label, &s->boundary[set]));
      s->time_shape += mica_wtime() - start;
      s->time_search += s->boundary[set]->time_search;
      s->caches_built++;
    }
    MICA_CALL(boundary_spacing(s, set));
  }
  return MICA_SUCCESS;
}

/* Lagrange multipliers: each Dirichlet condition gets the vertices of its set's boundary elements as
 * multiplier nodes, numbered after the particles. */
static int number_multipliers(MicaSolid *s) {
  MICA_CALL(MICA_CALLOC(s->multiplier_offset, s->ndirichlet > 0 ? s->ndirichlet : 1));
  s->nmultiplier_nodes = 0;
  if (!mica_bc_method_has(s->opt.bc_method, MICA_BC_MULTIPLIERS)) return MICA_SUCCESS;
  for (int c = 0; c < s->ndirichlet; c++) {
    s->multiplier_offset[c] = s->nparticles + s->nmultiplier_nodes;
    s->nmultiplier_nodes += s->disc->sets[s->dirichlet[c].set].nvertices;
  }
  return MICA_SUCCESS;
}

/* The particle at vertex v of a set, among the supports of the vertex: within 1e-8 of its spacing, or −1. */
static long particle_at(const MicaSolid *s, const MicaShapeCache *c, long v, const double *spacing) {
  const double *x = c->x + v * s->dim;
  for (long e = c->ptr[v]; e < c->ptr[v + 1]; e++) {
    const long J = c->index[e];
    double distance = 0, h = 0;
    for (int d = 0; d < s->dim; d++) {
      distance = fmax(distance, fabs(x[d] - s->disc->x[J * s->dim + d]));
      h = fmax(h, spacing[J * s->dim + d]);
    }
    if (distance <= 1e-8 * h) return J;
  }
  return -1;
}

/* Collocation (bc.method = collocation): shape functions at each constrained set's vertices, and the particle
 * standing at each vertex, whose equations the method replaces (src/bc/collocation.c). */
static int collocation_points(MicaSolid *s, int c) {
  const MicaBoundarySet *set = &s->disc->sets[s->dirichlet[c].set];
  const double *spacing = s->approx.ops->spacing(s->approx.ctx);
  char label[96];
  snprintf(label, sizeof label, "the vertices of boundary set '%s'", set->name);
  MICA_CALL(s->approx.ops->points(s->approx.ctx, set->nvertices, set->vertex_x, NULL, 1, label, &s->collocation[c]));
  MICA_CALL(MICA_MALLOC(s->collocation_particle[c], set->nvertices > 0 ? set->nvertices : 1));
  MICA_CALL(MICA_MALLOC(s->collocation_scale[c], set->nvertices > 0 ? set->nvertices : 1));
  for (long v = 0; v < set->nvertices; v++) {
    const long J = particle_at(s, s->collocation[c], v, spacing);
    if (J < 0) {
      const double *x = set->vertex_x + v * s->dim;
      char point[96];
      snprintf(point, sizeof point, s->dim == 3 ? "(%g, %g, %g)" : "(%g, %g)", x[0], x[1], s->dim == 3 ? x[2] : 0.0);
      MICA_ERROR(MICA_ERR_INPUT,
                 "%s: bc.method = \"collocation\" imposes the values at the particles on the set, but vertex %s of "
                 "boundary set '%s' is not a particle (jittered and irregular layouts move the particles off the "
                 "cells' vertices): use a regular or graded layout with the default quadrature.cells, a Gmsh mesh, "
                 "or another bc.method", s->dirichlet[c].where, point, set->name);
    }
    double h = 0;
    for (int d = 0; d < s->dim; d++) h = fmax(h, spacing[J * s->dim + d]);
    s->collocation_particle[c][v] = J;
    s->collocation_scale[c][v] = s->opt.field.material.E * pow(h, s->dim - 2);
  }
  return MICA_SUCCESS;
}

/* counts[(I·ncomp + a)·ndirichlet + c]: condition c has a vertex at particle I here and prescribes component a. */
static void collocation_count(const MicaSolid *s, double *counts) {
  for (int c = 0; c < s->ndirichlet; c++)
    for (long v = 0; v < s->collocation[c]->npoints; v++)
      for (int a = 0; a < s->ncomp; a++)
        if (s->dirichlet[c].mask & (1 << a))
          counts[(s->collocation_particle[c][v] * s->ncomp + a) * s->ndirichlet + c] += 1;
}

/* Who writes each row from the counts (over the ranks with distributed data): the last condition, each of its
 * holders a share. */
static void collocation_rows(MicaSolid *s, const double *counts) {
  const int nc = s->ndirichlet;
  for (long row = 0; row < s->nparticles * s->ncomp; row++) {
    s->collocation_last[row] = -1, s->collocation_share[row] = 0;
    for (int c = nc - 1; c >= 0 && s->collocation_last[row] < 0; c--)
      if (counts[row * nc + c] > 0) s->collocation_last[row] = c, s->collocation_share[row] = 1.0 / counts[row * nc + c];
  }
}

static int build_collocation(MicaSolid *s) {
  if (!mica_bc_method_has(s->opt.bc_method, MICA_BC_COLLOCATION)) return MICA_SUCCESS;
  const int n = s->ndirichlet > 0 ? s->ndirichlet : 1;
  const long rows = s->nparticles * s->ncomp;
  MICA_CALL(MICA_CALLOC(s->collocation, n));
  MICA_CALL(MICA_CALLOC(s->collocation_particle, n));
  MICA_CALL(MICA_CALLOC(s->collocation_scale, n));
  MICA_CALL(MICA_MALLOC(s->collocation_last, rows + 1));
  MICA_CALL(MICA_MALLOC(s->collocation_share, rows + 1));
  for (int c = 0; c < s->ndirichlet; c++) MICA_CALL(collocation_points(s, c));
  if (s->opt.parallel && s->opt.parallel->owned) return MICA_SUCCESS; /* owned_collocation, after the agreement */
  double *counts = NULL;
  MICA_CALL(MICA_CALLOC(counts, rows * n + 1));
  collocation_count(s, counts);
  collocation_rows(s, counts);
  MICA_FREE(counts);
  return MICA_SUCCESS;
}

/* parallel.data = "distributed": a particle's vertices may lie on other ranks' faces (a rank's sets are its cells'
 * faces), and every rank holding it has volume terms in its rows: the counts are summed over the holders. */
static int owned_collocation(MicaSolid *s) {
  const int n = s->ndirichlet > 0 ? s->ndirichlet : 1;
  double *counts = NULL;
  int ierr = MICA_CALLOC(counts, s->nparticles * s->ncomp * n + 1);
  if (!ierr) collocation_count(s, counts);
  ierr = mica_ghost_sum(s->opt.parallel, ierr, counts, s->ncomp * n);
  if (!ierr) collocation_rows(s, counts);
  MICA_FREE(counts);
  return ierr;
}

/* Cliques: every cached point's supporting particles (plus, for multipliers, its element's multiplier
 * nodes) are coupled all to all. Counted first, then filled. */
static long clique_size(const MicaSolid *s, const MicaShapeCache *c, long p, int cond) {
  long n = c->ptr[p + 1] - c->ptr[p];
  if (cond >= 0) n += s->disc->sets[s->dirichlet[cond].set].element_size;
  return n;
}

static void clique_fill(const MicaSolid *s, const MicaShapeCache *c, long p, int cond, long *nodes) {
  long n = 0;
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) nodes[n++] = c->index[e];
  if (cond < 0) return;
  const MicaBoundarySet *set = &s->disc->sets[s->dirichlet[cond].set];
  const long *vertices = set->element_vertices + set->element[p] * set->element_size;
  for (int v = 0; v < set->element_size; v++) nodes[n++] = s->multiplier_offset[cond] + vertices[v];
}

static int build_pattern(MicaSolid *s) {
  const int with_multipliers = mica_bc_method_has(s->opt.bc_method, MICA_BC_MULTIPLIERS);
  /* a cell pressure couples every point of a cell: the cell's points' supports are one clique */
  const int cells = mica_solid_pressure_cells(s);
  long ncliques = cells ? s->npcells : s->volume->npoints, total = s->volume->ptr[s->volume->npoints];
  const MicaShapeCache *stab = s->nsni ? s->nsni->cache : NULL; /* NSNI's points: their own supports */
  if (stab) ncliques += stab->npoints, total += stab->ptr[stab->npoints];
  /* parallel: every multiplier node's own block, which rank 0 pins whether or not its points touch the node */
  const long nsingle = s->opt.parallel ? s->nmultiplier_nodes : 0;
  ncliques += nsingle, total += nsingle;
  for (int c = 0; c < s->ndirichlet; c++) {
    const MicaShapeCache *b = s->boundary[s->dirichlet[c].set];
    ncliques += b->npoints;
    for (long p = 0; p < b->npoints; p++) total += clique_size(s, b, p, with_multipliers ? c : -1);
    if (!s->collocation) continue;
    ncliques += s->collocation[c]->npoints;
    total += s->collocation[c]->ptr[s->collocation[c]->npoints];
  }
  long *ptr = NULL, *nodes = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(ptr, ncliques + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(nodes, total));
  long q = 0;
  ptr[0] = 0;
  for (long k = 0; k < (cells ? s->npcells : s->volume->npoints); k++, q++) {
    ptr[q + 1] = ptr[q];
    for (long i = cells ? s->pcell_ptr[k] : k; i < (cells ? s->pcell_ptr[k + 1] : k + 1); i++) {
      const long p = cells ? s->pcell_point[i] : i;
      clique_fill(s, s->volume, p, -1, nodes + ptr[q + 1]);
      ptr[q + 1] += clique_size(s, s->volume, p, -1);
    }
  }
  for (long p = 0; stab && p < stab->npoints; p++, q++) {
    clique_fill(s, stab, p, -1, nodes + ptr[q]);
    ptr[q + 1] = ptr[q] + clique_size(s, stab, p, -1);
  }
  for (int c = 0; c < s->ndirichlet; c++) {
    const MicaShapeCache *b = s->boundary[s->dirichlet[c].set];
    const int cond = with_multipliers ? c : -1;
    for (long p = 0; p < b->npoints; p++, q++) {
      clique_fill(s, b, p, cond, nodes + ptr[q]);
      ptr[q + 1] = ptr[q] + clique_size(s, b, p, cond);
    }
    for (long v = 0; s->collocation && v < s->collocation[c]->npoints; v++, q++) {
      clique_fill(s, s->collocation[c], v, -1, nodes + ptr[q]);
      ptr[q + 1] = ptr[q] + clique_size(s, s->collocation[c], v, -1);
    }
  }
  for (long v = 0; v < nsingle; v++, q++) {
    nodes[ptr[q]] = s->nparticles + v;
    ptr[q + 1] = ptr[q] + 1;
  }
  MICA_CALL_CLEANUP(mica_sparse_create(s->nparticles + s->nmultiplier_nodes, s->ncomp, ncliques, ptr, nodes, &s->K));
cleanup:
  free(ptr);
  free(nodes);
  return ierr;
}

/* The largest support of a volume or NSNI point. */
static long largest_volume_support(const MicaSolid *s) {
  const long stab = s->nsni ? s->nsni->cache->max_support : 0;
  return s->volume->max_support > stab ? s->volume->max_support : stab;
}

static long largest_clique(const MicaSolid *s) {
  long largest = largest_volume_support(s);
  for (int set = 0; set < s->disc->nsets; set++)
    if (s->boundary[set] && s->boundary[set]->max_support > largest) largest = s->boundary[set]->max_support;
  for (int c = 0; s->collocation && c < s->ndirichlet; c++)
    if (s->collocation[c]->max_support > largest) largest = s->collocation[c]->max_support;
  return largest + 4; /* + the multiplier nodes of one boundary element */
}

/* An axisymmetric solid: a 2-D section, a first-order model whose unknowns are vectors of three components. */
static int check_axisymmetric(const MicaSolid *s) {
  const MicaSolidOptions *opt = &s->opt;
  MICA_CHECK(s->dim == 2, MICA_ERR_INPUT, "an axisymmetric solid needs a 2-D (r, z) section; this geometry is %d-D",
             s->dim);
  MICA_CHECK(opt->field.ops->order == 1 && s->ncomp % 3 == 0, MICA_ERR_INPUT,
             "model '%s' has no axisymmetric form (it needs %s): use a 3-D run", opt->field.ops->type.name,
             opt->field.ops->order == 1 ? "vector unknowns" : "second derivatives in cylindrical coordinates");
  MICA_CHECK(!mica_bc_method_has(opt->bc_method, MICA_BC_MODEL_TRACTION), MICA_ERR_INPUT,
             "bc.method = \"%s\" is not available for axisymmetric solids: use \"lagrange\" or \"penalty\"",
             opt->bc_method->type.name);
  for (long p = 0; p < s->disc->nquad; p++)
    MICA_CHECK(s->disc->qx[p * 2] > 0, MICA_ERR_INPUT,
               "an axisymmetric section lies in x = r ≥ 0; quadrature point %ld has r = %g", p + 1, s->disc->qx[p * 2]);
  return MICA_SUCCESS;
}

/* The model, the approximation and the boundary method must fit together and in the fixed-size scratch of a
 * point. */
static int check_model(const MicaSolidOptions *opt, const MicaApprox *approx, int ncomp, int nq) {
  MICA_CHECK(ncomp <= MICA_MAX_COMP && nq <= 128, MICA_ERR_ARGUMENT, "model '%s' has too many unknowns",
             opt->field.ops->type.name);
  MICA_CHECK(opt->field.ops->order <= approx->ops->max_order, MICA_ERR_INPUT,
             "model '%s' needs derivatives of order %d, which the %s approximation does not provide (it is C%d)",
             opt->field.ops->type.name, opt->field.ops->order, approx->ops->type.name, approx->ops->max_order - 1);
  MICA_CHECK(!opt->vci || mica_approx_has(approx->ops, MICA_APPROX_MLS), MICA_ERR_INPUT,
             "quadrature.vci corrects MLS gradients; the %s approximation has none to correct", approx->ops->type.name);
  MICA_CHECK(!opt->vci || opt->field.ops->order == 1, MICA_ERR_INPUT,
             "quadrature.vci corrects first derivatives only; model '%s' uses second derivatives",
             opt->field.ops->type.name);
  MICA_CHECK(!(opt->scni && opt->vci), MICA_ERR_INPUT, "quadrature.vci does not combine with SCNI");
  MICA_CHECK(!opt->scni || (opt->field.ops->order == 1 && !opt->axisymmetric), MICA_ERR_INPUT,
             "SCNI smooths first derivatives of plane or 3-D fields only; model '%s'%s", opt->field.ops->type.name,
             opt->axisymmetric ? " is axisymmetric" : " uses second derivatives");
  MICA_CHECK(!opt->vci || !opt->parallel || opt->parallel->owned, MICA_ERR_INPUT,
             "quadrature.vci is not available in parallel runs with parallel.data = \"replicated\" (its correction "
             "sums over every particle's support); use parallel.data = \"distributed\", or run on one process");
  MICA_CHECK(!opt->parallel || opt->parallel->owned || !mica_bc_method_has(opt->bc_method, MICA_BC_COLLOCATION),
             MICA_ERR_INPUT,
             "bc.method = \"%s\" replaces equations of the assembled system, which a parallel run with "
             "parallel.data = \"replicated\" sums over the ranks; use parallel.data = \"distributed\", run on one "
             "process, or use another bc.method", opt->bc_method->type.name);
  MICA_CHECK(opt->field.ops->order == 1 || !mica_bc_method_has(opt->bc_method, MICA_BC_MODEL_TRACTION), MICA_ERR_INPUT,
             "bc.method = \"%s\" needs a classical model or a first-order field model; model '%s' uses second "
             "derivatives (its tractions include double tractions): use \"lagrange\" or \"penalty\"",
             opt->bc_method->type.name, opt->field.ops->type.name);
  return MICA_SUCCESS;
}

/* VCI: corrected test gradients in the volume cache (vci.c), with NSNI's stabilization points in the constraint
 * when there are some, timed for the summary; over the ranks with distributed data (collective: at the end of the
 * solid's creation, owned_collectives). */
static int apply_vci(MicaSolid *s) {
  const double start = mica_wtime();
  MicaDistribution *owned = s->opt.parallel && s->opt.parallel->owned ? s->opt.parallel : NULL;
  /* NSNI: one degree more than the basis. One point per cell integrates ∇N_J·σ for σ of the basis's degree n
   * with an O(1) defect on jittered particles (Gauss cells do not), and the L2 error stalled (docs/theory.md
   * §NSNI, "one degree more"); the patch tests of degree ≤ n hold either way. */
  const int order = s->opt.basis_order + (s->nsni ? 1 : 0);
  /* NSNI, linear basis: trial and test gradients corrected alike where the supports admit it (symmetric VCI;
   * the Petrov–Galerkin form's trial gradients violate the constraint by O(1) on jittered cells and its L2
   * error flattened). On a regular grid the boundary rows' supports make (a) and (b) incompatible; there the
   * uncorrected trial gradients nearly meet the constraint, and the Petrov–Galerkin form is kept. With
   * distributed data the outcome is agreed, so every rank takes the same form. */
  int ierr = MICA_ERR_NUMERIC;
  if (s->nsni && s->opt.basis_order == 1) {
    ierr = mica_vci_correct_symmetric(s->disc, s->mls, s->volume, s->nsni, owned);
    if (ierr != MICA_SUCCESS && ierr != MICA_ERR_NUMERIC) MICA_CALL(ierr);
    if (ierr) mica_error_clear();
  }
  s->vci_symmetric = ierr == MICA_SUCCESS;
  if (ierr && owned) MICA_CALL(mica_vci_correct_owned(s->disc, s->mls, order, s->volume, s->nsni, owned));
  else if (ierr) MICA_CALL(mica_vci_correct_stabilized(s->disc, s->mls, order, s->volume, s->nsni));
  s->time_vci = mica_wtime() - start;
  return MICA_SUCCESS;
}

int mica_solid_symmetric_definite(const MicaSolid *s) {
  return mica_bc_method_has(s->opt.bc_method, MICA_BC_SYMMETRIC_DEFINITE) && !s->volume->dN_test;
}

int mica_solid_nearly_symmetric(const MicaSolid *s) {
  return mica_bc_method_has(s->opt.bc_method, MICA_BC_SYMMETRIC_DEFINITE) && s->volume->dN_test;
}

/* The energy of NSNI's stabilization points (docs/theory.md §NSNI): a quadratic model's own; for a
 * finite-strain classical model the linear model of the same E, ν (its tangent at F = I), so that the
 * stabilization stays a fixed quadratic form whose tangent is exact. Other finite models (finite-rotation
 * Cosserat) have no such form: the paired rule (nsni_pairs.c) integrates their own energy instead. */
static int stabilization_model(MicaSolid *s) {
  const MicaFieldModel *m = &s->opt.field;
  if (mica_field_model_quadratic(m)) {
    s->stab_model = *m;
    return MICA_SUCCESS;
  }
  if (!mica_type_has(&m->ops->type, MICA_FIELD_CLASSICAL)) {
    s->stab_pairs = 1;
    return MICA_SUCCESS;
  }
  MicaMaterial linear;
  s->stab_green = 1; /* a finite-strain model: the linear form of the Green strain's rate (nsni_green.c) */
  MICA_CALL(mica_material_set(&mica_model_linear, m->material.E, m->material.nu, m->material.plane, &linear));
  return mica_field_classical_set(&s->stab_model, &mica_model_linear, &linear);
}

/* NSNI: the stabilization points at the particles (nsni.c), before VCI, whose constraint includes them. */
static int build_nsni(MicaSolid *s) {
  MICA_CHECK(s->mls && s->disc->nodal, MICA_ERR_INPUT, "NSNI needs MLS shape functions on a nodal discretization");
  MICA_CHECK(s->opt.field.ops->order == 1 && !s->opt.axisymmetric, MICA_ERR_INPUT,
             "NSNI expands the kinematics to first order over each nodal cell; model '%s'%s", s->opt.field.ops->type.name,
             s->opt.axisymmetric ? " is axisymmetric (the hoop terms have no expansion here)"
                                 : " uses second derivatives, whose expansion needs third derivatives of the shape "
                                   "functions, which mica does not compute");
  MICA_CALL(stabilization_model(s));
  const double start = mica_wtime();
  MICA_CALL(mica_nsni_create(s->disc, s->mls, s->stab_green, &s->nsni));
  s->time_shape += mica_wtime() - start;
  s->time_search += s->nsni->cache->time_search;
  return MICA_SUCCESS;
}

/* The volume cache: the donor's when it was built for the same discretization, approximation, derivative
 * order and test functions (VCI or not); otherwise built, and corrected for VCI. */
static int volume_cache(MicaSolid *s, const MicaSolid *donor) {
  const MicaSolidOptions *opt = &s->opt;
  const MicaDiscretization *disc = s->disc;
  const int order = opt->field.ops->order >= 2 ? 2 : 1;
  if (same_approximation(s, donor) && donor->volume->order == order && !donor->opt.vci == !opt->vci &&
      !donor->opt.scni == !opt->scni && !donor->opt.nsni == !opt->nsni) {
    s->volume = mica_shape_cache_share(donor->volume);
    s->vci_symmetric = donor->vci_symmetric;
    s->caches_shared++;
    return MICA_SUCCESS;
  }
  const double start = mica_wtime();
  if (opt->scni)
    MICA_CALL(mica_scni_cache_create(disc, s->mls, &s->volume));
  else
    MICA_CALL(s->approx.ops->points(s->approx.ctx, disc->nquad, disc->qx, disc->qcell, order, "volume quadrature",
                                    &s->volume));
  s->time_shape += mica_wtime() - start;
  s->time_search += s->volume->time_search;
  s->caches_built++;
  if (opt->vci && !(opt->parallel && opt->parallel->owned)) MICA_CALL(apply_vci(s));
  return MICA_SUCCESS;
}

/* Scratch of the group matrices (assemble.c: a group's union holds at most 1/8 more particles than the largest
 * support), in the planar layout of mica/kernel.h over ncomp unknowns, then the kernel's scratch, its tangent A
 * and the shape-function entries β of one point, trial and (VCI) test. */
static int cell_scratch(MicaSolid *s) {
  s->cell_cap = largest_volume_support(s) + largest_volume_support(s) / 8 + 1;
  if (s->cell_cap > s->nparticles) s->cell_cap = s->nparticles;
  if (s->cell_cap < 1) s->cell_cap = 1;
  const long u = s->cell_cap;
  const int nc = s->ncomp, nd = mica_solid_shape_entries(s);
  /* the staged projections G (u·nc²·nd doubles a point) within about 256 KB, so they stay in the L2 cache */
  const long per_point = u * nc * nc * nd;
  s->chunk_points = per_point * 8 > 32768 ? (int)(32768 / per_point) : 8;
  if (s->chunk_points < 1) s->chunk_points = 1;
  MICA_CALL(MICA_MALLOC(s->cell_matrix, mica_kernel_ke_size(nc, u) + mica_kernel_chunk_size(nc, nd, u, s->chunk_points) +
                                            (long)(nc * nd) * (nc * nd) + 2 * u * nd));
  MICA_CALL(MICA_MALLOC(s->cell_nodes, u));
  MICA_CALL(MICA_MALLOC(s->cell_slot, s->nparticles + 1));
  for (long i = 0; i < s->nparticles; i++) s->cell_slot[i] = -1;
  return MICA_SUCCESS;
}

/* parallel.data = "distributed": the multiplier nodes' owners and rows over the ranks, each named by its
 * condition and its vertex's key in the grid of cell corners (the same on every rank that holds it). */
static int owned_multipliers(MicaSolid *s) {
  long *id = NULL;
  const long first = s->nparticles;
  MICA_CALL(MICA_MALLOC(id, s->nmultiplier_nodes + 1));
  int ierr = MICA_SUCCESS;
  for (int c = 0; c < s->ndirichlet && !ierr; c++) {
    const MicaBoundarySet *set = &s->disc->sets[s->dirichlet[c].set];
    if (!set->vertex_key && set->nvertices)
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "set '%s': no vertex keys", set->name);
    for (long v = 0; !ierr && v < set->nvertices; v++)
      id[s->multiplier_offset[c] - first + v] = set->vertex_key[v] * s->ndirichlet + c;
  }
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(mica_owned_add_nodes(s->opt.parallel, s->nmultiplier_nodes, id));
cleanup:
  free(id);
  return ierr;
}

/* Whether the solid's creation ends in collectives over distributed data (every rank reaches them, or agrees on
 * the failure that stopped it). */
static int owned_collectives(const MicaSolidOptions *opt) {
  return opt->parallel && opt->parallel->owned &&
         (opt->vci || mica_bc_method_has(opt->bc_method, MICA_BC_MULTIPLIERS) ||
          mica_bc_method_has(opt->bc_method, MICA_BC_COLLOCATION));
}

int mica_solid_create(const MicaDiscretization *disc, const MicaApprox *approx, const MicaSolidOptions *opt,
                      int ndirichlet, MicaDirichlet *dirichlet, int ntraction, MicaTraction *traction,
                      MicaSolid **out) {
  return mica_solid_create_sharing(disc, approx, opt, ndirichlet, dirichlet, ntraction, traction, NULL, out);
}

int mica_solid_create_sharing(const MicaDiscretization *disc, const MicaApprox *approx, const MicaSolidOptions *opt,
                              int ndirichlet, MicaDirichlet *dirichlet, int ntraction, MicaTraction *traction,
                              const MicaSolid *donor, MicaSolid **out) {
  *out = NULL;
  MicaSolid *s;
  MICA_CALL(MICA_CALLOC(s, 1));
  int ierr = MICA_SUCCESS, agreed = 0;
  s->disc = disc;
  s->approx = *approx;
  s->mls = mica_approx_has(approx->ops, MICA_APPROX_MLS) ? approx->ctx : NULL;
  s->opt = *opt;
  s->dim = disc->dim;
  s->model_dim = opt->axisymmetric ? 3 : s->dim;
  s->ncomp = opt->field.ops->ncomp(s->model_dim);
  s->nq = mica_field_model_nq(&opt->field, s->model_dim);
  s->nparticles = disc->nparticles;
  s->ndirichlet = ndirichlet;
  s->dirichlet = dirichlet;
  s->ntraction = ntraction;
  s->traction = traction;
  MICA_CALL_CLEANUP(check_model(opt, approx, s->ncomp, s->nq));
  if (opt->axisymmetric) MICA_CALL_CLEANUP(check_axisymmetric(s));
  if (opt->nsni) MICA_CALL_CLEANUP(build_nsni(s));
  MICA_CALL_CLEANUP(volume_cache(s, donor));
  MICA_CALL_CLEANUP(build_boundary_caches(s, donor));
  MICA_CALL_CLEANUP(number_multipliers(s));
  MICA_CALL_CLEANUP(build_collocation(s));
  s->ndof = (s->nparticles + s->nmultiplier_nodes) * s->ncomp;
  MICA_CALL_CLEANUP(mica_pressure_cells_build(s));
  const double start = mica_wtime();
  MICA_CALL_CLEANUP(build_pattern(s));
  s->time_pattern = mica_wtime() - start;
  /* scratch: the model's D (nq × nq), the element matrix (m × m) and the projections G (m × nq); the
   * classical kernel's padded element matrix and its scratch (mica/kernel.h) fit in the extra 8 m ncomp, and
   * nsni_green.c's P (m · 2 dim², 2 dim² ≤ nq + 8 ncomp) in the last two */
  const long m = largest_clique(s) * s->ncomp;
  MICA_CALL_CLEANUP(MICA_MALLOC(s->work, (long)s->nq * s->nq + m * m + m * s->nq + 8 * m * s->ncomp + 64));
  MICA_CALL_CLEANUP(MICA_MALLOC(s->work_nodes, largest_clique(s)));
  MICA_CALL_CLEANUP(cell_scratch(s));
  if (owned_collectives(opt)) {
    agreed = 1;
    MICA_CALL_CLEANUP(mica_parallel_agree(MICA_SUCCESS));
    if (opt->vci) MICA_CALL_CLEANUP(apply_vci(s));
    if (mica_bc_method_has(opt->bc_method, MICA_BC_MULTIPLIERS)) MICA_CALL_CLEANUP(owned_multipliers(s));
    if (mica_bc_method_has(opt->bc_method, MICA_BC_COLLOCATION)) MICA_CALL_CLEANUP(owned_collocation(s));
  }
  /* NSNI's paired rule moves the nodal points' shape functions, VCI's corrected ones: after VCI */
  if (s->stab_pairs) MICA_CALL_CLEANUP(mica_nsni_pairs_create(s->nsni, s->volume, s->disc->qw));
  *out = s;
  return MICA_SUCCESS;
cleanup:
  if (owned_collectives(opt) && !agreed) mica_parallel_agree(ierr);
  mica_solid_destroy(&s); /* it owns the conditions and body force from the start, failure or not */
  return ierr;
}

void mica_solid_conditions_free(MicaFunction **body, int ndirichlet, MicaDirichlet **dirichlet, int ntraction,
                                MicaTraction **traction) {
  for (int a = 0; body && a < MICA_MAX_COMP; a++) mica_function_destroy(&body[a]);
  for (int c = 0; *dirichlet && c < ndirichlet; c++)
    for (int a = 0; a < MICA_MAX_COMP; a++) mica_function_destroy(&(*dirichlet)[c].value[a]);
  for (int c = 0; *traction && c < ntraction; c++)
    for (int a = 0; a < MICA_MAX_COMP; a++) mica_function_destroy(&(*traction)[c].value[a]);
  MICA_FREE(*dirichlet);
  MICA_FREE(*traction);
}

int mica_solid_destroy(MicaSolid **solid) {
  MicaSolid *s = *solid;
  if (!s) return MICA_SUCCESS;
  mica_pressure_cells_free(s);
  mica_shape_cache_destroy(&s->volume);
  mica_nsni_destroy(&s->nsni);
  if (s->boundary)
    for (int set = 0; set < s->disc->nsets; set++) {
      mica_shape_cache_destroy(&s->boundary[set]);
      MICA_FREE(s->boundary_h[set]);
    }
  MICA_FREE(s->boundary);
  MICA_FREE(s->boundary_h);
  mica_solid_conditions_free(s->opt.body, s->ndirichlet, &s->dirichlet, s->ntraction, &s->traction);
  MICA_FREE(s->multiplier_offset);
  for (int c = 0; s->collocation && c < s->ndirichlet; c++) {
    mica_shape_cache_destroy(&s->collocation[c]);
    MICA_FREE(s->collocation_particle[c]);
    MICA_FREE(s->collocation_scale[c]);
  }
  MICA_FREE(s->collocation);
  MICA_FREE(s->collocation_particle);
  MICA_FREE(s->collocation_scale);
  MICA_FREE(s->collocation_last);
  MICA_FREE(s->collocation_share);
  mica_sparse_destroy(&s->K);
  MICA_FREE(s->work);
  MICA_FREE(s->work_nodes);
  MICA_FREE(s->cell_matrix);
  MICA_FREE(s->cell_nodes);
  MICA_FREE(s->cell_slot);
  MICA_FREE(*solid);
  return MICA_SUCCESS;
}
