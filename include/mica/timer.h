/* Wall-clock time in seconds (monotonic), for per-phase times and rates. */
#ifndef MICA_TIMER_H
#define MICA_TIMER_H

#include <time.h>

static inline double mica_wtime(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
