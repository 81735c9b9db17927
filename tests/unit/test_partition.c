/* The partition of parallel runs (src/parallel/partition.c), without MPI: supports of points from the
 * neighbor search against a brute-force scan of the radii, the particle graph against brute-force pairs,
 * the METIS k-way partition (every particle in exactly one part, no part empty, its edge cut recounted),
 * ghosts (every particle of every support touching an owned point is owned or a ghost, and nothing else is
 * a ghost) and overlaps (layers of graph neighbors). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mica/parallel.h"

typedef struct {
  int dim;
  long n, npoints;
  double *x, *q;
  MlsApprox *mls;
  long *ptr, *index, *nearest;
} Grid;

/* nx × ny particles on [0,1]², slightly jittered; points on a (2 nx) × (2 ny) grid of cell centers. */
static Grid grid_create(long nx, long ny, double dilation) {
  Grid g = {2, nx * ny, 4 * nx * ny, NULL, NULL, NULL, NULL, NULL, NULL};
  g.x = malloc(sizeof(double) * (size_t)(2 * g.n));
  g.q = malloc(sizeof(double) * (size_t)(2 * g.npoints));
  assert_non_null(g.x);
  assert_non_null(g.q);
  for (long j = 0; j < ny; j++)
    for (long i = 0; i < nx; i++) {
      const double jitter = 0.1 * sin(7.0 * (double)(i * ny + j)) / (double)nx;
      g.x[(j * nx + i) * 2] = (double)i / (double)(nx - 1) + (i > 0 && i < nx - 1 ? jitter : 0);
      g.x[(j * nx + i) * 2 + 1] = (double)j / (double)(ny - 1);
    }
  for (long j = 0; j < 2 * ny; j++)
    for (long i = 0; i < 2 * nx; i++) {
      g.q[(j * 2 * nx + i) * 2] = (i + 0.5) / (double)(2 * nx);
      g.q[(j * 2 * nx + i) * 2 + 1] = (j + 0.5) / (double)(2 * ny);
    }
  MlsOptions opt;
  mls_options_default(&opt);
  opt.dilation = dilation;
  assert_int_equal(mls_create(2, g.n, g.x, &opt, &g.mls), MICA_SUCCESS);
  g.nearest = malloc(sizeof(long) * (size_t)g.npoints);
  assert_non_null(g.nearest);
  assert_int_equal(mica_point_supports(g.mls, g.npoints, g.q, &g.ptr, &g.index, g.nearest), MICA_SUCCESS);
  return g;
}

static void grid_free(Grid *g) {
  mls_destroy(&g->mls);
  free(g->x), free(g->q), free(g->ptr), free(g->index), free(g->nearest);
}

/* Normalized box distance of point q to particle i. */
static double box_distance(const Grid *g, long p, long i) {
  const double *radii = mls_radii(g->mls);
  double r = 0;
  for (int d = 0; d < 2; d++) r = fmax(r, fabs(g->q[p * 2 + d] - g->x[i * 2 + d]) / radii[i * 2 + d]);
  return r;
}

static void test_supports_brute_force(void **state) {
  (void)state;
  Grid g = grid_create(12, 9, 2.2);
  for (long p = 0; p < g.npoints; p++) {
    long k = g.ptr[p], best = -1;
    double best_r = INFINITY;
    for (long i = 0; i < g.n; i++) {
      const double r = box_distance(&g, p, i);
      if (r < 1) {
        assert_true(k < g.ptr[p + 1]);
        assert_int_equal(g.index[k++], i); /* ascending, none missed, none extra */
        if (r < best_r) best_r = r, best = i;
      }
    }
    assert_int_equal(k, g.ptr[p + 1]);
    assert_int_equal(g.nearest[p], best);
  }
  grid_free(&g);
}

static int adjacent_brute_force(const Grid *g, long a, long b) {
  for (long p = 0; p < g->npoints; p++) {
    int has_a = 0, has_b = 0;
    for (long e = g->ptr[p]; e < g->ptr[p + 1]; e++) has_a |= g->index[e] == a, has_b |= g->index[e] == b;
    if (has_a && has_b) return 1;
  }
  return 0;
}

static void check_partition(const Grid *g, const MicaPartition *p, int nparts) {
  assert_int_equal(p->nparts, nparts);
  long *count = calloc((size_t)nparts, sizeof *count);
  assert_non_null(count);
  for (long i = 0; i < g->n; i++) {
    assert_true(p->part[i] >= 0 && p->part[i] < nparts); /* every particle in exactly one part */
    count[p->part[i]]++;
  }
  long total = 0;
  for (int r = 0; r < nparts; r++) {
    assert_true(count[r] > 0);
    assert_int_equal(count[r], p->part_size[r]);
    total += count[r];
  }
  assert_int_equal(total, g->n);
  long cut = 0;
  for (long i = 0; i < g->n; i++)
    for (long q = p->xadj[i]; q < p->xadj[i + 1]; q++)
      if (p->adjncy[q] > i && p->part[p->adjncy[q]] != p->part[i]) cut++;
  assert_int_equal(cut, p->edge_cut);
  assert_true(nparts == 1 ? cut == 0 : cut > 0);
  assert_true(p->imbalance >= 1.0 && p->imbalance < 1.2);
  free(count);
}

static void test_graph_and_partition(void **state) {
  (void)state;
  Grid g = grid_create(10, 8, 2.0);
  for (int nparts = 1; nparts <= 4; nparts++) {
    MicaPartition *p = NULL;
    assert_int_equal(mica_partition_create(g.n, g.npoints, g.ptr, g.index, NULL, nparts, &p), MICA_SUCCESS);
    if (nparts == 1) /* the graph: neighbors exactly the particles sharing a point, ascending, no self */
      for (long a = 0; a < g.n; a++) {
        long q = p->xadj[a];
        for (long b = 0; b < g.n; b++) {
          if (b == a || !adjacent_brute_force(&g, a, b)) continue;
          assert_true(q < p->xadj[a + 1]);
          assert_int_equal(p->adjncy[q++], b);
        }
        assert_int_equal(q, p->xadj[a + 1]);
      }
    check_partition(&g, p, nparts);
    mica_partition_destroy(&p);
    assert_null(p);
  }
  grid_free(&g);
}

static void test_ghosts_cover_supports(void **state) {
  (void)state;
  Grid g = grid_create(14, 11, 2.5);
  MicaPartition *p = NULL;
  assert_int_equal(mica_partition_create(g.n, g.npoints, g.ptr, g.index, NULL, 3, &p), MICA_SUCCESS);
  int *owner = malloc(sizeof(int) * (size_t)g.npoints);
  char *needed = malloc((size_t)g.n);
  assert_non_null(owner);
  assert_non_null(needed);
  for (long q = 0; q < g.npoints; q++) owner[q] = p->part[g.nearest[q]];
  for (int rank = 0; rank < 3; rank++) {
    long nghost = 0, *ghosts = NULL;
    assert_int_equal(mica_partition_ghosts(p, rank, g.npoints, g.ptr, g.index, owner, &nghost, &ghosts), MICA_SUCCESS);
    memset(needed, 0, (size_t)g.n);
    for (long q = 0; q < g.npoints; q++)
      if (owner[q] == rank)
        for (long e = g.ptr[q]; e < g.ptr[q + 1]; e++) needed[g.index[e]] = 1;
    long expected = 0;
    for (long i = 0; i < g.n; i++) expected += needed[i] && p->part[i] != rank;
    assert_int_equal(nghost, expected);
    assert_true(nghost > 0);
    for (long k = 0; k < nghost; k++) {
      assert_true(needed[ghosts[k]]);           /* in a support touching an owned point */
      assert_int_not_equal(p->part[ghosts[k]], rank); /* owned by another rank */
      if (k > 0) assert_true(ghosts[k] > ghosts[k - 1]);
    }
    /* every ghost shares a point with that point's nearest particle, which this rank owns: a graph neighbor */
    for (long k = 0; k < nghost; k++) {
      int neighbor = 0;
      for (long q = p->xadj[ghosts[k]]; q < p->xadj[ghosts[k] + 1] && !neighbor; q++)
        neighbor = p->part[p->adjncy[q]] == rank;
      assert_true(neighbor);
    }
    free(ghosts);
  }
  free(owner);
  free(needed);
  mica_partition_destroy(&p);
  grid_free(&g);
}

static void test_too_many_parts(void **state) {
  (void)state;
  Grid g = grid_create(3, 3, 2.0);
  MicaPartition *p = NULL;
  assert_int_equal(mica_partition_create(g.n, g.npoints, g.ptr, g.index, NULL, 10, &p), MICA_ERR_INPUT);
  assert_null(p);
  grid_free(&g);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_supports_brute_force),
      cmocka_unit_test(test_graph_and_partition),
      cmocka_unit_test(test_ghosts_cover_supports),
      cmocka_unit_test(test_too_many_parts),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
