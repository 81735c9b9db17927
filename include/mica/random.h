/* A small deterministic random number generator (SplitMix64), so that jittered particles and random
 * sample points are the same for the same seed on every machine. */
#ifndef MICA_RANDOM_H
#define MICA_RANDOM_H

#include <stdint.h>

typedef struct {
  uint64_t state;
} MicaRandom;

static inline MicaRandom mica_random_seed(uint64_t seed) { return (MicaRandom){seed * 0x9E3779B97F4A7C15ULL + 1}; }

static inline uint64_t mica_random_next(MicaRandom *r) {
  uint64_t z = (r->state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/* The generator k draws further on: SplitMix64 is a counter, so draw k of a stream is known without the k before
 * it (a rank lays out its block of jittered particles alone and gets the whole layout's values). */
static inline MicaRandom mica_random_skip(MicaRandom r, uint64_t k) { return (MicaRandom){r.state + k * 0x9E3779B97F4A7C15ULL}; }

/* Uniform in [0, 1). */
static inline double mica_random_uniform(MicaRandom *r) { return (double)(mica_random_next(r) >> 11) * 0x1.0p-53; }

#endif
