/* A family's registered types as a NULL-terminated array in the registry's order, for the tests that loop
 * over every type (extensions included when the test is linked with tests/extensions/). */
#ifndef MICA_TEST_REGISTRY_ARRAYS_H
#define MICA_TEST_REGISTRY_ARRAYS_H

#include <assert.h>

#include "mica/mls.h"
#include "mica/model.h"

enum { REGISTRY_ARRAY_MAX = 64 };

/* name_all(): the types that at(i) gives, i = 0, 1, ... until it gives NULL. */
#define REGISTRY_ARRAY(name, T, at)                                                                         \
  static inline const T *const *name(void) {                                                                \
    static const T *all[REGISTRY_ARRAY_MAX + 1];                                                            \
    int n = 0;                                                                                              \
    for (; at(n); n++) {                                                                                    \
      assert(n < REGISTRY_ARRAY_MAX && "more types than the test's array holds");                           \
      all[n] = at(n);                                                                                       \
    }                                                                                                       \
    all[n] = NULL;                                                                                          \
    return all;                                                                                             \
  }

REGISTRY_ARRAY(bases_all, MlsBasisOps, mls_basis_at)
REGISTRY_ARRAY(weights_all, MlsWeightOps, mls_weight_at)
REGISTRY_ARRAY(models_all, MicaModelOps, mica_model_at)

#endif
