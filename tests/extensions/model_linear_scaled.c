/* A classical model added from outside the library (issue 18: adding a type is one file): linear elasticity
 * with twice the stiffness, W, P and A of mica_model_linear times 2, i.e. the linear model with E doubled.
 * Under homogeneous Dirichlet conditions imposed exactly (bc.method = "lagrange") its displacements are half
 * the linear model's. Linked into build/tests/mica-ext and the _ext unit tests only; it registers itself before
 * main, and `material.model = "linear-scaled"` then chooses it. */
#include <stdlib.h>

#include "mica/model.h"

enum { MAX_A = 81 }; /* dim⁴ entries of A in 3-D */

static int scaled_eval(const MicaMaterial *mat, int dim, const double *F, double *W, double *P, double *A) {
  MICA_CALL(mica_model_linear.eval(mat, dim, F, W, P, A));
  const int n = dim * dim;
  if (W) *W *= 2.0;
  if (P)
    for (int a = 0; a < n; a++) P[a] *= 2.0;
  if (A)
    for (int a = 0; a < n * n && a < MAX_A; a++) A[a] *= 2.0;
  return MICA_SUCCESS;
}

static const MicaModelOps linear_scaled = {
    .type = {.name = "linear-scaled",
             .description = "test extension: linear elasticity with E doubled (3-D, plane strain, plane stress)",
             .flags = MICA_MODEL_PLANE_STRESS},
    .eval = scaled_eval,
};

__attribute__((constructor)) static void register_linear_scaled(void) {
  if (mica_registry_add(&mica_model_registry, &linear_scaled.type)) {
    mica_error_report("tests/extensions/model_linear_scaled.c");
    exit(1);
  }
}
