/* The classical point kernels (linear, svk, neohooke, neohooke-cook) seen as field models: the unknowns are
 * the dim displacements, q = [u | ∇u], and W(q) = W(F = I + ∇u). P fills the gradient slots of s, A the
 * gradient block of D; the value slots stay zero (W does not depend on u itself). */
#include <string.h>

#include "mica/model.h"

static int classical_ncomp(int dim) { return dim; }

static const char *const *classical_components(int dim) {
  static const char *const names[] = {"ux", "uy", "uz", NULL};
  (void)dim;
  return names;
}

static const char *const *classical_tractions(int dim) {
  static const char *const names[] = {"tx", "ty", "tz", NULL};
  (void)dim;
  return names;
}

static void deformation_gradient(int dim, const double *q, double *F) {
  const double *grad = q + dim; /* after the dim values */
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = (a == J) + grad[a * dim + J];
}

static int classical_eval(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D) {
  const int d2 = dim * dim, nq = dim + d2;
  double F[9], P[9], A[81], w = 0;
  deformation_gradient(dim, q, F);
  MICA_CALL(m->classical->eval(&m->material, dim, F, &w, s ? P : NULL, D ? A : NULL));
  if (W) *W = w;
  if (s) {
    memset(s, 0, sizeof(double) * (size_t)nq);
    memcpy(s + dim, P, sizeof(double) * (size_t)d2);
  }
  if (D) {
    memset(D, 0, sizeof(double) * (size_t)(nq * nq));
    for (int i = 0; i < d2; i++)
      for (int j = 0; j < d2; j++) D[(dim + i) * nq + dim + j] = A[i * d2 + j];
  }
  return MICA_SUCCESS;
}

static int classical_stress(const MicaFieldModel *m, int dim, const double *q, double *sigma, double *couple) {
  double F[9], strain[9];
  deformation_gradient(dim, q, F);
  if (couple) memset(couple, 0, sizeof(double) * 9);
  return mica_model_stress_strain(m->classical, &m->material, dim, F, sigma, strain);
}

const MicaFieldModelOps mica_field_classical = {
    {"classical", "a classical point kernel as a field model (u, q = [u | grad u])",
     MICA_FIELD_FINITE | MICA_FIELD_CLASSICAL, NULL, NULL},
    1, classical_ncomp, classical_components, classical_tractions, classical_eval, classical_stress,
    NULL,
};

int mica_field_classical_set(MicaFieldModel *m, const MicaModelOps *classical, const MicaMaterial *material) {
  memset(m, 0, sizeof *m);
  m->ops = &mica_field_classical;
  m->classical = classical;
  m->material = *material;
  return MICA_SUCCESS;
}
