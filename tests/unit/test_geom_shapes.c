/* Unit tests of the built-in shapes: maps, background cells, volume and boundary quadrature
 * (src/geom/shapes.c, cells.c, boundary.c, discretization.c).
 *
 * For every shape (2-D and 3-D box, Cook's polygon, plate with a hole (square and oblong), annulus sector,
 * cylinder):
 *   - Σ qw equals the exact area/volume (1e-14 relative where the map is polynomial (box, polygon) or
 *     its Jacobian is (annulus); 1e-12 for the plate and cylinder with enough cells and points, which
 *     converge exponentially with the order: measured errors in the comments);
 *   - each set's length/area is exact; the divergence theorem holds: Σ over all sets of w (x·n) = dim × V,
 *     and Σ w n = 0 over the closed boundary;
 *   - normals are unit vectors pointing out (checked against the known normal of each set);
 *   - set structure: elements and vertices counted, element vertices in range, lambda_N a partition of
 *     unity with nonnegative values, vertices on their set, and (affine maps) Σ λ_a x_a = x.
 * Errors (MICA_ERR_INPUT): counts < 2, order < 1, a clockwise or non-convex polygon, a hole as large as
 * the plate, an odd cell count along the plate's hole, an empty box, a full-circle annulus.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/geom.h"

#define PI 3.14159265358979323846

/* ---- helpers ---- */

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static void check_error(int ierr, int expected, const char *fragment) {
  if (ierr != expected || !strstr(mica_error_message(), fragment)) {
    print_error("expected error %d mentioning '%s', got %d (%s)\n", expected, fragment, ierr,
                mica_error_message());
    fail();
  }
  mica_error_clear();
}

static void assert_rel(double got, double want, double rtol, const char *what) {
  const double err = fabs(got - want) / fabs(want);
  if (!(err <= rtol)) {
    print_error("%s: got %.17g, want %.17g (relative error %.3g > %.1g)\n", what, got, want, err, rtol);
    fail();
  }
}

static MicaLayoutSpec regular(long n0, long n1, long n2) {
  return (MicaLayoutSpec){.kind = MICA_LAYOUT_REGULAR, .count = {n0, n1, n2}, .grading = {1, 1, 1}};
}

static MicaCellSpec gauss(int order) { return (MicaCellSpec){.order = order}; }

static MicaDiscretization *create(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                                  const MicaCellSpec *cells) {
  MicaDiscretization *disc = NULL;
  check_ok(mica_discretization_create(shape, layout, cells, &disc));
  assert_non_null(disc);
  return disc;
}

static const MicaBoundarySet *set_named(const MicaDiscretization *disc, const char *name) {
  const int s = mica_discretization_find_set(disc, name);
  if (s < 0) {
    char names[256];
    mica_discretization_set_names(disc, names, sizeof names);
    print_error("no set '%s' (sets: %s)\n", name, names);
    fail();
  }
  return &disc->sets[s];
}

static double set_measure(const MicaBoundarySet *set) {
  double m = 0.0;
  for (long q = 0; q < set->n; q++) m += set->w[q];
  return m;
}

static double boundary_measure(const MicaDiscretization *disc) {
  double m = 0.0;
  for (int s = 0; s < disc->nsets; s++) m += set_measure(&disc->sets[s]);
  return m;
}

static void check_volume(const MicaDiscretization *disc, double exact, double rtol) {
  double sum = 0.0;
  for (long q = 0; q < disc->nquad; q++) {
    assert_true(disc->qw[q] > 0);
    sum += disc->qw[q];
  }
  assert_rel(sum, exact, rtol, "Σ qw");
  assert_rel(disc->volume, exact, rtol, "disc->volume");
}

/* Σ w (x·n) = dim V over the whole boundary, and Σ w n = 0 (relative to the boundary's measure). */
static void check_divergence(const MicaDiscretization *disc, double rtol) {
  const int dim = disc->dim;
  double flux = 0.0, net[3] = {0, 0, 0};
  for (int s = 0; s < disc->nsets; s++) {
    const MicaBoundarySet *set = &disc->sets[s];
    for (long q = 0; q < set->n; q++)
      for (int d = 0; d < dim; d++) {
        flux += set->w[q] * set->x[q * dim + d] * set->normal[q * dim + d];
        net[d] += set->w[q] * set->normal[q * dim + d];
      }
  }
  assert_rel(flux, dim * disc->volume, rtol, "Σ w x·n / dim V");
  for (int d = 0; d < dim; d++)
    if (fabs(net[d]) > rtol * boundary_measure(disc)) {
      print_error("Σ w n_%d = %.3g over a closed boundary of measure %.6g\n", d, net[d],
                  boundary_measure(disc));
      fail();
    }
}

/* Unit normals equal to want (or, with radial != 0, to ±(x − c)/|x − c| in the xy-plane). */
static void check_normals(const MicaDiscretization *disc, const char *name, const double *want, double tol) {
  const MicaBoundarySet *set = set_named(disc, name);
  const int dim = disc->dim;
  for (long q = 0; q < set->n; q++)
    for (int d = 0; d < dim; d++)
      if (fabs(set->normal[q * dim + d] - want[d]) > tol) {
        print_error("set %s point %ld: normal[%d] = %.17g, want %.17g\n", name, q, d,
                    set->normal[q * dim + d], want[d]);
        fail();
      }
}

/* Normal = sign × (x, y, 0)/|(x, y)|: radial sets (hole, annulus arcs, cylinder side). */
static void check_radial_normals(const MicaDiscretization *disc, const char *name, double sign, double tol) {
  const MicaBoundarySet *set = set_named(disc, name);
  const int dim = disc->dim;
  for (long q = 0; q < set->n; q++) {
    const double *x = &set->x[q * dim], *n = &set->normal[q * dim], r = hypot(x[0], x[1]);
    double err = fabs(n[0] - sign * x[0] / r) + fabs(n[1] - sign * x[1] / r);
    if (dim == 3) err += fabs(n[2]);
    if (err > tol) {
      print_error("set %s point %ld: normal (%g, %g) is not %+g × radial at (%g, %g)\n", name, q, n[0], n[1],
                  sign, x[0], x[1]);
      fail();
    }
  }
}

/* Structure of every set: sizes, indices in range, normals of unit length, lambda a partition of unity. */
static void check_structure(const MicaDiscretization *disc) {
  const int dim = disc->dim;
  for (int s = 0; s < disc->nsets; s++) {
    const MicaBoundarySet *set = &disc->sets[s];
    assert_int_equal(set->element_size, dim == 2 ? 2 : 4);
    assert_true(set->nelements > 0 && set->nvertices > 0 && set->n > 0);
    for (long k = 0; k < set->nelements * set->element_size; k++)
      assert_true(set->element_vertices[k] >= 0 && set->element_vertices[k] < set->nvertices);
    for (long q = 0; q < set->n; q++) {
      double len = 0.0, sum = 0.0;
      for (int d = 0; d < dim; d++) len += set->normal[q * dim + d] * set->normal[q * dim + d];
      assert_true(fabs(sqrt(len) - 1.0) < 1e-14);
      assert_true(set->w[q] > 0);
      assert_true(set->element[q] >= 0 && set->element[q] < set->nelements);
      for (int a = 0; a < 4; a++) {
        assert_true(set->lambda_N[q * 4 + a] >= 0.0);
        sum += set->lambda_N[q * 4 + a];
      }
      assert_true(fabs(sum - 1.0) < 1e-14);
    }
  }
}

/* For affine maps the boundary points interpolate linearly between their element's vertices. */
static void check_vertex_interpolation(const MicaDiscretization *disc) {
  const int dim = disc->dim;
  for (int s = 0; s < disc->nsets; s++) {
    const MicaBoundarySet *set = &disc->sets[s];
    for (long q = 0; q < set->n; q++) {
      const long *ev = &set->element_vertices[set->element[q] * set->element_size];
      for (int d = 0; d < dim; d++) {
        double x = 0.0;
        for (int a = 0; a < set->element_size; a++)
          x += set->lambda_N[q * 4 + a] * set->vertex_x[ev[a] * dim + d];
        assert_true(fabs(x - set->x[q * dim + d]) < 1e-12);
      }
    }
  }
}

/* ---- box ---- */

static MicaShapeSpec box2(void) {
  return (MicaShapeSpec){.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, 0}, .upper = {3, 2}};
}

static void test_box_2d(void **state) {
  (void)state;
  const MicaShapeSpec shape = box2();
  const MicaLayoutSpec layout = regular(5, 4, 0);
  const MicaCellSpec cells = gauss(2);
  MicaDiscretization *disc = create(&shape, &layout, &cells);
  assert_int_equal(disc->dim, 2);
  assert_int_equal(disc->nparticles, 20);
  assert_int_equal(disc->ncells, 12);
  assert_int_equal(disc->nquad, 48);
  assert_int_equal(disc->nsets, 4);
  char names[128];
  mica_discretization_set_names(disc, names, sizeof names);
  assert_string_equal(names, "left, right, bottom, top");
  assert_int_equal(mica_discretization_find_set(disc, "hole"), -1);
  check_volume(disc, 8.0, 1e-14);
  assert_rel(set_measure(set_named(disc, "left")), 2.0, 1e-14, "left");
  assert_rel(set_measure(set_named(disc, "right")), 2.0, 1e-14, "right");
  assert_rel(set_measure(set_named(disc, "bottom")), 4.0, 1e-14, "bottom");
  assert_rel(set_measure(set_named(disc, "top")), 4.0, 1e-14, "top");
  check_normals(disc, "left", (double[]){-1, 0}, 1e-15);
  check_normals(disc, "right", (double[]){1, 0}, 1e-15);
  check_normals(disc, "bottom", (double[]){0, -1}, 1e-15);
  check_normals(disc, "top", (double[]){0, 1}, 1e-15);
  check_divergence(disc, 1e-14);
  check_structure(disc);
  check_vertex_interpolation(disc);
  const MicaBoundarySet *bottom = set_named(disc, "bottom");
  assert_int_equal(bottom->nelements, 4);
  assert_int_equal(bottom->nvertices, 5);
  assert_int_equal(bottom->n, 8);
  mica_discretization_destroy(&disc);
  assert_null(disc);
}

static void test_box_3d(void **state) {
  (void)state;
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {2, 1, 3}};
  const MicaLayoutSpec layout = regular(3, 4, 5);
  const MicaCellSpec cells = {.order = 2, .boundary_order = 3};
  MicaDiscretization *disc = create(&shape, &layout, &cells);
  assert_int_equal(disc->nparticles, 60);
  assert_int_equal(disc->ncells, 2 * 3 * 4);
  assert_int_equal(disc->nsets, 6);
  check_volume(disc, 6.0, 1e-14);
  const char *names[6] = {"left", "right", "bottom", "top", "back", "front"};
  const double areas[6] = {3, 3, 6, 6, 2, 2};
  for (int s = 0; s < 6; s++) {
    assert_rel(set_measure(set_named(disc, names[s])), areas[s], 1e-14, names[s]);
    double n[3] = {0, 0, 0};
    n[s / 2] = s % 2 ? 1.0 : -1.0;
    check_normals(disc, names[s], n, 1e-15);
  }
  check_divergence(disc, 1e-14);
  check_structure(disc);
  check_vertex_interpolation(disc);
  const MicaBoundarySet *left = set_named(disc, "left");
  assert_int_equal(left->nelements, 3 * 4);
  assert_int_equal(left->nvertices, 4 * 5);
  assert_int_equal(left->n, 3 * 4 * 9);
  mica_discretization_destroy(&disc);
}

/* Explicit cell counts: cells need not follow the particles. */
static void test_box_cell_count(void **state) {
  (void)state;
  const MicaShapeSpec shape = box2();
  const MicaLayoutSpec layout = regular(5, 4, 0);
  const MicaCellSpec cells = {.count = {7, 2}, .order = 3, .boundary_order = 1};
  MicaDiscretization *disc = create(&shape, &layout, &cells);
  assert_int_equal(disc->ncells, 14);
  assert_int_equal(disc->nquad, 14 * 9);
  assert_int_equal(set_named(disc, "top")->nelements, 7);
  assert_int_equal(set_named(disc, "top")->n, 7);
  check_volume(disc, 8.0, 1e-14);
  check_divergence(disc, 1e-14);
  mica_discretization_destroy(&disc);
}

/* ---- polygon: Cook's membrane ---- */

static MicaShapeSpec cook(void) {
  return (MicaShapeSpec){
      .kind = MICA_SHAPE_POLYGON, .dim = 2, .vertices = {{0, 0}, {48, 44}, {48, 60}, {0, 44}}};
}

static void test_polygon_cook(void **state) {
  (void)state;
  const MicaShapeSpec shape = cook();
  const MicaLayoutSpec layout = regular(9, 7, 0);
  const MicaCellSpec cells = gauss(2);
  MicaDiscretization *disc = create(&shape, &layout, &cells);
  check_volume(disc, 48.0 * (44.0 + 16.0) / 2.0, 1e-14); /* 1440 */
  assert_rel(set_measure(set_named(disc, "bottom")), hypot(48, 44), 1e-14, "bottom");
  assert_rel(set_measure(set_named(disc, "right")), 16.0, 1e-14, "right");
  assert_rel(set_measure(set_named(disc, "top")), hypot(48, 16), 1e-14, "top");
  assert_rel(set_measure(set_named(disc, "left")), 44.0, 1e-14, "left");
  check_normals(disc, "right", (double[]){1, 0}, 1e-15);
  check_normals(disc, "left", (double[]){-1, 0}, 1e-15);
  check_normals(disc, "bottom", (double[]){44 / hypot(48, 44), -48 / hypot(48, 44)}, 1e-15);
  check_normals(disc, "top", (double[]){-16 / hypot(48, 16), 48 / hypot(48, 16)}, 1e-15);
  check_divergence(disc, 1e-14);
  check_structure(disc);
  check_vertex_interpolation(disc); /* the map is linear along each side */
  /* the particle at parameter (1, 1) is the vertex (48, 60) */
  const double *corner = &disc->x[(9 * 7 - 1) * 2];
  assert_true(fabs(corner[0] - 48) < 1e-13 && fabs(corner[1] - 60) < 1e-13);
  mica_discretization_destroy(&disc);
}

static void test_polygon_errors(void **state) {
  (void)state;
  MicaDiscretization *disc = NULL;
  const MicaLayoutSpec layout = regular(3, 3, 0);
  const MicaCellSpec cells = gauss(2);
  {
    MicaShapeSpec s = cook();
    const double v[4][2] = {{0, 0}, {0, 44}, {48, 60}, {48, 44}}; /* clockwise */
    memcpy(s.vertices, v, sizeof v);
    check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "counterclockwise");
  }
  {
    MicaShapeSpec s = cook();
    s.vertices[2][0] = 10, s.vertices[2][1] = 20; /* a dent: not convex */
    check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "convex");
  }
  {
    MicaShapeSpec s = cook();
    s.vertices[2][0] = 48, s.vertices[2][1] = 44; /* three vertices on a line */
    s.vertices[1][1] = 44;
    check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "convex");
  }
  assert_null(disc);
}

/* ---- plate with a hole ---- */

static MicaShapeSpec plate(double a, double bx, double by) {
  return (MicaShapeSpec){.kind = MICA_SHAPE_PLATE_HOLE, .dim = 2, .hole_radius = a, .plate_size = {bx, by}};
}

static void plate_case(double a, double bx, double by, long n0, long n1, int order, double rtol) {
  const MicaShapeSpec shape = plate(a, bx, by);
  const MicaLayoutSpec layout = regular(n0, n1, 0);
  const MicaCellSpec cells = gauss(order);
  MicaDiscretization *disc = create(&shape, &layout, &cells);
  check_volume(disc, bx * by - PI * a * a / 4.0, rtol);
  assert_rel(set_measure(set_named(disc, "hole")), PI * a / 2.0, 1e-13, "hole length");
  assert_rel(set_measure(set_named(disc, "right")), by, 1e-14, "right");
  assert_rel(set_measure(set_named(disc, "top")), bx, 1e-14, "top");
  assert_rel(set_measure(set_named(disc, "bottom")), bx - a, 1e-14, "bottom");
  assert_rel(set_measure(set_named(disc, "left")), by - a, 1e-14, "left");
  check_normals(disc, "right", (double[]){1, 0}, 1e-15);
  check_normals(disc, "top", (double[]){0, 1}, 1e-15);
  check_normals(disc, "bottom", (double[]){0, -1}, 1e-15);
  check_normals(disc, "left", (double[]){-1, 0}, 1e-15);
  check_radial_normals(disc, "hole", -1.0, 1e-14);
  check_divergence(disc, rtol);
  check_structure(disc);
  /* the right and top sets meet at the corner: each has it as a vertex */
  const MicaBoundarySet *right = set_named(disc, "right"), *top = set_named(disc, "top");
  int found = 0;
  for (long v = 0; v < right->nvertices; v++)
    found += fabs(right->vertex_x[2 * v] - bx) < 1e-14 && fabs(right->vertex_x[2 * v + 1] - by) < 1e-14;
  for (long v = 0; v < top->nvertices; v++)
    found += fabs(top->vertex_x[2 * v] - bx) < 1e-14 && fabs(top->vertex_x[2 * v + 1] - by) < 1e-14;
  assert_int_equal(found, 2);
  assert_int_equal(right->nelements, (n0 - 1) / 2);
  mica_discretization_destroy(&disc);
}

static void test_plate_hole(void **state) {
  (void)state;
  /* measured relative area errors with 16×8 cells: order 1 1.5e-4, 2 1.6e-8, 3 5e-13, 4 and up ≈ 2e-15 */
  plate_case(1.0, 5.0, 5.0, 17, 9, 6, 1e-12);
  plate_case(0.5, 4.0, 1.0, 21, 5, 6, 1e-12);
  plate_case(0.99, 1.0, 1.0, 9, 3, 8, 1e-10); /* hole nearly as large as the plate */
}

/* The area converges with the Gauss order (the map is trigonometric along the hole). */
static void test_plate_convergence(void **state) {
  (void)state;
  const MicaShapeSpec shape = plate(1.0, 5.0, 5.0);
  const MicaLayoutSpec layout = regular(9, 5, 0);
  double previous = INFINITY;
  const double exact = 25.0 - PI / 4.0;
  for (int order = 1; order <= 5; order++) {
    const MicaCellSpec cells = gauss(order);
    MicaDiscretization *disc = create(&shape, &layout, &cells);
    const double err = fabs(disc->volume - exact) / exact;
    assert_true(err < previous || err < 1e-14);
    previous = err;
    mica_discretization_destroy(&disc);
  }
  assert_true(previous < 1e-8);
}

static void test_plate_errors(void **state) {
  (void)state;
  MicaDiscretization *disc = NULL;
  const MicaCellSpec cells = gauss(2);
  const MicaLayoutSpec layout = regular(9, 5, 0);
  MicaShapeSpec s = plate(5.0, 5.0, 6.0);
  check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "hole radius");
  s = plate(-1.0, 5.0, 5.0);
  check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "hole radius");
  s = plate(1.0, 0.0, 5.0);
  check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "plate size");
  /* 8 particles → 7 cells along the hole: no cell edge at the corner */
  s = plate(1.0, 5.0, 5.0);
  const MicaLayoutSpec even = regular(8, 5, 0);
  check_error(mica_discretization_create(&s, &even, &cells, &disc), MICA_ERR_INPUT, "kink");
  /* but 8 particles with 6 cells is fine */
  const MicaCellSpec six = {.count = {6, 0}, .order = 2};
  disc = create(&s, &even, &six);
  check_divergence(disc, 1e-6);
  mica_discretization_destroy(&disc);
  assert_null(disc);
}

/* ---- annulus sector ---- */

static void test_annulus(void **state) {
  (void)state;
  const double ri = 1.0, ro = 2.5, t0 = 0.3, t1 = 2.0, dt = t1 - t0;
  const MicaShapeSpec shape = {
      .kind = MICA_SHAPE_ANNULUS, .dim = 2, .r_inner = ri, .r_outer = ro, .theta0 = t0, .theta1 = t1};
  const MicaLayoutSpec layout = regular(4, 7, 0);
  /* the area and x·n are exact with any order; Σ w n over the arcs converges: 1e-6 with 2 points per edge */
  const MicaCellSpec cells = {.order = 2, .boundary_order = 6};
  MicaDiscretization *disc = create(&shape, &layout, &cells);
  check_volume(disc, 0.5 * dt * (ro * ro - ri * ri), 1e-14);
  assert_rel(set_measure(set_named(disc, "inner")), ri * dt, 1e-14, "inner");
  assert_rel(set_measure(set_named(disc, "outer")), ro * dt, 1e-14, "outer");
  assert_rel(set_measure(set_named(disc, "start")), ro - ri, 1e-14, "start");
  assert_rel(set_measure(set_named(disc, "end")), ro - ri, 1e-14, "end");
  check_radial_normals(disc, "inner", -1.0, 1e-14);
  check_radial_normals(disc, "outer", 1.0, 1e-14);
  check_normals(disc, "start", (double[]){sin(t0), -cos(t0)}, 1e-15);
  check_normals(disc, "end", (double[]){-sin(t1), cos(t1)}, 1e-15);
  check_divergence(disc, 1e-14);
  check_structure(disc);
  mica_discretization_destroy(&disc);
}

static void test_annulus_errors(void **state) {
  (void)state;
  MicaDiscretization *disc = NULL;
  const MicaLayoutSpec layout = regular(3, 3, 0);
  const MicaCellSpec cells = gauss(2);
  MicaShapeSpec s = {.kind = MICA_SHAPE_ANNULUS, .r_inner = 1, .r_outer = 2, .theta0 = 0, .theta1 = 2 * PI};
  check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "theta1");
  s.theta1 = 1.0, s.r_inner = 0.0;
  check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "r_inner");
  s.r_inner = 3.0;
  check_error(mica_discretization_create(&s, &layout, &cells, &disc), MICA_ERR_INPUT, "r_outer");
}

/* ---- cylinder ---- */

static void cylinder_case(long n, int order, double rtol) {
  const double R = 2.0, H = 3.0;
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_CYLINDER, .dim = 3, .radius = R, .height = H};
  const MicaLayoutSpec layout = regular(n, n, 3);
  const MicaCellSpec cells = gauss(order);
  MicaDiscretization *disc = create(&shape, &layout, &cells);
  assert_int_equal(disc->nsets, 3);
  check_volume(disc, PI * R * R * H, rtol);
  assert_rel(set_measure(set_named(disc, "side")), 2 * PI * R * H, rtol, "side");
  assert_rel(set_measure(set_named(disc, "bottom")), PI * R * R, rtol, "bottom");
  assert_rel(set_measure(set_named(disc, "top")), PI * R * R, rtol, "top");
  check_normals(disc, "bottom", (double[]){0, 0, -1}, 1e-15);
  check_normals(disc, "top", (double[]){0, 0, 1}, 1e-15);
  check_radial_normals(disc, "side", 1.0, 1e-13);
  check_divergence(disc, rtol);
  check_structure(disc);
  /* the side's vertices: 4 (n − 1) around × 3 levels, shared where the square's faces meet */
  const MicaBoundarySet *side = set_named(disc, "side");
  assert_int_equal(side->nvertices, 4 * (n - 1) * 3);
  assert_int_equal(side->nelements, 4 * (n - 1) * 2);
  for (long v = 0; v < side->nvertices; v++)
    assert_true(fabs(hypot(side->vertex_x[3 * v], side->vertex_x[3 * v + 1]) - R) < 1e-14);
  mica_discretization_destroy(&disc);
}

static void test_cylinder(void **state) {
  (void)state;
  /* measured relative volume errors (side area alike): 4×4 cells in the disk: order 2 2.9e-4, 4 2.2e-7,
   * 6 2.4e-10, 8 3.1e-13; 9×9 cells: order 4 4.1e-10, 6 3.1e-14, 8 6.6e-15 */
  cylinder_case(10, 8, 1e-12);
  cylinder_case(5, 4, 1e-6);
}

/* ---- generic errors ---- */

static void test_size_errors(void **state) {
  (void)state;
  MicaDiscretization *disc = NULL;
  const MicaShapeSpec shape = box2();
  const MicaCellSpec cells = gauss(2);
  MicaLayoutSpec layout = regular(1, 4, 0);
  check_error(mica_discretization_create(&shape, &layout, &cells, &disc), MICA_ERR_INPUT, "count[0]");
  layout = regular(4, 4, 0);
  const MicaCellSpec zero = gauss(0);
  check_error(mica_discretization_create(&shape, &layout, &zero, &disc), MICA_ERR_INPUT, "order");
  const MicaCellSpec negative_cells = {.count = {-1, 0}, .order = 2};
  check_error(mica_discretization_create(&shape, &layout, &negative_cells, &disc), MICA_ERR_INPUT, "cells");
  MicaShapeSpec flat = box2();
  flat.upper[1] = flat.lower[1];
  check_error(mica_discretization_create(&flat, &layout, &cells, &disc), MICA_ERR_INPUT, "upper[1]");
  MicaShapeSpec four_d = box2();
  four_d.dim = 4;
  check_error(mica_discretization_create(&four_d, &layout, &cells, &disc), MICA_ERR_INPUT, "dimension");
  const MicaShapeSpec cyl = {.kind = MICA_SHAPE_CYLINDER, .radius = 1, .height = 0};
  layout = regular(3, 3, 3);
  check_error(mica_discretization_create(&cyl, &layout, &cells, &disc), MICA_ERR_INPUT, "height");
  assert_null(disc);
  assert_int_equal(mica_discretization_destroy(&disc), MICA_SUCCESS);
  assert_int_equal(mica_discretization_destroy(NULL), MICA_SUCCESS);
}

static void test_set_names_truncate(void **state) {
  (void)state;
  const MicaShapeSpec shape = box2();
  const MicaLayoutSpec layout = regular(3, 3, 0);
  const MicaCellSpec cells = gauss(1);
  MicaDiscretization *disc = create(&shape, &layout, &cells);
  char small[8];
  mica_discretization_set_names(disc, small, sizeof small);
  assert_string_equal(small, "left, r");
  mica_discretization_destroy(&disc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_box_2d),
      cmocka_unit_test(test_box_3d),
      cmocka_unit_test(test_box_cell_count),
      cmocka_unit_test(test_polygon_cook),
      cmocka_unit_test(test_polygon_errors),
      cmocka_unit_test(test_plate_hole),
      cmocka_unit_test(test_plate_convergence),
      cmocka_unit_test(test_plate_errors),
      cmocka_unit_test(test_annulus),
      cmocka_unit_test(test_annulus_errors),
      cmocka_unit_test(test_cylinder),
      cmocka_unit_test(test_size_errors),
      cmocka_unit_test(test_set_names_truncate),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
