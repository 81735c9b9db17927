/* A weight function added from outside the library (issue 18: adding a type is one file): the C² bump
 *   w(r) = (1 − r²)³,  w' = −6r (1 − r²)²,  w'' = −6 (1 − r²)² + 24 r² (1 − r²)   for r < 1, zero beyond,
 * whose value and first two derivatives vanish at r = 1. Linked into build/tests/mica-ext and the _ext unit
 * tests only; it registers itself before main, and `mls.weight = "bump"` then chooses it. */
#include <stdio.h>
#include <stdlib.h>

#include "mica/mls.h"

static void bump_eval(double r, double param, double w[3]) {
  (void)param;
  if (r >= 1.0) {
    w[0] = w[1] = w[2] = 0.0;
    return;
  }
  const double s = 1.0 - r * r; /* ds/dr = −2r */
  w[0] = s * s * s;
  w[1] = -6.0 * r * s * s;
  w[2] = -6.0 * s * s + 24.0 * r * r * s;
}

static const MlsWeightOps bump = {{"bump", "test extension: the bump (1 - r^2)^3, C2", 0, NULL, NULL}, 2, bump_eval};

__attribute__((constructor)) static void register_bump(void) {
  if (mica_registry_add(&mls_weight_registry, &bump.type)) {
    mica_error_report("tests/extensions/weight_bump.c");
    exit(1);
  }
}
