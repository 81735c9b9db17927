/* Moving tangent contributions to the ranks that factor them (parallel_private.h).
 *
 * Each rank holds the contributions of its own quadrature points in a matrix with the global numbering
 * (its own, smaller pattern). A target rank s wants the entries (i, j) with both nodes in its set S_s,
 * summed over the ranks, in a matrix numbered by S_s. The first exchange sends the (row, column) of every
 * such entry; the target builds its pattern (sorted, duplicates merged) and remembers where each received
 * entry goes. Every factorization then moves only values: one MPI_Alltoallv and a scatter-add, no search. */
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "parallel_private.h"

static int compare_long(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

static int to_int_counts(const long *counts, int n, int *out) {
  for (int r = 0; r < n; r++) {
    MICA_CHECK(counts[r] < (1L << 30), MICA_ERR_ARGUMENT,
               "%ld matrix entries to move to one rank exceed MPI's int counts", counts[r]);
    out[r] = (int)counts[r];
  }
  return MICA_SUCCESS;
}

/* Sets the local numbering of target rank's nodes: local[node] = position in S, or −1. */
static long number_nodes(const char *member, long nnodes, long *local) {
  long count = 0;
  for (long i = 0; i < nnodes; i++) local[i] = member[i] ? count++ : -1;
  return count;
}

/* The pattern of the received (row, column) pairs (local dof numbers), and the map of each pair into it. */
static int build_target(Redistribution *rd, const long *pairs, long npairs, long n, int ndof) {
  long *keys = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(keys, npairs + 1));
  for (long k = 0; k < npairs; k++) keys[k] = pairs[2 * k + 1] * n + pairs[2 * k]; /* column-major */
  qsort(keys, (size_t)npairs, sizeof *keys, compare_long);
  long unique = 0;
  for (long k = 0; k < npairs; k++)
    if (k == 0 || keys[k] != keys[unique - 1]) keys[unique++] = keys[k];
  MicaSparse *A = NULL;
  MICA_CALL_CLEANUP(MICA_CALLOC(A, 1));
  rd->A = A;
  A->n = n;
  A->nnz = unique;
  A->ndof = ndof;
  MICA_CALL_CLEANUP(MICA_CALLOC(A->colptr, n + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(A->rowind, unique + 1));
  MICA_CALL_CLEANUP(MICA_CALLOC(A->val, unique + 1));
  for (long k = 0; k < unique; k++) {
    A->rowind[k] = keys[k] % n;
    A->colptr[keys[k] / n + 1]++;
  }
  for (long j = 0; j < n; j++) A->colptr[j + 1] += A->colptr[j];
  MICA_CALL_CLEANUP(MICA_MALLOC(rd->recv_map, npairs + 1));
  for (long k = 0; k < npairs; k++) { /* binary search of the row in its column */
    const long i = pairs[2 * k], j = pairs[2 * k + 1];
    long lo = A->colptr[j], hi = A->colptr[j + 1];
    while (lo < hi) {
      const long mid = lo + (hi - lo) / 2;
      if (A->rowind[mid] < i) lo = mid + 1;
      else hi = mid;
    }
    rd->recv_map[k] = lo;
  }
cleanup:
  free(keys);
  return ierr;
}

int redistribution_create(const MicaSparse *L, const char *const *member, long nnodes, Redistribution **out) {
  *out = NULL;
  const int P = mica_parallel_size(), me = mica_parallel_rank(), ndof = L->ndof;
  Redistribution *rd = NULL;
  long *local = NULL, *send_count = NULL, *recv_count = NULL, *pairs_out = NULL, *pairs_in = NULL;
  int *sc = NULL, *sd = NULL, *rc = NULL, *rdsp = NULL;
  long *cursor = NULL;
  int ierr = MICA_CALLOC(rd, 1);
  if (!ierr) ierr = MICA_CALLOC(rd->send_counts, P);
  if (!ierr) ierr = MICA_CALLOC(rd->send_displs, P + 1);
  if (!ierr) ierr = MICA_CALLOC(rd->recv_counts, P);
  if (!ierr) ierr = MICA_CALLOC(rd->recv_displs, P + 1);
  if (!ierr) ierr = MICA_CALLOC(send_count, P);
  if (!ierr) ierr = MICA_CALLOC(recv_count, P);
  if (!ierr) ierr = MICA_CALLOC(cursor, P);
  if (!ierr) ierr = MICA_MALLOC(sc, P);
  if (!ierr) ierr = MICA_MALLOC(sd, P);
  if (!ierr) ierr = MICA_MALLOC(rc, P);
  if (!ierr) ierr = MICA_MALLOC(rdsp, P);
  if (!ierr) ierr = MICA_MALLOC(local, nnodes);
  /* count, then list, the local entries each target wants */
  for (long j = 0; j < L->n && !ierr; j++) {
    const long nj = j / ndof;
    for (int s = 0; s < P; s++) {
      if (!member[s] || !member[s][nj]) continue;
      for (long q = L->colptr[j]; q < L->colptr[j + 1]; q++) send_count[s] += member[s][L->rowind[q] / ndof];
    }
  }
  long total_send = 0;
  for (int s = 0; s < P; s++) total_send += send_count[s];
  if (!ierr && total_send >= (1L << 30))
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                          "%ld matrix entries to send exceed MPI's int counts", total_send);
  for (int s = 0; s < P && !ierr; s++) rd->send_displs[s + 1] = rd->send_displs[s] + (int)send_count[s];
  if (!ierr) ierr = MICA_MALLOC(rd->send_pos, total_send + 1);
  if (!ierr) ierr = MICA_MALLOC(rd->send_buf, total_send + 1);
  if (!ierr) ierr = MICA_MALLOC(pairs_out, 2 * total_send + 1);
  if (!ierr) ierr = to_int_counts(send_count, P, rd->send_counts);
  for (int s = 0; s < P && !ierr; s++) {
    if (!member[s]) continue;
    number_nodes(member[s], nnodes, local);
    long k = rd->send_displs[s];
    for (long j = 0; j < L->n; j++) {
      const long nj = j / ndof;
      if (!member[s][nj]) continue;
      for (long q = L->colptr[j]; q < L->colptr[j + 1]; q++) {
        const long i = L->rowind[q], ni = i / ndof;
        if (!member[s][ni]) continue;
        rd->send_pos[k] = q;
        pairs_out[2 * k] = local[ni] * ndof + i % ndof;
        pairs_out[2 * k + 1] = local[nj] * ndof + j % ndof;
        k++;
      }
    }
  }
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoall(send_count, 1, MPI_LONG, recv_count, 1, MPI_LONG, mica_parallel_comm());
  ierr = to_int_counts(recv_count, P, rd->recv_counts);
  long total_recv = 0;
  for (int s = 0; s < P; s++) total_recv += recv_count[s];
  if (!ierr && total_recv >= (1L << 30))
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                          "%ld matrix entries to receive exceed MPI's int counts", total_recv);
  for (int s = 0; s < P && !ierr; s++) rd->recv_displs[s + 1] = rd->recv_displs[s] + rd->recv_counts[s];
  if (!ierr) ierr = MICA_MALLOC(pairs_in, 2 * total_recv + 1);
  if (!ierr) ierr = MICA_MALLOC(rd->recv_buf, total_recv + 1);
  for (int s = 0; s < P && !ierr; s++) {
    sc[s] = 2 * rd->send_counts[s], sd[s] = 2 * rd->send_displs[s];
    rc[s] = 2 * rd->recv_counts[s], rdsp[s] = 2 * rd->recv_displs[s];
  }
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoallv(pairs_out, sc, sd, MPI_LONG, pairs_in, rc, rdsp, MPI_LONG, mica_parallel_comm());
  rd->nrecv = total_recv;
  ierr = MICA_SUCCESS;
  if (member[me]) {
    const long nlocal = number_nodes(member[me], nnodes, local);
    ierr = build_target(rd, pairs_in, total_recv, nlocal * ndof, ndof);
  }
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  *out = rd;
  rd = NULL;
cleanup:
  redistribution_destroy(&rd);
  free(local), free(send_count), free(recv_count), free(pairs_out), free(pairs_in), free(cursor);
  free(sc), free(sd), free(rc), free(rdsp);
  return ierr;
}

int redistribution_move(Redistribution *rd, int ierr, const MicaSparse *L) {
  if (!ierr)
    for (int s = 0, P = mica_parallel_size(); s < P; s++)
      for (long k = rd->send_displs[s]; k < rd->send_displs[s + 1]; k++) rd->send_buf[k] = L->val[rd->send_pos[k]];
  MICA_CALL(mica_parallel_agree(ierr));
  MPI_Alltoallv(rd->send_buf, rd->send_counts, rd->send_displs, MPI_DOUBLE, rd->recv_buf, rd->recv_counts,
                rd->recv_displs, MPI_DOUBLE, mica_parallel_comm());
  if (rd->A) {
    mica_sparse_zero(rd->A);
    for (long k = 0; k < rd->nrecv; k++) rd->A->val[rd->recv_map[k]] += rd->recv_buf[k];
  }
  return MICA_SUCCESS;
}

void redistribution_destroy(Redistribution **redistribution) {
  Redistribution *rd = *redistribution;
  if (!rd) return;
  mica_sparse_destroy(&rd->A);
  free(rd->send_counts), free(rd->send_displs), free(rd->recv_counts), free(rd->recv_displs);
  free(rd->send_pos), free(rd->send_buf), free(rd->recv_map), free(rd->recv_buf);
  MICA_FREE(*redistribution);
}
