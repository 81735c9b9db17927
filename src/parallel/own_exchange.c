/* parallel.data = "distributed": what the ranks exchange once the distribution is built (parallel.h) — the ghost
 * plan (each ghost asked of its owner by its position there; the owners' values copied into the ghosts, the
 * ghosts' contributions added at the owners, in rank order), the extra nodes of Lagrange multipliers (owned by the
 * lowest rank holding one, decided at its home rank) with their numbering, the owned norms, and the rank that
 * evaluates a field at a point. The distributions themselves are built in own.c (grids) and own_mesh.c (Gmsh). */
#include <math.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "mica/parallel.h"
#include "mica/sort.h"
#include "parallel_private.h"

/* ---- the ghost plan --------------------------------------------------------------------------------------- */

/* The plan from each ghost's owner and its place there (code ≥ 0: the position of an owned particle in the
 * owner's block; < 0: the owner's extra node −code − 1): the owners learn what to send. ghost[nreq] are the local
 * nodes, grouped by owner in recv_index (ascending owner, then the given order). */
static int ghost_plan_build(MicaDistribution *dist, MicaGhostPlan *g, long nreq, const long *ghost, const int *owner,
                            const long *code) {
  const int P = mica_parallel_size(), rank = mica_parallel_rank();
  const long nlocal = dist->nowned + dist->nghost;
  long *request = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_CALLOC(g->send_counts, P + 1));
  MICA_CALL(MICA_CALLOC(g->send_displs, P + 1));
  MICA_CALL(MICA_CALLOC(g->recv_counts, P + 1));
  MICA_CALL(MICA_CALLOC(g->recv_displs, P + 1));
  MICA_CALL(MICA_CALLOC(g->scaled, 4L * P + 4));
  MICA_CALL(MICA_MALLOC(g->recv_index, nreq + 1));
  MICA_CALL(MICA_MALLOC(request, nreq + 1));
  for (long i = 0; i < nreq; i++) g->recv_counts[owner[i]]++;
  for (int r = 0; r < P; r++) g->recv_displs[r + 1] = g->recv_displs[r] + g->recv_counts[r];
  int *cursor = g->scaled; /* scratch, before its use per exchange */
  for (int r = 0; r < P; r++) cursor[r] = g->recv_displs[r];
  for (long i = 0; i < nreq; i++) {
    const int k = cursor[owner[i]]++;
    g->recv_index[k] = ghost[i];
    request[k] = code[i];
  }
  MPI_Alltoall(g->recv_counts, 1, MPI_INT, g->send_counts, 1, MPI_INT, mica_parallel_comm());
  for (int r = 0; r < P; r++) g->send_displs[r + 1] = g->send_displs[r] + g->send_counts[r];
  ierr = MICA_MALLOC(g->send_index, (long)g->send_displs[P] + 1);
  if (!ierr) {
    MPI_Alltoallv(request, g->recv_counts, g->recv_displs, MPI_LONG, g->send_index, g->send_counts, g->send_displs,
                  MPI_LONG, mica_parallel_comm());
    for (int k = 0; k < g->send_displs[P]; k++) {
      const long c = g->send_index[k], e = -c - 1;
      if (c >= 0 && c < dist->nowned) continue;
      if (c < 0 && e < dist->nextra && dist->extra_owner[e] == rank) {
        g->send_index[k] = nlocal + e;
        continue;
      }
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "ghost plan: request %ld of %ld owned",
                            c, dist->nowned);
    }
  }
  free(request);
  return ierr;
}

/* The ghost particles' plan: each asked of its owner by its position in the owner's block. */
int parallel_ghost_plan(MicaDistribution *dist, const long *offsets) {
  const long n = dist->nghost;
  long *ghost = NULL, *code = NULL;
  int ierr = MICA_MALLOC(ghost, n + 1);
  if (!ierr) ierr = MICA_MALLOC(code, n + 1);
  for (long i = 0; !ierr && i < n; i++) {
    const long k = dist->nowned + i;
    ghost[i] = k, code[i] = dist->global_node[k] - offsets[dist->partition->part[k]];
  }
  if (!ierr) ierr = ghost_plan_build(dist, &dist->ghosts, n, ghost, dist->partition->part + dist->nowned, code);
  free(ghost), free(code);
  return ierr;
}

static void ghost_plan_free(MicaGhostPlan *g) {
  free(g->send_counts), free(g->send_displs), free(g->recv_counts), free(g->recv_displs);
  free(g->send_index), free(g->recv_index), free(g->scaled), free(g->send_buffer), free(g->recv_buffer);
  memset(g, 0, sizeof *g);
}

/* counts and displacements × ncomp, and buffers large enough. */
static int scale_plan(MicaGhostPlan *g, int ncomp, int **sc, int **sd, int **rc, int **rd) {
  const int P = mica_parallel_size();
  *sc = g->scaled, *sd = g->scaled + P, *rc = g->scaled + 2 * P, *rd = g->scaled + 3 * P;
  for (int r = 0; r < P; r++) {
    (*sc)[r] = g->send_counts[r] * ncomp, (*sd)[r] = g->send_displs[r] * ncomp;
    (*rc)[r] = g->recv_counts[r] * ncomp, (*rd)[r] = g->recv_displs[r] * ncomp;
  }
  const long need = ((long)g->send_displs[P] > (long)g->recv_displs[P] ? g->send_displs[P] : g->recv_displs[P]) *
                    (long)ncomp + 1;
  if (need <= g->buffer_size) return MICA_SUCCESS;
  free(g->send_buffer), free(g->recv_buffer);
  g->send_buffer = g->recv_buffer = NULL;
  g->buffer_size = 0;
  MICA_CALL(MICA_MALLOC(g->send_buffer, need));
  MICA_CALL(MICA_MALLOC(g->recv_buffer, need));
  g->buffer_size = need;
  return MICA_SUCCESS;
}

static int plan_update(MicaGhostPlan *g, double *v, int ncomp) {
  const int P = mica_parallel_size();
  int *sc, *sd, *rc, *rd;
  MICA_CALL(mica_parallel_agree(scale_plan(g, ncomp, &sc, &sd, &rc, &rd)));
  for (long k = 0; k < g->send_displs[P]; k++)
    memcpy(g->send_buffer + k * ncomp, v + g->send_index[k] * ncomp, sizeof(double) * (size_t)ncomp);
  MPI_Alltoallv(g->send_buffer, sc, sd, MPI_DOUBLE, g->recv_buffer, rc, rd, MPI_DOUBLE, mica_parallel_comm());
  for (long k = 0; k < g->recv_displs[P]; k++)
    memcpy(v + g->recv_index[k] * ncomp, g->recv_buffer + k * ncomp, sizeof(double) * (size_t)ncomp);
  return MICA_SUCCESS;
}

/* The reverse of the update: the ghosts' entries added into their owners', in rank order (the same sums on every
 * run); the ghosts keep theirs. */
static int plan_reduce(MicaGhostPlan *g, int ierr, double *v, int ncomp) {
  const int P = mica_parallel_size();
  int *sc, *sd, *rc, *rd;
  if (!ierr) ierr = scale_plan(g, ncomp, &sc, &sd, &rc, &rd);
  MICA_CALL(mica_parallel_agree(ierr));
  for (long k = 0; k < g->recv_displs[P]; k++)
    memcpy(g->recv_buffer + k * ncomp, v + g->recv_index[k] * ncomp, sizeof(double) * (size_t)ncomp);
  MPI_Alltoallv(g->recv_buffer, rc, rd, MPI_DOUBLE, g->send_buffer, sc, sd, MPI_DOUBLE, mica_parallel_comm());
  for (long k = 0; k < g->send_displs[P]; k++)
    for (int c = 0; c < ncomp; c++) v[g->send_index[k] * ncomp + c] += g->send_buffer[k * ncomp + c];
  return MICA_SUCCESS;
}

static int plan_sum(MicaGhostPlan *g, int ierr, double *v, int ncomp) {
  MICA_CALL(plan_reduce(g, ierr, v, ncomp));
  return plan_update(g, v, ncomp);
}

int mica_ghost_update(MicaDistribution *dist, double *v, int ncomp) { return plan_update(&dist->ghosts, v, ncomp); }

int mica_ghost_sum(MicaDistribution *dist, int ierr, double *v, int ncomp) {
  return plan_sum(&dist->ghosts, ierr, v, ncomp);
}

int mica_ghost_reduce(MicaDistribution *dist, int ierr, double *v, int ncomp) {
  return plan_reduce(&dist->ghosts, ierr, v, ncomp);
}

int mica_owned_residual(MicaDistribution *dist, int ierr, double *R, int ncomp) {
  if (!ierr) ierr = mica_parallel_inject("assemble");
  return plan_sum(dist->nextra ? &dist->node_ghosts : &dist->ghosts, ierr, R, ncomp);
}

int mica_owned_norm(const MicaDistribution *dist, const double *v, int ncomp, double *norm) {
  double s = 0;
  for (long i = 0; i < dist->nowned * ncomp; i++) s += v[i] * v[i];
  for (long k = dist->nowned; k < dist->nowned_nodes; k++) /* the extra nodes this rank owns */
    for (int c = 0; c < ncomp; c++) s += v[dist->owned_node[k] * ncomp + c] * v[dist->owned_node[k] * ncomp + c];
  MICA_CALL(mica_parallel_sum(MICA_SUCCESS, &s, 1));
  *norm = sqrt(s);
  return MICA_SUCCESS;
}

/* ---- extra nodes (Lagrange multipliers) --------------------------------------------------------------------- */

typedef struct {
  long id, index; /* the node's name and its index among the extra nodes of rank `rank` */
  int rank, slot; /* who holds it, and where its answer goes in the reply */
} ExtraClaim;

static int compare_claim(const void *a, const void *b) {
  const ExtraClaim *x = a, *y = b;
  if (x->id != y->id) return (x->id > y->id) - (x->id < y->id);
  return (x->rank > y->rank) - (x->rank < y->rank);
}

static int home_of(long id, int P) { return (int)(id % P); }

/* At the home rank: every holder of a node hears the lowest holder's rank and index (pairs in `claims`'s order). */
static int decide_owners(const long *claims, long nclaims, const int *displs, long *reply) {
  const int P = mica_parallel_size();
  ExtraClaim *c = NULL;
  MICA_CALL(MICA_MALLOC(c, nclaims + 1));
  for (int r = 0; r < P; r++)
    for (int k = displs[r] / 2; k < displs[r + 1] / 2; k++)
      c[k] = (ExtraClaim){claims[2 * k], claims[2 * k + 1], r, k};
  qsort(c, (size_t)nclaims, sizeof *c, compare_claim);
  for (long k = 0, first = 0; k < nclaims; k++) {
    if (c[k].id != c[first].id) first = k;
    reply[2 * c[k].slot] = c[first].rank, reply[2 * c[k].slot + 1] = c[first].index;
  }
  free(c);
  return MICA_SUCCESS;
}

/* Each extra node's owner and its index there (owner[n], where[n]): claims sent to the nodes' homes, answered. */
static int extra_owners(long n, const long *id, int *owner, long *where) {
  const int P = mica_parallel_size();
  int *sc = NULL, *sd = NULL, *rc = NULL, *rd = NULL;
  long *send = NULL, *recv = NULL, *reply = NULL, *slot = NULL;
  int ierr = MICA_CALLOC(sc, P + 1);
  if (!ierr) ierr = MICA_CALLOC(sd, P + 1);
  if (!ierr) ierr = MICA_CALLOC(rc, P + 1);
  if (!ierr) ierr = MICA_CALLOC(rd, P + 1);
  if (!ierr) ierr = MICA_MALLOC(send, 2 * n + 2);
  if (!ierr) ierr = MICA_MALLOC(slot, n + 1);
  for (long k = 0; !ierr && k < n; k++) sc[home_of(id[k], P)] += 2;
  for (int r = 0; !ierr && r < P; r++) sd[r + 1] = sd[r] + sc[r];
  for (long k = 0; !ierr && k < n; k++) {
    const int h = home_of(id[k], P);
    slot[k] = sd[h] / 2 + (long)rd[h]++; /* rd: a cursor until the counts come back */
    send[2 * slot[k]] = id[k], send[2 * slot[k] + 1] = k;
  }
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoall(sc, 1, MPI_INT, rc, 1, MPI_INT, mica_parallel_comm());
  rd[0] = 0;
  for (int r = 0; r < P; r++) rd[r + 1] = rd[r] + rc[r];
  ierr = MICA_MALLOC(recv, (long)rd[P] + 2);
  if (!ierr) ierr = MICA_MALLOC(reply, (long)rd[P] + 2);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoallv(send, sc, sd, MPI_LONG, recv, rc, rd, MPI_LONG, mica_parallel_comm());
  ierr = decide_owners(recv, rd[P] / 2, rd, reply);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoallv(reply, rc, rd, MPI_LONG, send, sc, sd, MPI_LONG, mica_parallel_comm());
  for (long k = 0; k < n; k++) owner[k] = (int)send[2 * slot[k]], where[k] = send[2 * slot[k] + 1];
cleanup:
  free(sc), free(sd), free(rc), free(rd), free(send), free(recv), free(reply), free(slot);
  return ierr;
}

/* Rows: rank r's particles then its owned extra nodes, after the lower ranks' (offsets over the ranks' counts). */
static int number_nodes(MicaDistribution *dist) {
  const int P = mica_parallel_size(), rank = mica_parallel_rank();
  const long nlocal = dist->nowned + dist->nghost, *size = dist->partition->part_size;
  long *counts = NULL, *old = NULL, *fresh = NULL;
  int ierr = MICA_CALLOC(counts, P + 1);
  if (!ierr) ierr = MICA_CALLOC(old, P + 1);
  if (!ierr) ierr = MICA_CALLOC(fresh, P + 1);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Allgather(&dist->nowned_nodes, 1, MPI_LONG, counts, 1, MPI_LONG, mica_parallel_comm());
  for (int r = 0; r < P; r++) old[r + 1] = old[r] + size[r], fresh[r + 1] = fresh[r] + counts[r];
  dist->nglobal_nodes = fresh[P];
  const int *part = dist->partition->part;
  for (long i = 0; i < nlocal; i++) dist->global_node[i] = fresh[part[i]] + dist->global_node[i] - old[part[i]];
  for (long k = dist->nowned; k < dist->nowned_nodes; k++) dist->global_node[dist->owned_node[k]] = fresh[rank] + k;
cleanup:
  free(counts), free(old), free(fresh);
  return ierr;
}

/* The ghost extra nodes' numbers, from their owners (an exchange of doubles: exact below 2^53). */
static int ghost_numbers(MicaDistribution *dist) {
  const long nnodes = dist->nowned + dist->nghost + dist->nextra;
  double *v = NULL;
  int ierr = MICA_CALLOC(v, nnodes + 1);
  for (long k = 0; !ierr && k < dist->nowned_nodes; k++) v[dist->owned_node[k]] = (double)dist->global_node[dist->owned_node[k]];
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(plan_update(&dist->node_ghosts, v, 1));
  for (long k = 0; k < dist->nextra; k++) {
    const long node = dist->nowned + dist->nghost + k;
    if (dist->extra_owner[k] != mica_parallel_rank()) dist->global_node[node] = (long)v[node];
  }
cleanup:
  free(v);
  return ierr;
}

/* The plan over the ghost particles and the ghost extra nodes. */
static int node_plan(MicaDistribution *dist, const long *where) {
  const long nlocal = dist->nowned + dist->nghost, *size = dist->partition->part_size;
  const int P = mica_parallel_size(), rank = mica_parallel_rank();
  long *ghost = NULL, *code = NULL, *old = NULL, m = 0;
  int *owner = NULL;
  int ierr = MICA_MALLOC(ghost, dist->nghost + dist->nextra + 1);
  if (!ierr) ierr = MICA_MALLOC(code, dist->nghost + dist->nextra + 1);
  if (!ierr) ierr = MICA_MALLOC(owner, dist->nghost + dist->nextra + 1);
  if (!ierr) ierr = MICA_CALLOC(old, P + 1);
  for (int r = 0; !ierr && r < P; r++) old[r + 1] = old[r] + size[r];
  for (long i = dist->nowned; !ierr && i < nlocal; i++) { /* before number_nodes: the particle-only numbers */
    ghost[m] = i, owner[m] = dist->partition->part[i], code[m] = dist->global_node[i] - old[owner[m]];
    m++;
  }
  for (long k = 0; !ierr && k < dist->nextra; k++)
    if (dist->extra_owner[k] != rank) ghost[m] = nlocal + k, owner[m] = dist->extra_owner[k], code[m] = -where[k] - 1, m++;
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(ghost_plan_build(dist, &dist->node_ghosts, m, ghost, owner, code));
cleanup:
  free(ghost), free(code), free(owner), free(old);
  return ierr;
}

int mica_owned_add_nodes(MicaDistribution *dist, long n, const long *id) {
  const int rank = mica_parallel_rank();
  const long nlocal = dist->nowned + dist->nghost;
  long *where = NULL;
  MICA_CHECK(dist->owned && !dist->nextra, MICA_ERR_ARGUMENT, "extra nodes: added once, to distributed data");
  int ierr = MICA_MALLOC(dist->extra_owner, n + 1);
  if (!ierr) ierr = MICA_MALLOC(where, n + 1);
  if (!ierr) ierr = MICA_REALLOC(dist->global_node, nlocal + n + 1);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(extra_owners(n, id, dist->extra_owner, where));
  dist->nextra = n;
  long mine = 0;
  for (long k = 0; k < n; k++) mine += dist->extra_owner[k] == rank;
  dist->nowned_nodes = dist->nowned + mine;
  ierr = MICA_MALLOC(dist->owned_node, dist->nowned_nodes + 1);
  for (long i = 0; !ierr && i < dist->nowned; i++) dist->owned_node[i] = i;
  for (long k = 0, j = dist->nowned; !ierr && k < n; k++)
    if (dist->extra_owner[k] == rank) dist->owned_node[j++] = nlocal + k;
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MICA_CALL_CLEANUP(node_plan(dist, where));
  MICA_CALL_CLEANUP(number_nodes(dist));
  MICA_CALL_CLEANUP(ghost_numbers(dist));
cleanup:
  free(where);
  return ierr;
}

int mica_owned_node(const MicaDistribution *dist, long k) {
  const long nlocal = dist->nowned + dist->nghost;
  return k < nlocal ? k < dist->nowned : dist->extra_owner[k - nlocal] == mica_parallel_rank();
}

/* ---- points evaluated by one rank ------------------------------------------------------------------------ */

int mica_owned_point_rank(const MicaDistribution *dist, const double *x, int *root) {
  const int P = mica_parallel_size(), rank = mica_parallel_rank();
  long *ptr = NULL, *index = NULL;
  int ierr = mica_point_supports(dist->mls, 1, x, &ptr, &index, NULL);
  long counts[2] = {0, 0}; /* the owned particles covering x (summed: its whole support), the local ones */
  if (!ierr) {
    counts[1] = ptr[1];
    for (long e = 0; e < ptr[1]; e++) counts[0] += index[e] < dist->nowned;
  }
  free(ptr), free(index);
  MICA_CALL(mica_parallel_agree(ierr));
  long total = 0;
  MPI_Allreduce(&counts[0], &total, 1, MPI_LONG, MPI_SUM, mica_parallel_comm());
  int mine = total > 0 && counts[1] == total ? rank : P;
  MPI_Allreduce(&mine, root, 1, MPI_INT, MPI_MIN, mica_parallel_comm());
  MICA_CHECK(total > 0, MICA_ERR_INPUT, "no particle's support covers the point (%g, %g, %g)", x[0],
             mls_dim(dist->mls) > 1 ? x[1] : 0.0, mls_dim(dist->mls) > 2 ? x[2] : 0.0);
  MICA_CHECK(*root < P, MICA_ERR_ARGUMENT,
             "no rank holds all %ld particles whose supports cover the point (%g, %g, %g)", total, x[0],
             mls_dim(dist->mls) > 1 ? x[1] : 0.0, mls_dim(dist->mls) > 2 ? x[2] : 0.0);
  return MICA_SUCCESS;
}

/* Each ghost's position among its owner's particles: its key sent to the owner, found among the owner's keys
 * (ascending), sent back. Collective. */
int parallel_ghost_positions(long n, const int *owner, const long *key, long nowned, const long *owned_key,
                           long *position) {
  const int P = mica_parallel_size();
  int *sc = NULL, *sd = NULL, *rc = NULL, *rd = NULL;
  long *send = NULL, *recv = NULL, *slot = NULL;
  int ierr = MICA_CALLOC(sc, P + 1);
  if (!ierr) ierr = MICA_CALLOC(sd, P + 1);
  if (!ierr) ierr = MICA_CALLOC(rc, P + 1);
  if (!ierr) ierr = MICA_CALLOC(rd, P + 1);
  if (!ierr) ierr = MICA_MALLOC(send, n + 1);
  if (!ierr) ierr = MICA_MALLOC(slot, n + 1);
  for (long i = 0; !ierr && i < n; i++) sc[owner[i]]++;
  for (int r = 0; !ierr && r < P; r++) sd[r + 1] = sd[r] + sc[r];
  for (long i = 0; !ierr && i < n; i++) slot[i] = sd[owner[i]] + rd[owner[i]]++, send[slot[i]] = key[i]; /* rd: cursors */
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoall(sc, 1, MPI_INT, rc, 1, MPI_INT, mica_parallel_comm());
  rd[0] = 0;
  for (int r = 0; r < P; r++) rd[r + 1] = rd[r] + rc[r];
  ierr = MICA_MALLOC(recv, (long)rd[P] + 1);
  MICA_CALL_CLEANUP(mica_parallel_agree(ierr));
  MPI_Alltoallv(send, sc, sd, MPI_LONG, recv, rc, rd, MPI_LONG, mica_parallel_comm());
  for (long k = 0; k < rd[P]; k++) { /* the owner's answer: the key's position, −1 if it is not an owned particle */
    const long *hit = bsearch(&recv[k], owned_key, (size_t)nowned, sizeof(long), mica_compare_long);
    recv[k] = hit ? hit - owned_key : -1;
  }
  MPI_Alltoallv(recv, rc, rd, MPI_LONG, send, sc, sd, MPI_LONG, mica_parallel_comm());
  for (long i = 0; i < n; i++) {
    position[i] = send[slot[i]];
    if (position[i] < 0 && !ierr)
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "ghost with key %ld: rank %d owns no "
                            "such particle", key[i], owner[i]);
  }
  ierr = mica_parallel_agree(ierr); /* the ranks go on to collectives together, or stop together */
cleanup:
  free(sc), free(sd), free(rc), free(rd), free(send), free(recv), free(slot);
  return ierr;
}

void parallel_owned_free(MicaDistribution *dist) {
  ghost_plan_free(&dist->ghosts);
  ghost_plan_free(&dist->node_ghosts);
  free(dist->owned_node), free(dist->extra_owner);
  dist->owned_node = NULL, dist->extra_owner = NULL;
  free(dist->global_node);
  dist->global_node = NULL;
  mls_destroy(&dist->mls);
  mica_mesh_destroy(&dist->cells_mesh);
}
