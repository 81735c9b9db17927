/* Parallel runs with MPI and METIS (docs/architecture.md §parallel).
 *
 * Under `mpirun -np P` (P > 1) every rank reads the deck and builds the particles, the background cells
 * and the MLS approximation (replicated: O(particles) memory each). METIS partitions the particle graph
 * (particles that share a quadrature point are adjacent); each volume or boundary quadrature point follows
 * the particle nearest to it among its supports (distance measured in support radii). Each rank then
 * evaluates and caches shape functions only at its own points and assembles their residual and tangent
 * contributions. Its ghost particles — the supports of its points that other ranks own — are as deep as
 * the supports by construction. Vectors (u, R, Δu) are replicated: residual contributions are summed once
 * per assembly, by an MPI_Reduce to rank 0 and an MPI_Bcast of the sum (not MPI_Allreduce, whose sums may
 * differ in the last bit from rank to rank: every rank must take Newton's decisions on the same numbers).
 * Linear solves are PETSc's (solver.linear = "petsc", src/solve/linear_petsc.c): the tangent a matrix whose rows
 * are each rank's particles, its contributions to other ranks' rows moved by PETSc (ADD_VALUES).
 *
 * Errors: a failure on one rank reaches every rank at the next collective point (mica_parallel_agree);
 * all ranks unwind with the same error code and message, and rank 0 alone reports it. Rank 0 alone
 * prints (other ranks' stdout goes to /dev/null) and writes files.
 *
 * Groups: a command whose runs are independent (the points of a sweep, the combinations of a study) splits
 * the ranks into groups of consecutive ranks (mica_parallel_groups_begin); while the groups last, the
 * group's communicator is mica_parallel_comm(), rank and size are the group's, errors are agreed inside the
 * group, and a group of one rank takes the serial path. After mica_parallel_groups_end the outer ranks agree
 * again: an error one group agreed on is not agreed by the others until they meet there.
 *
 * Testing aid: MICA_INJECT_FAILURE=RANK:PHASE[:exit] makes rank RANK of MPI_COMM_WORLD fail at PHASE (deck,
 * build, assemble, solve, output; point: the start of each point of a sweep or combination of a study that
 * the rank solves) with an error (or, with ":exit", leave the process at once without MPI_Finalize, as a
 * crash would), so the tests can check that every rank stops.
 */
#ifndef MICA_PARALLEL_H
#define MICA_PARALLEL_H

#include <mpi.h>

#include "mica/error.h"
#include "mica/geom.h"
#include "mica/mls.h"
#include "mica/sparse.h"

struct MicaDiscretization;

/* ---- Processes ----------------------------------------------------------------------------------------- */

/* After MPI_Init (only when launched by mpirun): records rank and size; ranks other than 0 send stdout to
 * /dev/null. Serial runs never call it: then rank is 0 and size 1. */
void mica_parallel_start(void);
/* The communicator of the ranks that share the work (MPI_COMM_WORLD; MPI_COMM_SELF in a serial run). Every
 * collective of mica uses it, never MPI_COMM_WORLD itself, so that a command may give groups of ranks
 * problems of their own. */
MPI_Comm mica_parallel_comm(void);
int mica_parallel_rank(void);
int mica_parallel_size(void);
/* The rank in MPI_COMM_WORLD and its size (0 and 1 in a serial run), whatever group is current. */
int mica_parallel_world_rank(void);
int mica_parallel_world_size(void);
/* 1 when more than one rank shares the work (and no mica_parallel_set_alone is in force). */
int mica_parallel_active(void);
/* 1: this rank works alone from now on (each rank solves whole problems, e.g. the points of a sweep);
 * 0: back to sharing. Returns the previous setting. */
int mica_parallel_set_alone(int alone);

/* Collective: every rank passes its error code; all return the code of the lowest failing rank, with its
 * message (prefixed "rank k: ") set on every rank, or MICA_SUCCESS. An error already agreed on is returned
 * again without communication, so unwinding ranks pass later agreement points in step. */
int mica_parallel_agree(int ierr);
/* 1 if the current error was agreed on by all ranks (or the run is serial). */
int mica_parallel_error_agreed(void);

/* Groups of ranks (see the head of this file). */
typedef struct MicaParallelGroups {
  int group;   /* this rank's group, 0 .. ngroups − 1 */
  int ngroups; /* outer size / ranks */
  int ranks;   /* ranks per group */
  int leader;  /* 1 on rank 0 of the group */
  MPI_Comm outer; /* the communicator before the split (MPI_COMM_NULL: serial, nothing was split) */
  int outer_rank, outer_size;
} MicaParallelGroups;

/* Collective over the current communicator: splits its ranks into groups of ranks_per_group consecutive
 * ranks (it must divide their number; serial: only 1) and makes this rank's group current. */
int mica_parallel_groups_begin(int ranks_per_group, MicaParallelGroups *groups);
/* Frees the group's communicator and makes the outer one current again (not collective). */
void mica_parallel_groups_end(MicaParallelGroups *groups);

/* Collective, after agreeing on ierr: the nbytes bytes of every rank, concatenated in rank order, in *all
 * (allocated, *total bytes) on every rank. */
int mica_parallel_allgather(int ierr, const void *mine, long nbytes, char **all, long *total);

/* The failure injected by MICA_INJECT_FAILURE for this rank at this phase, or MICA_SUCCESS. */
int mica_parallel_inject(const char *phase);

/* Collective, after agreeing on ierr: v[n] summed over ranks in place, bitwise the same on every rank
 * (MPI_Reduce to rank 0, then MPI_Bcast). */
int mica_parallel_sum(int ierr, double *v, long n);
/* Collective, after agreeing on ierr: v[n] replaced by its maxima over ranks (MPI_Allreduce: exact, the same on
 * every rank). */
int mica_parallel_max(int ierr, double *v, long n);
/* Collective, after agreeing on ierr: v[n] from rank `root` to all. */
int mica_parallel_broadcast(int ierr, double *v, long n, int root);
/* Collective, after agreeing on ierr: the string *text of rank `root` to all (the others' *text, NULL or
 * allocated, is freed and replaced by a copy). */
int mica_parallel_broadcast_text(int ierr, char **text, int root);
/* Collective over the current communicator, after agreeing on ierr: rank 0's directory dir (ignored elsewhere),
 * which every rank reads and writes (the command's staging directory, where the ranks write their VTU pieces), made
 * known to all; mica_parallel_shared_dir gives it (NULL: none, e.g. a program that calls the library itself) until
 * mica_parallel_unshare_dir (not collective). */
int mica_parallel_share_dir(int ierr, const char *dir);
const char *mica_parallel_shared_dir(void);
void mica_parallel_unshare_dir(void);
/* Collective: each rank's text appended, in rank order, to the file at path (given on rank 0, which has written its
 * part and flushed; ignored elsewhere) — one rank at a time, a token passed along the ranks, so that a table whose
 * rows are spread over the ranks is one file and no rank holds more than its own rows. */
int mica_parallel_append_in_order(int ierr, const char *path, const char *text);
/* Ends every rank now (MPI_Abort) after printing the current error on this rank; serial: exit. */
void mica_parallel_abort(const char *program, int status);

/* ---- Partition ------------------------------------------------------------------------------------------ */

/* The particle graph (no self loops, CSR) and its METIS k-way partition. */
typedef struct MicaPartition {
  int nparts;
  long n;          /* particles (graph vertices) */
  long *xadj;      /* [n+1] */
  long *adjncy;    /* [xadj[n]] neighbors of each particle, ascending */
  int *part;       /* [n] owning rank of each particle */
  long edge_cut;   /* graph edges between parts */
  double imbalance; /* largest part / mean part (1 = perfect) */
  long *part_size; /* [nparts] particles per part */
} MicaPartition;

/* The supports of npoints points x[npoints*dim] (CSR: point p's particles index[ptr[p] .. ptr[p+1]),
 * ascending) from the MLS neighbor search, without evaluating shape functions, and (if nearest != NULL)
 * the supporting particle nearest to each point in the norm of its support (max_d |x_d − x_Id| / ρ_Id for
 * boxes, |x − x_I| / ρ_I for balls), −1 for a point without support. */
int mica_point_supports(const MlsApprox *mls, long npoints, const double *x, long **ptr, long **index,
                        long *nearest);

/* The particle graph of cliques (clique c: the particles nodes[ptr[c] .. ptr[c+1]) supporting point c) and
 * its partition into nparts with METIS_PartGraphKway, vertex weights `weights` (NULL: 1). nparts = 1:
 * everything in part 0, no METIS. An empty part is an error. */
int mica_partition_create(long n, long ncliques, const long *ptr, const long *nodes, const long *weights, int nparts,
                          MicaPartition **partition);
int mica_partition_destroy(MicaPartition **partition);

/* The ghost particles of `rank`: particles in the supports (CSR ptr/index over npoints points) of the
 * points it owns (owner[p] == rank) that another rank owns; ascending, *nghost of them. */
int mica_partition_ghosts(const MicaPartition *partition, int rank, long npoints, const long *ptr,
                          const long *index, const int *owner, long *nghost, long **ghosts);

/* ---- Distribution of a problem ------------------------------------------------------------------------ */

/* Statistics of the distributed solve (accumulated over the run). */
typedef struct MicaParallelStats {
  long owned_particles, ghost_particles, owned_points; /* this rank */
  long ghost_particles_max;                            /* over ranks */
  long max_owned_points, min_owned_points;             /* over ranks */
  double time_partition;
} MicaParallelStats;

/* parallel.data = "distributed" (own_exchange.c): the plan of the ghost exchange. A rank's ghosts are owned elsewhere;
 * per rank r, the ghosts it receives from r (recv_index: their local particle numbers, grouped by r) and the owned
 * particles it sends to r (send_index), counts and displacements in particles. */
typedef struct MicaGhostPlan {
  int *send_counts, *send_displs, *recv_counts, *recv_displs; /* [P + 1] each */
  long *send_index, *recv_index;
  int *scaled;      /* [4 P] the counts and displacements times the unknowns per particle, per exchange */
  double *send_buffer, *recv_buffer;
  long buffer_size; /* doubles in each buffer */
} MicaGhostPlan;

/* A problem distributed over the ranks: the partition, who owns which quadrature point, and this rank's
 * share of the discretization (its volume and boundary points; particles and boundary vertices whole). With
 * parallel.data = "distributed" (owned = 1), the particles too: `local` holds this rank's block of particles
 * (owned, first) and its ghosts (the other ranks' particles within the supports of its points), numbered
 * locally (its volume is the body's); partition->n is then the local count and partition->part the owner of each
 * local particle. */
typedef struct MicaDistribution {
  MicaPartition *partition;
  int *volume_owner;       /* [nquad] */
  int **set_owner;         /* [nsets][n] */
  struct MicaDiscretization *local; /* this rank's points */
  MicaParallelStats stats;
  long nparticles;
  int nsets;
  /* parallel.data = "distributed" only (0 / NULL otherwise) */
  int owned;
  int error_order;        /* the error norms' Gauss points per direction in a cell (quadrature.error_order; 0: none),
                             whose supports each rank holds for its cells */
  int procs[3];           /* the block split of the particle and cell grids: blocks per axis */
  long cell_lo[3], cell_hi[3]; /* this rank's block of the cell grid */
  long nowned, nghost;    /* local particles: owned ones first, then ghosts */
  long *global_node;      /* [nowned + nghost] each local particle's number in the ranks' contiguous numbering
                             (the offsets of the lower ranks' blocks + the position in its owner's block) */
  MlsApprox *mls;         /* the MLS approximation on the local particles, with the global run's radii */
  MicaGhostPlan ghosts;
  /* extra nodes (Lagrange multipliers, mica_owned_add_nodes): local nodes nowned + nghost + k, k < nextra. With
   * them the rows of each rank are its particles then its extra nodes, and global_node numbers both */
  long nextra;
  int *extra_owner;       /* [nextra] the rank owning each */
  long nowned_nodes;      /* nowned + the extra nodes this rank owns */
  long *owned_node;       /* [nowned_nodes] the local nodes this rank owns, in the order of their numbers */
  long nglobal_nodes;     /* the nodes over all ranks (nparticles without extra nodes) */
  MicaGhostPlan node_ghosts; /* the plan over ghost particles and ghost extra nodes */
  MicaMesh *cells_mesh;   /* a Gmsh mesh (own_mesh.c): the part of it this rank owns (its elements), else NULL */
} MicaDistribution;

/* Collective. parallel.data = "distributed": the particle and cell index grids of a built-in shape's layout split into one block per rank, P factored along the axes to keep the blocks'
 * interfaces small (as PETSc's DMDA does: no partitioner; an irregular layout: each particle in the block of its
 * nearest grid point, the rank drawing the layout's tiles around its box); this rank builds its particles, its cells' volume and
 * boundary points, and its ghosts from the supports of those points (a box of the grid around its block, with
 * its own MLS search), and the MLS approximation of its particles (mls_opt) with the whole layout's radii. */
/* What a rank's points are, beyond its cells' Gauss points. */
typedef struct MicaOwnedSpec {
  int error_order;      /* quadrature.error_order: the error norms' own points in the rank's cells (0: none) */
  int nodal;            /* quadrature at the particles: the volume points are the nodal cells of the rank's particles
                           (mica_discretization_nodal_block), the boundary sets their faces', and the cells' Gauss
                           points are kept for the error norms (gauss_x) */
  int centroids;        /* NSNI: the points at the cells' centroids (mica_discretization_nodal_centroids) */
  int cell_boundaries;  /* SCNI: the cells' boundary points are evaluated too (the smoothed gradients) */
  int revolve;          /* an axisymmetric section: the rank's weights times 2πr (mica_discretization_revolve) */
  int mesh;             /* output.mesh: the output mesh of the rank's cells (local->mesh), its points evaluated */
  double wider_support; /* > 1: the points also reach the particles within this multiple of the supports' radii
                           (NSNI's quadratic Hessians for a linear basis); 0 otherwise */
} MicaOwnedSpec;
int mica_distribution_create_owned(const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                                   const MicaCellSpec *cells, const MlsOptions *mls_opt, const MicaOwnedSpec *spec,
                                   MicaDistribution **dist);
/* Collective. parallel.data = "distributed" for a Gmsh mesh (own_mesh.c): its particles split into one box of
 * coordinates per rank (procs[] boxes per axis: slabs, columns and blocks of about equal node counts, cut on the
 * source's sample), each volume element owned by the box of its centroid and each boundary element by the owner of
 * the element it bounds; each rank reads only the region of the mesh around its box; the rest as
 * mica_distribution_create_owned (no nodal quadrature). */
int mica_distribution_create_owned_mesh(const MicaMeshSource *mesh, const MicaCellSpec *cells,
                                        const MlsOptions *mls_opt, const MicaOwnedSpec *spec, MicaDistribution **dist);
/* The volume points of order `order` per direction in this rank's cells (quadrature.error_order's points: a
 * discretization without particles or boundary points). */
int mica_owned_cell_points(const MicaShapeSpec *shape, const MicaLayoutSpec *layout, const MicaCellSpec *cells,
                           const MicaDistribution *dist, int order, MicaDiscretization **disc);
/* The blocks per axis the split of P ranks over a grid of cells[3] gives (procs[d] ≤ cells[d]); MICA_ERR_INPUT
 * if P does not fit the grid. */
int mica_block_split(int P, int dim, const long cells[3], int procs[3]);
/* Collective. v[nlocal·ncomp] (ncomp unknowns per particle): the owners' values copied into the ghosts. */
int mica_ghost_update(MicaDistribution *dist, double *v, int ncomp);
/* Collective, after agreeing on ierr: each ghost's entries added into its owner's, then the owners' sums copied
 * back into the ghosts (v complete everywhere: the sum over ranks of their contributions). */
int mica_ghost_sum(MicaDistribution *dist, int ierr, double *v, int ncomp);
/* Collective, after agreeing on ierr: each ghost's entries added into its owner's (the ghosts keep theirs: the owners
 * hold the sums, e.g. to solve there and mica_ghost_update the results). */
int mica_ghost_reduce(MicaDistribution *dist, int ierr, double *v, int ncomp);
/* Collective: mica_ghost_sum of a residual, after agreeing on ierr (the failure injection point "assemble"). */
int mica_owned_residual(MicaDistribution *dist, int ierr, double *R, int ncomp);
/* Collective: n extra local nodes (Lagrange multipliers) after the particles, node k named id[k] alike on every
 * rank that holds it. Each is owned by the lowest rank holding it (decided at rank id mod P, which hears from all
 * of them); the plan of the residual's exchange covers them (mica_owned_residual), and the numbering of the rows
 * (global_node, owned_node, nglobal_nodes) puts each rank's owned extra nodes after its particles. */
int mica_owned_add_nodes(MicaDistribution *dist, long n, const long *id);
/* Collective: the rank that evaluates a field at point x (the same x on every rank): the lowest one whose local
 * particles hold x's whole support — each rank counts its owned particles covering x, whose sum is the support's
 * size, and its local ones. Its value is then the serial one (round-off apart). MICA_ERR_INPUT if no particle
 * covers x. */
int mica_owned_point_rank(const MicaDistribution *dist, const double *x, int *root);
/* Whether this rank owns local node k (a particle or an extra node). */
int mica_owned_node(const MicaDistribution *dist, long k);
/* Collective: the 2-norm over the ranks of the owned entries of v (bitwise the same on every rank). */
int mica_owned_norm(const MicaDistribution *dist, const double *v, int ncomp, double *norm);

/* Collective. Partitions (on rank 0, broadcast) and builds this rank's share of disc. */
int mica_distribution_create(const struct MicaDiscretization *disc, const MlsApprox *mls, MicaDistribution **dist);
int mica_distribution_destroy(MicaDistribution **dist);

/* The solver of the distributed tangent (linear.c): ops, a solver that distributes the matrix itself
 * (MICA_LINEAR_DISTRIBUTED: petsc), on the layout of the ranks' particles; MICA_ERR_INPUT for a one-process
 * solver. Fits Newton's linear-solver slot: factor takes this rank's tangent contributions, solve this rank's
 * right-hand side and returns its solution (replicated data: whole vectors; distributed: owned and ghosts). */
int mica_parallel_linear_create(MicaDistribution *dist, const MicaLinearSolverOps *ops, MicaLinearSolver **solver);

/* Collective, replicated data: nnz of the sum over ranks of their matrices L (the pattern of the whole tangent),
 * every entry gathered to a rank by its column and counted there. */
int mica_parallel_matrix_nnz(const MicaSparse *L, long *nnz);
/* Collective, distributed data: nnz of the whole tangent whose contributions the ranks' K hold (local numbering),
 * counted at the rows' owners: only the ghost rows' entries travel (own_nnz.c). */
int mica_owned_matrix_nnz(const MicaDistribution *dist, const MicaSparse *K, long *nnz);
/* Collective: the largest value of v over the ranks (for counts: memory per rank, ...). */
long mica_parallel_max_long(long v);
long mica_parallel_sum_long(long v);
/* This process's peak resident memory, bytes (getrusage). */
long mica_parallel_peak_memory(void);

/* Collective: the distributed residual R (this rank's contributions) summed over ranks, after agreeing
 * on ierr (the failure injection point "assemble"). */
int mica_parallel_residual(int ierr, double *R, long n);
/* Wall-clock and thread CPU seconds this rank spent in mica_parallel_residual so far (waiting for the other
 * ranks to finish their assembly, then the sum), and the number of calls. */
void mica_parallel_residual_time(double *wall, double *cpu, long *calls);

#endif
