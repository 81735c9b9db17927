/* Sparse matrices and their direct solvers (docs/theory.md §Sparse matrices).
 *
 * The pattern is built once from "cliques": sets of nodes coupled all to all (the particles supporting a
 * quadrature point, plus any multiplier nodes at that point), each node carrying ndof unknowns. Building
 * it uses O(nnz) memory — no triplet list that grows with quadrature points × support². The matrix is
 * stored in full (both triangles) compressed-sparse-column form with 64-bit indices, rows sorted within
 * each column, so the same matrix feeds CHOLMOD (which reads the upper triangle) and UMFPACK.
 * Assembly scatters dense clique blocks straight into the values.
 */
#ifndef MICA_SPARSE_H
#define MICA_SPARSE_H

#include <mpi.h>

#include "mica/error.h"
#include "mica/registry.h"

typedef struct MicaSparse {
  long n;       /* rows = columns = nnodes × ndof */
  long nnz;
  int ndof;     /* unknowns per node; dof = node × ndof + component */
  long *colptr; /* [n+1] */
  long *rowind; /* [nnz], ascending within a column */
  double *val;  /* [nnz] */
  long *cursor; /* [n] scratch of mica_sparse_mirror_upper */
} MicaSparse;

/* Pattern of nnodes × ndof unknowns from ncliques cliques: clique c holds the nodes
 * clique_nodes[clique_ptr[c] .. clique_ptr[c+1]) (any order; duplicates allowed). Values are zero. */
int mica_sparse_create(long nnodes, int ndof, long ncliques, const long *clique_ptr, const long *clique_nodes,
                       MicaSparse **A);
/* The same from a node graph: node i's neighbors adj[ptr[i] .. ptr[i+1]) (any order, no repeats, the node itself
 * included where its diagonal block is wanted), the graph symmetric (j lists i whenever i lists j). */
int mica_sparse_create_graph(long nnodes, int ndof, const long *ptr, const long *adj, MicaSparse **A);
int mica_sparse_destroy(MicaSparse **A);
void mica_sparse_zero(MicaSparse *A);
/* A's values are dead until it is assembled again (zeroed first): their memory goes back to the system and they
 * read as zero afterwards (Linux's MADV_DONTNEED on the whole pages inside val; the rest zeroed). For a solver
 * that has copied them, while its own setup peaks (linear_petsc.c, MicaKrylovOptions.discardable). */
void mica_sparse_discard_values(MicaSparse *A);
/* A[dofs of nodes[a], dofs of nodes[b]] += K[(a*ndof + i) * (n*ndof) + (b*ndof + j)] for a clique's nodes
 * in ASCENDING order (n nodes, K dense row-major (n·ndof)²). Every pair must be in the pattern
 * (MICA_ERR_ARGUMENT otherwise). Cost O(Σ column lengths touched), no allocation. */
int mica_sparse_add_clique(MicaSparse *A, long n, const long *nodes, const double *K);
/* The same for a symmetric clique matrix given by its lower blocks in the planar layout of mica/kernel.h
 * (ndof = dim): adds the upper blocks, node pairs a ≤ b (clique order, ascending nodes), entry (a i, b j) read
 * from its transpose at K[(b·ndof + j)·(ndof·np) + i·np + a]. The lower triangle is left to
 * mica_sparse_mirror_upper. The nodes may be the union of several cliques: a pair outside the pattern is
 * skipped if its block is zero (no clique coupled it), an error otherwise. */
int mica_sparse_add_clique_upper(MicaSparse *A, long n, const long *nodes, const double *K, long np);
/* Any clique matrix given by its transpose in the planar layout: A[dofs of nodes[a], dofs of nodes[b]] +=
 * K[(b·ndof + j)·(ndof·np) + i·np + a] for every pair a, b (row (b j) of K is column (b j) of A; an unsymmetric
 * Petrov–Galerkin block computed with test and trial functions swapped). Pairs outside the pattern as above. */
int mica_sparse_add_clique_columns(MicaSparse *A, long n, const long *nodes, const double *K, long np);
/* A_ji = A_ij for every stored i < j: makes A symmetric from its upper triangle after upper-block cliques
 * (overwrites the strict lower triangle; the pattern is symmetric). O(nnz), no allocation. */
void mica_sparse_mirror_upper(MicaSparse *A);
/* y = A x */
void mica_sparse_matvec(const MicaSparse *A, const double *x, double *y);
/* max |A − Aᵀ| / max |A|: 0 for a symmetric matrix. */
double mica_sparse_asymmetry(const MicaSparse *A);
/* Row i set to zero. The pattern is symmetric, so row i's columns are column i's rows: O(column length ×
 * log(column length)), no allocation. Used to replace an equation (bc.method = collocation). */
void mica_sparse_zero_row(MicaSparse *A, long i);
/* A_ij = value; MICA_ERR_ARGUMENT if (i, j) is not in the pattern. */
int mica_sparse_set(MicaSparse *A, long i, long j, double value);

/* ---- Direct solvers (ops table) ------------------------------------------------------------------------ */

typedef struct MicaLinearSolverStats {
  long nnz_factor;      /* nnz(L) (CHOLMOD) or nnz(L) + nnz(U) (UMFPACK) */
  double flops;         /* flops of the last numeric factorization */
  double time_analyze;  /* seconds, summed over calls */
  double time_factor;
  double time_solve;
  long analyses, factorizations, solves;
  /* iterative solvers (petsc's Krylov methods, cholmod-sym's refinement): iterations over all solves, the most in one solve, |b − A x| / |b| of the last */
  long krylov_iterations, krylov_iterations_max;
  double krylov_residual;
  double krylov_cpu; /* thread CPU seconds of the iterations (mica_cputime), summed over solves */
  /* petsc under MPI: the off-rank columns of this rank's rows (MatGetGhosts): the entries of x every matrix–vector
   * product receives from other ranks, the halo of one Krylov iteration; 0 in one process */
  long halo_dofs;
  int multigrid_levels; /* petsc's gmg: the levels of its hierarchy, the particles' included; 0 for other methods */
  const char *ordering; /* cholmod, cholmod-sym: the fill-reducing ordering of the last analysis (a static name);
                         * NULL for the other methods */
} MicaLinearSolverStats;

/* Settings of the iterative solvers (petsc, cholmod-sym; zero members take the defaults). */
typedef struct MicaKrylovOptions {
  double rtol;        /* stop at |b − A x| ≤ rtol |b| (default 1e-10) */
  int max_iterations; /* per solve (default 10000) */
  int verbose;        /* one line per solve */
  /* petsc (linear_petsc.c): solver.petsc's preset and solver.petsc_options, applied over it */
  char petsc_preset[32];
  char petsc_options[1024];
  char petsc_where[256];   /* where the deck set solver.petsc_options, for its errors */
  char petsc_preset_where[256]; /* and solver.petsc */
  /* what the caller knows of the matrices, for the solvers that choose by it (petsc) */
  int spd;            /* symmetric positive definite: CG, Cholesky (else GMRES, LU) */
  int saddle;         /* Lagrange multipliers: a zero diagonal block (a saddle point) */
  int near_null_count; /* near-null space (rigid motions) for algebraic multigrid: */
  const double *near_null; /* [near_null_count][n] in mica's numbering, borrowed; NULL: none */
  int coord_dim;           /* the nodes' coordinates, for geometric multigrid (petsc's gmg): */
  long coord_nodes;        /* [coord_nodes][coord_dim], node k's unknowns k ndof .. (k + 1) ndof − 1; borrowed; */
  const double *coords;    /* NULL: none (finite elements) */
  /* the caller's matrix whose values it does not read after a factorization until it assembles them again: a
   * solver that copied them may discard them (mica_sparse_discard_values); NULL: none (Newton's, see newton.c) */
  MicaSparse *discardable;
} MicaKrylovOptions;

typedef struct MicaLinearSolver MicaLinearSolver;

/* Linear solvers: a registry of types (mica/registry.h), solver.linear. A solver's own settings (petsc:
 * solver.petsc, solver.petsc_options) are read by its type.from_settings into a MicaKrylovOptions. */
enum {
  MICA_LINEAR_SPD_ONLY = 1u << 0, /* symmetric positive definite matrices only (cholmod) */
  /* solves across the ranks itself from each rank's own contributions (petsc): under MPI it is given the ranks'
   * layout (mica_linear_solver_set_layout); the only kind an MPI run takes */
  MICA_LINEAR_DISTRIBUTED = 1u << 2,
  /* factors an approximation and refines to a tolerance (cholmod-sym): reports its iterations like petsc's */
  MICA_LINEAR_REFINES = 1u << 3
};

/* Which rank owns the rows of each node, for a MICA_LINEAR_DISTRIBUTED solver (default: MPI_COMM_SELF, every
 * node on rank 0). node_owner is borrowed and must outlive the solver. */
typedef struct MicaLinearLayout {
  MPI_Comm comm;
  long nnodes;
  const int *node_owner; /* [nnodes] ranks of comm; NULL: all on rank 0 */
  /* Local numbering (parallel.data = "distributed"): the matrices and vectors hold this rank's nodes only, the
   * nowned it owns first, then ghosts; node k is node_global[k] of the nglobal nodes, whose numbers are
   * contiguous per rank in rank order. NULL: the matrices are in the global numbering. owned_node[nowned]: the
   * owned nodes in the order of their numbers when they are not the first nowned (multipliers after the ghosts). */
  const long *node_global;
  long nowned, nglobal;
  const long *owned_node;
} MicaLinearLayout;

typedef struct MicaLinearSolverOps {
  MicaType type; /* "cholmod" (supernodal Cholesky), "umfpack" (LU), ...; flags MICA_LINEAR_* */
  int (*create)(MicaLinearSolver *solver);
  /* Numeric factorization of A; the symbolic analysis of the first call is reused while the pattern
   * (the same MicaSparse object) is unchanged. CHOLMOD returns MICA_ERR_NUMERIC, with a message saying so,
   * when A is not positive definite; UMFPACK when A is singular. */
  int (*factor)(MicaLinearSolver *solver, const MicaSparse *A);
  int (*solve)(MicaLinearSolver *solver, const double *b, double *x);
  void (*destroy)(MicaLinearSolver *solver);
} MicaLinearSolverOps;

struct MicaLinearSolver {
  const MicaLinearSolverOps *ops;
  void *data;
  MicaLinearSolverStats stats;
  MicaKrylovOptions krylov; /* read by the iterative solvers only */
  MicaLinearLayout layout;  /* read by the distributed solvers only */
};

extern const MicaLinearSolverOps mica_linear_cholmod, mica_linear_umfpack;
/* "cholmod-sym" (linear_cholmod_sym.c): CHOLMOD on the symmetric part (A + Aᵀ)/2 and refinement on A, for
 * unsymmetric matrices close to SPD (VCI's tangent); MICA_ERR_NUMERIC when the refinement does not converge. */
extern const MicaLinearSolverOps mica_linear_cholmod_sym;
/* "petsc": PETSc's KSP on a distributed AIJ matrix (linear_petsc.c), serial or under MPI; solver.petsc and
 * solver.petsc_options choose the method (MUMPS, GAMG, hypre, ASM or block Jacobi with CHOLMOD/UMFPACK). */
extern const MicaLinearSolverOps mica_linear_petsc;
/* PETSc for the whole program: PetscInitialize once (idempotent; after MPI_Init under mpirun, collective on
 * MPI_COMM_WORLD), PETSc's signal handler off, its errors returned, not printed; finalize at the end (a no-op if
 * it never started). A serial run starts it when it first creates a petsc solver. */
int mica_petsc_initialize(void);
/* Whether solver.petsc = preset (with solver.petsc_options, which decide for "none") factors the matrix whole
 * (MUMPS, or a LU/Cholesky PC in the options) rather than iterating: for the memory estimate. */
int mica_petsc_method_factors(const char *preset, const char *options);
void mica_petsc_finalize(void);
/* cholmod, umfpack, cholmod-sym, petsc (linear_solver.c). The deck's solver.linear also offers "auto", its default: CHOLMOD
 * for symmetric positive definite tangents, UMFPACK otherwise (the registry's default is the former). */
extern MicaRegistry mica_linear_solver_registry;
const MicaLinearSolverOps *mica_linear_solver_find(const char *name);
static inline int mica_linear_solver_has(const MicaLinearSolverOps *ops, unsigned flag) {
  return mica_type_has(&ops->type, flag);
}

int mica_linear_solver_create(const MicaLinearSolverOps *ops, MicaLinearSolver **solver);
int mica_linear_solver_factor(MicaLinearSolver *solver, const MicaSparse *A);
int mica_linear_solver_solve(MicaLinearSolver *solver, const double *b, double *x);
int mica_linear_solver_destroy(MicaLinearSolver **solver);
/* The iterative solvers' settings (copied; direct solvers ignore them). */
int mica_linear_solver_set_krylov(MicaLinearSolver *solver, const MicaKrylovOptions *opt);
/* The ranks' layout for a distributed solver (copied; the owner array is borrowed). Before the first factor. */
int mica_linear_solver_set_layout(MicaLinearSolver *solver, const MicaLinearLayout *layout);

#endif
