/* Private to src/parallel. */
#ifndef MICA_PARALLEL_PRIVATE_H
#define MICA_PARALLEL_PRIVATE_H

#include "mica/geom.h"
#include "mica/parallel.h"

/* own_exchange.c: what parallel.data = "distributed" adds to a distribution (its ghost plans, extra nodes), freed. */
void parallel_owned_free(MicaDistribution *dist);

/* Where the rank's own particles alone can support a point: no particle of another rank lies within
 * low[d] < x_d < high[d] on any axis d (own.c, parallel_add_supports). */
typedef struct {
  double low[3], high[3];
} OwnedZone;
/* set[nset] ∪= the particles (of mls) in the supports of the n points x[n·dim] outside the zone; ascending; set
 * holds the owned particles already (a point in the zone has only those). */
int parallel_add_supports(const MlsApprox *mls, const OwnedZone *zone, long n, const double *x, long **set,
                          long *nset);
/* ... within factor times the supports' radii (NSNI's Hessians of a linear basis: a quadratic fit on wider supports). */
int parallel_add_wider_supports(const MlsApprox *mls, const OwnedZone *zone, double factor, long n, const double *x,
                                long **set, long *nset);
/* ... of a discretization's boundary points and vertices. */
int parallel_add_set_supports(const MlsApprox *mls, const OwnedZone *zone, const MicaDiscretization *d, long **needed,
                              long *nneeded);
/* dist->mls: the MLS approximation of dist->local's particles with the radii, spacings and weight parameters of
 * particles map[i] of `source` (the approximation they were sized in). */
int parallel_local_mls(const MlsApprox *source, const MlsOptions *mls_opt, const long *map, MicaDistribution *dist);
/* own_exchange.c: the ghost particles' plan: each asked of its owner (partition->part) by its position there, global_node minus
 * offsets[owner] (offsets: the owners' first numbers). */
int parallel_ghost_plan(MicaDistribution *dist, const long *offsets);
/* Each of the n ghosts' position among its owner's particles: its key sent to the owner, found among the owner's
 * nowned keys (ascending), sent back. Collective. */
int parallel_ghost_positions(long n, const int *owner, const long *key, long nowned, const long *owned_key,
                             long *position);
/* Collective, after agreeing on ierr (the build so far): the local discretization revolved (an axisymmetric
 * section), its MLS approximation from `source` (parallel_local_mls), the ghost plan. */
int parallel_owned_complete(int ierr, const MlsApprox *source, const MlsOptions *mls_opt, const long *map,
                            const long *offsets, int revolve, MicaDistribution *dist);
/* Collective: a distribution of owned data (spec: the error order) built by build(ctx, dist), then the body's volume,
 * the global counts and the statistics, agreed over the ranks. */
int parallel_owned_create(int (*build)(void *ctx, MicaDistribution *dist), void *ctx, const MicaOwnedSpec *spec,
                          MicaDistribution **out);

#endif
