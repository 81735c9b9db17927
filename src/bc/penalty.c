/* Dirichlet conditions by penalty: Π += ½ ∫ β |u − ū|² dΓ over the prescribed components,
 *   β = α E (L/h)^(p−1) / h,   L = (body volume)^(1/dim), p = the basis order (≥ 1).
 * Not variationally consistent: it leaves an error of order 1/β, so β must grow faster than 1/h for bases
 * of order 2 and up to keep their convergence rate (measured on the Timoshenko beam: with β = α E / h the
 * quadratic L2 rate stalls near 1 on fine levels; with the extra (L/h)^(p−1) it is 3.1). Too large a β
 * locks instead, forcing the discrete trace onto boundary data it cannot represent (docs/verification.md). */
#include <math.h>

#include "bc_private.h"

static int penalty_add(MicaSolid *s, const MicaDirichlet *c, double t, const double *u, double *R, MicaSparse *K) {
  const int dim = s->dim, ncomp = s->ncomp;
  const long npoints = s->boundary[c->set]->npoints;
  double *Ke = s->work;
  for (long p = 0; p < npoints; p++) {
    BcPoint bp;
    MICA_CALL(bc_point(s, c, p, t, u, &bp));
    const double length = pow(s->disc->volume, 1.0 / dim);
    const int p_minus_1 = s->opt.basis_order > 1 ? s->opt.basis_order - 1 : 0;
    const double beta = bc_beta(s, &bp) * pow(length / bp.h, p_minus_1), wb = bp.w * beta;
    for (long k = 0; k < bp.n; k++)
      for (int a = 0; a < ncomp; a++) R[bp.index[k] * ncomp + a] += wb * bp.residual[a] * bp.N[k];
    if (!K) continue;
    const long m = bp.n * ncomp;
    for (long i = 0; i < m * m; i++) Ke[i] = 0;
    for (long k = 0; k < bp.n; k++)
      for (long l = 0; l < bp.n; l++)
        for (int a = 0; a < ncomp; a++)
          if (c->mask & (1 << a)) Ke[(k * ncomp + a) * m + l * ncomp + a] = wb * bp.N[k] * bp.N[l];
    MICA_CALL(mica_sparse_add_clique(K, bp.n, bp.index, Ke));
  }
  return MICA_SUCCESS;
}

static const MicaDeckKey penalty_keys[] = {BC_ALPHA_KEY("1e3"), {0}};

const MicaBoundaryMethodOps mica_bc_penalty = {
    {"penalty", "penalty: β = α E (L/h)^(p−1) / h on u − ū (symmetric positive definite, inconsistent)",
     MICA_BC_SYMMETRIC_DEFINITE, penalty_keys, bc_alpha_from_settings},
    penalty_add};
