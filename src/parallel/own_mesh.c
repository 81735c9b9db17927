/* parallel.data = "distributed" for a Gmsh mesh (parallel.h, mica_distribution_create_owned_mesh): the particles
 * (the mesh's nodes) split into one box of coordinates per rank, the volume elements owned by the box that holds
 * their centroid, and the boundary elements by the owner of the volume element they bound.
 *
 * The boxes: P factored into blocks per axis (mica_block_split, on the bounding box measured in mean spacings), then
 * cut by coordinates as a recursive coordinate bisection would, but axis after axis: slabs of equal particle counts
 * along x, columns of equal counts along y within each slab, blocks along z within each column. A cut lies halfway
 * between two distinct coordinates, so a particle's block follows from its coordinates and the O(P) cuts alone.
 *
 * Each rank keeps the particles within a reach R of its box (its source), sizes their supports there (their local
 * spacings and radii are those of the whole mesh when they lie deep enough inside the source, as own.c's grid boxes
 * do with layers), searches the supports of its points and keeps the owned particles and the ghosts they reach. R
 * doubles until the needed particles lie `margin` spacings inside every face of the source that cuts the mesh, and
 * no particle beyond it can reach the rank's points.
 *
 * What is whole here: every rank reads the whole mesh (the .msh file, or the .geo meshed by the Gmsh library) and
 * computes the cuts from all its particles, then keeps its part and frees the rest before anything else is built
 * (docs/architecture.md §Parallel runs says what a streamed read would change). */
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

/* ---- the rank's particles ------------------------------------------------------------------------------- */

typedef struct {
  const MeshBoxes *boxes;
  int rank;
} KeepRank;

static int keep_rank(const double *centroid, void *ctx) {
  const KeepRank *k = ctx;
  return box_of(k->boxes, centroid) == k->rank;
}

/* The rank's source: the whole mesh's particles within [lo − R, hi + R) on every axis (whole[], ascending), their MLS
 * approximation, and the zone of the owned box. */
typedef struct {
  long n, *whole;
  double lo[3], hi[3]; /* the source's box */
  MlsApprox *mls;
  OwnedZone zone;
} MeshSource;

static void mesh_source_free(MeshSource *s) {
  free(s->whole);
  mls_destroy(&s->mls);
  memset(s, 0, sizeof *s);
}

static int mesh_source_build(const MicaMesh *mesh, const MlsOptions *mls_opt, const double blo[3],
                             const double bhi[3], double reach, MeshSource *s) {
  const int dim = mica_mesh_dim(mesh);
  const long n = mica_mesh_num_particles(mesh);
  const double *x = mica_mesh_particles(mesh);
  double *sx = NULL;
  for (int d = 0; d < 3; d++) {
    s->lo[d] = blo[d] - reach, s->hi[d] = bhi[d] + reach;
    s->zone.low[d] = blo[d], s->zone.high[d] = bhi[d]; /* a point `reach` inside the box sees owned particles only */
  }
  MICA_CALL(MICA_MALLOC(s->whole, n + 1));
  for (long i = 0; i < n; i++) {
    int inside = 1;
    for (int d = 0; d < dim; d++) inside &= x[i * dim + d] >= s->lo[d] && x[i * dim + d] < s->hi[d];
    if (inside) s->whole[s->n++] = i;
  }
  MICA_CHECK(s->n >= 2, MICA_ERR_INPUT, "parallel.data = \"distributed\": a rank's box holds %ld of the mesh's "
             "particles; use fewer ranks", s->n);
  MICA_CALL(MICA_MALLOC(sx, s->n * dim + 1));
  for (long k = 0; k < s->n; k++) memcpy(sx + k * dim, x + s->whole[k] * dim, sizeof(double) * (size_t)dim);
  MlsOptions opt = *mls_opt;
  opt.spacing_points = NULL, opt.spacing_index = NULL; /* a mesh's supports are sized on its nodes */
  const int ierr = mls_create(dim, s->n, sx, &opt, &s->mls);
  free(sx);
  return ierr;
}

/* Whether the source is wide enough: every needed particle `margin` of its spacings inside each face of the source
 * that cuts the mesh (within its bounding box), and the reach beyond the largest radius in the source plus the
 * element size (the rank's points lie within an element of its box). */
static int mesh_source_enough(const MeshSource *s, int dim, const double wlo[3], const double whi[3],
                              const long *needed, long nneeded, double margin, double reach, double element) {
  const double *x = mls_particles(s->mls), *h = mls_spacing(s->mls), *rho = mls_radii(s->mls);
  double hmax = 0, rmax = 0;
  for (long k = 0; k < s->n * dim; k++) rmax = fmax(rmax, rho[k]);
  for (long k = 0; k < nneeded; k++)
    for (int d = 0; d < dim; d++) hmax = fmax(hmax, h[needed[k] * dim + d]);
  if (!(reach > rmax + element)) return 0;
  for (long k = 0; k < nneeded; k++)
    for (int d = 0; d < dim; d++) {
      const double xd = x[needed[k] * dim + d];
      if (s->lo[d] > wlo[d] && xd - s->lo[d] < margin * hmax) return 0;
      if (s->hi[d] <= whi[d] && s->hi[d] - xd < margin * hmax) return 0;
    }
  return 1;
}

/* The needed particles (source indices): the owned ones first, then the supports of the rank's points. */
static int mesh_needed(const MeshSource *s, const MicaDiscretization *d, const MicaDiscretization *error,
                       const int *owner, int rank, long **needed, long *nneeded) {
  const int dim = d->dim;
  double *x = NULL;
  long nowned = 0;
  for (long k = 0; k < s->n; k++) nowned += owner[s->whole[k]] == rank;
  MICA_CALL(MICA_MALLOC(*needed, nowned + 1));
  MICA_CALL(MICA_MALLOC(x, nowned * dim + 1));
  for (long k = 0; k < s->n; k++)
    if (owner[s->whole[k]] == rank) {
      memcpy(x + *nneeded * dim, mls_particles(s->mls) + k * dim, sizeof(double) * (size_t)dim);
      (*needed)[(*nneeded)++] = k;
    }
  int ierr = parallel_add_supports(s->mls, &s->zone, nowned, x, needed, nneeded); /* the outputs at the particles */
  free(x);
  MICA_CALL(ierr);
  if (d->mesh) MICA_CALL(parallel_add_supports(s->mls, &s->zone, d->mesh->npoints, d->mesh->x, needed, nneeded));
  MICA_CALL(parallel_add_supports(s->mls, &s->zone, d->nquad, d->qx, needed, nneeded));
  MICA_CALL(parallel_add_set_supports(s->mls, &s->zone, d, needed, nneeded));
  if (error) MICA_CALL(parallel_add_supports(s->mls, &s->zone, error->nquad, error->qx, needed, nneeded));
  return MICA_SUCCESS;
}

/* The source grown (R doubled) until it is wide enough; its needed particles. */
static int mesh_source_create(const MicaMesh *mesh, const MlsOptions *mls_opt, const MeshBoxes *boxes,
                              const MicaDiscretization *d, const MicaDiscretization *error, const int *owner,
                              MeshSource *s, long **needed, long *nneeded) {
  const int dim = mica_mesh_dim(mesh), rank = mica_parallel_rank();
  const long n = mica_mesh_num_particles(mesh);
  const double *x = mica_mesh_particles(mesh), element = mica_mesh_element_size(mesh);
  double blo[3], bhi[3], wlo[3] = {0, 0, 0}, whi[3] = {0, 0, 0};
  box_bounds(boxes, rank, blo, bhi);
  for (int d2 = 0; d2 < dim; d2++) wlo[d2] = HUGE_VAL, whi[d2] = -HUGE_VAL;
  for (long i = 0; i < n; i++)
    for (int d2 = 0; d2 < dim; d2++) wlo[d2] = fmin(wlo[d2], x[i * dim + d2]), whi[d2] = fmax(whi[d2], x[i * dim + d2]);
  /* layers kept beyond the needed particles, as own.c's grid boxes (an adaptive weight: as many as a support spans) */
  const double dilation = mls_opt->dilation > 0 ? mls_opt->dilation : 1.0;
  double margin = 3;
  if (mls_opt->weight && mica_type_has(&mls_opt->weight->type, MLS_WEIGHT_ADAPTIVE)) margin = fmax(margin, ceil(dilation) + 1);
  double reach = element * (dilation + margin + 2);
  for (;;) {
    MICA_CALL(mesh_source_build(mesh, mls_opt, blo, bhi, reach, s));
    *nneeded = 0;
    MICA_CALL(mesh_needed(s, d, error, owner, rank, needed, nneeded));
    int whole = 1; /* the source holds the whole mesh: nothing is cut */
    for (int d2 = 0; d2 < dim; d2++) whole &= s->lo[d2] <= wlo[d2] && s->hi[d2] > whi[d2];
    if (whole || mesh_source_enough(s, dim, wlo, whi, *needed, *nneeded, margin, reach, element)) return MICA_SUCCESS;
    mesh_source_free(s);
    free(*needed);
    *needed = NULL;
    reach *= 2;
  }
}

/* Local particles: the owned ones (the serial order), then the ghosts (ascending); their owners and numbers. */
static int mesh_local_particles(const MeshSource *s, const long *needed, long nneeded, const int *owner,
                                const long *position, const long *offsets, MicaDistribution *dist, long **map) {
  const int rank = mica_parallel_rank(), dim = dist->local->dim;
  long m = 0;
  dist->nowned = dist->nghost = 0;
  for (long k = 0; k < nneeded; k++) {
    if (owner[s->whole[needed[k]]] == rank) dist->nowned++;
    else dist->nghost++;
  }
  const long nlocal = dist->nowned + dist->nghost;
  int ierr = MICA_MALLOC(*map, nlocal + 1);
  for (long k = 0; !ierr && k < nneeded; k++) /* needed is ascending (parallel_add_supports): the owned first */
    if (owner[s->whole[needed[k]]] == rank) (*map)[m++] = needed[k];
  for (long k = 0; !ierr && k < nneeded; k++)
    if (owner[s->whole[needed[k]]] != rank) (*map)[m++] = needed[k];
  MICA_CALL(ierr);
  MicaDiscretization *d = dist->local;
  MicaPartition *p = dist->partition;
  free(d->x);
  d->x = NULL;
  d->nparticles = nlocal;
  p->n = nlocal;
  MICA_CALL(MICA_MALLOC(d->x, nlocal * dim + 1));
  MICA_CALL(MICA_MALLOC(dist->global_node, nlocal + 1));
  MICA_CALL(MICA_MALLOC(p->part, nlocal + 1));
  for (long i = 0; i < nlocal; i++) {
    const long w = s->whole[(*map)[i]];
    memcpy(d->x + i * dim, mls_particles(s->mls) + (*map)[i] * dim, sizeof(double) * (size_t)dim);
    p->part[i] = owner[w];
    dist->global_node[i] = offsets[owner[w]] + position[w];
  }
  return MICA_SUCCESS;
}

/* ---- the distribution ----------------------------------------------------------------------------------- */

/* Each particle's owner and its position among the owner's (the serial order); the blocks' sizes and offsets. */
static int number_particles(const MeshBoxes *boxes, int dim, long n, const double *x, MicaPartition *p, int **owner,
                            long **position, long **offsets) {
  const int P = p->nparts;
  MICA_CALL(MICA_MALLOC(*owner, n + 1));
  MICA_CALL(MICA_MALLOC(*position, n + 1));
  MICA_CALL(MICA_CALLOC(*offsets, P + 1));
  for (long i = 0; i < n; i++) {
    (*owner)[i] = box_of(boxes, x + i * dim);
    (*position)[i] = p->part_size[(*owner)[i]]++;
  }
  for (int r = 0; r < P; r++) {
    (*offsets)[r + 1] = (*offsets)[r] + p->part_size[r];
    MICA_CHECK(p->part_size[r] > 0, MICA_ERR_INPUT, "parallel.data = \"distributed\": rank %d's box holds none "
               "of the mesh's %ld particles; use fewer ranks", r, n);
    if ((double)p->part_size[r] * P / (double)n > p->imbalance) p->imbalance = (double)p->part_size[r] * P / (double)n;
  }
  return MICA_SUCCESS;
}

static int build_owned_mesh(const MicaMesh *mesh, const MicaCellSpec *cells, const MlsOptions *mls_opt,
                            const MicaOwnedSpec *spec, MicaDistribution *dist) {
  const int P = mica_parallel_size(), dim = mica_mesh_dim(mesh);
  const long n = mica_mesh_num_particles(mesh);
  const double *x = mica_mesh_particles(mesh);
  MeshBoxes boxes;
  MeshSource src;
  int *owner = NULL;
  long *position = NULL, *offsets = NULL, *needed = NULL, nneeded = 0, *map = NULL;
  MicaDiscretization *error = NULL;
  memset(&src, 0, sizeof src);
  MICA_CALL(boxes_create(P, dim, n, x, &boxes));
  memcpy(dist->procs, boxes.procs, sizeof dist->procs);
  int ierr = MICA_CALLOC(dist->partition, 1);
  if (!ierr) dist->partition->nparts = P, ierr = MICA_CALLOC(dist->partition->part_size, P + 1);
  if (!ierr) ierr = number_particles(&boxes, dim, n, x, dist->partition, &owner, &position, &offsets);
  KeepRank keep = {&boxes, mica_parallel_rank()};
  if (!ierr) ierr = mica_mesh_part(mesh, keep_rank, &keep, &dist->cells_mesh);
  if (!ierr) ierr = mica_discretization_create_mesh(dist->cells_mesh, cells, spec->mesh, &dist->local);
  if (!ierr && spec->error_order > 0) ierr = mica_owned_cell_points(NULL, NULL, cells, dist, spec->error_order, &error);
  if (!ierr) ierr = mesh_source_create(mesh, mls_opt, &boxes, dist->local, error, owner, &src, &needed, &nneeded);
  if (!ierr) ierr = mesh_local_particles(&src, needed, nneeded, owner, position, offsets, dist, &map);
  ierr = parallel_owned_complete(ierr, src.mls, mls_opt, map, offsets, spec->revolve, dist);
  boxes_free(&boxes);
  mesh_source_free(&src);
  mica_discretization_destroy(&error);
  free(owner), free(position), free(offsets), free(needed), free(map);
  return ierr;
}

typedef struct {
  const MicaMesh *mesh;
  const MicaCellSpec *cells;
  const MlsOptions *mls_opt;
  const MicaOwnedSpec *spec;
} MeshBuild;

static int build_mesh(void *ctx, MicaDistribution *dist) {
  const MeshBuild *b = ctx;
  return build_owned_mesh(b->mesh, b->cells, b->mls_opt, b->spec, dist);
}

int mica_distribution_create_owned_mesh(const MicaMesh *mesh, const MicaCellSpec *cells, const MlsOptions *mls_opt,
                                        const MicaOwnedSpec *spec, MicaDistribution **out) {
  *out = NULL;
  MICA_CHECK(!spec->nodal, MICA_ERR_ARGUMENT, "mica_distribution_create_owned_mesh: no nodal quadrature on a mesh");
  MeshBuild b = {mesh, cells, mls_opt, spec};
  return parallel_owned_create(build_mesh, &b, spec, out);
}
