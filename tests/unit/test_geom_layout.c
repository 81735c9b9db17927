/* Unit tests of the particle layouts (src/geom/layout.c) and of cells that follow them (src/geom/cells.c).
 *
 *   - regular: counts, particles inside every shape, the expected number on each boundary (hole, circle,
 *     box faces), the polygon's corners;
 *   - graded: spacing ratio last/first = grading per axis (1e-12), constant ratio between neighbors, cells
 *     between the graded particle lines (volume still exact);
 *   - jittered: same numbering as regular; boundary particles stay on their boundary (exactly); every
 *     coordinate moves by at most jitter × the local spacing, and some move visibly; the plate's corner
 *     particle stays put; same seed → the same particles, another seed → different ones;
 *   - irregular: the boundary particles of the regular layout, interior particles strictly inside and at
 *     least 0.8 regular spacings from every other particle (2-D and 3-D, anisotropic counts); the interior
 *     count is within 0.5 % of the regular one; deterministic per seed; the regular grid of the same counts
 *     (x_grid, ngrid points) and each particle's nearest grid point (grid_index: within half a spacing per
 *     axis, a boundary particle's own point), on which the supports are sized; a box of it (corner, middle, strip;
 *     2-D and 3-D) drawn from its tiles alone holds the whole layout's particles there, bit for bit, same keys;
 *   - errors: jitter outside [0, 0.5), grading ≤ 0.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/geom.h"

#define PI 3.14159265358979323846

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static MicaDiscretization *create(const MicaShapeSpec *shape, const MicaLayoutSpec *layout) {
  const MicaCellSpec cells = {.order = 2};
  MicaDiscretization *disc = NULL;
  check_ok(mica_discretization_create(shape, layout, &cells, &disc));
  return disc;
}

static MicaLayoutSpec layout_of(MicaLayoutKind kind, long n0, long n1, long n2) {
  return (MicaLayoutSpec){
      .kind = kind, .count = {n0, n1, n2}, .grading = {1, 1, 1}, .jitter = 0.3, .seed = 11};
}

static const MicaShapeSpec unit_square = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {0, 0}, .upper = {1, 1}};

/* Number of particles with |f(x)| < tol. */
typedef double (*Distance)(const double *x, const void *ctx);

static long count_on(const MicaDiscretization *disc, Distance f, const void *ctx, double tol) {
  long n = 0;
  for (long p = 0; p < disc->nparticles; p++) n += fabs(f(&disc->x[p * disc->dim], ctx)) < tol;
  return n;
}

static double radius_minus(const double *x, const void *r) { return hypot(x[0], x[1]) - *(const double *)r; }
static double x_minus(const double *x, const void *v) { return x[0] - *(const double *)v; }
static double y_minus(const double *x, const void *v) { return x[1] - *(const double *)v; }

static double min_distance(const MicaDiscretization *disc) {
  double best = INFINITY;
  const int dim = disc->dim;
  for (long i = 0; i < disc->nparticles; i++)
    for (long j = i + 1; j < disc->nparticles; j++) {
      double s = 0.0;
      for (int d = 0; d < dim; d++) s += pow(disc->x[i * dim + d] - disc->x[j * dim + d], 2);
      best = fmin(best, sqrt(s));
    }
  return best;
}

/* ---- regular ---- */

static void test_regular_inside(void **state) {
  (void)state;
  const double tol = 1e-12;
  {
    const MicaShapeSpec s = {.kind = MICA_SHAPE_PLATE_HOLE, .hole_radius = 1, .plate_size = {5, 4}};
    const MicaLayoutSpec l = layout_of(MICA_LAYOUT_REGULAR, 9, 6, 0);
    MicaDiscretization *disc = create(&s, &l);
    assert_int_equal(disc->nparticles, 54);
    for (long p = 0; p < disc->nparticles; p++) {
      const double *x = &disc->x[2 * p];
      assert_true(hypot(x[0], x[1]) >= 1 - tol && x[0] >= -tol && x[1] >= -tol && x[0] <= 5 + tol &&
                  x[1] <= 4 + tol);
    }
    const double a = 1, bx = 5, by = 4, zero = 0;
    assert_int_equal(count_on(disc, radius_minus, &a, tol), 9);
    assert_int_equal(count_on(disc, x_minus, &bx, tol), 5); /* right side, corner included */
    assert_int_equal(count_on(disc, y_minus, &by, tol), 5); /* top side, corner included */
    assert_int_equal(count_on(disc, x_minus, &zero, tol), 6);
    assert_int_equal(count_on(disc, y_minus, &zero, tol), 6);
    mica_discretization_destroy(&disc);
  }
  {
    const MicaShapeSpec s = {
        .kind = MICA_SHAPE_ANNULUS, .r_inner = 1, .r_outer = 2, .theta0 = -0.5, .theta1 = 1.0};
    const MicaLayoutSpec l = layout_of(MICA_LAYOUT_REGULAR, 4, 5, 0);
    MicaDiscretization *disc = create(&s, &l);
    for (long p = 0; p < disc->nparticles; p++) {
      const double *x = &disc->x[2 * p], r = hypot(x[0], x[1]), t = atan2(x[1], x[0]);
      assert_true(r >= 1 - tol && r <= 2 + tol && t >= -0.5 - tol && t <= 1.0 + tol);
    }
    const double ri = 1, ro = 2;
    assert_int_equal(count_on(disc, radius_minus, &ri, tol), 5);
    assert_int_equal(count_on(disc, radius_minus, &ro, tol), 5);
    mica_discretization_destroy(&disc);
  }
  {
    const MicaShapeSpec s = {.kind = MICA_SHAPE_CYLINDER, .radius = 2, .height = 3};
    const MicaLayoutSpec l = layout_of(MICA_LAYOUT_REGULAR, 5, 5, 4);
    MicaDiscretization *disc = create(&s, &l);
    assert_int_equal(disc->nparticles, 100);
    for (long p = 0; p < disc->nparticles; p++) {
      const double *x = &disc->x[3 * p];
      assert_true(hypot(x[0], x[1]) <= 2 + tol && x[2] >= -tol && x[2] <= 3 + tol);
    }
    const double R = 2;
    assert_int_equal(count_on(disc, radius_minus, &R, tol), 16 * 4); /* the square's perimeter × levels */
    mica_discretization_destroy(&disc);
  }
  {
    const MicaShapeSpec s = {.kind = MICA_SHAPE_POLYGON, .vertices = {{0, 0}, {48, 44}, {48, 60}, {0, 44}}};
    const MicaLayoutSpec l = layout_of(MICA_LAYOUT_REGULAR, 3, 4, 0);
    MicaDiscretization *disc = create(&s, &l);
    const double want[4][2] = {{0, 0}, {48, 44}, {0, 44}, {48, 60}};
    const long index[4] = {0, 2, 9, 11};
    for (int k = 0; k < 4; k++) {
      assert_true(fabs(disc->x[2 * index[k]] - want[k][0]) < 1e-13);
      assert_true(fabs(disc->x[2 * index[k] + 1] - want[k][1]) < 1e-13);
    }
    mica_discretization_destroy(&disc);
  }
}

/* ---- graded ---- */

static void test_graded(void **state) {
  (void)state;
  const MicaShapeSpec s = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {0, 0}, .upper = {1, 2}};
  MicaLayoutSpec l = layout_of(MICA_LAYOUT_GRADED, 6, 5, 0);
  l.grading[0] = 4.0, l.grading[1] = 0.5;
  MicaDiscretization *disc = create(&s, &l);
  double hx[5], hy[4];
  for (int i = 0; i < 5; i++) hx[i] = disc->x[2 * (i + 1)] - disc->x[2 * i];
  for (int j = 0; j < 4; j++) hy[j] = disc->x[2 * 6 * (j + 1) + 1] - disc->x[2 * 6 * j + 1];
  assert_true(fabs(hx[4] / hx[0] - 4.0) < 1e-12);
  assert_true(fabs(hy[3] / hy[0] - 0.5) < 1e-12);
  for (int i = 1; i < 4; i++) assert_true(fabs(hx[i + 1] / hx[i] - hx[1] / hx[0]) < 1e-12);
  for (int j = 1; j < 3; j++) assert_true(fabs(hy[j + 1] / hy[j] - hy[1] / hy[0]) < 1e-12);
  assert_true(fabs(disc->x[2 * 5] - 1.0) == 0.0); /* the last particle sits exactly on the boundary */
  /* default cells lie between the graded particle lines */
  assert_int_equal(disc->ncells, 5 * 4);
  assert_true(fabs(disc->volume - 2.0) < 1e-14);
  const MicaBoundarySet *bottom = &disc->sets[mica_discretization_find_set(disc, "bottom")];
  for (long v = 0; v < bottom->nvertices; v++) {
    int on_particle = 0;
    for (int i = 0; i < 6; i++) on_particle |= bottom->vertex_x[2 * v] == disc->x[2 * i];
    assert_true(on_particle);
  }
  mica_discretization_destroy(&disc);
}

/* ---- jittered ---- */

static void test_jittered_box(void **state) {
  (void)state;
  const MicaLayoutSpec reg = layout_of(MICA_LAYOUT_REGULAR, 9, 7, 0);
  MicaLayoutSpec jit = layout_of(MICA_LAYOUT_JITTERED, 9, 7, 0);
  MicaDiscretization *r = create(&unit_square, &reg), *j = create(&unit_square, &jit);
  assert_int_equal(j->nparticles, r->nparticles);
  const double h[2] = {1.0 / 8, 1.0 / 6};
  double moved = 0.0;
  for (long p = 0; p < r->nparticles; p++) {
    const long idx[2] = {p % 9, p / 9}, n[2] = {9, 7};
    for (int d = 0; d < 2; d++) {
      const double delta = fabs(j->x[2 * p + d] - r->x[2 * p + d]);
      if (idx[d] == 0 || idx[d] == n[d] - 1) assert_true(delta == 0.0); /* stays on its face */
      assert_true(delta <= 0.3 * h[d] * (1 + 1e-12));
      moved = fmax(moved, delta / h[d]);
    }
  }
  assert_true(moved > 0.2);
  const double zero = 0, one = 1;
  assert_int_equal(count_on(j, x_minus, &zero, 0.0 + 1e-300), 7);
  assert_int_equal(count_on(j, y_minus, &one, 1e-300), 9);
  /* the same seed gives the same particles; another seed other ones */
  MicaDiscretization *again = create(&unit_square, &jit);
  assert_memory_equal(again->x, j->x, sizeof(double) * 2 * j->nparticles);
  jit.seed = 12;
  MicaDiscretization *other = create(&unit_square, &jit);
  assert_memory_not_equal(other->x, j->x, sizeof(double) * 2 * j->nparticles);
  mica_discretization_destroy(&r);
  mica_discretization_destroy(&j);
  mica_discretization_destroy(&again);
  mica_discretization_destroy(&other);
}

static void test_jittered_curved(void **state) {
  (void)state;
  const double tol = 1e-12;
  {
    const MicaShapeSpec s = {.kind = MICA_SHAPE_PLATE_HOLE, .hole_radius = 1, .plate_size = {5, 5}};
    MicaLayoutSpec l = layout_of(MICA_LAYOUT_JITTERED, 9, 5, 0);
    l.jitter = 0.45;
    MicaDiscretization *disc = create(&s, &l);
    const double a = 1, b = 5, zero = 0;
    assert_int_equal(count_on(disc, radius_minus, &a, tol), 9);
    assert_int_equal(count_on(disc, x_minus, &b, tol), 5);
    assert_int_equal(count_on(disc, y_minus, &b, tol), 5);
    assert_int_equal(count_on(disc, x_minus, &zero, tol), 5);
    assert_int_equal(count_on(disc, y_minus, &zero, tol), 5);
    int corner = 0;
    for (long p = 0; p < disc->nparticles; p++) corner += disc->x[2 * p] == 5.0 && disc->x[2 * p + 1] == 5.0;
    assert_int_equal(corner, 1);
    for (long p = 0; p < disc->nparticles; p++) {
      const double *x = &disc->x[2 * p];
      assert_true(hypot(x[0], x[1]) >= 1 - tol && x[0] >= 0 && x[1] >= 0 && x[0] <= 5 && x[1] <= 5);
    }
    mica_discretization_destroy(&disc);
  }
  {
    const MicaShapeSpec s = {.kind = MICA_SHAPE_CYLINDER, .radius = 1, .height = 1};
    const MicaLayoutSpec l = layout_of(MICA_LAYOUT_JITTERED, 6, 6, 3);
    MicaDiscretization *disc = create(&s, &l);
    const double R = 1;
    assert_int_equal(count_on(disc, radius_minus, &R, tol), 20 * 3);
    for (long p = 0; p < disc->nparticles; p++)
      assert_true(hypot(disc->x[3 * p], disc->x[3 * p + 1]) <= 1 + tol);
    mica_discretization_destroy(&disc);
  }
}

/* ---- irregular ---- */

static void irregular_box(const MicaShapeSpec *s, long n0, long n1, long n2, double h, long seed) {
  MicaLayoutSpec l = layout_of(MICA_LAYOUT_IRREGULAR, n0, n1, n2);
  l.seed = seed;
  MicaDiscretization *disc = create(s, &l);
  const int dim = s->dim;
  const long regular = n0 * n1 * (dim == 3 ? n2 : 1);
  /* a tile that jams below its quota leaves the layout short (docs/theory.md: 0–0.3 % measured in 2-D, none in 3-D) */
  assert_true(disc->nparticles <= regular && disc->nparticles >= 0.995 * (double)regular);
  assert_true(min_distance(disc) >= 0.8 * h * (1 - 1e-12));
  /* boundary particles: the regular ones, on the box's faces; interior ones strictly inside */
  long on_boundary = 0;
  for (long p = 0; p < disc->nparticles; p++) {
    int face = 0;
    for (int d = 0; d < dim; d++) {
      const double x = disc->x[p * dim + d];
      assert_true(x >= s->lower[d] && x <= s->upper[d]);
      face |= x == s->lower[d] || x == s->upper[d];
    }
    if (face) {
      on_boundary++;
      for (int d = 0; d < dim; d++) {
        const double steps = (disc->x[p * dim + d] - s->lower[d]) / h;
        assert_true(fabs(steps - round(steps)) < 1e-9);
      }
    }
  }
  long interior = (n0 - 2) * (n1 - 2) * (dim == 3 ? n2 - 2 : 1);
  assert_int_equal(on_boundary, regular - interior);
  assert_int_equal(disc->ngrid, regular);
  assert_non_null(disc->x_grid);
  assert_non_null(disc->grid_index);
  for (long p = 0; p < disc->nparticles; p++) {
    const long k = disc->grid_index[p];
    assert_true(k >= 0 && k < regular);
    for (int d = 0; d < dim; d++) {
      const double g = disc->x_grid[k * dim + d], x = disc->x[p * dim + d];
      const double steps = (g - s->lower[d]) / h;
      assert_true(fabs(steps - round(steps)) < 1e-9); /* a grid point */
      assert_true(fabs(x - g) <= 0.5 * h * (1 + 1e-12)); /* the nearest one */
      if (x == s->lower[d] || x == s->upper[d]) assert_true(x == g);
    }
  }
  MicaDiscretization *again = create(s, &l);
  assert_memory_equal(again->x, disc->x, sizeof(double) * dim * disc->nparticles);
  mica_discretization_destroy(&again);
  l.seed = seed + 1;
  again = create(s, &l);
  assert_memory_not_equal(again->x, disc->x,
                          sizeof(double) * dim *
                              (again->nparticles < disc->nparticles ? again->nparticles : disc->nparticles));
  mica_discretization_destroy(&again);
  mica_discretization_destroy(&disc);
}

static void test_irregular(void **state) {
  (void)state;
  irregular_box(&unit_square, 11, 11, 0, 0.1, 1);
  const MicaShapeSpec oblong = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, 0}, .upper = {1, 1}};
  irregular_box(&oblong, 21, 11, 0, 0.1, 2);
  const MicaShapeSpec cube = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {1, 1, 1}};
  irregular_box(&cube, 7, 7, 7, 1.0 / 6, 3);
}

static void test_irregular_plate(void **state) {
  (void)state;
  const MicaShapeSpec s = {.kind = MICA_SHAPE_PLATE_HOLE, .hole_radius = 1, .plate_size = {4, 4}};
  const MicaLayoutSpec l = layout_of(MICA_LAYOUT_IRREGULAR, 13, 7, 0);
  MicaDiscretization *disc = create(&s, &l);
  const double a = 1;
  assert_int_equal(count_on(disc, radius_minus, &a, 1e-12), 13);
  for (long p = 0; p < disc->nparticles; p++) {
    const double *x = &disc->x[2 * p];
    assert_true(hypot(x[0], x[1]) >= 1 - 1e-12 && x[0] >= 0 && x[1] >= 0 && x[0] <= 4 && x[1] <= 4);
  }
  mica_discretization_destroy(&disc);
}

/* A box of the irregular layout (drawn from the tiles around it alone, as a rank of a distributed run draws it) holds
 * exactly the whole layout's particles whose nearest grid point lies in the box, in the same order, with the same
 * keys (ascending), bit for bit; the whole layout by box is mica_discretization_create's. */
static void irregular_parts(const MicaShapeSpec *s, const MicaLayoutSpec *l, const long boxes[][6], int nboxes) {
  const int dim = s->dim;
  const long lo0[3] = {0, 0, 0}, hi0[3] = {l->count[0], l->count[1], dim == 3 ? l->count[2] : 1};
  long n = 0, *grid = NULL, *key = NULL;
  double *x = NULL;
  check_ok(mica_layout_irregular_box(s, l, lo0, hi0, &n, &x, &grid, &key));
  MicaDiscretization *disc = create(s, l);
  assert_int_equal(n, disc->nparticles);
  assert_memory_equal(x, disc->x, sizeof(double) * (size_t)(n * dim));
  for (long i = 1; i < n; i++) assert_true(key[i] > key[i - 1]);
  for (int b = 0; b < nboxes; b++) {
    const long *lo = boxes[b], *hi = boxes[b] + 3;
    long m = 0, *bgrid = NULL, *bkey = NULL, k = 0;
    double *bx = NULL;
    check_ok(mica_layout_irregular_box(s, l, lo, hi, &m, &bx, &bgrid, &bkey));
    assert_true(m > 0);
    for (long i = 0; i < n; i++) {
      const long g[3] = {grid[i] % hi0[0], (grid[i] / hi0[0]) % hi0[1], grid[i] / (hi0[0] * hi0[1])};
      int in = 1;
      for (int d = 0; d < 3; d++) in &= g[d] >= lo[d] && g[d] < hi[d];
      if (!in) continue;
      assert_true(k < m);
      assert_int_equal(bkey[k], key[i]);
      assert_int_equal(bgrid[k], grid[i]);
      assert_memory_equal(&bx[k * dim], &x[i * dim], sizeof(double) * (size_t)dim);
      k++;
    }
    assert_int_equal(k, m);
    free(bx), free(bgrid), free(bkey);
  }
  mica_discretization_destroy(&disc);
  free(x), free(grid), free(key);
}

static void test_irregular_parts(void **state) {
  (void)state;
  const MicaShapeSpec oblong = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, 0}, .upper = {1, 1}};
  MicaLayoutSpec l = layout_of(MICA_LAYOUT_IRREGULAR, 61, 37, 0);
  l.seed = 4;
  /* a corner, the middle (far from every face: the tiles' dependencies reach it from all sides), a strip */
  const long boxes2[][6] = {{0, 0, 0, 9, 7, 1}, {25, 14, 0, 33, 21, 1}, {40, 0, 0, 41, 37, 1}};
  irregular_parts(&oblong, &l, boxes2, 3);
  const MicaShapeSpec cube = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {1, 1, 1}};
  l = layout_of(MICA_LAYOUT_IRREGULAR, 41, 41, 41);
  l.seed = 5;
  const long boxes3[][6] = {{18, 18, 18, 23, 22, 21}, {0, 30, 5, 41, 41, 9}};
  irregular_parts(&cube, &l, boxes3, 2);
}

/* ---- errors ---- */

static void test_layout_errors(void **state) {
  (void)state;
  MicaDiscretization *disc = NULL;
  const MicaCellSpec cells = {.order = 1};
  MicaLayoutSpec l = layout_of(MICA_LAYOUT_JITTERED, 4, 4, 0);
  l.jitter = 0.5;
  assert_int_equal(mica_discretization_create(&unit_square, &l, &cells, &disc), MICA_ERR_INPUT);
  assert_non_null(strstr(mica_error_message(), "jitter"));
  l = layout_of(MICA_LAYOUT_GRADED, 4, 4, 0);
  l.grading[1] = 0.0;
  assert_int_equal(mica_discretization_create(&unit_square, &l, &cells, &disc), MICA_ERR_INPUT);
  assert_non_null(strstr(mica_error_message(), "grading[1]"));
  assert_null(disc);
  mica_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_regular_inside), cmocka_unit_test(test_graded),
      cmocka_unit_test(test_jittered_box),   cmocka_unit_test(test_jittered_curved),
      cmocka_unit_test(test_irregular),      cmocka_unit_test(test_irregular_plate),
      cmocka_unit_test(test_irregular_parts),
      cmocka_unit_test(test_layout_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
