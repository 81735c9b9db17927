/* Shared by the direct solvers (linear_cholmod.c, linear_umfpack.c): when may a symbolic analysis be
 * reused? While the pattern is the same: same order, same nnz and the same 64-bit fingerprint of colptr and
 * rowind. Comparing the contents, not the object's address, stays right when a pattern is destroyed and a
 * different one happens to be allocated at the same address; it costs one O(nnz) read per factorization,
 * a small fraction of the factorization itself. */
#ifndef MICA_LINEAR_PRIVATE_H
#define MICA_LINEAR_PRIVATE_H

#include <stdint.h>

#include "mica/sparse.h"

typedef struct MicaPatternKey {
  long n, nnz;
  uint64_t fingerprint;
} MicaPatternKey;

/* The key of A's pattern (its values do not enter). */
MicaPatternKey mica_pattern_key(const MicaSparse *A);
int mica_pattern_key_equal(MicaPatternKey a, MicaPatternKey b);

#endif
