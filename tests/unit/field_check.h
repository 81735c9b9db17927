/* Shared by the unit tests of field models (include after <cmocka.h> and the model headers): a seeded
 * random state in [−1, 1] and the central-difference check of a field model's s and D. */
#ifndef MICA_TEST_FIELD_CHECK_H
#define MICA_TEST_FIELD_CHECK_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "mica/model.h"

/* Uniform in [−1, 1) from a 64-bit LCG: repeatable across machines. */
static inline double rnd(uint64_t *state) {
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*state >> 11) / 9007199254740992.0 * 2 - 1;
}

static inline void random_q(int nq, double amplitude, uint64_t *state, double *q) {
  for (int j = 0; j < nq; j++) q[j] = amplitude * rnd(state);
}

/* Largest |s − ∇W| / max|s| and |D − ∇s| / max|D| by central differences (step 1e-6). */
static inline void check_derivatives(const MicaFieldModel *m, int dim, const double *q, double *err_s,
                                     double *err_d) {
  const int nq = mica_field_model_nq(m, dim);
  double s[64], D[64 * 64], qp[64], qm[64], sp[64], sm[64], Wp, Wm, W;
  assert_int_equal(m->ops->eval(m, dim, q, &W, s, D), 0);
  double smax = 0, dmax = 0;
  for (int j = 0; j < nq; j++) smax = fmax(smax, fabs(s[j]));
  for (int j = 0; j < nq * nq; j++) dmax = fmax(dmax, fabs(D[j]));
  *err_s = *err_d = 0;
  const double h = 1e-6;
  for (int j = 0; j < nq; j++) {
    memcpy(qp, q, sizeof(double) * (size_t)nq);
    memcpy(qm, q, sizeof(double) * (size_t)nq);
    qp[j] += h, qm[j] -= h;
    assert_int_equal(m->ops->eval(m, dim, qp, &Wp, sp, NULL), 0);
    assert_int_equal(m->ops->eval(m, dim, qm, &Wm, sm, NULL), 0);
    *err_s = fmax(*err_s, fabs((Wp - Wm) / (2 * h) - s[j]) / smax);
    for (int i = 0; i < nq; i++) *err_d = fmax(*err_d, fabs((sp[i] - sm[i]) / (2 * h) - D[i * nq + j]) / dmax);
  }
}

#endif
