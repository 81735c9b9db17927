/* Unit tests of Nitsche's method for first-order field models (src/bc/nitsche_field.c; docs/theory.md
 * §boundary methods), on a small 2-D box of quadratic MLS particles with one Dirichlet condition on its
 * left side (some components prescribed, nonzero values):
 * - the tangent of the boundary terms against central differences of their residual, K·v vs
 *   (R(u + εv) − R(u − εv)) / 2ε for random u and v: the small-strain Cosserat model (R is affine in u, so
 *   the difference is exact up to round-off: 1e-8 relative) and Cosserat with finite rotations at a state
 *   of large rotations and a nonzero boundary residual (the term from ∂D/∂q, itself a central difference:
 *   1e-5 relative);
 *   (without that term the defect is 0.3: the test sees it);
 * - the tangent is symmetric: max |K − Kᵀ| / max |K| ≤ 1e-12 (1e-9 with finite rotations, whose ∂D/∂q term
 *   is a difference quotient), so with the FD check the residual is the gradient of an energy;
 * - for the small-strain model the residual is affine with the tangent as its slope: R(u) − R(0) = K u to
 *   1e-10 relative for a random u of order 1.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/cosserat.h"
#include "mica/bc.h"
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

/* A [0, 2] × [0, 1] box, 7 × 5 particles, quadratic MLS; the Cosserat model (finite rotations if finite);
 * on the left side u_x = 0.01 y and φ_z = 0.02 + 0.01 y prescribed (u_y free) by Nitsche with α = 10. */
static void build(Fixture *f, int finite) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {0, 0}, .upper = {2, 1}};
  const MicaLayoutSpec layout = {.kind = MICA_LAYOUT_REGULAR, .count = {7, 5}, .grading = {1, 1, 1}};
  const MicaCellSpec cells = {.order = 4};
  check_ok(mica_discretization_create(&shape, &layout, &cells, &f->disc));
  MlsOptions mo;
  mls_options_default(&mo);
  mo.order = 2, mo.dilation = 3.0;
  check_ok(mls_create(2, f->disc->nparticles, f->disc->x, &mo, &f->mls));
  MicaSolidOptions opt;
  memset(&opt, 0, sizeof opt);
  check_ok(mica_cosserat_set_technical(&opt.field, 2, 1000.0, 0.3, 0.7, 0.3, 0.3, 1.0));
  if (finite) check_ok(mica_cosserat_finite_set(&opt.field));
  opt.bc_method = &mica_bc_nitsche;
  opt.bc_alpha = 10.0;
  opt.basis_order = 2;
  MicaDirichlet *dir = calloc(1, sizeof *dir);
  assert_non_null(dir);
  dir->set = mica_discretization_find_set(f->disc, "left");
  assert_true(dir->set >= 0);
  dir->mask = (1 << 0) | (1 << 2);
  check_ok(mica_function_create("0.01*y", 0, NULL, NULL, &dir->value[0]));
  check_ok(mica_function_create("0.02 + 0.01*y", 0, NULL, NULL, &dir->value[2]));
  strcpy(dir->where, "test");
  const MicaApprox approx = {&mica_approx_mls, f->mls};
  check_ok(mica_solid_create(f->disc, &approx, &opt, 1, dir, 0, NULL, &f->solid));
}

static void release(Fixture *f) {
  mica_solid_destroy(&f->solid);
  mls_destroy(&f->mls);
  mica_discretization_destroy(&f->disc);
}

/* The boundary method's residual (and tangent into s->K if K) alone. */
static void boundary_terms(MicaSolid *s, const double *u, double *R, int with_tangent) {
  memset(R, 0, sizeof(double) * (size_t)s->ndof);
  if (with_tangent) mica_sparse_zero(s->K);
  check_ok(s->opt.bc_method->add(s, &s->dirichlet[0], 1.0, u, R, with_tangent ? s->K : NULL));
}

static double norm_inf(long n, const double *v) {
  double m = 0;
  for (long i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

/* Largest |K v − FD(R) v| / |K v| over three random directions, at the state u. */
static double tangent_defect(MicaSolid *s, const double *u, double step, uint64_t *seed) {
  const long n = s->ndof;
  double *R = malloc(sizeof(double) * (size_t)n), *Rp = malloc(sizeof(double) * (size_t)n),
         *Rm = malloc(sizeof(double) * (size_t)n), *v = malloc(sizeof(double) * (size_t)n),
         *up = malloc(sizeof(double) * (size_t)n), *Kv = malloc(sizeof(double) * (size_t)n);
  assert_true(R && Rp && Rm && v && up && Kv);
  boundary_terms(s, u, R, 1);
  double worst = 0;
  for (int trial = 0; trial < 3; trial++) {
    for (long i = 0; i < n; i++) v[i] = rnd(seed);
    mica_sparse_matvec(s->K, v, Kv);
    for (long i = 0; i < n; i++) up[i] = u[i] + step * v[i];
    boundary_terms(s, up, Rp, 0);
    for (long i = 0; i < n; i++) up[i] = u[i] - step * v[i];
    boundary_terms(s, up, Rm, 0);
    double diff = 0;
    for (long i = 0; i < n; i++) diff = fmax(diff, fabs((Rp[i] - Rm[i]) / (2 * step) - Kv[i]));
    worst = fmax(worst, diff / norm_inf(n, Kv));
  }
  free(R), free(Rp), free(Rm), free(v), free(up), free(Kv);
  return worst;
}

/* max |K − Kᵀ| / max |K| of the boundary terms' tangent at u. */
static double tangent_asymmetry(MicaSolid *s, const double *u) {
  double *R = malloc(sizeof(double) * (size_t)s->ndof);
  assert_non_null(R);
  boundary_terms(s, u, R, 1);
  free(R);
  return mica_sparse_asymmetry(s->K);
}

static void random_state(const MicaSolid *s, double amplitude, uint64_t *seed, double *u) {
  for (long i = 0; i < s->ndof; i++) u[i] = amplitude * rnd(seed);
}

/* The tangent at a random state of the given amplitude against central differences of step h, and its symmetry. */
static void check_tangent(int finite, double amplitude, double h, uint64_t seed, double defect_tol, double asym_tol,
                          const char *label) {
  Fixture f;
  build(&f, finite);
  double *u = malloc(sizeof(double) * (size_t)f.solid->ndof);
  assert_non_null(u);
  random_state(f.solid, amplitude, &seed, u);
  const double defect = tangent_defect(f.solid, u, h, &seed), asym = tangent_asymmetry(f.solid, u);
  print_message("%s: tangent vs central differences %.2e, asymmetry %.2e\n", label, defect, asym);
  assert_true(defect < defect_tol);
  assert_true(asym < asym_tol);
  free(u);
  release(&f);
}

static void test_small_strain_tangent(void **state) {
  (void)state;
  check_tangent(0, 0.05, 1e-3, 11, 1e-8, 1e-12, "small-strain Cosserat");
}

/* R(u) − R(0) = K u: the residual is affine with the tangent as its slope (the small-strain model). */
static void test_small_strain_affine(void **state) {
  (void)state;
  Fixture f;
  build(&f, 0);
  MicaSolid *s = f.solid;
  const long n = s->ndof;
  uint64_t seed = 5;
  double *u = malloc(sizeof(double) * (size_t)n), *R = malloc(sizeof(double) * (size_t)n),
         *R0 = malloc(sizeof(double) * (size_t)n), *zero = calloc((size_t)n, sizeof(double)),
         *Ku = malloc(sizeof(double) * (size_t)n);
  assert_true(u && R && R0 && zero && Ku);
  random_state(s, 1.0, &seed, u);
  boundary_terms(s, zero, R0, 1);
  mica_sparse_matvec(s->K, u, Ku);
  boundary_terms(s, u, R, 0);
  double diff = 0;
  for (long i = 0; i < n; i++) diff = fmax(diff, fabs(R[i] - R0[i] - Ku[i]));
  print_message("small-strain Cosserat: |R(u) - R(0) - K u| / |K u| = %.2e\n", diff / norm_inf(n, Ku));
  assert_true(diff / norm_inf(n, Ku) < 1e-10);
  free(u), free(R), free(R0), free(zero), free(Ku);
  release(&f);
}

/* Finite rotations: at rotations of order 1 rad the Nitsche residual has a nonzero r, and the tangent includes
 * the ∂D/∂q term. */
static void test_finite_tangent(void **state) {
  (void)state;
  check_tangent(1, 0.5, 1e-5, 23, 1e-5, 1e-9, "finite-rotation Cosserat");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_small_strain_tangent),
      cmocka_unit_test(test_small_strain_affine),
      cmocka_unit_test(test_finite_tangent),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
