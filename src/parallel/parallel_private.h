/* Private to src/parallel: moving matrix entries between ranks, and the distributed linear solvers. */
#ifndef MICA_PARALLEL_PRIVATE_H
#define MICA_PARALLEL_PRIVATE_H

#include "mica/parallel.h"

/* The entries of each rank's local matrix L (global numbering) whose nodes both lie in a target's node set,
 * summed over ranks into the target's matrix A (numbered by the set, in node order). */
typedef struct Redistribution {
  int *send_counts, *send_displs; /* [P], [P+1] entries to each rank */
  int *recv_counts, *recv_displs;
  long *send_pos;   /* positions in L->val, grouped by destination */
  double *send_buf;
  long nrecv;
  long *recv_map;   /* position in A->val of each received entry */
  double *recv_buf;
  MicaSparse *A;    /* this rank's target matrix, or NULL if it is no target */
} Redistribution;

/* Collective. member[s][node] != 0: node belongs to target s (member[s] == NULL: s is no target). Every rank
 * passes the same sets. */
int redistribution_create(const MicaSparse *L, const char *const *member, long nnodes, Redistribution **rd);
/* Collective, after agreeing on ierr: L's current values summed into the targets' A. */
int redistribution_move(Redistribution *rd, int ierr, const MicaSparse *L);
void redistribution_destroy(Redistribution **rd);

extern const MicaLinearSolverOps mica_linear_gather, mica_linear_schwarz;
/* create and destroy of both (gather.c) */
int parallel_solver_create(MicaLinearSolver *solver);
void parallel_solver_destroy(MicaLinearSolver *solver);

/* What the distributed solvers keep (MicaLinearSolver.data). */
typedef struct ParallelSolver {
  MicaDistribution *dist;
  const MicaLinearSolverOps *inner_ops;
  MicaLinearSolver *inner;   /* rank 0 (gather) or every rank (its subdomain, Schwarz) */
  Redistribution *rd;
  const MicaSparse *L;       /* this rank's contributions of the last factorization (Schwarz matvec) */
  long pattern_n, pattern_nnz; /* of L when rd was built */
  void *krylov;              /* Schwarz work space */
} ParallelSolver;

/* own.c: what parallel.data = "distributed" adds to a distribution (its ghost plan, numbering, local MLS). */
void parallel_owned_free(MicaDistribution *dist);

#endif
