/* Unit tests of the finite-element baseline (src/fe).
 *
 *   - reference elements (Q1, Q2, hex8, hex27): Kronecker delta at the nodes (1e-15), partition of unity and
 *     Σ ∂N/∂ξ = 0 at random points (1e-14);
 *   - completeness through the isoparametric map, values and physical gradients at random points, 1e-13
 *     (relative to the field's scale):
 *       linear fields on every element kind, distorted: Q1/hex8 with randomly moved corners (non-affine),
 *       Q2/hex27 with randomly moved nodes, midside and center nodes included (curved edges);
 *       quadratic fields on Q2/hex27 with multilinear geometry (randomly moved corners, the other nodes
 *       where the multilinear map puts them): x², xy, ... lie in the tensor space of degree 2 per axis then;
 *     and, so that the check can fail, a quadratic is NOT reproduced on the curved Q2 element (error > 1e-6);
 *   - the mesh on a jittered grid: element Gauss weights sum to the box's area/volume, each boundary set's
 *     weights to its side's length/area (1e-13), normals are the outward unit normals of the box;
 *   - point location: random points are found in an element whose map returns them (1e-13);
 *   - the approximation: N sums to 1 and ∇N to 0 at the volume points; at the particles N = δ;
 *   - refusals: an even node count for order 2, a particle count that is not the grid's (MICA_ERR_INPUT).
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/fe.h"
#include "mica/random.h"

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

static void check_small(double err, double tol, const char *what, int dim, int order) {
  if (!(err <= tol)) {
    print_error("%s (dim %d, order %d): error %.3g > %.3g\n", what, dim, order, err, tol);
    fail();
  }
}

/* ---- reference elements ---- */

static void test_kronecker_and_unity(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(7);
  for (int dim = 2; dim <= 3; dim++)
    for (int order = 1; order <= 2; order++) {
      const int nen = mica_fe_element_nodes(dim, order);
      double xin[MICA_FE_MAX_NODES * 3], N[MICA_FE_MAX_NODES], dN[MICA_FE_MAX_NODES * 3];
      mica_fe_reference_nodes(dim, order, xin);
      double worst = 0;
      for (int b = 0; b < nen; b++) {
        mica_fe_reference_eval(dim, order, xin + b * dim, N, NULL);
        for (int a = 0; a < nen; a++) worst = fmax(worst, fabs(N[a] - (a == b)));
      }
      check_small(worst, 1e-15, "Kronecker delta at the nodes", dim, order);
      worst = 0;
      for (int k = 0; k < 50; k++) {
        double xi[3];
        for (int d = 0; d < dim; d++) xi[d] = 2 * mica_random_uniform(&rng) - 1;
        mica_fe_reference_eval(dim, order, xi, N, dN);
        double sum = 0, dsum[3] = {0, 0, 0};
        for (int a = 0; a < nen; a++) {
          sum += N[a];
          for (int d = 0; d < dim; d++) dsum[d] += dN[d * nen + a];
        }
        worst = fmax(worst, fabs(sum - 1));
        for (int d = 0; d < dim; d++) worst = fmax(worst, fabs(dsum[d]));
      }
      check_small(worst, 1e-14, "partition of unity", dim, order);
    }
}

/* ---- completeness through the isoparametric map ---- */

/* Node coordinates of a distorted element: corners moved by up to 0.2 (the reference element spans 2);
 * curved: every node moved independently; otherwise the non-corner nodes where the multilinear map of the
 * moved corners puts them. Scaled and sheared so the element is not near the reference one. */
static void distorted_element(int dim, int order, int curved, MicaRandom *rng, double *xe) {
  const int nen = mica_fe_element_nodes(dim, order), ncorner = 1 << dim;
  double xin[MICA_FE_MAX_NODES * 3], corner[8][3], move[MICA_FE_MAX_NODES][3];
  mica_fe_reference_nodes(dim, order, xin);
  for (int c = 0; c < ncorner; c++)
    for (int d = 0; d < dim; d++) corner[c][d] = ((c >> d) & 1 ? 1 : -1) + 0.2 * (2 * mica_random_uniform(rng) - 1);
  for (int a = 0; a < nen; a++)
    for (int d = 0; d < dim; d++) move[a][d] = 0.1 * (2 * mica_random_uniform(rng) - 1);
  for (int a = 0; a < nen; a++) {
    double x[3] = {0, 0, 0};
    for (int c = 0; c < ncorner; c++) { /* multilinear map of the corners */
      double w = 1;
      for (int d = 0; d < dim; d++) w *= 0.5 * (1 + ((c >> d) & 1 ? 1 : -1) * xin[a * dim + d]);
      for (int d = 0; d < dim; d++) x[d] += w * corner[c][d];
    }
    if (curved)
      for (int d = 0; d < dim; d++) x[d] += move[a][d];
    /* scale and shear: x ← A x + b */
    const double A[3][3] = {{3.0, 0.7, 0.2}, {-0.4, 1.5, 0.3}, {0.1, 0.2, 2.0}}, b[3] = {5.0, -2.0, 1.0};
    for (int i = 0; i < dim; i++) {
      double s = b[i];
      for (int j = 0; j < dim; j++) s += A[i][j] * x[j];
      xe[a * dim + i] = s;
    }
  }
}

/* A polynomial of degree ≤ deg (fixed coefficients) and its gradient. */
static double poly(int dim, int deg, const double *x, double *grad) {
  const double c[3] = {0.3, -0.7, 0.45}, q[3][3] = {{0.2, -0.35, 0.15}, {-0.35, 0.5, 0.25}, {0.15, 0.25, -0.4}};
  double v = 1.25;
  for (int i = 0; i < dim; i++) v += c[i] * x[i], grad[i] = c[i];
  if (deg >= 2)
    for (int i = 0; i < dim; i++)
      for (int j = 0; j < dim; j++) v += q[i][j] * x[i] * x[j], grad[i] += 2 * q[i][j] * x[j];
  return v;
}

/* The worst relative error of Σ N_a p(x_a) and Σ ∇N_a p(x_a) against p, ∇p at random points of an element. */
static double reproduction_error(int dim, int order, int deg, int curved, MicaRandom *rng) {
  const int nen = mica_fe_element_nodes(dim, order);
  double xe[MICA_FE_MAX_NODES * 3], pa[MICA_FE_MAX_NODES], g[3], worst = 0, scale = 0;
  distorted_element(dim, order, curved, rng, xe);
  for (int a = 0; a < nen; a++) pa[a] = poly(dim, deg, xe + a * dim, g), scale = fmax(scale, fabs(pa[a]));
  for (int k = 0; k < 20; k++) {
    double xi[3], N[MICA_FE_MAX_NODES], dN[MICA_FE_MAX_NODES * 3], dNdx[MICA_FE_MAX_NODES * 3], x[3] = {0, 0, 0}, det;
    for (int d = 0; d < dim; d++) xi[d] = 2 * mica_random_uniform(rng) - 1;
    mica_fe_reference_eval(dim, order, xi, N, dN);
    check_ok(mica_fe_gradients(dim, nen, xe, dN, NULL, &det, dNdx));
    assert_true(det > 0);
    for (int a = 0; a < nen; a++)
      for (int d = 0; d < dim; d++) x[d] += N[a] * xe[a * dim + d];
    double v = 0, gv[3] = {0, 0, 0};
    for (int a = 0; a < nen; a++) {
      v += N[a] * pa[a];
      for (int d = 0; d < dim; d++) gv[d] += dNdx[a * dim + d] * pa[a];
    }
    const double exact = poly(dim, deg, x, g);
    worst = fmax(worst, fabs(v - exact) / scale);
    for (int d = 0; d < dim; d++) worst = fmax(worst, fabs(gv[d] - g[d]) / scale);
  }
  return worst;
}

static void test_completeness(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(11);
  for (int dim = 2; dim <= 3; dim++)
    for (int trial = 0; trial < 10; trial++) {
      check_small(reproduction_error(dim, 1, 1, 0, &rng), 1e-13, "Q1/hex8 linear, distorted", dim, 1);
      check_small(reproduction_error(dim, 2, 1, 1, &rng), 1e-13, "Q2/hex27 linear, curved", dim, 2);
      check_small(reproduction_error(dim, 2, 2, 0, &rng), 1e-13, "Q2/hex27 quadratic, multilinear geometry", dim, 2);
      const double curved = reproduction_error(dim, 2, 2, 1, &rng);
      if (!(curved > 1e-6)) {
        print_error("dim %d: a quadratic is reproduced on a curved Q2 element to %.3g: the check is blind\n", dim,
                    curved);
        fail();
      }
    }
}

/* ---- the mesh on a jittered box ---- */

static void build(int dim, int order, long n, MicaDiscretization **like, MicaFe **fe, MicaDiscretization **disc) {
  MicaShapeSpec shape = {.kind = MICA_SHAPE_BOX, .dim = dim, .lower = {-1, 0, 2}, .upper = {2, 0.5, 3}};
  MicaLayoutSpec layout = {.kind = MICA_LAYOUT_JITTERED, .count = {n, n - 2, n}, .jitter = 0.3, .seed = 3};
  MicaCellSpec cells = {.order = 3};
  check_ok(mica_discretization_create(&shape, &layout, &cells, like));
  check_ok(mica_fe_create(dim, order, layout.count, (*like)->nparticles, (*like)->x, fe));
  check_ok(mica_fe_discretize(*fe, *like, order + 1, order + 1, disc));
}

static void test_mesh_measures(void **state) {
  (void)state;
  const double side[3] = {3, 0.5, 1};
  for (int dim = 2; dim <= 3; dim++)
    for (int order = 1; order <= 2; order++) {
      MicaDiscretization *like = NULL, *disc = NULL;
      MicaFe *fe = NULL;
      build(dim, order, 7, &like, &fe, &disc);
      double volume = 1;
      for (int d = 0; d < dim; d++) volume *= side[d];
      check_small(fabs(disc->volume - volume) / volume, 1e-13, "volume", dim, order);
      assert_int_equal(disc->nsets, like->nsets);
      for (int s = 0; s < disc->nsets; s++) {
        const MicaBoundarySet *set = &disc->sets[s];
        const int axis = s / 2;
        double area = 1, sum = 0, worst = 0;
        for (int d = 0; d < dim; d++) area *= d == axis ? 1 : side[d];
        for (long p = 0; p < set->n; p++) {
          sum += set->w[p];
          for (int d = 0; d < dim; d++) worst = fmax(worst, fabs(set->normal[p * dim + d] - (d == axis ? (s % 2 ? 1 : -1) : 0)));
        }
        assert_string_equal(set->name, like->sets[s].name);
        check_small(fabs(sum - area) / area, 1e-13, set->name, dim, order);
        check_small(worst, 1e-13, "outward normal", dim, order);
      }
      mica_discretization_destroy(&disc);
      mica_discretization_destroy(&like);
      mica_fe_destroy(&fe);
    }
}

static void test_locate(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(5);
  for (int dim = 2; dim <= 3; dim++)
    for (int order = 1; order <= 2; order++) {
      MicaDiscretization *like = NULL, *disc = NULL;
      MicaFe *fe = NULL;
      build(dim, order, 5, &like, &fe, &disc);
      double worst = 0;
      for (int k = 0; k < 30; k++) {
        const double lo[3] = {-1, 0, 2}, size[3] = {3, 0.5, 1};
        double x[3], xi[3], back[3] = {0, 0, 0}, N[MICA_FE_MAX_NODES];
        long el;
        for (int d = 0; d < dim; d++) x[d] = lo[d] + size[d] * mica_random_uniform(&rng);
        check_ok(mica_fe_locate(fe, x, &el, xi));
        for (int d = 0; d < dim; d++) assert_true(fabs(xi[d]) <= 1 + 1e-10);
        mica_fe_reference_eval(dim, order, xi, N, NULL);
        for (int a = 0; a < fe->nen; a++)
          for (int d = 0; d < dim; d++) back[d] += N[a] * fe->x[fe->conn[el * fe->nen + a] * dim + d];
        for (int d = 0; d < dim; d++) worst = fmax(worst, fabs(back[d] - x[d]));
      }
      check_small(worst, 1e-13, "located point mapped back", dim, order);
      const double far[3] = {10, 10, 10};
      double xi[3];
      long el;
      assert_int_equal(mica_fe_locate(fe, far, &el, xi), MICA_ERR_INPUT);
      mica_error_clear();
      mica_discretization_destroy(&disc);
      mica_discretization_destroy(&like);
      mica_fe_destroy(&fe);
    }
}

static void test_approximation(void **state) {
  (void)state;
  for (int dim = 2; dim <= 3; dim++)
    for (int order = 1; order <= 2; order++) {
      MicaDiscretization *like = NULL, *disc = NULL;
      MicaFe *fe = NULL;
      MicaShapeCache *vol = NULL, *nodes = NULL;
      build(dim, order, 5, &like, &fe, &disc);
      check_ok(mica_approx_fe.points(fe, disc->nquad, disc->qx, disc->qcell, 1, "volume", &vol));
      double worst = 0;
      for (long p = 0; p < vol->npoints; p++) {
        double sum = 0, g[3] = {0, 0, 0};
        for (long e = vol->ptr[p]; e < vol->ptr[p + 1]; e++) {
          sum += vol->N[e];
          for (int d = 0; d < dim; d++) g[d] += vol->dN[e * dim + d];
        }
        worst = fmax(worst, fabs(sum - 1));
        for (int d = 0; d < dim; d++) worst = fmax(worst, fabs(g[d]));
      }
      check_small(worst, 1e-12, "unity of the volume cache", dim, order);
      check_ok(mica_approx_fe.particles(fe, 1, &nodes));
      worst = 0;
      for (long i = 0; i < nodes->npoints; i++)
        for (long e = nodes->ptr[i]; e < nodes->ptr[i + 1]; e++) worst = fmax(worst, fabs(nodes->N[e] - (nodes->index[e] == i)));
      check_small(worst, 0, "N = δ at the nodes", dim, order);
      MicaShapeCache *hessian = NULL;
      assert_int_equal(mica_approx_fe.points(fe, 1, disc->qx, NULL, 2, "hessian", &hessian), MICA_ERR_INPUT);
      assert_null(hessian);
      mica_error_clear();
      mica_shape_cache_destroy(&vol);
      mica_shape_cache_destroy(&nodes);
      mica_discretization_destroy(&disc);
      mica_discretization_destroy(&like);
      mica_fe_destroy(&fe);
    }
}

static void test_refusals(void **state) {
  (void)state;
  const double x[16 * 2] = {0};
  MicaFe *fe = NULL;
  const long even[3] = {4, 3, 1}, grid[3] = {4, 4, 1};
  assert_int_equal(mica_fe_create(2, 2, even, 12, x, &fe), MICA_ERR_INPUT);
  mica_error_clear();
  assert_int_equal(mica_fe_create(2, 1, grid, 15, x, &fe), MICA_ERR_INPUT);
  mica_error_clear();
  assert_null(fe);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_kronecker_and_unity), cmocka_unit_test(test_completeness),
      cmocka_unit_test(test_mesh_measures),       cmocka_unit_test(test_locate),
      cmocka_unit_test(test_approximation),       cmocka_unit_test(test_refusals),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
