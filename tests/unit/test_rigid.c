/* mica_dirichlet_check_rigid on hand-made boundary sets, against the rigid motions counted by hand: a rotation
 * needs its displacements held at two distinct places (or its micro-rotation held), a translation one prescribed
 * component anywhere.
 * mica_rigid_motions (the near-null space for GAMG) against the motions written out here: translations, and
 * rotations u = ω × (x − x0), φ = ω with ω = e_k / L — the Cosserat rigid motion of test_cosserat.c's sign
 * convention (u = (−ωy, ωx), φ_z = ω has W = 0) — with x0 the particles' centroid and L their extent; the
 * multiplier unknowns after the particles' are 0. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mica/bc.h"

static const char *const PLANE[] = {"ux", "uy", NULL};
static const char *const COSSERAT[] = {"ux", "uy", "phiz", NULL};
static const char *const SPACE[] = {"ux", "uy", "uz", NULL};

/* Two sets of points in the plane (or space): a = {(0,0), (0,0)} (one place, twice), b = {(0,0), (0,1)}. */
static double xa[] = {0, 0, 0, 0}, xb[] = {0, 0, 0, 1}, w2[] = {0.5, 0.5};
static double xa3[] = {0, 0, 0, 0, 0, 0}, xb3[] = {0, 0, 0, 0, 1, 0, 1, 0, 0};
static double w3[] = {1, 1, 1};

static MicaDiscretization plane(MicaBoundarySet *sets) {
  memset(sets, 0, 2 * sizeof *sets);
  sets[0].n = 2, sets[0].x = xa, sets[0].w = w2;
  sets[1].n = 2, sets[1].x = xb, sets[1].w = w2;
  MicaDiscretization disc;
  memset(&disc, 0, sizeof disc);
  disc.dim = 2, disc.nsets = 2, disc.sets = sets;
  return disc;
}

static int check(const MicaDiscretization *disc, int ncomp, const char *const *names, int n, const MicaDirichlet *c) {
  const int ierr = mica_dirichlet_check_rigid(disc, 0, 0, ncomp, names, n, c, "deck.cfg:3");
  return ierr;
}

static void expect_free(const MicaDiscretization *disc, int ncomp, const char *const *names, int n,
                        const MicaDirichlet *c, const char *message) {
  assert_int_equal(check(disc, ncomp, names, n, c), MICA_ERR_INPUT);
  assert_string_equal(mica_error_message(), message);
  mica_error_clear();
}

static void test_plane(void **state) {
  (void)state;
  MicaBoundarySet sets[2];
  const MicaDiscretization disc = plane(sets);
  MicaDirichlet c[2];
  memset(c, 0, sizeof c);
  expect_free(&disc, 2, PLANE, 0, c,
              "deck.cfg:3: the body can move freely: 3 rigid modes are not held (translation in x, translation in y, "
              "rotation about z); add Dirichlet conditions on ux, uy");
  c[0].set = 0, c[0].mask = 3; /* ux, uy at one place: the rotation about it is free */
  expect_free(&disc, 2, PLANE, 1, c,
              "deck.cfg:3: the body can move freely: 1 rigid mode is not held (rotation about z); add Dirichlet "
              "conditions on ux, uy");
  c[1].set = 1, c[1].mask = 1; /* and ux at a second place off the line through it along x: held */
  assert_int_equal(check(&disc, 2, PLANE, 2, c), MICA_SUCCESS);
  c[1].mask = 2; /* uy at (0,1), straight above (0,0): a rotation about (0,0) moves it along x only */
  expect_free(&disc, 2, PLANE, 2, c,
              "deck.cfg:3: the body can move freely: 1 rigid mode is not held (rotation about z); add Dirichlet "
              "conditions on ux, uy");
}

static void test_cosserat(void **state) {
  (void)state;
  MicaBoundarySet sets[2];
  const MicaDiscretization disc = plane(sets);
  MicaDirichlet c[1];
  memset(c, 0, sizeof c);
  c[0].set = 0, c[0].mask = 3; /* ux, uy at one place, and φ there: the rigid rotation turns φ too */
  expect_free(&disc, 3, COSSERAT, 1, c,
              "deck.cfg:3: the body can move freely: 1 rigid mode is not held (rotation about z); add Dirichlet "
              "conditions on ux, uy, phiz");
  c[0].mask = 7;
  assert_int_equal(check(&disc, 3, COSSERAT, 1, c), MICA_SUCCESS);
}

static void test_space(void **state) {
  (void)state;
  MicaBoundarySet sets[2];
  memset(sets, 0, sizeof sets);
  sets[0].n = 2, sets[0].x = xa3, sets[0].w = w2;
  sets[1].n = 3, sets[1].x = xb3, sets[1].w = w3; /* (0,0,0), (0,1,0), (1,0,0): the plane z = 0 */
  MicaDiscretization disc;
  memset(&disc, 0, sizeof disc);
  disc.dim = 3, disc.nsets = 2, disc.sets = sets;
  MicaDirichlet c[1];
  memset(c, 0, sizeof c);
  c[0].set = 1, c[0].mask = 4; /* uz on the plane z = 0: holds the translation in z and the rotations about x, y */
  expect_free(&disc, 3, SPACE, 1, c,
              "deck.cfg:3: the body can move freely: 3 rigid modes are not held (translation in x, translation in y, "
              "rotation about z); add Dirichlet conditions on ux, uy");
  c[0].set = 0, c[0].mask = 7; /* everything at one point: the three rotations about it are free */
  expect_free(&disc, 3, SPACE, 1, c,
              "deck.cfg:3: the body can move freely: 3 rigid modes are not held (rotation about x, rotation about y, "
              "rotation about z); add Dirichlet conditions on ux, uy, uz");
  c[0].set = 1; /* everything on three points not on one line: held */
  assert_int_equal(check(&disc, 3, SPACE, 1, c), MICA_SUCCESS);
}

/* The rigid motions as vectors: 3 particles of the unit square, then 1 multiplier node (3 unknowns, all 0). */
static void test_motions_cosserat(void **state) {
  (void)state;
  const double x[] = {0, 0, 1, 0, 1, 1}; /* centroid (2/3, 1/3), extent L = 1 */
  const long n = 4 * 3;
  int count = 0;
  double *m = NULL;
  assert_int_equal(mica_rigid_motions(x, 3, 2, 0, 3, COSSERAT, n, &count, &m), 0);
  assert_int_equal(count, 3);
  for (long p = 0; p < 3; p++) {
    const double dx = x[2 * p] - 2.0 / 3.0, dy = x[2 * p + 1] - 1.0 / 3.0;
    const double want[3][3] = {{1, 0, 0}, {0, 1, 0}, {-dy, dx, 1}}; /* t_x, t_y, rotation ω = 1 / L = 1 */
    for (int j = 0; j < 3; j++)
      for (int c = 0; c < 3; c++) assert_true(fabs(m[j * n + p * 3 + c] - want[j][c]) < 1e-15);
  }
  for (int j = 0; j < 3; j++)
    for (int c = 0; c < 3; c++) assert_true(m[j * n + 9 + c] == 0.0);
  free(m);
}

/* 3-D classical (6 motions) and Cosserat (u, φ): a rotation about z at particles spread over L = 2. */
static void test_motions_space(void **state) {
  (void)state;
  const double x[] = {0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 2}; /* centroid (0.5, 0.5, 0.5), L = 2 */
  static const char *const COSSERAT3[] = {"ux", "uy", "uz", "phix", "phiy", "phiz", NULL};
  int count = 0;
  double *m = NULL;
  assert_int_equal(mica_rigid_motions(x, 4, 3, 0, 3, SPACE, 12, &count, &m), 0);
  assert_int_equal(count, 6);
  free(m);
  assert_int_equal(mica_rigid_motions(x, 4, 3, 0, 6, COSSERAT3, 24, &count, &m), 0);
  assert_int_equal(count, 6);
  const int about_z = 5; /* translations x, y, z, then rotations about x, y, z */
  for (long p = 0; p < 4; p++) {
    const double dx = x[3 * p] - 0.5, dy = x[3 * p + 1] - 0.5, w = 0.5; /* ω = e_z / L */
    const double want[6] = {-w * dy, w * dx, 0, 0, 0, w};
    for (int c = 0; c < 6; c++) assert_true(fabs(m[about_z * 24 + p * 6 + c] - want[c]) < 1e-15);
  }
  free(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_plane), cmocka_unit_test(test_cosserat),
                                     cmocka_unit_test(test_space), cmocka_unit_test(test_motions_cosserat),
                                     cmocka_unit_test(test_motions_space)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
