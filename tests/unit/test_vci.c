/* Unit tests of variationally consistent integration (src/assemble/vci.c; docs/theory.md §VCI) and of the
 * boundary-coverage count it relies on (src/geom/mesh.c).
 *
 * After mica_vci_correct, every particle I satisfies the discrete divergence identity
 *   Σ_vol w (∇̃_d N_I p + N_I ∂_d p) = Σ_∂Ω w N_I p n_d
 * for every monomial p of degree ≤ n − 1 (n the basis order), in global coordinates (the implementation
 * works in each particle's local ones), to 1e-12 relative to Σ_vol w (|∇̃_d N_I p| + |N_I ∂_d p|) +
 * Σ_∂Ω w |N_I p n_d|: 2-D and 3-D boxes on regular and jittered particles, a jittered annulus sector (curved
 * boundary, mapped cells) and a jittered cylinder, bases of order 1, 2 (and 3 in 2-D). The uncorrected
 * gradients violate it (the largest relative defect is printed and must exceed 1e-9, so the test can tell a
 * correction from none). The MLS gradients themselves are left as they were (the trial functions).
 * Coverage: the shipped square mesh of quadrangles covers its boundary (0 faces uncovered); with the
 * bottom curve's physical group removed, or given a second group, exactly its edges count as uncovered, and
 * mica_vci_correct refuses with MICA_ERR_INPUT.
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

#include "mica/solid.h"

#define PI 3.14159265358979323846

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

/* ---- the identity, measured independently of vci.c ---- */

/* Global monomial x^e0 y^e1 z^e2 and its derivative along d. */
static double monomial(const int *e, const double *x, int dim) {
  double v = 1.0;
  for (int k = 0; k < dim; k++) v *= pow(x[k], e[k]);
  return v;
}

static double monomial_derivative(const int *e, const double *x, int dim, int d) {
  if (e[d] == 0) return 0.0;
  double v = e[d] * pow(x[d], e[d] - 1);
  for (int k = 0; k < dim; k++)
    if (k != d) v *= pow(x[k], e[k]);
  return v;
}

/* Exponents of the monomials of degree ≤ degree. */
static int exponents(int dim, int degree, int e[][3]) {
  int m = 0;
  for (int i = 0; i <= degree; i++)
    for (int j = 0; i + j <= degree; j++)
      for (int k = 0; i + j + k <= degree; k++) {
        if (dim == 2 && k) continue;
        e[m][0] = i, e[m][1] = j, e[m][2] = k, m++;
      }
  return m;
}

/* Largest relative defect of the identity over particles, directions and monomials, with gradients dN. */
static double identity_defect(const MicaDiscretization *disc, const MlsApprox *mls, const MicaShapeCache *vol,
                              const double *dN, int degree) {
  const int dim = disc->dim;
  const long np = disc->nparticles;
  int e[10][3];
  const int m = exponents(dim, degree, e);
  double *sum = calloc((size_t)(np * dim * m), sizeof *sum), *scale = calloc((size_t)(np * dim * m), sizeof *scale);
  assert_non_null(sum);
  assert_non_null(scale);
  for (long p = 0; p < vol->npoints; p++) {
    const double *x = disc->qx + p * dim, w = disc->qw[p];
    for (long k = vol->ptr[p]; k < vol->ptr[p + 1]; k++)
      for (int d = 0; d < dim; d++)
        for (int a = 0; a < m; a++) {
          const double t1 = w * dN[k * dim + d] * monomial(e[a], x, dim);
          const double t2 = w * vol->N[k] * monomial_derivative(e[a], x, dim, d);
          const long i = (vol->index[k] * dim + d) * m + a;
          sum[i] += t1 + t2;
          scale[i] += fabs(t1) + fabs(t2);
        }
  }
  for (int s = 0; s < disc->nsets; s++) {
    const MicaBoundarySet *set = &disc->sets[s];
    MicaShapeCache *b = NULL;
    check_ok(mica_shape_cache_create(mls, set->n, set->x, 1, "boundary", &b));
    for (long p = 0; p < set->n; p++)
      for (long k = b->ptr[p]; k < b->ptr[p + 1]; k++)
        for (int d = 0; d < dim; d++)
          for (int a = 0; a < m; a++) {
            const double t = set->w[p] * b->N[k] * monomial(e[a], set->x + p * dim, dim) * set->normal[p * dim + d];
            const long i = (b->index[k] * dim + d) * m + a;
            sum[i] -= t;
            scale[i] += fabs(t);
          }
    mica_shape_cache_destroy(&b);
  }
  double worst = 0.0;
  for (long i = 0; i < np * dim * m; i++)
    if (scale[i] > 0) worst = fmax(worst, fabs(sum[i]) / scale[i]);
  free(sum);
  free(scale);
  return worst;
}

/* Builds the discretization, MLS and volume cache; corrects; checks the identity before and after. */
static void check_shape(const char *name, const MicaShapeSpec *shape, const MicaLayoutSpec *layout, int cells_order,
                        int order, double dilation) {
  const MicaCellSpec cells = {.order = cells_order};
  MicaDiscretization *disc = NULL;
  MlsApprox *mls = NULL;
  MicaShapeCache *vol = NULL;
  MlsOptions opt;
  check_ok(mica_discretization_create(shape, layout, &cells, &disc));
  mls_options_default(&opt);
  opt.order = order, opt.dilation = dilation;
  check_ok(mls_create(disc->dim, disc->nparticles, disc->x, &opt, &mls));
  check_ok(mica_shape_cache_create(mls, disc->nquad, disc->qx, 1, "volume", &vol));
  const long nnz = vol->ptr[vol->npoints];
  double *dN_before = malloc(sizeof(double) * (size_t)(nnz * disc->dim));
  assert_non_null(dN_before);
  memcpy(dN_before, vol->dN, sizeof(double) * (size_t)(nnz * disc->dim));
  const double before = identity_defect(disc, mls, vol, vol->dN, order - 1);
  check_ok(mica_vci_correct(disc, mls, order, vol));
  assert_non_null(vol->dN_test);
  const double after = identity_defect(disc, mls, vol, vol->dN_test, order - 1);
  print_message("%-28s order %d: %ld particles, identity defect %.2e without VCI, %.2e with\n", name, order,
                disc->nparticles, before, after);
  assert_true(after <= 1e-12);
  assert_true(before > 1e-9);
  assert_memory_equal(dN_before, vol->dN, sizeof(double) * (size_t)(nnz * disc->dim)); /* trial untouched */
  free(dN_before);
  mica_shape_cache_destroy(&vol);
  mls_destroy(&mls);
  mica_discretization_destroy(&disc);
}

static MicaLayoutSpec layout_of(MicaLayoutKind kind, long n0, long n1, long n2) {
  return (MicaLayoutSpec){.kind = kind, .count = {n0, n1, n2}, .jitter = 0.3, .grading = {1, 1, 1}, .seed = 7};
}

static void test_box_2d(void **state) {
  (void)state;
  const MicaShapeSpec box = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {-1, -1}, .upper = {1, 2}};
  for (int order = 1; order <= 3; order++) {
    MicaLayoutSpec regular = layout_of(MICA_LAYOUT_REGULAR, 9, 11, 0), jittered = layout_of(MICA_LAYOUT_JITTERED, 9, 11, 0);
    check_shape("box 2-D, regular", &box, &regular, 3, order, order + 1.2);
    check_shape("box 2-D, jittered", &box, &jittered, 3, order, order + 1.2);
  }
}

static void test_box_3d(void **state) {
  (void)state;
  const MicaShapeSpec box = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {1, 1, 2}};
  for (int order = 1; order <= 2; order++) {
    MicaLayoutSpec regular = layout_of(MICA_LAYOUT_REGULAR, 5, 5, 7), jittered = layout_of(MICA_LAYOUT_JITTERED, 5, 5, 7);
    check_shape("box 3-D, regular", &box, &regular, 2, order, order + 1.2);
    check_shape("box 3-D, jittered", &box, &jittered, 2, order, order + 1.2);
  }
}

static void test_curved(void **state) {
  (void)state;
  const MicaShapeSpec annulus = {
      .kind = MICA_SHAPE_ANNULUS, .dim = 2, .r_inner = 1, .r_outer = 2, .theta0 = 0, .theta1 = 0.5 * PI};
  const MicaShapeSpec cylinder = {.kind = MICA_SHAPE_CYLINDER, .dim = 3, .radius = 1, .height = 1.5};
  for (int order = 1; order <= 2; order++) {
    MicaLayoutSpec a = layout_of(MICA_LAYOUT_JITTERED, 7, 11, 0), c = layout_of(MICA_LAYOUT_JITTERED, 5, 5, 5);
    check_shape("annulus, jittered", &annulus, &a, 3, order, order + 1.2);
    check_shape("cylinder, jittered", &cylinder, &c, 2, order, order + 1.2);
  }
}

/* ---- coverage of a Gmsh mesh's boundary by its sets ---- */

static MicaDiscretization *load_mesh(const char *path) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_GMSH, .mesh_path = path};
  const MicaLayoutSpec layout = {0};
  const MicaCellSpec cells = {.order = 2};
  MicaDiscretization *disc = NULL;
  check_ok(mica_discretization_create(&shape, &layout, &cells, &disc));
  return disc;
}

/* A copy of square_quads.msh with the bottom curve's entity line replaced; returns the path. */
static void write_variant(const char *replacement, char *path, size_t size) {
  FILE *in = fopen("tests/meshes/square_quads.msh", "rb");
  assert_non_null(in);
  static char text[1 << 16];
  const size_t n = fread(text, 1, sizeof text - 1, in);
  fclose(in);
  text[n] = '\0';
  const char *line = "\n1 0 0 0 1 0 0 1 1 2 1 -2 \n";
  char *at = strstr(text, line);
  assert_non_null(at);
  snprintf(path, size, "/tmp/mica_test_vci_%d.msh", (int)getpid());
  FILE *out = fopen(path, "wb");
  assert_non_null(out);
  fwrite(text, 1, (size_t)(at - text), out);
  fputs(replacement, out);
  fputs(at + strlen(line), out);
  fclose(out);
}

static void test_mesh_coverage(void **state) {
  (void)state;
  MicaDiscretization *disc = load_mesh("tests/meshes/square_quads.msh");
  assert_int_equal(disc->boundary_uncovered, 0);
  const long bottom_edges = disc->sets[mica_discretization_find_set(disc, "bottom")].nelements;
  assert_true(bottom_edges > 0);
  mica_discretization_destroy(&disc);
  const char *variants[2] = {"\n1 0 0 0 1 0 0 0 2 1 -2 \n",      /* the bottom in no group */
                             "\n1 0 0 0 1 0 0 2 1 2 2 1 -2 \n"}; /* in "bottom" and "right" */
  for (int v = 0; v < 2; v++) {
    char path[128];
    write_variant(variants[v], path, sizeof path);
    disc = load_mesh(path);
    assert_int_equal(disc->boundary_uncovered, bottom_edges);
    MlsOptions opt;
    MlsApprox *mls = NULL;
    MicaShapeCache *vol = NULL;
    mls_options_default(&opt);
    opt.dilation = 2.2;
    check_ok(mls_create(disc->dim, disc->nparticles, disc->x, &opt, &mls));
    check_ok(mica_shape_cache_create(mls, disc->nquad, disc->qx, 1, "volume", &vol));
    const int ierr = mica_vci_correct(disc, mls, 1, vol);
    assert_int_equal(ierr, MICA_ERR_INPUT);
    assert_non_null(strstr(mica_error_message(), "cover the whole boundary"));
    mica_error_clear();
    mica_shape_cache_destroy(&vol);
    mls_destroy(&mls);
    mica_discretization_destroy(&disc);
    remove(path);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_box_2d),
      cmocka_unit_test(test_box_3d),
      cmocka_unit_test(test_curved),
      cmocka_unit_test(test_mesh_coverage),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
