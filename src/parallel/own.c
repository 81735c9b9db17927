/* parallel.data = "distributed": each rank owns a block of a built-in shape's particle index grid and the
 * background cells of the same block of the cell grid, and holds only those, their quadrature and boundary
 * points and the ghost particles its points' supports reach (parallel.h). No partitioner: the grids are split
 * as PETSc's DMDA splits its index box, P factored into blocks per axis. A particle's owner and its number in
 * the ranks' contiguous numbering follow from its grid index and the O(P) block sizes, on any rank.
 *
 * This first step still builds the whole discretization and MLS search on every rank and cuts this rank's share
 * out of it (the search is run for this rank's points only); the caller frees the whole one before the solid
 * is built. */
#include <math.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "mica/geom.h"
#include "mica/parallel.h"
#include "mica/timer.h"
#include "parallel_private.h"

/* ---- the block split --------------------------------------------------------------------------------------- */

/* Interface between blocks, in cell faces: Σ_d (p_d − 1) Π_{e≠d} n_e. */
static double split_cost(int dim, const long n[3], const int p[3]) {
  double cost = 0;
  for (int d = 0; d < dim; d++) {
    double area = (double)(p[d] - 1);
    for (int e = 0; e < dim; e++)
      if (e != d) area *= (double)n[e];
    cost += area;
  }
  return cost;
}

int mica_block_split(int P, int dim, const long cells[3], int procs[3]) {
  double best = -1;
  procs[0] = procs[1] = procs[2] = 1;
  for (int p0 = 1; p0 <= P; p0++) {
    if (P % p0) continue;
    for (int p1 = 1; p1 <= P / p0; p1++) {
      if ((P / p0) % p1) continue;
      const int p[3] = {p0, p1, P / p0 / p1};
      if (dim < 3 && p[2] != 1) continue;
      if (dim < 2 && p[1] != 1) continue;
      int fits = 1;
      for (int d = 0; d < 3; d++) fits &= p[d] <= cells[d];
      if (!fits) continue;
      const double cost = split_cost(dim, cells, p);
      if (best < 0 || cost < best) best = cost, memcpy(procs, p, sizeof p);
    }
  }
  MICA_CHECK(best >= 0, MICA_ERR_INPUT,
             "parallel.data = \"distributed\": %d ranks cannot split the %ld × %ld × %ld background cells into one "
             "block each; use fewer ranks or more cells", P, cells[0], cells[1], cells[2]);
  return MICA_SUCCESS;
}

static long block_lo(long n, int p, int k) { return n * k / p; }

/* The block along an axis that index i falls in. */
static int block_of(long i, long n, int p) {
  int k = (int)(i * p / n);
  while (k + 1 < p && block_lo(n, p, k + 1) <= i) k++;
  while (k > 0 && block_lo(n, p, k) > i) k--;
  return k;
}

static void rank_block(int rank, const int procs[3], int b[3]) {
  b[0] = rank % procs[0], b[1] = (rank / procs[0]) % procs[1], b[2] = rank / (procs[0] * procs[1]);
}

/* Rank r's box [lo, hi) of a grid of n[3]. */
static void block_box(int r, const int procs[3], const long n[3], long lo[3], long hi[3]) {
  int b[3];
  rank_block(r, procs, b);
  for (int d = 0; d < 3; d++) lo[d] = block_lo(n[d], procs[d], b[d]), hi[d] = block_lo(n[d], procs[d], b[d] + 1);
}

static long box_size(const long lo[3], const long hi[3]) { return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); }

static void grid_index(long t, const long n[3], long idx[3]) {
  idx[0] = t % n[0], t /= n[0];
  idx[1] = t % n[1], idx[2] = t / n[1];
}

static int in_box(const long idx[3], const long lo[3], const long hi[3]) {
  for (int d = 0; d < 3; d++)
    if (idx[d] < lo[d] || idx[d] >= hi[d]) return 0;
  return 1;
}

/* The owner of grid particle t and its number in the ranks' contiguous numbering (offsets[P]: the lower ranks'
 * particles before each rank). */
static long global_number(long t, const long n[3], const int procs[3], const long *offsets, int *owner) {
  long idx[3], lo[3], hi[3];
  int b[3];
  grid_index(t, n, idx);
  for (int d = 0; d < 3; d++) b[d] = block_of(idx[d], n[d], procs[d]);
  const int r = b[0] + procs[0] * (b[1] + procs[1] * b[2]);
  block_box(r, procs, n, lo, hi);
  *owner = r;
  return offsets[r] + (idx[0] - lo[0]) + (hi[0] - lo[0]) * ((idx[1] - lo[1]) + (hi[1] - lo[1]) * (idx[2] - lo[2]));
}

/* ---- the particles the rank's points need ----------------------------------------------------------------- */

static int compare_long(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

static long sort_unique(long *v, long n) {
  qsort(v, (size_t)n, sizeof *v, compare_long);
  long m = 0;
  for (long i = 0; i < n; i++)
    if (!m || v[i] != v[m - 1]) v[m++] = v[i];
  return m;
}

/* set ∪= the supports of x[n·dim], searched in chunks so that only the distinct particles are kept. */
static int add_supports(const MlsApprox *mls, long n, const double *x, long **set, long *nset) {
  enum { CHUNK = 4096 };
  const int dim = mls_dim(mls);
  for (long first = 0; first < n; first += CHUNK) {
    const long count = n - first < CHUNK ? n - first : CHUNK;
    long *ptr = NULL, *index = NULL, *merged = NULL;
    MICA_CALL(mica_point_supports(mls, count, x + first * dim, &ptr, &index, NULL));
    const long found = sort_unique(index, ptr[count]);
    int ierr = MICA_MALLOC(merged, *nset + found + 1);
    long m = 0, i = 0, j = 0;
    while (!ierr && (i < *nset || j < found)) {
      const long a = i < *nset ? (*set)[i] : -1, b = j < found ? index[j] : -1;
      if (j >= found || (i < *nset && a < b)) merged[m++] = a, i++;
      else if (i >= *nset || b < a) merged[m++] = b, j++;
      else merged[m++] = a, i++, j++;
    }
    free(ptr);
    free(index);
    MICA_CALL(ierr);
    free(*set);
    *set = merged, *nset = m;
  }
  return MICA_SUCCESS;
}

/* ---- this rank's discretization --------------------------------------------------------------------------- */

static int cell_owned(long c, const MicaDiscretization *disc, const long lo[3], const long hi[3]) {
  long idx[3];
  grid_index(c, disc->grid_cells, idx);
  return in_box(idx, lo, hi);
}

static int local_volume(const MicaDiscretization *disc, const long lo[3], const long hi[3], MicaDiscretization *d) {
  const int dim = disc->dim;
  const long per = disc->grid_points_per_cell, ncells = disc->nquad / per;
  long n = 0, k = 0;
  for (long c = 0; c < ncells; c++) n += cell_owned(c, disc, lo, hi);
  d->ncells = n;
  d->nquad = n * per;
  MICA_CALL(MICA_MALLOC(d->qx, d->nquad * dim + 1));
  MICA_CALL(MICA_MALLOC(d->qw, d->nquad + 1));
  for (long c = 0; c < ncells; c++) {
    if (!cell_owned(c, disc, lo, hi)) continue;
    memcpy(d->qx + k * dim, disc->qx + c * per * dim, sizeof(double) * (size_t)(per * dim));
    memcpy(d->qw + k, disc->qw + c * per, sizeof(double) * (size_t)per);
    k += per;
  }
  for (long q = 0; q < d->nquad; q++) d->volume += d->qw[q]; /* this rank's part: summed once built */
  return MICA_SUCCESS;
}

/* The set's points on this rank's cells (no boundary vertices or elements: the multipliers are refused). */
static int local_set(const MicaDiscretization *disc, const MicaBoundarySet *set, const long lo[3], const long hi[3],
                     MicaBoundarySet *out) {
  const int dim = disc->dim;
  memset(out, 0, sizeof *out);
  memcpy(out->name, set->name, sizeof out->name);
  MICA_CHECK(set->grid_cell, MICA_ERR_ARGUMENT, "boundary set '%s' has no grid cells", set->name);
  long n = 0, k = 0;
  for (long q = 0; q < set->n; q++) n += cell_owned(set->grid_cell[q], disc, lo, hi);
  out->n = n;
  out->element_size = set->element_size;
  MICA_CALL(MICA_MALLOC(out->x, n * dim + 1));
  MICA_CALL(MICA_MALLOC(out->w, n + 1));
  MICA_CALL(MICA_MALLOC(out->normal, n * dim + 1));
  MICA_CALL(MICA_MALLOC(out->element, n + 1));
  MICA_CALL(MICA_MALLOC(out->lambda_N, n * 4 + 1));
  for (long q = 0; q < set->n; q++) {
    if (!cell_owned(set->grid_cell[q], disc, lo, hi)) continue;
    memcpy(out->x + k * dim, set->x + q * dim, sizeof(double) * (size_t)dim);
    memcpy(out->normal + k * dim, set->normal + q * dim, sizeof(double) * (size_t)dim);
    memcpy(out->lambda_N + k * 4, set->lambda_N + q * 4, sizeof(double) * 4);
    out->w[k] = set->w[q];
    out->element[k] = set->element[q];
    k++;
  }
  return MICA_SUCCESS;
}

/* The local particles: the owned block (grid order), then the ghosts (ascending grid index); their owners and
 * contiguous numbers. grid[]: the grid index of each. */
static int local_particles(const MicaDiscretization *disc, MicaDistribution *dist, const long *needed, long nneeded,
                           const long *offsets, long **grid_out, MicaDiscretization *d) {
  const int dim = disc->dim, rank = mica_parallel_rank();
  const long *n = disc->grid_particles;
  long lo[3], hi[3], *grid = NULL;
  block_box(rank, dist->procs, n, lo, hi);
  dist->nowned = box_size(lo, hi);
  long nghost = 0;
  for (long k = 0; k < nneeded; k++) {
    long idx[3];
    grid_index(needed[k], n, idx);
    nghost += !in_box(idx, lo, hi);
  }
  dist->nghost = nghost;
  const long nlocal = dist->nowned + nghost;
  MICA_CALL(MICA_MALLOC(grid, nlocal + 1));
  long m = 0;
  for (long i2 = lo[2]; i2 < hi[2]; i2++)
    for (long i1 = lo[1]; i1 < hi[1]; i1++)
      for (long i0 = lo[0]; i0 < hi[0]; i0++) grid[m++] = i0 + n[0] * (i1 + n[1] * i2);
  for (long k = 0; k < nneeded; k++) {
    long idx[3];
    grid_index(needed[k], n, idx);
    if (!in_box(idx, lo, hi)) grid[m++] = needed[k];
  }
  *grid_out = grid;
  d->nparticles = nlocal;
  MICA_CALL(MICA_MALLOC(d->x, nlocal * dim + 1));
  MICA_CALL(MICA_MALLOC(dist->global_node, nlocal + 1));
  MicaPartition *p = dist->partition;
  p->n = nlocal;
  MICA_CALL(MICA_MALLOC(p->part, nlocal + 1));
  for (long i = 0; i < nlocal; i++) {
    memcpy(d->x + i * dim, disc->x + grid[i] * dim, sizeof(double) * (size_t)dim);
    dist->global_node[i] = global_number(grid[i], n, dist->procs, offsets, &p->part[i]);
  }
  return MICA_SUCCESS;
}

/* The MLS approximation of the local particles with the whole run's radii and local spacings (a ghost at the
 * layer's edge would get other ones from its truncated neighborhood; the spacings are the boundary methods' h). */
static int local_mls(const MlsApprox *mls, const MlsOptions *mls_opt, const long *grid, MicaDistribution *dist) {
  const MicaDiscretization *d = dist->local;
  const int dim = d->dim;
  const double *radii = mls_radii(mls), *spacing = mls_spacing(mls);
  double *local = NULL;
  MICA_CALL(mls_create(dim, d->nparticles, d->x, mls_opt, &dist->mls));
  MICA_CALL(MICA_MALLOC(local, d->nparticles * dim + 1));
  for (long i = 0; i < d->nparticles; i++)
    memcpy(local + i * dim, radii + grid[i] * dim, sizeof(double) * (size_t)dim);
  int ierr = mls_set_radii(dist->mls, local);
  for (long i = 0; i < d->nparticles; i++)
    memcpy(local + i * dim, spacing + grid[i] * dim, sizeof(double) * (size_t)dim);
  if (!ierr) ierr = mls_set_spacing(dist->mls, local);
  free(local);
  return ierr;
}

/* ---- the ghost plan --------------------------------------------------------------------------------------- */

/* Each ghost is asked of its owner by its position in the owner's block: the owners learn what to send. */
static int ghost_plan(MicaDistribution *dist, const long *offsets) {
  MicaGhostPlan *g = &dist->ghosts;
  const int P = mica_parallel_size();
  long *request = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(g->send_counts, P + 1));
  MICA_CALL(MICA_CALLOC(g->send_displs, P + 1));
  MICA_CALL(MICA_CALLOC(g->recv_counts, P + 1));
  MICA_CALL(MICA_CALLOC(g->recv_displs, P + 1));
  MICA_CALL(MICA_CALLOC(g->scaled, 4L * P + 4));
  MICA_CALL(MICA_MALLOC(g->recv_index, dist->nghost + 1));
  MICA_CALL(MICA_MALLOC(request, dist->nghost + 1));
  const int *part = dist->partition->part;
  for (long i = dist->nowned; i < dist->nowned + dist->nghost; i++) g->recv_counts[part[i]]++;
  for (int r = 0; r < P; r++) g->recv_displs[r + 1] = g->recv_displs[r] + g->recv_counts[r];
  int *cursor = g->scaled; /* scratch, before its use per exchange */
  for (int r = 0; r < P; r++) cursor[r] = g->recv_displs[r];
  for (long i = dist->nowned; i < dist->nowned + dist->nghost; i++) {
    const int k = cursor[part[i]]++;
    g->recv_index[k] = i;
    request[k] = dist->global_node[i] - offsets[part[i]];
  }
  MPI_Alltoall(g->recv_counts, 1, MPI_INT, g->send_counts, 1, MPI_INT, mica_parallel_comm());
  for (int r = 0; r < P; r++) g->send_displs[r + 1] = g->send_displs[r] + g->send_counts[r];
  ierr = MICA_MALLOC(g->send_index, (long)g->send_displs[P] + 1);
  if (!ierr) {
    MPI_Alltoallv(request, g->recv_counts, g->recv_displs, MPI_LONG, g->send_index, g->send_counts, g->send_displs,
                  MPI_LONG, mica_parallel_comm());
    for (int k = 0; k < g->send_displs[P]; k++)
      if (g->send_index[k] < 0 || g->send_index[k] >= dist->nowned)
        ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "ghost plan: position %ld of %ld",
                              g->send_index[k], dist->nowned);
  }
  free(request);
  return ierr;
}

static void ghost_plan_free(MicaGhostPlan *g) {
  free(g->send_counts), free(g->send_displs), free(g->recv_counts), free(g->recv_displs);
  free(g->send_index), free(g->recv_index), free(g->scaled), free(g->send_buffer), free(g->recv_buffer);
  memset(g, 0, sizeof *g);
}

/* counts and displacements × ncomp, and buffers large enough. */
static int scale_plan(MicaGhostPlan *g, int ncomp, int **sc, int **sd, int **rc, int **rd) {
  const int P = mica_parallel_size();
  *sc = g->scaled, *sd = g->scaled + P, *rc = g->scaled + 2 * P, *rd = g->scaled + 3 * P;
  for (int r = 0; r < P; r++) {
    (*sc)[r] = g->send_counts[r] * ncomp, (*sd)[r] = g->send_displs[r] * ncomp;
    (*rc)[r] = g->recv_counts[r] * ncomp, (*rd)[r] = g->recv_displs[r] * ncomp;
  }
  const long need = ((long)g->send_displs[P] > (long)g->recv_displs[P] ? g->send_displs[P] : g->recv_displs[P]) *
                    (long)ncomp + 1;
  if (need <= g->buffer_size) return MICA_SUCCESS;
  free(g->send_buffer), free(g->recv_buffer);
  g->send_buffer = g->recv_buffer = NULL;
  g->buffer_size = 0;
  MICA_CALL(MICA_MALLOC(g->send_buffer, need));
  MICA_CALL(MICA_MALLOC(g->recv_buffer, need));
  g->buffer_size = need;
  return MICA_SUCCESS;
}

int mica_ghost_update(MicaDistribution *dist, double *v, int ncomp) {
  MicaGhostPlan *g = &dist->ghosts;
  const int P = mica_parallel_size();
  int *sc, *sd, *rc, *rd;
  MICA_CALL(mica_parallel_agree(scale_plan(g, ncomp, &sc, &sd, &rc, &rd)));
  for (long k = 0; k < g->send_displs[P]; k++)
    memcpy(g->send_buffer + k * ncomp, v + g->send_index[k] * ncomp, sizeof(double) * (size_t)ncomp);
  MPI_Alltoallv(g->send_buffer, sc, sd, MPI_DOUBLE, g->recv_buffer, rc, rd, MPI_DOUBLE, mica_parallel_comm());
  for (long k = 0; k < g->recv_displs[P]; k++)
    memcpy(v + g->recv_index[k] * ncomp, g->recv_buffer + k * ncomp, sizeof(double) * (size_t)ncomp);
  return MICA_SUCCESS;
}

int mica_ghost_sum(MicaDistribution *dist, int ierr, double *v, int ncomp) {
  MicaGhostPlan *g = &dist->ghosts;
  const int P = mica_parallel_size();
  int *sc, *sd, *rc, *rd;
  if (!ierr) ierr = scale_plan(g, ncomp, &sc, &sd, &rc, &rd);
  MICA_CALL(mica_parallel_agree(ierr));
  for (long k = 0; k < g->recv_displs[P]; k++)
    memcpy(g->recv_buffer + k * ncomp, v + g->recv_index[k] * ncomp, sizeof(double) * (size_t)ncomp);
  /* the reverse of the update: ghosts to owners, added in rank order (the same sums on every run) */
  MPI_Alltoallv(g->recv_buffer, rc, rd, MPI_DOUBLE, g->send_buffer, sc, sd, MPI_DOUBLE, mica_parallel_comm());
  for (long k = 0; k < g->send_displs[P]; k++)
    for (int c = 0; c < ncomp; c++) v[g->send_index[k] * ncomp + c] += g->send_buffer[k * ncomp + c];
  return mica_ghost_update(dist, v, ncomp);
}

int mica_owned_residual(MicaDistribution *dist, int ierr, double *R, int ncomp) {
  if (!ierr) ierr = mica_parallel_inject("assemble");
  return mica_ghost_sum(dist, ierr, R, ncomp);
}

int mica_owned_norm(const MicaDistribution *dist, const double *v, int ncomp, double *norm) {
  double s = 0;
  for (long i = 0; i < dist->nowned * ncomp; i++) s += v[i] * v[i];
  MICA_CALL(mica_parallel_sum(MICA_SUCCESS, &s, 1));
  *norm = sqrt(s);
  return MICA_SUCCESS;
}

/* ---- public ----------------------------------------------------------------------------------------------- */

static int check_grid(const MicaDiscretization *disc) {
  MICA_CHECK(disc->grid_points_per_cell > 0 && !disc->nodal, MICA_ERR_INPUT,
             "parallel.data = \"distributed\" needs a built-in shape with a regular, graded or jittered particle "
             "layout and background-cell quadrature (an index grid to split); use parallel.data = \"replicated\"");
  return MICA_SUCCESS;
}

static int build_owned(const MicaDiscretization *disc, const MlsApprox *mls, const MlsOptions *mls_opt,
                       MicaDistribution *dist) {
  const int P = mica_parallel_size(), rank = mica_parallel_rank();
  long lo[3], hi[3], *offsets = NULL, *needed = NULL, nneeded = 0, *grid = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(check_grid(disc));
  MICA_CALL(mica_block_split(P, disc->dim, disc->grid_cells, dist->procs));
  for (int d = 0; d < disc->dim; d++)
    MICA_CHECK(dist->procs[d] <= disc->grid_particles[d], MICA_ERR_INPUT,
               "parallel.data = \"distributed\": %d blocks along axis %d for %ld particles; use fewer ranks",
               dist->procs[d], d, disc->grid_particles[d]);
  MICA_CALL(MICA_CALLOC(dist->partition, 1));
  MicaPartition *p = dist->partition;
  p->nparts = P;
  MICA_CALL(MICA_CALLOC(p->part_size, P + 1));
  MICA_CALL(MICA_CALLOC(offsets, P + 1));
  for (int r = 0; r < P; r++) {
    block_box(r, dist->procs, disc->grid_particles, lo, hi);
    p->part_size[r] = box_size(lo, hi);
    offsets[r + 1] = offsets[r] + p->part_size[r];
  }
  p->imbalance = (double)p->part_size[0] * P / (double)offsets[P];
  for (int r = 1; r < P; r++)
    if ((double)p->part_size[r] * P / (double)offsets[P] > p->imbalance)
      p->imbalance = (double)p->part_size[r] * P / (double)offsets[P];
  MICA_CALL_CLEANUP(MICA_CALLOC(dist->local, 1));
  MicaDiscretization *d = dist->local;
  d->dim = disc->dim;
  block_box(rank, dist->procs, disc->grid_cells, lo, hi);
  MICA_CALL_CLEANUP(local_volume(disc, lo, hi, d));
  MICA_CALL_CLEANUP(MICA_CALLOC(d->sets, disc->nsets + 1));
  d->nsets = disc->nsets;
  for (int s = 0; s < disc->nsets; s++) MICA_CALL_CLEANUP(local_set(disc, &disc->sets[s], lo, hi, &d->sets[s]));
  MICA_CALL_CLEANUP(add_supports(mls, d->nquad, d->qx, &needed, &nneeded));
  for (int s = 0; s < d->nsets; s++) MICA_CALL_CLEANUP(add_supports(mls, d->sets[s].n, d->sets[s].x, &needed, &nneeded));
  MICA_CALL_CLEANUP(local_particles(disc, dist, needed, nneeded, offsets, &grid, d));
  MICA_CALL_CLEANUP(local_mls(mls, mls_opt, grid, dist));
  MICA_CALL_CLEANUP(ghost_plan(dist, offsets));
cleanup:
  free(offsets), free(needed), free(grid);
  return ierr;
}

int mica_distribution_create_owned(const MicaDiscretization *disc, const MlsApprox *mls, const MlsOptions *mls_opt,
                                   const MicaParallelOptions *opt, MicaDistribution **out) {
  *out = NULL;
  const double start = mica_wtime();
  MicaDistribution *dist = NULL;
  int ierr = MICA_CALLOC(dist, 1);
  if (!ierr) {
    dist->opt = *opt;
    dist->owned = 1;
    dist->nsets = disc->nsets;
    ierr = build_owned(disc, mls, mls_opt, dist);
  }
  if (!ierr) ierr = mica_parallel_inject("build");
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  /* the body's volume, not the rank's part (the penalty's length scale L = volume^(1/dim) is the body's) */
  MICA_CALL_CLEANUP(mica_parallel_sum(MICA_SUCCESS, &dist->local->volume, 1));
  dist->nparticles = mica_parallel_sum_long(dist->nowned);
  MicaParallelStats *st = &dist->stats;
  st->owned_particles = dist->nowned;
  st->ghost_particles = dist->nghost;
  st->ghost_particles_max = mica_parallel_max_long(dist->nghost);
  st->owned_points = dist->local->nquad;
  MPI_Allreduce(&st->owned_points, &st->max_owned_points, 1, MPI_LONG, MPI_MAX, mica_parallel_comm());
  MPI_Allreduce(&st->owned_points, &st->min_owned_points, 1, MPI_LONG, MPI_MIN, mica_parallel_comm());
  st->time_partition = mica_wtime() - start;
  *out = dist;
  dist = NULL;
cleanup:
  mica_distribution_destroy(&dist);
  return ierr;
}

void parallel_owned_free(MicaDistribution *dist) {
  ghost_plan_free(&dist->ghosts);
  free(dist->global_node);
  dist->global_node = NULL;
  mls_destroy(&dist->mls);
}
