/* Sparse matrices from cliques (sparse.h): the pattern, the scatter of dense clique blocks, y = A x.
 *
 * Building the pattern never forms the (quadrature points × support²) list of coupled pairs:
 *   1. transpose the cliques: for each node, the cliques that contain it (O(Σ clique sizes) memory);
 *   2. for each node i, walk its cliques and collect the nodes they hold, a marker array (marker[j] == i)
 *      keeping each neighbor once: the node-level adjacency, unsorted, O(nnz of the node graph);
 *   3. sort every adjacency list at once by transposing it: the node graph is symmetric, so listing i
 *      under each of its neighbors j, for i ascending, leaves every list sorted in O(nnz) time;
 *   4. expand each node pair to a dense ndof × ndof block of dofs (dof = node × ndof + component).
 * Step 2 costs Σ (clique size)² marker tests, the lower bound for reading the cliques' couplings at all.
 *
 * The scatter walks, for each node b of a clique, the rows of b's first dof column in step with the
 * clique's ascending nodes (a merge); every column of b has the same rows, so the offset found once
 * serves all ndof columns and each pair (a, b) costs one merge step plus its ndof² additions.
 */
#define _DEFAULT_SOURCE /* madvise */
#include "mica/sparse.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

/* ---- Argument checks ---------------------------------------------------------------------------------- */

static int check_cliques(long nnodes, long ncliques, const long *clique_ptr, const long *clique_nodes) {
  MICA_CHECK(ncliques == 0 || (clique_ptr && clique_nodes), MICA_ERR_ARGUMENT,
             "mica_sparse_create: clique arrays are NULL");
  for (long c = 0; c < ncliques; c++) {
    MICA_CHECK(clique_ptr[c] >= 0 && clique_ptr[c] <= clique_ptr[c + 1], MICA_ERR_ARGUMENT,
               "mica_sparse_create: clique_ptr is not nondecreasing at clique %ld", c);
    for (long k = clique_ptr[c]; k < clique_ptr[c + 1]; k++)
      MICA_CHECK(clique_nodes[k] >= 0 && clique_nodes[k] < nnodes, MICA_ERR_ARGUMENT,
                 "mica_sparse_create: clique %ld holds node %ld, outside [0, %ld)", c, clique_nodes[k], nnodes);
  }
  return MICA_SUCCESS;
}

/* ---- Step 1: the cliques of each node ----------------------------------------------------------------- */

/* Is clique c the same node list as clique c − 1? The quadrature points of a background cell often share
 * their support: such repeats add no coupling, and skipping them saves their (clique size)² marker tests. */
static int repeats_previous(const long *clique_ptr, const long *clique_nodes, long c) {
  const long size = clique_ptr[c + 1] - clique_ptr[c];
  return c > 0 && clique_ptr[c] - clique_ptr[c - 1] == size &&
         !memcmp(clique_nodes + clique_ptr[c - 1], clique_nodes + clique_ptr[c], sizeof(long) * (size_t)size);
}

/* node_ptr[nnodes+1], node_cliques[Σ sizes]: the cliques containing node i, in ascending clique order
 * (repeats of the previous clique left out). */
static int transpose_cliques(long nnodes, long ncliques, const long *clique_ptr, const long *clique_nodes,
                             long **node_ptr_out, long **node_cliques_out) {
  long total = 0;
  long *node_ptr = NULL, *node_cliques = NULL;
  unsigned char *repeat = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(node_ptr, nnodes + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(repeat, ncliques + 1));
  for (long c = 0; c < ncliques; c++) {
    repeat[c] = (unsigned char)repeats_previous(clique_ptr, clique_nodes, c);
    if (!repeat[c]) total += clique_ptr[c + 1] - clique_ptr[c];
  }
  MICA_CALL_CLEANUP(MICA_MALLOC(node_cliques, total + 1));
  for (long c = 0; c < ncliques; c++)
    for (long k = clique_ptr[c]; k < clique_ptr[c + 1] && !repeat[c]; k++) node_ptr[clique_nodes[k] + 1]++;
  for (long i = 0; i < nnodes; i++) node_ptr[i + 1] += node_ptr[i];
  /* node_ptr[i] serves as node i's fill cursor, then is shifted back into place */
  for (long c = 0; c < ncliques; c++)
    for (long k = clique_ptr[c]; k < clique_ptr[c + 1] && !repeat[c]; k++)
      node_cliques[node_ptr[clique_nodes[k]]++] = c;
  free(repeat);
  for (long i = nnodes; i > 0; i--) node_ptr[i] = node_ptr[i - 1];
  node_ptr[0] = 0;
  *node_ptr_out = node_ptr;
  *node_cliques_out = node_cliques;
  return MICA_SUCCESS;
cleanup:
  free(node_ptr);
  free(node_cliques);
  free(repeat);
  return ierr;
}

/* ---- Step 2: node adjacency, unsorted ------------------------------------------------------------------ */

typedef struct {
  long *ptr; /* [nnodes+1] */
  long *adj; /* [ptr[nnodes]] neighbors of each node, the node itself included */
  long cap;  /* allocated length of adj */
} NodeGraph;

static int graph_append(NodeGraph *g, long count, long node) {
  if (count == g->cap) {
    g->cap = g->cap < 1024 ? 1024 : 2 * g->cap; /* doubling: amortized O(1) per neighbor */
    MICA_CALL(MICA_REALLOC(g->adj, g->cap));
  }
  g->adj[count] = node;
  return MICA_SUCCESS;
}

/* Neighbors of every node from the cliques containing it; marker[j] == i once j is listed for i. */
static int collect_neighbors(long nnodes, const long *clique_ptr, const long *clique_nodes, const long *node_ptr,
                             const long *node_cliques, NodeGraph *g) {
  long *marker = NULL, count = 0;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(marker, nnodes));
  for (long j = 0; j < nnodes; j++) marker[j] = -1;
  for (long i = 0; i < nnodes; i++) {
    g->ptr[i] = count;
    for (long q = node_ptr[i]; q < node_ptr[i + 1]; q++) {
      long c = node_cliques[q];
      for (long k = clique_ptr[c]; k < clique_ptr[c + 1]; k++) {
        long j = clique_nodes[k];
        if (marker[j] == i) continue;
        marker[j] = i;
        MICA_CALL_CLEANUP(graph_append(g, count++, j));
      }
    }
  }
  g->ptr[nnodes] = count;
cleanup:
  free(marker);
  return ierr;
}

/* ---- Step 3: sort by transposition --------------------------------------------------------------------- */

/* sorted[ptr[j] ..] lists the i with j in adj(i), i ascending; by symmetry that is adj(j), sorted. */
static int sort_by_transpose(long nnodes, const NodeGraph *g, long **sorted_out) {
  long nnz = g->ptr[nnodes], *sorted = NULL, *cursor = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(sorted, nnz));
  MICA_CALL_CLEANUP(MICA_MALLOC(cursor, nnodes));
  memcpy(cursor, g->ptr, (size_t)nnodes * sizeof *cursor);
  for (long i = 0; i < nnodes; i++)
    for (long q = g->ptr[i]; q < g->ptr[i + 1]; q++) sorted[cursor[g->adj[q]]++] = i;
  free(cursor);
  *sorted_out = sorted;
  return MICA_SUCCESS;
cleanup:
  free(sorted);
  free(cursor);
  return ierr;
}

/* ---- Step 4: dof expansion ----------------------------------------------------------------------------- */

static int expand_to_dofs(long nnodes, int ndof, const long *ptr, const long *adj, MicaSparse *A) {
  long nnz_nodes = ptr[nnodes];
  MICA_CHECK(nnz_nodes <= LONG_MAX / ((long)ndof * ndof), MICA_ERR_ARGUMENT,
             "mica_sparse_create: %ld coupled node pairs × %d² dofs overflow", nnz_nodes, ndof);
  A->n = nnodes * ndof;
  A->nnz = nnz_nodes * ndof * ndof;
  MICA_CALL(MICA_MALLOC(A->colptr, A->n + 1));
  MICA_CALL(MICA_MALLOC(A->rowind, A->nnz));
  MICA_CALL(MICA_CALLOC(A->val, A->nnz));
  MICA_CALL(MICA_MALLOC(A->cursor, A->n + 1));
  long p = 0;
  for (long i = 0; i < nnodes; i++)
    for (int c = 0; c < ndof; c++) {
      A->colptr[i * ndof + c] = p;
      for (long q = ptr[i]; q < ptr[i + 1]; q++)
        for (int r = 0; r < ndof; r++) A->rowind[p++] = adj[q] * ndof + r;
    }
  A->colptr[A->n] = p;
  return MICA_SUCCESS;
}

/* ---- Public ------------------------------------------------------------------------------------------- */

int mica_sparse_create(long nnodes, int ndof, long ncliques, const long *clique_ptr, const long *clique_nodes,
                       MicaSparse **A_out) {
  MICA_CHECK(A_out, MICA_ERR_ARGUMENT, "mica_sparse_create: A is NULL");
  *A_out = NULL;
  MICA_CHECK(nnodes >= 0 && ncliques >= 0 && ndof >= 1, MICA_ERR_ARGUMENT,
             "mica_sparse_create: nnodes %ld, ndof %d, ncliques %ld", nnodes, ndof, ncliques);
  MICA_CHECK(nnodes <= LONG_MAX / ndof, MICA_ERR_ARGUMENT, "mica_sparse_create: too many unknowns");
  MICA_CALL(check_cliques(nnodes, ncliques, clique_ptr, clique_nodes));

  long *node_ptr = NULL, *node_cliques = NULL, *sorted = NULL;
  NodeGraph graph = {NULL, NULL, 0};
  MicaSparse *A = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(transpose_cliques(nnodes, ncliques, clique_ptr, clique_nodes, &node_ptr, &node_cliques));
  MICA_CALL_CLEANUP(MICA_MALLOC(graph.ptr, nnodes + 1));
  MICA_CALL_CLEANUP(collect_neighbors(nnodes, clique_ptr, clique_nodes, node_ptr, node_cliques, &graph));
  MICA_FREE(node_ptr); /* release Σ clique sizes before the O(nnz) arrays are allocated */
  MICA_FREE(node_cliques);
  MICA_CALL_CLEANUP(sort_by_transpose(nnodes, &graph, &sorted));
  MICA_FREE(graph.adj);
  MICA_CALL_CLEANUP(MICA_CALLOC(A, 1));
  A->ndof = ndof;
  MICA_CALL_CLEANUP(expand_to_dofs(nnodes, ndof, graph.ptr, sorted, A));
  *A_out = A;
  A = NULL;
cleanup:
  free(node_ptr);
  free(node_cliques);
  free(sorted);
  free(graph.ptr);
  free(graph.adj);
  mica_sparse_destroy(&A);
  return ierr;
}

int mica_sparse_create_graph(long nnodes, int ndof, const long *ptr, const long *adj, MicaSparse **A_out) {
  MICA_CHECK(A_out && ptr && (ptr[nnodes] == 0 || adj), MICA_ERR_ARGUMENT, "mica_sparse_create_graph: NULL argument");
  *A_out = NULL;
  MICA_CHECK(nnodes >= 0 && ndof >= 1 && nnodes <= LONG_MAX / ndof, MICA_ERR_ARGUMENT,
             "mica_sparse_create_graph: nnodes %ld, ndof %d", nnodes, ndof);
  for (long q = 0; q < ptr[nnodes]; q++)
    MICA_CHECK(adj[q] >= 0 && adj[q] < nnodes, MICA_ERR_ARGUMENT,
               "mica_sparse_create_graph: neighbor %ld outside [0, %ld)", adj[q], nnodes);
  const NodeGraph graph = {(long *)ptr, (long *)adj, ptr[nnodes]};
  long *sorted = NULL;
  MicaSparse *A = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(sort_by_transpose(nnodes, &graph, &sorted));
  MICA_CALL_CLEANUP(MICA_CALLOC(A, 1));
  A->ndof = ndof;
  MICA_CALL_CLEANUP(expand_to_dofs(nnodes, ndof, ptr, sorted, A));
  *A_out = A;
  A = NULL;
cleanup:
  free(sorted);
  mica_sparse_destroy(&A);
  return ierr;
}

int mica_sparse_destroy(MicaSparse **A) {
  if (!A || !*A) return MICA_SUCCESS;
  free((*A)->colptr);
  free((*A)->rowind);
  free((*A)->val);
  free((*A)->cursor);
  MICA_FREE(*A);
  return MICA_SUCCESS;
}

void mica_sparse_zero(MicaSparse *A) {
  if (A && A->nnz > 0) memset(A->val, 0, (size_t)A->nnz * sizeof *A->val);
}

void mica_sparse_discard_values(MicaSparse *A) {
  if (!A || A->nnz <= 0) return;
  const uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE), start = (uintptr_t)A->val, end = (uintptr_t)(A->val + A->nnz);
  const uintptr_t first = (start + page - 1) & ~(page - 1), last = end & ~(page - 1); /* the whole pages inside */
  if (last <= first || madvise((void *)first, last - first, MADV_DONTNEED)) {
    mica_sparse_zero(A); /* too small, or refused: zeroed in place */
    return;
  }
  memset(A->val, 0, first - start); /* the partial pages at both ends */
  memset((void *)last, 0, end - last);
}

static int check_clique_nodes(const MicaSparse *A, long n, const long *nodes) {
  long nnodes = A->n / A->ndof;
  for (long a = 0; a < n; a++) {
    MICA_CHECK(nodes[a] >= 0 && nodes[a] < nnodes, MICA_ERR_ARGUMENT,
               "mica_sparse_add_clique: node %ld outside [0, %ld)", nodes[a], nnodes);
    MICA_CHECK(a == 0 || nodes[a - 1] <= nodes[a], MICA_ERR_ARGUMENT,
               "mica_sparse_add_clique: nodes not ascending (%ld after %ld)", nodes[a], nodes[a - 1]);
  }
  return MICA_SUCCESS;
}

/* Adds the ndof × ndof block of clique rows a, columns b, whose rows start at offset `offset` in each of
 * node b's dof columns. */
static void add_block(MicaSparse *A, long col0, long offset, const double *K, long ldk, long a, long b) {
  int ndof = A->ndof;
  for (int j = 0; j < ndof; j++) {
    double *column = A->val + A->colptr[col0 + j] + offset;
    const double *k_col = K + (a * ndof) * ldk + b * ndof + j;
    for (int i = 0; i < ndof; i++) column[i] += k_col[i * ldk];
  }
}

int mica_sparse_add_clique(MicaSparse *A, long n, const long *nodes, const double *K) {
  MICA_CHECK(A && (n == 0 || (nodes && K)), MICA_ERR_ARGUMENT, "mica_sparse_add_clique: NULL argument");
  MICA_CALL(check_clique_nodes(A, n, nodes));
  const int ndof = A->ndof;
  const long ldk = n * ndof;
  for (long b = 0; b < n; b++) {
    const long col0 = nodes[b] * ndof;
    const long start = A->colptr[col0], end = A->colptr[col0 + 1];
    long p = start;
    for (long a = 0; a < n; a++) {
      const long row0 = nodes[a] * ndof;
      /* rows come in blocks of ndof per neighbor: step a block at a time */
      while (p < end && A->rowind[p] < row0) p += ndof;
      MICA_CHECK(p < end && A->rowind[p] == row0, MICA_ERR_ARGUMENT,
                 "mica_sparse_add_clique: nodes %ld and %ld are not coupled in the pattern", nodes[a], nodes[b]);
      add_block(A, col0, p - start, K, ldk, a, b);
    }
  }
  return MICA_SUCCESS;
}

/* Position of node row0's block in column col0 (start..end), from p on: the merge step of the scatters. */
static inline long find_block(const MicaSparse *A, long p, long end, long row0) {
  while (p < end && A->rowind[p] < row0) p += A->ndof; /* rows come in blocks of ndof per neighbor */
  return p;
}

/* Is the block of pair (a, b) zero? The union of several cliques may pair nodes that no clique couples. */
static int block_is_zero(const double *K, long ldr, long np, int ndof, long a, long b) {
  for (int j = 0; j < ndof; j++)
    for (int i = 0; i < ndof; i++)
      if (K[(b * ndof + j) * ldr + i * np + a] != 0.0) return 0;
  return 1;
}

/* Column (b j) of A gets row (b j) of the planar K, for the row nodes a ≤ b (upper) or all a. */
static int add_clique_columns(MicaSparse *A, long n, const long *nodes, const double *K, long np, int upper) {
  MICA_CHECK(A && (n == 0 || (nodes && K)) && np >= n, MICA_ERR_ARGUMENT,
             "mica_sparse_add_clique_%s: NULL argument or row length %ld < %ld", upper ? "upper" : "columns", np, n);
  MICA_CALL(check_clique_nodes(A, n, nodes));
  const int ndof = A->ndof;
  const long ldr = ndof * np; /* one row: ndof runs of np */
  for (long b = 0; b < n; b++) {
    const long col0 = nodes[b] * ndof, start = A->colptr[col0], end = A->colptr[col0 + 1];
    long p = start;
    for (long a = 0; a < (upper ? b + 1 : n); a++) {
      const long next = find_block(A, p, end, nodes[a] * ndof);
      if (next >= end || A->rowind[next] != nodes[a] * ndof) {
        MICA_CHECK(block_is_zero(K, ldr, np, ndof, a, b), MICA_ERR_ARGUMENT,
                   "mica_sparse_add_clique_%s: nodes %ld and %ld are not coupled in the pattern",
                   upper ? "upper" : "columns", nodes[a], nodes[b]);
        continue;
      }
      p = next;
      for (int j = 0; j < ndof; j++) { /* row (b j) of K is column (b j) of A */
        double *column = A->val + A->colptr[col0 + j] + (p - start);
        const double *k = K + (b * ndof + j) * ldr + a;
        for (int i = 0; i < ndof; i++) column[i] += k[i * np];
      }
    }
  }
  return MICA_SUCCESS;
}

int mica_sparse_add_clique_upper(MicaSparse *A, long n, const long *nodes, const double *K, long np) {
  return add_clique_columns(A, n, nodes, K, np, 1);
}

int mica_sparse_add_clique_columns(MicaSparse *A, long n, const long *nodes, const double *K, long np) {
  return add_clique_columns(A, n, nodes, K, np, 0);
}

/* Column j's entries above the diagonal, (i, j) with i < j, go to (j, i) in column i; as j grows, the rows j of
 * each column i are met in ascending order, so a cursor per column finds them in one pass. */
void mica_sparse_mirror_upper(MicaSparse *A) {
  for (long i = 0; i < A->n; i++) A->cursor[i] = A->colptr[i];
  for (long j = 0; j < A->n; j++)
    for (long p = A->colptr[j]; p < A->colptr[j + 1] && A->rowind[p] < j; p++) {
      const long i = A->rowind[p];
      long q = A->cursor[i];
      while (A->rowind[q] < j) q++;
      A->val[q] = A->val[p];
      A->cursor[i] = q + 1;
    }
}

void mica_sparse_matvec(const MicaSparse *A, const double *x, double *y) {
  memset(y, 0, (size_t)A->n * sizeof *y);
  for (long j = 0; j < A->n; j++) {
    const double xj = x[j];
    for (long p = A->colptr[j]; p < A->colptr[j + 1]; p++) y[A->rowind[p]] += A->val[p] * xj;
  }
}

/* Position of row i in column j, or -1: binary search of the sorted rows. */
static long find_entry(const MicaSparse *A, long i, long j) {
  long lo = A->colptr[j], hi = A->colptr[j + 1];
  while (lo < hi) {
    long mid = lo + (hi - lo) / 2;
    if (A->rowind[mid] < i) lo = mid + 1;
    else hi = mid;
  }
  return lo < A->colptr[j + 1] && A->rowind[lo] == i ? lo : -1;
}

double mica_sparse_asymmetry(const MicaSparse *A) {
  double largest = 0.0, largest_difference = 0.0;
  for (long j = 0; j < A->n; j++)
    for (long p = A->colptr[j]; p < A->colptr[j + 1]; p++) {
      long i = A->rowind[p], q = find_entry(A, j, i);
      double transposed = q >= 0 ? A->val[q] : 0.0;
      largest = fmax(largest, fabs(A->val[p]));
      largest_difference = fmax(largest_difference, fabs(A->val[p] - transposed));
    }
  return largest > 0.0 ? largest_difference / largest : 0.0;
}

void mica_sparse_zero_row(MicaSparse *A, long i) {
  for (long p = A->colptr[i]; p < A->colptr[i + 1]; p++) {
    const long q = find_entry(A, i, A->rowind[p]);
    if (q >= 0) A->val[q] = 0.0;
  }
}

int mica_sparse_set(MicaSparse *A, long i, long j, double value) {
  MICA_CHECK(i >= 0 && i < A->n && j >= 0 && j < A->n, MICA_ERR_ARGUMENT, "mica_sparse_set: (%ld, %ld) outside the matrix", i, j);
  const long q = find_entry(A, i, j);
  MICA_CHECK(q >= 0, MICA_ERR_ARGUMENT, "mica_sparse_set: (%ld, %ld) is not in the pattern", i, j);
  A->val[q] = value;
  return MICA_SUCCESS;
}
