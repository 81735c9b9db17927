/* Private to src/parallel. */
#ifndef MICA_PARALLEL_PRIVATE_H
#define MICA_PARALLEL_PRIVATE_H

#include "mica/parallel.h"

/* own.c: what parallel.data = "distributed" adds to a distribution (its ghost plan, numbering, local MLS). */
void parallel_owned_free(MicaDistribution *dist);

#endif
