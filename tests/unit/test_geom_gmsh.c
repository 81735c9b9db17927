/* Unit tests of the Gmsh reader and mesh discretization (src/geom/gmsh.c, src/geom/mesh.c), on the shipped
 * meshes (input/meshes) and the test meshes (tests/meshes, see its README.md). Run from the repository root.
 *
 *   - plate_hole.msh (triangles): dimension 2, sets hole, left, bottom, right, top in tag order; the area
 *     equals 25 minus the polygonal hole (the fan of the hole's chords) to 1e-13, and π/4-close to the
 *     exact 25 − π/4; straight sets' lengths exact; the hole's length equals its chords' sum (1e-13) and is
 *     close to π/2; normals outward (constant on straight sides, pointing into the hole on the arc); the
 *     divergence theorem Σ w x·n = 2V and Σ w n = 0 to 1e-13; particles are only the triangles' nodes.
 *   - cube.msh (tetrahedra), box_hex.msh (hexahedra), square_quads.msh (quadrangles): volume/area, every
 *     set's area/length, normals, divergence theorem, element sizes, vertex counts, lambda_N interpolating
 *     the points from the vertices exactly (linear elements).
 *   - errors, each MICA_ERR_INPUT naming file:LINE: truncated file (inside a section, and between sections:
 *     a missing $Elements), version 2.2, binary, second-order elements, an undefined node in an element, a
 *     node tag outside the header's range, not a mesh at all, a missing file.
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

static MicaDiscretization *load(const char *path, int order, int boundary_order) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = path};
  const MicaLayoutSpec layout = {0};
  const MicaCellSpec cells = {.order = order, .boundary_order = boundary_order};
  MicaDiscretization *disc = NULL;
  check_ok(mica_discretization_create(&shape, &layout, &cells, &disc));
  return disc;
}

static void load_fails(const char *path, const char *where, const char *what) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = path};
  const MicaLayoutSpec layout = {0};
  const MicaCellSpec cells = {.order = 2};
  MicaDiscretization *disc = NULL;
  const int ierr = mica_discretization_create(&shape, &layout, &cells, &disc);
  const char *msg = mica_error_message();
  if (ierr != MICA_ERR_INPUT || !strstr(msg, where) || !strstr(msg, what)) {
    print_error("%s: expected MICA_ERR_INPUT with '%s' and '%s', got %d: %s\n", path, where, what, ierr, msg);
    fail();
  }
  assert_null(disc);
  mica_error_clear();
}

static const MicaBoundarySet *set_named(const MicaDiscretization *disc, const char *name) {
  const int s = mica_discretization_find_set(disc, name);
  if (s < 0) {
    print_error("no set '%s'\n", name);
    fail();
  }
  return &disc->sets[s];
}

static double set_measure(const MicaBoundarySet *set) {
  double m = 0.0;
  for (long q = 0; q < set->n; q++) m += set->w[q];
  return m;
}

static void assert_rel(double got, double want, double rtol, const char *what) {
  if (!(fabs(got - want) <= rtol * fabs(want))) {
    print_error("%s: got %.17g, want %.17g\n", what, got, want);
    fail();
  }
}

/* Σ w x·n = dim V and Σ w n = 0 over every set (the sets close the boundary). */
static void check_divergence(const MicaDiscretization *disc, double rtol) {
  const int dim = disc->dim;
  double flux = 0.0, net[3] = {0, 0, 0}, measure = 0.0;
  for (int s = 0; s < disc->nsets; s++) {
    const MicaBoundarySet *set = &disc->sets[s];
    measure += set_measure(set);
    for (long q = 0; q < set->n; q++)
      for (int d = 0; d < dim; d++) {
        flux += set->w[q] * set->x[q * dim + d] * set->normal[q * dim + d];
        net[d] += set->w[q] * set->normal[q * dim + d];
      }
  }
  assert_rel(flux, dim * disc->volume, rtol, "Σ w x·n");
  for (int d = 0; d < dim; d++) assert_true(fabs(net[d]) <= rtol * measure);
}

static void check_constant_normal(const MicaDiscretization *disc, const char *name, const double *want) {
  const MicaBoundarySet *set = set_named(disc, name);
  for (long q = 0; q < set->n; q++)
    for (int d = 0; d < disc->dim; d++) assert_true(fabs(set->normal[q * disc->dim + d] - want[d]) < 1e-14);
}

/* Linear elements: lambda_N interpolates each point from its element's vertices. */
static void check_interpolation(const MicaDiscretization *disc) {
  const int dim = disc->dim;
  for (int s = 0; s < disc->nsets; s++) {
    const MicaBoundarySet *set = &disc->sets[s];
    for (long q = 0; q < set->n; q++) {
      const long *ev = &set->element_vertices[set->element[q] * set->element_size];
      double sum = 0.0;
      for (int a = 0; a < 4; a++) sum += set->lambda_N[q * 4 + a];
      assert_true(fabs(sum - 1.0) < 1e-14);
      for (int d = 0; d < dim; d++) {
        double x = 0.0;
        for (int a = 0; a < set->element_size; a++)
          x += set->lambda_N[q * 4 + a] * set->vertex_x[ev[a] * dim + d];
        assert_true(fabs(x - set->x[q * dim + d]) < 1e-13);
      }
    }
  }
}

/* ---- the shipped plate with a hole ---- */

static int compare_angle(const void *a, const void *b) {
  const double *p = a, *q = b, ta = atan2(p[1], p[0]), tb = atan2(q[1], q[0]);
  return (ta > tb) - (ta < tb);
}

static void test_plate_hole_mesh(void **state) {
  (void)state;
  MicaDiscretization *disc = load("input/meshes/plate_hole.msh", 2, 2);
  assert_int_equal(disc->dim, 2);
  char names[128];
  mica_discretization_set_names(disc, names, sizeof names);
  assert_string_equal(names, "hole, left, bottom, right, top");
  /* the hole's vertices in angle order: the chords' fan is the polygonal hole */
  const MicaBoundarySet *hole = set_named(disc, "hole");
  double *v = malloc(sizeof(double) * 2 * hole->nvertices);
  memcpy(v, hole->vertex_x, sizeof(double) * 2 * hole->nvertices);
  qsort(v, (size_t)hole->nvertices, 2 * sizeof(double), compare_angle);
  double hole_area = 0.0, chords = 0.0;
  for (long k = 0; k + 1 < hole->nvertices; k++) {
    hole_area += 0.5 * (v[2 * k] * v[2 * k + 3] - v[2 * k + 1] * v[2 * k + 2]);
    chords += hypot(v[2 * k + 2] - v[2 * k], v[2 * k + 3] - v[2 * k + 1]);
  }
  assert_true(fabs(hypot(v[0], v[1]) - 1) < 1e-12 && fabs(v[0] - 1) < 1e-12); /* starts at (1, 0) */
  free(v);
  assert_rel(disc->volume, 25.0 - hole_area, 1e-13, "area");
  assert_rel(disc->volume, 25.0 - PI / 4.0, 1e-3, "area ≈ 25 − π/4");
  assert_rel(set_measure(hole), chords, 1e-13, "hole length = Σ chords");
  assert_rel(set_measure(hole), PI / 2.0, 1e-2, "hole length ≈ π/2");
  assert_rel(set_measure(set_named(disc, "left")), 4.0, 1e-13, "left");
  assert_rel(set_measure(set_named(disc, "bottom")), 4.0, 1e-13, "bottom");
  assert_rel(set_measure(set_named(disc, "right")), 5.0, 1e-13, "right");
  assert_rel(set_measure(set_named(disc, "top")), 5.0, 1e-13, "top");
  check_constant_normal(disc, "left", (double[]){-1, 0});
  check_constant_normal(disc, "bottom", (double[]){0, -1});
  check_constant_normal(disc, "right", (double[]){1, 0});
  check_constant_normal(disc, "top", (double[]){0, 1});
  for (long q = 0; q < hole->n; q++) { /* into the hole: nearly −x/|x| (within a chord's half angle) */
    const double *x = &hole->x[2 * q], *n = &hole->normal[2 * q];
    assert_true(-(x[0] * n[0] + x[1] * n[1]) / hypot(x[0], x[1]) > cos(0.2));
  }
  check_divergence(disc, 1e-13);
  check_interpolation(disc);
  assert_int_equal(hole->element_size, 2);
  assert_int_equal(hole->nvertices, hole->nelements + 1);
  /* particles: inside the plate, outside the (polygonal) hole, each a node of a triangle */
  for (long p = 0; p < disc->nparticles; p++) {
    const double *x = &disc->x[2 * p];
    assert_true(x[0] >= 0 && x[1] >= 0 && x[0] <= 5 && x[1] <= 5 && hypot(x[0], x[1]) > 0.99);
  }
  assert_int_equal(disc->nquad, disc->ncells * 4);
  mica_discretization_destroy(&disc);
}

/* ---- 3-D: tetrahedra and hexahedra ---- */

static const char *box_sets[6] = {"left", "right", "bottom", "top", "back", "front"};

static void check_box_mesh(const MicaDiscretization *disc, const double size[3]) {
  assert_int_equal(disc->dim, 3);
  assert_rel(disc->volume, size[0] * size[1] * size[2], 1e-13, "volume");
  for (int s = 0; s < 6; s++) {
    const int axis = s / 2;
    double n[3] = {0, 0, 0};
    n[axis] = s % 2 ? 1.0 : -1.0;
    check_constant_normal(disc, box_sets[s], n);
    assert_rel(set_measure(set_named(disc, box_sets[s])), size[0] * size[1] * size[2] / size[axis], 1e-13,
               box_sets[s]);
    const MicaBoundarySet *set = set_named(disc, box_sets[s]);
    for (long q = 0; q < set->n; q++)
      assert_true(fabs(set->x[3 * q + axis] - (s % 2 ? size[axis] : 0.0)) < 1e-13);
  }
  check_divergence(disc, 1e-13);
  check_interpolation(disc);
}

static void test_cube_mesh(void **state) {
  (void)state;
  MicaDiscretization *disc = load("input/meshes/cube.msh", 2, 3);
  check_box_mesh(disc, (double[]){1, 1, 1});
  assert_int_equal(disc->nsets, 6);
  assert_int_equal(set_named(disc, "front")->element_size, 3);
  assert_int_equal(set_named(disc, "front")->n, set_named(disc, "front")->nelements * 9);
  assert_int_equal(disc->nquad, disc->ncells * 8);
  mica_discretization_destroy(&disc);
}

static void test_hex_mesh(void **state) {
  (void)state;
  MicaDiscretization *disc = load("tests/meshes/box_hex.msh", 2, 2);
  check_box_mesh(disc, (double[]){2, 1, 1});
  assert_int_equal(disc->ncells, 16);
  assert_int_equal(disc->nparticles, 5 * 3 * 3);
  const MicaBoundarySet *left = set_named(disc, "left");
  assert_int_equal(left->element_size, 4);
  assert_int_equal(left->nelements, 4);
  assert_int_equal(left->nvertices, 9);
  const MicaBoundarySet *top = set_named(disc, "top");
  assert_int_equal(top->nelements, 8);
  assert_int_equal(top->nvertices, 15);
  mica_discretization_destroy(&disc);
}

static void test_quad_mesh(void **state) {
  (void)state;
  MicaDiscretization *disc = load("tests/meshes/square_quads.msh", 3, 1);
  assert_int_equal(disc->dim, 2);
  assert_int_equal(disc->ncells, 16);
  assert_int_equal(disc->nparticles, 25);
  assert_int_equal(disc->nquad, 16 * 9);
  assert_rel(disc->volume, 1.0, 1e-13, "area");
  const char *names[4] = {"left", "right", "bottom", "top"};
  const double normals[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  for (int s = 0; s < 4; s++) {
    assert_rel(set_measure(set_named(disc, names[s])), 1.0, 1e-13, names[s]);
    check_constant_normal(disc, names[s], normals[s]);
    assert_int_equal(set_named(disc, names[s])->nvertices, 5);
    assert_int_equal(set_named(disc, names[s])->n, 4);
  }
  check_divergence(disc, 1e-13);
  check_interpolation(disc);
  mica_discretization_destroy(&disc);
}

/* ---- errors ---- */

static void test_errors(void **state) {
  (void)state;
  load_fails("tests/meshes/plate_hole_truncated.msh",
             "tests/meshes/plate_hole_truncated.msh:1000:", "truncated");
  load_fails("tests/meshes/plate_hole_truncated.msh", ":1000:", "$Elements");
  load_fails("tests/meshes/square_v22.msh", "square_v22.msh:2:", "version 2.2");
  load_fails("tests/meshes/square_binary.msh", "square_binary.msh:2:", "binary");
  load_fails("tests/meshes/square_tri6.msh", "square_tri6.msh:109:", "element type 8");
  load_fails("tests/meshes/square_bad_node.msh", "square_bad_node.msh:90:", "node 99");
  load_fails("tests/meshes/square_node_range.msh",
             "square_node_range.msh:27:", "node tag 26 is out of range");
  load_fails("tests/meshes/square_no_elements.msh",
             "square_no_elements.msh:85:", "without a $Elements section");
  load_fails("tests/meshes/no_such_mesh.msh", "no_such_mesh.msh", "cannot open");
  load_fails("tests/meshes/README.md", "README.md:1:", "$MeshFormat");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plate_hole_mesh), cmocka_unit_test(test_cube_mesh),
      cmocka_unit_test(test_hex_mesh),        cmocka_unit_test(test_quad_mesh),
      cmocka_unit_test(test_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
