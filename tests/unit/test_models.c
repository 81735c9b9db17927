/* Unit tests of the continuum models (src/models): the registry; P = ∂W/∂F and A = ∂P/∂F against central
 * finite differences for every model × {3-D, plane strain, plane stress (linear)}; energies against the
 * formulas written out independently here; objectivity; the small-strain limit; the stress-free
 * reference; plane stress; Cook's volumetric response; the Cauchy stress and strain for output; and the
 * errors of mica_material_set and of inverted deformations.
 *
 * Tolerances. Finite differences use the step h = 1e-6 on each component of F (entries of order 1):
 * the truncation error is O(h² |W'''|) ≈ 1e-12 relative and the rounding error ≈ 1e-16 |W| / h ≈ 1e-10
 * relative, so P must match the differences of W to 1e-6 × max|P| and A those of P to 1e-6 × max|A|
 * (the acceptance tolerance; the worst errors measured are printed and are around 1e-9). Identities that
 * hold exactly in exact arithmetic (objectivity, P(I) = 0, plane stress, Cook's volumetric response,
 * closed-form energies and Cauchy stresses) are checked to 1e-11 relative. The small-strain limit at
 * F = I + εH, ε = 1e-7, has an O(ε) model error and ≈ 1e-9 cancellation, checked to 1e-5 relative.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "mica/model.h"
#include "mica/random.h"
#include "registry_arrays.h"

#define FD_STEP 1e-6
#define FD_TOL 1e-6
#define EXACT_TOL 1e-11
#define SMALL_STRAIN 1e-7
#define SMALL_STRAIN_TOL 1e-5

/* A model in one of its kinematic settings. */
typedef struct {
  const MicaModelOps *model;
  int dim;
  MicaPlaneKind plane;
} Case;

static const Case all_cases[] = {
    {&mica_model_linear, 3, MICA_PLANE_NONE},          {&mica_model_linear, 2, MICA_PLANE_STRAIN},
    {&mica_model_linear, 2, MICA_PLANE_STRESS},        {&mica_model_svk, 3, MICA_PLANE_NONE},
    {&mica_model_svk, 2, MICA_PLANE_STRAIN},           {&mica_model_neohooke, 3, MICA_PLANE_NONE},
    {&mica_model_neohooke, 2, MICA_PLANE_STRAIN},      {&mica_model_neohooke_cook, 3, MICA_PLANE_NONE},
    {&mica_model_neohooke_cook, 2, MICA_PLANE_STRAIN},
};
#define NUM_CASES (sizeof all_cases / sizeof all_cases[0])

/* (E, ν): a generic steel-like scaling, Cook's membrane (μ = 0.4225, ν = 0.3: E = 2μ(1 + ν)), a nearly
 * incompressible one and an auxetic one. */
static const double materials[][2] = {{100.0, 0.3}, {1.0985, 0.3}, {10.0, 0.45}, {5.0, -0.2}};
#define NUM_MATERIALS (sizeof materials / sizeof materials[0])

static const char *plane_name(int dim, MicaPlaneKind plane) {
  if (dim == 3) return "3-D";
  return plane == MICA_PLANE_STRESS ? "plane stress" : "plane strain";
}

static MicaMaterial make_material(const Case *c, double E, double nu) {
  MicaMaterial mat;
  int ierr = mica_material_set(c->model, E, nu, c->plane, &mat);
  if (ierr) {
    print_error("mica_material_set(%s, E = %g, ν = %g): %s\n", c->model->type.name, E, nu, mica_error_message());
    fail();
  }
  return mat;
}

static void eval_ok(const Case *c, const MicaMaterial *mat, const double *F, double *W, double *P, double *A) {
  int ierr = c->model->eval(mat, c->dim, F, W, P, A);
  if (ierr) {
    print_error("%s (%s): eval failed: %s\n", c->model->type.name, plane_name(c->dim, c->plane), mica_error_message());
    fail();
  }
}

static double eval_W(const Case *c, const MicaMaterial *mat, const double *F) {
  double W;
  eval_ok(c, mat, F, &W, NULL, NULL);
  return W;
}

static double max_abs(const double *a, int n) {
  double m = 0.0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(a[i]));
  return m;
}

static void assert_close(double expected, double actual, double tol, const char *what) {
  if (!(fabs(expected - actual) <= tol)) {
    print_error("%s: expected %.17g, got %.17g (difference %.3g, tolerance %.3g)\n", what, expected, actual,
                fabs(expected - actual), tol);
    fail();
  }
}

static void identity(int dim, double *F) {
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) F[i * dim + j] = (i == j);
}

/* F = I + H with H uniform in [−1, 1] per entry, scaled to the Frobenius norm ‖H‖ = size. */
static void random_F(MicaRandom *rng, int dim, double size, double *F) {
  double H[9], norm = 0.0;
  for (int a = 0; a < dim * dim; a++) {
    H[a] = 2.0 * mica_random_uniform(rng) - 1.0;
    norm += H[a] * H[a];
  }
  identity(dim, F);
  for (int a = 0; a < dim * dim; a++) F[a] += size * H[a] / sqrt(norm);
}

/* Large deformations with det F > 0: stretch and shear (det 1.32 in 2-D, 1.05 in 3-D) and compression
 * (det 0.39 in 2-D, 0.34 in 3-D). */
static const double large_F2[][4] = {{1.5, 0.6, -0.2, 0.8}, {0.55, -0.3, 0.1, 0.65}};
static const double large_F3[][9] = {{1.6, 0.5, -0.2, 0.3, 0.7, 0.4, -0.1, 0.25, 1.3},
                                     {0.6, 0.2, 0.0, 0.0, 0.7, 0.1, 0.1, 0.0, 0.8}};

/* Calls check(c, mat, F, worst) at 12 random F near I (‖F − I‖ = 0.1, 0.2, 0.3) and the large ones. */
typedef void (*FCheck)(const Case *c, const MicaMaterial *mat, const double *F, double *worst);

static void for_each_F(const Case *c, const MicaMaterial *mat, FCheck check, double *worst) {
  MicaRandom rng = mica_random_seed(20240917u + (uint64_t)c->dim);
  double F[9];
  for (int s = 1; s <= 3; s++)
    for (int n = 0; n < 4; n++) {
      random_F(&rng, c->dim, 0.1 * s, F);
      check(c, mat, F, worst);
    }
  for (int n = 0; n < 2; n++) check(c, mat, c->dim == 2 ? large_F2[n] : large_F3[n], worst);
}

/* ---- registry ---- */

/* Types an extension adds to the registry when the test is linked with tests/extensions (test_models_ext). */
#ifndef EXTRA_MODELS
#define EXTRA_MODELS 0
#endif


static void test_registry(void **state) {
  (void)state;
  static const struct {
    const char *name;
    const MicaModelOps *ops;
    int finite_strain, plane_stress;
  } expected[] = {
      {"linear", &mica_model_linear, 0, 1},
      {"svk", &mica_model_svk, 1, 0},
      {"neohooke", &mica_model_neohooke, 1, 0},
      {"neohooke-cook", &mica_model_neohooke_cook, 1, 0},
  };
  const MicaModelOps *const *all = models_all();
  for (int i = 0; i < 4; i++) {
    assert_ptr_equal(all[i], expected[i].ops);
    assert_ptr_equal(mica_model_find(expected[i].name), expected[i].ops);
    assert_string_equal(expected[i].ops->type.name, expected[i].name);
    assert_int_equal(mica_type_has(&expected[i].ops->type, MICA_MODEL_FINITE_STRAIN), expected[i].finite_strain);
    assert_int_equal(mica_type_has(&expected[i].ops->type, MICA_MODEL_PLANE_STRESS), expected[i].plane_stress);
    assert_non_null(expected[i].ops->type.description);
    assert_non_null(expected[i].ops->eval);
  }
  assert_null(all[4 + EXTRA_MODELS]);
  assert_null(mica_model_find("neo-hooke"));
  assert_null(mica_model_find(""));
  assert_null(mica_model_find(NULL));
}

/* ---- finite differences ---- */

/* max_J |∂W/∂F_iJ (central difference) − P_iJ| / max|P|. */
static void check_P_against_W(const Case *c, const MicaMaterial *mat, const double *F, double *worst) {
  int n = c->dim * c->dim;
  double P[9], Fh[9], err = 0.0;
  eval_ok(c, mat, F, NULL, P, NULL);
  for (int a = 0; a < n; a++) {
    memcpy(Fh, F, (size_t)n * sizeof *F);
    Fh[a] = F[a] + FD_STEP;
    double Wp = eval_W(c, mat, Fh);
    Fh[a] = F[a] - FD_STEP;
    double Wm = eval_W(c, mat, Fh);
    err = fmax(err, fabs((Wp - Wm) / (2.0 * FD_STEP) - P[a]));
  }
  err /= max_abs(P, n);
  if (!(err <= FD_TOL)) {
    print_error("%s (%s, E = %g, ν = %g): P differs from the differences of W by %.3g relative\n", c->model->type.name,
                plane_name(c->dim, c->plane), mat->E, mat->nu, err);
    fail();
  }
  *worst = fmax(*worst, err);
}

/* max |∂P_iJ/∂F_kL (central difference) − A_iJkL| / max|A|. */
static void check_A_against_P(const Case *c, const MicaMaterial *mat, const double *F, double *worst) {
  int n = c->dim * c->dim;
  double A[81], Pp[9], Pm[9], Fh[9], err = 0.0;
  eval_ok(c, mat, F, NULL, NULL, A);
  for (int b = 0; b < n; b++) { /* b = (k, L): one column of A */
    memcpy(Fh, F, (size_t)n * sizeof *F);
    Fh[b] = F[b] + FD_STEP;
    eval_ok(c, mat, Fh, NULL, Pp, NULL);
    Fh[b] = F[b] - FD_STEP;
    eval_ok(c, mat, Fh, NULL, Pm, NULL);
    for (int a = 0; a < n; a++) err = fmax(err, fabs((Pp[a] - Pm[a]) / (2.0 * FD_STEP) - A[a * n + b]));
  }
  err /= max_abs(A, n * n);
  if (!(err <= FD_TOL)) {
    print_error("%s (%s, E = %g, ν = %g): A differs from the differences of P by %.3g relative\n", c->model->type.name,
                plane_name(c->dim, c->plane), mat->E, mat->nu, err);
    fail();
  }
  *worst = fmax(*worst, err);
}

/* A_iJkL = A_kLiJ (A is a second derivative of W); minor symmetry of the linear C as well. */
static void check_A_symmetry(const Case *c, const MicaMaterial *mat, const double *F, double *worst) {
  int n = c->dim * c->dim, dim = c->dim;
  double A[81], err = 0.0;
  eval_ok(c, mat, F, NULL, NULL, A);
  for (int a = 0; a < n; a++)
    for (int b = 0; b < n; b++) {
      err = fmax(err, fabs(A[a * n + b] - A[b * n + a]));
      if (!mica_type_has(&c->model->type, MICA_MODEL_FINITE_STRAIN)) { /* a = (i, J) ↔ (J, i) */
        int i = a / dim, J = a % dim;
        err = fmax(err, fabs(A[a * n + b] - A[(J * dim + i) * n + b]));
      }
    }
  err /= max_abs(A, n * n);
  if (!(err <= EXACT_TOL)) {
    print_error("%s (%s): A is not symmetric: %.3g relative\n", c->model->type.name, plane_name(c->dim, c->plane), err);
    fail();
  }
  *worst = fmax(*worst, err);
}

static void run_over_cases(FCheck check, const char *what) {
  double worst = 0.0;
  for (size_t k = 0; k < NUM_CASES; k++)
    for (size_t m = 0; m < NUM_MATERIALS; m++) {
      MicaMaterial mat = make_material(&all_cases[k], materials[m][0], materials[m][1]);
      for_each_F(&all_cases[k], &mat, check, &worst);
    }
  print_message("worst %s: %.3g\n", what, worst);
}

static void test_P_is_dW_dF(void **state) {
  (void)state;
  run_over_cases(check_P_against_W, "|P − FD(W)| / max|P|");
}

static void test_A_is_dP_dF(void **state) {
  (void)state;
  run_over_cases(check_A_against_P, "|A − FD(P)| / max|A|");
}

/* The same differences for every model of the registry, each in 3-D, plane strain and (if it has it) plane
 * stress: a model an extension registers is checked too. */
static void test_registry_tangents(void **state) {
  (void)state;
  double worst_P = 0.0, worst_A = 0.0;
  int checked = 0;
  for (const MicaModelOps *const *model = models_all(); *model; model++, checked++) {
    const Case cases[] = {{*model, 3, MICA_PLANE_NONE}, {*model, 2, MICA_PLANE_STRAIN}, {*model, 2, MICA_PLANE_STRESS}};
    const int ncases = mica_type_has(&(*model)->type, MICA_MODEL_PLANE_STRESS) ? 3 : 2;
    for (int k = 0; k < ncases; k++)
      for (size_t m = 0; m < NUM_MATERIALS; m++) {
        MicaMaterial mat = make_material(&cases[k], materials[m][0], materials[m][1]);
        for_each_F(&cases[k], &mat, check_P_against_W, &worst_P);
        for_each_F(&cases[k], &mat, check_A_against_P, &worst_A);
      }
  }
  assert_int_equal(checked, 4 + EXTRA_MODELS);
  print_message("%d registered models: worst |P − FD(W)| / max|P| %.3g, |A − FD(P)| / max|A| %.3g\n", checked,
                worst_P, worst_A);
}

static void test_A_symmetric(void **state) {
  (void)state;
  run_over_cases(check_A_symmetry, "asymmetry of A / max|A|");
}

/* ---- energies written out independently ---- */

/* The 3×3 F of a 2-D F in plane strain. */
static void embed(int dim, const double *F, double F3[9]) {
  identity(3, F3);
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) F3[3 * i + j] = F[i * dim + j];
}

static double det3(const double a[9]) {
  return a[0] * a[4] * a[8] + a[1] * a[5] * a[6] + a[2] * a[3] * a[7] - a[2] * a[4] * a[6] - a[0] * a[5] * a[7] -
         a[1] * a[3] * a[8];
}

/* W of each model from its definition, evaluated on the 3×3 F. */
static double reference_W(const MicaModelOps *model, const MicaMaterial *mat, const double F[9]) {
  double C[9] = {0}, lambda = mat->lambda, mu = mat->mu;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 3; k++) C[3 * i + j] += F[3 * k + i] * F[3 * k + j];
  double I1 = C[0] + C[4] + C[8], J = det3(F);
  if (model == &mica_model_svk) {
    double EE = 0.0, trE = 0.5 * (I1 - 3.0);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        double Eij = 0.5 * (C[3 * i + j] - (i == j));
        EE += Eij * Eij;
      }
    return 0.5 * lambda * trE * trE + mu * EE;
  }
  if (model == &mica_model_neohooke) return 0.5 * mu * (I1 - 3.0) - mu * log(J) + 0.5 * lambda * log(J) * log(J);
  if (model == &mica_model_neohooke_cook)
    return 0.5 * mu * (pow(J, -2.0 / 3.0) * I1 - 3.0) + 0.25 * mat->kappa * (J * J - 1.0 - 2.0 * log(J));
  /* linear, plane strain or 3-D: ½ λ (tr ε)² + μ ε:ε */
  double tr = F[0] + F[4] + F[8] - 3.0, ee = 0.0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double eij = 0.5 * (F[3 * i + j] + F[3 * j + i]) - (i == j);
      ee += eij * eij;
    }
  return 0.5 * lambda * tr * tr + mu * ee;
}

static void check_W_reference(const Case *c, const MicaMaterial *mat, const double *F, double *worst) {
  double F3[9];
  if (c->plane == MICA_PLANE_STRESS) return; /* its own test */
  embed(c->dim, F, F3);
  double expected = reference_W(c->model, mat, F3), W = eval_W(c, mat, F);
  double err = fabs(W - expected) / fabs(expected);
  if (!(err <= EXACT_TOL)) {
    print_error("%s (%s): W = %.17g, its definition gives %.17g\n", c->model->type.name, plane_name(c->dim, c->plane),
                W, expected);
    fail();
  }
  *worst = fmax(*worst, err);
}

static void test_energy_values(void **state) {
  (void)state;
  run_over_cases(check_W_reference, "|W − W(definition)| / |W|");
}

/* ---- stress-free reference ---- */

static void test_stress_free_reference(void **state) {
  (void)state;
  for (size_t k = 0; k < NUM_CASES; k++) {
    const Case *c = &all_cases[k];
    MicaMaterial mat = make_material(c, 100.0, 0.3);
    double F[9], W, P[9];
    identity(c->dim, F);
    eval_ok(c, &mat, F, &W, P, NULL);
    assert_close(0.0, W, 1e-14 * mat.E, "W(I)");
    for (int a = 0; a < c->dim * c->dim; a++) assert_close(0.0, P[a], 1e-14 * mat.E, "P(I)");
  }
}

/* ---- objectivity ---- */

/* Rotation by angle θ about the unit axis n (Rodrigues), or in the plane in 2-D. */
static void rotation(int dim, const double n[3], double theta, double *Q) {
  double c = cos(theta), s = sin(theta);
  if (dim == 2) {
    double Q2[4] = {c, -s, s, c};
    memcpy(Q, Q2, sizeof Q2);
    return;
  }
  double K[9] = {0, -n[2], n[1], n[2], 0, -n[0], -n[1], n[0], 0};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) Q[3 * i + j] = c * (i == j) + s * K[3 * i + j] + (1.0 - c) * n[i] * n[j];
}

static void matmul(int dim, const double *a, const double *b, double *c) {
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) {
      c[i * dim + j] = 0.0;
      for (int k = 0; k < dim; k++) c[i * dim + j] += a[i * dim + k] * b[k * dim + j];
    }
}

/* Largest relative change of W and of P under F → QF (P → QP) over a few rotations. */
static double objectivity_error(const Case *c, const MicaMaterial *mat, const double *F) {
  static const double axis[3] = {0.48, -0.6, 0.64}; /* unit length */
  static const double angles[] = {0.3, 1.7, -2.9};
  int n = c->dim * c->dim;
  double W, P[9], err = 0.0;
  eval_ok(c, mat, F, &W, P, NULL);
  double scale = fmax(fabs(W), max_abs(P, n));
  for (int r = 0; r < 3; r++) {
    double Q[9], QF[9], QP[9], Wq, Pq[9];
    rotation(c->dim, axis, angles[r], Q);
    matmul(c->dim, Q, F, QF);
    matmul(c->dim, Q, P, QP);
    eval_ok(c, mat, QF, &Wq, Pq, NULL);
    err = fmax(err, fabs(Wq - W) / scale);
    for (int a = 0; a < n; a++) err = fmax(err, fabs(Pq[a] - QP[a]) / scale);
  }
  return err;
}

static void check_objective(const Case *c, const MicaMaterial *mat, const double *F, double *worst) {
  if (!mica_type_has(&c->model->type, MICA_MODEL_FINITE_STRAIN)) return;
  double err = objectivity_error(c, mat, F);
  if (!(err <= EXACT_TOL)) {
    print_error("%s (%s): W(QF) ≠ W(F) or P(QF) ≠ Q P(F): %.3g relative\n", c->model->type.name,
                plane_name(c->dim, c->plane), err);
    fail();
  }
  *worst = fmax(*worst, err);
}

static void test_objectivity(void **state) {
  (void)state;
  run_over_cases(check_objective, "objectivity error");
  /* The check can fail: linear elasticity is not objective under finite rotations. */
  const Case lin = {&mica_model_linear, 3, MICA_PLANE_NONE};
  MicaMaterial mat = make_material(&lin, 100.0, 0.3);
  assert_true(objectivity_error(&lin, &mat, large_F3[0]) > 1e-2);
}

/* ---- small-strain limit ---- */

static void test_small_strain_limit(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(7);
  double worst = 0.0;
  for (size_t k = 0; k < NUM_CASES; k++) {
    const Case *c = &all_cases[k];
    if (!mica_type_has(&c->model->type, MICA_MODEL_FINITE_STRAIN)) continue;
    const Case lin = {&mica_model_linear, c->dim, c->plane};
    for (size_t m = 0; m < NUM_MATERIALS; m++) {
      MicaMaterial mat = make_material(c, materials[m][0], materials[m][1]);
      MicaMaterial mat_lin = make_material(&lin, materials[m][0], materials[m][1]);
      for (int trial = 0; trial < 4; trial++) {
        int n = c->dim * c->dim;
        double IH[9], F[9], P[9], CH[9], A[81], C[81], Fid[9];
        random_F(&rng, c->dim, 1.0, IH); /* I + H */
        identity(c->dim, Fid);
        for (int a = 0; a < n; a++) F[a] = Fid[a] + SMALL_STRAIN * (IH[a] - Fid[a]); /* I + εH */
        eval_ok(c, &mat, F, NULL, P, NULL);
        eval_ok(&lin, &mat_lin, IH, NULL, CH, NULL); /* C : sym H */
        double err = 0.0, scale = max_abs(CH, n);
        for (int a = 0; a < n; a++) err = fmax(err, fabs(P[a] / SMALL_STRAIN - CH[a]) / scale);
        if (!(err <= SMALL_STRAIN_TOL)) {
          print_error("%s (%s): P/ε differs from C : sym H by %.3g relative\n", c->model->type.name,
                      plane_name(c->dim, c->plane), err);
          fail();
        }
        worst = fmax(worst, err);
        /* and the tangent at the reference is C itself */
        eval_ok(c, &mat, Fid, NULL, NULL, A);
        eval_ok(&lin, &mat_lin, Fid, NULL, NULL, C);
        for (int a = 0; a < n * n; a++) assert_close(C[a], A[a], EXACT_TOL * max_abs(C, n * n), "A(I) = C");
      }
    }
  }
  print_message("worst |P/ε − C:sym H| / max|C:sym H| at ε = %g: %.3g\n", SMALL_STRAIN, worst);
}

/* ---- linear plane stress ---- */

static void test_plane_stress_uniaxial(void **state) {
  (void)state;
  const Case c = {&mica_model_linear, 2, MICA_PLANE_STRESS};
  for (size_t m = 0; m < NUM_MATERIALS; m++) {
    double E = materials[m][0], nu = materials[m][1], e = 1e-3;
    MicaMaterial mat = make_material(&c, E, nu);
    double F[4] = {1.0 + e, 0.0, 0.0, 1.0 - nu * e}, P[4], sigma[9], strain[9];
    eval_ok(&c, &mat, F, NULL, P, NULL);
    assert_close(E * e, P[0], EXACT_TOL * E * e, "uniaxial σ_11 = E ε_11");
    assert_close(0.0, P[3], EXACT_TOL * E * e, "uniaxial σ_22 = 0");
    assert_close(0.0, P[1], EXACT_TOL * E * e, "uniaxial σ_12 = 0");
    assert_int_equal(mica_model_stress_strain(c.model, &mat, 2, F, sigma, strain), MICA_SUCCESS);
    assert_close(0.0, sigma[8], 0.0, "σ_33");
    assert_close(E * e, sigma[0], EXACT_TOL * E * e, "output σ_11");
    assert_close(-nu * e, strain[8], EXACT_TOL * e, "uniaxial ε_33 = −ν ε_11");
  }
}

/* At any in-plane strain, the plane stress law equals the 3-D law with the ε_33 that makes σ_33 = 0. */
static void test_plane_stress_is_3d_with_free_e33(void **state) {
  (void)state;
  const Case ps = {&mica_model_linear, 2, MICA_PLANE_STRESS}, d3 = {&mica_model_linear, 3, MICA_PLANE_NONE};
  MicaRandom rng = mica_random_seed(11);
  for (size_t m = 0; m < NUM_MATERIALS; m++) {
    MicaMaterial mat_ps = make_material(&ps, materials[m][0], materials[m][1]);
    MicaMaterial mat_3d = make_material(&d3, materials[m][0], materials[m][1]);
    for (int trial = 0; trial < 5; trial++) {
      double F[4], P[4], F3[9], P3[9], sigma[9], strain[9];
      random_F(&rng, 2, 0.2, F);
      eval_ok(&ps, &mat_ps, F, NULL, P, NULL);
      assert_int_equal(mica_model_stress_strain(ps.model, &mat_ps, 2, F, sigma, strain), MICA_SUCCESS);
      embed(2, F, F3);
      F3[8] = 1.0 + strain[8]; /* ε_33 from the output */
      eval_ok(&d3, &mat_3d, F3, NULL, P3, NULL);
      double scale = max_abs(P3, 9);
      assert_close(0.0, P3[8], EXACT_TOL * scale, "3-D σ_33 at the plane stress ε_33");
      for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
          assert_close(P3[3 * i + j], P[2 * i + j], EXACT_TOL * scale, "plane stress σ = 3-D σ");
          assert_close(P3[3 * i + j], sigma[3 * i + j], EXACT_TOL * scale, "output σ");
        }
    }
  }
}

/* ---- neohooke-cook ---- */

static void test_cook_kappa(void **state) {
  (void)state;
  const Case c = {&mica_model_neohooke_cook, 2, MICA_PLANE_STRAIN};
  for (size_t m = 0; m < NUM_MATERIALS; m++) {
    double nu = materials[m][1];
    MicaMaterial mat = make_material(&c, materials[m][0], nu);
    assert_close(2.0 * mat.mu * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu)), mat.kappa, 1e-14 * mat.kappa,
                 "κ = 2μ(1+ν)/(3(1−2ν))");
    assert_close(mat.lambda + 2.0 * mat.mu / 3.0, mat.kappa, 1e-14 * mat.kappa, "κ = λ + 2μ/3");
  }
  /* Cook's membrane: μ = 0.4225, ν = 0.3 */
  MicaMaterial cook = make_material(&c, 2.0 * 0.4225 * 1.3, 0.3);
  assert_close(0.4225, cook.mu, 1e-15, "Cook's μ");
  assert_close(2.0 * 0.4225 * 1.3 / (3.0 * 0.4), cook.kappa, 1e-15, "Cook's κ");
}

/* F = s I: Ī₁ = 3, so only the volumetric part acts: W = κ/4 (J² − 1 − 2 ln J) and the Cauchy stress is
 * the pressure σ = U'(J) I = κ/2 (J − 1/J) I. */
static void test_cook_volumetric(void **state) {
  (void)state;
  const Case c = {&mica_model_neohooke_cook, 3, MICA_PLANE_NONE};
  MicaMaterial mat = make_material(&c, 1.0985, 0.3);
  const double stretches[] = {0.7, 0.95, 1.0 + 1e-4, 1.1, 1.4};
  for (size_t k = 0; k < sizeof stretches / sizeof stretches[0]; k++) {
    double s = stretches[k], J = s * s * s, F[9] = {s, 0, 0, 0, s, 0, 0, 0, s}, W, sigma[9], strain[9];
    double p = 0.5 * mat.kappa * (J - 1.0 / J);
    eval_ok(&c, &mat, F, &W, NULL, NULL);
    assert_close(0.25 * mat.kappa * (J * J - 1.0 - 2.0 * log(J)), W, EXACT_TOL * mat.kappa, "volumetric W");
    assert_int_equal(mica_model_stress_strain(c.model, &mat, 3, F, sigma, strain), MICA_SUCCESS);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        assert_close(i == j ? p : 0.0, sigma[3 * i + j], EXACT_TOL * mat.kappa, "σ = p I");
  }
}

/* Plane strain F = diag(s, s) (F_33 = 1): J = s², I₁ = 2s² + 1, and σ_33 = P_33 / J with
 * P_33 = μ J^(−2/3) (1 − I₁/3) + κ/2 (J² − 1). */
static void test_cook_plane_strain(void **state) {
  (void)state;
  const Case c = {&mica_model_neohooke_cook, 2, MICA_PLANE_STRAIN};
  MicaMaterial mat = make_material(&c, 1.0985, 0.3);
  const double stretches[] = {0.8, 1.05, 1.3};
  for (size_t k = 0; k < 3; k++) {
    double s = stretches[k], J = s * s, I1 = 2.0 * s * s + 1.0, a = pow(J, -2.0 / 3.0);
    double F[4] = {s, 0, 0, s}, W, sigma[9], strain[9];
    eval_ok(&c, &mat, F, &W, NULL, NULL);
    double expected = 0.5 * mat.mu * (a * I1 - 3.0) + 0.25 * mat.kappa * (J * J - 1.0 - 2.0 * log(J));
    assert_close(expected, W, EXACT_TOL * fabs(expected), "plane strain W with I₁ = 2s² + 1");
    assert_int_equal(mica_model_stress_strain(c.model, &mat, 2, F, sigma, strain), MICA_SUCCESS);
    double s33 = (mat.mu * a * (1.0 - I1 / 3.0) + 0.5 * mat.kappa * (J * J - 1.0)) / J;
    assert_close(s33, sigma[8], EXACT_TOL * mat.kappa, "plane strain σ_33");
    assert_close(0.0, strain[8], 0.0, "plane strain E_33");
  }
}

/* ---- output stress and strain ---- */

/* Neo-Hooke's Cauchy stress in closed form, σ = μ/J (b − I) + λ ln J / J I, and E = ½(FᵀF − I). */
static void test_stress_strain_neohooke(void **state) {
  (void)state;
  for (int dim = 2; dim <= 3; dim++) {
    const Case c = {&mica_model_neohooke, dim, dim == 2 ? MICA_PLANE_STRAIN : MICA_PLANE_NONE};
    MicaMaterial mat = make_material(&c, 100.0, 0.3);
    const double *F = dim == 2 ? large_F2[0] : large_F3[0];
    double F3[9], sigma[9], strain[9];
    embed(dim, F, F3);
    assert_int_equal(mica_model_stress_strain(c.model, &mat, dim, F, sigma, strain), MICA_SUCCESS);
    double J = det3(F3);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        double b = 0.0, C = 0.0;
        for (int k = 0; k < 3; k++) {
          b += F3[3 * i + k] * F3[3 * j + k];
          C += F3[3 * k + i] * F3[3 * k + j];
        }
        double expected = mat.mu / J * (b - (i == j)) + mat.lambda * log(J) / J * (i == j);
        assert_close(expected, sigma[3 * i + j], EXACT_TOL * mat.E, "Neo-Hooke Cauchy stress");
        assert_close(0.5 * (C - (i == j)), strain[3 * i + j], 1e-15, "Green-Lagrange strain");
      }
  }
}

/* Linear plane strain: σ = P, σ_33 = λ (ε_11 + ε_22), ε = sym(F − I) with ε_33 = 0. */
static void test_stress_strain_linear_plane_strain(void **state) {
  (void)state;
  const Case c = {&mica_model_linear, 2, MICA_PLANE_STRAIN};
  MicaMaterial mat = make_material(&c, 100.0, 0.3);
  double F[4] = {1.01, 0.004, -0.002, 0.995}, P[4], sigma[9], strain[9];
  eval_ok(&c, &mat, F, NULL, P, NULL);
  assert_int_equal(mica_model_stress_strain(c.model, &mat, 2, F, sigma, strain), MICA_SUCCESS);
  double tol = EXACT_TOL * mat.E;
  assert_close(mat.lambda * (0.01 - 0.005), sigma[8], tol, "plane strain σ_33 = λ tr ε");
  assert_close(P[0], sigma[0], tol, "σ_11");
  assert_close(P[1], sigma[1], tol, "σ_12");
  assert_close(P[3], sigma[4], tol, "σ_22");
  assert_close(0.001, strain[1], 1e-15, "ε_12");
  assert_close(0.001, strain[3], 1e-15, "ε_21");
  assert_close(0.0, strain[8], 0.0, "ε_33");
  assert_close(0.0, sigma[2], 0.0, "σ_13");
}

/* ---- errors ---- */

static void expect_input_error(const MicaModelOps *model, double E, double nu, MicaPlaneKind plane,
                               const char *const *fragments) {
  MicaMaterial mat;
  memset(&mat, 0x5a, sizeof mat);
  unsigned char before[sizeof mat];
  memcpy(before, &mat, sizeof mat);
  mica_error_clear();
  assert_int_equal(mica_material_set(model, E, nu, plane, &mat), MICA_ERR_INPUT);
  const char *msg = mica_error_message();
  print_message("  %s\n", msg);
  for (int i = 0; fragments[i]; i++)
    if (!strstr(msg, fragments[i])) {
      print_error("message \"%s\" lacks \"%s\"\n", msg, fragments[i]);
      fail();
    }
  assert_memory_equal(before, &mat, sizeof mat); /* untouched on error */
  mica_error_clear();
}

static void test_material_errors(void **state) {
  (void)state;
  expect_input_error(&mica_model_linear, 0.0, 0.3, MICA_PLANE_NONE,
                     (const char *const[]){"Young's modulus E = 0", "positive", NULL});
  expect_input_error(&mica_model_svk, -5.0, 0.3, MICA_PLANE_NONE,
                     (const char *const[]){"Young's modulus E = -5", NULL});
  expect_input_error(&mica_model_neohooke, 1.0, 0.5, MICA_PLANE_STRAIN,
                     (const char *const[]){"ν = 0.5", "'neohooke'", "singular (λ = ∞)", "use ν < 0.5", NULL});
  expect_input_error(&mica_model_linear, 1.0, 0.7, MICA_PLANE_NONE,
                     (const char *const[]){"ν = 0.7", "'linear'", "use ν < 0.5", NULL});
  expect_input_error(&mica_model_neohooke_cook, 1.0, -1.0, MICA_PLANE_NONE,
                     (const char *const[]){"ν = -1", "−1 < ν < 0.5", NULL});
  expect_input_error(&mica_model_linear, 1.0, NAN, MICA_PLANE_NONE, (const char *const[]){"Poisson", NULL});
  expect_input_error(&mica_model_linear, INFINITY, 0.3, MICA_PLANE_NONE, (const char *const[]){"Young", NULL});
  const MicaModelOps *no_plane_stress[] = {&mica_model_svk, &mica_model_neohooke, &mica_model_neohooke_cook};
  for (int i = 0; i < 3; i++)
    expect_input_error(no_plane_stress[i], 1.0, 0.3, MICA_PLANE_STRESS,
                       (const char *const[]){no_plane_stress[i]->type.name, "plane stress", "'linear'", NULL});
  /* the valid edges */
  MicaMaterial mat;
  assert_int_equal(mica_material_set(&mica_model_linear, 1.0, 0.3, MICA_PLANE_STRESS, &mat), MICA_SUCCESS);
  assert_int_equal(mica_material_set(&mica_model_svk, 1.0, 0.499, MICA_PLANE_STRAIN, &mat), MICA_SUCCESS);
  assert_int_equal(mica_material_set(&mica_model_svk, 1.0, -0.999, MICA_PLANE_NONE, &mat), MICA_SUCCESS);
  assert_close(1.0 / (2.0 * 0.001), mat.mu, 1e-9, "μ at ν = −0.999");
}

/* Contract violations a caller could commit: dimension 1 or 4, plane stress on a model without it. */
static void test_argument_errors(void **state) {
  (void)state;
  MicaMaterial mat;
  double F[16] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, W;
  assert_int_equal(mica_material_set(&mica_model_svk, 1.0, 0.3, MICA_PLANE_NONE, &mat), MICA_SUCCESS);
  assert_int_equal(mica_model_svk.eval(&mat, 4, F, &W, NULL, NULL), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_model_linear.eval(&mat, 1, F, &W, NULL, NULL), MICA_ERR_ARGUMENT);
  mat.plane = MICA_PLANE_STRESS;
  assert_int_equal(mica_model_neohooke.eval(&mat, 2, F, &W, NULL, NULL), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_model_neohooke.eval(&mat, 3, F, &W, NULL, NULL), MICA_SUCCESS); /* ignored in 3-D */
  mica_error_clear();
}

static void assert_all_finite(const double *a, int n, const char *what) {
  for (int i = 0; i < n; i++)
    if (!isfinite(a[i])) {
      print_error("%s[%d] = %g after an inverted F\n", what, i, a[i]);
      fail();
    }
}

/* det F = −0.3, 0 and NaN: the models with ln J refuse with MICA_ERR_NUMERIC and write no NaN; SVK and
 * linear elasticity are defined there. */
static void test_inverted_deformation(void **state) {
  (void)state;
  const double F3_bad[][9] = {
      {-0.3, 0, 0, 0, 1, 0, 0, 0, 1}, {1, 2, 0, 0.5, 1, 0, 0, 0, 1}, {NAN, 0, 0, 0, 1, 0, 0, 0, 1}};
  const double F2_bad[][4] = {{1, 0, 0, -0.3}, {1, 2, 0.5, 1}, {1, 0, 0, NAN}};
  const char *det_text[] = {"det F = -0.3", "det F = 0", "det F = nan"};
  for (size_t k = 0; k < NUM_CASES; k++) {
    const Case *c = &all_cases[k];
    MicaMaterial mat = make_material(c, 100.0, 0.3);
    for (int b = 0; b < 3; b++) {
      const double *F = c->dim == 2 ? F2_bad[b] : F3_bad[b];
      double W = 0.0, P[9] = {0}, A[81] = {0}, sigma[9], strain[9];
      int n = c->dim * c->dim;
      mica_error_clear();
      int ierr = c->model->eval(&mat, c->dim, F, &W, P, A);
      if (c->model == &mica_model_neohooke || c->model == &mica_model_neohooke_cook) {
        assert_int_equal(ierr, MICA_ERR_NUMERIC);
        if (!strstr(mica_error_message(), det_text[b]) || !strstr(mica_error_message(), "step is too large")) {
          print_error("message \"%s\" lacks \"%s\"\n", mica_error_message(), det_text[b]);
          fail();
        }
        assert_all_finite(&W, 1, "W");
        assert_all_finite(P, n, "P");
        assert_all_finite(A, n * n, "A");
        assert_int_equal(mica_model_stress_strain(c->model, &mat, c->dim, F, sigma, strain), MICA_ERR_NUMERIC);
      } else if (b < 2) {
        assert_int_equal(ierr, MICA_SUCCESS);
        assert_all_finite(&W, 1, "W");
        assert_all_finite(P, n, "P");
        assert_all_finite(A, n * n, "A");
      }
      mica_error_clear();
    }
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_registry),
      cmocka_unit_test(test_P_is_dW_dF),
      cmocka_unit_test(test_A_is_dP_dF),
      cmocka_unit_test(test_registry_tangents),
      cmocka_unit_test(test_A_symmetric),
      cmocka_unit_test(test_energy_values),
      cmocka_unit_test(test_stress_free_reference),
      cmocka_unit_test(test_objectivity),
      cmocka_unit_test(test_small_strain_limit),
      cmocka_unit_test(test_plane_stress_uniaxial),
      cmocka_unit_test(test_plane_stress_is_3d_with_free_e33),
      cmocka_unit_test(test_cook_kappa),
      cmocka_unit_test(test_cook_volumetric),
      cmocka_unit_test(test_cook_plane_strain),
      cmocka_unit_test(test_stress_strain_neohooke),
      cmocka_unit_test(test_stress_strain_linear_plane_strain),
      cmocka_unit_test(test_material_errors),
      cmocka_unit_test(test_argument_errors),
      cmocka_unit_test(test_inverted_deformation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
