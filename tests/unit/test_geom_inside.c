/* Unit tests of the inside test (src/geom/inside.c): for every built-in shape (2-D and 3-D box, Cook's
 * quadrilateral, the quarter plate with a hole, annulus sectors narrower and wider than π, the cylinder) and
 * for Gmsh meshes of triangles (input/meshes/plate_hole.msh), quadrilaterals and hexahedra (tests/meshes)
 * and a tetrahedron (written here):
 *   - points well inside are inside; corners, edges and arcs are inside, also a round-off (1e-12 of the size)
 *     past them; points past the boundary by 1e-5 of the size, or in a hole or a re-entrant region inside the
 *     bounding box, are outside (the tolerance is MICA_BODY_TOLERANCE = 1e-8 of the box's diagonal);
 *   - the bounding box (exact: the annulus' cos(π/2) round-off is set to 0) and the description.
 * Errors: a clockwise polygon (the shape's own check), a missing mesh file. Run from the repository root. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "mica/geom.h"

#define PI 3.14159265358979323846

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static MicaBody *body_of(const MicaShapeSpec *shape) {
  MicaBody *b = NULL;
  check_ok(mica_body_create(shape, &b));
  return b;
}

static int in2(const MicaBody *b, double x, double y) {
  const double p[2] = {x, y};
  return mica_body_contains(b, p);
}

static int in3(const MicaBody *b, double x, double y, double z) {
  const double p[3] = {x, y, z};
  return mica_body_contains(b, p);
}

static void assert_bounds(const MicaBody *b, const double *lo, const double *hi) {
  double l[3], h[3];
  mica_body_bounds(b, l, h);
  for (int d = 0; d < mica_body_dim(b); d++) {
    assert_true(l[d] == lo[d]);
    assert_true(h[d] == hi[d]);
  }
}

static void assert_describes(const MicaBody *b, const char *text) {
  char buf[256];
  mica_body_describe(b, buf, sizeof buf);
  if (!strstr(buf, text)) {
    print_error("'%s' lacks '%s'\n", buf, text);
    fail();
  }
}

static void test_box(void **state) {
  (void)state;
  MicaShapeSpec s = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {0, -6}, .upper = {48, 6}};
  MicaBody *b = body_of(&s);
  assert_int_equal(mica_body_dim(b), 2);
  assert_true(in2(b, 24, 0) && in2(b, 0, -6) && in2(b, 48, 6) && in2(b, 48, 0) && in2(b, 48 * (1 + 1e-12), 0));
  assert_false(in2(b, 48.8, 0));
  assert_false(in2(b, 48 + 5e-4, 0)); /* 1e-5 of the diagonal 49.5 */
  assert_false(in2(b, 10, -6.001));
  assert_bounds(b, (double[]){0, -6}, (double[]){48, 6});
  assert_describes(b, "the box");
  mica_body_destroy(&b);
  assert_null(b);
  MicaShapeSpec s3 = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {1, 1, 1}};
  b = body_of(&s3);
  assert_int_equal(mica_body_dim(b), 3);
  assert_true(in3(b, 1, 1, 1) && in3(b, 0.5, 0.5, 0.5) && in3(b, 0, 0.3, 1));
  assert_false(in3(b, 0.5, 0.5, 1.001));
  mica_body_destroy(&b);
}

/* Cook's trapezoid (0,0), (48,44), (48,60), (0,44): the sloped edges are the test */
static void test_polygon(void **state) {
  (void)state;
  MicaShapeSpec s = {.kind = MICA_SHAPE_POLYGON, .dim = 2, .vertices = {{0, 0}, {48, 44}, {48, 60}, {0, 44}}};
  MicaBody *b = body_of(&s);
  assert_true(in2(b, 48, 60) && in2(b, 0, 0) && in2(b, 24, 40) && in2(b, 24, 52) && in2(b, 24, 22));
  assert_true(in2(b, 24, 52 * (1 + 1e-12)));
  assert_false(in2(b, 24, 52.01)); /* above the top edge */
  assert_false(in2(b, 24, 21.99)); /* below the bottom edge, inside the bounding box */
  assert_false(in2(b, 48, 30));
  assert_bounds(b, (double[]){0, 0}, (double[]){48, 60});
  assert_describes(b, "the quadrilateral");
  mica_body_destroy(&b);
  MicaShapeSpec cw = {.kind = MICA_SHAPE_POLYGON, .dim = 2, .vertices = {{0, 44}, {48, 60}, {48, 44}, {0, 0}}};
  b = NULL;
  assert_int_equal(mica_body_create(&cw, &b), MICA_ERR_INPUT);
  assert_null(b);
  mica_error_clear();
}

static void test_plate_hole(void **state) {
  (void)state;
  MicaShapeSpec s = {.kind = MICA_SHAPE_PLATE_HOLE, .dim = 2, .hole_radius = 1, .plate_size = {5, 4}};
  MicaBody *b = body_of(&s);
  assert_true(in2(b, cos(0.3), sin(0.3)) && in2(b, 0, 1) && in2(b, 1, 0) && in2(b, 5, 4) && in2(b, 0, 3));
  assert_true(in2(b, 3, 2));
  assert_false(in2(b, 0.5, 0.5)); /* in the hole */
  assert_false(in2(b, 0.999 * cos(0.3), 0.999 * sin(0.3)));
  assert_false(in2(b, 5.01, 1));
  assert_false(in2(b, -0.01, 2));
  assert_bounds(b, (double[]){0, 0}, (double[]){5, 4});
  assert_describes(b, "the quarter plate with a hole of radius 1");
  mica_body_destroy(&b);
}

static double rx(double r, double deg) { return r * cos(deg * PI / 180); }
static double ry(double r, double deg) { return r * sin(deg * PI / 180); }

static void test_annulus(void **state) {
  (void)state;
  MicaShapeSpec s = {.kind = MICA_SHAPE_ANNULUS, .dim = 2, .r_inner = 1, .r_outer = 2, .theta0 = 0, .theta1 = PI / 2};
  MicaBody *b = body_of(&s);
  assert_true(in2(b, 1.5, 0) && in2(b, 0, 1.5) && in2(b, 0, 1) && in2(b, 2, 0) && in2(b, sqrt(2), sqrt(2)));
  assert_true(in2(b, rx(1.5, 45), ry(1.5, 45)) && in2(b, 1.5, -1e-13) && in2(b, -1e-13, 1.5));
  assert_false(in2(b, 1.5, -0.01));
  assert_false(in2(b, -0.01, 1.5));
  assert_false(in2(b, 0.5, 0.5)); /* r < r_inner */
  assert_false(in2(b, 1.5, 1.5)); /* r > r_outer, inside the bounding box */
  assert_bounds(b, (double[]){0, 0}, (double[]){2, 2});
  assert_describes(b, "the annulus sector 1 <= r <= 2, 0 <= theta <= 90 degrees");
  mica_body_destroy(&b);
  /* wider than π, across the negative x axis: 30° to 300° */
  MicaShapeSpec w = {.kind = MICA_SHAPE_ANNULUS, .dim = 2, .r_inner = 1, .r_outer = 2, .theta0 = PI / 6,
                     .theta1 = 5 * PI / 3};
  b = body_of(&w);
  assert_true(in2(b, rx(1.5, 200), ry(1.5, 200)) && in2(b, rx(1.5, 300), ry(1.5, 300)) &&
              in2(b, rx(1.5, 30), ry(1.5, 30)) && in2(b, -2, 0) && in2(b, 0, -2));
  assert_false(in2(b, rx(1.5, 330), ry(1.5, 330)));
  assert_false(in2(b, rx(1.5, 10), ry(1.5, 10)));
  assert_bounds(b, (double[]){-2, -2}, (double[]){rx(2, 30), 2});
  mica_body_destroy(&b);
}

static void test_cylinder(void **state) {
  (void)state;
  MicaShapeSpec s = {.kind = MICA_SHAPE_CYLINDER, .dim = 3, .radius = 1, .height = 2};
  MicaBody *b = body_of(&s);
  assert_true(in3(b, 0, 0, 0) && in3(b, sqrt(0.5), sqrt(0.5), 2) && in3(b, 1, 0, 1) && in3(b, 0, -1, 0.5));
  assert_false(in3(b, 0.72, 0.72, 1)); /* r = 1.018, inside the bounding box */
  assert_false(in3(b, 0, 0, 2.01));
  assert_false(in3(b, 0, 0, -0.01));
  assert_bounds(b, (double[]){-1, -1, 0}, (double[]){1, 1, 2});
  assert_describes(b, "the cylinder of radius 1 and height 2");
  mica_body_destroy(&b);
}

static MicaBody *mesh_body(const char *path) {
  MicaShapeSpec s = {.kind = MICA_SHAPE_GMSH, .mesh_path = path};
  return body_of(&s);
}

static void test_mesh_triangles(void **state) {
  (void)state;
  MicaBody *b = mesh_body("input/meshes/plate_hole.msh"); /* a = 1, plate 5 × 5, polygonal hole */
  assert_int_equal(mica_body_dim(b), 2);
  assert_true(in2(b, 3, 3) && in2(b, 0, 1) && in2(b, 1, 0) && in2(b, 5, 5) && in2(b, 0, 4) && in2(b, 2.5, 0));
  assert_false(in2(b, 0.5, 0.5)); /* the hole */
  assert_false(in2(b, 5.01, 2));
  assert_bounds(b, (double[]){0, 0}, (double[]){5, 5});
  assert_describes(b, "the elements of input/meshes/plate_hole.msh");
  mica_body_destroy(&b);
}

static void test_mesh_quads_hexes(void **state) {
  (void)state;
  MicaBody *b = mesh_body("tests/meshes/square_quads.msh"); /* the unit square */
  assert_true(in2(b, 0.5, 0.5) && in2(b, 1, 1) && in2(b, 0, 0.3) && in2(b, 0.125, 0.875));
  assert_false(in2(b, 1.01, 0.5));
  assert_false(in2(b, 0.5, -0.001));
  mica_body_destroy(&b);
  b = mesh_body("tests/meshes/box_hex.msh"); /* [0, 2] × [0, 1] × [0, 1] */
  assert_int_equal(mica_body_dim(b), 3);
  assert_true(in3(b, 1, 0.5, 0.5) && in3(b, 2, 1, 1) && in3(b, 0, 0, 0) && in3(b, 0.3, 0.7, 0.1));
  assert_true(in3(b, 0.25, 0.25, 0.25) && in3(b, 1.9, 0.05, 0.95));
  assert_false(in3(b, 2.01, 0.5, 0.5));
  assert_false(in3(b, 1, 0.5, -0.001));
  assert_bounds(b, (double[]){0, 0, 0}, (double[]){2, 1, 1});
  mica_body_destroy(&b);
}

/* One tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) as a .msh 4.1 file. */
static void test_mesh_tetrahedron(void **state) {
  (void)state;
  char path[] = "/tmp/mica_test_tet_XXXXXX";
  const int fd = mkstemp(path);
  assert_true(fd >= 0);
  FILE *f = fdopen(fd, "w");
  assert_non_null(f);
  fputs("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
        "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"
        "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n", f);
  fclose(f);
  MicaBody *b = mesh_body(path);
  assert_int_equal(mica_body_dim(b), 3);
  assert_true(in3(b, 0.2, 0.2, 0.2) && in3(b, 1.0 / 3, 1.0 / 3, 1.0 / 3) && in3(b, 0, 0, 1) && in3(b, 0.5, 0, 0));
  assert_false(in3(b, 0.4, 0.4, 0.4));
  assert_false(in3(b, 0.1, 0.1, -0.01));
  mica_body_destroy(&b);
  unlink(path);
}

static void test_errors(void **state) {
  (void)state;
  MicaBody *b = NULL;
  MicaShapeSpec s = {.kind = MICA_SHAPE_GMSH, .mesh_path = "tests/meshes/no_such_mesh.msh"};
  assert_int_not_equal(mica_body_create(&s, &b), MICA_SUCCESS);
  assert_null(b);
  mica_error_clear();
  assert_int_equal(mica_body_create(NULL, &b), MICA_ERR_ARGUMENT);
  mica_error_clear();
  assert_int_equal(mica_body_destroy(&b), MICA_SUCCESS); /* NULL is fine */
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_box),
      cmocka_unit_test(test_polygon),
      cmocka_unit_test(test_plate_hole),
      cmocka_unit_test(test_annulus),
      cmocka_unit_test(test_cylinder),
      cmocka_unit_test(test_mesh_triangles),
      cmocka_unit_test(test_mesh_quads_hexes),
      cmocka_unit_test(test_mesh_tetrahedron),
      cmocka_unit_test(test_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
