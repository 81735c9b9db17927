/* Unit tests of boundary collocation (src/bc/collocation.c; docs/theory.md §boundary methods), on a small 2-D
 * box of linear MLS particles, Neo-Hooke, with u_x = 0.01 y and u_y = −0.02 x prescribed on the left side:
 * - the whole residual's tangent (volume terms, then the replaced rows) against central differences,
 *   K·v vs (R(u + εv) − R(u − εv)) / 2ε for random u and v: 1e-6 relative (Neo-Hooke's own terms are
 *   nonlinear; without the replacement of the rows of K the defect is O(1): the test sees it);
 * - a replaced row is exactly the collocated condition: R_(I,a) = s_I (Σ_J N_J(x_I) u_Ja − ū_a(x_I)) with
 *   s_I = E h_I^(dim−2) (2-D: E) to 1e-12, and K's row (I, a) holds s_I N_J(x_I) in columns (J, a), nothing else;
 * - every collocated particle stands at a vertex of the set (x = 0), one per vertex;
 * - a non-prescribed component (u_y when only u_x is given) keeps its Galerkin row.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/bc.h"
#include "mica/solid.h"
#include "field_check.h"

static void check_ok(int ierr) {
  if (ierr != MICA_SUCCESS) {
    print_error("unexpected error %d: %s\n", ierr, mica_error_message());
    fail();
  }
}

typedef struct {
  MicaDiscretization *disc;
  MlsApprox *mls;
  MicaSolid *solid;
} Fixture;

/* [0, 2] × [0, 1], 9 × 5 particles, linear MLS (dilation 2), Neo-Hooke E = 100, ν = 0.3 plane strain;
 * collocation on 'left' of the components in mask (bit 0: u_x = 0.01 y, bit 1: u_y = −0.02 x). */
static void build(Fixture *f, int mask) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {0, 0}, .upper = {2, 1}};
  const MicaLayoutSpec layout = {.kind = MICA_LAYOUT_REGULAR, .count = {9, 5}, .grading = {1, 1, 1}};
  const MicaCellSpec cells = {.order = 3};
  check_ok(mica_discretization_create(&shape, &layout, &cells, &f->disc));
  MlsOptions mo;
  mls_options_default(&mo);
  mo.order = 1, mo.dilation = 2.0;
  check_ok(mls_create(2, f->disc->nparticles, f->disc->x, &mo, &f->mls));
  MicaSolidOptions opt;
  memset(&opt, 0, sizeof opt);
  MicaMaterial material;
  check_ok(mica_material_set(&mica_model_neohooke, 100.0, 0.3, MICA_PLANE_STRAIN, &material));
  check_ok(mica_field_classical_set(&opt.field, &mica_model_neohooke, &material));
  opt.bc_method = &mica_bc_collocation;
  opt.basis_order = 1;
  MicaDirichlet *dir = calloc(1, sizeof *dir);
  assert_non_null(dir);
  dir->set = mica_discretization_find_set(f->disc, "left");
  assert_true(dir->set >= 0);
  dir->mask = mask;
  if (mask & 1) check_ok(mica_function_create("0.01*y", 0, NULL, NULL, &dir->value[0]));
  if (mask & 2) check_ok(mica_function_create("-0.02*x", 0, NULL, NULL, &dir->value[1]));
  strcpy(dir->where, "test");
  const MicaApprox approx = {&mica_approx_mls, f->mls};
  check_ok(mica_solid_create(f->disc, &approx, &opt, 1, dir, 0, NULL, &f->solid));
}

static void release(Fixture *f) {
  mica_solid_destroy(&f->solid);
  mls_destroy(&f->mls);
  mica_discretization_destroy(&f->disc);
}

static double *vector(long n) {
  double *v = calloc((size_t)n, sizeof *v);
  assert_non_null(v);
  return v;
}

static void random_state(long n, double amplitude, uint64_t *seed, double *u) {
  for (long i = 0; i < n; i++) u[i] = amplitude * rnd(seed);
}

static double norm_inf(long n, const double *v) {
  double m = 0;
  for (long i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

static void test_tangent(void **state) {
  (void)state;
  Fixture f;
  build(&f, 3);
  MicaSolid *s = f.solid;
  const long n = s->ndof;
  double *u = vector(n), *R = vector(n), *Rp = vector(n), *Rm = vector(n), *v = vector(n), *w = vector(n),
         *Kv = vector(n);
  uint64_t seed = 5;
  random_state(n, 0.02, &seed, u);
  check_ok(mica_solid_assemble(s, 1.0, u, R, s->K));
  const double step = 1e-6;
  double worst = 0;
  for (int trial = 0; trial < 3; trial++) {
    random_state(n, 1.0, &seed, v);
    mica_sparse_matvec(s->K, v, Kv);
    for (long i = 0; i < n; i++) w[i] = u[i] + step * v[i];
    check_ok(mica_solid_assemble(s, 1.0, w, Rp, NULL));
    for (long i = 0; i < n; i++) w[i] = u[i] - step * v[i];
    check_ok(mica_solid_assemble(s, 1.0, w, Rm, NULL));
    double diff = 0;
    for (long i = 0; i < n; i++) diff = fmax(diff, fabs((Rp[i] - Rm[i]) / (2 * step) - Kv[i]));
    worst = fmax(worst, diff / norm_inf(n, Kv));
  }
  print_message("collocation + Neo-Hooke: tangent vs central differences %.2e\n", worst);
  assert_true(worst < 1e-6);
  free(u), free(R), free(Rp), free(Rm), free(v), free(w), free(Kv);
  release(&f);
}

/* The stored entry (i, j) of K, or 0. */
static double entry(const MicaSparse *K, long i, long j) {
  for (long p = K->colptr[j]; p < K->colptr[j + 1]; p++)
    if (K->rowind[p] == i) return K->val[p];
  return 0.0;
}

static void test_rows(void **state) {
  (void)state;
  Fixture f;
  build(&f, 1); /* u_x only */
  MicaSolid *s = f.solid;
  const long n = s->ndof;
  const MicaShapeCache *c = s->collocation[0];
  assert_int_equal(c->npoints, 5); /* the 5 particles of x = 0 */
  double *u = vector(n), *R = vector(n);
  uint64_t seed = 9;
  random_state(n, 0.02, &seed, u);
  check_ok(mica_solid_assemble(s, 1.0, u, R, s->K));
  for (long v = 0; v < c->npoints; v++) {
    const long I = s->collocation_particle[0][v];
    assert_true(fabs(f.disc->x[I * 2]) < 1e-14 && fabs(f.disc->x[I * 2 + 1] - c->x[v * 2 + 1]) < 1e-14);
    assert_true(fabs(s->collocation_scale[0][v] - 100.0) < 1e-12); /* E h^0 */
    double uh = 0;
    for (long e = c->ptr[v]; e < c->ptr[v + 1]; e++) uh += c->N[e] * u[c->index[e] * 2];
    const double expected = 100.0 * (uh - 0.01 * c->x[v * 2 + 1]);
    assert_true(fabs(R[I * 2] - expected) <= 1e-12 * fmax(1.0, fabs(expected)));
    /* row (I, x): s N_J(x_I) in columns (J, x), zero elsewhere */
    long stored = 0;
    for (long j = 0; j < n; j++) {
      const double value = entry(s->K, I * 2, j);
      if (value == 0.0) continue;
      stored++;
      long e = c->ptr[v];
      while (e < c->ptr[v + 1] && c->index[e] * 2 != j) e++;
      assert_true(e < c->ptr[v + 1]);
      assert_true(fabs(value - 100.0 * c->N[e]) < 1e-12);
    }
    assert_true(stored <= c->ptr[v + 1] - c->ptr[v]);
    /* the free component u_y keeps its Galerkin row: it couples to u_x of neighbors through the volume */
    long coupled = 0;
    for (long j = 0; j < n; j++) coupled += entry(s->K, I * 2 + 1, j) != 0.0;
    assert_true(coupled > c->ptr[v + 1] - c->ptr[v]);
  }
  free(u), free(R);
  release(&f);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_tangent), cmocka_unit_test(test_rows)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
