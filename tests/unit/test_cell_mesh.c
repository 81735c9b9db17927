/* Unit tests of the cells as an output mesh (src/geom/cell_mesh.c, the finite elements' in src/fe/fe_mesh.c):
 *   - a 2-D box: bilinear quadrilaterals (VTK 9) on the particles themselves, cell 0 = points 0, 1, n+1, n in
 *     VTK's counterclockwise order; a 3-D box: trilinear hexahedra (12), (n+1)^3 points;
 *   - the plate with a hole, whose map reverses orientation: biquadratic quadrilaterals (28) on the grid refined
 *     by two, every cell positively oriented after mica_cell_mesh_orient, the hole's nodes (corners and edge
 *     midpoints) on the circle r = a to 1e-14, and the cells' shoelace area of the corners just above the
 *     plate's (their chords cut into the hole);
 *   - every node of an affine triquadratic hexahedron and biquadratic quadrilateral at its lattice position
 *     (mica_cell_lattice), before and after reversing a negatively oriented one;
 *   - Gmsh meshes: the elements of square_quads.msh and box_hex.msh, on the particles;
 *   - Q2 finite elements: the element's nine nodes in VTK's order.
 * Every cell's points are in range and no point is unused. Run from the repository root. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/fe.h"
#include "mica/geom.h"

#define PI 3.14159265358979323846

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static MicaDiscretization *mapped(MicaShapeSpec shape, long n0, long n1, long n2) {
  const MicaLayoutSpec layout = {.kind = MICA_LAYOUT_REGULAR, .count = {n0, n1, n2}, .grading = {1, 1, 1}};
  const MicaCellSpec cells = {.order = 2};
  MicaDiscretization *disc = NULL;
  check_ok(mica_discretization_create(&shape, &layout, &cells, &disc));
  return disc;
}

/* Points in range, each used, node counts per type. */
static void check_structure(const MicaCellMesh *m, int type) {
  char *used = calloc((size_t)m->npoints, 1);
  assert_non_null(used);
  assert_int_equal(m->offsets[0], 0);
  for (long c = 0; c < m->ncells; c++) {
    if (type) assert_int_equal(m->type[c], type);
    assert_int_equal(m->offsets[c + 1] - m->offsets[c], mica_cell_nodes(m->type[c]));
    for (long k = m->offsets[c]; k < m->offsets[c + 1]; k++) {
      assert_true(m->conn[k] >= 0 && m->conn[k] < m->npoints);
      used[m->conn[k]] = 1;
    }
  }
  for (long p = 0; p < m->npoints; p++) assert_true(used[p]);
  free(used);
}

/* Signed area of a planar cell's corners (shoelace over nodes 0..3 or 0..2). */
static double corner_area(const MicaCellMesh *m, long c) {
  const long *n = m->conn + m->offsets[c];
  const int corners = m->type[c] == MICA_CELL_TRIANGLE ? 3 : 4;
  double area = 0;
  for (int a = 0; a < corners; a++) {
    const double *p = m->x + n[a] * 2, *q = m->x + n[(a + 1) % corners] * 2;
    area += 0.5 * (p[0] * q[1] - q[0] * p[1]);
  }
  return area;
}

/* det of the edges from node 0 to nodes 1, 3, 4 of a hexahedral cell. */
static double hex_corner_volume(const MicaCellMesh *m, long c) {
  const long *n = m->conn + m->offsets[c];
  double e[3][3];
  for (int k = 0; k < 3; k++)
    for (int i = 0; i < 3; i++) e[k][i] = m->x[n[k == 0 ? 1 : k == 1 ? 3 : 4] * 3 + i] - m->x[n[0] * 3 + i];
  return e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
         e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
}

static void test_box(void **state) {
  (void)state;
  MicaDiscretization *d = mapped((MicaShapeSpec){.kind = MICA_SHAPE_BOX, .dim = 2, .upper = {3, 2}}, 4, 3, 1);
  const MicaCellMesh *m = d->mesh;
  assert_non_null(m);
  assert_int_equal(m->npoints, 12);
  assert_int_equal(m->ncells, 6);
  check_structure(m, MICA_CELL_QUAD);
  assert_memory_equal(m->x, d->x, sizeof(double) * 24); /* the points are the particles */
  const long first[4] = {0, 1, 5, 4};
  assert_memory_equal(m->conn, first, sizeof first);
  for (long c = 0; c < m->ncells; c++) assert_true(fabs(corner_area(m, c) - 1.0) < 1e-14);
  mica_discretization_destroy(&d);

  d = mapped((MicaShapeSpec){.kind = MICA_SHAPE_BOX, .dim = 3, .upper = {2, 1, 1}}, 5, 3, 3);
  assert_int_equal(d->mesh->npoints, 45);
  assert_int_equal(d->mesh->ncells, 16);
  check_structure(d->mesh, MICA_CELL_HEXAHEDRON);
  for (long c = 0; c < d->mesh->ncells; c++) assert_true(fabs(hex_corner_volume(d->mesh, c) - 0.125) < 1e-14);
  mica_discretization_destroy(&d);
}

static void test_plate_hole(void **state) {
  (void)state;
  const double a = 1.0, b = 4.0;
  MicaShapeSpec shape = {.kind = MICA_SHAPE_PLATE_HOLE, .hole_radius = a, .plate_size = {b, b}};
  MicaDiscretization *d = mapped(shape, 9, 5, 1);
  const MicaCellMesh *m = d->mesh;
  assert_int_equal(m->ncells, 8 * 4);
  assert_int_equal(m->npoints, 17 * 9);
  check_structure(m, MICA_CELL_BIQUADRATIC_QUAD);
  double area = 0;
  int on_hole = 0;
  for (long c = 0; c < m->ncells; c++) {
    const double A = corner_area(m, c);
    assert_true(A > 0); /* the map reverses orientation; the written cells do not */
    area += A;
    const long *n = m->conn + m->offsets[c];
    for (int a_ = 0; a_ < 9; a_++) {
      const double r = hypot(m->x[n[a_] * 2], m->x[n[a_] * 2 + 1]);
      if (fabs(r - a) < 1e-9) {
        assert_true(fabs(r - a) < 1e-14);
        on_hole++;
      }
    }
  }
  assert_int_equal(on_hole, 8 * 3); /* 8 cells on the hole, two corners and an edge midpoint each */
  const double exact = b * b - PI * a * a / 4;
  assert_true(area > exact && area < 1.001 * exact); /* the corners' chords cut into the hole */
  mica_discretization_destroy(&d);
}

/* An affine hexahedron x = o + A ξ written in VTK's order (reversed when det A < 0 by swapping nodes), checked
 * node by node against its lattice position. */
static void check_affine_cell(int type, int dim, const double *A, int reverse) {
  int lattice[27 * 3];
  const int n = mica_cell_lattice(type, lattice);
  MicaCellMesh *m = NULL;
  check_ok(mica_cell_mesh_create_uniform(dim, n, 1, type, &m));
  for (int a = 0; a < n; a++) {
    m->conn[a] = reverse ? n - 1 - a : a; /* points numbered backwards: the order comes from conn */
    double *x = m->x + m->conn[a] * dim;
    for (int i = 0; i < dim; i++) {
      x[i] = 0.25 * i;
      for (int k = 0; k < dim; k++) x[i] += A[i * dim + k] * 0.5 * lattice[a * 3 + k];
    }
  }
  mica_cell_mesh_orient(m);
  /* now node a sits at o + A' (lattice_a / 2) with A' = A, or A with its first two columns exchanged */
  double det = dim == 2 ? A[0] * A[3] - A[1] * A[2] : 0;
  if (dim == 3)
    det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) + A[2] * (A[3] * A[7] - A[4] * A[6]);
  for (int a = 0; a < n; a++) {
    const double *x = m->x + m->conn[a] * dim;
    for (int i = 0; i < dim; i++) {
      double want = 0.25 * i;
      for (int k = 0; k < dim; k++) {
        const int column = det > 0 || k > 1 ? k : 1 - k;
        want += A[i * dim + column] * 0.5 * lattice[a * 3 + k];
      }
      assert_true(fabs(x[i] - want) < 1e-14);
    }
  }
  mica_cell_mesh_destroy(&m);
}

static void test_lattice_and_orientation(void **state) {
  (void)state;
  const double positive2[4] = {2, 0.5, -0.25, 1}, negative2[4] = {0.5, 2, 1, -0.25};
  const double positive3[9] = {2, 0.5, 0, 0, 1, 0.25, 0.1, 0, 3}, negative3[9] = {0.5, 2, 0, 1, 0, 0.25, 0, 0.1, 3};
  for (int reverse = 0; reverse < 2; reverse++) {
    check_affine_cell(MICA_CELL_BIQUADRATIC_QUAD, 2, positive2, reverse);
    check_affine_cell(MICA_CELL_BIQUADRATIC_QUAD, 2, negative2, reverse);
    check_affine_cell(MICA_CELL_QUAD, 2, negative2, reverse);
    check_affine_cell(MICA_CELL_TRIQUADRATIC_HEXAHEDRON, 3, positive3, reverse);
    check_affine_cell(MICA_CELL_TRIQUADRATIC_HEXAHEDRON, 3, negative3, reverse);
    check_affine_cell(MICA_CELL_HEXAHEDRON, 3, negative3, reverse);
  }
  int lattice[27 * 3];
  assert_int_equal(mica_cell_lattice(MICA_CELL_TRIANGLE, lattice), 0);
  assert_int_equal(mica_cell_nodes(77), 0);
}

static void test_gmsh(void **state) {
  (void)state;
  const char *paths[2] = {"tests/meshes/square_quads.msh", "tests/meshes/box_hex.msh"};
  const int types[2] = {MICA_CELL_QUAD, MICA_CELL_HEXAHEDRON};
  const long ncells[2] = {16, 16};
  for (int k = 0; k < 2; k++) {
    const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = paths[k]};
    const MicaLayoutSpec layout = {0};
    const MicaCellSpec cells = {.order = 2};
    MicaDiscretization *d = NULL;
    check_ok(mica_discretization_create(&shape, &layout, &cells, &d));
    assert_int_equal(d->mesh->ncells, ncells[k]);
    assert_int_equal(d->mesh->npoints, d->nparticles);
    assert_memory_equal(d->mesh->x, d->x, sizeof(double) * (size_t)(d->nparticles * d->dim));
    check_structure(d->mesh, types[k]);
    for (long c = 0; c < d->mesh->ncells; c++)
      assert_true(k == 0 ? corner_area(d->mesh, c) > 0 : hex_corner_volume(d->mesh, c) > 0);
    mica_discretization_destroy(&d);
  }
}

static void test_fe(void **state) {
  (void)state;
  const long count[3] = {5, 3, 1};
  double x[15 * 2];
  for (long j = 0; j < 3; j++)
    for (long i = 0; i < 5; i++) x[(j * 5 + i) * 2] = 0.5 * i, x[(j * 5 + i) * 2 + 1] = 0.5 * j;
  MicaFe *fe = NULL;
  check_ok(mica_fe_create(2, 2, count, 15, x, &fe));
  MicaDiscretization *like = mapped((MicaShapeSpec){.kind = MICA_SHAPE_BOX, .dim = 2, .upper = {2, 1}}, 5, 3, 1);
  MicaDiscretization *d = NULL;
  check_ok(mica_fe_discretize(fe, like, 3, 3, &d));
  assert_int_equal(d->mesh->ncells, 2);
  assert_int_equal(d->mesh->npoints, 15);
  check_structure(d->mesh, MICA_CELL_BIQUADRATIC_QUAD);
  const long first[9] = {0, 2, 12, 10, 1, 7, 11, 5, 6}; /* corners, edge midpoints, centre */
  assert_memory_equal(d->mesh->conn, first, sizeof first);
  mica_discretization_destroy(&d);
  mica_discretization_destroy(&like);
  mica_fe_destroy(&fe);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_box),    cmocka_unit_test(test_plate_hole), cmocka_unit_test(test_lattice_and_orientation),
      cmocka_unit_test(test_gmsh),   cmocka_unit_test(test_fe),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
