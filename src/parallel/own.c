/* parallel.data = "distributed": each rank owns a block of a built-in shape's particle index grid and the
 * background cells of the same block of the cell grid, and holds only those, their quadrature and boundary
 * points and the ghost particles its points' supports reach (parallel.h). No partitioner: the grids are split
 * as PETSc's DMDA splits its index box, P factored into blocks per axis. A particle's owner and its number in
 * the ranks' contiguous numbering follow from its grid index and the O(P) block sizes, on any rank.
 *
 * A rank builds the particles of a box of the grid around its block (mica_discretization_create_block: jittered
 * particles from their own draws of the counter-based stream), its cells' volume and boundary points, and the MLS
 * approximation of that box; the supports of its points in it are its particles; the box grows until they lie
 * MARGIN layers inside it, so that their local spacings and radii are those of the whole layout. With nodal
 * quadrature (MicaOwnedSpec) the points are the nodal cells of the rank's particles instead of its cells' Gauss
 * points, which the error norms keep. Nothing of the whole layout's size is allocated on any rank. An irregular
 * layout's particles belong to the blocks of their nearest grid points; a rank draws those whose grid points lie in
 * its box from the layout's tiles around it (mica_layout_irregular_box: the whole layout's particles), numbers its
 * own in the layout's order and asks the owners of its ghosts for theirs, by key. A Gmsh mesh has no
 * index grid: own_mesh.c. What the ranks exchange once a distribution is built (ghost plans, Lagrange multipliers'
 * nodes, owned norms): own_exchange.c. */
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
/* The rank whose block holds grid point idx. */
static int block_owner(const long idx[3], const long n[3], const int procs[3]) {
  int b[3];
  for (int d = 0; d < 3; d++) b[d] = block_of(idx[d], n[d], procs[d]);
  return b[0] + procs[0] * (b[1] + procs[1] * b[2]);
}

static long global_number(long t, const long n[3], const int procs[3], const long *offsets, int *owner) {
  long idx[3], lo[3], hi[3];
  grid_index(t, n, idx);
  const int r = block_owner(idx, n, procs);
  block_box(r, procs, n, lo, hi);
  *owner = r;
  return offsets[r] + (idx[0] - lo[0]) + (hi[0] - lo[0]) * ((idx[1] - lo[1]) + (hi[1] - lo[1]) * (idx[2] - lo[2]));
}

/* ---- the particles the rank's points need ----------------------------------------------------------------- */

/* Where the rank's own particles alone can support a point: no particle of another block lies within
 * low[d] < x_d < high[d] on any axis d (low[d]: the largest coordinate x_d of the source's particles below the
 * owned block along axis d, high[d]: the smallest above it). A point farther than every support radius inside
 * these bounds on every axis has only owned particles in its support — they are in the set from the start — and
 * is not searched: the search becomes one of the block's rim (33³ cube, P = 2: 0.39 s a rank before). */
static int inside_zone(const OwnedZone *z, int dim, double reach, const double *x) {
  for (int d = 0; d < dim; d++)
    if (!(x[d] - reach > z->low[d] && x[d] + reach < z->high[d])) return 0;
  return 1;
}

static double largest_radius(const MlsApprox *mls) {
  const double *r = mls_radii(mls);
  double most = 0;
  for (long k = 0; k < mls_num_particles(mls) * mls_dim(mls); k++) most = r[k] > most ? r[k] : most;
  return most;
}

/* set ∪= the supports of x[n·dim] outside the owned zone, searched in chunks; the union kept as marks over the
 * approximation's particles and read back in ascending order, so no index list is sorted (a qsort of each chunk's
 * supports made this 2.5 times the cost of the search itself: 1.1 s of the 33³ cube's 131 072 points a rank at
 * P = 2). set holds the owned particles already. */
int parallel_add_supports(const MlsApprox *mls, const OwnedZone *zone, long n, const double *x, long **set,
                          long *nset) {
  enum { CHUNK = 4096 };
  const int dim = mls_dim(mls);
  const long nparticles = mls_num_particles(mls);
  const double reach = largest_radius(mls);
  unsigned char *mark = NULL;
  double *rim = NULL; /* the chunk's points outside the zone */
  MICA_CALL(MICA_CALLOC(mark, nparticles + 1));
  int ierr = MICA_MALLOC(rim, (long)CHUNK * dim);
  for (long i = 0; i < *nset && !ierr; i++) mark[(*set)[i]] = 1;
  for (long first = 0; first < n && !ierr; first += CHUNK) {
    const long count = n - first < CHUNK ? n - first : CHUNK;
    long nrim = 0, *ptr = NULL, *index = NULL;
    for (long i = first; i < first + count; i++)
      if (!inside_zone(zone, dim, reach, x + i * dim))
        memcpy(rim + nrim++ * dim, x + i * dim, sizeof(double) * (size_t)dim);
    if (!nrim) continue;
    ierr = mica_point_supports(mls, nrim, rim, &ptr, &index, NULL);
    for (long e = 0; !ierr && e < ptr[nrim]; e++) mark[index[e]] = 1;
    free(ptr), free(index);
  }
  free(rim);
  long total = 0, *merged = NULL;
  for (long k = 0; k < nparticles; k++) total += mark[k];
  if (!ierr) ierr = MICA_MALLOC(merged, total + 1);
  for (long k = 0, m = 0; !ierr && k < nparticles; k++)
    if (mark[k]) merged[m++] = k;
  free(mark);
  MICA_CALL(ierr);
  free(*set);
  *set = merged, *nset = total;
  return MICA_SUCCESS;
}

/* ---- this rank's discretization --------------------------------------------------------------------------- */

/* The rank's source: the particles of a grid box around its block (src_lo, src_hi), its cells' volume and
 * boundary points, and the MLS approximation of those particles. */
typedef struct {
  long lo[3], hi[3];
  MicaDiscretization *disc;
  MlsApprox *mls;
  OwnedZone zone;
  /* an irregular layout: the source's particles are the layout's whose nearest grid point lies in the box, in the
   * layout's order — their keys and their grid points (NULL: the box's grid particles) */
  long *key, *grid_of;
  long grid_n[3]; /* the particle grid's size */
} Source;

static void source_free(Source *src) {
  mls_destroy(&src->mls);
  mica_discretization_destroy(&src->disc);
  free(src->key), free(src->grid_of);
  src->key = src->grid_of = NULL;
}

static long source_index(const Source *src, const long idx[3]) {
  return (idx[0] - src->lo[0]) + (src->hi[0] - src->lo[0]) * ((idx[1] - src->lo[1]) + (src->hi[1] - src->lo[1]) * (idx[2] - src->lo[2]));
}

static void source_grid(const Source *src, long k, long idx[3]) {
  if (src->grid_of) {
    grid_index(src->grid_of[k], src->grid_n, idx);
    return;
  }
  const long w0 = src->hi[0] - src->lo[0], w1 = src->hi[1] - src->lo[1];
  idx[0] = src->lo[0] + k % w0, k /= w0;
  idx[1] = src->lo[1] + k % w1, idx[2] = src->lo[2] + k / w1;
}

/* Layers of particles kept beyond the farthest one a point's support needs: their neighbors set its local spacing,
 * hence its radius, as in the whole layout (docs/architecture.md §Parallel runs). */
enum { MARGIN = 3 };

/* The layers kept beyond the needed particles: MARGIN, and for an adaptive weight, whose shape parameter at a
 * particle comes from the particles whose supports cover it, as many as a support spans and one for the jitter. */
static long source_margin(const MlsOptions *mls_opt) {
  if (!mls_opt->weight || !mica_type_has(&mls_opt->weight->type, MLS_WEIGHT_ADAPTIVE)) return MARGIN;
  const long span = (long)ceil(mls_opt->dilation > 0 ? mls_opt->dilation : 1.0) + 1;
  return span > MARGIN ? span : MARGIN;
}

/* Whether the needed particles stay `margin` layers inside the box wherever it does not end at the grid's edge. */
static int source_deep_enough(const Source *src, const long n[3], const long *needed, long nneeded, long margin) {
  for (long k = 0; k < nneeded; k++) {
    long idx[3];
    source_grid(src, needed[k], idx);
    for (int d = 0; d < 3; d++) {
      if (src->lo[d] > 0 && idx[d] - src->lo[d] < margin) return 0;
      if (src->hi[d] < n[d] && src->hi[d] - 1 - idx[d] < margin) return 0;
    }
  }
  return 1;
}

/* The source's zone around the owned block (OwnedZone). */
static void owned_zone(Source *src, const long plo[3], const long phi[3]) {
  const int dim = src->disc->dim;
  for (int d = 0; d < 3; d++) src->zone.low[d] = -HUGE_VAL, src->zone.high[d] = HUGE_VAL;
  for (long k = 0; k < src->disc->nparticles; k++) {
    long idx[3];
    source_grid(src, k, idx);
    for (int d = 0; d < dim; d++) {
      const double x = src->disc->x[k * dim + d];
      if (idx[d] < plo[d] && x > src->zone.low[d]) src->zone.low[d] = x;
      if (idx[d] >= phi[d] && x < src->zone.high[d]) src->zone.high[d] = x;
    }
  }
}

/* The rank's source with `layers` layers of particles around its particle block and the particles of its cells
 * (cell c of m along an axis lies between particle lines about c (n − 1)/m and (c + 1)(n − 1)/m). */
/* Cells around the rank's block whose Gauss points NSNI's cells are made of, on an irregular layout: a point nearer
 * an owned particle than any other lies within about a spacing of the block (a particle within half a spacing of its
 * grid point, the Poisson-disk holes smaller than a spacing), and cells are about a spacing wide. */
enum { NSNI_CELLS = 3 };

/* NSNI on an irregular layout (docs/theory.md §NSNI, cells from the Gauss points; as own_mesh.c's nsni_cells): each
 * owned particle's cell is the set of Gauss points whose nearest particle it is, among the points of the cells within
 * NSNI_CELLS of the rank's cell block (the source holds their nearest particles); the block's own Gauss points stay
 * the error norms' (disc->gauss_x). */
static int irregular_nsni_cells(const MicaShapeSpec *shape, const MicaLayoutSpec *grid, const MicaCellSpec *cells,
                                const MicaGridBlock *block, const long ncells[3], const long plo[3], const long phi[3],
                                Source *src) {
  MicaGridBlock near;
  MicaDiscretization *gauss = NULL;
  char *mine = NULL;
  memset(&near, 0, sizeof near);
  for (int d = 0; d < 3; d++) {
    near.cell_lo[d] = block->cell_lo[d] - NSNI_CELLS < 0 ? 0 : block->cell_lo[d] - NSNI_CELLS;
    near.cell_hi[d] = block->cell_hi[d] + NSNI_CELLS > ncells[d] ? ncells[d] : block->cell_hi[d] + NSNI_CELLS;
  }
  const long n = src->disc->nparticles;
  int ierr = mica_discretization_create_block(shape, grid, cells, &near, &gauss);
  if (!ierr) ierr = MICA_MALLOC(mine, n + 1);
  for (long k = 0; !ierr && k < n; k++) {
    long idx[3];
    grid_index(src->grid_of[k], src->grid_n, idx);
    mine[k] = (char)in_box(idx, plo, phi);
  }
  if (!ierr) ierr = mica_discretization_nodal_points_from(src->disc, mine, gauss->nquad, gauss->qx, gauss->qw);
  MICA_FREE(mine);
  mica_discretization_destroy(&gauss);
  return ierr;
}

/* The irregular layout's source: the box's cells and regular grid points (a regular layout's block: the spacing
 * points), and the layout's particles whose nearest grid point is in the box, each sized on that point's spacing;
 * with NSNI (nsni) the owned particles' cells from the Gauss points. */
static int source_build_irregular(const MicaShapeSpec *shape, const MicaLayoutSpec *irregular,
                                  const MicaCellSpec *cells, const MlsOptions *mls_opt, const MicaGridBlock *block,
                                  const long ncells[3], const long plo[3], const long phi[3], int nsni, Source *src) {
  MicaLayoutSpec grid = *irregular;
  grid.kind = MICA_LAYOUT_REGULAR;
  MICA_CALL(mica_discretization_create_block(shape, &grid, cells, block, &src->disc));
  MicaDiscretization *d = src->disc;
  const int dim = d->dim;
  long *spacing_index = NULL;
  d->x_grid = d->x, d->ngrid = d->nparticles; /* the box's grid points, in box order */
  d->x = NULL;
  MICA_CALL(mica_layout_irregular_box(shape, irregular, src->lo, src->hi, &d->nparticles, &d->x, &src->grid_of,
                                      &src->key));
  MICA_CALL(MICA_MALLOC(spacing_index, d->nparticles + 1));
  for (long k = 0; k < d->nparticles; k++) {
    long idx[3];
    grid_index(src->grid_of[k], src->grid_n, idx);
    spacing_index[k] = source_index(src, idx);
  }
  owned_zone(src, plo, phi);
  MlsOptions opt = *mls_opt;
  opt.spacing_points = d->x_grid, opt.spacing_count = d->ngrid, opt.spacing_index = spacing_index;
  int ierr = mls_create(dim, d->nparticles, d->x, &opt, &src->mls);
  free(spacing_index);
  if (!ierr && nsni) ierr = irregular_nsni_cells(shape, &grid, cells, block, ncells, plo, phi, src);
  return ierr;
}

static int source_build(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                        const MlsOptions *mls_opt, const long n[3], const long m[3], const long plo[3],
                        const long phi[3], const long clo[3], const long chi[3], long layers, int mesh,
                        const MicaLayoutSpec *irregular, int nsni, Source *src) {
  MicaGridBlock block;
  memset(&block, 0, sizeof block);
  block.mesh = mesh;
  for (int d = 0; d < 3; d++) {
    long a = clo[d] * (n[d] - 1) / m[d], b = (chi[d] * (n[d] - 1) + m[d] - 1) / m[d] + 1;
    a = (a < plo[d] ? a : plo[d]) - layers, b = (b > phi[d] ? b : phi[d]) + layers;
    src->lo[d] = block.particle_lo[d] = a < 0 ? 0 : a;
    src->hi[d] = block.particle_hi[d] = b > n[d] ? n[d] : b;
    block.cell_lo[d] = block.boundary_lo[d] = clo[d];
    block.cell_hi[d] = block.boundary_hi[d] = chi[d];
  }
  memcpy(src->grid_n, n, sizeof src->grid_n);
  if (irregular) return source_build_irregular(shape, irregular, cells, mls_opt, &block, m, plo, phi, nsni, src);
  MICA_CALL(mica_discretization_create_block(shape, layout, cells, &block, &src->disc));
  owned_zone(src, plo, phi);
  MlsOptions opt = *mls_opt;
  opt.spacing_points = src->disc->x_grid; /* a jittered layout's supports are sized on its grid, as run_geometry.c's */
  return mls_create(src->disc->dim, src->disc->nparticles, src->disc->x, &opt, &src->mls);
}

/* The rank's own particles (needed first: add_supports skips the points they alone support), and the supports
 * of their positions (the outputs evaluate the fields there). */
/* The source's particles in the owned block, in the numbering's order (the block's grid order; an irregular layout's
 * order): *owned[*nowned] (room for `extra` more). */
static int owned_in_source(const Source *src, const long plo[3], const long phi[3], long extra, long **owned,
                           long *nowned) {
  *nowned = 0;
  if (src->grid_of) {
    for (long k = 0; k < src->disc->nparticles; k++) {
      long idx[3];
      source_grid(src, k, idx);
      *nowned += in_box(idx, plo, phi);
    }
    MICA_CALL(MICA_MALLOC(*owned, *nowned + extra + 1));
    for (long k = 0, m = 0; k < src->disc->nparticles; k++) {
      long idx[3];
      source_grid(src, k, idx);
      if (in_box(idx, plo, phi)) (*owned)[m++] = k;
    }
    return MICA_SUCCESS;
  }
  *nowned = box_size(plo, phi);
  MICA_CALL(MICA_MALLOC(*owned, *nowned + extra + 1));
  long k = 0;
  for (long i2 = plo[2]; i2 < phi[2]; i2++)
    for (long i1 = plo[1]; i1 < phi[1]; i1++)
      for (long i0 = plo[0]; i0 < phi[0]; i0++) {
        const long idx[3] = {i0, i1, i2};
        (*owned)[k++] = source_index(src, idx);
      }
  return MICA_SUCCESS;
}

static int add_owned_supports(const Source *src, const long plo[3], const long phi[3], long **needed, long *nneeded) {
  const int dim = src->disc->dim;
  double *x = NULL;
  long *owned = NULL, nowned = 0;
  MICA_CALL(owned_in_source(src, plo, phi, *nneeded, &owned, &nowned));
  int ierr = MICA_MALLOC(x, nowned * dim + 1);
  for (long k = 0; !ierr && k < nowned; k++)
    memcpy(x + k * dim, src->disc->x + owned[k] * dim, sizeof(double) * (size_t)dim);
  if (!ierr) {
    if (*nneeded) memcpy(owned + nowned, *needed, sizeof(long) * (size_t)*nneeded); /* in any order */
    free(*needed);
    *needed = owned, *nneeded += nowned;
    owned = NULL;
    ierr = parallel_add_supports(src->mls, &src->zone, nowned, x, needed, nneeded);
  }
  free(x), free(owned);
  return ierr;
}

int mica_owned_cell_points(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                           const MicaDistribution *dist, int order, MicaDiscretization **disc) {
  MicaGridBlock block;
  MicaCellSpec c = *cells;
  c.order = order;
  if (dist->cells_mesh) return mica_discretization_create_mesh(dist->cells_mesh, &c, 0, disc); /* own_mesh.c */
  MicaLayoutSpec grid = *layout; /* an irregular layout's cells: the regular layout's */
  if (grid.kind == MICA_LAYOUT_IRREGULAR) grid.kind = MICA_LAYOUT_REGULAR;
  layout = &grid;
  memset(&block, 0, sizeof block);
  memcpy(block.cell_lo, dist->cell_lo, sizeof block.cell_lo);
  memcpy(block.cell_hi, dist->cell_hi, sizeof block.cell_hi);
  return mica_discretization_create_block(shape, layout, &c, &block, disc);
}

/* ... and of the error norms' own points in the rank's cells (quadrature.error_order). */
static int add_error_supports(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                              const MicaDistribution *dist, const Source *src, long **needed, long *nneeded) {
  if (dist->error_order <= 0) return MICA_SUCCESS;
  MicaDiscretization *e = NULL;
  MICA_CALL(mica_owned_cell_points(shape, layout, cells, dist, dist->error_order, &e));
  const int ierr = parallel_add_supports(src->mls, &src->zone, e->nquad, e->qx, needed, nneeded);
  mica_discretization_destroy(&e);
  return ierr;
}

int parallel_add_wider_supports(const MlsApprox *mls, const OwnedZone *zone, double factor, long n, const double *x,
                                long **set, long *nset) {
  const int dim = mls_dim(mls);
  const long nr = mls_num_particles(mls) * dim;
  MlsApprox *wide = NULL;
  double *radii = NULL;
  int ierr = mls_create(dim, mls_num_particles(mls), mls_particles(mls), mls_options(mls), &wide);
  if (!ierr) ierr = MICA_MALLOC(radii, nr + 1);
  for (long i = 0; !ierr && i < nr; i++) radii[i] = factor * mls_radii(mls)[i];
  if (!ierr) ierr = mls_set_radii(wide, radii);
  if (!ierr) ierr = parallel_add_supports(wide, zone, n, x, set, nset);
  free(radii);
  mls_destroy(&wide);
  return ierr;
}

/* ... and of the sets' points and vertices (collocation evaluates the fields at the vertices). */
int parallel_add_set_supports(const MlsApprox *mls, const OwnedZone *zone, const MicaDiscretization *d, long **needed,
                              long *nneeded) {
  for (int s = 0; s < d->nsets; s++) {
    MICA_CALL(parallel_add_supports(mls, zone, d->sets[s].n, d->sets[s].x, needed, nneeded));
    MICA_CALL(parallel_add_supports(mls, zone, d->sets[s].nvertices, d->sets[s].vertex_x, needed, nneeded));
  }
  return MICA_SUCCESS;
}

/* ... and of the nodal points (parallel.data = "distributed" with nodal quadrature): the cells' points, their
 * boundary sets' and (SCNI) their boundary points, and the particles a wider support reaches from the points. */
static int add_nodal_supports(const Source *src, const MicaDiscretization *nodal, const MicaOwnedSpec *spec,
                              long **needed, long *nneeded) {
  MICA_CALL(parallel_add_supports(src->mls, &src->zone, nodal->nquad, nodal->qx, needed, nneeded));
  MICA_CALL(parallel_add_set_supports(src->mls, &src->zone, nodal, needed, nneeded));
  if (spec->cell_boundaries)
    MICA_CALL(parallel_add_supports(src->mls, &src->zone, nodal->nodal->ptr[nodal->nodal->n], nodal->nodal->x, needed, nneeded));
  if (!(spec->wider_support > 1)) return MICA_SUCCESS;
  return parallel_add_wider_supports(src->mls, &src->zone, spec->wider_support, nodal->nquad, nodal->qx, needed,
                                     nneeded);
}

/* The source's particles in the supports of its points: grown until they lie MARGIN layers inside it. nodal: the
 * rank's nodal cells, whose points replace its cells' volume points and boundary sets (NULL: none). */
static int source_create(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                         const MlsOptions *mls_opt, const long n[3], const long m[3], const long plo[3],
                         const long phi[3], const MicaDistribution *dist, const MicaOwnedSpec *spec,
                         const MicaDiscretization *nodal, const MicaLayoutSpec *irregular, Source *src, long **needed,
                         long *nneeded) {
  const long *clo = dist->cell_lo, *chi = dist->cell_hi;
  const double reach = (mls_opt->dilation > 0 ? mls_opt->dilation : 1.0) * (spec->wider_support > 1 ? spec->wider_support : 1);
  long layers = (long)ceil(reach) + source_margin(mls_opt);
  for (;;) {
    MICA_CALL(source_build(shape, layout, cells, mls_opt, n, m, plo, phi, clo, chi, layers, spec->mesh, irregular,
                           irregular && spec->nodal, src));
    const MicaDiscretization *d = src->disc;
    *nneeded = 0;
    MICA_CALL(add_owned_supports(src, plo, phi, needed, nneeded)); /* first: the zone's points are theirs */
    if (d->mesh) MICA_CALL(parallel_add_supports(src->mls, &src->zone, d->mesh->npoints, d->mesh->x, needed, nneeded)); /* output.mesh */
    MICA_CALL(parallel_add_supports(src->mls, &src->zone, d->nquad, d->qx, needed, nneeded)); /* nodal: the error norms' points */
    if (nodal) MICA_CALL(add_nodal_supports(src, nodal, spec, needed, nneeded));
    else MICA_CALL(parallel_add_set_supports(src->mls, &src->zone, d, needed, nneeded));
    if (d->nodal) { /* NSNI's cells from the Gauss points (irregular): the error norms' points, the Hessians' reach */
      MICA_CALL(parallel_add_supports(src->mls, &src->zone, d->ngauss, d->gauss_x, needed, nneeded));
      if (spec->wider_support > 1)
        MICA_CALL(parallel_add_wider_supports(src->mls, &src->zone, spec->wider_support, d->nquad, d->qx, needed,
                                              nneeded));
    }
    MICA_CALL(add_error_supports(shape, layout, cells, dist, src, needed, nneeded));
    if (source_deep_enough(src, n, *needed, *nneeded, source_margin(mls_opt))) return MICA_SUCCESS;
    source_free(src);
    free(*needed);
    *needed = NULL;
    layers *= 2;
  }
}

/* The local particles: the owned block (grid order; an irregular layout's: its order), then the ghosts (ascending
 * source index); their owners and contiguous numbers (an irregular layout's ghosts: irregular_ghost_numbers). The
 * volume and boundary points are the source's (its cells are the rank's). */
static int local_particles(const Source *src, MicaDistribution *dist, const long n[3], const long *needed,
                           long nneeded, const long *offsets, long **srcmap) {
  const MicaDiscretization *sd = src->disc;
  const int dim = sd->dim, rank = mica_parallel_rank();
  long lo[3], hi[3], *map = NULL, nowned = 0;
  block_box(rank, dist->procs, n, lo, hi);
  long nghost = 0;
  for (long k = 0; k < nneeded; k++) {
    long idx[3];
    source_grid(src, needed[k], idx);
    nghost += !in_box(idx, lo, hi);
  }
  MICA_CALL(owned_in_source(src, lo, hi, nghost, &map, &nowned));
  *srcmap = map;
  dist->nowned = nowned, dist->nghost = nghost;
  const long nlocal = dist->nowned + nghost;
  long m = nowned;
  for (long k = 0; k < nneeded; k++) {
    long idx[3];
    source_grid(src, needed[k], idx);
    if (!in_box(idx, lo, hi)) map[m++] = needed[k];
  }
  MicaDiscretization *d = dist->local;
  d->nparticles = nlocal;
  MICA_CALL(MICA_MALLOC(d->x, nlocal * dim + 1));
  MICA_CALL(MICA_MALLOC(dist->global_node, nlocal + 1));
  MicaPartition *p = dist->partition;
  p->n = nlocal;
  MICA_CALL(MICA_MALLOC(p->part, nlocal + 1));
  for (long i = 0; i < nlocal; i++) {
    long idx[3];
    source_grid(src, map[i], idx);
    memcpy(d->x + i * dim, sd->x + map[i] * dim, sizeof(double) * (size_t)dim);
    if (src->key) { /* the owned ones in the layout's order, a ghost's number from its owner */
      p->part[i] = block_owner(idx, n, dist->procs);
      dist->global_node[i] = i < nowned ? offsets[rank] + i : -1;
    } else {
      dist->global_node[i] = global_number(idx[0] + n[0] * (idx[1] + n[1] * idx[2]), n, dist->procs, offsets, &p->part[i]);
    }
  }
  return MICA_SUCCESS;
}

/* The source's volume and boundary points become the local discretization's (moved, not copied). */
static void take_points(Source *src, MicaDiscretization *d) {
  MicaDiscretization *sd = src->disc;
  d->dim = sd->dim;
  d->mesh = sd->mesh, sd->mesh = NULL;
  d->ncells = sd->ncells, d->nquad = sd->nquad, d->qx = sd->qx, d->qw = sd->qw;
  d->nsets = sd->nsets, d->sets = sd->sets;
  sd->qx = sd->qw = NULL, sd->sets = NULL, sd->nsets = 0, sd->nquad = 0;
  /* NSNI's cells from the Gauss points (an irregular layout), the Gauss points kept for the error norms */
  d->nodal = sd->nodal, d->ngauss = sd->ngauss, d->gauss_x = sd->gauss_x, d->gauss_w = sd->gauss_w;
  sd->nodal = NULL, sd->gauss_x = sd->gauss_w = NULL, sd->ngauss = 0;
  d->volume = 0; /* this rank's part: summed once built */
  for (long q = 0; q < d->nquad; q++) d->volume += d->qw[q];
}

/* Nodal quadrature: the volume points, weights, cells and boundary sets are the rank's nodal cells' (moved), and
 * the cells' Gauss points are kept for the error norms, as mica_discretization_nodal keeps the whole ones. */
static void take_nodal_points(Source *src, MicaDiscretization *nodal, MicaDiscretization *d) {
  MicaDiscretization *sd = src->disc;
  d->dim = sd->dim;
  d->mesh = sd->mesh, sd->mesh = NULL;
  d->ngauss = sd->nquad, d->gauss_x = sd->qx, d->gauss_w = sd->qw;
  sd->qx = sd->qw = NULL, sd->nquad = 0;
  d->ncells = d->nquad = nodal->nquad, d->qx = nodal->qx, d->qw = nodal->qw, d->nodal = nodal->nodal;
  d->nsets = nodal->nsets, d->sets = nodal->sets;
  nodal->qx = nodal->qw = NULL, nodal->nodal = NULL, nodal->sets = NULL, nodal->nsets = 0, nodal->nquad = 0;
  d->volume = 0;
  for (long q = 0; q < d->nquad; q++) d->volume += d->qw[q];
}

/* The MLS approximation of the local particles with the source's radii and local spacings (a ghost at the
 * source's edge would get other ones from its truncated neighborhood; the spacings are the boundary methods' h). */
int parallel_local_mls(const MlsApprox *source, const MlsOptions *mls_opt, const long *map, MicaDistribution *dist) {
  const MicaDiscretization *d = dist->local;
  const int dim = d->dim;
  const double *radii = mls_radii(source), *spacing = mls_spacing(source);
  double *local = NULL;
  MICA_CALL(mls_create(dim, d->nparticles, d->x, mls_opt, &dist->mls));
  MICA_CALL(MICA_MALLOC(local, d->nparticles * dim + 1));
  for (long i = 0; i < d->nparticles; i++)
    memcpy(local + i * dim, radii + map[i] * dim, sizeof(double) * (size_t)dim);
  int ierr = mls_set_radii(dist->mls, local);
  for (long i = 0; i < d->nparticles; i++)
    memcpy(local + i * dim, spacing + map[i] * dim, sizeof(double) * (size_t)dim);
  if (!ierr) ierr = mls_set_spacing(dist->mls, local);
  const double *wparam = mls_weight_params(source); /* an adaptive weight's: from the supports covering each */
  for (long i = 0; i < d->nparticles; i++)
    memcpy(local + i * dim, wparam + map[i] * dim, sizeof(double) * (size_t)dim);
  if (!ierr) ierr = mls_set_weight_params(dist->mls, local);
  free(local);
  return ierr;
}

/* ---- public ----------------------------------------------------------------------------------------------- */

/* The rank's nodal cells (spec->nodal): those of its particle block, their points at the centroids for NSNI. */
static int owned_nodal(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                       const MicaOwnedSpec *spec, const long plo[3], const long phi[3], MicaDiscretization **nodal) {
  if (!spec->nodal) return MICA_SUCCESS;
  MICA_CALL(mica_discretization_nodal_block(shape, layout, cells, plo, phi, nodal));
  return spec->centroids ? mica_discretization_nodal_centroids(*nodal) : MICA_SUCCESS;
}

/* An irregular layout's blocks' counts (p->part_size) and offsets: each rank's from its source. Collective. */
static int irregular_offsets(int ierr, const Source *src, const long plo[3], const long phi[3], MicaPartition *p,
                             long *offsets) {
  long nowned = 0;
  MICA_CALL(mica_parallel_agree(ierr));
  for (long k = 0; k < src->disc->nparticles; k++) {
    long idx[3];
    source_grid(src, k, idx);
    nowned += in_box(idx, plo, phi);
  }
  MPI_Allgather(&nowned, 1, MPI_LONG, p->part_size, 1, MPI_LONG, mica_parallel_comm());
  for (int r = 0; r < p->nparts; r++) offsets[r + 1] = offsets[r] + p->part_size[r];
  for (int r = 0; r < p->nparts; r++)
    MICA_CHECK(p->part_size[r] > 0, MICA_ERR_INPUT, "parallel.data = \"distributed\": rank %d's block holds none of "
               "the irregular layout's %ld particles; use fewer ranks", r, offsets[p->nparts]);
  return MICA_SUCCESS;
}

/* An irregular layout's ghosts' numbers: each one's position among its owner's particles, asked by key. Collective. */
static int irregular_ghost_numbers(int ierr, const Source *src, const long *map, const long *offsets,
                                   MicaDistribution *dist) {
  long *key = NULL, *owned_key = NULL, *position = NULL;
  int *owner = NULL;
  const long ng = dist->nghost, no = dist->nowned;
  if (!ierr) ierr = MICA_MALLOC(key, ng + 1);
  if (!ierr) ierr = MICA_MALLOC(owner, ng + 1);
  if (!ierr) ierr = MICA_MALLOC(position, ng + 1);
  if (!ierr) ierr = MICA_MALLOC(owned_key, no + 1);
  for (long i = 0; !ierr && i < no; i++) owned_key[i] = src->key[map[i]];
  for (long g = 0; !ierr && g < ng; g++) key[g] = src->key[map[no + g]], owner[g] = dist->partition->part[no + g];
  ierr = mica_parallel_agree(ierr);
  if (!ierr) ierr = parallel_ghost_positions(ng, owner, key, no, owned_key, position);
  for (long g = 0; !ierr && g < ng; g++) dist->global_node[no + g] = offsets[owner[g]] + position[g];
  free(key), free(owned_key), free(position), free(owner);
  return ierr;
}

static int build_owned(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                       const MlsOptions *mls_opt, const MicaOwnedSpec *spec, MicaDistribution *dist) {
  const int P = mica_parallel_size(), rank = mica_parallel_rank();
  long n[3], m[3], per_cell, plo[3], phi[3], *offsets = NULL, *needed = NULL, nneeded = 0;
  long *map = NULL;
  Source src;
  MicaDiscretization *nodal = NULL;
  memset(&src, 0, sizeof src);
  int ierr = MICA_SUCCESS;
  /* an irregular layout: its particles drawn around the rank's box, its grid (and cells) the regular layout's */
  const MicaLayoutSpec *irregular = layout->kind == MICA_LAYOUT_IRREGULAR ? layout : NULL;
  MicaLayoutSpec grid = *layout;
  grid.kind = irregular ? MICA_LAYOUT_REGULAR : layout->kind;
  layout = &grid;
  MICA_CHECK(!irregular || !spec->nodal || (spec->centroids && !spec->cell_boundaries), MICA_ERR_ARGUMENT,
             "build_owned: off a grid only NSNI's cells (from the Gauss points)");
  MICA_CALL(mica_discretization_grid(shape, layout, cells, n, m, &per_cell));
  MICA_CALL(mica_block_split(P, shape->dim, m, dist->procs));
  for (int d = 0; d < shape->dim; d++)
    MICA_CHECK(dist->procs[d] <= n[d], MICA_ERR_INPUT,
               "parallel.data = \"distributed\": %d blocks along axis %d for %ld particles; use fewer ranks",
               dist->procs[d], d, n[d]);
  MICA_CALL(MICA_CALLOC(dist->partition, 1));
  MicaPartition *p = dist->partition;
  p->nparts = P;
  MICA_CALL(MICA_CALLOC(p->part_size, P + 1));
  MICA_CALL(MICA_CALLOC(offsets, P + 1));
  for (int r = 0; r < P && !irregular; r++) {
    block_box(r, dist->procs, n, plo, phi);
    p->part_size[r] = box_size(plo, phi);
    offsets[r + 1] = offsets[r] + p->part_size[r];
  }
  block_box(rank, dist->procs, n, plo, phi);
  block_box(rank, dist->procs, m, dist->cell_lo, dist->cell_hi);
  if (!irregular) ierr = owned_nodal(shape, layout, cells, spec, plo, phi, &nodal);
  if (!ierr)
    ierr = source_create(shape, layout, cells, mls_opt, n, m, plo, phi, dist, spec, nodal, irregular, &src, &needed,
                         &nneeded);
  if (irregular) MICA_CALL_CLEANUP(irregular_offsets(ierr, &src, plo, phi, p, offsets));
  for (int r = 0; r < P; r++)
    if ((double)p->part_size[r] * P / (double)offsets[P] > p->imbalance)
      p->imbalance = (double)p->part_size[r] * P / (double)offsets[P];
  if (!ierr) ierr = MICA_CALLOC(dist->local, 1);
  if (!ierr && nodal) take_nodal_points(&src, nodal, dist->local);
  else if (!ierr) take_points(&src, dist->local);
  if (!ierr) ierr = local_particles(&src, dist, n, needed, nneeded, offsets, &map);
  if (irregular) ierr = irregular_ghost_numbers(ierr, &src, map, offsets, dist);
  ierr = parallel_owned_complete(ierr, src.mls, mls_opt, map, offsets, spec->revolve, dist);
cleanup:
  source_free(&src);
  mica_discretization_destroy(&nodal);
  free(offsets), free(needed), free(map);
  return ierr;
}

typedef struct {
  const MicaShapeSpec *shape;
  const MicaLayoutSpec *layout;
  const MicaCellSpec *cells;
  const MlsOptions *mls_opt;
  const MicaOwnedSpec *spec;
} GridBuild;

static int build_grid(void *ctx, MicaDistribution *dist) {
  const GridBuild *b = ctx;
  return build_owned(b->shape, b->layout, b->cells, b->mls_opt, b->spec, dist);
}

int mica_distribution_create_owned(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                                   const MicaCellSpec *cells, const MlsOptions *mls_opt, const MicaOwnedSpec *spec,
                                   MicaDistribution **out) {
  GridBuild b = {shape, layout, cells, mls_opt, spec};
  return parallel_owned_create(build_grid, &b, spec, out);
}

int parallel_owned_complete(int ierr, const MlsApprox *source, const MlsOptions *mls_opt, const long *map,
                            const long *offsets, int revolve, MicaDistribution *dist) {
  if (!ierr && revolve) ierr = mica_discretization_revolve(dist->local);
  if (!ierr) ierr = parallel_local_mls(source, mls_opt, map, dist);
  /* every rank reaches the plan's collectives, or none */
  MICA_CALL(mica_parallel_agree(ierr));
  return parallel_ghost_plan(dist, offsets);
}

/* Collective, after agreeing on ierr: the body's volume, the global counts and the statistics (start: when the
 * distribution's build began). */
static int owned_finish(int ierr, MicaDistribution *dist, double start) {
  if (!ierr) ierr = mica_parallel_inject("build");
  MICA_CALL(mica_parallel_agree(ierr));
  dist->nsets = dist->local->nsets;
  dist->nowned_nodes = dist->nowned; /* until extra nodes are added */
  /* the body's volume, not the rank's part (the penalty's length scale L = volume^(1/dim) is the body's) */
  MICA_CALL(mica_parallel_sum(MICA_SUCCESS, &dist->local->volume, 1));
  dist->nparticles = dist->nglobal_nodes = mica_parallel_sum_long(dist->nowned);
  MicaParallelStats *st = &dist->stats;
  st->owned_particles = dist->nowned;
  st->ghost_particles = dist->nghost;
  st->ghost_particles_max = mica_parallel_max_long(dist->nghost);
  st->owned_points = dist->local->nquad;
  MPI_Allreduce(&st->owned_points, &st->max_owned_points, 1, MPI_LONG, MPI_MAX, mica_parallel_comm());
  MPI_Allreduce(&st->owned_points, &st->min_owned_points, 1, MPI_LONG, MPI_MIN, mica_parallel_comm());
  st->time_partition = mica_wtime() - start;
  return MICA_SUCCESS;
}

int parallel_owned_create(int (*build)(void *ctx, MicaDistribution *dist), void *ctx, const MicaOwnedSpec *spec,
                          MicaDistribution **out) {
  *out = NULL;
  const double start = mica_wtime();
  MicaDistribution *dist = NULL;
  int ierr = MICA_CALLOC(dist, 1);
  if (!ierr) {
    dist->owned = 1;
    dist->error_order = spec->error_order;
    ierr = build(ctx, dist);
  }
  MICA_CALL_CLEANUP(owned_finish(ierr, dist, start));
  *out = dist;
  dist = NULL;
cleanup:
  mica_distribution_destroy(&dist);
  return ierr;
}
