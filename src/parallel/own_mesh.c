/* parallel.data = "distributed" for a Gmsh mesh (parallel.h, mica_distribution_create_owned_mesh): the particles
 * (the mesh's nodes) split into one box of coordinates per rank, the volume elements owned by the box that holds
 * their centroid, and the boundary elements by the owner of the volume element they bound.
 *
 * The boxes: P factored into blocks per axis (mica_block_split, on the bounding box measured in mean spacings), then
 * cut by coordinates as a recursive coordinate bisection would, but axis after axis: slabs of equal node counts
 * along x, columns of equal counts along y within each slab, blocks along z within each column. A cut lies halfway
 * between two distinct coordinates, so a particle's block follows from its coordinates and the O(P) cuts alone.
 *
 * The cuts come from a sample of the nodes (MicaMeshSource: at most 2^18, the same on every rank), so the boxes hold
 * about equal shares. Each rank reads the region of the mesh within a reach R of its box (the nodes there and the
 * elements whose nodes all lie there: a .msh file is read through a filter, never whole), sizes the supports of the
 * region's particles there (their local spacings and radii are those of the whole mesh when they lie deep enough
 * inside it, as own.c's grid boxes do with layers), searches the supports of its points and keeps the owned
 * particles and the ghosts they reach. R doubles until the needed particles lie `margin` spacings inside every face
 * of the region that cuts the mesh, and no particle beyond it can reach the rank's points. A particle is numbered
 * within its owner in the order of the mesh's nodes (the serial order); a ghost's number comes from its owner, asked
 * by the particle's key (its node's position in the whole mesh). */
#include <math.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "mica/geom.h"
#include "mica/parallel.h"
#include "mica/timer.h"
#include "parallel_private.h"

/* ---- the boxes ------------------------------------------------------------------------------------------ */

typedef struct {
  int dim, procs[3];
  double *cut[3]; /* axis 0: [p0 + 1]; axis 1: [p0][p1 + 1]; axis 2: [p0·p1][p2 + 1]; ±HUGE_VAL at the ends */
} MeshBoxes;

static void boxes_free(MeshBoxes *b) {
  for (int d = 0; d < 3; d++) free(b->cut[d]);
  memset(b, 0, sizeof *b);
}

/* The cuts of the column `column` along `axis`. */
static double *column_cuts(const MeshBoxes *b, int axis, long column) { return b->cut[axis] + column * (b->procs[axis] + 1); }

/* Along each axis, the block whose [cut_k, cut_k+1) holds x; the rank b0 + p0 (b1 + p1 b2), as own.c's grid. */
static int box_of(const MeshBoxes *b, const double *x) {
  long column = 0;
  int k[3] = {0, 0, 0};
  for (int d = 0; d < 3; d++) {
    const double *cut = column_cuts(b, d, column), xd = d < b->dim ? x[d] : 0.0;
    int lo = 0, hi = b->procs[d]; /* the last block whose lower cut is ≤ x */
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      if (cut[mid] <= xd) lo = mid;
      else hi = mid;
    }
    k[d] = lo;
    column = column * b->procs[d] + lo;
  }
  return k[0] + b->procs[0] * (k[1] + b->procs[1] * k[2]);
}

/* Rank r's box [lo, hi) (infinite where it reaches the end of an axis). */
static void box_bounds(const MeshBoxes *b, int r, double lo[3], double hi[3]) {
  const int k[3] = {r % b->procs[0], (r / b->procs[0]) % b->procs[1], r / (b->procs[0] * b->procs[1])};
  long column = 0;
  for (int d = 0; d < 3; d++) {
    const double *cut = column_cuts(b, d, column);
    lo[d] = cut[k[d]], hi[d] = cut[k[d] + 1];
    column = column * b->procs[d] + k[d];
  }
}

typedef struct {
  double key;
  long index;
} Keyed;

static int compare_keyed(const void *a, const void *b) {
  const Keyed *x = a, *y = b;
  if (x->key != y->key) return (x->key > y->key) - (x->key < y->key);
  return (x->index > y->index) - (x->index < y->index);
}

/* cut[0 .. p]: p blocks of about equal counts of the m particles `member` along `axis`, each cut halfway between
 * two distinct coordinates (the nearest such gap to the equal share). */
static int cut_axis(const double *x, int dim, const long *member, long m, int axis, int p, double *cut) {
  cut[0] = -HUGE_VAL, cut[p] = HUGE_VAL;
  if (p == 1) return MICA_SUCCESS;
  Keyed *v = NULL;
  MICA_CALL(MICA_MALLOC(v, m + 1));
  for (long i = 0; i < m; i++) v[i] = (Keyed){x[member[i] * dim + axis], member[i]};
  qsort(v, (size_t)m, sizeof *v, compare_keyed);
  int ierr = MICA_SUCCESS;
  for (int k = 1; k < p && !ierr; k++) {
    const long want = m * k / p;
    long at = -1;
    for (long step = 0; at < 0 && (want - step > 0 || want + step < m); step++) {
      if (want - step > 0 && want - step < m && v[want - step - 1].key < v[want - step].key) at = want - step;
      else if (want + step > 0 && want + step < m && v[want + step - 1].key < v[want + step].key) at = want + step;
    }
    const double c = at > 0 ? 0.5 * (v[at - 1].key + v[at].key) : 0;
    if (at <= 0 || !(c > cut[k - 1]))
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                            "parallel.data = \"distributed\": %d blocks along axis %d cannot split the mesh's %ld "
                            "particles there by distinct coordinates; use fewer ranks", p, axis, m);
    cut[k] = c;
  }
  free(v);
  return ierr;
}

/* The blocks per axis: the mesh's bounding box in mean spacings (volume per particle)^(1/dim) is the "grid" that
 * mica_block_split factors P over. */
static int split_mesh(int P, int dim, long n, const double *x, int procs[3]) {
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, volume = 1;
  for (int d = 0; d < dim; d++) lo[d] = HUGE_VAL, hi[d] = -HUGE_VAL;
  for (long i = 0; i < n; i++)
    for (int d = 0; d < dim; d++) lo[d] = fmin(lo[d], x[i * dim + d]), hi[d] = fmax(hi[d], x[i * dim + d]);
  for (int d = 0; d < dim; d++) volume *= fmax(hi[d] - lo[d], 1e-300);
  const double h = pow(volume / (double)(n > 1 ? n : 1), 1.0 / dim);
  long cells[3] = {1, 1, 1};
  for (int d = 0; d < dim; d++) cells[d] = (long)fmax(1.0, round((hi[d] - lo[d]) / h));
  return mica_block_split(P, dim, cells, procs);
}

/* Axis after axis: the particles of each column (their blocks along the earlier axes) cut along the next one;
 * column[i] the particle's column so far, the members grouped by column with a counting sort. */
static int boxes_create(int P, int dim, long n, const double *x, MeshBoxes *b) {
  long *member = NULL, *column = NULL, *first = NULL;
  memset(b, 0, sizeof *b);
  b->dim = dim;
  MICA_CALL(split_mesh(P, dim, n, x, b->procs));
  const int *p = b->procs;
  int ierr = MICA_MALLOC(b->cut[0], p[0] + 1);
  if (!ierr) ierr = MICA_MALLOC(b->cut[1], (long)p[0] * (p[1] + 1));
  if (!ierr) ierr = MICA_MALLOC(b->cut[2], (long)p[0] * p[1] * (p[2] + 1));
  if (!ierr) ierr = MICA_MALLOC(member, n + 1);
  if (!ierr) ierr = MICA_CALLOC(column, n + 1);
  if (!ierr) ierr = MICA_MALLOC(first, (long)P + 2);
  long columns = 1;
  for (int d = 0; d < 3 && !ierr; d++) {
    for (long c = 0; c <= columns; c++) first[c] = 0;
    for (long i = 0; i < n; i++) first[column[i] + 1]++;
    for (long c = 0; c < columns; c++) first[c + 1] += first[c];
    for (long i = 0; i < n; i++) member[first[column[i]]++] = i; /* first[c]: now the end of column c */
    for (long c = 0; c < columns && !ierr; c++) {
      const long lo = c ? first[c - 1] : 0;
      double *cut = column_cuts(b, d, c);
      if (d < dim) ierr = cut_axis(x, dim, member + lo, first[c] - lo, d, p[d], cut);
      else cut[0] = -HUGE_VAL, cut[1] = HUGE_VAL;
    }
    for (long i = 0; i < n && !ierr; i++) { /* the block along d within the particle's column */
      const double *cut = column_cuts(b, d, column[i]), xd = d < dim ? x[i * dim + d] : 0.0;
      int k = 0;
      while (k + 1 < p[d] && cut[k + 1] <= xd) k++;
      column[i] = column[i] * p[d] + k;
    }
    columns *= p[d];
  }
  free(member), free(column), free(first);
  if (ierr) boxes_free(b);
  return ierr;
}

/* ---- the rank's region ----------------------------------------------------------------------------------- */

typedef struct {
  const MeshBoxes *boxes;
  int rank;
} KeepRank;

static int keep_rank(const double *centroid, void *ctx) {
  const KeepRank *k = ctx;
  return box_of(k->boxes, centroid) == k->rank;
}

/* The rank's source: the region within `reach` of its box, the MLS approximation of the region's particles, the zone
 * of owned-only supports (the box itself), its part of the region and the part's points. */
typedef struct {
  double lo[3], hi[3]; /* the region's box */
  MicaMesh *region, *part;
  MlsApprox *mls;
  OwnedZone zone;
  MicaDiscretization *disc, *error; /* the part's points, and the error norms' own (NULL: none) */
} MeshSource;

static void mesh_source_free(MeshSource *s) {
  mls_destroy(&s->mls);
  mica_mesh_destroy(&s->region);
  mica_mesh_destroy(&s->part);
  mica_discretization_destroy(&s->disc);
  mica_discretization_destroy(&s->error);
  memset(s, 0, sizeof *s);
}

typedef struct {
  double lo[3], hi[3];
} Near;

static int keep_near(const double *c, void *ctx) {
  const Near *b = ctx;
  for (int d = 0; d < 3; d++)
    if (!(c[d] >= b->lo[d] && c[d] < b->hi[d])) return 0;
  return 1;
}

/* NSNI (docs/theory.md §NSNI, cells from the Gauss points): each owned particle's cell, the Gauss points whose
 * nearest particle it is, from the elements within two element sizes of the box (every point nearer an owned
 * particle than any other lies within one element size of the box, and the region holds its nearest particle);
 * the part's own Gauss points stay the error norms'. */
static int nsni_cells(MeshSource *s, const MicaCellSpec *cells, const KeepRank *keep) {
  const int dim = s->disc->dim;
  const long n = mica_mesh_num_particles(s->region);
  const double *x = mica_mesh_particles(s->region), e = mica_mesh_element_size(s->region);
  Near near;
  MicaMesh *halo = NULL;
  MicaDiscretization *gauss = NULL;
  char *mine = NULL;
  box_bounds(keep->boxes, keep->rank, near.lo, near.hi);
  for (int d = 0; d < 3; d++) near.lo[d] -= 2 * e, near.hi[d] += 2 * e;
  int ierr = mica_mesh_part(s->region, keep_near, &near, &halo);
  if (!ierr) ierr = mica_discretization_create_mesh(halo, cells, 0, &gauss);
  if (!ierr) ierr = MICA_MALLOC(mine, n + 1);
  for (long k = 0; !ierr && k < n; k++) mine[k] = (char)(box_of(keep->boxes, x + k * dim) == keep->rank);
  if (!ierr) { /* the cells' particles: the region's */
    MICA_FREE(s->disc->x);
    s->disc->nparticles = n;
    ierr = MICA_MALLOC(s->disc->x, n * dim + 1);
  }
  if (!ierr) memcpy(s->disc->x, x, sizeof(double) * (size_t)(n * dim));
  if (!ierr) ierr = mica_discretization_nodal_points_from(s->disc, mine, gauss->nquad, gauss->qx, gauss->qw);
  MICA_FREE(mine);
  mica_discretization_destroy(&gauss);
  mica_mesh_destroy(&halo);
  return ierr;
}

static int mesh_source_build(const MicaMeshSource *mesh, const MicaCellSpec *cells, const MlsOptions *mls_opt,
                             const MicaOwnedSpec *spec, const KeepRank *keep, double reach, MeshSource *s) {
  const int dim = mica_mesh_source_dim(mesh);
  double blo[3], bhi[3];
  box_bounds(keep->boxes, keep->rank, blo, bhi);
  for (int d = 0; d < 3; d++) {
    s->lo[d] = blo[d] - reach, s->hi[d] = bhi[d] + reach;
    s->zone.low[d] = blo[d], s->zone.high[d] = bhi[d]; /* a point `reach` inside the box sees owned particles only */
  }
  MICA_CALL(mica_mesh_source_region(mesh, s->lo, s->hi, &s->region));
  const long n = mica_mesh_num_particles(s->region);
  MICA_CHECK(n >= 2, MICA_ERR_INPUT, "parallel.data = \"distributed\": a rank's region holds %ld of the mesh's "
             "particles; use fewer ranks", n);
  MICA_CALL(mica_mesh_part(s->region, keep_rank, (void *)keep, &s->part));
  MICA_CALL(mica_discretization_create_mesh(s->part, cells, spec->mesh, &s->disc));
  if (spec->nodal) MICA_CALL(nsni_cells(s, cells, keep));
  if (spec->error_order > 0) {
    MicaCellSpec e = *cells;
    e.order = spec->error_order;
    MICA_CALL(mica_discretization_create_mesh(s->part, &e, 0, &s->error));
  }
  MlsOptions opt = *mls_opt;
  opt.spacing_points = NULL, opt.spacing_index = NULL; /* a mesh's supports are sized on its nodes */
  return mls_create(dim, n, mica_mesh_particles(s->region), &opt, &s->mls);
}

/* Whether the region is wide enough: every needed particle `margin` of its spacings inside each face of the region
 * that cuts the mesh, and the reach beyond the largest radius in the region plus the element size (the rank's points
 * lie within an element of its box). */
static int mesh_source_enough(const MeshSource *s, const MicaOwnedSpec *spec, int dim, const double wlo[3],
                              const double whi[3], const long *needed, long nneeded, double margin, double reach) {
  const double *x = mls_particles(s->mls), *h = mls_spacing(s->mls), *rho = mls_radii(s->mls);
  double hmax = 0, rmax = 0;
  int cut = 0;
  for (int d = 0; d < dim; d++) cut |= s->lo[d] > wlo[d] || s->hi[d] <= whi[d];
  if (!cut) return 1; /* the region is the whole mesh */
  for (long k = 0; k < mls_num_particles(s->mls) * dim; k++) rmax = fmax(rmax, rho[k]);
  for (long k = 0; k < nneeded; k++)
    for (int d = 0; d < dim; d++) hmax = fmax(hmax, h[needed[k] * dim + d]);
  const double e = mica_mesh_element_size(s->region), wider = spec->wider_support > 1 ? spec->wider_support : 1;
  if (!(reach > wider * rmax + e)) return 0;
  if (spec->nodal && !(reach > 4 * e)) return 0; /* nsni_cells: the nearest particle of every point it samples */
  for (long k = 0; k < nneeded; k++)
    for (int d = 0; d < dim; d++) {
      const double xd = x[needed[k] * dim + d];
      if (s->lo[d] > wlo[d] && xd - s->lo[d] < margin * hmax) return 0;
      if (s->hi[d] <= whi[d] && s->hi[d] - xd < margin * hmax) return 0;
    }
  return 1;
}

/* The needed particles (region indices): the owned ones first, then the supports of the rank's points. */
static int mesh_needed(const MeshSource *s, const MicaOwnedSpec *spec, const MeshBoxes *boxes, int rank,
                       long **needed, long *nneeded) {
  const MicaDiscretization *d = s->disc;
  const int dim = d->dim;
  const long n = mica_mesh_num_particles(s->region);
  const double *px = mica_mesh_particles(s->region);
  double *x = NULL;
  long nowned = 0;
  *nneeded = 0;
  for (long k = 0; k < n; k++) nowned += box_of(boxes, px + k * dim) == rank;
  MICA_CALL(MICA_MALLOC(*needed, nowned + 1));
  MICA_CALL(MICA_MALLOC(x, nowned * dim + 1));
  for (long k = 0; k < n; k++)
    if (box_of(boxes, px + k * dim) == rank) {
      memcpy(x + *nneeded * dim, px + k * dim, sizeof(double) * (size_t)dim);
      (*needed)[(*nneeded)++] = k;
    }
  int ierr = parallel_add_supports(s->mls, &s->zone, nowned, x, needed, nneeded); /* the outputs at the particles */
  free(x);
  MICA_CALL(ierr);
  if (d->mesh) MICA_CALL(parallel_add_supports(s->mls, &s->zone, d->mesh->npoints, d->mesh->x, needed, nneeded));
  MICA_CALL(parallel_add_supports(s->mls, &s->zone, d->nquad, d->qx, needed, nneeded));
  MICA_CALL(parallel_add_set_supports(s->mls, &s->zone, d, needed, nneeded));
  if (s->error) MICA_CALL(parallel_add_supports(s->mls, &s->zone, s->error->nquad, s->error->qx, needed, nneeded));
  if (d->gauss_x) MICA_CALL(parallel_add_supports(s->mls, &s->zone, d->ngauss, d->gauss_x, needed, nneeded));
  if (spec->wider_support > 1) /* NSNI's Hessians of a linear basis */
    MICA_CALL(parallel_add_wider_supports(s->mls, &s->zone, spec->wider_support, d->nquad, d->qx, needed, nneeded));
  return MICA_SUCCESS;
}

/* The source grown (R doubled) until it is wide enough; its needed particles. */
static int mesh_source_create(const MicaMeshSource *mesh, const MicaCellSpec *cells, const MlsOptions *mls_opt,
                              const MicaOwnedSpec *spec, const KeepRank *keep, MeshSource *s, long **needed,
                              long *nneeded) {
  const int dim = mica_mesh_source_dim(mesh);
  double wlo[3], whi[3], blo[3], bhi[3], h = HUGE_VAL;
  mica_mesh_source_bounds(mesh, wlo, whi);
  box_bounds(keep->boxes, keep->rank, blo, bhi);
  /* the first reach: a few mean spacings of the sample (the region's elements tell the truth afterwards) */
  long nsample;
  (void)mica_mesh_source_sample(mesh, &nsample);
  double volume = 1;
  for (int d = 0; d < dim; d++) volume *= fmax(whi[d] - wlo[d], 1e-300);
  h = pow(volume / (double)(nsample > 1 ? nsample : 1), 1.0 / dim);
  const double dilation = mls_opt->dilation > 0 ? mls_opt->dilation : 1.0;
  double margin = 3;
  if (mls_opt->weight && mica_type_has(&mls_opt->weight->type, MLS_WEIGHT_ADAPTIVE)) margin = fmax(margin, ceil(dilation) + 1);
  double reach = h * (dilation + margin + 2);
  for (;;) {
    MICA_CALL(mesh_source_build(mesh, cells, mls_opt, spec, keep, reach, s));
    MICA_CALL(mesh_needed(s, spec, keep->boxes, keep->rank, needed, nneeded));
    if (mesh_source_enough(s, spec, dim, wlo, whi, *needed, *nneeded, margin, reach)) return MICA_SUCCESS;
    mesh_source_free(s);
    free(*needed);
    *needed = NULL;
    reach *= 2;
  }
}

/* ---- numbers -------------------------------------------------------------------------------------------- */

/* Local particles: the owned ones (ascending keys: the serial order), then the ghosts (ascending); their owners
 * and numbers. Collective (the offsets, the ghosts' positions). */
static int mesh_local_particles(const MeshSource *s, const MeshBoxes *boxes, const long *needed, long nneeded,
                                MicaDistribution *dist, long **map, long **offsets) {
  const int rank = mica_parallel_rank(), P = mica_parallel_size(), dim = dist->local->dim;
  const double *px = mica_mesh_particles(s->region);
  const long *keys = mica_mesh_particle_keys(s->region);
  long *ghost_key = NULL, *position = NULL, *owned_key = NULL, m = 0;
  int *ghost_owner = NULL;
  dist->nowned = dist->nghost = 0;
  for (long k = 0; k < nneeded; k++) {
    if (box_of(boxes, px + needed[k] * dim) == rank) dist->nowned++;
    else dist->nghost++;
  }
  const long nlocal = dist->nowned + dist->nghost;
  int ierr = MICA_MALLOC(*map, nlocal + 1);
  if (!ierr) ierr = MICA_MALLOC(owned_key, dist->nowned + 1);
  if (!ierr) ierr = MICA_MALLOC(ghost_key, dist->nghost + 1);
  if (!ierr) ierr = MICA_MALLOC(ghost_owner, dist->nghost + 1);
  if (!ierr) ierr = MICA_MALLOC(position, dist->nghost + 1);
  if (!ierr) ierr = MICA_CALLOC(*offsets, P + 1);
  for (long k = 0; !ierr && k < nneeded; k++) /* needed is ascending (parallel_add_supports), keys too */
    if (box_of(boxes, px + needed[k] * dim) == rank) owned_key[m] = keys[needed[k]], (*map)[m++] = needed[k];
  for (long k = 0, g = 0; !ierr && k < nneeded; k++) {
    const int r = box_of(boxes, px + needed[k] * dim);
    if (r != rank) ghost_key[g] = keys[needed[k]], ghost_owner[g++] = r, (*map)[m++] = needed[k];
  }
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MicaPartition *p = dist->partition;
  MPI_Allgather(&dist->nowned, 1, MPI_LONG, p->part_size, 1, MPI_LONG, mica_parallel_comm());
  for (int r = 0; r < P; r++) (*offsets)[r + 1] = (*offsets)[r] + p->part_size[r];
  for (int r = 0; r < P && !ierr; r++) {
    if (p->part_size[r] == 0)
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "parallel.data = \"distributed\": rank %d's "
                            "box holds none of the mesh's %ld particles; use fewer ranks", r, (*offsets)[P]);
    if ((double)p->part_size[r] * P / (double)(*offsets)[P] > p->imbalance)
      p->imbalance = (double)p->part_size[r] * P / (double)(*offsets)[P];
  }
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(parallel_ghost_positions(dist->nghost, ghost_owner, ghost_key, dist->nowned, owned_key, position));
  MicaDiscretization *d = dist->local;
  free(d->x);
  d->x = NULL;
  d->nparticles = p->n = nlocal;
  ierr = MICA_MALLOC(d->x, nlocal * dim + 1);
  if (!ierr) ierr = MICA_MALLOC(dist->global_node, nlocal + 1);
  if (!ierr) ierr = MICA_MALLOC(p->part, nlocal + 1);
  for (long i = 0; !ierr && i < nlocal; i++) {
    memcpy(d->x + i * dim, px + (*map)[i] * dim, sizeof(double) * (size_t)dim);
    const int owned = i < dist->nowned;
    p->part[i] = owned ? rank : ghost_owner[i - dist->nowned];
    dist->global_node[i] = (*offsets)[p->part[i]] + (owned ? i : position[i - dist->nowned]);
  }
cleanup:
  free(ghost_key), free(position), free(owned_key), free(ghost_owner);
  return ierr;
}


/* ---- the distribution ----------------------------------------------------------------------------------- */

static int build_owned_mesh(const MicaMeshSource *mesh, const MicaCellSpec *cells, const MlsOptions *mls_opt,
                            const MicaOwnedSpec *spec, MicaDistribution *dist) {
  const int P = mica_parallel_size(), dim = mica_mesh_source_dim(mesh);
  long nsample, *needed = NULL, nneeded = 0, *map = NULL, *offsets = NULL;
  const double *sample = mica_mesh_source_sample(mesh, &nsample);
  MeshBoxes boxes;
  MeshSource src;
  memset(&src, 0, sizeof src);
  MICA_CALL(boxes_create(P, dim, nsample, sample, &boxes));
  memcpy(dist->procs, boxes.procs, sizeof dist->procs);
  KeepRank keep = {&boxes, mica_parallel_rank()};
  int ierr = MICA_CALLOC(dist->partition, 1);
  if (!ierr) dist->partition->nparts = P, ierr = MICA_CALLOC(dist->partition->part_size, P + 1);
  if (!ierr) ierr = mesh_source_create(mesh, cells, mls_opt, spec, &keep, &src, &needed, &nneeded);
  if (!ierr) dist->local = src.disc, src.disc = NULL;
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  ierr = mesh_local_particles(&src, &boxes, needed, nneeded, dist, &map, &offsets);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr)); /* before the sum below */
  /* the uncovered boundary faces: each rank's part counted those centred in its box */
  dist->local->boundary_uncovered = mica_parallel_sum_long(dist->local->boundary_uncovered);
  dist->cells_mesh = src.part, src.part = NULL; /* the rank's elements: the error norms' points */
  ierr = parallel_owned_complete(ierr, src.mls, mls_opt, map, offsets, spec->revolve, dist);
cleanup:
  boxes_free(&boxes);
  mesh_source_free(&src);
  free(needed), free(map), free(offsets);
  return ierr;
}

typedef struct {
  const MicaMeshSource *mesh;
  const MicaCellSpec *cells;
  const MlsOptions *mls_opt;
  const MicaOwnedSpec *spec;
} MeshBuild;

static int build_mesh(void *ctx, MicaDistribution *dist) {
  const MeshBuild *b = ctx;
  return build_owned_mesh(b->mesh, b->cells, b->mls_opt, b->spec, dist);
}

int mica_distribution_create_owned_mesh(const MicaMeshSource *mesh, const MicaCellSpec *cells,
                                        const MlsOptions *mls_opt, const MicaOwnedSpec *spec,
                                        MicaDistribution **out) {
  *out = NULL;
  MICA_CHECK(!spec->nodal || (spec->centroids && !spec->cell_boundaries), MICA_ERR_ARGUMENT,
             "mica_distribution_create_owned_mesh: of the nodal modes only NSNI's cells from the Gauss points");
  MeshBuild b = {mesh, cells, mls_opt, spec};
  return parallel_owned_create(build_mesh, &b, spec, out);
}
