/* parallel.data = "distributed": the whole tangent's nnz from the ranks' parts, counted where the rows are owned
 * (summary.json's nnz; run_parallel.c). Only the ghost nodes' rows travel, as node pairs: the tangent's entries come
 * in ndof × ndof blocks. Split from own.c, which builds the distribution this reads. */
#include <mpi.h>
#include <stdlib.h>

#include "mica/parallel.h"
#include "mica/sort.h"
#include "parallel_private.h"

typedef struct {
  long row, col;
} Entry;

static int compare_entry(const void *a, const void *b) {
  const Entry *x = a, *y = b;
  return x->row != y->row ? (x->row > y->row) - (x->row < y->row) : (x->col > y->col) - (x->col < y->col);
}

static int node_owner(const MicaDistribution *dist, long k) {
  const long nlocal = dist->nowned + dist->nghost;
  return k < nlocal ? dist->partition->part[k] : dist->extra_owner[k - nlocal];
}

/* The tangent's entries come in nd × nd blocks (a clique of nodes couples all their unknowns), so its nnz is nd²
 * times the number of node pairs, which is what is counted: the ghost rows send 1/nd² of their entries (at 33³,
 * P = 2: 0.6 of the 0.8 s the count took sending and sorting every entry). A node's neighbors are the nodes of
 * column nd·k's rows nd·i. */
static long node_neighbors(const MicaSparse *K, long k, const long *global_node, long *out) {
  const long nd = K->ndof, j = k * nd;
  long len = 0;
  for (long q = K->colptr[j]; q < K->colptr[j + 1]; q++)
    if (K->rowind[q] % nd == 0) {
      if (out) out[len] = global_node ? global_node[K->rowind[q] / nd] : K->rowind[q] / nd;
      len++;
    }
  return len;
}

/* The distinct neighbors of owned node k together with the received ones, got[0 .. ngot) (sorted, one node's). */
static long union_count(const MicaSparse *K, const long *global_node, long k, const Entry *got, long ngot,
                        long *scratch) {
  const long len = node_neighbors(K, k, global_node, scratch);
  qsort(scratch, (size_t)len, sizeof *scratch, mica_compare_long);
  long count = len, a = 0;
  for (long e = 0; e < ngot; e++) {
    if (e > 0 && got[e].col == got[e - 1].col) continue;
    while (a < len && scratch[a] < got[e].col) a++;
    count += a >= len || scratch[a] != got[e].col;
  }
  return count;
}

int mica_owned_matrix_nnz(const MicaDistribution *dist, const MicaSparse *K, long *nnz) {
  const int P = mica_parallel_size(), rank = mica_parallel_rank();
  const long nd = K->ndof, nnodes = K->n / nd;
  int *counts = NULL, *rcounts = NULL, *displs = NULL, *rdispls = NULL;
  Entry *send = NULL, *got = NULL;
  long *owned = NULL, *scratch = NULL, longest = 1, nsend = 0, nowned = 0, mine = 0;
  int ierr = MICA_CALLOC(counts, 4L * (P + 1));
  if (!ierr) rcounts = counts + P + 1, displs = rcounts + P + 1, rdispls = displs + P + 1;
  for (long k = 0; k < nnodes && !ierr; k++) { /* ghost nodes' rows go to their owners, as (row, column) pairs */
    const long len = node_neighbors(K, k, NULL, NULL);
    if (len > longest) longest = len;
    const int to = node_owner(dist, k);
    if (to != rank) counts[to] += (int)len, nsend += len;
    else nowned++;
  }
  if (!ierr && nsend >= (1L << 30)) ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                                                         "%ld ghost-row entries exceed MPI's counts", nsend);
  if (!ierr) ierr = MICA_MALLOC(send, nsend + 1);
  if (!ierr) ierr = MICA_MALLOC(owned, 2 * nowned + 1); /* (global node, local node) of the owned rows */
  if (!ierr) ierr = MICA_MALLOC(scratch, longest + 1);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoall(counts, 1, MPI_INT, rcounts, 1, MPI_INT, mica_parallel_comm());
  for (int r = 0; r < P; r++) displs[r + 1] = displs[r] + counts[r], rdispls[r + 1] = rdispls[r] + rcounts[r];
  for (long k = 0, o = 0; k < nnodes; k++) {
    const long gk = dist->global_node[k];
    const int to = node_owner(dist, k);
    if (to == rank) {
      owned[2 * o] = gk, owned[2 * o + 1] = k, o++;
      continue;
    }
    const long len = node_neighbors(K, k, dist->global_node, scratch);
    for (long q = 0; q < len; q++) send[displs[to]++] = (Entry){gk, scratch[q]};
  }
  for (int r = P; r > 0; r--) displs[r] = displs[r - 1]; /* the cursors moved them one block on */
  displs[0] = 0;
  const long ngot = rdispls[P];
  ierr = MICA_MALLOC(got, ngot + 1);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  for (int r = 0; r <= P; r++) counts[r] *= 2, displs[r] *= 2, rcounts[r] *= 2, rdispls[r] *= 2; /* longs */
  MPI_Alltoallv(send, counts, displs, MPI_LONG, got, rcounts, rdispls, MPI_LONG, mica_parallel_comm());
  qsort(got, (size_t)ngot, sizeof *got, compare_entry);
  qsort(owned, (size_t)nowned, 2 * sizeof *owned, mica_compare_long); /* by global node */
  /* the owned nodes: their own neighbors, and the received ones merged in */
  for (long o = 0; o < nowned; o++) mine += node_neighbors(K, owned[2 * o + 1], NULL, NULL);
  for (long e = 0; e < ngot;) {
    long end = e;
    while (end < ngot && got[end].row == got[e].row) end++;
    long lo = 0, hi = nowned; /* the row's local node: owned[] by global number */
    while (hi - lo > 1) {
      const long mid = (lo + hi) / 2;
      if (owned[2 * mid] <= got[e].row) lo = mid;
      else hi = mid;
    }
    if (nowned && owned[2 * lo] == got[e].row) {
      const long k = owned[2 * lo + 1];
      mine += union_count(K, dist->global_node, k, got + e, end - e, scratch) - node_neighbors(K, k, NULL, NULL);
    } else { /* a node this rank owns but holds no column of: the received neighbors alone */
      for (long f = e; f < end; f++) mine += f == e || got[f].col != got[f - 1].col;
    }
    e = end;
  }
  MPI_Allreduce(&mine, nnz, 1, MPI_LONG, MPI_SUM, mica_parallel_comm());
  *nnz *= nd * nd;
cleanup:
  free(counts), free(send), free(got), free(owned), free(scratch);
  return ierr;
}
