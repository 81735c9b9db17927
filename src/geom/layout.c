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
 *              via a background grid of cells one minimum distance wide), until there are as many interior
 *              particles as the regular layout has or ATTEMPTS_PER_PARTICLE × that many candidates
 *              were drawn.
 * Random numbers come from mica/random.h seeded with layout->seed: the same seed gives the same particles.
 */
#include <math.h>
#include <stdlib.h>

#include "geom_private.h"
#include "mica/random.h"

#define MIN_DISTANCE 0.8 /* Poisson-disk minimum distance, in regular spacings */
enum { ATTEMPTS_PER_PARTICLE = 200 };

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

/* ---- irregular: regular boundary + Poisson-disk interior ---- */

static int on_parameter_boundary(const GeomAxes *axes, const long idx[3]) {
  for (int d = 0; d < axes->dim; d++)
    if (idx[d] == 0 || idx[d] == axes->n[d] - 1) return 1;
  return 0;
}

/* A uniform grid over the scaled parameter box [0, n_d − 1]^dim with cells MIN_DISTANCE wide, each a
 * linked list of the points in it: a candidate needs to look at the 3^dim cells around its own only. */
typedef struct {
  int dim;
  long m[3];
  long *head, *next;
  const double *s; /* scaled coordinates of the points so far */
} DiskGrid;

static long disk_cell(const DiskGrid *g, const double *s) {
  long c = 0;
  for (int d = g->dim - 1; d >= 0; d--) {
    long k = (long)(s[d] / MIN_DISTANCE);
    if (k >= g->m[d]) k = g->m[d] - 1;
    c = c * g->m[d] + k;
  }
  return c;
}

static int disk_is_free(const DiskGrid *g, const double *s) {
  long k[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int d = 0; d < g->dim; d++) {
    k[d] = (long)(s[d] / MIN_DISTANCE);
    lo[d] = k[d] > 0 ? k[d] - 1 : 0;
    hi[d] = k[d] + 1 < g->m[d] ? k[d] + 1 : g->m[d] - 1;
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

/* Fills s (scaled coordinates, room for the regular count) with the boundary particles and then darts;
 * returns the number of points in *n. */
static int poisson_disk(const GeomAxes *axes, MicaRandom *rng, double *s, long *n) {
  int ierr = MICA_SUCCESS;
  const int dim = axes->dim;
  const long total = tensor_count(axes);
  long ncells = 1, interior = 1, count = 0;
  DiskGrid g = {.dim = dim, .m = {1, 1, 1}, .s = s};
  for (int d = 0; d < dim; d++) {
    g.m[d] = (long)ceil((double)(axes->n[d] - 1) / MIN_DISTANCE) + 1;
    ncells *= g.m[d];
    interior *= axes->n[d] - 2;
  }
  MICA_CALL_CLEANUP(MICA_MALLOC(g.head, ncells));
  MICA_CALL_CLEANUP(MICA_MALLOC(g.next, total));
  for (long c = 0; c < ncells; c++) g.head[c] = -1;
  for (long p = 0; p < total; p++) {
    long idx[3];
    tensor_index(axes, p, idx);
    if (!on_parameter_boundary(axes, idx)) continue;
    for (int d = 0; d < dim; d++) s[count * dim + d] = (double)idx[d];
    disk_insert(&g, count++);
  }
  const long boundary = count, attempts = ATTEMPTS_PER_PARTICLE * interior;
  for (long a = 0; a < attempts && count - boundary < interior; a++) {
    double *c = &s[count * dim];
    for (int d = 0; d < dim; d++) c[d] = (double)(axes->n[d] - 1) * mica_random_uniform(rng);
    if (disk_is_free(&g, c)) disk_insert(&g, count++);
  }
  *n = count;
cleanup:
  MICA_FREE(g.head);
  MICA_FREE(g.next);
  return ierr;
}

static int irregular_points(const GeomAxes *axes, MicaRandom *rng, long *n, double *xi) {
  MICA_CALL(poisson_disk(axes, rng, xi, n));
  for (long p = 0; p < *n; p++)
    for (int d = 0; d < axes->dim; d++) {
      double *v = &xi[p * axes->dim + d];
      *v = *v / (double)(axes->n[d] - 1);
    }
  return MICA_SUCCESS;
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
    for (int d = axes->dim - 1; d >= 0; d--) { /* regular axes: t_i = i / (n_d − 1) */
      long i = lround(xi[p * axes->dim + d] * (double)(axes->n[d] - 1));
      i = i < 0 ? 0 : i > axes->n[d] - 1 ? axes->n[d] - 1 : i;
      k = k * axes->n[d] + i;
    }
    (*index)[p] = k;
  }
  return MICA_SUCCESS;
}

int geom_layout_particles(const GeomMap *map, const MicaLayoutSpec *layout, const GeomAxes *axes, long *n,
                          double **xi) {
  int ierr = MICA_SUCCESS;
  const long total = tensor_count(axes);
  MicaRandom rng = mica_random_seed((uint64_t)layout->seed);
  *n = 0;
  if (layout->kind == MICA_LAYOUT_JITTERED)
    MICA_CHECK(layout->jitter >= 0 && layout->jitter < 0.5, MICA_ERR_INPUT,
               "particles: jitter = %g must lie in [0, 0.5) (a fraction of the spacing)", layout->jitter);
  MICA_CALL(MICA_MALLOC(*xi, total * axes->dim));
  if (layout->kind == MICA_LAYOUT_IRREGULAR) {
    MICA_CALL_CLEANUP(irregular_points(axes, &rng, n, *xi));
    return MICA_SUCCESS;
  }
  tensor_points(axes, *xi);
  if (layout->kind == MICA_LAYOUT_JITTERED) jitter_points(map, axes, layout->jitter, &rng, *xi);
  *n = total;
  return MICA_SUCCESS;
cleanup:
  MICA_FREE(*xi);
  return ierr;
}
