/* CHOLMOD supernodal Cholesky (cholmod_l_*, 64-bit indices) for symmetric positive definite matrices.
 *
 * The MicaSparse arrays are lent to CHOLMOD as a packed, sorted cholmod_sparse with stype = 1 (only the
 * upper triangle is read), so nothing is copied. The symbolic factor (fill-reducing ordering, supernodes)
 * comes from the first factorization and is reused while the pattern is unchanged (linear_private.h):
 * Newton iterations and load steps pay only for cholmod_l_factorize. The ordering is chosen on the graph of the
 * nodes (node_ordering: natural, AMD or METIS, the fewest flops), not by CHOLMOD's default on the unknowns.
 * CHOLMOD prints nothing (print = 0); its status is turned into mica errors here.
 */
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

#include "linear_private.h"
#include "mica/sort.h"
#include "mica/timer.h"

typedef struct {
  cholmod_common common;
  cholmod_factor *L;      /* symbolic, then numeric factor; NULL before the first analysis */
  MicaPatternKey pattern; /* of the matrix L was analyzed for */
  double analysis_flops;  /* Common->fl of that analysis: the flops of one factorization */
  int factored;           /* L holds a complete factorization that solve may use */
  const char *ordering;   /* the fill-reducing ordering of that analysis: node_orderings' names, or "cholmod" */
} CholmodData;

/* The caller's matrix as a cholmod_sparse that borrows its arrays (CHOLMOD only reads them). */
static cholmod_sparse borrow_matrix(const MicaSparse *A) {
  cholmod_sparse view;
  memset(&view, 0, sizeof view);
  view.nrow = (size_t)A->n;
  view.ncol = (size_t)A->n;
  view.nzmax = (size_t)A->nnz;
  view.p = A->colptr;
  view.i = A->rowind;
  view.x = A->val;
  view.stype = 1;
  view.itype = CHOLMOD_LONG;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  return view;
}

/* A negative Common->status is a failure of CHOLMOD itself (memory, size limits, bad input). */
static int library_error(const cholmod_common *common, const char *what) {
  if (common->status == CHOLMOD_OUT_OF_MEMORY) MICA_ERROR(MICA_ERR_MEMORY, "CHOLMOD %s: out of memory", what);
  MICA_ERROR(MICA_ERR_LIBRARY, "CHOLMOD %s failed (status %d)", what, common->status);
}

/* Entries of L as stored: per supernode a trapezoid of nscol columns and nsrow rows. */
static long factor_entries(const cholmod_factor *L) {
  if (!L->is_super) {
    long count = 0;
    const long *column_counts = L->nz;
    for (size_t j = 0; j < L->n; j++) count += column_counts[j];
    return count;
  }
  const long *super = L->super, *pi = L->pi;
  long count = 0;
  for (size_t s = 0; s < L->nsuper; s++) {
    long nscol = super[s + 1] - super[s], nsrow = pi[s + 1] - pi[s];
    count += nscol * nsrow - nscol * (nscol - 1) / 2;
  }
  return count;
}

/* The column of A (not of the permuted matrix CHOLMOD factors) where the factorization broke down. */
static long failed_column(const cholmod_factor *L) {
  const long *perm = L->Perm;
  if (L->minor >= L->n) return -1;
  return perm ? perm[L->minor] : (long)L->minor;
}

static int cholmod_create(MicaLinearSolver *solver) {
  CholmodData *data = NULL;
  MICA_CALL(MICA_CALLOC(data, 1));
  if (!cholmod_l_start(&data->common)) {
    free(data);
    MICA_ERROR(MICA_ERR_LIBRARY, "CHOLMOD: cholmod_l_start failed");
  }
  data->common.supernodal = CHOLMOD_SUPERNODAL;
  data->common.print = 0;
  solver->data = data;
  return MICA_SUCCESS;
}

/* The upper triangle of the graph of A's nodes (ndof unknowns each, node-major): node I is a row of node
 * column J when any entry of the block (I, J) is stored, I ≤ J. Rows ascending; pattern only. */
static int node_graph(const MicaSparse *A, cholmod_common *common, cholmod_sparse **graph_out) {
  const int ndof = A->ndof;
  const long nodes = A->n / ndof;
  long *last = NULL; /* last[I]: the node column that has already listed node I */
  long count = 0;
  MICA_CALL(MICA_MALLOC(last, nodes));
  for (int pass = 0; pass < 2; pass++) { /* count, then fill */
    cholmod_sparse *graph = *graph_out;
    long *colptr = graph ? graph->p : NULL, *rowind = graph ? graph->i : NULL;
    for (long I = 0; I < nodes; I++) last[I] = -1;
    count = 0;
    for (long J = 0; J < nodes; J++) {
      if (colptr) colptr[J] = count;
      for (long j = J * ndof; j < (J + 1) * ndof; j++)
        for (long e = A->colptr[j]; e < A->colptr[j + 1]; e++) {
          const long I = A->rowind[e] / ndof;
          if (I > J || last[I] == J) continue;
          last[I] = J;
          if (rowind) rowind[count] = I;
          count++;
        }
      if (rowind) qsort(rowind + colptr[J], (size_t)(count - colptr[J]), sizeof *rowind, mica_compare_long);
    }
    if (colptr) colptr[nodes] = count;
    if (pass == 0) {
      *graph_out = cholmod_l_allocate_sparse((size_t)nodes, (size_t)nodes, (size_t)count, 1, 1, 1, CHOLMOD_PATTERN,
                                             common);
      if (!*graph_out) {
        free(last);
        return library_error(common, "node graph");
      }
    }
  }
  free(last);
  return MICA_SUCCESS;
}

/* The orderings tried on the node graph, and their names in the log. A box of particles numbered along its
 * axes with supports several spacings wide gives a banded matrix whose natural order AMD does not beat (13³
 * particles, quadratic ball supports: 2.4x the flops); nested dissection wins on large bodies. */
static const struct {
  int ordering;
  const char *name;
} node_orderings[] = {{CHOLMOD_NATURAL, "natural"}, {CHOLMOD_AMD, "amd"}, {CHOLMOD_METIS, "metis"}};

/* The fill-reducing ordering of A's unknowns: each of node_orderings on the graph of the nodes (ndof² times
 * fewer entries than A), the one whose symbolic factor needs the fewest flops (its index in *best), each node's
 * unknowns kept together in their order. perm: [A->n]. */
static int node_ordering(CholmodData *data, const MicaSparse *A, long *perm, size_t *best) {
  cholmod_common *common = &data->common;
  cholmod_sparse *graph = NULL;
  MICA_CALL(node_graph(A, common, &graph));
  const long nodes = (long)graph->nrow;
  double best_flops = -1.0;
  int ierr = MICA_SUCCESS;
  double best_lnz = 0.0;
  const double graph_entries = (double)((const long *)graph->p)[nodes];
  for (size_t m = 0; m < sizeof node_orderings / sizeof node_orderings[0] && !ierr; m++) {
    /* METIS only where the best so far fills much, CHOLMOD's own rule for trying it (its cost on the node graph
     * of the 13³ cube is twice the other two together, its flops there 1.4x natural's) */
    if (node_orderings[m].ordering == CHOLMOD_METIS &&
        (best_lnz < 5.0 * graph_entries || best_flops < 500.0 * best_lnz))
      continue;
    common->nmethods = 1;
    common->method[0].ordering = node_orderings[m].ordering;
    common->postorder = 1;
    cholmod_factor *symbolic = cholmod_l_analyze(graph, common);
    if (!symbolic && common->status == CHOLMOD_NOT_INSTALLED) continue; /* a CHOLMOD built without METIS */
    if (!symbolic) {
      ierr = library_error(common, "node ordering");
      break;
    }
    if (best_flops < 0.0 || common->fl < best_flops) {
      const long *node_perm = symbolic->Perm;
      best_flops = common->fl;
      best_lnz = common->lnz;
      *best = m;
      data->ordering = node_orderings[m].name;
      for (long k = 0; k < nodes; k++)
        for (int c = 0; c < A->ndof; c++) perm[k * A->ndof + c] = node_perm[k] * A->ndof + c;
    }
    cholmod_l_free_factor(&symbolic, common);
  }
  cholmod_l_free_sparse(&graph, common);
  return ierr;
}

/* Fill-reducing ordering and symbolic factor for A's pattern, replacing any earlier one: the ordering from the
 * node graph when the unknowns come in whole nodes, else CHOLMOD's default choice (AMD, METIS when AMD fills). */
static int analyze(MicaLinearSolver *solver, const MicaSparse *A, cholmod_sparse *view, MicaPatternKey key) {
  CholmodData *data = solver->data;
  double start = mica_wtime();
  cholmod_l_free_factor(&data->L, &data->common);
  long *perm = NULL;
  if (A->ndof >= 1 && A->n % A->ndof == 0) {
    size_t best = 0;
    MICA_CALL(MICA_MALLOC(perm, A->n));
    int ierr = node_ordering(data, A, perm, &best);
    if (ierr) {
      free(perm);
      return ierr;
    }
    /* natural: without a given permutation CHOLMOD's analysis reads A in place (a given one costs two
     * permuted transposes of A, a third of the analysis on a 6591-unknown cube) */
    const int natural = node_orderings[best].ordering == CHOLMOD_NATURAL;
    data->common.nmethods = 1;
    data->common.method[0].ordering = natural ? CHOLMOD_NATURAL : CHOLMOD_GIVEN;
    data->common.postorder = 1;
    data->L = cholmod_l_analyze_p(view, natural ? NULL : perm, NULL, 0, &data->common);
    free(perm);
  } else {
    data->common.nmethods = 0;
    data->ordering = "cholmod";
    data->L = cholmod_l_analyze(view, &data->common);
  }
  solver->stats.time_analyze += mica_wtime() - start;
  if (!data->L) return library_error(&data->common, "analysis");
  data->pattern = key;
  data->analysis_flops = data->common.fl;
  solver->stats.analyses++;
  return MICA_SUCCESS;
}

static int cholmod_factor_matrix(MicaLinearSolver *solver, const MicaSparse *A) {
  CholmodData *data = solver->data;
  cholmod_sparse view = borrow_matrix(A);
  MicaPatternKey key = mica_pattern_key(A);
  data->factored = 0;
  if (!data->L || !mica_pattern_key_equal(key, data->pattern)) MICA_CALL(analyze(solver, A, &view, key));
  int ok = cholmod_l_factorize(&view, data->L, &data->common);
  if (data->common.status == CHOLMOD_NOT_POSDEF || (ok && data->L->minor < data->L->n))
    MICA_ERROR(MICA_ERR_NUMERIC,
               "matrix is not positive definite (CHOLMOD: column %ld); use solver.linear = umfpack or check the "
               "constraints",
               failed_column(data->L));
  if (!ok || data->common.status < CHOLMOD_OK) return library_error(&data->common, "factorization");
  data->factored = 1;
  solver->stats.nnz_factor = factor_entries(data->L);
  solver->stats.ordering = data->ordering;
  solver->stats.flops = data->analysis_flops;
  return MICA_SUCCESS;
}

static int cholmod_solve_system(MicaLinearSolver *solver, const double *b, double *x) {
  CholmodData *data = solver->data;
  MICA_CHECK(data->factored, MICA_ERR_ARGUMENT, "CHOLMOD solve: no successful factorization to solve with");
  size_t n = data->L->n;
  cholmod_dense rhs;
  memset(&rhs, 0, sizeof rhs);
  rhs.nrow = n;
  rhs.ncol = 1;
  rhs.nzmax = n;
  rhs.d = n;
  rhs.x = (double *)b; /* read only */
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  cholmod_dense *solution = cholmod_l_solve(CHOLMOD_A, data->L, &rhs, &data->common);
  if (!solution) return library_error(&data->common, "solve");
  memcpy(x, solution->x, n * sizeof *x);
  cholmod_l_free_dense(&solution, &data->common);
  return MICA_SUCCESS;
}

static void cholmod_destroy(MicaLinearSolver *solver) {
  CholmodData *data = solver->data;
  if (!data) return;
  cholmod_l_free_factor(&data->L, &data->common);
  cholmod_l_finish(&data->common);
  free(data);
  solver->data = NULL;
}

const MicaLinearSolverOps mica_linear_cholmod = {
    {"cholmod", "CHOLMOD supernodal Cholesky (symmetric positive definite)", MICA_LINEAR_SPD_ONLY, NULL, NULL},
    cholmod_create, cholmod_factor_matrix,
                                                 cholmod_solve_system, cholmod_destroy};
