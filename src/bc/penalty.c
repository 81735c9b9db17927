/* Dirichlet conditions by penalty: Π += ½ ∫ β |u − ū|² dΓ over the prescribed components, β = α E / h.
 * Not variationally consistent: the error it leaves decreases as 1/α (docs/theory.md §boundary methods). */
#include "bc_private.h"

static int penalty_add(MicaSolid *s, const MicaDirichlet *c, double t, const double *u, double *R, MicaSparse *K) {
  const int dim = s->dim;
  const long npoints = s->boundary[c->set]->npoints;
  double *Ke = s->work;
  for (long p = 0; p < npoints; p++) {
    BcPoint bp;
    bc_point(s, c, p, t, u, &bp);
    const double beta = bc_beta(s, &bp), wb = bp.w * beta;
    for (long k = 0; k < bp.n; k++)
      for (int a = 0; a < dim; a++) R[bp.index[k] * dim + a] += wb * bp.residual[a] * bp.N[k];
    if (!K) continue;
    const long m = bp.n * dim;
    for (long i = 0; i < m * m; i++) Ke[i] = 0;
    for (long k = 0; k < bp.n; k++)
      for (long l = 0; l < bp.n; l++)
        for (int a = 0; a < dim; a++)
          if (c->mask & (1 << a)) Ke[(k * dim + a) * m + l * dim + a] = wb * bp.N[k] * bp.N[l];
    MICA_CALL(mica_sparse_add_clique(K, bp.n, bp.index, Ke));
  }
  return MICA_SUCCESS;
}

const MicaBoundaryMethodOps mica_bc_penalty = {"penalty", 1e4, 1, 0, penalty_add};
