/* Unit tests of the neighbor search (src/mls/search.c) against brute force.
 *
 *   - support queries: random, clustered, planar and degenerate clouds in 1-3 dimensions, radii varying by a
 *     factor 3 per particle and axis (and one huge outlier), box and ball supports, k-d tree and cells,
 *     radii replaced a second time on the same search (refit). Query points: random (inside and well
 *     outside the cloud), exactly on particles, and exactly on support boundaries. The sorted index lists
 *     must be identical to a brute-force scan using the same membership test.
 *   - kNN: the squared distances equal the k smallest of a brute-force scan, and each index is a distinct
 *     other particle at its reported distance.
 *   - local spacing: exact spacing on regular grids (isotropic 3-D, anisotropic 2-D, 1-D, one-particle-thick
 *     layers), a band on a jittered grid, equality with a brute-force evaluation of the definition on
 *     random clouds, and coincident particles.
 *   - the result array grows from NULL / capacity 0 and is not reallocated when it is large enough.
 *   - contract violations return MICA_ERR_ARGUMENT (and an unmeasurable spacing MICA_ERR_INPUT).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/mls.h"

/* ---- helpers ------------------------------------------------------------------------------------- */

/* xorshift64*: reproducible on every platform. */
static uint64_t rng_state;
static void rng_seed(uint64_t seed) { rng_state = seed * 2685821657736338717ULL + 1; }
static double uniform(double a, double b) {
  rng_state ^= rng_state >> 12, rng_state ^= rng_state << 25, rng_state ^= rng_state >> 27;
  uint64_t r = rng_state * 2685821657736338717ULL;
  return a + (b - a) * ((double)(r >> 11) * 0x1.0p-53);
}

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static void check_error(int ierr, int expected) {
  if (ierr != expected) {
    print_error("expected error %d, got %d (%s)\n", expected, ierr, mica_error_message());
    fail();
  }
  assert_true(strlen(mica_error_message()) > 0);
  mica_error_clear();
}

/* The membership test of the contract, particle by particle: indices in ascending order. */
static long brute_query(int dim, long n, const double *x, MlsSupportKind support, const double *radii,
                        const double *p, long *out) {
  long count = 0;
  for (long i = 0; i < n; i++) {
    int in = 1;
    if (support == MLS_SUPPORT_BALL) {
      double s = 0;
      for (int d = 0; d < dim; d++) s += (p[d] - x[i * dim + d]) * (p[d] - x[i * dim + d]);
      in = sqrt(s) < radii[i * dim];
    } else {
      for (int d = 0; d < dim; d++) in &= fabs(p[d] - x[i * dim + d]) < radii[i * dim + d];
    }
    if (in) out[count++] = i;
  }
  return count;
}

static double sq_dist(int dim, const double *a, const double *b) {
  double s = 0;
  for (int d = 0; d < dim; d++) s += (a[d] - b[d]) * (a[d] - b[d]);
  return s;
}

/* A test cloud: particles and two sets of radii. */
typedef struct {
  int dim;
  long n;
  double *x, *radii[2];
  double lo[3], hi[3], rmax;
} Cloud;

static void cloud_alloc(Cloud *c, int dim, long n) {
  c->dim = dim, c->n = n;
  c->x = malloc((size_t)(n * dim) * sizeof(double));
  for (int s = 0; s < 2; s++) c->radii[s] = malloc((size_t)(n * dim) * sizeof(double));
  assert_non_null(c->x);
}

static void cloud_free(Cloud *c) {
  free(c->x);
  free(c->radii[0]);
  free(c->radii[1]);
}

/* Radii r0 × U(1, 3) per particle and axis, r0 chosen for about `neighbors` supports per point. */
static void cloud_random_radii(Cloud *c, double neighbors) {
  double volume = 1;
  for (int d = 0; d < c->dim; d++) volume *= fmax(c->hi[d] - c->lo[d], 1e-3);
  double r0 = 0.5 * pow(neighbors * volume / (double)c->n, 1.0 / c->dim) / 2.0;
  c->rmax = 0;
  for (int s = 0; s < 2; s++)
    for (long j = 0; j < c->n * c->dim; j++) {
      c->radii[s][j] = r0 * uniform(1.0, 3.0) * (s ? 1.5 : 1.0);
      c->rmax = fmax(c->rmax, c->radii[s][j]);
    }
}

static void cloud_bounds(Cloud *c) {
  for (int d = 0; d < c->dim; d++) c->lo[d] = INFINITY, c->hi[d] = -INFINITY;
  for (long i = 0; i < c->n; i++)
    for (int d = 0; d < c->dim; d++) {
      c->lo[d] = fmin(c->lo[d], c->x[i * c->dim + d]);
      c->hi[d] = fmax(c->hi[d], c->x[i * c->dim + d]);
    }
}

enum { CLOUD_RANDOM, CLOUD_CLUSTERED, CLOUD_PLANAR, CLOUD_COINCIDENT, CLOUD_OUTLIER, NUM_CLOUDS };

static void cloud_make(Cloud *c, int shape, int dim) {
  long n = shape == CLOUD_COINCIDENT ? 20 : dim == 1 ? 200 : 500;
  cloud_alloc(c, dim, n);
  for (long i = 0; i < n; i++)
    for (int d = 0; d < dim; d++) {
      double v = uniform(-1.0, 2.0);
      if (shape == CLOUD_CLUSTERED && i % 2) v = 0.3 + 1e-3 * uniform(0, 1); /* half in a tiny cluster */
      if (shape == CLOUD_PLANAR && dim > 1 && d == dim - 1) v = 0.5;      /* no extent along one axis */
      if (shape == CLOUD_COINCIDENT) v = 0.25;
      c->x[i * dim + d] = v;
    }
  cloud_bounds(c);
  cloud_random_radii(c, 12.0);
  if (shape == CLOUD_OUTLIER) /* one support covering most of the cloud */
    for (int d = 0; d < dim; d++) c->radii[0][7 * dim + d] = c->radii[1][7 * dim + d] = 1.2;
  if (shape == CLOUD_OUTLIER) c->rmax = 1.2;
}

/* Query points: random inside and beyond the cloud, on particles, on support boundaries, far away. */
static long make_query_points(const Cloud *c, const double *radii, double *q, long max) {
  const int dim = c->dim;
  long m = 0;
  for (; m < 300; m++)
    for (int d = 0; d < dim; d++) {
      double margin = 0.3 * (c->hi[d] - c->lo[d]) + c->rmax;
      q[m * dim + d] = uniform(c->lo[d] - margin, c->hi[d] + margin);
    }
  for (long i = 0; i < c->n && m < max; i += 5, m++) memcpy(q + m * dim, c->x + i * dim, dim * sizeof *q);
  for (long i = 1; i < c->n && m + 3 <= max; i += 9, m += 3) {
    int axis = (int)(i % dim);
    for (int k = 0; k < 3; k++) memcpy(q + (m + k) * dim, c->x + i * dim, dim * sizeof *q);
    q[m * dim + axis] += radii[i * dim + axis];       /* on a face (box) or the sphere (ball) */
    q[(m + 1) * dim + axis] -= radii[i * dim + axis];
    for (int d = 0; d < dim; d++) q[(m + 2) * dim + d] += radii[i * dim + d]; /* a box corner */
  }
  for (int d = 0; d < dim; d++) q[m * dim + d] = 1e6;
  return m + 1;
}

static void expect_same_lists(const long *want, long nwant, const long *got, long ngot, const double *p,
                              int dim) {
  int same = nwant == ngot;
  for (long j = 0; same && j < nwant; j++) same = want[j] == got[j];
  if (!same) {
    print_error("query at (%.17g, %.17g, %.17g): %ld supports expected, %ld found\n", p[0],
                dim > 1 ? p[1] : 0.0, dim > 2 ? p[2] : 0.0, nwant, ngot);
    for (long j = 0; j < nwant || j < ngot; j++)
      print_error("  %ld: expected %ld, got %ld\n", j, j < nwant ? want[j] : -1L, j < ngot ? got[j] : -1L);
    fail();
  }
}

/* ---- support queries ----------------------------------------------------------------------------- */

static void check_queries(const Cloud *c, MlsSearch *search, MlsSupportKind support, const double *radii) {
  enum { MAX_POINTS = 600 };
  double *q = malloc(MAX_POINTS * 3 * sizeof *q);
  long *want = malloc((size_t)c->n * sizeof *want), *index = NULL, count = -1, cap = 0;
  long m = make_query_points(c, radii, q, MAX_POINTS - 1);
  for (long j = 0; j < m; j++) {
    const double *p = q + j * c->dim;
    long nwant = brute_query(c->dim, c->n, c->x, support, radii, p, want);
    check_ok(mls_search_query(search, p, &index, &count, &cap));
    expect_same_lists(want, nwant, index, count, p, c->dim);
  }
  free(q);
  free(want);
  free(index);
}

static void test_query_matches_brute_force(void **state) {
  (void)state;
  rng_seed(1);
  for (int shape = 0; shape < NUM_CLOUDS; shape++)
    for (int dim = 1; dim <= 3; dim++) {
      Cloud c;
      cloud_make(&c, shape, dim);
      for (int kind = MLS_SEARCH_KDTREE; kind <= MLS_SEARCH_CELLS; kind++)
        for (int support = MLS_SUPPORT_BOX; support <= MLS_SUPPORT_BALL; support++) {
          MlsSearch *search = NULL;
          check_ok(mls_search_create(dim, c.n, c.x, (MlsSearchKind)kind, &search));
          for (int set = 0; set < 2; set++) { /* the second set refits the same structure */
            check_ok(mls_search_set_supports(search, (MlsSupportKind)support, c.radii[set]));
            check_queries(&c, search, (MlsSupportKind)support, c.radii[set]);
          }
          check_ok(mls_search_destroy(&search));
          assert_null(search);
        }
      cloud_free(&c);
    }
}

/* The caller's coordinates may change after create: the search keeps its own copy. */
static void test_query_copies_particles(void **state) {
  (void)state;
  double x[4] = {0, 0, 1, 0}, radii[4] = {0.6, 0.6, 0.6, 0.6}, p[2] = {0.1, 0};
  MlsSearch *search = NULL;
  check_ok(mls_search_create(2, 2, x, MLS_SEARCH_KDTREE, &search));
  x[0] = 5;
  check_ok(mls_search_set_supports(search, MLS_SUPPORT_BOX, radii));
  long *index = NULL, count = 0, cap = 0;
  check_ok(mls_search_query(search, p, &index, &count, &cap));
  assert_int_equal(count, 1);
  assert_int_equal(index[0], 0);
  free(index);
  mls_search_destroy(&search);
}

static void test_capacity_growth(void **state) {
  (void)state;
  rng_seed(2);
  Cloud c;
  cloud_alloc(&c, 3, 3000);
  for (long j = 0; j < c.n * 3; j++) c.x[j] = uniform(0, 1);
  for (long j = 0; j < c.n * 3; j++) c.radii[0][j] = uniform(0.15, 0.3); /* ~200 supports per point */
  long *want = malloc((size_t)c.n * sizeof *want);
  for (int kind = MLS_SEARCH_KDTREE; kind <= MLS_SEARCH_CELLS; kind++) {
    MlsSearch *search = NULL;
    check_ok(mls_search_create(3, c.n, c.x, (MlsSearchKind)kind, &search));
    check_ok(mls_search_set_supports(search, MLS_SUPPORT_BOX, c.radii[0]));
    long *index = NULL, count = 0, cap = 0;
    double center[3] = {0.5, 0.5, 0.5}, edge[3] = {0.0, 0.5, 1.0};
    check_ok(mls_search_query(search, center, &index, &count, &cap));
    assert_true(count > 64); /* grew more than once from nothing */
    assert_true(cap >= count);
    expect_same_lists(want, brute_query(3, c.n, c.x, MLS_SUPPORT_BOX, c.radii[0], center, want), index,
                      count, center, 3);
    long *before = index, cap_before = cap; /* a smaller result must reuse the array */
    check_ok(mls_search_query(search, edge, &index, &count, &cap));
    assert_ptr_equal(index, before);
    assert_int_equal(cap, cap_before);
    expect_same_lists(want, brute_query(3, c.n, c.x, MLS_SUPPORT_BOX, c.radii[0], edge, want), index,
                      count, edge, 3);
    free(index);
    index = malloc(sizeof *index), cap = 1; /* a caller's own small array grows too */
    check_ok(mls_search_query(search, center, &index, &count, &cap));
    expect_same_lists(want, brute_query(3, c.n, c.x, MLS_SUPPORT_BOX, c.radii[0], center, want), index,
                      count, center, 3);
    /* supports spanning the cloud: more results than the radix sort's stack scratch holds */
    for (long j = 0; j < c.n * 3; j++) c.radii[1][j] = uniform(0.6, 1.2);
    check_ok(mls_search_set_supports(search, MLS_SUPPORT_BOX, c.radii[1]));
    check_ok(mls_search_query(search, center, &index, &count, &cap));
    assert_true(count > 2000);
    expect_same_lists(want, brute_query(3, c.n, c.x, MLS_SUPPORT_BOX, c.radii[1], center, want), index,
                      count, center, 3);
    free(index);
    mls_search_destroy(&search);
  }
  free(want);
  cloud_free(&c);
}

/* ---- k nearest neighbors ------------------------------------------------------------------------- */

static int compare_doubles(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static void check_knn(const Cloud *c, const MlsSearch *search, long i, int k) {
  const int dim = c->dim;
  double *all = malloc((size_t)c->n * sizeof *all), *d2 = malloc((size_t)(k + 1) * sizeof *d2);
  long *index = malloc((size_t)(k + 1) * sizeof *index), m = 0;
  for (long j = 0; j < c->n; j++)
    if (j != i) all[m++] = sq_dist(dim, c->x + i * dim, c->x + j * dim);
  qsort(all, (size_t)m, sizeof *all, compare_doubles);
  for (int with_dist = 0; with_dist < 2; with_dist++) {
    check_ok(mls_search_knn(search, i, k, index, with_dist ? d2 : NULL));
    for (int j = 0; j < k; j++) {
      assert_true(index[j] >= 0 && index[j] < c->n && index[j] != i);
      for (int l = 0; l < j; l++) assert_true(index[l] != index[j]);
      double true_d2 = sq_dist(dim, c->x + i * dim, c->x + index[j] * dim);
      if (true_d2 != all[j]) {
        print_error("particle %ld, k = %d: neighbor %d at d2 = %.17g, expected %.17g\n", i, k, j, true_d2,
                    all[j]);
        fail();
      }
      if (with_dist) assert_true(d2[j] == true_d2);
    }
  }
  free(all);
  free(d2);
  free(index);
}

static void test_knn_matches_brute_force(void **state) {
  (void)state;
  rng_seed(3);
  for (int shape = 0; shape < NUM_CLOUDS; shape++)
    for (int dim = 1; dim <= 3; dim++) {
      Cloud c;
      cloud_make(&c, shape, dim);
      MlsSearch *search = NULL;
      check_ok(mls_search_create(dim, c.n, c.x, MLS_SEARCH_CELLS, &search));
      const int ks[] = {0, 1, 2, 7, 33, (int)c.n - 1};
      for (long i = 0; i < c.n; i += 13)
        for (size_t j = 0; j < sizeof ks / sizeof ks[0]; j++)
          if (ks[j] <= c.n - 1) check_knn(&c, search, i, ks[j]);
      mls_search_destroy(&search);
      cloud_free(&c);
    }
}

/* ---- local spacing ------------------------------------------------------------------------------- */

/* The definition, particle by particle (mica/mls.h, docs/theory.md §supports): per axis and side the nearest
 * particle pointing mainly along the axis, ties to the smallest |Δx_d|; near: the nearer side's, ties to the
 * smaller |Δx_d|; far: the larger side's if at most twice the smaller, else the smaller; an axis without any:
 * the largest other h. */
static void brute_spacing_rule(int dim, long n, const double *x, MlsSpacingRule rule, double *h) {
  for (long i = 0; i < n; i++) {
    double best[6], side_h[6], *hi = h + i * dim, largest = 0;
    for (int e = 0; e < 6; e++) best[e] = INFINITY, side_h[e] = INFINITY;
    for (long j = 0; j < n; j++) {
      double delta[3], m = 0, d2 = sq_dist(dim, x + i * dim, x + j * dim);
      for (int d = 0; d < dim; d++) m = fmax(m, delta[d] = fabs(x[j * dim + d] - x[i * dim + d]));
      for (int d = 0; d < dim && m > 0; d++) {
        const int e = 2 * d + (x[j * dim + d] > x[i * dim + d]);
        if (delta[d] == m && (d2 < best[e] || (d2 == best[e] && delta[d] < side_h[e]))) best[e] = d2, side_h[e] = delta[d];
      }
    }
    for (int d = 0; d < dim; d++) {
      const double *b = best + 2 * d, *sh = side_h + 2 * d;
      const double lo = fmin(sh[0], sh[1]), high = fmax(sh[0], sh[1]);
      if (rule == MLS_SPACING_FAR) hi[d] = high <= 2.0 * lo ? high : lo;
      else hi[d] = b[0] < b[1] || (b[0] == b[1] && sh[0] <= sh[1]) ? sh[0] : sh[1];
      if (hi[d] < INFINITY) largest = fmax(largest, hi[d]);
    }
    for (int d = 0; d < dim; d++)
      if (hi[d] == INFINITY) hi[d] = largest;
  }
}

static void brute_spacing(int dim, long n, const double *x, double *h) {
  brute_spacing_rule(dim, n, x, MLS_SPACING_NEAR, h);
}

/* A regular grid of count[d] particles spaced step[d] apart, from origin. */
static double *make_grid(int dim, const int *count, const double *step, const double *origin, long *n) {
  long total = 1;
  for (int d = 0; d < dim; d++) total *= count[d];
  double *x = malloc((size_t)(total * dim) * sizeof *x);
  for (long i = 0; i < total; i++) {
    long rest = i;
    for (int d = 0; d < dim; d++) {
      x[i * dim + d] = origin[d] + step[d] * (double)(rest % count[d]);
      rest /= count[d];
    }
  }
  *n = total;
  return x;
}

static double *spacing_with(int dim, long n, const double *x, MlsSearchKind kind, MlsSpacingRule rule) {
  MlsSearch *search = NULL;
  double *h = malloc((size_t)(n * dim) * sizeof *h);
  check_ok(mls_search_create(dim, n, x, kind, &search));
  if (rule == MLS_SPACING_NEAR) check_ok(mls_search_local_spacing(search, h)); /* the near rule's own entry */
  else check_ok(mls_search_local_spacing_rule(search, rule, h));
  mls_search_destroy(&search);
  return h;
}

static double *spacing_of(int dim, long n, const double *x, MlsSearchKind kind) {
  return spacing_with(dim, n, x, kind, MLS_SPACING_NEAR);
}

static double *spacing_rule_of(int dim, long n, const double *x, MlsSpacingRule rule) {
  return spacing_with(dim, n, x, MLS_SEARCH_KDTREE, rule);
}

static void expect_grid_spacing(int dim, const int *count, const double *step, const double *expected) {
  const double origin[3] = {-3.0, 2.0, 0.5};
  long n;
  double *x = make_grid(dim, count, step, origin, &n);
  double *h = spacing_of(dim, n, x, MLS_SEARCH_KDTREE), *hf = spacing_rule_of(dim, n, x, MLS_SPACING_FAR);
  for (long i = 0; i < n; i++)
    for (int d = 0; d < dim; d++)
      if (!(fabs(h[i * dim + d] - expected[d]) <= 1e-12) || !(fabs(hf[i * dim + d] - expected[d]) <= 1e-12)) {
        print_error("particle %ld axis %d: h = %.17g (far rule %.17g), expected %.17g\n", i, d, h[i * dim + d],
                    hf[i * dim + d], expected[d]);
        fail();
      }
  free(x);
  free(h);
  free(hf);
}

static void test_spacing_regular_grids(void **state) {
  (void)state;
  expect_grid_spacing(3, (const int[]){11, 11, 11}, (const double[]){1, 1, 1}, (const double[]){1, 1, 1});
  expect_grid_spacing(2, (const int[]){9, 33}, (const double[]){1, 0.25}, (const double[]){1, 0.25});
  expect_grid_spacing(2, (const int[]){33, 9}, (const double[]){0.25, 1}, (const double[]){0.25, 1});
  expect_grid_spacing(3, (const int[]){4, 9, 3}, (const double[]){0.5, 0.125, 2},
                      (const double[]){0.5, 0.125, 2});
  expect_grid_spacing(1, (const int[]){17}, (const double[]){0.5}, (const double[]){0.5});
  expect_grid_spacing(1, (const int[]){2}, (const double[]){3}, (const double[]){3});
  /* layers one particle thick: the missing axis takes the largest other spacing */
  expect_grid_spacing(3, (const int[]){7, 5, 1}, (const double[]){1, 0.5, 1}, (const double[]){1, 0.5, 1});
  expect_grid_spacing(3, (const int[]){1, 6, 1}, (const double[]){1, 0.75, 1},
                      (const double[]){0.75, 0.75, 0.75});
  expect_grid_spacing(2, (const int[]){6, 1}, (const double[]){2, 1}, (const double[]){2, 2});
}

static void test_spacing_nonuniform_1d(void **state) {
  (void)state;
  /* sorted 0, 1, 3, 6: near takes the nearer side, far the farther (at 3: 2 to the left, 3 to the right) */
  const double x[] = {6, 0, 3, 1}, near[] = {3, 1, 2, 1}, far[] = {3, 1, 3, 2};
  double *h = spacing_of(1, 4, x, MLS_SEARCH_KDTREE), *hf = spacing_rule_of(1, 4, x, MLS_SPACING_FAR);
  for (int i = 0; i < 4; i++) assert_true(h[i] == near[i] && hf[i] == far[i]);
  free(h);
  free(hf);
}

/* A 2-D grid graded along x (spacings 1, 1.3, 1.3², ...) and uniform (0.5) along y: under the far rule h_x is
 * the spacing on the coarse side, the right one, of every particle but the last, which has only its left one;
 * under the near rule the fine side, the left one, but for the first. h_y is 0.5 under both. */
static void test_spacing_graded_grid(void **state) {
  (void)state;
  enum { NX = 9, NY = 4 };
  double xs[NX], x[NX * NY * 2];
  xs[0] = 0;
  for (int i = 1; i < NX; i++) xs[i] = xs[i - 1] + pow(1.3, i - 1);
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++) x[2 * (j * NX + i)] = xs[i], x[2 * (j * NX + i) + 1] = 0.5 * j;
  double *far = spacing_rule_of(2, NX * NY, x, MLS_SPACING_FAR), *near = spacing_rule_of(2, NX * NY, x, MLS_SPACING_NEAR);
  for (int j = 0; j < NY; j++)
    for (int i = 0; i < NX; i++) {
      const long p = j * NX + i;
      const double coarse = i + 1 < NX ? xs[i + 1] - xs[i] : xs[i] - xs[i - 1];
      const double fine = i > 0 ? xs[i] - xs[i - 1] : xs[1] - xs[0];
      assert_true(fabs(far[2 * p] - coarse) <= 1e-14 * coarse);
      assert_true(fabs(near[2 * p] - fine) <= 1e-14 * fine);
      assert_true(far[2 * p + 1] == 0.5 && near[2 * p + 1] == 0.5);
    }
  free(far);
  free(near);
}

/* A particle across a gap is no graded neighbor: on a row 0, 1, 2, 5 (a gap of 3 after a spacing of 1) the far
 * rule keeps 1 at x = 2, whose right side is three times its left. */
static void test_spacing_far_gap(void **state) {
  (void)state;
  const double x[] = {0, 1, 2, 5}, expected[] = {1, 1, 1, 3};
  double *h = spacing_rule_of(1, 4, x, MLS_SPACING_FAR);
  for (int i = 0; i < 4; i++) assert_true(h[i] == expected[i]);
  free(h);
}

static void test_spacing_jittered_grid(void **state) {
  (void)state;
  rng_seed(4);
  long n;
  double *x = make_grid(3, (const int[]){10, 10, 10}, (const double[]){1, 1, 1}, (const double[]){0, 0, 0}, &n);
  for (long j = 0; j < n * 3; j++) x[j] += uniform(-0.1, 0.1);
  double *h = spacing_of(3, n, x, MLS_SEARCH_KDTREE), *want = malloc((size_t)(n * 3) * sizeof *want);
  brute_spacing(3, n, x, want);
  for (long j = 0; j < n * 3; j++) {
    assert_true(h[j] >= 0.8 && h[j] <= 1.2); /* a unit step ± two jitters */
    assert_true(h[j] == want[j]);
  }
  free(x);
  free(h);
  free(want);
}

static void test_spacing_matches_brute_force(void **state) {
  (void)state;
  rng_seed(5);
  for (int shape = 0; shape < NUM_CLOUDS; shape++) {
    if (shape == CLOUD_COINCIDENT) continue; /* no spacing at all: tested as an error */
    for (int dim = 1; dim <= 3; dim++) {
      Cloud c;
      cloud_make(&c, shape, dim);
      for (int rule = MLS_SPACING_NEAR; rule <= MLS_SPACING_FAR; rule++) {
        double *h = rule == MLS_SPACING_NEAR ? spacing_of(dim, c.n, c.x, MLS_SEARCH_CELLS)
                                             : spacing_rule_of(dim, c.n, c.x, MLS_SPACING_FAR);
        double *want = malloc((size_t)(c.n * dim) * sizeof *want);
        brute_spacing_rule(dim, c.n, c.x, (MlsSpacingRule)rule, want);
        for (long j = 0; j < c.n * dim; j++)
          if (h[j] != want[j]) {
            print_error("rule %d, cloud %d, dim %d, particle %ld axis %ld: h = %.17g, expected %.17g\n", rule,
                        shape, dim, j / dim, j % dim, h[j], want[j]);
            fail();
          }
        free(h);
        free(want);
      }
      cloud_free(&c);
    }
  }
}

/* A particle duplicated on a grid: the duplicate has no direction and is ignored. */
static void test_spacing_duplicates(void **state) {
  (void)state;
  long n;
  double *x = make_grid(2, (const int[]){5, 5}, (const double[]){1, 1}, (const double[]){0, 0}, &n);
  x = realloc(x, (size_t)((n + 1) * 2) * sizeof *x);
  x[2 * n] = x[2 * 12], x[2 * n + 1] = x[2 * 12 + 1];
  double *h = spacing_of(2, n + 1, x, MLS_SEARCH_KDTREE);
  for (long j = 0; j < (n + 1) * 2; j++) assert_true(h[j] == 1.0);
  free(x);
  free(h);
}

/* Equally near candidates along x, (4, 3) and (5, 0): the smaller |Δx| wins, whatever their order. */
static void test_spacing_ties(void **state) {
  (void)state;
  const double orders[2][8] = {{0, 0, 4, 3, 5, 0, 0, 10}, {0, 0, 5, 0, 4, 3, 0, 10}};
  for (int o = 0; o < 2; o++) {
    double *h = spacing_of(2, 4, orders[o], MLS_SEARCH_KDTREE);
    assert_true(h[0] == 4.0);
    assert_true(h[1] == 10.0);
    free(h);
  }
}

/* A row along x with one particle off it at (3, 3): from the origin, the 6 nearest are all on the row
 * (up to 3.5 away), yet (3, 3), 4.24 away, points mainly along y (|Δy| = |Δx|). The search must look past
 * the first neighbors: the cloud reaches 3 along y, and 3 ≥ 3.5 / sqrt(2). */
static void test_spacing_far_diagonal(void **state) {
  (void)state;
  const double row[] = {0, 1, -1, 2, -2, 3.5, -3.5, 5, -5, 6.5, -6.5};
  const int nrow = (int)(sizeof row / sizeof row[0]);
  double x[2 * 12], want[2 * 12];
  for (int i = 0; i < nrow; i++) x[2 * i] = row[i], x[2 * i + 1] = 0;
  x[2 * nrow] = 3, x[2 * nrow + 1] = 3;
  brute_spacing(2, nrow + 1, x, want);
  assert_true(want[1] == 3.0); /* the origin's spacing along y */
  double *h = spacing_of(2, nrow + 1, x, MLS_SEARCH_KDTREE);
  for (int j = 0; j < 2 * (nrow + 1); j++) assert_true(h[j] == want[j]);
  free(h);
}

/* ---- errors -------------------------------------------------------------------------------------- */

static void test_argument_errors(void **state) {
  (void)state;
  double x[6] = {0, 0, 1, 0, 0, 1}, radii[6] = {1, 1, 1, 1, 1, 1}, h[6], d2[3];
  long index[3], *hits = NULL, count = 0, cap = 0;
  MlsSearch *search = NULL;
  check_error(mls_search_create(0, 3, x, MLS_SEARCH_KDTREE, &search), MICA_ERR_ARGUMENT);
  check_error(mls_search_create(4, 1, x, MLS_SEARCH_KDTREE, &search), MICA_ERR_ARGUMENT);
  check_error(mls_search_create(2, 0, x, MLS_SEARCH_KDTREE, &search), MICA_ERR_ARGUMENT);
  check_error(mls_search_create(2, 3, NULL, MLS_SEARCH_KDTREE, &search), MICA_ERR_ARGUMENT);
  check_error(mls_search_create(2, 3, x, (MlsSearchKind)7, &search), MICA_ERR_ARGUMENT);
  x[3] = NAN;
  check_error(mls_search_create(2, 3, x, MLS_SEARCH_KDTREE, &search), MICA_ERR_ARGUMENT);
  x[3] = 0;
  assert_null(search);

  check_ok(mls_search_create(2, 3, x, MLS_SEARCH_KDTREE, &search));
  check_error(mls_search_query(search, x, &hits, &count, &cap), MICA_ERR_ARGUMENT); /* no supports yet */
  check_error(mls_search_knn(search, 0, 3, index, d2), MICA_ERR_ARGUMENT);         /* k > n − 1 */
  check_error(mls_search_knn(search, 0, -1, index, d2), MICA_ERR_ARGUMENT);
  check_error(mls_search_knn(search, 3, 1, index, d2), MICA_ERR_ARGUMENT);
  check_error(mls_search_knn(search, -1, 1, index, d2), MICA_ERR_ARGUMENT);
  check_ok(mls_search_knn(search, 0, 2, index, d2));
  radii[3] = 0;
  check_error(mls_search_set_supports(search, MLS_SUPPORT_BOX, radii), MICA_ERR_ARGUMENT);
  radii[3] = -1;
  check_error(mls_search_set_supports(search, MLS_SUPPORT_BOX, radii), MICA_ERR_ARGUMENT);
  radii[3] = NAN;
  check_error(mls_search_set_supports(search, MLS_SUPPORT_BOX, radii), MICA_ERR_ARGUMENT);
  check_error(mls_search_query(search, x, &hits, &count, &cap), MICA_ERR_ARGUMENT); /* still none */
  check_ok(mls_search_set_supports(search, MLS_SUPPORT_BALL, radii)); /* a ball uses radius 0 only */
  check_error(mls_search_set_supports(search, (MlsSupportKind)5, radii), MICA_ERR_ARGUMENT);
  check_error(mls_search_set_supports(search, MLS_SUPPORT_BOX, NULL), MICA_ERR_ARGUMENT);
  check_ok(mls_search_query(search, x, &hits, &count, &cap));
  cap = 4; /* a capacity without an array */
  long *none = NULL;
  check_error(mls_search_query(search, x, &none, &count, &cap), MICA_ERR_ARGUMENT);
  check_error(mls_search_local_spacing(search, NULL), MICA_ERR_ARGUMENT);
  check_ok(mls_search_local_spacing(search, h));
  mls_search_destroy(&search);
  check_ok(mls_search_destroy(&search)); /* twice is harmless */
  free(hits);

  /* no spacing can be measured: one particle, or particles that all coincide */
  check_ok(mls_search_create(2, 1, x, MLS_SEARCH_KDTREE, &search));
  check_error(mls_search_local_spacing(search, h), MICA_ERR_INPUT);
  check_error(mls_search_knn(search, 0, 1, index, d2), MICA_ERR_ARGUMENT);
  mls_search_destroy(&search);
  double same[6] = {1, 2, 1, 2, 1, 2};
  check_ok(mls_search_create(2, 3, same, MLS_SEARCH_CELLS, &search));
  check_error(mls_search_local_spacing(search, h), MICA_ERR_INPUT);
  mls_search_destroy(&search);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_query_matches_brute_force),
      cmocka_unit_test(test_query_copies_particles),
      cmocka_unit_test(test_capacity_growth),
      cmocka_unit_test(test_knn_matches_brute_force),
      cmocka_unit_test(test_spacing_regular_grids),
      cmocka_unit_test(test_spacing_nonuniform_1d),
      cmocka_unit_test(test_spacing_graded_grid),
      cmocka_unit_test(test_spacing_far_gap),
      cmocka_unit_test(test_spacing_jittered_grid),
      cmocka_unit_test(test_spacing_matches_brute_force),
      cmocka_unit_test(test_spacing_duplicates),
      cmocka_unit_test(test_spacing_ties),
      cmocka_unit_test(test_spacing_far_diagonal),
      cmocka_unit_test(test_argument_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
