/* Unit tests of the nodal cells (src/geom/nodal.c, mica_discretization_nodal) and of SCNI's smoothed gradients
 * (src/assemble/scni.c, mica_scni_cache_create); docs/theory.md §nodal integration.
 *
 * - Tiling: the cell volumes (the nodal weights) sum to the body's area/volume, against the analytic value, to
 *   1e-12 relative: 2-D box, Cook's trapezoid (polygon), the quarter plate with a hole (curved, with a kink),
 *   the annulus sector, the 3-D box, each on regular and jittered (0.3) particles; on the regular box the cells
 *   are the boxes between midpoints (interior h², edge h²/2, corner h²/4, to 1e-14). The cylinder's faces are
 *   curved in a way Gauss does not integrate exactly: its sum is checked against πR²H to 1e-8 (measured
 *   3.6e-11 at 7³ particles, order 4).
 * - Closed cells: Σ_b (w n)_b = 0 and Σ_b x_b ⊗ (w n)_b = |Ω_I| I on every cell (divergence theorem), to 1e-12
 *   relative, on the box, the polygon and the 3-D box (faces integrated exactly).
 * - Rebuilt boundary sets: the same names, no uncovered face, the lengths of the box's sides.
 * - SCNI reproduces the gradient of linear fields: Σ_J ∇̃N_J(x_I) u(x_J) = ∇u for u = a + b·x, to 1e-12
 *   relative, on jittered particles (2-D box, polygon, 3-D box), and Σ_J ∇̃N_J = 0.
 * - The divergence identity Σ_I |Ω_I| ∇̃N_J(x_I) = Σ_∂Ω w N_J n (boundary sets) for every particle J, to 1e-12
 *   relative to Σ |terms|: the conformity that the linear patch test needs. Direct nodal integration's MLS
 *   gradients violate it (defect > 1e-6 printed), so the check can tell.
 * - Blocks (mica_discretization_nodal_block, what a rank builds with parallel.data = "distributed"): the plate with
 *   a hole (a kink splits faces) and the 3-D box, jittered, cut into 2 × 2 (2 × 1 × 2) blocks: every block's
 *   volumes, second moments and cell boundary points equal the whole build's for the same particles (to 1e-14
 *   relative), each set's points and weights over the blocks sum to the whole set's, and every block vertex has
 *   the key and position of the whole set's vertex with that key.
 * - Refusals: a Gmsh mesh and an irregular layout are MICA_ERR_INPUT.
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

#include "mica/solid.h"

#define PI 3.14159265358979323846

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static MicaLayoutSpec layout_of(MicaLayoutKind kind, long n0, long n1, long n2) {
  return (MicaLayoutSpec){.kind = kind, .count = {n0, n1, n2}, .jitter = 0.3, .grading = {1, 1, 1}, .seed = 11};
}

static MicaDiscretization *nodal(const MicaShapeSpec *shape, const MicaLayoutSpec *layout) {
  const MicaCellSpec cells = {.order = 4};
  MicaDiscretization *disc = NULL;
  check_ok(mica_discretization_create(shape, layout, &cells, &disc));
  check_ok(mica_discretization_nodal(shape, layout, &cells, disc));
  assert_non_null(disc->nodal);
  assert_int_equal(disc->nquad, disc->nparticles);
  assert_int_equal(disc->boundary_uncovered, 0);
  assert_true(disc->ngauss > 0);
  return disc;
}

static double weight_sum(const MicaDiscretization *disc) {
  double sum = 0.0;
  for (long p = 0; p < disc->nquad; p++) {
    assert_true(disc->qw[p] > 0);
    sum += disc->qw[p];
  }
  return sum;
}

/* Σ|Ω_I| against the exact volume, on regular and jittered particles. */
static void check_volume(const char *name, const MicaShapeSpec *shape, long n0, long n1, long n2, double exact,
                         double tol) {
  for (int k = 0; k < 2; k++) {
    MicaLayoutSpec layout = layout_of(k ? MICA_LAYOUT_JITTERED : MICA_LAYOUT_REGULAR, n0, n1, n2);
    MicaDiscretization *disc = nodal(shape, &layout);
    const double sum = weight_sum(disc), err = fabs(sum / exact - 1);
    print_message("%-22s %-8s: Σ|Ω_I| = %.16g, exact %.16g, relative error %.2e\n", name, k ? "jittered" : "regular",
                  sum, exact, err);
    assert_true(err <= tol);
    assert_true(fabs(disc->volume / exact - 1) <= tol);
    mica_discretization_destroy(&disc);
  }
}

static void test_volumes(void **state) {
  (void)state;
  const MicaShapeSpec box2 = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, -1}, .upper = {3, 2}};
  const MicaShapeSpec cook = {.kind = MICA_SHAPE_POLYGON, .dim = 2, .vertices = {{0, 0}, {48, 44}, {48, 60}, {0, 44}}};
  const MicaShapeSpec plate = {.kind = MICA_SHAPE_PLATE_HOLE, .dim = 2, .hole_radius = 1, .plate_size = {5, 4}};
  const MicaShapeSpec annulus = {
      .kind = MICA_SHAPE_ANNULUS, .dim = 2, .r_inner = 1, .r_outer = 2, .theta0 = 0.1, .theta1 = 1.2};
  const MicaShapeSpec box3 = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {2, 1, 1.5}};
  const MicaShapeSpec cylinder = {.kind = MICA_SHAPE_CYLINDER, .dim = 3, .radius = 1, .height = 1.5};
  check_volume("box 2-D", &box2, 9, 7, 0, 12.0, 1e-12);
  check_volume("Cook's trapezoid", &cook, 9, 9, 0, 0.5 * 48 * (44 + 16), 1e-12);
  check_volume("plate with hole", &plate, 11, 7, 0, 20 - 0.25 * PI, 1e-12);
  check_volume("annulus sector", &annulus, 7, 9, 0, 0.5 * 1.1 * (4 - 1), 1e-12);
  check_volume("box 3-D", &box3, 5, 4, 6, 3.0, 1e-12);
  check_volume("cylinder", &cylinder, 7, 7, 7, PI * 1.5, 1e-8);
}

/* On regular particles the cells are the boxes between midpoints: h² inside, half on an edge, a quarter at a
 * corner. */
static void test_regular_weights(void **state) {
  (void)state;
  const MicaShapeSpec box = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {0, 0}, .upper = {4, 2}};
  MicaLayoutSpec layout = layout_of(MICA_LAYOUT_REGULAR, 5, 3, 0);
  MicaDiscretization *disc = nodal(&box, &layout);
  for (long p = 0; p < disc->nparticles; p++) {
    const long i = p % 5, j = p / 5;
    const double expected = (i == 0 || i == 4 ? 0.5 : 1.0) * (j == 0 || j == 2 ? 0.5 : 1.0);
    assert_true(fabs(disc->qw[p] - expected) <= 1e-14);
    for (int d = 0; d < 2; d++) assert_true(disc->qx[p * 2 + d] == disc->x[p * 2 + d]);
  }
  mica_discretization_destroy(&disc);
}

/* Σ_b (w n)_b = 0 and Σ_b x_b ⊗ (w n)_b = |Ω_I| I on every cell. */
static void check_closed(const char *name, const MicaShapeSpec *shape, const MicaLayoutSpec *layout) {
  MicaDiscretization *disc = nodal(shape, layout);
  const int dim = disc->dim;
  const MicaNodalCells *c = disc->nodal;
  double worst = 0.0;
  for (long i = 0; i < c->n; i++) {
    double sum_n[3] = {0, 0, 0}, xn[9] = {0}, scale = 0.0;
    for (long b = c->ptr[i]; b < c->ptr[i + 1]; b++)
      for (int a = 0; a < dim; a++) {
        sum_n[a] += c->wn[b * dim + a];
        scale += fabs(c->wn[b * dim + a]);
        for (int d = 0; d < dim; d++) xn[d * dim + a] += (c->x[b * dim + d] - disc->x[i * dim + d]) * c->wn[b * dim + a];
      }
    for (int a = 0; a < dim; a++) {
      worst = fmax(worst, fabs(sum_n[a]) / scale);
      for (int d = 0; d < dim; d++) worst = fmax(worst, fabs(xn[d * dim + a] - (a == d) * disc->qw[i]) / disc->qw[i]);
    }
  }
  print_message("%-22s: closed cells, largest relative defect %.2e\n", name, worst);
  assert_true(worst <= 1e-12);
  mica_discretization_destroy(&disc);
}

static void test_closed_cells(void **state) {
  (void)state;
  const MicaShapeSpec box2 = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, -1}, .upper = {3, 2}};
  const MicaShapeSpec cook = {.kind = MICA_SHAPE_POLYGON, .dim = 2, .vertices = {{0, 0}, {48, 44}, {48, 60}, {0, 44}}};
  const MicaShapeSpec box3 = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {2, 1, 1.5}};
  MicaLayoutSpec j2 = layout_of(MICA_LAYOUT_JITTERED, 9, 7, 0), j3 = layout_of(MICA_LAYOUT_JITTERED, 5, 4, 6);
  check_closed("box 2-D, jittered", &box2, &j2);
  check_closed("Cook, jittered", &cook, &j2);
  check_closed("box 3-D, jittered", &box3, &j3);
}

static void test_boundary_sets(void **state) {
  (void)state;
  const MicaShapeSpec box = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, -1}, .upper = {3, 2}};
  MicaLayoutSpec layout = layout_of(MICA_LAYOUT_JITTERED, 9, 7, 0);
  MicaDiscretization *disc = nodal(&box, &layout);
  const char *names[4] = {"left", "right", "bottom", "top"};
  const double lengths[4] = {3, 3, 4, 4};
  assert_int_equal(disc->nsets, 4);
  for (int s = 0; s < 4; s++) {
    const int k = mica_discretization_find_set(disc, names[s]);
    assert_true(k >= 0);
    double len = 0;
    for (long p = 0; p < disc->sets[k].n; p++) len += disc->sets[k].w[p];
    assert_true(fabs(len - lengths[s]) <= 1e-13);
    assert_int_equal(disc->sets[k].nelements, s < 2 ? 7 : 9); /* one face per boundary particle's cell */
    assert_int_equal(disc->sets[k].nvertices, s < 2 ? 8 : 10);
  }
  mica_discretization_destroy(&disc);
}

/* ---- SCNI ---- */

typedef struct {
  MicaDiscretization *disc;
  MlsApprox *mls;
  MicaShapeCache *scni;
} Scni;

static Scni scni_create(const MicaShapeSpec *shape, const MicaLayoutSpec *layout) {
  Scni s = {.disc = nodal(shape, layout)};
  MlsOptions opt;
  mls_options_default(&opt);
  opt.order = 1, opt.dilation = 2.2;
  check_ok(mls_create(s.disc->dim, s.disc->nparticles, s.disc->x, &opt, &s.mls));
  check_ok(mica_scni_cache_create(s.disc, s.mls, &s.scni));
  return s;
}

static void scni_destroy(Scni *s) {
  mica_shape_cache_destroy(&s->scni);
  mls_destroy(&s->mls);
  mica_discretization_destroy(&s->disc);
}

/* Σ_J ∇̃N_J(x_I) u(x_J) against ∇u = b for u = 0.7 + b·x, and Σ_J ∇̃N_J(x_I) against 0. */
static void check_linear(const char *name, const MicaShapeSpec *shape, const MicaLayoutSpec *layout) {
  Scni s = scni_create(shape, layout);
  const int dim = s.disc->dim;
  const double b[3] = {0.3, -1.1, 0.45};
  const MicaShapeCache *c = s.scni;
  double worst = 0.0, worst_unity = 0.0;
  for (long I = 0; I < c->npoints; I++) {
    double g[3] = {0, 0, 0}, g1[3] = {0, 0, 0}, scale = 0;
    for (long e = c->ptr[I]; e < c->ptr[I + 1]; e++) {
      const double *xJ = s.disc->x + c->index[e] * dim;
      double u = 0.7;
      for (int d = 0; d < dim; d++) u += b[d] * xJ[d];
      for (int d = 0; d < dim; d++) {
        g[d] += c->dN[e * dim + d] * u;
        g1[d] += c->dN[e * dim + d];
        scale += fabs(c->dN[e * dim + d]);
      }
      if (e > c->ptr[I]) assert_true(c->index[e] > c->index[e - 1]); /* ascending */
    }
    for (int d = 0; d < dim; d++) {
      worst = fmax(worst, fabs(g[d] - b[d]) / 1.1);
      worst_unity = fmax(worst_unity, fabs(g1[d]) / scale);
    }
  }
  print_message("%-22s: SCNI gradient of a linear field, largest relative error %.2e; of unity %.2e\n", name, worst,
                worst_unity);
  assert_true(worst <= 1e-12);
  assert_true(worst_unity <= 1e-12);
  scni_destroy(&s);
}

static void test_scni_linear(void **state) {
  (void)state;
  const MicaShapeSpec box2 = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, -1}, .upper = {3, 2}};
  const MicaShapeSpec cook = {.kind = MICA_SHAPE_POLYGON, .dim = 2, .vertices = {{0, 0}, {48, 44}, {48, 60}, {0, 44}}};
  const MicaShapeSpec box3 = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {2, 1, 1.5}};
  MicaLayoutSpec j2 = layout_of(MICA_LAYOUT_JITTERED, 9, 7, 0), j3 = layout_of(MICA_LAYOUT_JITTERED, 5, 4, 6);
  check_linear("box 2-D, jittered", &box2, &j2);
  check_linear("Cook, jittered", &cook, &j2);
  check_linear("box 3-D, jittered", &box3, &j3);
}

/* Σ_I |Ω_I| ∇N_J(x_I) − Σ_∂Ω w N_J n per particle J and direction, relative to the sum of |terms|. */
static double divergence_defect(const MicaDiscretization *disc, const MlsApprox *mls, const MicaShapeCache *vol) {
  const int dim = disc->dim;
  const long np = disc->nparticles;
  double *sum = calloc((size_t)(np * dim), sizeof *sum), *scale = calloc((size_t)(np * dim), sizeof *scale);
  assert_non_null(sum);
  assert_non_null(scale);
  for (long I = 0; I < vol->npoints; I++)
    for (long e = vol->ptr[I]; e < vol->ptr[I + 1]; e++)
      for (int d = 0; d < dim; d++) {
        const double t = disc->qw[I] * vol->dN[e * dim + d];
        sum[vol->index[e] * dim + d] += t, scale[vol->index[e] * dim + d] += fabs(t);
      }
  for (int k = 0; k < disc->nsets; k++) {
    const MicaBoundarySet *set = &disc->sets[k];
    MicaShapeCache *b = NULL;
    check_ok(mica_shape_cache_create(mls, set->n, set->x, 1, "boundary", &b));
    for (long p = 0; p < set->n; p++)
      for (long e = b->ptr[p]; e < b->ptr[p + 1]; e++)
        for (int d = 0; d < dim; d++) {
          const double t = set->w[p] * b->N[e] * set->normal[p * dim + d];
          sum[b->index[e] * dim + d] -= t, scale[b->index[e] * dim + d] += fabs(t);
        }
    mica_shape_cache_destroy(&b);
  }
  double worst = 0;
  for (long i = 0; i < np * dim; i++)
    if (scale[i] > 0) worst = fmax(worst, fabs(sum[i]) / scale[i]);
  free(sum);
  free(scale);
  return worst;
}

static void check_divergence(const char *name, const MicaShapeSpec *shape, const MicaLayoutSpec *layout) {
  Scni s = scni_create(shape, layout);
  MicaShapeCache *direct = NULL;
  check_ok(mica_shape_cache_create(s.mls, s.disc->nquad, s.disc->qx, 1, "nodal", &direct));
  const double smoothed = divergence_defect(s.disc, s.mls, s.scni), plain = divergence_defect(s.disc, s.mls, direct);
  print_message("%-22s: divergence identity defect, SCNI %.2e, direct nodal %.2e\n", name, smoothed, plain);
  assert_true(smoothed <= 1e-12);
  assert_true(plain > 1e-6);
  mica_shape_cache_destroy(&direct);
  scni_destroy(&s);
}

static void test_scni_divergence(void **state) {
  (void)state;
  const MicaShapeSpec box2 = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, -1}, .upper = {3, 2}};
  const MicaShapeSpec plate = {.kind = MICA_SHAPE_PLATE_HOLE, .dim = 2, .hole_radius = 1, .plate_size = {5, 4}};
  const MicaShapeSpec box3 = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {2, 1, 1.5}};
  MicaLayoutSpec j2 = layout_of(MICA_LAYOUT_JITTERED, 9, 7, 0), jp = layout_of(MICA_LAYOUT_JITTERED, 11, 7, 0);
  MicaLayoutSpec j3 = layout_of(MICA_LAYOUT_JITTERED, 5, 4, 6);
  check_divergence("box 2-D, jittered", &box2, &j2);
  check_divergence("plate, jittered", &plate, &jp);
  check_divergence("box 3-D, jittered", &box3, &j3);
}

/* The whole set's vertex with this key, or −1. */
static long find_key(const MicaBoundarySet *set, long key) {
  for (long v = 0; v < set->nvertices; v++)
    if (set->vertex_key[v] == key) return v;
  return -1;
}

/* One block [lo, hi) against the whole build: cells, then the sets (counts and weights added into got[]). */
static void check_block(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                        const MicaDiscretization *whole, const long lo[3], const long hi[3], double *got) {
  MicaDiscretization *b = NULL;
  const int dim = whole->dim;
  check_ok(mica_discretization_nodal_block(shape, layout, cells, lo, hi, &b));
  long k = 0;
  for (long i2 = lo[2]; i2 < hi[2]; i2++)
    for (long i1 = lo[1]; i1 < hi[1]; i1++)
      for (long i0 = lo[0]; i0 < hi[0]; i0++, k++) {
        const long w = i0 + whole->grid_particles[0] * (i1 + whole->grid_particles[1] * i2);
        for (int d = 0; d < dim; d++) assert_true(b->x[k * dim + d] == whole->x[w * dim + d]);
        assert_true(fabs(b->qw[k] / whole->qw[w] - 1) <= 1e-14);
        const double *Mb = b->nodal->moment + k * dim * dim, *Mw = whole->nodal->moment + w * dim * dim;
        for (int e = 0; e < dim * dim; e++) assert_true(fabs(Mb[e] - Mw[e]) <= 1e-14 * fabs(Mw[0]));
        assert_int_equal(b->nodal->ptr[k + 1] - b->nodal->ptr[k], whole->nodal->ptr[w + 1] - whole->nodal->ptr[w]);
      }
  assert_int_equal(k, b->nquad);
  assert_int_equal(b->nsets, whole->nsets);
  for (int s = 0; s < b->nsets; s++) {
    const MicaBoundarySet *bs = &b->sets[s], *ws = &whole->sets[s];
    assert_string_equal(bs->name, ws->name);
    got[2 * s] += (double)bs->n;
    for (long q = 0; q < bs->n; q++) got[2 * s + 1] += bs->w[q];
    for (long v = 0; v < bs->nvertices; v++) {
      const long wv = find_key(ws, bs->vertex_key[v]);
      assert_true(wv >= 0);
      for (int d = 0; d < dim; d++) assert_true(fabs(bs->vertex_x[v * dim + d] - ws->vertex_x[wv * dim + d]) <= 1e-13);
    }
  }
  mica_discretization_destroy(&b);
}

static void check_blocks(const char *name, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                         const long cut[3]) {
  const MicaCellSpec cells = {.order = 4};
  MicaDiscretization *whole = nodal(shape, layout);
  const long *n = whole->grid_particles;
  double got[64] = {0};
  for (int c = 0; c < 8; c++) {
    long lo[3], hi[3];
    for (int d = 0; d < 3; d++) {
      const int upper = (c >> d) & 1;
      if (cut[d] <= 0 && upper) goto next; /* this axis is not cut */
      lo[d] = cut[d] > 0 && upper ? cut[d] : 0, hi[d] = cut[d] > 0 && !upper ? cut[d] : n[d];
    }
    check_block(shape, layout, &cells, whole, lo, hi, got);
  next:;
  }
  for (int s = 0; s < whole->nsets; s++) {
    double w = 0;
    for (long q = 0; q < whole->sets[s].n; q++) w += whole->sets[s].w[q];
    print_message("%-16s set %-8s: %4.0f points in blocks, %4ld whole; weights %.16g / %.16g\n", name,
                  whole->sets[s].name, got[2 * s], whole->sets[s].n, got[2 * s + 1], w);
    assert_int_equal((long)got[2 * s], whole->sets[s].n);
    assert_true(fabs(got[2 * s + 1] - w) <= 1e-13 * w);
  }
  mica_discretization_destroy(&whole);
}

static void test_blocks(void **state) {
  (void)state;
  const MicaShapeSpec plate = {.kind = MICA_SHAPE_PLATE_HOLE, .dim = 2, .hole_radius = 1, .plate_size = {5, 4}};
  const MicaShapeSpec box3 = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {2, 1, 1.5}};
  const MicaLayoutSpec lp = layout_of(MICA_LAYOUT_JITTERED, 11, 7, 0), lb = layout_of(MICA_LAYOUT_JITTERED, 5, 4, 6);
  const long cut2[3] = {5, 3, 0}, cut3[3] = {2, 0, 3};
  check_blocks("plate with hole", &plate, &lp, cut2);
  check_blocks("box 3-D", &box3, &lb, cut3);
}

static void test_refused(void **state) {
  (void)state;
  const MicaShapeSpec box = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {0, 0}, .upper = {1, 1}};
  const MicaCellSpec cells = {.order = 2};
  MicaLayoutSpec irregular = layout_of(MICA_LAYOUT_IRREGULAR, 7, 7, 0);
  MicaDiscretization *disc = NULL;
  check_ok(mica_discretization_create(&box, &irregular, &cells, &disc));
  assert_int_equal(mica_discretization_nodal(&box, &irregular, &cells, disc), MICA_ERR_INPUT);
  assert_non_null(strstr(mica_error_message(), "logical grid"));
  mica_discretization_destroy(&disc);
  const MicaShapeSpec mesh = {.kind = MICA_SHAPE_GMSH, .mesh_path = "tests/meshes/square_quads.msh"};
  const MicaLayoutSpec none = {0};
  check_ok(mica_discretization_create(&mesh, &none, &cells, &disc));
  assert_int_equal(mica_discretization_nodal(&mesh, &none, &cells, disc), MICA_ERR_INPUT);
  assert_non_null(strstr(mica_error_message(), "built-in shape"));
  mica_discretization_destroy(&disc);
  mica_error_clear();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_volumes),        cmocka_unit_test(test_regular_weights), cmocka_unit_test(test_closed_cells),
      cmocka_unit_test(test_boundary_sets),  cmocka_unit_test(test_scni_linear),     cmocka_unit_test(test_scni_divergence),
      cmocka_unit_test(test_blocks),         cmocka_unit_test(test_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
