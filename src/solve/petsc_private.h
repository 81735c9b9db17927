/* Shared by the PETSc solver's files (linear_petsc.c, petsc_lattice.c): PETSc's error codes as mica's. */
#ifndef MICA_PETSC_PRIVATE_H
#define MICA_PETSC_PRIVATE_H

#include <petscksp.h>

#include "mica/error.h"
#include "mica/sparse.h"

/* A PETSc error code as a mica error (PETSc's message says what failed; its handler printed nothing). */
int mica_petsc_error(PetscErrorCode code, const char *call, const char *file, int line);
#define PCALL(call)                                                                                                 \
  do {                                                                                                              \
    PetscErrorCode petsc_code_ = (call);                                                                            \
    if (petsc_code_) return mica_petsc_error(petsc_code_, #call, __FILE__, __LINE__);                               \
  } while (0)

/* mica's tangent K (CSC, local or global numbering, its pattern symmetric) into PETSc's AIJ matrix A by
 * position (petsc_fill.c): mica_petsc_fill_create makes A (MATSEQAIJ on one rank, MATMPIAIJ, block size bs) with
 * the rows this rank owns (nlocal of the N; unknown i of K is PETSc's row row_of_dof[i]), every rank's
 * contributions to them included, once per pattern (collective); A's arrays are the fill's, so A is destroyed
 * first. mica_petsc_fill_values puts a tangent's values into A (collective: the values of other ranks' rows are
 * sent to them) and assembles it. symmetric: K's values are symmetric (each column is copied as its row).
 * lend: the caller lends K's values array (Newton's discardable tangent: K is assembled anew, zeroed first, before
 * its values or A are read again after a fill): with several ranks and symmetric values the fill then rearranges
 * K's values in place into A's diagonal block (no copy into fresh memory), and A holds the tangent only until K is
 * assembled again. */
typedef struct MicaPetscFill MicaPetscFill;
int mica_petsc_fill_create(MPI_Comm comm, const MicaSparse *K, const PetscInt *row_of_dof, PetscInt nlocal,
                           PetscInt N, int bs, int symmetric, int lend, Mat *A, MicaPetscFill **fill);
int mica_petsc_fill_values(MicaPetscFill *fill, const MicaSparse *K, Mat A);
/* Whether fill_values can take K (one rank with symmetric values shares K's values array: the same K only). */
int mica_petsc_fill_takes(const MicaPetscFill *fill, const MicaSparse *K);
/* Whether A's values are K's own array (one rank, symmetric values; or lent): K's values stay alive with A. */
int mica_petsc_fill_shares(const MicaPetscFill *fill);
void mica_petsc_fill_destroy(MicaPetscFill **fill);

/* Geometric multigrid on particles (petsc_lattice.c): pc becomes PCMG whose coarse spaces are regular lattices
 * over the bounding box of the particles, each about half as fine as the one below, with multilinear
 * interpolation; the finest level is the matrix's rows, nrows_local of them on this rank, ndof consecutive unknowns
 * per node, node i of them at points[i * dim ..]. nglobal_nodes: the nodes over all ranks; where: the deck's
 * solver.petsc, for the errors. K's nodes (this rank's tangent, owned and ghost nodes: nnodes_K of them at
 * coords_K) give the first coarse operator: mica_petsc_lattice_mg_first makes it from K (Σ over the ranks of
 * Pᵀ K_r P) before K's values go into A (the fill may rearrange them); then mica_petsc_lattice_mg_operators makes
 * the coarser ones, PETSc's PᵀAP level by level, for each new tangent A (of one pattern: the symbolic phases once),
 * before the PC is set up. symmetric: K's values are symmetric. */
typedef struct MicaLatticeMG MicaLatticeMG;
int mica_petsc_lattice_mg_create(PC pc, MPI_Comm comm, int dim, int ndof, PetscInt nrows_local, const double *points,
                                 long nglobal_nodes, long nnodes_K, const double *coords_K, int symmetric,
                                 const char *where, MicaLatticeMG **mg);
int mica_petsc_lattice_mg_levels(const MicaLatticeMG *mg); /* the lattices and the particles */
int mica_petsc_lattice_mg_first(MicaLatticeMG *mg, const MicaSparse *K);
int mica_petsc_lattice_mg_operators(MicaLatticeMG *mg, Mat A);
void mica_petsc_lattice_mg_destroy(MicaLatticeMG **mg);

#endif
