/* Benchmark of the neighbor search (src/mls/search.c) in 3-D: jittered grids of about N = 1e3 .. 1e6
 * particles (spacing h, jitter ±0.25 h per axis), box supports of radius 2.5 h (about 125 supporting
 * particles per point), k-d tree and cells.
 *
 * For each N and kind it prints the time to build (create + set_supports), the time to answer N support
 * queries at points near the particles (in particle order, as an assembly loop would), the time of the
 * local spacing (kNN per particle, the same for both kinds), and each cost per particle relative to
 * N = 1e3: ratios near 1 mean O(N) in total, ratios growing like log N mean O(N log N). Small N are
 * repeated (about 1e5 particles' worth) so their times are not lost in timer noise. The number of
 * supports per query grows with N (fewer points near the boundary), which accounts for part of the query
 * ratio. It only reports figures: it never fails on time.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "mica/mls.h"
#include "mica/timer.h"

static uint64_t rng_state = 88172645463325252ULL;
static double uniform(double a, double b) {
  rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
  return a + (b - a) * ((double)(rng_state >> 11) * 0x1.0p-53);
}

/* m³ particles with spacing h on [0, 1]³, each moved by up to a quarter spacing per axis. */
static double *jittered_grid(long m, double h) {
  double *x = malloc((size_t)(m * m * m * 3) * sizeof *x);
  if (!x) return NULL;
  long i = 0;
  for (long a = 0; a < m; a++)
    for (long b = 0; b < m; b++)
      for (long c = 0; c < m; c++, i++) {
        x[3 * i + 0] = (a + 0.5) * h + uniform(-0.25, 0.25) * h;
        x[3 * i + 1] = (b + 0.5) * h + uniform(-0.25, 0.25) * h;
        x[3 * i + 2] = (c + 0.5) * h + uniform(-0.25, 0.25) * h;
      }
  return x;
}

typedef struct {
  long n;
  double build, query, spacing; /* seconds */
  double supports;              /* mean supporting particles per query */
} Timing;

/* N queries at points near the particles, repeated reps times; t->query is the time of one round. */
static int time_queries(const MlsSearch *search, long n, const double *x, double h, int reps, Timing *t) {
  long *index = NULL, count = 0, cap = 0, total = 0;
  double start = mica_wtime();
  for (int r = 0; r < reps; r++)
    for (long i = 0; i < n; i++) {
      const double p[3] = {x[3 * i] + 0.3 * h, x[3 * i + 1] - 0.2 * h, x[3 * i + 2] + 0.1 * h};
      MICA_CALL(mls_search_query(search, p, &index, &count, &cap));
      total += count;
    }
  t->query = (mica_wtime() - start) / reps;
  t->supports = (double)total / ((double)n * reps);
  free(index);
  return MICA_SUCCESS;
}

/* create + set_supports, repeated reps times (all but the last search destroyed); time of one. */
static int time_build(long n, const double *x, const double *radii, MlsSearchKind kind, int reps,
                      MlsSearch **search, Timing *t) {
  double start = mica_wtime();
  for (int r = 0; r < reps; r++) {
    mls_search_destroy(search);
    MICA_CALL(mls_search_create(3, n, x, kind, search));
    MICA_CALL(mls_search_set_supports(*search, MLS_SUPPORT_BOX, radii));
  }
  t->build = (mica_wtime() - start) / reps;
  return MICA_SUCCESS;
}

static int time_spacing(const MlsSearch *search, double *spacing, int reps, Timing *t) {
  double start = mica_wtime();
  for (int r = 0; r < reps; r++) MICA_CALL(mls_search_local_spacing(search, spacing));
  t->spacing = (mica_wtime() - start) / reps;
  return MICA_SUCCESS;
}

static int run_one(long m, MlsSearchKind kind, Timing *t) {
  const double h = 1.0 / (double)m;
  const long n = m * m * m;
  double *x = jittered_grid(m, h), *radii = malloc((size_t)(n * 3) * sizeof *radii);
  double *spacing = malloc((size_t)(n * 3) * sizeof *spacing);
  MlsSearch *search = NULL;
  int ierr = MICA_SUCCESS;
  if (!x || !radii || !spacing) {
    ierr = MICA_ERR_MEMORY;
    goto cleanup;
  }
  for (long j = 0; j < n * 3; j++) radii[j] = 2.5 * h;
  t->n = n;
  const int reps = n < 100000 ? (int)(100000 / n) : 1;
  MICA_CALL_CLEANUP(time_build(n, x, radii, kind, reps, &search, t));
  MICA_CALL_CLEANUP(time_queries(search, n, x, h, reps, t));
  MICA_CALL_CLEANUP(time_spacing(search, spacing, reps, t));
cleanup:
  mls_search_destroy(&search);
  free(x);
  free(radii);
  free(spacing);
  return ierr;
}

static void print_row(const char *kind, const Timing *t, const Timing *base) {
  double per = 1e6 / (double)t->n, base_per = 1e6 / (double)base->n;
  printf("%-7s %8ld %9.4f %6.2f %9.4f %8.3f %6.2f %9.4f %6.2f %7.1f\n", kind, t->n, t->build,
         (t->build * per) / (base->build * base_per), t->query, t->query * per,
         (t->query * per) / (base->query * base_per), t->spacing,
         (t->spacing * per) / (base->spacing * base_per), t->supports);
}

int main(void) {
  const long sides[] = {10, 22, 46, 100}; /* N = 1000, 10648, 97336, 1000000 */
  const int nsizes = (int)(sizeof sides / sizeof sides[0]);
  const struct {
    const char *name;
    MlsSearchKind kind;
  } kinds[] = {{"kdtree", MLS_SEARCH_KDTREE}, {"cells", MLS_SEARCH_CELLS}};
  printf("neighbor search, 3-D jittered grid, box supports of radius 2.5 h\n");
  printf("ratio = cost per particle / cost per particle at N = 1000\n");
  printf("%-7s %8s %9s %6s %9s %8s %6s %9s %6s %7s\n", "kind", "N", "build[s]", "ratio", "query[s]",
         "us/query", "ratio", "spacing", "ratio", "hits/q");
  for (int k = 0; k < 2; k++) {
    Timing base = {0}, t = {0};
    for (int s = 0; s < nsizes; s++) {
      int ierr = run_one(sides[s], kinds[k].kind, &t);
      if (ierr) {
        mica_error_report("bench_search");
        return 1;
      }
      if (s == 0) base = t;
      print_row(kinds[k].name, &t, &base);
      fflush(stdout);
    }
  }
  return 0;
}
