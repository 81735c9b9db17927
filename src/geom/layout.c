/* Particle layouts in parameter space (docs/theory.md §geometry, "Particle layouts"):
 *   regular    count[d] evenly spaced values per axis, tensor product;
 *   graded     per axis, spacings growing geometrically, h_i ∝ q^i with q^(count−2) = grading[d];
 *   jittered   regular, then each coordinate of a particle that is interior along that axis moves by a
 *              uniform random amount in ±jitter × (the smaller neighboring spacing): particles on a face
 *              of the parameter box stay on it (they move only along the face), and coordinates on a
 *              kink of the map (the plate's corner line) do not move;
 *   irregular  the regular layout's particles on the faces of the parameter box, and inside, Poisson-disk
 *              samples by dart throwing: uniform random candidates, accepted when no particle lies within
 *              MIN_DISTANCE regular spacings (distances measured in units of the regular spacing per axis,
 *              via a background grid of cells one minimum distance wide), tile by tile (16 spacings wide in
 *              2-D, 4 in 3-D; one colour of tiles at a time), until each tile holds as many particles as the regular layout's
 *              interior has there or ATTEMPTS_PER_PARTICLE × that many candidates were drawn; a box of the
 *              layout is drawn from the tiles around it alone (geom_layout_irregular_box), so that each rank of
 *              a distributed run draws its own part of the same layout.
 * Random numbers come from mica/random.h seeded with layout->seed: the same seed gives the same particles.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom_private.h"
#include "mica/random.h"

/* Poisson-disk minimum distance, in regular spacings */
#define MIN_DISTANCE 0.8
enum { ATTEMPTS_PER_PARTICLE = 1000 };

/* ---- 1-D axes ---- */

/* t_i = (Σ_{k<i} q^k) / (Σ_{k<n−1} q^k): spacing ratio q between neighbors, last/first = q^(n−2). */
static void graded_axis(long n, double ratio, double *t) {
  const double q = n > 2 ? pow(ratio, 1.0 / (double)(n - 2)) : 1.0;
  double sum = 0.0, h = 1.0;
  t[0] = 0.0;
  for (long i = 1; i < n; i++) {
    sum += h;
    t[i] = sum;
    h *= q;
  }
  for (long i = 1; i < n; i++) t[i] /= sum;
  t[n - 1] = 1.0;
}

int geom_axes_create(const MicaLayoutSpec *layout, int dim, GeomAxes *axes) {
  int ierr = MICA_SUCCESS;
  *axes = (GeomAxes){.dim = dim};
  MICA_CHECK(layout->kind >= MICA_LAYOUT_REGULAR && layout->kind <= MICA_LAYOUT_IRREGULAR, MICA_ERR_ARGUMENT,
             "unknown layout kind %d", (int)layout->kind);
  for (int d = 0; d < dim; d++) {
    const long n = layout->count[d];
    MICA_CHECK(n >= 2, MICA_ERR_INPUT, "particles: count[%d] = %ld, need at least 2 per axis", d, n);
    if (layout->kind == MICA_LAYOUT_GRADED)
      MICA_CHECK(layout->grading[d] > 0 && isfinite(layout->grading[d]), MICA_ERR_INPUT,
                 "particles: grading[%d] = %g must be positive", d, layout->grading[d]);
  }
  for (int d = 0; d < dim; d++) {
    const long n = layout->count[d];
    axes->n[d] = n;
    MICA_CALL_CLEANUP(MICA_MALLOC(axes->t[d], n));
    if (layout->kind == MICA_LAYOUT_GRADED) {
      graded_axis(n, layout->grading[d], axes->t[d]);
    } else {
      for (long i = 0; i < n; i++) axes->t[d][i] = (double)i / (double)(n - 1);
    }
  }
  return MICA_SUCCESS;
cleanup:
  geom_axes_destroy(axes);
  return ierr;
}

void geom_axes_destroy(GeomAxes *axes) {
  for (int d = 0; d < 3; d++) MICA_FREE(axes->t[d]);
}

/* ---- regular and graded: the tensor product, axis 0 fastest ---- */

static long tensor_count(const GeomAxes *axes) {
  long n = 1;
  for (int d = 0; d < axes->dim; d++) n *= axes->n[d];
  return n;
}

/* The per-axis indices of tensor-product point p (axis 0 fastest). */
static void tensor_index(const GeomAxes *axes, long p, long idx[3]) {
  for (int d = 0; d < axes->dim; d++) {
    idx[d] = p % axes->n[d];
    p /= axes->n[d];
  }
}

static void tensor_points(const GeomAxes *axes, double *xi) {
  const int dim = axes->dim;
  const long n = tensor_count(axes);
  for (long p = 0; p < n; p++) {
    long idx[3];
    tensor_index(axes, p, idx);
    for (int d = 0; d < dim; d++) xi[p * dim + d] = axes->t[d][idx[d]];
  }
}

/* ---- jittered ---- */

static int on_kink(const GeomMap *map, int d, double t) {
  for (int k = 0; k < map->nkinks[d]; k++)
    if (fabs(t - map->kinks[d][k]) < 1e-12) return 1;
  return 0;
}

static void jitter_points(const GeomMap *map, const GeomAxes *axes, double jitter, MicaRandom *rng,
                          double *xi) {
  const int dim = axes->dim;
  const long n = tensor_count(axes);
  for (long p = 0; p < n; p++) {
    long idx[3];
    tensor_index(axes, p, idx);
    for (int d = 0; d < dim; d++) {
      const double *t = axes->t[d];
      const long i = idx[d];
      const double u = 2.0 * mica_random_uniform(rng) - 1.0; /* drawn for every coordinate: stable stream */
      if (i == 0 || i == axes->n[d] - 1 || on_kink(map, d, t[i])) continue;
      const double h = fmin(t[i + 1] - t[i], t[i] - t[i - 1]);
      xi[p * dim + d] = t[i] + u * jitter * h;
    }
  }
}

/* ---- irregular: regular boundary + Poisson-disk interior, drawn tile by tile ---- */

/* Distances are in regular spacings: a point's scaled coordinates s_d = ξ_d (n_d − 1) lie in [0, n_d − 1]. The
 * interior is cut into tiles w spacings wide (the last one along an axis narrower); tile t's quota is the number of
 * interior grid points i with ⌊i_d / w⌋ = t_d, so the quotas sum to the regular layout's interior count. Tiles are
 * drawn colour by colour (colour = the parities of t, 2^dim colours): two tiles of one colour lie at least one tile
 * apart, farther than MIN_DISTANCE, so no dart of one sees the other's and the order within a colour does not matter;
 * a tile's darts see only its neighbours of earlier colours. Tile t draws from its own place in the counter-based
 * stream (tile index × 2^32), so each tile's particles depend only on its neighbourhood: a box of the layout is drawn
 * from the tiles within 2^dim − 1 − c tiles of it for colour c (whose earlier-colour neighbours are then drawn too),
 * the same particles whatever the box, and the whole layout is the box of everything. */
static const uint64_t TILE_STREAM = (uint64_t)1 << 32;

/* The tiles' width w in spacings. 2-D, 16: in tiles of 4 a tile drawn after its neighbours often jams below its quota
 * (the plane's random sequential draw jams at 1.09 particles a spacing² for the distance 0.8, the quota is 1), 3 % of
 * the particles missing, and the tiles' edges show in the errors (energy 14 % above the whole draw's on the
 * manufactured field at 65²); at 16 both go (0.02 % missing). 3-D, 4: the space's draw jams at 1.43, far from 1;
 * the region a rank draws reaches (2^dim − 1) w beyond its box, 48 spacings in 2-D and 28 in 3-D. */
static long tile_width(int dim) { return dim == 3 ? 4 : 16; }

static int on_parameter_boundary(const GeomAxes *axes, const long idx[3]) {
  for (int d = 0; d < axes->dim; d++)
    if (idx[d] == 0 || idx[d] == axes->n[d] - 1) return 1;
  return 0;
}

/* A uniform grid over the scaled box [origin, origin + m·MIN_DISTANCE) with cells MIN_DISTANCE wide, each a linked
 * list of the points in it: a candidate needs to look at the 3^dim cells around its own only. */
typedef struct {
  int dim;
  long m[3];
  double origin[3];
  long *head, *next;
  const double *s; /* scaled coordinates of the points so far */
} DiskGrid;

static long disk_axis(const DiskGrid *g, const double *s, int d) {
  long k = (long)floor((s[d] - g->origin[d]) / MIN_DISTANCE);
  return k < 0 ? 0 : k >= g->m[d] ? g->m[d] - 1 : k;
}

static long disk_cell(const DiskGrid *g, const double *s) {
  long c = 0;
  for (int d = g->dim - 1; d >= 0; d--) c = c * g->m[d] + disk_axis(g, s, d);
  return c;
}

static int disk_is_free(const DiskGrid *g, const double *s) {
  long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int d = 0; d < g->dim; d++) {
    const long k = disk_axis(g, s, d);
    lo[d] = k > 0 ? k - 1 : 0;
    hi[d] = k + 1 < g->m[d] ? k + 1 : g->m[d] - 1;
  }
  for (long c2 = lo[2]; c2 <= hi[2]; c2++)
    for (long c1 = lo[1]; c1 <= hi[1]; c1++)
      for (long c0 = lo[0]; c0 <= hi[0]; c0++) {
        const long cell = (c2 * g->m[1] + c1) * g->m[0] + c0;
        for (long p = g->head[cell]; p >= 0; p = g->next[p]) {
          double r2 = 0.0;
          for (int d = 0; d < g->dim; d++)
            r2 += (s[d] - g->s[p * g->dim + d]) * (s[d] - g->s[p * g->dim + d]);
          if (r2 < MIN_DISTANCE * MIN_DISTANCE) return 0;
        }
      }
  return 1;
}

static void disk_insert(DiskGrid *g, long p) {
  const long cell = disk_cell(g, &g->s[p * g->dim]);
  g->next[p] = g->head[cell];
  g->head[cell] = p;
}

/* The tiles of the interior and the range of them drawn. */
typedef struct {
  int dim, colours;
  long w; /* tile_width */
  long n[3], tiles[3];
  long lo[3], hi[3]; /* the tiles that hold particles of the box (colour 2^dim − 1's range) */
} Tiling;

/* Tiles of interior indices 1 .. n − 2. */
static long tile_count_along(long n, long w) { return n > 2 ? (n - 2) / w + 1 : 0; }

/* Interior grid indices i (1 ≤ i ≤ n − 2) in tile t along an axis. */
static long tile_quota_along(long n, long w, long t) {
  long a = t * w, b = (t + 1) * w - 1;
  a = a < 1 ? 1 : a, b = b > n - 2 ? n - 2 : b;
  return b >= a ? b - a + 1 : 0;
}

static int tile_colour(const Tiling *T, const long t[3]) {
  int c = 0;
  for (int d = 0; d < T->dim; d++) c |= (int)(t[d] & 1) << d;
  return c;
}

/* The tiles of colour position c to draw: the box's tiles widened by colours − 1 − c, within the interior's. */
static void tile_range(const Tiling *T, int c, long lo[3], long hi[3]) {
  const long widen = T->colours - 1 - c;
  for (int d = 0; d < 3; d++) {
    lo[d] = d < T->dim ? T->lo[d] - widen : 0, hi[d] = d < T->dim ? T->hi[d] + widen : 1;
    lo[d] = lo[d] < 0 ? 0 : lo[d];
    if (d < T->dim) hi[d] = hi[d] > T->tiles[d] ? T->tiles[d] : hi[d];
  }
}

/* The box [lo, hi) of grid indices holds the particles whose nearest grid point is in it: scaled coordinates in
 * [lo − ½, hi − ½], so the tiles from ⌊(lo − ½)/w⌋ to ⌊(hi − ½)/w⌋. */
static void tiling_init(const GeomAxes *axes, const long lo[3], const long hi[3], Tiling *T) {
  memset(T, 0, sizeof *T);
  T->dim = axes->dim, T->colours = 1 << axes->dim, T->w = tile_width(axes->dim);
  for (int d = 0; d < 3; d++) {
    T->n[d] = d < axes->dim ? axes->n[d] : 1;
    T->tiles[d] = d < axes->dim ? tile_count_along(axes->n[d], T->w) : 1;
    if (d >= axes->dim) {
      T->lo[d] = 0, T->hi[d] = 1;
      continue;
    }
    const double w = (double)T->w;
    const long a = (long)floor(((double)lo[d] - 0.5) / w), b = (long)floor(((double)hi[d] - 0.5) / w) + 1;
    T->lo[d] = a < 0 ? 0 : a, T->hi[d] = b > T->tiles[d] ? T->tiles[d] : b;
  }
}

/* The drawn region: the widest range's tiles and a tile more (boundary particles a dart may see), in scaled
 * coordinates, and the grid indices of its boundary particles. */
static void drawn_region(const Tiling *T, double slo[3], double shi[3], long glo[3], long ghi[3]) {
  long lo[3], hi[3];
  tile_range(T, 0, lo, hi);
  for (int d = 0; d < 3; d++) {
    slo[d] = 0, shi[d] = 0, glo[d] = 0, ghi[d] = 1;
    if (d >= T->dim) continue;
    glo[d] = (lo[d] - 1) * T->w, ghi[d] = (hi[d] + 1) * T->w + 1;
    glo[d] = glo[d] < 0 ? 0 : glo[d], ghi[d] = ghi[d] > T->n[d] ? T->n[d] : ghi[d];
    slo[d] = (double)glo[d], shi[d] = (double)(ghi[d] - 1);
  }
}

/* The most particles a tile holds (its quota): w^dim. */
static long tile_capacity(const Tiling *T) { return T->dim == 3 ? T->w * T->w * T->w : T->w * T->w; }

/* Room in the drawn region: its boundary grid points and its tiles' quotas. */
static long drawn_capacity(const Tiling *T, const long glo[3], const long ghi[3]) {
  long count = 1, lo[3], hi[3];
  for (int d = 0; d < 3; d++) count *= ghi[d] - glo[d];
  tile_range(T, 0, lo, hi);
  long tiles = 1;
  for (int d = 0; d < 3; d++) tiles *= hi[d] - lo[d];
  return count + tiles * tile_capacity(T);
}

/* The tiles' streams: from a scrambled seed, since mica_random_seed(s + k) is mica_random_seed(s)'s stream k draws on
 * (seeds dim apart would give nearly the same darts, shifted by one candidate). */
static MicaRandom tile_streams(uint64_t seed) {
  MicaRandom r = mica_random_seed(seed);
  return mica_random_seed(mica_random_next(&r));
}

/* Darts into tile t until its quota is met or ATTEMPTS_PER_PARTICLE × quota were thrown; the accepted ones
 * appended to the grid's points from *count on, each with its key. */
static void draw_tile(const Tiling *T, uint64_t seed, const long t[3], long key_base, DiskGrid *g, double *s,
                      long *key, long *count) {
  const int dim = T->dim;
  long quota = 1;
  double lo[3], width[3];
  for (int d = 0; d < dim; d++) { /* the region of its grid points, [t·w − ½, (t + 1)·w − ½], to the faces */
    quota *= tile_quota_along(T->n[d], T->w, t[d]);
    lo[d] = t[d] == 0 ? 0.0 : (double)(t[d] * T->w) - 0.5;
    const double hi = t[d] == T->tiles[d] - 1 ? (double)(T->n[d] - 1) : (double)((t[d] + 1) * T->w) - 0.5;
    width[d] = hi - lo[d];
  }
  const long linear = t[0] + T->tiles[0] * (t[1] + T->tiles[1] * t[2]);
  MicaRandom rng = mica_random_skip(tile_streams(seed), (uint64_t)linear * TILE_STREAM);
  long accepted = 0;
  for (long a = 0; a < ATTEMPTS_PER_PARTICLE * quota && accepted < quota; a++) {
    double *c = &s[*count * dim];
    for (int d = 0; d < dim; d++) c[d] = lo[d] + width[d] * mica_random_uniform(&rng);
    if (!disk_is_free(g, c)) continue;
    disk_insert(g, *count);
    key[(*count)++] = key_base + accepted++;
  }
}

/* The boundary grid points of the drawn region (ascending grid index), then the tiles colour by colour. */
static void draw_region(const GeomAxes *axes, const Tiling *T, uint64_t seed, const long glo[3], const long ghi[3],
                        DiskGrid *g, double *s, long *key, long *count) {
  const int dim = T->dim;
  const long ngrid = tensor_count(axes), ntiles = T->tiles[0] * T->tiles[1] * T->tiles[2];
  const long per_tile = tile_capacity(T);
  for (long i2 = glo[2]; i2 < ghi[2]; i2++)
    for (long i1 = glo[1]; i1 < ghi[1]; i1++)
      for (long i0 = glo[0]; i0 < ghi[0]; i0++) {
        const long idx[3] = {i0, i1, i2};
        if (!on_parameter_boundary(axes, idx)) continue;
        for (int d = 0; d < dim; d++) s[*count * dim + d] = (double)idx[d];
        disk_insert(g, *count);
        key[(*count)++] = i0 + T->n[0] * (i1 + T->n[1] * i2);
      }
  for (int c = 0; c < T->colours; c++) {
    long lo[3], hi[3];
    tile_range(T, c, lo, hi);
    for (long t2 = lo[2]; t2 < hi[2]; t2++)
      for (long t1 = lo[1]; t1 < hi[1]; t1++)
        for (long t0 = lo[0]; t0 < hi[0]; t0++) {
          const long t[3] = {t0, t1, t2};
          if (tile_colour(T, t) != c) continue;
          const long linear = t0 + T->tiles[0] * (t1 + T->tiles[1] * t2);
          draw_tile(T, seed, t, ngrid + ((long)c * ntiles + linear) * per_tile, g, s, key, count);
        }
  }
}

/* The index along axis d of the regular grid point nearest to parameter coordinate xi (t_i = i / (n_d − 1)): the one
 * rule by which an irregular particle belongs to a grid point, for a box's draw and for grid_index alike. */
static long nearest_grid_index(const GeomAxes *axes, int d, double xi) {
  const long i = lround(xi * (double)(axes->n[d] - 1));
  return i < 0 ? 0 : i > axes->n[d] - 1 ? axes->n[d] - 1 : i;
}

/* Whether scaled point s has its nearest grid point in [lo, hi) (as geom_layout_grid_index rounds it). */
static int nearest_in_box(const GeomAxes *axes, const double *s, const long lo[3], const long hi[3]) {
  for (int d = 0; d < axes->dim; d++) {
    const long i = nearest_grid_index(axes, d, s[d] / (double)(axes->n[d] - 1));
    if (i < lo[d] || i >= hi[d]) return 0;
  }
  return 1;
}

int geom_layout_irregular_box(const GeomAxes *axes, uint64_t seed, const long lo[3], const long hi[3], long *n,
                              double **xi, long **key) {
  int ierr = MICA_SUCCESS;
  const int dim = axes->dim;
  Tiling T;
  double slo[3], shi[3];
  long glo[3], ghi[3], ncells = 1, count = 0;
  double *s = NULL;
  long *all_keys = NULL;
  DiskGrid g = {.dim = dim, .m = {1, 1, 1}};
  *n = 0, *xi = NULL, *key = NULL;
  tiling_init(axes, lo, hi, &T);
  drawn_region(&T, slo, shi, glo, ghi);
  const long capacity = drawn_capacity(&T, glo, ghi);
  for (int d = 0; d < dim; d++) {
    g.origin[d] = slo[d];
    g.m[d] = (long)ceil((shi[d] - slo[d]) / MIN_DISTANCE) + 1;
    ncells *= g.m[d];
  }
  MICA_CALL_CLEANUP(MICA_MALLOC(g.head, ncells));
  MICA_CALL_CLEANUP(MICA_MALLOC(g.next, capacity));
  MICA_CALL_CLEANUP(MICA_MALLOC(s, capacity * dim));
  MICA_CALL_CLEANUP(MICA_MALLOC(all_keys, capacity));
  g.s = s;
  for (long c = 0; c < ncells; c++) g.head[c] = -1;
  draw_region(axes, &T, seed, glo, ghi, &g, s, all_keys, &count);
  /* the box's particles, in key order: the boundary's by grid index first, then the darts as drawn */
  long kept = 0;
  for (long p = 0; p < count; p++) kept += nearest_in_box(axes, &s[p * dim], lo, hi);
  MICA_CALL_CLEANUP(MICA_MALLOC(*xi, kept * dim + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(*key, kept + 1));
  for (long p = 0; p < count; p++) {
    if (!nearest_in_box(axes, &s[p * dim], lo, hi)) continue;
    for (int d = 0; d < dim; d++) (*xi)[*n * dim + d] = s[p * dim + d] / (double)(axes->n[d] - 1);
    (*key)[(*n)++] = all_keys[p];
  }
cleanup:
  MICA_FREE(g.head);
  MICA_FREE(g.next);
  MICA_FREE(s);
  MICA_FREE(all_keys);
  if (ierr) {
    MICA_FREE(*xi);
    MICA_FREE(*key);
    *n = 0;
  }
  return ierr;
}

/* The particles of the index box [lo, hi) of a regular, graded or jittered layout, in grid order (axis 0
 * fastest): the values geom_layout_particles gives them, a jittered coordinate from its own draw of the stream
 * (draw p·dim + d of particle p, coordinate d, as jitter_points draws them in turn). */
int geom_layout_box(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes, const long lo[3],
                    const long hi[3], long *n, double **xi) {
  const int dim = axes->dim;
  MICA_CHECK(layout->kind != MICA_LAYOUT_IRREGULAR, MICA_ERR_ARGUMENT, "geom_layout_box: an irregular layout has no grid");
  if (layout->kind == MICA_LAYOUT_JITTERED)
    MICA_CHECK(layout->jitter >= 0 && layout->jitter < 0.5, MICA_ERR_INPUT,
               "particles: jitter = %g must lie in [0, 0.5) (a fraction of the spacing)", layout->jitter);
  long count = 1;
  for (int d = 0; d < 3; d++) count *= hi[d] > lo[d] ? hi[d] - lo[d] : 0;
  *n = count;
  MICA_CALL(MICA_MALLOC(*xi, count * dim + 1));
  const MicaRandom rng = mica_random_seed((uint64_t)layout->seed);
  long k = 0;
  for (long i2 = lo[2]; i2 < hi[2]; i2++)
    for (long i1 = lo[1]; i1 < hi[1]; i1++)
      for (long i0 = lo[0]; i0 < hi[0]; i0++, k++) {
        const long idx[3] = {i0, i1, i2}, p = i0 + axes->n[0] * (i1 + axes->n[1] * i2);
        for (int d = 0; d < dim; d++) {
          const double *t = axes->t[d];
          const long i = idx[d];
          (*xi)[k * dim + d] = t[i];
          if (layout->kind != MICA_LAYOUT_JITTERED) continue;
          MicaRandom draw = mica_random_skip(rng, (uint64_t)(p * dim + d));
          const double u = 2.0 * mica_random_uniform(&draw) - 1.0;
          if (i == 0 || i == axes->n[d] - 1 || on_kink(map, d, t[i])) continue;
          const double h = fmin(t[i + 1] - t[i], t[i] - t[i - 1]);
          (*xi)[k * dim + d] = t[i] + u * layout->jitter * h;
        }
      }
  return MICA_SUCCESS;
}

int geom_layout_grid_index(const GeomAxes *axes, long n, const double *xi, long **index) {
  MICA_CALL(MICA_MALLOC(*index, n + 1));
  for (long p = 0; p < n; p++) {
    long k = 0;
    for (int d = axes->dim - 1; d >= 0; d--) k = k * axes->n[d] + nearest_grid_index(axes, d, xi[p * axes->dim + d]);
    (*index)[p] = k;
  }
  return MICA_SUCCESS;
}

int geom_layout_particles(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes, long *n,
                          double **xi) {
  const long total = tensor_count(axes);
  MicaRandom rng = mica_random_seed((uint64_t)layout->seed);
  *n = 0;
  if (layout->kind == MICA_LAYOUT_JITTERED)
    MICA_CHECK(layout->jitter >= 0 && layout->jitter < 0.5, MICA_ERR_INPUT,
               "particles: jitter = %g must lie in [0, 0.5) (a fraction of the spacing)", layout->jitter);
  if (layout->kind == MICA_LAYOUT_IRREGULAR) { /* the box of every grid point */
    long *key = NULL;
    const long lo[3] = {0, 0, 0}, hi[3] = {axes->n[0], axes->dim > 1 ? axes->n[1] : 1, axes->dim > 2 ? axes->n[2] : 1};
    MICA_CALL(geom_layout_irregular_box(axes, (uint64_t)layout->seed, lo, hi, n, xi, &key));
    MICA_FREE(key);
    return MICA_SUCCESS;
  }
  MICA_CALL(MICA_MALLOC(*xi, total * axes->dim));
  tensor_points(axes, *xi);
  if (layout->kind == MICA_LAYOUT_JITTERED) jitter_points(map, axes, layout->jitter, &rng, *xi);
  *n = total;
  return MICA_SUCCESS;
}
