/* Wall-clock time in seconds (monotonic), for per-phase times and rates. */
#ifndef MICA_TIMER_H
#define MICA_TIMER_H

#include <time.h>

static inline double mica_wtime(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU time of the calling thread, seconds: what a phase cost this process, whatever else the machine runs
 * (wall-clock times on a shared machine include the time other processes took). */
static inline double mica_cputime(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
