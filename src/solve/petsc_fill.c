/* The tangent into PETSc's AIJ matrix by position: the pattern once, the values by copying (petsc_private.h).
 *
 * Why: MatSetValues(ADD_VALUES) looks every entry up in its row, and entries of rows another rank owns go through
 * PETSc's stash (row, column and value per entry, sorted and looked up again at the owner). Measured on the 33³
 * speed-up cube (9.45·10⁷ entries, gmg): 4.1 s of a 5.6–6.8 s factor step serially (43 ns an entry), and at P = 2
 * 2.2 s a rank plus 1.4 s of stash in MatAssemblyBegin/End — more than the whole preconditioner setup.
 *
 * The slots. mica's tangent K is CSC with a symmetric pattern (its entries come from cliques of nodes), so column c
 * of K lists the columns of row c too: slot s of column c (s in colptr[c] .. colptr[c+1]) stands for the matrix
 * entry (row g[c], column g[rowind[s]]) in PETSc's numbering g = row_of_dof. Its value is val[s] when the values
 * are symmetric (symmetric != 0: the slot is the entry's mirror), and otherwise the value of the transposed CSC
 * entry, found by walking the columns in order with a cursor per column (next[]): entry (i, j) at q, met in
 * ascending j, is slot colptr[i] + next[i]++ of column i (rowind ascending within a column, pattern symmetric).
 *
 * The rows. The slots of a column c whose row this rank owns are that row's own entries; the slots of the other
 * columns (ghost nodes: rows other ranks own, which this rank's points contribute to) are sent to the row's owner,
 * which adds them. Each row of PETSc's matrix is the union of its own slots' columns and those received, sorted: a
 * row whose own slots are already in PETSc's order — its diagonal block (owned columns) first, ascending, then the
 * off-diagonal block ascending — and which receives nothing is copied (memcpy of the column's values: one process,
 * and the interior of a rank's part); the other rows keep a position per slot. PETSc's matrix is made on arrays of
 * ours holding these rows (MatCreateSeqAIJWithArrays, MatCreateMPIAIJWithSplitArrays: nothing inserted, nothing
 * searched; PETSc's MatXAIJSetPreallocationCSR still inserts row by row through MatSetValues, 4.1 s on the cube),
 * once per pattern; one process with symmetric values and K's columns in row order gives it K's own values array.
 * Several ranks with symmetric values and K lent (the caller reads neither K's values nor A between a fill and
 * K's next assembly): the diagonal block is K's values array too, each fill moving the values down into the
 * block's order in place (fill_in_place) — no second array of the tangent's size, and none of its first-touch
 * cost (0.95 s a rank of the 33³ cube's factor step at P = 2 on a virtual machine's fresh pages).
 *
 * Each tangent: the copies and positions into the diagonal and off-diagonal blocks' value arrays, the slots of
 * other ranks' rows into one buffer per neighbour (MPI_Isend/Irecv: one message each way per neighbour), the received
 * values added at their positions; no search, no stash. Memory beyond the matrix's arrays: a position (PetscInt) per
 * slot of a mapped row and per received value, the send and receive buffers, a send offset per column and a row
 * number per unknown. */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "petsc_private.h"

enum { FILL_TAG = 7311 };

struct MicaPetscFill {
  MPI_Comm comm;
  int size, symmetric;
  long n;                 /* columns of K (this rank's unknowns) */
  PetscInt nlocal;        /* PETSc rows this rank owns */
  PetscInt *row;          /* [n] the PETSc local row of each unknown, -1 when another rank owns it */
  long *dof_of_row;       /* [nlocal] the unknown of each owned row */
  /* PETSc's matrix is made on these arrays: its diagonal block (columns local to the rank) and off-diagonal block
   * (global columns, which PETSc renumbers in place), CSR */
  PetscInt *diag_start, *diag_col, *off_start, *off_col;
  double *diag_val, *off_val;
  const double *shared;   /* diag_val is K's val: one rank with symmetric values and K's columns in PETSc's row order,
                           * or in_place */
  int in_place;           /* K's values lent (several ranks, symmetric values): each fill rearranges them in place */
  double *row_values;     /* in_place: [row_cap] a mapped row's own values, saved before its place is written */
  long row_cap;
  long *mapped;           /* [nlocal] -1: the row is copied; else its first position in pos */
  PetscInt *pos;          /* positions of the slots of mapped rows: k in the diagonal block, -1 - k off it */
  long *send_start;       /* [n] an unknown owned elsewhere: its column's first value in send, else -1 */
  long *next;             /* [n] the transposed walk's cursors (unsymmetric values) */
  double *send, *recv;
  long nsend, nrecv;
  PetscInt *recv_pos;     /* [nrecv] */
  int nsend_ranks, nrecv_ranks;
  int *send_rank, *recv_rank;       /* the neighbours */
  long *send_offset, *recv_offset;  /* [neighbours + 1] their parts of send and recv */
  MPI_Request *requests;
};

void mica_petsc_fill_destroy(MicaPetscFill **fill) {
  MicaPetscFill *f = *fill;
  if (!f) return;
  free(f->row), free(f->dof_of_row), free(f->mapped), free(f->pos);
  if (f->shared) f->diag_val = NULL; /* K's */
  free(f->diag_start), free(f->diag_col), free(f->diag_val), free(f->off_start), free(f->off_col), free(f->off_val);
  free(f->send_start), free(f->next), free(f->send), free(f->recv), free(f->recv_pos), free(f->row_values);
  free(f->send_rank), free(f->recv_rank), free(f->send_offset), free(f->recv_offset), free(f->requests);
  free(f);
  *fill = NULL;
}

/* The owner of PETSc row g: range[owner] <= g < range[owner + 1]; *hint: the last answer (rows come in runs). */
static int owner_of(const PetscInt *range, int size, PetscInt g, int *hint) {
  if (g >= range[*hint] && g < range[*hint + 1]) return *hint;
  int lo = 0, hi = size;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (g < range[mid]) hi = mid;
    else lo = mid;
  }
  return *hint = lo;
}

/* Which rows are this rank's, and for the others' columns where their slots go: send_start, the neighbours, and
 * the slots' (row, column) pairs for the owners (*pairs, in send order). counts[r]: the slots for rank r. */
static int plan_send(MicaPetscFill *f, const MicaSparse *K, const PetscInt *g, const PetscInt *range, int rank,
                     PetscInt **pairs, int *counts) {
  const PetscInt rstart = range[rank], rend = range[rank + 1];
  int hint = rank;
  long *at = NULL; /* per rank: the next free place in send */
  MICA_CALL(MICA_CALLOC(at, f->size + 1));
  PetscInt owned = 0;
  for (PetscInt r = 0; r < f->nlocal; r++) f->dof_of_row[r] = -1;
  for (long c = 0; c < f->n && owned >= 0; c++) {
    const long len = K->colptr[c + 1] - K->colptr[c];
    f->row[c] = g[c] >= rstart && g[c] < rend ? g[c] - rstart : -1;
    f->send_start[c] = -1;
    if (f->row[c] >= 0 && f->dof_of_row[f->row[c]] < 0) f->dof_of_row[f->row[c]] = c, owned++;
    else if (f->row[c] >= 0) owned = -1; /* a row twice */
    else if (len) at[owner_of(range, f->size, g[c], &hint) + 1] += len;
  }
  int ierr = MICA_SUCCESS;
  if (owned != f->nlocal)
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                          "petsc: %ld unknowns in this rank's rows, %ld expected", (long)owned, (long)f->nlocal);
  for (int r = 0; r < f->size && !ierr; r++) {
    if (at[r + 1] > INT_MAX / 2) ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                                                       "petsc: %ld entries for rank %d (at most %d)", at[r + 1], r,
                                                       INT_MAX / 2);
    counts[r] = (int)at[r + 1];
    f->nsend_ranks += at[r + 1] > 0;
    at[r + 1] += at[r];
  }
  f->nsend = at[f->size];
  if (!ierr) ierr = MICA_MALLOC(f->send, f->nsend + 1);
  if (!ierr) ierr = MICA_MALLOC(*pairs, 2 * f->nsend + 1);
  if (!ierr) ierr = MICA_MALLOC(f->send_rank, f->nsend_ranks + 1);
  if (!ierr) ierr = MICA_MALLOC(f->send_offset, f->nsend_ranks + 1);
  for (int r = 0, k = 0; r < f->size && !ierr; r++)
    if (counts[r]) f->send_rank[k] = r, f->send_offset[k++] = at[r];
  if (!ierr) f->send_offset[f->nsend_ranks] = f->nsend;
  for (long c = 0; c < f->n && !ierr; c++) {
    const long first = K->colptr[c], len = K->colptr[c + 1] - first;
    if (f->row[c] >= 0 || !len) continue;
    const int owner = owner_of(range, f->size, g[c], &hint);
    const long start = at[owner];
    at[owner] += len;
    f->send_start[c] = start;
    for (long k = 0; k < len; k++) (*pairs)[2 * (start + k)] = g[c], (*pairs)[2 * (start + k) + 1] = g[K->rowind[first + k]];
  }
  free(at);
  return ierr;
}

/* The pairs of this rank's rows from the others (MPI_Alltoall of the counts: O(P) a rank, once per pattern). */
static int exchange_pairs(MicaPetscFill *f, const PetscInt *pairs, const int *send_counts, PetscInt **received) {
  int *sc = NULL, *sd = NULL, *rc = NULL, *rd = NULL; /* the pairs' counts and displacements, in PetscInts */
  int ierr = MICA_CALLOC(sc, f->size + 1);
  if (!ierr) ierr = MICA_CALLOC(sd, f->size + 1);
  if (!ierr) ierr = MICA_CALLOC(rc, f->size + 1);
  if (!ierr) ierr = MICA_CALLOC(rd, f->size + 1);
  if (!ierr) MPI_Alltoall(send_counts, 1, MPI_INT, rc, 1, MPI_INT, f->comm);
  long total = 0;
  for (int r = 0; r < f->size && !ierr; r++) {
    f->nrecv_ranks += rc[r] > 0;
    total += rc[r];
  }
  if (!ierr && (2 * total > INT_MAX || 2 * f->nsend > INT_MAX))
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                          "petsc: %ld entries to send and %ld to receive (at most %d)", f->nsend, total, INT_MAX / 2);
  f->nrecv = total;
  if (!ierr) ierr = MICA_MALLOC(*received, 2 * total + 1);
  if (!ierr) ierr = MICA_MALLOC(f->recv, total + 1);
  if (!ierr) ierr = MICA_MALLOC(f->recv_pos, total + 1);
  if (!ierr) ierr = MICA_MALLOC(f->recv_rank, f->nrecv_ranks + 1);
  if (!ierr) ierr = MICA_MALLOC(f->recv_offset, f->nrecv_ranks + 1);
  if (!ierr) ierr = MICA_MALLOC(f->requests, f->nsend_ranks + f->nrecv_ranks + 1);
  if (!ierr) {
    long s = 0, r = 0;
    for (int q = 0, k = 0; q < f->size; q++) {
      if (rc[q]) f->recv_rank[k] = q, f->recv_offset[k++] = r;
      sc[q] = 2 * send_counts[q], sd[q] = (int)(2 * s);
      rd[q] = (int)(2 * r);
      s += send_counts[q], r += rc[q];
      rc[q] *= 2;
    }
    f->recv_offset[f->nrecv_ranks] = f->nrecv;
    MPI_Alltoallv(pairs, sc, sd, MPIU_INT, *received, rc, rd, MPIU_INT, f->comm);
  }
  free(sc), free(sd), free(rc), free(rd);
  return ierr;
}

typedef struct {
  PetscInt col;
  long source; /* k >= 0: the row's own slot k; -1 - k: received value k */
} Item;

/* The end of the ascending run of items that begins at start. */
static long run_end(const Item *items, long start, long m) {
  long end = start + 1;
  while (end < m && items[end - 1].col <= items[end].col) end++;
  return end < m ? end : m;
}

/* items[0 .. m) in ascending column (ties in any order: they share an entry), by merging the ascending runs they
 * come in — the row's own slots and each neighbour's part, a few runs a row — pairwise through tmp[m]: a qsort of
 * them cost 0.5 s of the 33³ cube's P = 2 pattern on the rank with more rows by the interface. Returns the sorted
 * array (items or tmp). */
static Item *sort_items(Item *items, Item *tmp, long m) {
  for (;;) {
    long runs = 0;
    for (long start = 0; start < m; runs++) { /* merge the run at start with the next one (if any) into tmp */
      const long mid = run_end(items, start, m), end = mid < m ? run_end(items, mid, m) : m;
      long i = start, j = mid, k = start;
      while (i < mid && j < end) tmp[k++] = items[j].col < items[i].col ? items[j++] : items[i++];
      while (i < mid) tmp[k++] = items[i++];
      while (j < end) tmp[k++] = items[j++];
      start = end;
    }
    if (runs <= 1) return tmp; /* one merge step that found at most two runs: tmp is sorted */
    Item *swap = items;
    items = tmp, tmp = swap;
  }
}

/* Whether row r's own slots, as they are, are its AIJ row: no received entries, owned columns first, each block
 * ascending. */
static int copied(const MicaSparse *K, const PetscInt *g, long c, PetscInt rstart, PetscInt rend, long nreceived) {
  if (nreceived) return 0;
  int off = 0;
  PetscInt last = -1;
  for (long s = K->colptr[c]; s < K->colptr[c + 1]; s++) {
    const PetscInt col = g[K->rowind[s]];
    const int in = col >= rstart && col < rend;
    if (in && off) return 0;
    if (!in && !off) off = 1, last = -1;
    if (col <= last) return 0;
    last = col;
  }
  return 1;
}

/* Whether the diagonal block fits in K's values array, each row's place written only after its own slots were
 * read: the rows' columns ascending in memory and row r's place ending before row r + 1's slots begin (the rows
 * with entries from other ranks may be longer than their own slots; the interior rows are as long or shorter).
 * The slots of other ranks' rows (send) and of the off-diagonal block are copied out before any place is written.
 * Sets row_cap, the longest mapped row. */
static int in_place_fits(MicaPetscFill *f, const MicaSparse *K) {
  for (PetscInt r = 0; r < f->nlocal; r++) {
    const long c = f->dof_of_row[r], len = K->colptr[c + 1] - K->colptr[c];
    if (r > 0 && c <= f->dof_of_row[r - 1]) return 0;
    const long end = r + 1 < f->nlocal ? K->colptr[f->dof_of_row[r + 1]] : K->nnz;
    if (f->diag_start[r + 1] > end) return 0;
    if (f->mapped[r] >= 0 && len > f->row_cap) f->row_cap = len;
  }
  return 1;
}

/* The rows as PETSc's two blocks keep them (CSR: diagonal block with local columns diag_start, diag_col;
 * off-diagonal block with global columns off_start, off_col) and where each slot and received value goes.
 * received: the (row, column) pairs for this rank's rows. The column arrays are allocated for the most they could
 * hold (pages never written cost nothing) and cut to their length at the end. */
static int build_rows(MicaPetscFill *f, const MicaSparse *K, const PetscInt *g, PetscInt rstart, PetscInt rend,
                      const PetscInt *received, int lend) {
  long *rptr = NULL, *rlist = NULL, nmapped = 0, nown = 0;
  Item *items = NULL, *tmp = NULL;
  long item_cap = 0;
  int ierr = MICA_CALLOC(rptr, f->nlocal + 2);
  if (!ierr) ierr = MICA_MALLOC(rlist, f->nrecv + 1);
  for (long k = 0; k < f->nrecv && !ierr; k++) rptr[received[2 * k] - rstart + 2]++;
  for (PetscInt r = 0; r < f->nlocal && !ierr; r++) rptr[r + 2] += rptr[r + 1];
  for (long k = 0; k < f->nrecv && !ierr; k++) rlist[rptr[received[2 * k] - rstart + 1]++] = k;
  /* rptr[r] .. rptr[r + 1]: the received values of row r */
  for (PetscInt r = 0; r < f->nlocal && !ierr; r++) {
    const long c = f->dof_of_row[r], len = K->colptr[c + 1] - K->colptr[c];
    nown += len;
    f->mapped[r] = copied(K, g, c, rstart, rend, rptr[r + 1] - rptr[r]) ? -1 : nmapped;
    if (f->mapped[r] >= 0) nmapped += len;
  }
  const long most = nown + f->nrecv;
  if (!ierr && most > INT_MAX)
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                          "petsc: %ld entries in this rank's rows (at most %d)", most, INT_MAX);
  if (!ierr) ierr = MICA_MALLOC(f->pos, nmapped + 1);
  if (!ierr) ierr = MICA_MALLOC(f->diag_col, most + 1);
  if (!ierr) ierr = MICA_MALLOC(f->off_col, most + 1);
  if (ierr) goto cleanup;
  PetscInt nd = 0, no = 0; /* entries so far in each block */
  f->diag_start[0] = 0, f->off_start[0] = 0;
  for (PetscInt r = 0; r < f->nlocal; r++) {
    const long c = f->dof_of_row[r], first = K->colptr[c], len = K->colptr[c + 1] - first;
    if (f->mapped[r] < 0) {
      for (long k = 0; k < len; k++) {
        const PetscInt col = g[K->rowind[first + k]];
        if (col >= rstart && col < rend) f->diag_col[nd++] = col - rstart;
        else f->off_col[no++] = col;
      }
    } else {
      const long nrecv = rptr[r + 1] - rptr[r];
      if (len + nrecv > item_cap) {
        item_cap = 2 * (len + nrecv);
        MICA_CALL_CLEANUP(MICA_REALLOC(items, item_cap));
        MICA_CALL_CLEANUP(MICA_REALLOC(tmp, item_cap));
      }
      long m = 0;
      for (long k = 0; k < len; k++) items[m].col = g[K->rowind[first + k]], items[m++].source = k;
      for (long k = rptr[r]; k < rptr[r + 1]; k++) items[m].col = received[2 * rlist[k] + 1], items[m++].source = -1 - rlist[k];
      const Item *sorted = sort_items(items, tmp, m);
      for (long k = 0; k < m; k++) {
        const int fresh = !k || sorted[k].col != sorted[k - 1].col;
        const int in = sorted[k].col >= rstart && sorted[k].col < rend;
        if (fresh && in) f->diag_col[nd++] = sorted[k].col - rstart;
        else if (fresh) f->off_col[no++] = sorted[k].col;
        const PetscInt at = in ? nd - 1 : -1 - (no - 1);
        if (sorted[k].source >= 0) f->pos[f->mapped[r] + sorted[k].source] = at;
        else f->recv_pos[-1 - sorted[k].source] = at;
      }
    }
    f->diag_start[r + 1] = nd, f->off_start[r + 1] = no;
  }
  MICA_CALL_CLEANUP(MICA_REALLOC(f->diag_col, nd + 1));
  MICA_CALL_CLEANUP(MICA_REALLOC(f->off_col, no + 1));
  MICA_CALL_CLEANUP(MICA_CALLOC(f->off_val, no + 1));
  /* one rank with symmetric values and every row as its column: PETSc's values are K's, shared (no copy, and
   * none of the matrix's largest array twice; 0.76 GB of the 33³ cube's 3.4) */
  int share = f->size == 1 && f->symmetric;
  for (PetscInt r = 0; r < f->nlocal && share; r++) share = f->mapped[r] < 0 && f->dof_of_row[r] == r;
  if (share) f->shared = f->diag_val = K->val;
  else if (lend && f->symmetric && in_place_fits(f, K)) {
    f->shared = f->diag_val = K->val, f->in_place = 1;
    MICA_CALL_CLEANUP(MICA_MALLOC(f->row_values, f->row_cap + 1));
  } else MICA_CALL_CLEANUP(MICA_CALLOC(f->diag_val, nd + 1));
cleanup:
  free(rptr), free(rlist), free(items), free(tmp);
  return ierr;
}

/* The unsymmetric walk once: the pattern must be symmetric for the cursors to meet the transposed entries. */
static int check_symmetric_pattern(const MicaSparse *K, long *next) {
  memset(next, 0, (size_t)K->n * sizeof *next);
  for (long j = 0; j < K->n; j++)
    for (long q = K->colptr[j]; q < K->colptr[j + 1]; q++) {
      const long i = K->rowind[q], s = K->colptr[i] + next[i]++;
      MICA_CHECK(s < K->colptr[i + 1] && K->rowind[s] == j, MICA_ERR_ARGUMENT,
                 "petsc: the tangent's pattern is not symmetric (entry %ld, %ld)", i, j);
    }
  return MICA_SUCCESS;
}

/* The diagonal and off-diagonal blocks of A (one rank: A and none). */
static int blocks(Mat A, int size, Mat *Ad, Mat *Ao) {
  *Ao = NULL;
  if (size == 1) {
    *Ad = A;
    return MICA_SUCCESS;
  }
  PCALL(MatMPIAIJGetSeqAIJ(A, Ad, Ao, NULL));
  return MICA_SUCCESS;
}

/* PETSc's blocks hold the rows as built (it keeps the sorted rows' order; the counts tell a surprise). */
static int check_blocks(const MicaPetscFill *f, Mat A) {
  Mat B[2];
  MICA_CALL(blocks(A, f->size, &B[0], &B[1]));
  for (int b = 0; b < 2 && B[b]; b++) {
    const PetscInt *ia, *ja, *start = b ? f->off_start : f->diag_start;
    PetscInt m;
    PetscBool done;
    PCALL(MatGetRowIJ(B[b], 0, PETSC_FALSE, PETSC_FALSE, &m, &ia, &ja, &done));
    int same = done && m == f->nlocal;
    for (PetscInt r = 0; same && r <= m; r++) same = ia[r] == start[r];
    PCALL(MatRestoreRowIJ(B[b], 0, PETSC_FALSE, PETSC_FALSE, &m, &ia, &ja, &done));
    MICA_CHECK(same, MICA_ERR_ARGUMENT, "petsc: the %s block's rows are not those built",
               b ? "off-diagonal" : "diagonal");
  }
  return MICA_SUCCESS;
}

int mica_petsc_fill_create(MPI_Comm comm, const MicaSparse *K, const PetscInt *row_of_dof, PetscInt nlocal,
                           PetscInt N, int bs, int symmetric, int lend, Mat *A, MicaPetscFill **out) {
  *out = NULL;
  MicaPetscFill *f = NULL;
  MICA_CALL(MICA_CALLOC(f, 1));
  int rank, ierr = MICA_SUCCESS;
  f->comm = comm, f->n = K->n, f->nlocal = nlocal, f->symmetric = symmetric;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &f->size);
  PetscInt *range = NULL, *pairs = NULL, *received = NULL;
  int *counts = NULL;
  MICA_CALL_CLEANUP(MICA_MALLOC(range, f->size + 1));
  range[0] = 0;
  MPI_Allgather(&nlocal, 1, MPIU_INT, range + 1, 1, MPIU_INT, comm);
  for (int r = 0; r < f->size; r++) range[r + 1] += range[r];
  if (range[f->size] != N)
    MICA_CALL_CLEANUP(mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                                     "petsc: the ranks own %ld rows of %ld", (long)range[f->size], (long)N));
  MICA_CALL_CLEANUP(MICA_MALLOC(f->row, f->n + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(f->dof_of_row, nlocal + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(f->send_start, f->n + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(f->diag_start, nlocal + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(f->off_start, nlocal + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(f->mapped, nlocal + 1));
  MICA_CALL_CLEANUP(MICA_CALLOC(counts, f->size + 1));
  if (!symmetric) {
    MICA_CALL_CLEANUP(MICA_MALLOC(f->next, f->n + 1));
    MICA_CALL_CLEANUP(check_symmetric_pattern(K, f->next));
  }
  MICA_CALL_CLEANUP(plan_send(f, K, row_of_dof, range, rank, &pairs, counts));
  MICA_CALL_CLEANUP(exchange_pairs(f, pairs, counts, &received));
  MICA_CALL_CLEANUP(build_rows(f, K, row_of_dof, range[rank], range[rank + 1], received, lend));
  free(pairs), free(received);
  pairs = received = NULL;
  /* PETSc's matrix on these arrays (not copied: they are freed after it) */
  PetscErrorCode code = f->size == 1 ? MatCreateSeqAIJWithArrays(comm, nlocal, nlocal, f->diag_start, f->diag_col,
                                                                 f->diag_val, A)
                                     : MatCreateMPIAIJWithSplitArrays(comm, nlocal, nlocal, N, N, f->diag_start,
                                                                      f->diag_col, f->diag_val, f->off_start,
                                                                      f->off_col, f->off_val, A);
  if (!code) code = MatSetBlockSize(*A, bs);
  if (code) MICA_CALL_CLEANUP(mica_petsc_error(code, "MatCreate...WithArrays", __FILE__, __LINE__));
  MICA_CALL_CLEANUP(check_blocks(f, *A));
  *out = f;
  f = NULL;
cleanup:
  free(range), free(pairs), free(received), free(counts);
  mica_petsc_fill_destroy(&f);
  return ierr;
}

/* Value v of row r's own slot k (its column's k-th entry). */
static inline void put(const MicaPetscFill *f, PetscInt r, long k, double v, double *ad, double *ao) {
  if (f->mapped[r] >= 0) {
    const PetscInt p = f->pos[f->mapped[r] + k];
    if (p >= 0) ad[p] += v;
    else ao[-1 - p] += v;
    return;
  }
  const PetscInt nd = f->diag_start[r + 1] - f->diag_start[r];
  if (k < nd) ad[f->diag_start[r] + k] = v;
  else ao[f->off_start[r] + k - nd] = v;
}

/* Symmetric values: each column's values are its row's, copied whole. */
static void fill_symmetric(MicaPetscFill *f, const MicaSparse *K, double *ad, double *ao) {
  for (PetscInt r = 0; r < f->nlocal; r++) {
    const long c = f->dof_of_row[r], first = K->colptr[c], len = K->colptr[c + 1] - first;
    if (f->mapped[r] >= 0) {
      for (long k = 0; k < len; k++) put(f, r, k, K->val[first + k], ad, ao);
      continue;
    }
    const PetscInt nd = f->diag_start[r + 1] - f->diag_start[r];
    memcpy(ad + f->diag_start[r], K->val + first, (size_t)nd * sizeof *ad);
    if (len > nd) memcpy(ao + f->off_start[r], K->val + first + nd, (size_t)(len - nd) * sizeof *ao);
  }
  for (long c = 0; c < f->n; c++)
    if (f->send_start[c] >= 0)
      memcpy(f->send + f->send_start[c], K->val + K->colptr[c],
             (size_t)(K->colptr[c + 1] - K->colptr[c]) * sizeof *f->send);
}

/* Symmetric values lent (in_place_fits): the slots of other ranks' rows and the off-diagonal entries copied out,
 * then, row after row, the diagonal block's entries moved down into place in K's values array (ad is K->val); a
 * mapped row's own values saved first, its place zeroed and its slots added by position. */
static void fill_in_place(MicaPetscFill *f, const MicaSparse *K, double *ad, double *ao) {
  for (long c = 0; c < f->n; c++)
    if (f->send_start[c] >= 0)
      memcpy(f->send + f->send_start[c], K->val + K->colptr[c],
             (size_t)(K->colptr[c + 1] - K->colptr[c]) * sizeof *f->send);
  for (PetscInt r = 0; r < f->nlocal; r++) {
    const long c = f->dof_of_row[r], first = K->colptr[c], len = K->colptr[c + 1] - first;
    const PetscInt d0 = f->diag_start[r], nd = f->diag_start[r + 1] - d0;
    if (f->mapped[r] >= 0) {
      memcpy(f->row_values, K->val + first, (size_t)len * sizeof *ad);
      memset(ad + d0, 0, (size_t)nd * sizeof *ad);
      memset(ao + f->off_start[r], 0, (size_t)(f->off_start[r + 1] - f->off_start[r]) * sizeof *ao);
      for (long k = 0; k < len; k++) put(f, r, k, f->row_values[k], ad, ao);
      continue;
    }
    if (len > nd) memcpy(ao + f->off_start[r], K->val + first + nd, (size_t)(len - nd) * sizeof *ao);
    if (ad + d0 != K->val + first) memmove(ad + d0, K->val + first, (size_t)nd * sizeof *ad);
  }
}

/* Unsymmetric values: entry (i, j) is slot next[i]++ of column i (the transposed walk). */
static void fill_general(MicaPetscFill *f, const MicaSparse *K, double *ad, double *ao) {
  memset(f->next, 0, (size_t)f->n * sizeof *f->next);
  for (long j = 0; j < f->n; j++)
    for (long q = K->colptr[j]; q < K->colptr[j + 1]; q++) {
      const long i = K->rowind[q], k = f->next[i]++;
      if (f->row[i] >= 0) put(f, f->row[i], k, K->val[q], ad, ao);
      else f->send[f->send_start[i] + k] = K->val[q];
    }
}

int mica_petsc_fill_takes(const MicaPetscFill *f, const MicaSparse *K) {
  return f && K->n == f->n && (!f->shared || f->shared == K->val);
}

int mica_petsc_fill_shares(const MicaPetscFill *f) { return f && f->shared; }

int mica_petsc_fill_values(MicaPetscFill *f, const MicaSparse *K, Mat A) {
  MICA_CHECK(mica_petsc_fill_takes(f, K), MICA_ERR_ARGUMENT, "petsc: a tangent of %ld unknowns (values at %p) for "
             "a pattern of %ld (values at %p)", K->n, (const void *)K->val, f->n, (const void *)f->shared);
  Mat Ad, Ao;
  MICA_CALL(blocks(A, f->size, &Ad, &Ao));
  PetscScalar *ad = NULL, *ao = NULL;
  PCALL(MatSeqAIJGetArray(Ad, &ad));
  if (Ao) PCALL(MatSeqAIJGetArray(Ao, &ao));
  /* the receives first, so that the sends find them posted */
  int nreq = 0;
  for (int k = 0; k < f->nrecv_ranks; k++)
    MPI_Irecv(f->recv + f->recv_offset[k], (int)(f->recv_offset[k + 1] - f->recv_offset[k]), MPI_DOUBLE,
              f->recv_rank[k], FILL_TAG, f->comm, &f->requests[nreq++]);
  /* mapped rows add (several slots or received values may share an entry): zeroed first (in place: row by row) */
  for (PetscInt r = 0; r < f->nlocal && !f->in_place; r++)
    if (f->mapped[r] >= 0) {
      memset(ad + f->diag_start[r], 0, (size_t)(f->diag_start[r + 1] - f->diag_start[r]) * sizeof *ad);
      if (ao) memset(ao + f->off_start[r], 0, (size_t)(f->off_start[r + 1] - f->off_start[r]) * sizeof *ao);
    }
  if (!f->symmetric) fill_general(f, K, ad, ao);
  else if (f->in_place) fill_in_place(f, K, ad, ao);
  else if (!f->shared) fill_symmetric(f, K, ad, ao); /* shared: A's values are K's already */
  for (int k = 0; k < f->nsend_ranks; k++)
    MPI_Isend(f->send + f->send_offset[k], (int)(f->send_offset[k + 1] - f->send_offset[k]), MPI_DOUBLE,
              f->send_rank[k], FILL_TAG, f->comm, &f->requests[nreq++]);
  MPI_Waitall(nreq, f->requests, MPI_STATUSES_IGNORE);
  for (long k = 0; k < f->nrecv; k++) {
    const PetscInt p = f->recv_pos[k];
    if (p >= 0) ad[p] += f->recv[k];
    else ao[-1 - p] += f->recv[k];
  }
  PCALL(MatSeqAIJRestoreArray(Ad, &ad));
  if (Ao) PCALL(MatSeqAIJRestoreArray(Ao, &ao));
  /* the matrix's state moves on (its preconditioner sees new values); no entries in the stash to move */
  PCALL(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
  PCALL(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  return MICA_SUCCESS;
}
