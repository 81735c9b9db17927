/* The particle graph, its METIS partition, owners of points and ghosts (parallel.h).
 *
 * The graph is the scalar sparsity pattern of the cliques (mica_sparse_create with one unknown per node)
 * without its diagonal: particles are adjacent when they support a common point. METIS_PartGraphKway
 * (32-bit idx_t here) cuts it into parts of balanced vertex weight: the weight of a particle is 1 + the
 * number of points nearest to it, so a part's weight is about the quadrature work of the rank that owns it. */
#include <math.h>
#include <metis.h>
#include <stdlib.h>
#include <string.h>

#include "mica/parallel.h"

int mica_point_supports(const MlsApprox *mls, long npoints, const double *x, long **ptr_out, long **index_out,
                        long *nearest) {
  const MlsSearch *search = mls_search(mls);
  const int dim = mls_dim(mls), ball = mls_support_kind(mls) == MLS_SUPPORT_BALL;
  const double *xp = mls_particles(mls), *radii = mls_radii(mls);
  long *ptr = NULL, *index = NULL, *found = NULL, count = 0, cap = 0, total = 0, index_cap = 0;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(ptr, npoints + 1));
  ptr[0] = 0;
  for (long p = 0; p < npoints; p++) {
    const double *xq = x + p * dim;
    MICA_CALL_CLEANUP(mls_search_query(search, xq, &found, &count, &cap));
    if (total + count > index_cap) {
      index_cap = 2 * (total + count) + 1024;
      MICA_CALL_CLEANUP(MICA_REALLOC(index, index_cap));
    }
    double best = INFINITY;
    long best_particle = -1;
    for (long k = 0; k < count; k++) {
      const long i = found[k];
      index[total + k] = i;
      double r = 0;
      if (ball) {
        for (int d = 0; d < dim; d++) r += (xq[d] - xp[i * dim + d]) * (xq[d] - xp[i * dim + d]);
        r = sqrt(r) / radii[i * dim];
      } else {
        for (int d = 0; d < dim; d++) r = fmax(r, fabs(xq[d] - xp[i * dim + d]) / radii[i * dim + d]);
      }
      if (r < best) best = r, best_particle = i; /* ties: the lowest number (found is ascending) */
    }
    if (nearest) nearest[p] = best_particle;
    total += count;
    ptr[p + 1] = total;
  }
  if (!index) MICA_CALL_CLEANUP(MICA_MALLOC(index, 1));
  *ptr_out = ptr;
  *index_out = index;
  ptr = index = NULL;
cleanup:
  free(found);
  free(ptr);
  free(index);
  return ierr;
}

/* The graph without self loops, from the scalar pattern of the cliques. */
static int build_graph(MicaPartition *p, long ncliques, const long *ptr, const long *nodes) {
  MicaSparse *pattern = NULL;
  MICA_CALL(mica_sparse_create(p->n, 1, ncliques, ptr, nodes, &pattern));
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(p->xadj, p->n + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(p->adjncy, pattern->nnz > p->n ? pattern->nnz - p->n : 1));
  long count = 0;
  for (long i = 0; i < p->n; i++) {
    p->xadj[i] = count;
    for (long q = pattern->colptr[i]; q < pattern->colptr[i + 1]; q++)
      if (pattern->rowind[q] != i) p->adjncy[count++] = pattern->rowind[q];
  }
  p->xadj[p->n] = count;
cleanup:
  mica_sparse_destroy(&pattern);
  return ierr;
}

static int metis_error(int status) {
  MICA_ERROR(status == METIS_ERROR_MEMORY ? MICA_ERR_MEMORY : MICA_ERR_LIBRARY, "METIS_PartGraphKway failed (%s)",
             status == METIS_ERROR_INPUT ? "METIS_ERROR_INPUT" : status == METIS_ERROR_MEMORY ? "METIS_ERROR_MEMORY"
                                                                                               : "METIS_ERROR");
}

static int run_metis(MicaPartition *p, const long *weights) {
  const long nnz = p->xadj[p->n];
  MICA_CHECK(p->n < IDX_MAX && nnz < IDX_MAX, MICA_ERR_ARGUMENT,
             "the particle graph (%ld particles, %ld edges) is too large for METIS's %d-bit indices", p->n, nnz,
             IDXTYPEWIDTH);
  idx_t *xadj = NULL, *adjncy = NULL, *vwgt = NULL, *part = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(xadj, p->n + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(adjncy, nnz + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(vwgt, p->n + 1));
  MICA_CALL_CLEANUP(MICA_MALLOC(part, p->n + 1));
  for (long i = 0; i <= p->n; i++) xadj[i] = (idx_t)p->xadj[i];
  for (long k = 0; k < nnz; k++) adjncy[k] = (idx_t)p->adjncy[k];
  for (long i = 0; i < p->n; i++) vwgt[i] = (idx_t)(weights ? weights[i] : 1);
  idx_t nvtxs = (idx_t)p->n, ncon = 1, nparts = p->nparts, objval = 0, options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  options[METIS_OPTION_SEED] = 1; /* the same partition every run */
  const int status = METIS_PartGraphKway(&nvtxs, &ncon, xadj, adjncy, vwgt, NULL, NULL, &nparts, NULL, NULL, options,
                                         &objval, part);
  if (status != METIS_OK) {
    ierr = metis_error(status);
    goto cleanup;
  }
  for (long i = 0; i < p->n; i++) p->part[i] = (int)part[i];
cleanup:
  free(xadj);
  free(adjncy);
  free(vwgt);
  free(part);
  return ierr;
}

/* Edge cut (each undirected edge once), sizes, and the weight imbalance max / mean. */
static void measure(MicaPartition *p, const long *weights) {
  p->edge_cut = 0;
  for (long i = 0; i < p->n; i++)
    for (long q = p->xadj[i]; q < p->xadj[i + 1]; q++)
      if (p->adjncy[q] > i && p->part[p->adjncy[q]] != p->part[i]) p->edge_cut++;
  double total = 0, largest = 0;
  double *load = calloc((size_t)p->nparts, sizeof *load);
  for (long i = 0; i < p->n; i++) {
    const double w = weights ? (double)weights[i] : 1.0;
    p->part_size[p->part[i]]++;
    total += w;
    if (load) load[p->part[i]] += w;
  }
  for (int r = 0; load && r < p->nparts; r++) largest = fmax(largest, load[r]);
  p->imbalance = load && total > 0 ? largest / (total / p->nparts) : 1.0;
  free(load);
}

int mica_partition_create(long n, long ncliques, const long *ptr, const long *nodes, const long *weights, int nparts,
                          MicaPartition **out) {
  *out = NULL;
  MICA_CHECK(n >= 1 && nparts >= 1, MICA_ERR_ARGUMENT, "mica_partition_create: %ld particles, %d parts", n, nparts);
  MICA_CHECK(nparts <= n, MICA_ERR_INPUT, "%d ranks for %ld particles: use fewer ranks than particles", nparts, n);
  MicaPartition *p = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(p, 1));
  p->n = n;
  p->nparts = nparts;
  MICA_CALL_CLEANUP(MICA_CALLOC(p->part, n));
  MICA_CALL_CLEANUP(MICA_CALLOC(p->part_size, nparts));
  MICA_CALL_CLEANUP(build_graph(p, ncliques, ptr, nodes));
  if (nparts > 1) MICA_CALL_CLEANUP(run_metis(p, weights));
  measure(p, weights);
  for (int r = 0; r < nparts; r++)
    if (p->part_size[r] == 0) {
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                            "METIS left part %d of %d empty (%ld particles): use fewer ranks", r, nparts, n);
      goto cleanup;
    }
  *out = p;
  return MICA_SUCCESS;
cleanup:
  mica_partition_destroy(&p);
  return ierr;
}

int mica_partition_destroy(MicaPartition **partition) {
  MicaPartition *p = *partition;
  if (!p) return MICA_SUCCESS;
  MICA_FREE(p->xadj);
  MICA_FREE(p->adjncy);
  MICA_FREE(p->part);
  MICA_FREE(p->part_size);
  MICA_FREE(*partition);
  return MICA_SUCCESS;
}

int mica_partition_ghosts(const MicaPartition *p, int rank, long npoints, const long *ptr, const long *index,
                          const int *owner, long *nghost, long **ghosts) {
  char *mark = NULL;
  long *list = NULL, count = 0;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(mark, p->n));
  for (long q = 0; q < npoints; q++) {
    if (owner[q] != rank) continue;
    for (long e = ptr[q]; e < ptr[q + 1]; e++)
      if (p->part[index[e]] != rank && !mark[index[e]]) mark[index[e]] = 1, count++;
  }
  MICA_CALL_CLEANUP(MICA_MALLOC(list, count));
  count = 0;
  for (long i = 0; i < p->n; i++)
    if (mark[i]) list[count++] = i;
  *nghost = count;
  *ghosts = list;
  list = NULL;
cleanup:
  free(mark);
  free(list);
  return ierr;
}
