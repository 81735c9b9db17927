/* What `mica run` and `mica check` both do before run solves: the problem built and checked (rigid modes,
 * probes), and its sizes counted (under MPI, over the ranks), printed and put in the summary. */
#include <stdio.h>
#include <string.h>

#include "run.h"

static long boundary_points(const MicaDiscretization *disc) {
  long n = 0;
  for (int i = 0; i < disc->nsets; i++) n += disc->sets[i].n;
  return n;
}

static size_t cache_bytes(const MicaSolid *s) {
  size_t bytes = mica_shape_cache_bytes(s->volume);
  for (int set = 0; set < s->disc->nsets; set++) bytes += mica_shape_cache_bytes(s->boundary[set]);
  return bytes;
}

/* The smallest reciprocal condition estimate of a moment matrix over the solid's MLS caches, volume and boundary
 * points (every one is held to mls.rcond_min); 0 when none is MLS. */
static double rcond_min(const MicaSolid *s) {
  double r = s->volume ? s->volume->rcond_min : 0;
  for (int set = 0; set < s->disc->nsets; set++) {
    const MicaShapeCache *b = s->boundary[set];
    if (b && b->rcond_min > 0 && (r == 0 || b->rcond_min < r)) r = b->rcond_min;
  }
  return r;
}

/* The sizes of the problem; under MPI, totals over the ranks (run_parallel.c). */
static int count_totals(const RunProblem *rp, RunTotals *c) {
  const MicaSolid *s = rp->solid;
  c->nnz = s->K->nnz;
  c->support_entries = s->volume->ptr[s->volume->npoints];
  c->support_points = s->volume->npoints;
  c->max_support = s->volume->max_support;
  c->cache_bytes = (long)cache_bytes(s);
  c->particles = rp->disc->nparticles, c->cells = rp->disc->ncells, c->quadrature_points = rp->disc->nquad;
  c->boundary_points = boundary_points(rp->disc), c->dofs = s->ndof, c->volume = rp->disc->volume;
  if (rp->dist) MICA_CALL(run_parallel_totals(rp, c));
  return MICA_SUCCESS;
}

static int add_counts(RunProblem *rp, const RunTotals *c, MicaJson *summary) {
  const MicaSolid *s = rp->solid;
  if (!rp->error_disc) MICA_CALL(run_error_discretization(rp, &rp->error_disc)); /* NULL without error_order */
  MICA_CALL(mica_json_string(summary, "method", rp->approx.ops->type.name));
  if (rp->fe) MICA_CALL(mica_json_string(summary, "element", mica_fe_element_name(rp->fe->dim, rp->fe->order)));
  MICA_CALL(mica_json_int(summary, "dim", rp->disc->dim));
  MICA_CALL(mica_json_int(summary, "particles", c->particles));
  MICA_CALL(mica_json_int(summary, "cells", c->cells));
  MICA_CALL(mica_json_string(summary, "integration", rp->integration));
  MICA_CALL(mica_json_int(summary, "quadrature_points", c->quadrature_points));
  /* the error norms' points: quadrature.error_order's own, else the solve's (the Gauss points of the nodal cells
   * for the nodal modes) */
  long error_points = rp->error_disc ? rp->error_disc->nquad : rp->disc->nodal ? rp->disc->ngauss
                                                                                : c->quadrature_points;
  if (rp->owned_data && rp->error_disc) error_points = mica_parallel_sum_long(error_points); /* the ranks' cells' */
  MICA_CALL(mica_json_int(summary, "error_points", error_points));
  MICA_CALL(mica_json_int(summary, "boundary_points", c->boundary_points));
  MICA_CALL(mica_json_int(summary, "dofs", c->dofs));
  /* distributed data: the ranks' own ones (a node on two ranks' faces once) */
  const long multipliers = rp->owned_data ? rp->dist->nglobal_nodes - rp->dist->nparticles : s->nmultiplier_nodes;
  MICA_CALL(mica_json_int(summary, "multiplier_nodes", multipliers));
  MICA_CALL(mica_json_int(summary, "nnz", c->nnz));
  MICA_CALL(mica_json_int(summary, "support_max", c->max_support));
  MICA_CALL(mica_json_number(summary, "support_mean", (double)c->support_entries / (double)c->support_points));
  /* how close the leanest support came to the mls.rcond_min limit (MLS only) */
  if (rcond_min(s) > 0) MICA_CALL(mica_json_number(summary, "rcond_min", rcond_min(s)));
  MICA_CALL(mica_json_int(summary, "cache_bytes", c->cache_bytes));
  MICA_CALL(mica_json_int(summary, "matrix_bytes", (long)(c->nnz * 16 + (c->dofs + 1) * 8)));
  MICA_CALL(mica_json_number(summary, "volume", c->volume));
  MICA_CALL(mica_json_string(summary, "model", mica_type_has(&s->opt.field.ops->type, MICA_FIELD_CLASSICAL)
                                                   ? s->opt.field.classical->type.name
                                                   : s->opt.field.ops->type.name));
  MICA_CALL(mica_json_int(summary, "unknowns_per_particle", s->ncomp));
  MICA_CALL(mica_json_string(summary, "bc_method", s->opt.bc_method->type.name));
  MICA_CALL(mica_json_string(summary, "pressure", s->opt.pressure ? s->opt.pressure->type.name : "none"));
  MICA_CALL(mica_json_number(summary, "bc_alpha", s->opt.bc_alpha));
  MICA_CALL(mica_json_number(summary, "time_discretize", rp->time_discretize));
  MICA_CALL(mica_json_number(summary, "time_mls_setup", rp->time_mls));
  MICA_CALL(mica_json_number(summary, "time_cache_and_pattern", rp->time_cache_pattern));
  MICA_CALL(mica_json_bool(summary, "vci", s->opt.vci));
  MICA_CALL(mica_json_bool(summary, "vci_symmetric", s->vci_symmetric));
  MICA_CALL(run_vci_summary(&rp->vci, summary));
  MICA_CALL(mica_json_number(summary, "time_vci", s->time_vci)); /* part of time_cache_and_pattern */
  /* the split of time_cache_and_pattern: shape functions (without their neighbor search), search, pattern */
  MICA_CALL(mica_json_number(summary, "time_search", s->time_search));
  MICA_CALL(mica_json_number(summary, "time_shape_functions", s->time_shape - s->time_search));
  MICA_CALL(mica_json_number(summary, "time_pattern", s->time_pattern));
  MICA_CALL(mica_json_bool(summary, "reused_discretization", rp->reused_geometry));
  MICA_CALL(mica_json_int(summary, "shape_caches_built", s->caches_built));
  MICA_CALL(mica_json_int(summary, "shape_caches_shared", s->caches_shared));
  return MICA_SUCCESS;
}

static void print_counts(const RunProblem *rp, const RunTotals *c) {
  const MicaSolid *s = rp->solid;
  printf("%ld particles, %ld %s cells, %ld quadrature points (+%ld on the boundary), %ld dofs, nnz %ld, support "
         "%.1f mean / %ld max, cache %.1f MB, matrix %.1f MB\n",
         c->particles, c->cells, rp->disc->nodal ? "nodal" : "background", c->quadrature_points,
         c->boundary_points, c->dofs, c->nnz, (double)c->support_entries / (double)c->support_points,
         c->max_support, (double)c->cache_bytes / 1e6, (double)(c->nnz * 16) / 1e6);
  if (s->opt.vci) printf("VCI: corrected test gradients in %.3g s\n", s->time_vci);
  if (rp->fe)
    printf("finite elements: %ld %s elements on the particles\n", rp->fe->nelements,
           mica_fe_element_name(rp->fe->dim, rp->fe->order));
  if (s->opt.scni) printf("SCNI: smoothed gradients on the nodal cells\n");
  if (s->nsni && s->stab_pairs)
    printf("NSNI: the paired rule, %ld points (%d per particle) moved along the MLS Hessians, energy of model '%s'\n",
           s->nsni->pairs->npoints, 2 * s->dim, s->opt.field.ops->type.name);
  else if (s->nsni)
    printf("NSNI: %ld stabilization points (%d per particle) from the MLS Hessians, energy of model '%s'\n",
           s->nsni->cache->npoints, s->dim, s->stab_model.ops->type.name);
  fflush(stdout);
}

/* A body its conditions do not hold has a singular tangent: said before anything is assembled, with the motions
 * and the components to hold; with parallel.data = "distributed" on the ranks' shares of the sets, summed. Not part
 * of building the problem: `mica stability` builds free bodies on purpose, to count their rigid modes. */
int run_check_rigid(const MicaDeck *deck, const RunProblem *rp, const MicaFieldModel *field, int ndirichlet,
                    const MicaDirichlet *dirichlet) {
  const char *names[MICA_MAX_COMP + 1];
  const int ncomp = run_model_names(rp, field, 0, names);
  char where[256];
  mica_deck_where(deck, ndirichlet ? "bcs.dirichlet" : "bcs", where, sizeof where);
  return mica_dirichlet_check_rigid(rp->disc, rp->axisymmetric, rp->owned_data, ncomp, names, ndirichlet, dirichlet,
                                    where);
}

/* (parallel.data = "distributed": on the ranks' shares of the sets, the sums over all ranks) */
static int check_rigid_modes(const MicaDeck *deck, const RunProblem *rp) {
  const MicaSolid *s = rp->solid;
  return run_check_rigid(deck, rp, &s->opt.field, s->ndirichlet, s->dirichlet);
}

int run_problem_prepare(const MicaDeck *deck, RunProblem *rp, RunReuse *reuse, const char *outdir, RunOutput *out,
                        RunTotals *totals, MicaJson *summary) {
  MICA_CALL(run_problem_build_reusing(deck, rp, reuse));
  MICA_CALL(check_rigid_modes(deck, rp));
  MICA_CALL(run_outputs_read(rp, outdir, out));
  MICA_CALL(count_totals(rp, totals));
  print_counts(rp, totals);
  MICA_CALL(add_counts(rp, totals, summary));
  MICA_CALL(run_parallel_counts(rp, summary));
  return run_estimate_report(&rp->estimate, summary);
}
