/* Unit tests of the MLS bases (src/mls/basis.c): lookup, sizes, the analytic gradients and Hessians
 * against central finite differences, the Pascal term order and values, the Kronecker property and
 * partition of unity of Lagrange, partition of unity and positivity of Bernstein, and that Bernstein and
 * Pascal lie in the Lagrange (tensor) space, via Lagrange interpolation, which is exact on that space.
 *
 * Tolerances: derivatives agree with central differences (step 1e-5) to 1e-7 × (1 + |exact|): the
 * truncation error is about 1e-10 × |third derivative| ≤ 1e-8 here and the rounding error about 1e-11.
 * They also agree to 1e-11 × (1 + |exact|) with Richardson-extrapolated differences (steps 0.1, 0.05),
 * which are exact for polynomials of degree ≤ 3 per axis up to rounding (about 1e-14 × 10 / 0.05); this
 * catches relative errors in a derivative far below the plain difference's 1e-7.
 * Identities that hold exactly in exact arithmetic (partition of unity, Kronecker, interpolation) hold to
 * 1e-13. The random points come from a fixed-seed generator, so a failure reproduces.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "mica/mls.h"
#include "registry_arrays.h"


#define MAX_TERMS 64 /* (3 + 1)^3 */
#define FD_STEP 1e-5
#define FD_TOL 1e-7
#define RICHARDSON_STEP 0.1
#define RICHARDSON_TOL 1e-11
#define EXACT_TOL 1e-13
#define NUM_POINTS 6
#define SENTINEL 12345.0

static const MlsBasisOps *const all_bases[] = {&mls_basis_pascal, &mls_basis_lagrange, &mls_basis_bernstein};

/* A basis evaluation with room for the largest basis and sentinels after the m terms in use. */
typedef struct {
  double p[MAX_TERMS], dp[MLS_MAX_DIM * MAX_TERMS], ddp[MLS_MAX_HESS * MAX_TERMS];
} Eval;

static void eval_basis(const MlsBasisOps *b, int dim, int order, const double *s, Eval *e) {
  for (int i = 0; i < MAX_TERMS; i++) e->p[i] = SENTINEL;
  for (int i = 0; i < MLS_MAX_DIM * MAX_TERMS; i++) e->dp[i] = SENTINEL;
  for (int i = 0; i < MLS_MAX_HESS * MAX_TERMS; i++) e->ddp[i] = SENTINEL;
  b->eval(dim, order, s, e->p, e->dp, e->ddp);
}

/* xorshift64*, uniform in [−1, 1). */
static double random_coordinate(uint64_t *state) {
  *state ^= *state >> 12;
  *state ^= *state << 25;
  *state ^= *state >> 27;
  uint64_t bits = (*state * 2685821657736338717ULL) >> 11;
  return 2.0 * (double)bits / 9007199254740992.0 - 1.0;
}

static void random_point(uint64_t *state, int dim, double *s) {
  for (int d = 0; d < dim; d++) s[d] = random_coordinate(state);
}

static void assert_close(double expected, double actual, double tol, const char *what, const MlsBasisOps *b,
                         int dim, int order, int term) {
  if (!(fabs(expected - actual) <= tol)) {
    print_error("%s %s dim %d order %d term %d: expected %.17g, got %.17g (tolerance %.3g)\n", b->type.name, what,
                dim, order, term, expected, actual, tol);
    fail();
  }
}

/* Node k of the equally spaced 1-D Lagrange nodes. */
static double lagrange_node(int order, int k) { return -1.0 + 2.0 * k / order; }

/* Tensor node of term a for the documented term order a = k0 + n k1 + n² k2 (axis 0 fastest). */
static void tensor_node(int dim, int order, int a, double *s) {
  for (int d = 0; d < dim; d++, a /= order + 1) s[d] = lagrange_node(order, a % (order + 1));
}

static int binomial(int n, int k) {
  int c = 1;
  for (int i = 1; i <= k; i++) c = c * (n - k + i) / i;
  return c;
}

/* ---- lookup and sizes ---- */

/* The composed mls.* key at path: its choices and default come from the registry of its chooser. */
static const MicaDeckKey *mls_key(MicaSchema **schema, const char *path) {
  MICA_SCHEMA_TABLES
  static const MicaDeckKey base[] = {{.path = "mls", .type = MICA_KEY_FRAGMENT, .fragment = mls_keys}, {NULL}};
  assert_int_equal(mica_schema_compose(base, schema), MICA_SUCCESS);
  const MicaDeckKey *key = mica_schema_find(mica_schema_keys(*schema), path);
  assert_non_null(key);
  return key;
}

/* The choices of mls.basis, mls.support, mls.search and mls.spacing, their defaults in the schema and in
 * mls_options_default, all follow the registries: a type added at run time is offered, and a registry's
 * default (its one place) moves both defaults. */
static void test_registries_give_choices_and_defaults(void **state) {
  (void)state;
  static MlsBasisOps copy = {{"pascal-copy", "the Pascal basis again", 0, NULL, NULL}, 0, 3, NULL, NULL};
  copy.size = mls_basis_pascal.size, copy.eval = mls_basis_pascal.eval; /* usable by any later loop */
  assert_int_equal(mica_registry_add(&mls_basis_registry, &copy.type), MICA_SUCCESS);
  assert_int_equal(mica_registry_add(&mls_basis_registry, &copy.type), MICA_ERR_ARGUMENT); /* name taken */
  assert_ptr_equal(mls_basis_find("pascal-copy"), &copy);
  MicaSchema *schema;
  assert_string_equal(mls_key(&schema, "mls.basis")->choices, "pascal|lagrange|bernstein|pascal-copy");
  mica_schema_destroy(&schema);
  assert_string_equal(mls_key(&schema, "mls.support")->choices, "box|ball");
  mica_schema_destroy(&schema);
  assert_string_equal(mls_key(&schema, "mls.search")->choices, "kdtree|cells");
  mica_schema_destroy(&schema);
  assert_string_equal(mls_key(&schema, "mls.spacing")->choices, "near|far");
  mica_schema_destroy(&schema);
  MlsOptions opt;
  mls_options_default(&opt);
  assert_ptr_equal(opt.basis, &mls_basis_pascal);
  assert_int_equal(opt.support, MLS_SUPPORT_BOX);
  assert_int_equal(opt.search, MLS_SEARCH_KDTREE);
  assert_int_equal(opt.spacing, MLS_SPACING_NEAR);
  /* move each default: the schema and the options follow */
  const char *defaults[4] = {mls_basis_registry.def, mls_support_registry.def, mls_search_registry.def,
                             mls_spacing_registry.def};
  mls_basis_registry.def = "lagrange", mls_support_registry.def = "ball", mls_search_registry.def = "cells",
  mls_spacing_registry.def = "far";
  mls_options_default(&opt);
  assert_ptr_equal(opt.basis, &mls_basis_lagrange);
  assert_int_equal(opt.support, MLS_SUPPORT_BALL);
  assert_int_equal(opt.search, MLS_SEARCH_CELLS);
  assert_int_equal(opt.spacing, MLS_SPACING_FAR);
  assert_string_equal(mls_key(&schema, "mls.support")->def, "\"ball\"");
  mica_schema_destroy(&schema);
  assert_string_equal(mls_key(&schema, "mls.basis")->def, "\"lagrange\"");
  mica_schema_destroy(&schema);
  mls_basis_registry.def = defaults[0], mls_support_registry.def = defaults[1], mls_search_registry.def = defaults[2],
  mls_spacing_registry.def = defaults[3];
}

static void test_find(void **state) {
  (void)state;
  const char *names[] = {"pascal", "lagrange", "bernstein"};
  const MlsBasisOps *const *all = bases_all();
  for (int i = 0; i < 3; i++) {
    assert_ptr_equal(mls_basis_find(names[i]), all_bases[i]);
    assert_ptr_equal(all[i], all_bases[i]);
    assert_string_equal(all_bases[i]->type.name, names[i]);
  }
  assert_null(all[3]);
  assert_null(mls_basis_find("Pascal"));
  assert_null(mls_basis_find("legendre"));
  assert_null(mls_basis_find(""));
  assert_null(mls_basis_find(NULL));
  assert_int_equal(mls_basis_pascal.min_order, 0);
  assert_int_equal(mls_basis_pascal.max_order, 3);
  for (int i = 1; i < 3; i++) {
    assert_int_equal(all_bases[i]->min_order, 1);
    assert_int_equal(all_bases[i]->max_order, 3);
  }
}

/* Pascal m = C(order + dim, dim), counted here as the exponent tuples of total degree ≤ order;
 * tensor m = (order + 1)^dim. */
static void test_sizes(void **state) {
  (void)state;
  for (int dim = 1; dim <= 3; dim++)
    for (int order = 0; order <= 3; order++) {
      int count = 0, n = order + 1;
      for (int e0 = 0; e0 < n; e0++)
        for (int e1 = 0; e1 < (dim > 1 ? n : 1); e1++)
          for (int e2 = 0; e2 < (dim > 2 ? n : 1); e2++) count += e0 + e1 + e2 <= order;
      assert_int_equal(mls_basis_pascal.size(dim, order), count);
      assert_int_equal(mls_basis_pascal.size(dim, order), binomial(order + dim, dim));
      if (order >= 1) {
        assert_int_equal(mls_basis_lagrange.size(dim, order), n * (dim > 1 ? n : 1) * (dim > 2 ? n : 1));
        assert_int_equal(mls_basis_bernstein.size(dim, order), mls_basis_lagrange.size(dim, order));
      }
    }
  assert_int_equal(mls_basis_pascal.size(3, 3), 20);
  assert_int_equal(mls_basis_lagrange.size(3, 3), 64);
}

/* ---- derivatives, for every basis, dimension and order ---- */

/* Central differences with step h along axis j: of p into fd_p[m], of the analytic ∂p/∂s_i into
 * fd_dp[i*m + a]. */
static void central_differences(const MlsBasisOps *b, int dim, int order, const double *s, int j, double h,
                                double *fd_p, double *fd_dp) {
  int m = b->size(dim, order);
  double sp[MLS_MAX_DIM], sm[MLS_MAX_DIM];
  Eval plus, minus;
  memcpy(sp, s, dim * sizeof *s);
  memcpy(sm, s, dim * sizeof *s);
  sp[j] += h;
  sm[j] -= h;
  eval_basis(b, dim, order, sp, &plus);
  eval_basis(b, dim, order, sm, &minus);
  for (int a = 0; a < m; a++) fd_p[a] = (plus.p[a] - minus.p[a]) / (2.0 * h);
  for (int a = 0; a < dim * m; a++) fd_dp[a] = (plus.dp[a] - minus.dp[a]) / (2.0 * h);
}

/* ∂p/∂s_j against central differences of p, and ∂²p/∂s_i∂s_j against central differences of the analytic
 * ∂p/∂s_i along j (every (i, j), which also checks the packed index). With richardson, the differences
 * with steps h and h/2 are combined as (4 D(h/2) − D(h))/3, which cancels the h² error term; the bases
 * have degree ≤ 3 along each axis, so that term is the only one and the result is exact up to rounding. */
static void check_derivatives_at(const MlsBasisOps *b, int dim, int order, const double *s, double h,
                                 int richardson, double tol) {
  int m = b->size(dim, order);
  Eval e;
  eval_basis(b, dim, order, s, &e);
  for (int j = 0; j < dim; j++) {
    double fd_p[MAX_TERMS], fd_dp[MLS_MAX_DIM * MAX_TERMS];
    double half_p[MAX_TERMS], half_dp[MLS_MAX_DIM * MAX_TERMS];
    central_differences(b, dim, order, s, j, h, fd_p, fd_dp);
    if (richardson) {
      central_differences(b, dim, order, s, j, 0.5 * h, half_p, half_dp);
      for (int a = 0; a < m; a++) fd_p[a] = (4.0 * half_p[a] - fd_p[a]) / 3.0;
      for (int a = 0; a < dim * m; a++) fd_dp[a] = (4.0 * half_dp[a] - fd_dp[a]) / 3.0;
    }
    for (int a = 0; a < m; a++) {
      double exact = e.dp[j * m + a];
      assert_close(fd_p[a], exact, tol * (1.0 + fabs(exact)), "dp", b, dim, order, a);
      for (int i = 0; i < dim; i++) {
        exact = e.ddp[mls_hess_index(dim, i, j) * m + a];
        assert_close(fd_dp[i * m + a], exact, tol * (1.0 + fabs(exact)), "ddp", b, dim, order, a);
      }
    }
  }
}

/* Nothing is written past the m terms of p, the dim blocks of dp, the nhess blocks of ddp. */
static void check_bounds(const MlsBasisOps *b, int dim, int order, const double *s) {
  int m = b->size(dim, order);
  Eval e;
  eval_basis(b, dim, order, s, &e);
  for (int i = m; i < MAX_TERMS; i++) assert_true(e.p[i] == SENTINEL);
  for (int i = dim * m; i < MLS_MAX_DIM * MAX_TERMS; i++) assert_true(e.dp[i] == SENTINEL);
  for (int i = mls_num_hess(dim) * m; i < MLS_MAX_HESS * MAX_TERMS; i++) assert_true(e.ddp[i] == SENTINEL);
}

/* Values do not depend on whether derivatives are asked for (dp, ddp may be NULL). */
static void check_null_derivatives(const MlsBasisOps *b, int dim, int order, const double *s) {
  int m = b->size(dim, order);
  Eval e;
  double p[MAX_TERMS];
  eval_basis(b, dim, order, s, &e);
  b->eval(dim, order, s, p, NULL, NULL);
  for (int a = 0; a < m; a++) assert_true(p[a] == e.p[a]);
  b->eval(dim, order, s, p, e.dp, NULL);
  for (int a = 0; a < m; a++) assert_true(p[a] == e.p[a]);
}

static void test_derivatives_vs_fd(void **state) {
  (void)state;
  uint64_t rng = 0x9E3779B97F4A7C15ULL;
  for (int ib = 0; ib < 3; ib++) {
    const MlsBasisOps *b = all_bases[ib];
    for (int dim = 1; dim <= 3; dim++)
      for (int order = b->min_order; order <= b->max_order; order++)
        for (int k = 0; k < NUM_POINTS; k++) {
          double s[MLS_MAX_DIM];
          random_point(&rng, dim, s);
          check_derivatives_at(b, dim, order, s, FD_STEP, 0, FD_TOL);
          check_derivatives_at(b, dim, order, s, RICHARDSON_STEP, 1, RICHARDSON_TOL);
          check_bounds(b, dim, order, s);
          check_null_derivatives(b, dim, order, s);
        }
  }
}

/* ---- Pascal ---- */

static void test_pascal_at_origin(void **state) {
  (void)state;
  const double zero[MLS_MAX_DIM] = {0.0, 0.0, 0.0};
  for (int dim = 1; dim <= 3; dim++)
    for (int order = 0; order <= 3; order++) {
      Eval e;
      eval_basis(&mls_basis_pascal, dim, order, zero, &e);
      int m = mls_basis_pascal.size(dim, order);
      for (int a = 0; a < m; a++) assert_true(e.p[a] == (a == 0 ? 1.0 : 0.0));
    }
}

/* Each term is homogeneous: P_a(2s) = 2^deg P_a(s). The degrees must not decrease along the terms and
 * there must be C(deg + dim − 1, dim − 1) terms of each degree; the lower orders are leading parts. */
static void test_pascal_degree_order(void **state) {
  (void)state;
  const double s[MLS_MAX_DIM] = {0.31, -0.47, 0.23}, s2[MLS_MAX_DIM] = {0.62, -0.94, 0.46};
  for (int dim = 1; dim <= 3; dim++) {
    Eval e, e2, low;
    eval_basis(&mls_basis_pascal, dim, 3, s, &e);
    eval_basis(&mls_basis_pascal, dim, 3, s2, &e2);
    int count[4] = {0}, last = 0;
    for (int a = 0; a < mls_basis_pascal.size(dim, 3); a++) {
      int deg = (int)lround(log2(e2.p[a] / e.p[a]));
      assert_close(ldexp(e.p[a], deg), e2.p[a], 1e-15, "homogeneity", &mls_basis_pascal, dim, 3, a);
      assert_true(deg >= last && deg <= 3);
      last = deg;
      count[deg]++;
    }
    for (int deg = 0; deg <= 3; deg++) assert_int_equal(count[deg], binomial(deg + dim - 1, dim - 1));
    for (int order = 0; order < 3; order++) {
      eval_basis(&mls_basis_pascal, dim, order, s, &low);
      for (int a = 0; a < mls_basis_pascal.size(dim, order); a++) assert_true(low.p[a] == e.p[a]);
    }
  }
}

/* The documented order within a degree: lexicographic, x before y before z. */
static void test_pascal_values(void **state) {
  (void)state;
  const double x = 0.3, y = -0.7, z = 0.55, s[3] = {x, y, z};
  const double expect2[10] = {1, x, y, x * x, x * y, y * y, x * x * x, x * x * y, x * y * y, y * y * y};
  const double expect3[20] = {1,         x,         y,         z,         x * x,     x * y,     x * z,
                              y * y,     y * z,     z * z,     x * x * x, x * x * y, x * x * z, x * y * y,
                              x * y * z, x * z * z, y * y * y, y * y * z, y * z * z, z * z * z};
  const double expect1[4] = {1, x, x * x, x * x * x};
  Eval e;
  eval_basis(&mls_basis_pascal, 1, 3, s, &e);
  for (int a = 0; a < 4; a++) assert_close(expect1[a], e.p[a], 1e-15, "value", &mls_basis_pascal, 1, 3, a);
  eval_basis(&mls_basis_pascal, 2, 3, s, &e);
  for (int a = 0; a < 10; a++) assert_close(expect2[a], e.p[a], 1e-15, "value", &mls_basis_pascal, 2, 3, a);
  eval_basis(&mls_basis_pascal, 3, 3, s, &e);
  for (int a = 0; a < 20; a++) assert_close(expect3[a], e.p[a], 1e-15, "value", &mls_basis_pascal, 3, 3, a);
  /* Two derivatives by hand: ∂(x²y)/∂x = 2xy, ∂²(xyz)/∂y∂z (packed yz = 3) = x. */
  assert_close(2 * x * y, e.dp[0 * 20 + 11], 1e-15, "dp", &mls_basis_pascal, 3, 3, 11);
  assert_close(x, e.ddp[3 * 20 + 14], 1e-15, "ddp", &mls_basis_pascal, 3, 3, 14);
}

/* ---- Lagrange and Bernstein ---- */

/* At tensor node b, Lagrange term a is δ_ab. */
static void test_lagrange_kronecker(void **state) {
  (void)state;
  for (int dim = 1; dim <= 3; dim++)
    for (int order = 1; order <= 3; order++) {
      int m = mls_basis_lagrange.size(dim, order);
      for (int node = 0; node < m; node++) {
        double s[MLS_MAX_DIM];
        Eval e;
        tensor_node(dim, order, node, s);
        eval_basis(&mls_basis_lagrange, dim, order, s, &e);
        for (int a = 0; a < m; a++)
          assert_close(a == node ? 1.0 : 0.0, e.p[a], EXACT_TOL, "Kronecker", &mls_basis_lagrange, dim, order,
                       a);
      }
    }
}

/* Σ p = 1, Σ ∂p = 0, Σ ∂²p = 0 at random points. */
static void check_partition_of_unity(const MlsBasisOps *b) {
  uint64_t rng = 0xD1B54A32D192ED03ULL;
  for (int dim = 1; dim <= 3; dim++)
    for (int order = b->min_order; order <= b->max_order; order++)
      for (int k = 0; k < NUM_POINTS; k++) {
        double s[MLS_MAX_DIM];
        Eval e;
        random_point(&rng, dim, s);
        eval_basis(b, dim, order, s, &e);
        int m = b->size(dim, order);
        for (int blk = 0; blk < 1 + dim + mls_num_hess(dim); blk++) { /* p, then each ∂p, then each ∂²p */
          const double *v =
              blk == 0 ? e.p : (blk <= dim ? e.dp + (blk - 1) * m : e.ddp + (blk - 1 - dim) * m);
          double sum = 0.0;
          for (int a = 0; a < m; a++) sum += v[a];
          assert_close(blk == 0 ? 1.0 : 0.0, sum, EXACT_TOL, "partition of unity", b, dim, order, blk);
        }
      }
}

static void test_lagrange_partition_of_unity(void **state) {
  (void)state;
  check_partition_of_unity(&mls_basis_lagrange);
}

static void test_bernstein_partition_of_unity(void **state) {
  (void)state;
  check_partition_of_unity(&mls_basis_bernstein);
}

/* 0 ≤ B_a ≤ 1 on [−1, 1]^dim: at random points and on a grid that includes the faces and corners. */
static void test_bernstein_nonnegative(void **state) {
  (void)state;
  uint64_t rng = 0x2545F4914F6CDD1DULL;
  for (int dim = 1; dim <= 3; dim++)
    for (int order = 1; order <= 3; order++) {
      int m = mls_basis_bernstein.size(dim, order), grid = 1;
      for (int d = 0; d < dim; d++) grid *= 5;
      for (int k = 0; k < grid + 20; k++) {
        double s[MLS_MAX_DIM];
        Eval e;
        if (k < grid)
          for (int d = 0, g = k; d < dim; d++, g /= 5) s[d] = -1.0 + 0.5 * (g % 5);
        else
          random_point(&rng, dim, s);
        eval_basis(&mls_basis_bernstein, dim, order, s, &e);
        for (int a = 0; a < m; a++) assert_true(e.p[a] >= 0.0 && e.p[a] <= 1.0);
      }
    }
}

/* Lagrange interpolation reproduces its tensor space exactly: f(s) = Σ_k f(node_k) L_k(s) and likewise
 * for ∂f, ∂²f. Applied to every Bernstein term (same space) and every Pascal term of degree ≤ order (a
 * subspace), at generic points. A term outside the space, or a wrong derivative, fails. */
static void check_in_lagrange_space(const MlsBasisOps *b, int dim, int order, uint64_t *rng) {
  int m = mls_basis_lagrange.size(dim, order), mb = b->size(dim, order);
  static double at_nodes[MAX_TERMS][MAX_TERMS]; /* [node][term of b] */
  for (int k = 0; k < m; k++) {
    double s[MLS_MAX_DIM];
    Eval e;
    tensor_node(dim, order, k, s);
    eval_basis(b, dim, order, s, &e);
    for (int a = 0; a < mb; a++) at_nodes[k][a] = e.p[a];
  }
  int nvalues = 1 + dim + mls_num_hess(dim);
  for (int point = 0; point < m; point++) {
    double s[MLS_MAX_DIM];
    Eval lag, eb;
    random_point(rng, dim, s);
    eval_basis(&mls_basis_lagrange, dim, order, s, &lag);
    eval_basis(b, dim, order, s, &eb);
    for (int v = 0; v < nvalues; v++) { /* v = 0: value; 1..dim: gradient; then the Hessian */
      const double *L = v == 0 ? lag.p : (v <= dim ? lag.dp + (v - 1) * m : lag.ddp + (v - 1 - dim) * m);
      const double *B = v == 0 ? eb.p : (v <= dim ? eb.dp + (v - 1) * mb : eb.ddp + (v - 1 - dim) * mb);
      for (int a = 0; a < mb; a++) {
        double interp = 0.0;
        for (int k = 0; k < m; k++) interp += at_nodes[k][a] * L[k];
        assert_close(B[a], interp, EXACT_TOL * (1.0 + fabs(B[a])), "interpolated", b, dim, order, a);
      }
    }
  }
}

static void test_same_space(void **state) {
  (void)state;
  uint64_t rng = 0xBF58476D1CE4E5B9ULL;
  for (int dim = 1; dim <= 3; dim++)
    for (int order = 1; order <= 3; order++) {
      check_in_lagrange_space(&mls_basis_bernstein, dim, order, &rng);
      check_in_lagrange_space(&mls_basis_pascal, dim, order, &rng);
    }
}

/* The Bernstein end values: B_0(−1) = 1 and B_n(1) = 1 along each axis, so corner terms are 1 there. */
static void test_bernstein_corners(void **state) {
  (void)state;
  for (int dim = 1; dim <= 3; dim++)
    for (int order = 1; order <= 3; order++) {
      int m = mls_basis_bernstein.size(dim, order);
      double lo[MLS_MAX_DIM] = {-1.0, -1.0, -1.0}, hi[MLS_MAX_DIM] = {1.0, 1.0, 1.0};
      Eval e;
      eval_basis(&mls_basis_bernstein, dim, order, lo, &e);
      assert_true(e.p[0] == 1.0);
      eval_basis(&mls_basis_bernstein, dim, order, hi, &e);
      assert_true(e.p[m - 1] == 1.0);
    }
  /* 1-D cubic at s = 0 (t = 1/2): C(3,k)/8. */
  Eval e;
  const double s0 = 0.0;
  eval_basis(&mls_basis_bernstein, 1, 3, &s0, &e);
  const double expected[4] = {0.125, 0.375, 0.375, 0.125};
  for (int a = 0; a < 4; a++)
    assert_close(expected[a], e.p[a], 1e-16, "value", &mls_basis_bernstein, 1, 3, a);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_find),
      cmocka_unit_test(test_registries_give_choices_and_defaults),
      cmocka_unit_test(test_sizes),
      cmocka_unit_test(test_derivatives_vs_fd),
      cmocka_unit_test(test_pascal_at_origin),
      cmocka_unit_test(test_pascal_degree_order),
      cmocka_unit_test(test_pascal_values),
      cmocka_unit_test(test_lagrange_kronecker),
      cmocka_unit_test(test_lagrange_partition_of_unity),
      cmocka_unit_test(test_bernstein_partition_of_unity),
      cmocka_unit_test(test_bernstein_nonnegative),
      cmocka_unit_test(test_bernstein_corners),
      cmocka_unit_test(test_same_space),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
