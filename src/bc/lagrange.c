/* Dirichlet conditions by Lagrange multipliers (docs/theory.md §boundary methods): a multiplier field λ on
 * the constrained set, interpolated linearly between the vertices of its boundary elements (ψ_v), and
 *   Π_L = ∫ λ·(u − ū) dΓ over the prescribed components,
 * so R_kb += ∫ [b∈C] λ_b N_k,  R_vb += ∫ [b∈C] ψ_v r_b,  K_(kb)(vb) = K_(vb)(kb) = ∫ [b∈C] N_k ψ_v.
 * The tangent is symmetric indefinite (a saddle point): it needs UMFPACK. The constraint is scaled by E
 * (λ = E λ̃, solving for λ̃) so that its block is of the size of the stiffness: unscaled, the two differ by
 * E (1e7 for steel-like moduli) and the factorization's residual stalls near 1e-8. Multiplier components
 * that are not prescribed are pinned to zero by an identity row, once per multiplier node. */
#include <stdlib.h>
#include <string.h>

#include "bc_private.h"
#include "mica/parallel.h"

enum { MAX_ELEMENT = 4 };

/* The condition's multiplier nodes at point p, in ascending order, with their shape functions. */
static int point_multipliers(const MicaSolid *s, const MicaDirichlet *c, int cond, long p, long *nodes,
                             double *psi) {
  const MicaBoundarySet *set = &s->disc->sets[c->set];
  const int m = set->element_size;
  const long *vertices = set->element_vertices + set->element[p] * m;
  for (int v = 0; v < m; v++) {
    nodes[v] = s->multiplier_offset[cond] + vertices[v];
    psi[v] = set->lambda_N[p * 4 + v];
  }
  for (int i = 1; i < m; i++) /* insertion sort, carrying ψ along */
    for (int j = i; j > 0 && nodes[j - 1] > nodes[j]; j--) {
      long tn = nodes[j];
      nodes[j] = nodes[j - 1], nodes[j - 1] = tn;
      double tp = psi[j];
      psi[j] = psi[j - 1], psi[j - 1] = tp;
    }
  return m;
}

static int condition_index(const MicaSolid *s, const MicaDirichlet *c) { return (int)(c - s->dirichlet); }

static int lagrange_point(MicaSolid *s, const MicaDirichlet *c, long p, double t, const double *u, double *R,
                          MicaSparse *K) {
  const int dim = s->ncomp, cond = condition_index(s, c); /* unknowns per node */
  BcPoint bp;
  MICA_CALL(bc_point(s, c, p, t, u, &bp));
  const double scale = s->opt.field.material.E, ws = bp.w * scale;
  long mnodes[MAX_ELEMENT];
  double psi[MAX_ELEMENT], lambda[MICA_MAX_COMP] = {0};
  const int nm = point_multipliers(s, c, cond, p, mnodes, psi);
  for (int v = 0; v < nm; v++)
    for (int b = 0; b < dim; b++) lambda[b] += psi[v] * u[mnodes[v] * dim + b];
  for (int b = 0; b < dim; b++) {
    if (!(c->mask & (1 << b))) continue;
    for (long k = 0; k < bp.n; k++) R[bp.index[k] * dim + b] += ws * lambda[b] * bp.N[k];
    for (int v = 0; v < nm; v++) R[mnodes[v] * dim + b] += ws * psi[v] * bp.residual[b];
  }
  if (!K) return MICA_SUCCESS;
  /* clique: the supporting particles, then the multiplier nodes (all larger than any particle index) */
  long *nodes = s->work_nodes, n = bp.n + nm;
  double *Ke = s->work;
  for (long k = 0; k < bp.n; k++) nodes[k] = bp.index[k];
  for (int v = 0; v < nm; v++) nodes[bp.n + v] = mnodes[v];
  const long m = n * dim;
  memset(Ke, 0, sizeof(double) * (size_t)(m * m));
  for (int b = 0; b < dim; b++) {
    if (!(c->mask & (1 << b))) continue;
    for (long k = 0; k < bp.n; k++)
      for (int v = 0; v < nm; v++) {
        const double value = ws * bp.N[k] * psi[v];
        Ke[(k * dim + b) * m + (bp.n + v) * dim + b] += value;
        Ke[((bp.n + v) * dim + b) * m + k * dim + b] += value;
      }
  }
  return mica_sparse_add_clique(K, n, nodes, Ke);
}

/* Who pins a multiplier node: the one process, rank 0 with replicated data (its pattern holds every multiplier
 * node's block), the node's owner with distributed data. */
static int pins_node(const MicaSolid *s, long node) {
  const MicaDistribution *dist = s->opt.parallel;
  if (!dist) return 1;
  return dist->owned ? mica_owned_node(dist, node) : mica_parallel_rank() == 0;
}

/* Multiplier components that are not prescribed: λ_b = 0 through an identity row and column. */
static int pin_free_components(MicaSolid *s, const MicaDirichlet *c, const double *u, double *R, MicaSparse *K) {
  const int dim = s->ncomp, cond = condition_index(s, c); /* unknowns per node */
  const long nvertices = s->disc->sets[c->set].nvertices;
  double block[MICA_MAX_COMP * MICA_MAX_COMP];
  for (long v = 0; v < nvertices; v++) {
    const long node = s->multiplier_offset[cond] + v;
    if (!pins_node(s, node)) continue;
    memset(block, 0, sizeof block);
    for (int b = 0; b < dim; b++)
      if (!(c->mask & (1 << b))) {
        R[node * dim + b] += u[node * dim + b];
        block[b * dim + b] = 1.0;
      }
    if (K) MICA_CALL(mica_sparse_add_clique(K, 1, &node, block));
  }
  return MICA_SUCCESS;
}

static int lagrange_add(MicaSolid *s, const MicaDirichlet *c, double t, const double *u, double *R, MicaSparse *K) {
  const long npoints = s->boundary[c->set]->npoints;
  for (long p = 0; p < npoints; p++) MICA_CALL(lagrange_point(s, c, p, t, u, R, K));
  MICA_CALL(pin_free_components(s, c, u, R, K)); /* once per problem (pins_node) */
  return MICA_SUCCESS;
}

const MicaBoundaryMethodOps mica_bc_lagrange = {
    {"lagrange", "Lagrange multipliers on the constrained sets: exact, indefinite tangent", MICA_BC_MULTIPLIERS,
     NULL, NULL},
    lagrange_add};
