/* Unit tests of the Gmsh reader and mesh discretization (src/geom/gmsh*.c, src/geom/mesh.c), on the shipped
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
 *   - the same mesh in every form gives the same discretization (particles, volume points and weights, sets
 *     with their points, weights, normals and elements, in the same order): 4.1 ASCII, 2.2 ASCII, 4.1 binary
 *     and the .geo meshed by the Gmsh library, for the square, the plate with a hole, the hexahedral box (and
 *     the OpenCASCADE cube, .msh and .geo). Binary files and the library hold Gmsh's doubles exactly: equal
 *     bit for bit; ASCII files print 16 digits: within 1e-14 of the largest value of each array (measured:
 *     2.2 and 4.1 ASCII bit for bit alike, ASCII against binary at most 3.1e-15). A 2.2 file
 *     lists an element once per physical group: the copies are merged (square_groups). geometry.mesh_size_factor
 *     2 on plate_hole.geo equals `gmsh -2 -clscale 2` (plate_hole_clscale2.msh), bit for bit. Entities out of
 *     tag order and a repeated entity tag (square_groups_shuffled) change nothing: the first entity read counts.
 *   - errors, each MICA_ERR_INPUT naming file:LINE: truncated file (inside a section, and between sections:
 *     a missing $Elements), version 4.0, second-order elements (with the remedy gmsh -order 1), an undefined
 *     node in an element, a node tag outside the header's range, not a mesh at all, a missing file; binary:
 *     truncated inside $Nodes and $Elements, the byte-order integer of the other byte order or damaged, data
 *     size 4, a binary 2.2 file; .geo: Gmsh's syntax error with its file:LINE, no surface, second order, a
 *     physical curve but no physical surface (Gmsh would save no 2-D element). The .geo after the syntax
 *     error is read cleanly: with General.AbortOnError = 2 Gmsh's parser kept the broken file's input and
 *     every later .geo of the process failed with "line 0: syntax error".
 *   - a .geo that would run a shell command, run a program, end the process or write files is refused with
 *     file:LINE before Gmsh runs it (SystemCall "touch pwned" creates no file), also inside an Included file;
 *     the same words in comments, strings, option names and variables are not refused.
 *   - parts (src/geom/mesh_part.c, parallel.data = "distributed"): plate_hole.msh and cube.msh cut into three
 *     parts by their elements' centroids (x below 1/3, 2/3 of the extent): the parts' volume points and weights,
 *     every set's points, weights and outward normals (the divergence theorem over the union), output cells and
 *     uncovered-face counts (also square_quads_open's, which are not 0) add up to the whole mesh's (1e-13); every
 *     part names every set; a part's boundary
 *     vertex keeps its node's index in the whole mesh (the whole set's vertex with that key sits at the same
 *     coordinates); the whole mesh's particles are the discretization's, in its order.
 *   - a source (mesh_part.c, read in passes through a filter): its first pass names every set of the whole mesh
 *     (also of a 2.2 file, whose groups live on its elements) in the same order, gives the dimension, the nodes'
 *     bounding box and a sample of node coordinates; a region covering the body has the whole mesh's particles
 *     (coordinates and keys) and discretization (volume, sets' measures); a region of a box holds only particles
 *     in it, each with its key's whole particle's coordinates, and the particles of the two halves of a cut (with a
 *     margin) cover the whole mesh's — for 4.1 ASCII and binary, 2.2, hexahedra and the .geo (cut in memory).
 *   - 3000 random byte changes of a binary, a 2.2 and a 4.1 ASCII file each either load or fail with
 *     MICA_ERR_INPUT (under `make test SAN=1`: without an out-of-bounds access or a leak).
 */
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
#include "mica/random.h"

#define PI 3.14159265358979323846

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static MicaDiscretization *load_scaled(const char *path, double size_factor, int order, int boundary_order) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = path, .mesh_size_factor = size_factor};
  const MicaLayoutSpec layout = {0};
  const MicaCellSpec cells = {.order = order, .boundary_order = boundary_order};
  MicaDiscretization *disc = NULL;
  check_ok(mica_discretization_create(&shape, &layout, &cells, &disc));
  return disc;
}

static MicaDiscretization *load(const char *path, int order, int boundary_order) {
  return load_scaled(path, 0, order, boundary_order);
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

/* ---- every form of a mesh gives the same discretization ---- */

static double worst; /* the largest relative difference seen in assert_close */

/* |a − b| ≤ rtol max |a| for n values; rtol = 0: bit for bit. */
static void assert_close(const double *a, const double *b, long n, double rtol, const char *what) {
  double scale = 0;
  for (long i = 0; i < n; i++) scale = fmax(scale, fabs(a[i]));
  for (long i = 0; i < n; i++) {
    worst = fmax(worst, fabs(a[i] - b[i]) / scale);
    if (!(fabs(a[i] - b[i]) <= rtol * scale) && !(rtol == 0 && a[i] == b[i])) {
      print_error("%s[%ld]: %.17g against %.17g (tolerance %g relative to %g)\n", what, i, a[i], b[i], rtol, scale);
      fail();
    }
  }
}

static void assert_same_set(const MicaBoundarySet *a, const MicaBoundarySet *b, int dim, double tol) {
  assert_string_equal(a->name, b->name);
  assert_int_equal(a->n, b->n);
  assert_int_equal(a->nelements, b->nelements);
  assert_int_equal(a->element_size, b->element_size);
  assert_int_equal(a->nvertices, b->nvertices);
  assert_close(a->x, b->x, a->n * dim, tol, "set x");
  assert_close(a->w, b->w, a->n, tol, "set w");
  assert_close(a->normal, b->normal, a->n * dim, tol, "set normal");
  assert_close(a->vertex_x, b->vertex_x, a->nvertices * dim, tol, "set vertex_x");
  assert_memory_equal(a->element_vertices, b->element_vertices,
                      sizeof(long) * (size_t)(a->nelements * a->element_size));
  assert_memory_equal(a->element, b->element, sizeof(long) * (size_t)a->n);
}

/* b (another file, or the .geo) against the reference a, in the same order. */
static void assert_same(const MicaDiscretization *a, const MicaDiscretization *b, double tol) {
  const int dim = a->dim;
  assert_int_equal(a->dim, b->dim);
  assert_int_equal(a->nparticles, b->nparticles);
  assert_int_equal(a->ncells, b->ncells);
  assert_int_equal(a->nquad, b->nquad);
  assert_int_equal(a->nsets, b->nsets);
  assert_int_equal(a->boundary_uncovered, b->boundary_uncovered);
  assert_close(a->x, b->x, a->nparticles * dim, tol, "particles");
  assert_close(a->qx, b->qx, a->nquad * dim, tol, "qx");
  assert_close(a->qw, b->qw, a->nquad, tol, "qw");
  assert_close(&a->volume, &b->volume, 1, tol, "volume");
  for (int s = 0; s < a->nsets; s++) assert_same_set(&a->sets[s], &b->sets[s], dim, tol);
}

/* forms[0] is the 4.1 ASCII reference; exact[i]: form i holds Gmsh's doubles (binary, .geo) */
static void check_forms(const char *const *forms, const int *exact, int n) {
  MicaDiscretization *ref = load(forms[0], 2, 2), *first_exact = NULL;
  for (int i = 1; i < n; i++) {
    MicaDiscretization *d = load(forms[i], 2, 2);
    worst = 0;
    assert_same(ref, d, 1e-14);
    print_message("%s against %s: largest relative difference %.2g\n", forms[i], forms[0], worst);
    if (exact[i] && first_exact) assert_same(first_exact, d, 0);
    if (exact[i] && !first_exact)
      first_exact = d;
    else
      mica_discretization_destroy(&d);
  }
  mica_discretization_destroy(&first_exact);
  mica_discretization_destroy(&ref);
}

static void test_forms_agree(void **state) {
  (void)state;
  const int exact[4] = {0, 0, 1, 1};
  check_forms((const char *[]){"tests/meshes/square_quads.msh", "tests/meshes/square_v22.msh",
                               "tests/meshes/square_binary.msh", "tests/meshes/square_quads.geo"},
              exact, 4);
  check_forms((const char *[]){"input/meshes/plate_hole.msh", "tests/meshes/plate_hole_v22.msh",
                               "tests/meshes/plate_hole_binary.msh", "input/meshes/plate_hole.geo"},
              exact, 4);
  check_forms((const char *[]){"tests/meshes/box_hex.msh", "tests/meshes/box_hex_v22.msh",
                               "tests/meshes/box_hex_binary.msh", "tests/meshes/box_hex.geo"},
              exact, 4);
  check_forms((const char *[]){"input/meshes/cube.msh", "input/meshes/cube.geo"}, (const int[]){0, 1}, 2);
}

static void test_groups_merged(void **state) {
  (void)state;
  MicaDiscretization *ref = load("tests/meshes/square_groups.msh", 2, 2);
  MicaDiscretization *v22 = load("tests/meshes/square_groups_v22.msh", 2, 2);
  assert_same(ref, v22, 1e-15);
  assert_int_equal(v22->ncells, 16);
  assert_rel(v22->volume, 1.0, 1e-13, "area (one copy of each quadrangle)");
  char names[128];
  mica_discretization_set_names(v22, names, sizeof names);
  assert_string_equal(names, "bottom, right, top, left, sides");
  assert_rel(set_measure(set_named(v22, "sides")), 2.0, 1e-13, "sides = left + right");
  assert_rel(set_measure(set_named(v22, "left")), 1.0, 1e-13, "left");
  mica_discretization_destroy(&v22);
  mica_discretization_destroy(&ref);
}

/* The entity lookup is a binary search over the entities sorted by tag: entities listed out of tag order, and a
 * second entity of a tag already read (the first one read counts, as the scan before it did), give the same
 * discretization, bit for bit, as the file in order. */
static void test_entity_order(void **state) {
  (void)state;
  MicaDiscretization *ref = load("tests/meshes/square_groups.msh", 2, 2);
  MicaDiscretization *shuffled = load("tests/meshes/square_groups_shuffled.msh", 2, 2);
  assert_same(ref, shuffled, 0);
  assert_rel(set_measure(set_named(shuffled, "left")), 1.0, 1e-13, "left (not also bottom)");
  assert_rel(set_measure(set_named(shuffled, "bottom")), 1.0, 1e-13, "bottom (not in left)");
  mica_discretization_destroy(&shuffled);
  mica_discretization_destroy(&ref);
}

static void test_size_factor(void **state) {
  (void)state;
  MicaDiscretization *cli = load("tests/meshes/plate_hole_clscale2.msh", 2, 2);
  MicaDiscretization *geo = load_scaled("input/meshes/plate_hole.geo", 2.0, 2, 2);
  MicaDiscretization *fine = load("input/meshes/plate_hole.msh", 2, 2);
  assert_same(cli, geo, 1e-14);
  assert_int_equal(geo->nparticles, 119);
  assert_true(geo->nparticles < fine->nparticles / 2);
  mica_discretization_destroy(&cli);
  mica_discretization_destroy(&geo);
  mica_discretization_destroy(&fine);
}

/* ---- files written for a test, in a fresh directory ---- */

typedef struct {
  char dir[64];
  char path[256];
} Scratch;

static const char *scratch_write(Scratch *s, const char *name, const void *data, size_t n) {
  snprintf(s->path, sizeof s->path, "%s/%s", s->dir, name);
  FILE *f = fopen(s->path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(data, 1, n, f), n);
  fclose(f);
  return s->path;
}

static const char *scratch_text(Scratch *s, const char *name, const char *text) {
  return scratch_write(s, name, text, strlen(text));
}

static char *slurp(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  fseek(f, 0, SEEK_END);
  *n = (size_t)ftell(f);
  rewind(f);
  char *buf = malloc(*n + 1);
  assert_int_equal(fread(buf, 1, *n, f), *n);
  fclose(f);
  return buf;
}

/* The first `text` in buf[0, n), which may hold NUL bytes. */
static const char *find(const char *buf, size_t n, const char *text) {
  const size_t k = strlen(text);
  for (size_t i = 0; i + k <= n; i++)
    if (!memcmp(buf + i, text, k)) return buf + i;
  return NULL;
}

static void scratch_open(Scratch *s) {
  snprintf(s->dir, sizeof s->dir, "/tmp/mica_test_gmsh_XXXXXX");
  assert_non_null(mkdtemp(s->dir));
}

static void scratch_close(Scratch *s) {
  char cmd[128]; /* the test's own directory under /tmp, made by mkdtemp */
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", s->dir);
  assert_int_equal(system(cmd), 0);
}

/* ---- errors ---- */

/* Binary files changed for the test: truncated, the byte-order integer swapped or wrong, data size 4. */
static void test_binary_errors(void **state) {
  (void)state;
  Scratch s;
  size_t n;
  scratch_open(&s);
  char *bin = slurp("tests/meshes/square_binary.msh", &n);
  const char *nodes = find(bin, n, "\n$Nodes\n"), *elements = find(bin, n, "\n$Elements\n");
  assert_non_null(nodes);
  assert_non_null(elements);
  load_fails(scratch_write(&s, "cut_nodes.msh", bin, (size_t)(nodes - bin) + 300), ":", "truncated");
  load_fails(scratch_write(&s, "cut_nodes.msh", bin, (size_t)(nodes - bin) + 300), "while reading a node",
             "$Nodes");
  load_fails(scratch_write(&s, "cut_elements.msh", bin, (size_t)(elements - bin) + 100), "$Elements",
             "truncated");
  load_fails(scratch_write(&s, "cut_header.msh", bin, 22), "cut_header.msh:3:", "byte-order integer");
  char *copy = malloc(n);
  memcpy(copy, bin, n);
  const unsigned char big[4] = {0, 0, 0, 1}, junk[4] = {7, 0, 0, 0};
  memcpy(copy + 20, big, 4);
  load_fails(scratch_write(&s, "big_endian.msh", copy, n), "big_endian.msh:3:", "other byte order");
  memcpy(copy + 20, junk, 4);
  load_fails(scratch_write(&s, "junk.msh", copy, n), "junk.msh:3:", "found 0x00000007");
  memcpy(copy, bin, n);
  copy[18] = '4';
  load_fails(scratch_write(&s, "size4.msh", copy, n), "size4.msh:2:", "data size 4");
  load_fails(scratch_text(&s, "bin22.msh", "$MeshFormat\n2.2 1 8\n"), "bin22.msh:2:", "binary 2.2");
  load_fails(scratch_text(&s, "v40.msh", "$MeshFormat\n4.0 0 8\n$EndMeshFormat\n"), "v40.msh:2:", "version 4.0");
  free(copy);
  free(bin);
  scratch_close(&s);
}

static void test_errors(void **state) {
  (void)state;
  load_fails("tests/meshes/plate_hole_truncated.msh",
             "tests/meshes/plate_hole_truncated.msh:1000:", "truncated");
  load_fails("tests/meshes/plate_hole_truncated.msh", ":1000:", "$Elements");
  load_fails("tests/meshes/square_tri6.msh", "square_tri6.msh:109:", "element type 8");
  load_fails("tests/meshes/square_tri6.msh", "square_tri6.msh:109:", "gmsh -order 1");
  load_fails("tests/meshes/square_bad_node.msh", "square_bad_node.msh:90:", "node 99");
  load_fails("tests/meshes/square_node_range.msh",
             "square_node_range.msh:27:", "node tag 26 is out of range");
  load_fails("tests/meshes/square_no_elements.msh",
             "square_no_elements.msh:85:", "without a $Elements section");
  load_fails("tests/meshes/no_such_mesh.msh", "no_such_mesh.msh", "cannot open");
  load_fails("tests/meshes/README.md", "README.md:1:", "$MeshFormat");
}

/* ---- .geo files ---- */

static const char *SQUARE = "Point(1) = {0, 0, 0, 0.5}; Point(2) = {1, 0, 0, 0.5}; Point(3) = {1, 1, 0, 0.5};\n"
                            "Point(4) = {0, 1, 0, 0.5}; Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4};\n"
                            "Line(4) = {4, 1}; Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
                            "Physical Curve(\"left\") = {4}; Physical Surface(\"square\") = {1};\n";

/* A .geo made of the square and `extra` at line 5; checks the error and that nothing ran. */
static void geo_refused(Scratch *s, const char *extra, const char *where, const char *what) {
  char text[2048], pwned[300];
  snprintf(text, sizeof text, "%s%s\n", SQUARE, extra);
  load_fails(scratch_text(s, "refused.geo", text), where, what);
  snprintf(pwned, sizeof pwned, "%s/pwned", s->dir);
  assert_int_equal(access(pwned, F_OK), -1);
  assert_int_equal(access("pwned", F_OK), -1);
}

static void test_geo_refused(void **state) {
  (void)state;
  Scratch s;
  scratch_open(&s);
  char touch[512];
  snprintf(touch, sizeof touch, "SystemCall \"touch %s/pwned\";", s.dir);
  geo_refused(&s, touch, "refused.geo:5:", "SystemCall runs a shell command");
  geo_refused(&s, "SystemCall \"touch pwned\";", "refused.geo:5:", "SystemCall runs a shell command");
  geo_refused(&s, "System StrCat(\"touch \", \"pwned\");", "refused.geo:5:", "System runs a shell command");
  geo_refused(&s, "\n\nNonBlockingSystemCall 'touch pwned';", "refused.geo:7:", "shell command");
  geo_refused(&s, "OnelabRun(\"x\", \"touch pwned\");", "refused.geo:5:", "OnelabRun runs a program");
  geo_refused(&s, "If (1)\n  Exit;\nEndIf", "refused.geo:6:", "Exit would end mica");
  geo_refused(&s, "Printf(\"%g\", 1) > \"pwned\";", "refused.geo:5:", "Printf into a file");
  geo_refused(&s, "Printf(\"%g\", (1 + 2)) >> 'pwned';", "refused.geo:5:", "Printf into a file");
  geo_refused(&s, "Save \"pwned.msh\";", "refused.geo:5:", "Save writes files");
  geo_refused(&s, "Print Sprintf(\"pwned%g.png\", 1);", "refused.geo:5:", "Print writes files");
  geo_refused(&s, "CreateDir \"pwned\";", "refused.geo:5:", "CreateDir writes files");
  geo_refused(&s, "Plugin(Skin).Run;", "refused.geo:5:", "Gmsh plugin");
  geo_refused(&s, "Include StrCat(\"a\", \".geo\");", "refused.geo:5:", "plain string");
  geo_refused(&s, "Merge \"solver.py\";", "refused.geo:5:", "Merge 'solver.py'");
  geo_refused(&s, "Merge \"model.pro\";", "refused.geo:5:", "Merge 'model.pro'");
  geo_refused(&s, "Include \"missing.geo\";", "refused.geo:5:", "cannot open");
  scratch_text(&s, "inner.geo", "// an included file\nx = 1;\nSystemCall \"touch pwned\";\n");
  geo_refused(&s, "Include \"inner.geo\";", "inner.geo:3:", "SystemCall runs a shell command");
  scratch_text(&s, "loop.geo", "Include \"loop.geo\";\n");
  geo_refused(&s, "Include \"loop.geo\";", "loop.geo:1:", "deeper than 16");
  char nul[1024];
  const int len = snprintf(nul, sizeof nul, "%s// a comment\n", SQUARE);
  nul[len - 3] = '\0';
  load_fails(scratch_write(&s, "nul.geo", nul, (size_t)len), "nul.geo:5:", "NUL byte");
  char *big = malloc(4096);
  snprintf(big, 4096, "%sx = \"%01100d\";\n", SQUARE, 0);
  load_fails(scratch_text(&s, "long.geo", big), "long.geo:5:", "longer than 1023");
  free(big);
  scratch_close(&s);
}

/* The same words where they are no command: comments, strings, options, variables. */
static void test_geo_words_allowed(void **state) {
  (void)state;
  Scratch s;
  scratch_open(&s);
  char text[2048];
  snprintf(text, sizeof text,
           "// SystemCall \"touch pwned\"; Exit;\n/* Save \"x\"; Plugin(Skin).Run; */\n%s"
           "Print.Width = 640; System = 2; y = System + 1; s = \"SystemCall 'x'; Exit;\";\n"
           "Printf(\"no file: %%g\", y);\nMesh.Algorithm = 6;\n",
           SQUARE);
  MicaDiscretization *d = load(scratch_text(&s, "allowed.geo", text), 2, 2);
  assert_rel(d->volume, 1.0, 1e-13, "area");
  assert_int_equal(d->nsets, 1);
  mica_discretization_destroy(&d);
  scratch_text(&s, "inner.geo", "h = 0.5; // included\n");
  snprintf(text, sizeof text, "Include \"inner.geo\";\n%s", SQUARE);
  d = load(scratch_text(&s, "include.geo", text), 2, 2);
  assert_rel(d->volume, 1.0, 1e-13, "area");
  mica_discretization_destroy(&d);
  assert_int_equal(access("pwned", F_OK), -1);
  scratch_close(&s);
}

static void test_geo_errors(void **state) {
  (void)state;
  Scratch s;
  scratch_open(&s);
  char text[2048];
  load_fails(scratch_text(&s, "syntax.geo", "Point(1) = {0, 0, 0};\nPoint(2) = {1, 0, 0}\nLine(1) = {1, 2};\n"),
             "syntax.geo:3:", "syntax error");
  load_fails(scratch_text(&s, "points.geo", "Point(1) = {0, 0, 0};\n"), "points.geo", "no surface or volume");
  snprintf(text, sizeof text, "%sMesh.ElementOrder = 2;\n", SQUARE);
  load_fails(scratch_text(&s, "order2.geo", text), "order2.geo", "gmsh -order 1");
  load_fails(scratch_text(&s, "curves.geo",
                          "Point(1) = {0, 0, 0, 0.5}; Point(2) = {1, 0, 0, 0.5}; Point(3) = {0, 1, 0, 0.5};\n"
                          "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 1}; Curve Loop(1) = {1, 2, 3};\n"
                          "Plane Surface(1) = {1}; Physical Curve(\"base\") = {1};\n"),
             "curves.geo", "Physical Surface");
  load_fails("tests/meshes/no_such.geo", "no_such.geo", "cannot open");
  scratch_close(&s);
}

/* ---- damaged files: each loads or fails as bad input, never worse ---- */

static void mutate_and_load(const char *path, int rounds, uint64_t seed) {
  Scratch s;
  size_t n;
  scratch_open(&s);
  char *orig = slurp(path, &n), *buf = malloc(n);
  MicaRandom rng = mica_random_seed(seed);
  int loaded = 0, refused = 0;
  for (int r = 0; r < rounds; r++) {
    memcpy(buf, orig, n);
    const int changes = 1 + (int)(mica_random_next(&rng) % 4);
    size_t len = n;
    for (int c = 0; c < changes; c++) {
      const size_t at = (size_t)(mica_random_next(&rng) % n);
      const uint64_t kind = mica_random_next(&rng) % 8;
      static const char picks[] = "0 \n\t$-9.e\"\0\377";
      buf[at] = kind < 5 ? (char)mica_random_next(&rng) : picks[mica_random_next(&rng) % (sizeof picks - 1)];
      if (kind == 7) len = at + 1; /* and cut the file there */
    }
    const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = scratch_write(&s, "fuzz.msh", buf, len)};
    const MicaLayoutSpec layout = {0};
    const MicaCellSpec cells = {.order = 2};
    MicaDiscretization *disc = NULL;
    const int ierr = mica_discretization_create(&shape, &layout, &cells, &disc);
    if (ierr == MICA_SUCCESS) {
      assert_true(isfinite(disc->volume));
      mica_discretization_destroy(&disc);
      loaded++;
    } else {
      if (ierr != MICA_ERR_INPUT) {
        print_error("round %d: error %d: %s\n", r, ierr, mica_error_message());
        fail();
      }
      mica_error_clear();
      refused++;
    }
  }
  print_message("%s: %d damaged copies loaded, %d refused\n", path, loaded, refused);
  assert_true(refused > rounds / 10);
  free(buf);
  free(orig);
  scratch_close(&s);
}

static void test_damaged_files(void **state) {
  (void)state;
  mutate_and_load("tests/meshes/square_binary.msh", 3000, 1);
  mutate_and_load("tests/meshes/square_v22.msh", 3000, 2);
  mutate_and_load("tests/meshes/square_quads.msh", 3000, 3);
}

/* ---- parts (mesh_part.c) ---- */

typedef struct {
  double lo, hi;
} Slab;

static int keep_slab(const double *c, void *ctx) {
  const Slab *slab = ctx;
  return c[0] >= slab->lo && c[0] < slab->hi;
}

static void check_parts(const char *path, double x0, double x1) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = path};
  const MicaCellSpec cells = {.order = 2};
  MicaDiscretization *whole = load(path, 2, 0);
  MicaMesh *mesh = NULL;
  check_ok(mica_mesh_read(&shape, &mesh));
  const int dim = whole->dim;
  assert_int_equal(mica_mesh_dim(mesh), dim);
  assert_int_equal(mica_mesh_num_particles(mesh), whole->nparticles);
  assert_memory_equal(mica_mesh_particles(mesh), whole->x, sizeof(double) * (size_t)(whole->nparticles * dim));
  long nquad = 0, ncells = 0, npoints[16] = {0}, uncovered = 0;
  double volume = 0, measure[16] = {0}, flux = 0;
  assert_true(whole->nsets <= 16);
  for (int k = 0; k < 3; k++) {
    const Slab slab = {k ? x0 + (x1 - x0) * k / 3.0 : -HUGE_VAL, k < 2 ? x0 + (x1 - x0) * (k + 1) / 3.0 : HUGE_VAL};
    MicaMesh *part = NULL;
    MicaDiscretization *d = NULL;
    check_ok(mica_mesh_part(mesh, keep_slab, (void *)&slab, &part));
    check_ok(mica_discretization_create_mesh(part, &cells, 1, &d));
    assert_int_equal(d->nsets, whole->nsets);
    uncovered += d->boundary_uncovered;
    assert_true(d->nquad > 0 && d->nquad < whole->nquad);
    nquad += d->nquad, ncells += d->mesh->ncells;
    for (long q = 0; q < d->nquad; q++) volume += d->qw[q];
    for (int s = 0; s < d->nsets; s++) {
      const MicaBoundarySet *set = &d->sets[s], *ws = &whole->sets[s];
      assert_string_equal(set->name, ws->name);
      npoints[s] += set->n, measure[s] += set_measure(set);
      for (long q = 0; q < set->n; q++)
        for (int i = 0; i < dim; i++) flux += set->w[q] * set->x[q * dim + i] * set->normal[q * dim + i];
      for (long v = 0; v < set->nvertices; v++) { /* the whole set's vertex of the same key: the same place */
        long lo = 0, hi = ws->nvertices;
        while (hi - lo > 1) {
          const long mid = (lo + hi) / 2;
          if (ws->vertex_key[mid] <= set->vertex_key[v]) lo = mid;
          else hi = mid;
        }
        assert_true(ws->vertex_key[lo] == set->vertex_key[v]);
        assert_memory_equal(ws->vertex_x + lo * dim, set->vertex_x + v * dim, sizeof(double) * (size_t)dim);
      }
    }
    mica_discretization_destroy(&d);
    mica_mesh_destroy(&part);
  }
  assert_int_equal(nquad, whole->nquad);
  assert_int_equal(ncells, whole->ncells);
  assert_int_equal(uncovered, whole->boundary_uncovered);
  if (strstr(path, "open")) assert_true(whole->boundary_uncovered > 0);
  assert_rel(volume, whole->volume, 1e-13, "the parts' volume");
  assert_rel(flux, dim * whole->volume, 1e-13, "Σ w x·n over the parts' sets");
  for (int s = 0; s < whole->nsets; s++) {
    assert_int_equal(npoints[s], whole->sets[s].n);
    assert_rel(measure[s], set_measure(&whole->sets[s]), 1e-13, whole->sets[s].name);
  }
  mica_mesh_destroy(&mesh);
  mica_discretization_destroy(&whole);
}

static void test_mesh_parts(void **state) {
  (void)state;
  check_parts("input/meshes/plate_hole.msh", 0.0, 5.0);
  check_parts("input/meshes/cube.msh", 0.0, 1.0);
  check_parts("tests/meshes/square_quads_open.msh", 0.0, 1.0); /* its bottom edges in no set: uncovered */
}

/* ---- a source read in passes (mesh_part.c) ---- */

/* The whole particle of key `key` (whole keys are node positions, ascending), or −1. */
static long whole_particle(const MicaMesh *whole, long key) {
  const long *keys = mica_mesh_particle_keys(whole);
  long lo = 0, hi = mica_mesh_num_particles(whole);
  while (lo < hi) {
    const long mid = (lo + hi) / 2;
    if (keys[mid] < key) lo = mid + 1;
    else hi = mid;
  }
  return lo < mica_mesh_num_particles(whole) && keys[lo] == key ? lo : -1;
}

/* Every particle of the region lies in [lo, hi) at its key's whole particle; marks them in seen[]. */
static void check_region(const MicaMesh *whole, const MicaMesh *region, const double lo[3], const double hi[3],
                         char *seen) {
  const int dim = mica_mesh_dim(whole);
  const double *x = mica_mesh_particles(region), *wx = mica_mesh_particles(whole);
  for (long i = 0; i < mica_mesh_num_particles(region); i++) {
    const long w = whole_particle(whole, mica_mesh_particle_keys(region)[i]);
    assert_true(w >= 0);
    assert_memory_equal(x + i * dim, wx + w * dim, sizeof(double) * (size_t)dim);
    for (int d = 0; d < dim; d++) assert_true(x[i * dim + d] >= lo[d] && x[i * dim + d] < hi[d]);
    seen[w] = 1;
  }
}

static void check_source(const char *path) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = path};
  const MicaCellSpec cells = {.order = 2};
  MicaMesh *whole = NULL, *region = NULL;
  MicaMeshSource *src = NULL;
  MicaDiscretization *wd = load(path, 2, 0), *names = NULL, *rd = NULL;
  check_ok(mica_mesh_read(&shape, &whole));
  check_ok(mica_mesh_source_open(&shape, &src));
  const int dim = mica_mesh_dim(whole);
  assert_int_equal(mica_mesh_source_dim(src), dim);
  check_ok(mica_discretization_create_mesh(mica_mesh_source_names(src), &cells, 0, &names));
  assert_int_equal(names->nsets, wd->nsets);
  for (int k = 0; k < wd->nsets; k++) assert_string_equal(names->sets[k].name, wd->sets[k].name);
  double lo[3], hi[3], big_lo[3] = {-1e300, -1e300, -1e300}, big_hi[3] = {1e300, 1e300, 1e300};
  long nsample;
  const double *sample = mica_mesh_source_sample(src, &nsample);
  mica_mesh_source_bounds(src, lo, hi);
  assert_true(nsample > 0);
  for (long i = 0; i < nsample; i++)
    for (int d = 0; d < dim; d++) assert_true(sample[i * dim + d] >= lo[d] && sample[i * dim + d] <= hi[d]);
  for (int d = 0; d < dim; d++) { /* the whole mesh's particles lie in the bounds, and reach them */
    double a = HUGE_VAL, b = -HUGE_VAL;
    for (long i = 0; i < mica_mesh_num_particles(whole); i++)
      a = fmin(a, mica_mesh_particles(whole)[i * dim + d]), b = fmax(b, mica_mesh_particles(whole)[i * dim + d]);
    assert_true(a >= lo[d] && b <= hi[d]);
  }
  /* the region of everything: the whole mesh */
  check_ok(mica_mesh_source_region(src, big_lo, big_hi, &region));
  assert_int_equal(mica_mesh_num_particles(region), mica_mesh_num_particles(whole));
  assert_memory_equal(mica_mesh_particle_keys(region), mica_mesh_particle_keys(whole),
                      sizeof(long) * (size_t)mica_mesh_num_particles(whole));
  check_ok(mica_discretization_create_mesh(region, &cells, 0, &rd));
  assert_int_equal(rd->nquad, wd->nquad);
  assert_rel(rd->volume, wd->volume, 1e-14, "the region's volume");
  for (int k = 0; k < wd->nsets; k++) assert_rel(set_measure(&rd->sets[k]), set_measure(&wd->sets[k]), 1e-14, "a set");
  mica_discretization_destroy(&rd);
  mica_mesh_destroy(&region);
  /* two halves along x, each widened by a quarter of the extent: they hold every particle between them */
  char *seen = NULL;
  assert_int_equal(MICA_CALLOC(seen, mica_mesh_num_particles(whole) + 1), MICA_SUCCESS);
  const double mid = 0.5 * (lo[0] + hi[0]), q = 0.25 * (hi[0] - lo[0]);
  for (int half = 0; half < 2; half++) {
    double a[3], b[3];
    memcpy(a, big_lo, sizeof a), memcpy(b, big_hi, sizeof b);
    if (half == 0) b[0] = mid + q;
    else a[0] = mid - q;
    check_ok(mica_mesh_source_region(src, a, b, &region));
    assert_true(mica_mesh_num_particles(region) < mica_mesh_num_particles(whole));
    check_region(whole, region, a, b, seen);
    mica_mesh_destroy(&region);
  }
  for (long i = 0; i < mica_mesh_num_particles(whole); i++) assert_true(seen[i]);
  MICA_FREE(seen);
  mica_discretization_destroy(&names);
  mica_discretization_destroy(&wd);
  mica_mesh_source_close(&src);
  mica_mesh_destroy(&whole);
}

static void test_mesh_source(void **state) {
  (void)state;
  check_source("input/meshes/plate_hole.msh");
  check_source("tests/meshes/plate_hole_binary.msh");
  check_source("tests/meshes/plate_hole_v22.msh");
  check_source("tests/meshes/square_groups_v22.msh");
  check_source("tests/meshes/box_hex.msh");
  check_source("input/meshes/cube.msh");
  check_source("input/meshes/plate_hole.geo");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plate_hole_mesh), cmocka_unit_test(test_cube_mesh),
      cmocka_unit_test(test_hex_mesh),        cmocka_unit_test(test_quad_mesh),
      cmocka_unit_test(test_forms_agree),     cmocka_unit_test(test_groups_merged),
      cmocka_unit_test(test_size_factor),     cmocka_unit_test(test_errors),
      cmocka_unit_test(test_binary_errors),   cmocka_unit_test(test_geo_refused),
      cmocka_unit_test(test_geo_words_allowed), cmocka_unit_test(test_geo_errors),
      cmocka_unit_test(test_damaged_files),   cmocka_unit_test(test_entity_order),
      cmocka_unit_test(test_mesh_parts),      cmocka_unit_test(test_mesh_source),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
