/* Unit tests of the cell pressure (material.pressure = cell-constant, src/assemble/pressure.c; docs/theory.md
 * §Nearly incompressible solids), for every classical model of the registry that has plane strain and 3-D
 * (all of them), for each pressure type with cells (cell-constant, cell-linear), on a small box of MLS particles whose background cells hold 2 × 2 particle spacings:
 * - the residual against central differences of the energy Π = Σ_q w W(F̄_q): R·v vs (Π(u + εv) − Π(u − εv))/2ε;
 * - the tangent against central differences of the residual: K v vs (R(u + εv) − R(u − εv))/2ε, three random v;
 * - the tangent is symmetric (max |K − Kᵀ| / max |K| ≤ 1e-12): the cell tangent is a Hessian;
 * - a uniform dilatation F = (1 + e) I, which every cell's projection reproduces, has Θ_c = j(F) in every cell and
 *   the same energy as the displacement form (F̄ = F), and the cells tile the body (Σ V_c = area);
 * - the cells' point lists (6 cells of 9 points).
 * Tolerances: 1e-6 relative for the central differences (step 1e-6 on states of amplitude 0.05: truncation
 * ~ε² ‖∂³Π‖ ≈ 1e-12, round-off ~1e-16/ε ≈ 1e-10 of the largest entries).
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

/* A box of 7 × 5 (× 4) particles, cells of 2 × 2 (× 1) spacings, MLS of the given order; the classical model,
 * E = 1, ν = 0.45, plane strain; the pressure space given; no conditions (the volume terms alone). */
static void build(Fixture *f, int dim, int order, const MicaModelOps *model, const MicaPressureOps *pressure) {
  const MicaShapeSpec shape = {.kind = MICA_SHAPE_BOX, .dim = dim, .lower = {0, 0, 0}, .upper = {2, 1, 1}};
  const MicaLayoutSpec layout = {.kind = MICA_LAYOUT_REGULAR, .count = {7, 5, 4}, .grading = {1, 1, 1}};
  const MicaCellSpec cells = {.order = 3, .count = {3, 2, 3}};
  check_ok(mica_discretization_create(&shape, &layout, &cells, &f->disc));
  MlsOptions mo;
  mls_options_default(&mo);
  mo.order = order, mo.dilation = order + 1.5;
  check_ok(mls_create(dim, f->disc->nparticles, f->disc->x, &mo, &f->mls));
  MicaSolidOptions opt;
  memset(&opt, 0, sizeof opt);
  MicaMaterial mat;
  check_ok(mica_material_set(model, 1.0, 0.45, dim == 2 ? MICA_PLANE_STRAIN : MICA_PLANE_NONE, &mat));
  check_ok(mica_field_classical_set(&opt.field, model, &mat));
  opt.bc_method = &mica_bc_penalty;
  opt.bc_alpha = 1.0;
  opt.basis_order = order;
  opt.pressure = pressure;
  const MicaApprox approx = {&mica_approx_mls, f->mls};
  check_ok(mica_solid_create(f->disc, &approx, &opt, 0, NULL, 0, NULL, &f->solid));
}

static void release(Fixture *f) {
  mica_solid_destroy(&f->solid);
  mls_destroy(&f->mls);
  mica_discretization_destroy(&f->disc);
}

static double norm_inf(long n, const double *v) {
  double m = 0;
  for (long i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

static double dot(long n, const double *a, const double *b) {
  double s = 0;
  for (long i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

typedef struct {
  double residual, tangent, asymmetry;
} Defects;

/* At a random state of amplitude 0.05: the residual against the energy, the tangent against the residual. */
static Defects defects(MicaSolid *s, uint64_t *seed) {
  const long n = s->ndof;
  const double step = 1e-6;
  double *u = calloc((size_t)n, sizeof(double)), *R = calloc((size_t)n, sizeof(double)),
         *Rp = calloc((size_t)n, sizeof(double)), *Rm = calloc((size_t)n, sizeof(double)),
         *v = calloc((size_t)n, sizeof(double)), *up = calloc((size_t)n, sizeof(double)),
         *Kv = calloc((size_t)n, sizeof(double));
  assert_true(u && R && Rp && Rm && v && up && Kv);
  for (long i = 0; i < n; i++) u[i] = 0.05 * rnd(seed);
  check_ok(mica_solid_assemble(s, 0.0, u, R, s->K));
  Defects d = {0, 0, mica_sparse_asymmetry(s->K)};
  for (int trial = 0; trial < 3; trial++) {
    for (long i = 0; i < n; i++) v[i] = rnd(seed);
    mica_sparse_matvec(s->K, v, Kv);
    double Ep, Em;
    for (long i = 0; i < n; i++) up[i] = u[i] + step * v[i];
    check_ok(mica_pressure_energy(s, up, &Ep));
    check_ok(mica_solid_assemble(s, 0.0, up, Rp, NULL));
    for (long i = 0; i < n; i++) up[i] = u[i] - step * v[i];
    check_ok(mica_pressure_energy(s, up, &Em));
    check_ok(mica_solid_assemble(s, 0.0, up, Rm, NULL));
    const double Rv = dot(n, R, v);
    d.residual = fmax(d.residual, fabs((Ep - Em) / (2 * step) - Rv) / fabs(Rv));
    double diff = 0;
    for (long i = 0; i < n; i++) diff = fmax(diff, fabs((Rp[i] - Rm[i]) / (2 * step) - Kv[i]));
    d.tangent = fmax(d.tangent, diff / norm_inf(n, Kv));
  }
  free(u), free(R), free(Rp), free(Rm), free(v), free(up), free(Kv);
  return d;
}

/* Every pressure type with cells (the registry's flag) × every classical model × 2-D, 3-D × orders 1, 2. */
static void test_registry_derivatives(void **state) {
  (void)state;
  uint64_t seed = 21;
  int checked = 0;
  for (int t = 0; mica_registry_type(&mica_pressure_registry, t); t++) {
    const MicaType *type = mica_registry_type(&mica_pressure_registry, t);
    if (!mica_type_has(type, MICA_PRESSURE_CELLS)) continue;
    for (int i = 0; mica_model_at(i); i++) {
      const MicaModelOps *model = mica_model_at(i);
      for (int dim = 2; dim <= 3; dim++)
        for (int order = 1; order <= 2; order++) {
          Fixture f;
          build(&f, dim, order, model, (const MicaPressureOps *)type);
          const Defects d = defects(f.solid, &seed);
          print_message("%-13s %-13s %d-D order %d: residual vs energy %.2e, tangent vs residual %.2e, asymmetry "
                        "%.2e (%ld cells)\n", type->name, model->type.name, dim, order, d.residual, d.tangent,
                        d.asymmetry, f.solid->npcells);
          assert_true(d.residual < 1e-6);
          assert_true(d.tangent < 1e-6);
          assert_true(d.asymmetry < 1e-12);
          release(&f);
          checked++;
        }
    }
  }
  assert_true(checked >= 32); /* two cell types, the four built-in models, 2-D and 3-D, orders 1 and 2 */
}

/* Θ_c is the cell's weighted mean of j(F) at its points; and a uniform dilatation gives F̄ = F. */
static void test_uniform_dilatation(void **state) {
  (void)state;
  for (int i = 0; mica_model_at(i); i++) {
    const MicaModelOps *model = mica_model_at(i);
    Fixture f, g;
    build(&f, 2, 2, model, &mica_pressure_cell_linear);
    build(&g, 2, 2, model, &mica_pressure_none);
    const long np = f.disc->nparticles;
    double *u = calloc((size_t)f.solid->ndof, sizeof(double));
    assert_non_null(u);
    const double e = 0.03; /* u = e x: a quadratic basis reproduces it, so F = (1 + e) I at every point */
    for (long I = 0; I < np; I++)
      for (int a = 0; a < 2; a++) u[I * 2 + a] = e * f.disc->x[I * 2 + a];
    double Ef, theta, V, total = 0;
    check_ok(mica_pressure_energy(f.solid, u, &Ef));
    const int finite = mica_type_has(&model->type, MICA_MODEL_FINITE_STRAIN);
    for (long c = 0; c < f.solid->npcells; c++) {
      mica_pressure_cell_dilatation(f.solid, c, u, &theta, &V);
      const double expect = finite ? (1 + e) * (1 + e) : 2 * e;
      assert_true(fabs(theta - expect) < 1e-10);
      total += V;
    }
    assert_true(fabs(total - 2.0) < 1e-12); /* the cells tile the box */
    /* the displacement form's energy of the same field: W((1 + e) I) × area */
    double F[4] = {1 + e, 0, 0, 1 + e}, W;
    check_ok(model->eval(&f.solid->opt.field.material, 2, F, &W, NULL, NULL));
    print_message("%-13s uniform dilatation: Π = %.12g, W·area = %.12g\n", model->type.name, Ef, 2.0 * W);
    assert_true(fabs(Ef - 2.0 * W) < 1e-10 * fabs(Ef));
    free(u);
    release(&f);
    release(&g);
  }
}

/* The pattern of the cell pressure couples every pair of particles that share a cell; each cell's points are
 * listed once. */
static void test_cells(void **state) {
  (void)state;
  Fixture f;
  build(&f, 2, 1, &mica_model_linear, &mica_pressure_cell_constant);
  assert_int_equal(f.solid->npcells, 6);
  assert_int_equal(f.solid->pcell_ptr[6], f.disc->nquad);
  for (long c = 0; c < 6; c++) assert_int_equal(f.solid->pcell_ptr[c + 1] - f.solid->pcell_ptr[c], 9);
  release(&f);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_registry_derivatives),
      cmocka_unit_test(test_uniform_dilatation),
      cmocka_unit_test(test_cells),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
