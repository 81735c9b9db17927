/* Dirichlet conditions by boundary collocation (docs/theory.md §boundary methods, seed 001 §3.3.2.1): the
 * equations of the particles on the set are replaced by the prescribed values at those particles,
 *   row (I, a):  s_I (u_h,a(x_I) − ū_a(x_I)) = s_I (Σ_J N_J(x_I) u_Ja − ū_a(x_I)) = 0,
 * for every prescribed component a and every particle I standing at a vertex of the set, s_I = E h_I^(dim−2)
 * so that the rows are of the size of the stiffness. Nothing is integrated on the boundary.
 *
 * MLS shape functions do not interpolate (N_J(x_I) ≠ δ_IJ), so two things are lost that the weak methods
 * keep: the condition holds at the particles only, not between them, and the Galerkin equations dropped for
 * the boundary particles are not those of test functions that vanish on the boundary — the discrete
 * problem is not a Galerkin method on the constrained space, and convergence is slower than with Nitsche
 * or Lagrange multipliers (tests/cli/collocation.sh measures how much). Linear fields are still reproduced
 * exactly by a linear basis (the patch test passes). The tangent is unsymmetric (UMFPACK). */
#include "bc_private.h"

/* Writes particle I's collocated rows for the prescribed components at vertex v: the rows whose last condition
 * this is (collocation_last), times the share of the ranks that write them (1 serially). */
static int collocate(MicaSolid *s, const MicaDirichlet *c, long v, double t, const double *u, double *R,
                     MicaSparse *K) {
  const int cond = (int)(c - s->dirichlet), ncomp = s->ncomp, dim = s->dim;
  const MicaShapeCache *cache = s->collocation[cond];
  const long I = s->collocation_particle[cond][v];
  const double load = s->opt.ramp ? t : 1.0;
  const double *x = cache->x + v * dim;
  for (int a = 0; a < ncomp; a++) {
    const long row = I * ncomp + a;
    if (!(c->mask & (1 << a)) || s->collocation_last[row] != cond) continue;
    const double scale = s->collocation_scale[cond][v] * s->collocation_share[row];
    double value, uh = 0;
    MICA_CALL(mica_function_eval_finite(c->value[a], "on the whole set", dim, x, t, &value));
    for (long e = cache->ptr[v]; e < cache->ptr[v + 1]; e++) uh += cache->N[e] * u[cache->index[e] * ncomp + a];
    R[row] = scale * (uh - load * value);
    for (long e = cache->ptr[v]; K && e < cache->ptr[v + 1]; e++)
      MICA_CALL(mica_sparse_set(K, row, cache->index[e] * ncomp + a, scale * cache->N[e]));
  }
  return MICA_SUCCESS;
}

/* The rows this condition replaces are emptied first on every rank that holds them (with distributed data the
 * volume terms of a ghost's rows would be added to the owner's), then written by the ranks with the vertex. */
static int collocation_add(MicaSolid *s, const MicaDirichlet *c, double t, const double *u, double *R, MicaSparse *K) {
  const int cond = (int)(c - s->dirichlet);
  const MicaShapeCache *cache = s->collocation[cond];
  for (long row = 0; row < s->nparticles * s->ncomp; row++) {
    if (s->collocation_last[row] != cond) continue;
    R[row] = 0;
    if (K) mica_sparse_zero_row(K, row);
  }
  for (long v = 0; v < cache->npoints; v++) MICA_CALL(collocate(s, c, v, t, u, R, K));
  return MICA_SUCCESS;
}

const MicaBoundaryMethodOps mica_bc_collocation = {
    {"collocation",
     "collocation: u_h = ū at the particles on the set, their equations replaced (unsymmetric; MLS does not "
     "interpolate, so it converges more slowly)",
     MICA_BC_COLLOCATION, NULL, NULL},
    collocation_add};
