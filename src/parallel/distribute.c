/* Distributing a problem over the ranks (parallel.h): rank 0 finds the supports of every quadrature point
 * (neighbor search only, no shape functions), partitions the particle graph with METIS and gives each point
 * to the owner of its nearest supporting particle; the partition and the owners are broadcast; each rank
 * keeps a discretization with its own points only (particles, boundary vertices and elements whole, so
 * that numbering stays global). */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/geom.h"
#include "mica/parallel.h"
#include "mica/timer.h"
#include "parallel_private.h"

/* ---- rank 0: partition and owners ---------------------------------------------------------------------- */

typedef struct {
  long *nearest_volume;  /* [nquad] */
  long **nearest_set;    /* [nsets][n] */
  long *ptr, *index;     /* supports of the volume points */
} Supports;

static void supports_free(Supports *sp, int nsets) {
  free(sp->nearest_volume);
  if (sp->nearest_set)
    for (int s = 0; s < nsets; s++) free(sp->nearest_set[s]);
  free(sp->nearest_set);
  free(sp->ptr);
  free(sp->index);
}

static int owners_from_nearest(const MicaPartition *p, long n, const long *nearest, int *owner) {
  for (long q = 0; q < n; q++) owner[q] = nearest[q] >= 0 ? p->part[nearest[q]] : 0;
  return MICA_SUCCESS;
}

/* Ghost particles per rank (the largest count, and rank 0's), from the volume supports. */
static int count_ghosts(MicaDistribution *dist, const Supports *sp, long nquad, long *ghost_counts) {
  for (int r = 0; r < dist->partition->nparts; r++) {
    long nghost = 0, *ghosts = NULL;
    MICA_CALL(mica_partition_ghosts(dist->partition, r, nquad, sp->ptr, sp->index, dist->volume_owner, &nghost,
                                    &ghosts));
    free(ghosts);
    ghost_counts[r] = nghost;
  }
  return MICA_SUCCESS;
}

static int partition_on_root(MicaDistribution *dist, const MicaDiscretization *disc, const MlsApprox *mls, int nparts,
                             long *ghost_counts) {
  Supports sp = {0};
  long *weights = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(sp.nearest_volume, disc->nquad + 1));
  MICA_CALL_CLEANUP(MICA_CALLOC(sp.nearest_set, disc->nsets + 1));
  MICA_CALL_CLEANUP(mica_point_supports(mls, disc->nquad, disc->qx, &sp.ptr, &sp.index, sp.nearest_volume));
  MICA_CALL_CLEANUP(MICA_CALLOC(weights, disc->nparticles));
  for (long i = 0; i < disc->nparticles; i++) weights[i] = 1;
  for (long q = 0; q < disc->nquad; q++)
    if (sp.nearest_volume[q] >= 0) weights[sp.nearest_volume[q]]++;
  for (int s = 0; s < disc->nsets; s++) {
    long *ptr = NULL, *index = NULL;
    MICA_CALL_CLEANUP(MICA_MALLOC(sp.nearest_set[s], disc->sets[s].n + 1));
    MICA_CALL_CLEANUP(mica_point_supports(mls, disc->sets[s].n, disc->sets[s].x, &ptr, &index, sp.nearest_set[s]));
    free(ptr);
    free(index);
  }
  MICA_CALL_CLEANUP(
      mica_partition_create(disc->nparticles, disc->nquad, sp.ptr, sp.index, weights, nparts, &dist->partition));
  owners_from_nearest(dist->partition, disc->nquad, sp.nearest_volume, dist->volume_owner);
  for (int s = 0; s < disc->nsets; s++)
    owners_from_nearest(dist->partition, disc->sets[s].n, sp.nearest_set[s], dist->set_owner[s]);
  MICA_CALL_CLEANUP(count_ghosts(dist, &sp, disc->nquad, ghost_counts));
cleanup:
  supports_free(&sp, disc->nsets);
  free(weights);
  return ierr;
}

/* ---- broadcast ------------------------------------------------------------------------------------------- */

static void bcast_longs(long *v, long n) {
  for (long first = 0; first < n; first += 1L << 28) {
    const long count = n - first < (1L << 28) ? n - first : (1L << 28);
    MPI_Bcast(v + first, (int)count, MPI_LONG, 0, mica_parallel_comm());
  }
}

static void bcast_ints(int *v, long n) {
  for (long first = 0; first < n; first += 1L << 28) {
    const long count = n - first < (1L << 28) ? n - first : (1L << 28);
    MPI_Bcast(v + first, (int)count, MPI_INT, 0, mica_parallel_comm());
  }
}

/* Rank 0's partition to every rank (the others allocate theirs first). */
static int broadcast_partition(MicaDistribution *dist, const MicaDiscretization *disc, int root) {
  long header[3] = {0, 0, 0};
  double imbalance = 0;
  if (root) {
    header[0] = dist->partition->xadj[disc->nparticles];
    header[1] = dist->partition->edge_cut;
    imbalance = dist->partition->imbalance;
  }
  bcast_longs(header, 3);
  MPI_Bcast(&imbalance, 1, MPI_DOUBLE, 0, mica_parallel_comm());
  int ierr = MICA_SUCCESS;
  if (!root) {
    MicaPartition *p = NULL;
    ierr = MICA_CALLOC(p, 1);
    if (!ierr) {
      dist->partition = p;
      p->n = disc->nparticles;
      p->nparts = mica_parallel_size();
      ierr = MICA_MALLOC(p->xadj, p->n + 1);
      if (!ierr) ierr = MICA_MALLOC(p->adjncy, header[0] + 1);
      if (!ierr) ierr = MICA_MALLOC(p->part, p->n);
      if (!ierr) ierr = MICA_CALLOC(p->part_size, p->nparts);
    }
  }
  MICA_CALL(mica_parallel_agree(ierr));
  MicaPartition *p = dist->partition;
  p->edge_cut = header[1];
  p->imbalance = imbalance;
  bcast_longs(p->xadj, p->n + 1);
  bcast_longs(p->adjncy, header[0]);
  bcast_ints(p->part, p->n);
  bcast_longs(p->part_size, p->nparts);
  bcast_ints(dist->volume_owner, disc->nquad);
  for (int s = 0; s < disc->nsets; s++) bcast_ints(dist->set_owner[s], disc->sets[s].n);
  return MICA_SUCCESS;
}

/* ---- this rank's discretization ------------------------------------------------------------------------- */

static int copy_doubles(double **to, const double *from, long n) {
  MICA_CALL(MICA_MALLOC(*to, n + 1));
  if (n > 0) memcpy(*to, from, sizeof(double) * (size_t)n);
  return MICA_SUCCESS;
}

static int local_set(const MicaBoundarySet *set, const int *owner, int rank, int dim, MicaBoundarySet *out) {
  memset(out, 0, sizeof *out);
  memcpy(out->name, set->name, sizeof out->name);
  long n = 0;
  for (long q = 0; q < set->n; q++) n += owner[q] == rank;
  out->n = n;
  MICA_CALL(MICA_MALLOC(out->x, n * dim + 1));
  MICA_CALL(MICA_MALLOC(out->w, n + 1));
  MICA_CALL(MICA_MALLOC(out->normal, n * dim + 1));
  MICA_CALL(MICA_MALLOC(out->element, n + 1));
  MICA_CALL(MICA_MALLOC(out->lambda_N, n * 4 + 1));
  long k = 0;
  for (long q = 0; q < set->n; q++) {
    if (owner[q] != rank) continue;
    memcpy(out->x + k * dim, set->x + q * dim, sizeof(double) * (size_t)dim);
    memcpy(out->normal + k * dim, set->normal + q * dim, sizeof(double) * (size_t)dim);
    out->w[k] = set->w[q];
    out->element[k] = set->element ? set->element[q] : 0;
    if (set->lambda_N) memcpy(out->lambda_N + k * 4, set->lambda_N + q * 4, sizeof(double) * 4);
    k++;
  }
  out->nvertices = set->nvertices;
  MICA_CALL(copy_doubles(&out->vertex_x, set->vertex_x, set->nvertices * dim));
  out->nelements = set->nelements;
  out->element_size = set->element_size;
  const long nev = set->nelements * set->element_size;
  MICA_CALL(MICA_MALLOC(out->element_vertices, nev + 1));
  if (nev > 0) memcpy(out->element_vertices, set->element_vertices, sizeof(long) * (size_t)nev);
  return MICA_SUCCESS;
}

static int local_discretization(const MicaDiscretization *disc, const MicaDistribution *dist, int rank,
                                MicaDiscretization **out) {
  MicaDiscretization *d = NULL;
  const int dim = disc->dim;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(d, 1));
  d->dim = dim;
  d->nparticles = disc->nparticles;
  d->ncells = disc->ncells;
  d->volume = disc->volume;
  d->boundary_uncovered = disc->boundary_uncovered;
  MICA_CALL_CLEANUP(copy_doubles(&d->x, disc->x, disc->nparticles * dim));
  long n = 0;
  for (long q = 0; q < disc->nquad; q++) n += dist->volume_owner[q] == rank;
  d->nquad = n;
  MICA_CALL_CLEANUP(MICA_MALLOC(d->qx, n * dim + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(d->qw, n + 1));
  long k = 0;
  for (long q = 0; q < disc->nquad; q++) {
    if (dist->volume_owner[q] != rank) continue;
    memcpy(d->qx + k * dim, disc->qx + q * dim, sizeof(double) * (size_t)dim);
    d->qw[k++] = disc->qw[q];
  }
  MICA_CALL_CLEANUP(MICA_CALLOC(d->sets, disc->nsets + 1));
  d->nsets = disc->nsets;
  for (int s = 0; s < disc->nsets; s++)
    MICA_CALL_CLEANUP(local_set(&disc->sets[s], dist->set_owner[s], rank, dim, &d->sets[s]));
  *out = d;
  return MICA_SUCCESS;
cleanup:
  mica_discretization_destroy(&d);
  return ierr;
}

/* ---- public -------------------------------------------------------------------------------------------- */

int mica_distribution_create(const MicaDiscretization *disc, const MlsApprox *mls, MicaDistribution **out) {
  *out = NULL;
  const int rank = mica_parallel_rank(), nparts = mica_parallel_size(), root = rank == 0;
  const double start = mica_wtime();
  MicaDistribution *dist = NULL;
  long *ghost_counts = NULL;
  int ierr = MICA_CALLOC(dist, 1);
  if (!ierr) {
    dist->nparticles = disc->nparticles;
    dist->nsets = disc->nsets;
    ierr = MICA_MALLOC(dist->volume_owner, disc->nquad + 1);
  }
  if (!ierr) ierr = MICA_CALLOC(dist->set_owner, disc->nsets + 1);
  for (int s = 0; s < disc->nsets && !ierr; s++) ierr = MICA_MALLOC(dist->set_owner[s], disc->sets[s].n + 1);
  if (!ierr) ierr = MICA_CALLOC(ghost_counts, nparts);
  if (!ierr && root) ierr = partition_on_root(dist, disc, mls, nparts, ghost_counts);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(broadcast_partition(dist, disc, root));
  bcast_longs(ghost_counts, nparts);
  ierr = local_discretization(disc, dist, rank, &dist->local);
  if (!ierr) ierr = mica_parallel_inject("build");
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MicaParallelStats *st = &dist->stats;
  st->owned_particles = dist->partition->part_size[rank];
  st->ghost_particles = ghost_counts[rank];
  st->ghost_particles_max = 0;
  for (int r = 0; r < nparts; r++)
    if (ghost_counts[r] > st->ghost_particles_max) st->ghost_particles_max = ghost_counts[r];
  st->owned_points = dist->local->nquad;
  MPI_Allreduce(&st->owned_points, &st->max_owned_points, 1, MPI_LONG, MPI_MAX, mica_parallel_comm());
  MPI_Allreduce(&st->owned_points, &st->min_owned_points, 1, MPI_LONG, MPI_MIN, mica_parallel_comm());
  st->time_partition = mica_wtime() - start;
  *out = dist;
  dist = NULL;
cleanup:
  free(ghost_counts);
  mica_distribution_destroy(&dist);
  return ierr;
}

int mica_distribution_destroy(MicaDistribution **distribution) {
  MicaDistribution *dist = *distribution;
  if (!dist) return MICA_SUCCESS;
  mica_partition_destroy(&dist->partition);
  parallel_owned_free(dist);
  free(dist->volume_owner);
  if (dist->set_owner)
    for (int s = 0; s < dist->nsets; s++) free(dist->set_owner[s]);
  free(dist->set_owner);
  mica_discretization_destroy(&dist->local);
  MICA_FREE(*distribution);
  return MICA_SUCCESS;
}
