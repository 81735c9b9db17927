/* MLS shape functions per point at the bases and supports of the peers decks (issue 20, item 2): 2-D and 3-D,
 * Pascal order 1 and 2, box and ball supports, regular grids, random points. Prints CPU µs per point (best of
 * 3) and a checksum of every N, ∇N (and ∇∇N) computed, to 17 digits, so that two builds can be compared for
 * speed and for identical results (bench/bench_lean.sh runs this file against the baseline's library too).
 *   bench_shape [points] [case]   case: run only that row (0-based), e.g. under callgrind
 * Never fails on time. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "mica/mls.h"
#include "mica/random.h"

typedef struct {
  const char *what;
  int dim, order, hess;
  MlsSupportKind support;
  double dilation;
} Case;

static const Case cases[] = {
    {"beam/cook linear 2-D", 2, 1, 0, MLS_SUPPORT_BOX, 2.0},
    {"beam quadratic 2-D", 2, 2, 0, MLS_SUPPORT_BOX, 3.0},
    {"beam quadratic-d4 2-D", 2, 2, 0, MLS_SUPPORT_BOX, 4.0},
    {"hole q4fb 2-D (ball)", 2, 2, 0, MLS_SUPPORT_BALL, 2.7},
    {"strain gradient 2-D", 2, 2, 1, MLS_SUPPORT_BOX, 3.0},
    {"block linear 3-D", 3, 1, 0, MLS_SUPPORT_BOX, 2.0},
    {"block quadratic 3-D", 3, 2, 0, MLS_SUPPORT_BOX, 3.0},
    {"3-D quadratic + Hessian", 3, 2, 1, MLS_SUPPORT_BOX, 3.0},
};
enum { NCASES = sizeof cases / sizeof *cases };

static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A regular grid of spacing 0.5 on [−5, 5]^dim (21 per axis in 3-D, 41 in 2-D). */
static double *grid(int dim, long *n) {
  const int per = dim == 2 ? 41 : 21;
  const double h = 10.0 / (per - 1);
  *n = dim == 2 ? (long)per * per : (long)per * per * per;
  double *x = malloc(sizeof(double) * (size_t)(*n * dim));
  for (long p = 0; p < *n; p++) {
    long r = p;
    for (int d = 0; d < dim; d++, r /= per) x[p * dim + d] = -5.0 + h * (double)(r % per);
  }
  return x;
}

static int run_case(const Case *c, long npoints) {
  long n;
  double *x = grid(c->dim, &n), *pts = malloc(sizeof(double) * (size_t)(npoints * c->dim));
  MicaRandom rng = mica_random_seed(7);
  for (long p = 0; p < npoints * c->dim; p++) pts[p] = -3.0 + 6.0 * mica_random_uniform(&rng);
  MlsOptions opt;
  mls_options_default(&opt);
  opt.order = c->order;
  opt.support = c->support;
  opt.dilation = c->dilation;
  MlsApprox *mls;
  MlsShape *sh;
  MICA_CALL(mls_create(c->dim, n, x, &opt, &mls));
  MICA_CALL(mls_shape_create(mls, &sh));
  const int nderiv = c->hess ? MLS_HESSIAN : MLS_GRADIENT, nh = c->hess ? mls_num_hess(c->dim) : 0;
  double best = INFINITY, checksum = 0;
  long support = 0;
  for (int rep = 0; rep < 3; rep++) {
    checksum = 0, support = 0;
    const double t0 = cpu_now();
    for (long p = 0; p < npoints; p++) {
      MICA_CALL(mls_eval(mls, pts + p * c->dim, nderiv, sh));
      support += sh->n;
      for (long k = 0; k < sh->n; k++) checksum += fabs(sh->N[k]);
      for (long k = 0; k < sh->n * c->dim; k++) checksum += fabs(sh->dN[k]);
      for (long k = 0; k < sh->n * nh; k++) checksum += fabs(sh->ddN[k]);
    }
    best = fmin(best, cpu_now() - t0);
  }
  printf("%-26s m %2d  %-4s dilation %.1f  support %6.1f  %8.3f us/pt  checksum %.17g\n", c->what,
         mls_num_terms(mls), c->support == MLS_SUPPORT_BOX ? "box" : "ball", c->dilation,
         (double)support / (double)npoints, 1e6 * best / (double)npoints, checksum);
  mls_shape_destroy(&sh);
  mls_destroy(&mls);
  free(x);
  free(pts);
  return MICA_SUCCESS;
}

int main(int argc, char **argv) {
  const long npoints = argc > 1 ? atol(argv[1]) : 20000;
  const int only = argc > 2 ? atoi(argv[2]) : -1;
  for (int i = 0; i < NCASES; i++) {
    if (only >= 0 && i != only) continue;
    if (run_case(&cases[i], npoints)) {
      fprintf(stderr, "bench_shape: %s\n", mica_error_message());
      return 1;
    }
  }
  return 0;
}
