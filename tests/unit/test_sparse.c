/* Sparse matrices from cliques (src/solve/sparse.c): the pattern against a brute-force set of coupled
 * node pairs, the scatter of clique blocks against a dense accumulation, y = A x, the asymmetry measure,
 * and the contract errors (pairs outside the pattern, unsorted nodes, nodes out of range). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mica/random.h"
#include "mica/sparse.h"

/* Random cliques over nnodes nodes: sizes 1..max_size, nodes drawn with repetition (so duplicates occur),
 * and node nnodes-1 never used (an empty column). */
typedef struct {
  long nnodes, ncliques;
  long *ptr, *nodes;
} Cliques;

static Cliques random_cliques(MicaRandom *rng, long nnodes, long ncliques, long max_size) {
  Cliques c = {nnodes, ncliques, malloc((size_t)(ncliques + 1) * sizeof(long)),
               malloc((size_t)(ncliques * max_size) * sizeof(long))};
  assert_non_null(c.ptr);
  assert_non_null(c.nodes);
  c.ptr[0] = 0;
  for (long q = 0; q < ncliques; q++) {
    long size = 1 + (long)(mica_random_uniform(rng) * (double)max_size);
    if (size > max_size) size = max_size;
    for (long k = 0; k < size; k++)
      c.nodes[c.ptr[q] + k] = (long)(mica_random_uniform(rng) * (double)(nnodes - 1));
    c.ptr[q + 1] = c.ptr[q] + size;
  }
  return c;
}

static void cliques_free(Cliques *c) {
  free(c->ptr);
  free(c->nodes);
}

/* coupled[i * nnodes + j] = 1 when nodes i and j share a clique: the definition of the pattern. */
static unsigned char *brute_force_pairs(const Cliques *c) {
  unsigned char *coupled = calloc((size_t)(c->nnodes * c->nnodes), 1);
  assert_non_null(coupled);
  for (long q = 0; q < c->ncliques; q++)
    for (long a = c->ptr[q]; a < c->ptr[q + 1]; a++)
      for (long b = c->ptr[q]; b < c->ptr[q + 1]; b++) coupled[c->nodes[a] * c->nnodes + c->nodes[b]] = 1;
  return coupled;
}

static void check_pattern(const Cliques *c, int ndof) {
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(c->nnodes, ndof, c->ncliques, c->ptr, c->nodes, &A), MICA_SUCCESS);
  unsigned char *coupled = brute_force_pairs(c);
  long pairs = 0;
  for (long k = 0; k < c->nnodes * c->nnodes; k++) pairs += coupled[k];
  assert_int_equal(A->n, c->nnodes * ndof);
  assert_int_equal(A->ndof, ndof);
  assert_int_equal(A->nnz, pairs * ndof * ndof);
  assert_int_equal(A->colptr[0], 0);
  assert_int_equal(A->colptr[A->n], A->nnz);
  for (long col = 0; col < A->n; col++) {
    long expected = 0;
    for (long i = 0; i < c->nnodes; i++) expected += coupled[i * c->nnodes + col / ndof] * ndof;
    assert_int_equal(A->colptr[col + 1] - A->colptr[col], expected);
    for (long p = A->colptr[col]; p < A->colptr[col + 1]; p++) {
      long row = A->rowind[p];
      assert_true(row >= 0 && row < A->n);
      if (p > A->colptr[col]) assert_true(A->rowind[p - 1] < row); /* strictly ascending */
      assert_true(coupled[(row / ndof) * c->nnodes + col / ndof]);
      assert_true(A->val[p] == 0.0);
    }
  }
  assert_int_equal(A->colptr[A->n] - A->colptr[A->n - ndof], 0); /* the unused last node */
  free(coupled);
  mica_sparse_destroy(&A);
  assert_null(A);
}

static void test_pattern_matches_brute_force(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(11);
  for (int trial = 0; trial < 4; trial++) {
    Cliques c = random_cliques(&rng, 40 + 30 * trial, 25 + 40 * trial, 3 + 4 * trial);
    for (int ndof = 1; ndof <= 3; ndof++) check_pattern(&c, ndof);
    cliques_free(&c);
  }
}

static void test_pattern_edge_cases(void **state) {
  (void)state;
  MicaSparse *A = NULL;
  /* no cliques: an n × n matrix without entries */
  assert_int_equal(mica_sparse_create(5, 2, 0, NULL, NULL, &A), MICA_SUCCESS);
  assert_int_equal(A->n, 10);
  assert_int_equal(A->nnz, 0);
  mica_sparse_destroy(&A);
  /* node out of range, bad ndof, decreasing clique_ptr */
  const long ptr[] = {0, 2, 4}, nodes[] = {0, 1, 1, 7}, bad_ptr[] = {0, 3, 2};
  assert_int_equal(mica_sparse_create(5, 1, 2, ptr, nodes, &A), MICA_ERR_ARGUMENT);
  assert_null(A);
  assert_int_equal(mica_sparse_create(8, 0, 2, ptr, nodes, &A), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_sparse_create(8, 1, 2, bad_ptr, nodes, &A), MICA_ERR_ARGUMENT);
  mica_error_clear();
  assert_int_equal(mica_sparse_destroy(NULL), MICA_SUCCESS);
  assert_int_equal(mica_sparse_destroy(&A), MICA_SUCCESS);
}

/* ---- Scatter ------------------------------------------------------------------------------------------ */

static int compare_longs(const void *a, const void *b) {
  long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* A random clique block: B Bᵀ (symmetric positive semidefinite) or B itself (unsymmetric). */
static void random_block(MicaRandom *rng, long size, int symmetric, double *K) {
  double *B = malloc((size_t)(size * size) * sizeof *B);
  assert_non_null(B);
  for (long k = 0; k < size * size; k++) B[k] = 2.0 * mica_random_uniform(rng) - 1.0;
  for (long i = 0; i < size; i++)
    for (long j = 0; j < size; j++) {
      double sum = 0.0;
      for (long k = 0; k < size; k++) sum += B[i * size + k] * B[j * size + k];
      K[i * size + j] = symmetric ? sum : B[i * size + j];
    }
  free(B);
}

/* Assembles every clique (nodes sorted, duplicates kept) into A and into a dense matrix; both must agree. */
static void check_scatter(int ndof, int symmetric) {
  MicaRandom rng = mica_random_seed(100 + (uint64_t)ndof);
  Cliques c = random_cliques(&rng, 50, 60, 9);
  for (long q = 0; q < c.ncliques; q++) qsort(c.nodes + c.ptr[q], (size_t)(c.ptr[q + 1] - c.ptr[q]), sizeof(long), compare_longs);
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(c.nnodes, ndof, c.ncliques, c.ptr, c.nodes, &A), MICA_SUCCESS);
  long n = A->n;
  double *dense = calloc((size_t)(n * n), sizeof *dense), *K = malloc(sizeof(double) * 27 * 27);
  assert_non_null(dense);
  assert_non_null(K);
  for (long q = 0; q < c.ncliques; q++) {
    long m = c.ptr[q + 1] - c.ptr[q], size = m * ndof;
    const long *nodes = c.nodes + c.ptr[q];
    random_block(&rng, size, symmetric, K);
    assert_int_equal(mica_sparse_add_clique(A, m, nodes, K), MICA_SUCCESS);
    for (long a = 0; a < m; a++)
      for (long b = 0; b < m; b++)
        for (int i = 0; i < ndof; i++)
          for (int j = 0; j < ndof; j++)
            dense[(nodes[a] * ndof + i) * n + nodes[b] * ndof + j] += K[(a * ndof + i) * size + b * ndof + j];
  }
  /* every sparse entry matches, and the dense entries outside the pattern are zero */
  double *rebuilt = calloc((size_t)(n * n), sizeof *rebuilt);
  assert_non_null(rebuilt);
  for (long col = 0; col < n; col++)
    for (long p = A->colptr[col]; p < A->colptr[col + 1]; p++) rebuilt[A->rowind[p] * n + col] = A->val[p];
  double largest_error = 0.0;
  for (long k = 0; k < n * n; k++) largest_error = fmax(largest_error, fabs(rebuilt[k] - dense[k]));
  assert_true(largest_error <= 1e-12);
  /* y = A x against the dense product */
  double *x = malloc((size_t)n * sizeof *x), *y = malloc((size_t)n * sizeof *y);
  assert_non_null(x);
  assert_non_null(y);
  for (long i = 0; i < n; i++) x[i] = mica_random_uniform(&rng) - 0.5;
  mica_sparse_matvec(A, x, y);
  for (long i = 0; i < n; i++) {
    double expected = 0.0;
    for (long j = 0; j < n; j++) expected += dense[i * n + j] * x[j];
    assert_true(fabs(y[i] - expected) <= 1e-12 * (1.0 + fabs(expected)));
  }
  double asymmetry = mica_sparse_asymmetry(A);
  if (symmetric) assert_true(asymmetry <= 1e-15);
  else assert_true(asymmetry > 1e-3);
  mica_sparse_zero(A);
  for (long p = 0; p < A->nnz; p++) assert_true(A->val[p] == 0.0);
  assert_true(mica_sparse_asymmetry(A) == 0.0);
  free(x);
  free(y);
  free(rebuilt);
  free(dense);
  free(K);
  cliques_free(&c);
  mica_sparse_destroy(&A);
}

static void test_scatter_symmetric(void **state) {
  (void)state;
  for (int ndof = 1; ndof <= 3; ndof++) check_scatter(ndof, 1);
}

static void test_scatter_unsymmetric(void **state) {
  (void)state;
  for (int ndof = 1; ndof <= 3; ndof++) check_scatter(ndof, 0);
}

static void test_scatter_errors(void **state) {
  (void)state;
  /* cliques {0,1} and {2,3}: nodes 1 and 2 are not coupled */
  const long ptr[] = {0, 2, 4}, nodes[] = {0, 1, 2, 3};
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(4, 2, 2, ptr, nodes, &A), MICA_SUCCESS);
  double K[16] = {0};
  const long uncoupled[] = {1, 2}, unsorted[] = {1, 0}, outside[] = {3, 4};
  assert_int_equal(mica_sparse_add_clique(A, 2, uncoupled, K), MICA_ERR_ARGUMENT);
  assert_non_null(strstr(mica_error_message(), "not coupled"));
  assert_int_equal(mica_sparse_add_clique(A, 2, unsorted, K), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_sparse_add_clique(A, 2, outside, K), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_sparse_add_clique(A, 2, nodes + 2, K), MICA_SUCCESS);
  assert_int_equal(mica_sparse_add_clique(A, 0, NULL, NULL), MICA_SUCCESS);
  mica_error_clear();
  mica_sparse_destroy(&A);
}

/* Discarded values read as zero — the whole pages given back, the partial ones at the ends zeroed — and the
 * matrix takes new values after (a 3-dof pattern of some 10⁵ entries: many pages; and one smaller than a page). */
static void test_discard_values(void **state) {
  (void)state;
  MicaRandom rng = mica_random_seed(5);
  const long sizes[2] = {600, 3};
  for (int t = 0; t < 2; t++) {
    Cliques c = random_cliques(&rng, sizes[t], sizes[t], 6);
    MicaSparse *A = NULL;
    assert_int_equal(mica_sparse_create(sizes[t], 3, c.ncliques, c.ptr, c.nodes, &A), MICA_SUCCESS);
    for (long q = 0; q < A->nnz; q++) A->val[q] = 1.0 + (double)q;
    mica_sparse_discard_values(A);
    long nonzero = 0;
    for (long q = 0; q < A->nnz; q++) nonzero += A->val[q] != 0.0;
    assert_int_equal(nonzero, 0);
    for (long q = 0; q < A->nnz; q++) A->val[q] = 2.0 * (double)q;
    double sum = 0;
    for (long q = 0; q < A->nnz; q++) sum += A->val[q];
    assert_true(fabs(sum - (double)A->nnz * (double)(A->nnz - 1)) <= 1e-9 * sum);
    print_message("  discard: nnz %ld, all zero after, writable again\n", A->nnz);
    mica_sparse_destroy(&A);
    cliques_free(&c);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_pattern_matches_brute_force), cmocka_unit_test(test_pattern_edge_cases),
      cmocka_unit_test(test_scatter_symmetric),          cmocka_unit_test(test_scatter_unsymmetric),
      cmocka_unit_test(test_scatter_errors),             cmocka_unit_test(test_discard_values),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
