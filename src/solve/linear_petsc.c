/* solver.linear = "petsc": PETSc's linear solvers (KSP, PC) on the tangent as a distributed AIJ matrix.
 *
 * Rows: the rows of node k belong to the rank that owns it (layout.node_owner: the partition's particles under
 * MPI; the multiplier nodes and everything in a serial run on rank 0), renumbered so that each rank's rows are
 * contiguous, as PETSc's ownership ranges want: node k becomes the (position of k among its owner's nodes)-th
 * node after the nodes of the lower ranks, its unknowns consecutive (block size = unknowns per node, which GAMG
 * and the block preconditioners read). One rank's nodes keep mica's order, so a serial run's numbering is mica's.
 *
 * Values: petsc_fill.c makes the AIJ matrix on arrays of its own, once per pattern — each rank's rows from its
 * own contributions (its MicaSparse: the quadrature points it owns) and the pattern of those other ranks send it,
 * exactly preallocated — and copies each tangent's values into it by position, sending the values of rows other
 * ranks own to them (no MatSetValues: its search per entry and the stash cost more than the preconditioner's
 * setup on the 33³ cube, docs/performance.md). PETSc then sees a changed matrix with the same nonzero structure, and
 * its preconditioners redo only their numeric part (MUMPS and CHOLMOD/UMFPACK in ASM keep their symbolic analysis;
 * GAMG with -pc_gamg_reuse_interpolation keeps its prolongators).
 *
 * Vectors: with parallel.data = "replicated" they are replicated in mica: the right-hand side is copied into
 * each rank's owned rows, the solution gathered to every rank with VecScatterCreateToAll and put back in mica's
 * numbering. With "distributed" the layout is local (MicaLinearLayout.node_global): K and the vectors hold the
 * rank's nodes only, owned first; its nodes' PETSc numbers are the layout's, the right-hand side's owned
 * entries (summed over the ranks by the caller) are the rank's rows, and the solution comes back at the rank's
 * nodes, ghosts included, through one VecScatter from PETSc's x; no array of the global length on any rank.
 *
 * The method: solver.petsc, a preset (mumps, gamg, gmg, hypre, asm-cholmod, asm-umfpack, bjacobi-cholmod, or none;
 * gmg's lattices are petsc_lattice.c's, made from the coordinates in krylov.coords),
 * then solver.petsc_options over it, passed to PETSc's options database under a prefix of this solver's own
 * ("mica1_"), never through a shell. An option PETSc did not use by the end of the first solve had no effect: an
 * input error. The rigid motions the caller gives (krylov.near_null) are PETSc's near-null space of the matrix,
 * orthonormalized (GAMG builds its coarse spaces from them; the other methods ignore them).
 */
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linear_private.h"
#include "petsc_private.h"
#include "mica/timer.h"

/* ---- PETSc for the program ---------------------------------------------------------------------------- */

/* Debian's libsuperlu_dist, which libpetsc pulls in, calls mallopt(M_MMAP_MAX, 0) from a constructor as it is
 * loaded: no allocation would be mmapped any more, so a freed cache or matrix stays in the heap and fragments it
 * (measured: the serial CHOLMOD run of a 10³ cube peaked at 857 MB instead of 475). Constructors of the shared
 * libraries run before the program's, so this one puts glibc's default (65536 mmapped regions) back. */
__attribute__((constructor)) static void restore_mmap(void) { mallopt(M_MMAP_MAX, 65536); }

static int petsc_started;

int mica_petsc_error(PetscErrorCode code, const char *call, const char *file, int line) {
  const char *text = NULL;
  PetscErrorMessage(code, &text, NULL);
  return mica_error_set(file, line, "petsc", code == PETSC_ERR_MEM ? MICA_ERR_MEMORY : MICA_ERR_LIBRARY,
                        "PETSc: %s (error %d in %s)", text ? text : "error", (int)code, call);
}
int mica_petsc_initialize(void) {
  if (petsc_started) return MICA_SUCCESS;
  /* no ~/.petscrc or ./.petscrc: a deck's run must not depend on files of the user's (PETSC_OPTIONS is still
   * read: PETSc's own debugging aid; this solver's objects read only their own prefix) */
  int argc = 2;
  char arg0[] = "mica", arg1[] = "-skip_petscrc", *args[] = {arg0, arg1, NULL}, **argv = args;
  PetscErrorCode code = PetscInitialize(&argc, &argv, NULL, NULL);
  if (code) MICA_ERROR(MICA_ERR_LIBRARY, "PetscInitialize failed (error %d)", (int)code);
  petsc_started = 1;
  PCALL(PetscPopSignalHandler()); /* mica's own handlers (publish.h) decide what a signal does */
  PCALL(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
  return MICA_SUCCESS;
}

void mica_petsc_finalize(void) {
  if (!petsc_started) return;
  PetscFinalize();
  petsc_started = 0;
}

/* ---- presets ------------------------------------------------------------------------------------------- */

/* solver.petsc: each preset's PETSc options, for a symmetric positive definite tangent (NULL: the general ones)
 * and for any other (NULL: the preset cannot take one); iterative ones refuse saddle points (multipliers: a zero
 * diagonal block). GAMG's CG form: its Chebyshev smoothers estimate their own eigenvalues at every setup
 * (-pc_gamg_use_sa_esteig false). By default they take the estimate made while smoothing the prolongators, and
 * with the prolongators reused across Newton's tangents that estimate is the first tangent's: Cook's Neo-Hooke
 * membrane (input/cook_neohooke.cfg) stopped at load factor 0.73 with DIVERGED_INDEFINITE_PC; with fresh
 * estimates it takes 2106 CG iterations in 40 solves (rebuilding the prolongators instead: 2121, 8 % slower).
 * The general forms smooth with GMRES, which makes the preconditioner change from one application to the next, so
 * the outer method is flexible GMRES (right-preconditioned by construction): plain GMRES's residual estimate then
 * no longer tracks the true one, and on the jittered Cook membrane with VCI (tests/cli/mpi_distributed.sh) it
 * stopped "converged" at a true |b - Ax| / |b| of 2e-2, Newton taking 29 iterations for 2 steps instead of 12. */
typedef struct {
  const char *name;
  const char *spd, *general;
  int iterative;
  int geometric; /* PCMG on lattices over the particles (petsc_lattice.c), made before the options are read */
} Preset;

static const Preset presets[] = {
    {"mumps", "-ksp_type preonly -pc_type cholesky -pc_factor_mat_solver_type mumps",
     "-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps", 0, 0},
    {"gamg",
     "-ksp_type cg -ksp_norm_type unpreconditioned -pc_type gamg -pc_gamg_reuse_interpolation true "
     "-pc_gamg_threshold -1 -pc_gamg_square_graph 1 -pc_gamg_use_sa_esteig false -mg_levels_ksp_type chebyshev "
     "-mg_levels_pc_type jacobi",
     "-ksp_type fgmres -ksp_gmres_restart 100 -pc_type gamg -pc_gamg_reuse_interpolation true "
     "-pc_gamg_threshold -1 -pc_gamg_square_graph 1 -mg_levels_ksp_type gmres -mg_levels_pc_type jacobi",
     1, 0},
    {"gmg", /* the smoothers as GAMG's, their largest eigenvalue estimated by CG (Lanczos) rather than PETSc's
             * GMRES, whose estimate made the PC indefinite on Cook's membrane (150², linear basis: CG stopped after
             * 3 iterations on the first tangent); the levels and interpolations from the coordinates */
     "-ksp_type cg -ksp_norm_type unpreconditioned -mg_levels_ksp_type chebyshev -mg_levels_pc_type jacobi "
     "-mg_levels_esteig_ksp_type cg",
     "-ksp_type fgmres -ksp_gmres_restart 100 -mg_levels_ksp_type gmres -mg_levels_pc_type jacobi",
     1, 1},
    {"hypre", "-ksp_type cg -ksp_norm_type unpreconditioned -pc_type hypre -pc_hypre_type boomeramg",
     "-ksp_type gmres -ksp_pc_side right -ksp_gmres_restart 100 -pc_type hypre -pc_hypre_type boomeramg", 1, 0},
    {"asm-cholmod",
     "-ksp_type cg -ksp_norm_type unpreconditioned -pc_type asm -pc_asm_type basic -sub_pc_type cholesky "
     "-sub_pc_factor_mat_solver_type cholmod",
     NULL, 1, 0},
    {"asm-umfpack", NULL, /* GMRES: ASM's restricted form is not symmetric, so any tangent */
     "-ksp_type gmres -ksp_pc_side right -ksp_gmres_restart 100 -pc_type asm -sub_pc_type lu "
     "-sub_pc_factor_mat_solver_type umfpack",
     1, 0},
    {"bjacobi-cholmod",
     "-ksp_type cg -ksp_norm_type unpreconditioned -pc_type bjacobi -sub_pc_type cholesky "
     "-sub_pc_factor_mat_solver_type cholmod",
     NULL, 1, 0},
    {"none", "", "", 0, 0},
    {NULL, NULL, NULL, 0, 0}};

static const Preset *find_preset(const char *name) {
  for (const Preset *p = presets; p->name; p++)
    if (!strcmp(p->name, name)) return p;
  return NULL;
}

int mica_petsc_method_factors(const char *preset, const char *options) {
  const Preset *p = find_preset(preset && preset[0] ? preset : "mumps");
  if (p && strcmp(p->name, "none")) return !p->iterative;
  /* "none": the options alone say; subdomain factors (-sub_pc_type) are small beside a whole one */
  return options && (strstr(options, "-pc_type lu") || strstr(options, "-pc_type cholesky"));
}

/* ---- the solver ------------------------------------------------------------------------------------------ */

typedef struct {
  MPI_Comm comm;
  int rank, size;
  long n, nnodes;
  long N;               /* global unknowns (n, unless the layout is local) */
  int ndof;
  int local;            /* the layout's local numbering: K and the vectors hold this rank's nodes only */
  MicaPatternKey pattern;
  PetscInt *row_of_dof; /* [n] PETSc's row of each mica unknown (replicated) */
  long *local_dofs;     /* [nlocal] mica's unknown of each row this rank owns, in PETSc's order */
  PetscInt nlocal;
  int symmetric;        /* the values are symmetric (krylov.spd): each column is copied as its row */
  Mat A;
  MicaPetscFill *fill;  /* how K's values reach A (petsc_fill.c) */
  KSP ksp;
  Vec b, x, r, all;     /* all: the solution on every rank (local layout: at this rank's nodes, ghosts included) */
  VecScatter to_all;
  MatNullSpace near_null;
  MicaLatticeMG *lattice; /* gmg: its levels (petsc_lattice.c), whose coarse operators each tangent remakes */
  char prefix[32];
  char *options;        /* the options given to PETSc under prefix (cleared at the end) */
  int solved;           /* a solve has run: the options were checked */
  int ready;            /* A holds a complete assembled matrix that KSP set up */
} PetscSolver;

static int counter; /* prefixes: one per solver the process created */

static int petsc_create(MicaLinearSolver *solver) {
  MICA_CALL(mica_petsc_initialize());
  PetscSolver *ps = NULL;
  MICA_CALL(MICA_CALLOC(ps, 1));
  snprintf(ps->prefix, sizeof ps->prefix, "mica%d_", ++counter);
  solver->data = ps;
  return MICA_SUCCESS;
}

/* The option names of text (words "-name" not followed by a digit: "-1" is a value), cleared under the prefix. */
static void clear_options(PetscSolver *ps) {
  if (!ps->options) return;
  char *copy = strdup(ps->options), *save = NULL, name[300];
  for (char *word = copy ? strtok_r(copy, " \t\n", &save) : NULL; word; word = strtok_r(NULL, " \t\n", &save)) {
    if (word[0] != '-' || !word[1] || (word[1] >= '0' && word[1] <= '9') || word[1] == '.') continue;
    snprintf(name, sizeof name, "-%s%s", ps->prefix, word + 1);
    PetscOptionsClearValue(NULL, name);
  }
  free(copy);
  free(ps->options);
  ps->options = NULL;
}

static void free_objects(PetscSolver *ps) {
  mica_petsc_lattice_mg_destroy(&ps->lattice);
  KSPDestroy(&ps->ksp);
  MatNullSpaceDestroy(&ps->near_null);
  MatDestroy(&ps->A);
  mica_petsc_fill_destroy(&ps->fill);
  VecDestroy(&ps->b), VecDestroy(&ps->x), VecDestroy(&ps->r), VecDestroy(&ps->all);
  VecScatterDestroy(&ps->to_all);
  free(ps->row_of_dof), free(ps->local_dofs);
  ps->row_of_dof = NULL, ps->local_dofs = NULL;
  ps->ready = 0;
}

static void petsc_destroy(MicaLinearSolver *solver) {
  PetscSolver *ps = solver->data;
  if (!ps) return;
  free_objects(ps);
  clear_options(ps);
  free(ps);
  solver->data = NULL;
}

/* Local numbering: the layout's node numbers are PETSc's; this rank's rows are its first nowned nodes (or its
 * owned_node list). */
static int number_local_rows(PetscSolver *ps, const MicaLinearLayout *layout) {
  MICA_CHECK(layout->nnodes == ps->nnodes && layout->nowned <= ps->nnodes, MICA_ERR_ARGUMENT,
             "petsc: a local layout of %ld nodes (%ld owned) for a matrix of %ld", layout->nnodes, layout->nowned,
             ps->nnodes);
  ps->local = 1;
  ps->N = layout->nglobal * ps->ndof;
  ps->nlocal = (PetscInt)(layout->nowned * ps->ndof);
  MICA_CALL(MICA_MALLOC(ps->row_of_dof, ps->n + 1));
  MICA_CALL(MICA_MALLOC(ps->local_dofs, ps->nlocal + 1));
  for (long k = 0; k < ps->nnodes; k++)
    for (int c = 0; c < ps->ndof; c++) ps->row_of_dof[k * ps->ndof + c] = (PetscInt)(layout->node_global[k] * ps->ndof + c);
  for (PetscInt i = 0; i < ps->nlocal; i++)
    ps->local_dofs[i] = layout->owned_node ? layout->owned_node[i / ps->ndof] * ps->ndof + i % ps->ndof : i;
  return MICA_SUCCESS;
}

/* Contiguous rows per rank: node k's PETSc node number, and the unknowns this rank owns. */
static int number_rows(PetscSolver *ps, const MicaLinearLayout *layout) {
  ps->local = 0;
  ps->N = ps->n;
  if (layout->node_global) return number_local_rows(ps, layout);
  long *start = NULL;
  MICA_CALL(MICA_CALLOC(start, ps->size + 1));
  int ierr = MICA_SUCCESS;
  for (long k = 0; k < ps->nnodes && !ierr; k++) {
    const int owner = layout->node_owner && k < layout->nnodes ? layout->node_owner[k] : 0;
    if (owner < 0 || owner >= ps->size)
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "petsc: node %ld owned by rank %d of %d",
                            k, owner, ps->size);
    else start[owner + 1]++;
  }
  for (int r = 0; r < ps->size; r++) start[r + 1] += start[r];
  ps->nlocal = (PetscInt)((start[ps->rank + 1] - start[ps->rank]) * ps->ndof);
  if (!ierr) ierr = MICA_MALLOC(ps->row_of_dof, ps->n);
  if (!ierr) ierr = MICA_MALLOC(ps->local_dofs, ps->nlocal + 1);
  long mine = 0;
  for (long k = 0; k < ps->nnodes && !ierr; k++) {
    const int owner = layout->node_owner && k < layout->nnodes ? layout->node_owner[k] : 0;
    const long node = start[owner]++;
    for (int c = 0; c < ps->ndof; c++) ps->row_of_dof[k * ps->ndof + c] = (PetscInt)(node * ps->ndof + c);
    if (owner == ps->rank)
      for (int c = 0; c < ps->ndof; c++) ps->local_dofs[mine++] = k * ps->ndof + c;
  }
  free(start);
  return ierr;
}

/* The solution at this rank's nodes (local layout: owned and ghosts) from the distributed x: all[i] is x's entry
 * row_of_dof[i]; without a local layout, all of x on every rank. */
static int create_gather(PetscSolver *ps) {
  if (!ps->local) {
    PCALL(VecScatterCreateToAll(ps->x, &ps->to_all, &ps->all));
    return MICA_SUCCESS;
  }
  IS from;
  PCALL(VecCreateSeq(PETSC_COMM_SELF, (PetscInt)ps->n, &ps->all));
  PCALL(ISCreateGeneral(PETSC_COMM_SELF, (PetscInt)ps->n, ps->row_of_dof, PETSC_USE_POINTER, &from));
  PetscErrorCode code = VecScatterCreate(ps->x, from, ps->all, NULL, &ps->to_all);
  ISDestroy(&from);
  PCALL(code);
  return MICA_SUCCESS;
}

static int create_matrix(PetscSolver *ps, const MicaSparse *L, const MicaKrylovOptions *k) {
  const PetscInt N = (PetscInt)ps->N;
  MICA_CALL(mica_petsc_fill_create(ps->comm, L, ps->row_of_dof, ps->nlocal, N, ps->ndof, ps->symmetric,
                                   k->discardable == L, &ps->A, &ps->fill));
  PCALL(MatSetOption(ps->A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  PCALL(MatSetOption(ps->A, MAT_NO_OFF_PROC_ENTRIES, PETSC_TRUE)); /* other ranks' rows: petsc_fill.c sends them */
  /* symmetric, not MAT_SPD: a tangent positive definite at the start may turn indefinite under load, and MUMPS's
   * Cholesky is then LDLᵀ with pivoting (its sym = 2), right either way; CG and CHOLMOD say so when it happens */
  if (k->spd) {
    PCALL(MatSetOption(ps->A, MAT_SYMMETRIC, PETSC_TRUE));
    PCALL(MatSetOption(ps->A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  }
  PCALL(MatCreateVecs(ps->A, &ps->x, &ps->b));
  PCALL(VecDuplicate(ps->b, &ps->r));
  return create_gather(ps);
}

/* The caller's rigid motions, orthonormalized (modified Gram–Schmidt; a dependent one is dropped). */
static int attach_near_null(PetscSolver *ps, const MicaKrylovOptions *k) {
  if (!k->near_null || k->near_null_count <= 0) return MICA_SUCCESS;
  Vec modes[16];
  int count = 0;
  for (int m = 0; m < k->near_null_count && m < 16; m++) {
    PetscScalar *a;
    PCALL(VecDuplicate(ps->x, &modes[count]));
    PCALL(VecGetArray(modes[count], &a));
    for (PetscInt i = 0; i < ps->nlocal; i++) a[i] = k->near_null[(long)m * ps->n + ps->local_dofs[i]];
    PCALL(VecRestoreArray(modes[count], &a));
    for (int p = 0; p < count; p++) {
      PetscScalar dot;
      PCALL(VecDot(modes[count], modes[p], &dot));
      PCALL(VecAXPY(modes[count], -dot, modes[p]));
    }
    PetscReal norm;
    PCALL(VecNormalize(modes[count], &norm));
    if (norm > 1e-12) count++;
    else PCALL(VecDestroy(&modes[count]));
  }
  PCALL(MatNullSpaceCreate(ps->comm, PETSC_FALSE, count, modes, &ps->near_null));
  for (int m = 0; m < count; m++) PCALL(VecDestroy(&modes[m]));
  PCALL(MatSetNearNullSpace(ps->A, ps->near_null));
  return MICA_SUCCESS;
}

/* solver.petsc = "gmg": the lattices and interpolations from the coordinates of this rank's rows' nodes. */
static int attach_lattice_mg(PetscSolver *ps, const MicaKrylovOptions *k, int *levels) {
  MICA_CHECK(k->coords && k->coord_dim > 0 && k->coord_nodes == ps->nnodes, MICA_ERR_INPUT,
             "%s: solver.petsc = \"gmg\" builds its coarse spaces from the coordinates of the particles, and this "
             "problem's unknowns are not all at particles (finite elements or multipliers); use solver.petsc = "
             "\"gamg\"", k->petsc_preset_where);
  const int dim = k->coord_dim;
  const PetscInt npoints = ps->nlocal / ps->ndof;
  double *points = NULL;
  MICA_CALL(MICA_MALLOC(points, (long)npoints * dim + 1));
  for (PetscInt p = 0; p < npoints; p++) {
    const long node = ps->local_dofs[(long)p * ps->ndof] / ps->ndof;
    for (int d = 0; d < dim; d++) points[(long)p * dim + d] = k->coords[node * dim + d];
  }
  PC pc;
  PetscErrorCode code = KSPGetPC(ps->ksp, &pc);
  int ierr = code ? MICA_SUCCESS
                  : mica_petsc_lattice_mg_create(pc, ps->comm, dim, ps->ndof, ps->nlocal, points, ps->N / ps->ndof,
                                                 ps->nnodes, k->coords, ps->symmetric, k->petsc_preset_where,
                                                 &ps->lattice);
  free(points);
  PCALL(code);
  *levels = mica_petsc_lattice_mg_levels(ps->lattice);
  return ierr;
}

/* The preset's options, then the deck's, into PETSc's database under this solver's prefix. */
static int set_options(PetscSolver *ps, const MicaKrylovOptions *k) {
  const char *name = k->petsc_preset[0] ? k->petsc_preset : "mumps";
  const Preset *preset = find_preset(name);
  MICA_CHECK(preset, MICA_ERR_ARGUMENT, "petsc: unknown preset '%s'", name);
  const char *base = k->spd && preset->spd ? preset->spd : preset->general;
  MICA_CHECK(base, MICA_ERR_INPUT,
             "solver.petsc = \"%s\" needs a symmetric positive definite tangent (CG with Cholesky subdomains), "
             "which this problem does not give; use \"asm-umfpack\", \"gamg\" or \"mumps\"",
             name);
  MICA_CHECK(!(preset->iterative && k->saddle), MICA_ERR_INPUT,
             "solver.petsc = \"%s\": the Lagrange multipliers make the tangent a saddle point (a zero diagonal "
             "block), which this iterative method cannot precondition; use solver.petsc = \"mumps\" (LU), or "
             "bc.method = \"nitsche\" or \"penalty\"",
             name);
  const size_t size = strlen(base) + strlen(k->petsc_options) + 2;
  MICA_CALL(MICA_MALLOC(ps->options, size));
  snprintf(ps->options, size, "%s %s", base, k->petsc_options);
  PCALL(PetscOptionsPrefixPush(NULL, ps->prefix));
  PetscErrorCode code = PetscOptionsInsertString(NULL, ps->options);
  PCALL(PetscOptionsPrefixPop(NULL));
  if (code) {
    const char *text = NULL;
    PetscErrorMessage(code, &text, NULL);
    MICA_ERROR(MICA_ERR_INPUT, "%s: PETSc cannot read \"%s\" (%s)", k->petsc_where, k->petsc_options,
               text ? text : "error");
  }
  return MICA_SUCCESS;
}

static int create_ksp(PetscSolver *ps, const MicaKrylovOptions *k, int *mg_levels) {
  MICA_CALL(set_options(ps, k));
  PCALL(KSPCreate(ps->comm, &ps->ksp));
  PCALL(KSPSetOptionsPrefix(ps->ksp, ps->prefix));
  PCALL(KSPSetOperators(ps->ksp, ps->A, ps->A));
  if (find_preset(k->petsc_preset[0] ? k->petsc_preset : "mumps")->geometric)
    MICA_CALL(attach_lattice_mg(ps, k, mg_levels));
  PCALL(KSPSetTolerances(ps->ksp, k->rtol > 0 ? k->rtol : 1e-10, 0.0, PETSC_DEFAULT,
                         k->max_iterations > 0 ? k->max_iterations : 10000));
  PCALL(KSPSetFromOptions(ps->ksp));
  return MICA_SUCCESS;
}

/* An option of the prefix PETSc has not used had no effect: a misspelling, or one the method does not read. */
static int check_options_used(PetscSolver *ps, const char *where) {
  PetscInt count = 0;
  char **names = NULL, **values = NULL, unused[512] = "";
  const size_t plen = strlen(ps->prefix);
  PCALL(PetscOptionsLeftGet(NULL, &count, &names, &values));
  for (PetscInt i = 0; i < count; i++) {
    const char *name = names[i][0] == '-' ? names[i] + 1 : names[i];
    if (strncmp(name, ps->prefix, plen)) continue;
    const size_t used = strlen(unused);
    snprintf(unused + used, sizeof unused - used, "%s-%s", used ? ", " : "", name + plen);
  }
  PCALL(PetscOptionsLeftRestore(NULL, &count, &names, &values));
  MICA_CHECK(!unused[0], MICA_ERR_INPUT,
             "%s: PETSc did not use %s: misspelled, or without effect under the chosen method (solver.petsc and "
             "solver.petsc_options)", where[0] ? where : "solver.petsc_options", unused);
  return MICA_SUCCESS;
}

static int setup(MicaLinearSolver *solver, const MicaSparse *L, MicaPatternKey key) {
  PetscSolver *ps = solver->data;
  free_objects(ps);
  clear_options(ps);
  ps->solved = 0;
  ps->comm = solver->layout.comm;
  MPI_Comm_rank(ps->comm, &ps->rank);
  MPI_Comm_size(ps->comm, &ps->size);
  ps->n = L->n, ps->ndof = L->ndof, ps->nnodes = L->n / L->ndof;
  ps->symmetric = solver->krylov.spd;
  MICA_CHECK(L->ndof <= 64, MICA_ERR_ARGUMENT, "petsc: %d unknowns per node (at most 64)", L->ndof);
  MICA_CALL(number_rows(ps, &solver->layout));
  MICA_CALL(create_matrix(ps, L, &solver->krylov));
  MICA_CALL(attach_near_null(ps, &solver->krylov));
  MICA_CALL(create_ksp(ps, &solver->krylov, &solver->stats.multigrid_levels));
  ps->pattern = key;
  solver->stats.analyses++;
  return MICA_SUCCESS;
}

static int petsc_factor(MicaLinearSolver *solver, const MicaSparse *L) {
  PetscSolver *ps = solver->data;
  const MicaPatternKey key = mica_pattern_key(L);
  ps->ready = 0;
  if (!ps->A || !mica_pattern_key_equal(key, ps->pattern) || !mica_petsc_fill_takes(ps->fill, L)) {
    const double start = mica_wtime();
    int ierr = setup(solver, L, key);
    solver->stats.time_analyze += mica_wtime() - start;
    MICA_CALL(ierr);
  }
  /* gmg's first coarse operator from K itself, before the fill may rearrange K's values */
  if (ps->lattice) MICA_CALL(mica_petsc_lattice_mg_first(ps->lattice, L));
  MICA_CALL(mica_petsc_fill_values(ps->fill, L, ps->A));
  /* the caller will not read K's values again before it assembles them: their memory goes back before the
   * preconditioner's setup, where a rank's memory peaks (GAMG, P = 4, 47³ cube: 1074 → 900 MB a rank) */
  if (solver->krylov.discardable == L && !mica_petsc_fill_shares(ps->fill))
    mica_sparse_discard_values(solver->krylov.discardable);
  if (ps->size > 1) { /* the halo of a matrix–vector product, fixed by the pattern */
    PetscInt nghosts;
    const PetscInt *ghosts;
    PCALL(MatGetGhosts(ps->A, &nghosts, &ghosts));
    solver->stats.halo_dofs = (long)nghosts;
  }
  if (ps->lattice) MICA_CALL(mica_petsc_lattice_mg_operators(ps->lattice, ps->A)); /* gmg's coarse operators */
  /* the preconditioner (factorization, multigrid hierarchy) for these values, here and not in the solve: KSPSetUp
   * sets it up only once per KSPSetOperators, PCSetUp again whenever the matrix changed since */
  PCALL(KSPSetUp(ps->ksp));
  PC pc;
  PCALL(KSPGetPC(ps->ksp, &pc));
  PCALL(PCSetUp(pc));
  ps->ready = 1;
  return MICA_SUCCESS;
}

static int report_divergence(PetscSolver *ps, KSPConvergedReason reason, PetscInt its) {
  KSPType ksp_type;
  PCType pc_type;
  PC pc;
  PCALL(KSPGetType(ps->ksp, &ksp_type));
  PCALL(KSPGetPC(ps->ksp, &pc));
  PCALL(PCGetType(pc, &pc_type));
  if (reason == KSP_DIVERGED_PC_FAILED)
    MICA_ERROR(MICA_ERR_NUMERIC, "PETSc %s/%s: the preconditioner failed (a zero pivot or an indefinite matrix: "
               "the tangent is singular, or not positive definite for a Cholesky method; solver.petsc = \"mumps\" "
               "with an unsymmetric tangent uses LU)", ksp_type, pc_type);
  MICA_ERROR(MICA_ERR_NUMERIC, "PETSc %s/%s did not converge: %s after %d iterations; raise "
             "solver.linear_max_iterations, or choose another solver.petsc", ksp_type, pc_type,
             KSPConvergedReasons[reason], (int)its);
}

static int petsc_solve(MicaLinearSolver *solver, const double *b, double *x) {
  PetscSolver *ps = solver->data;
  MICA_CHECK(ps->ready, MICA_ERR_ARGUMENT, "petsc: solve before a successful factor");
  const double start = mica_wtime(), cpu = mica_cputime();
  PetscScalar *a;
  PCALL(VecGetArray(ps->b, &a));
  /* replicated b, or a local layout's owned entries (complete: summed over the ranks): no communication */
  for (PetscInt i = 0; i < ps->nlocal; i++) a[i] = b[ps->local_dofs[i]];
  PCALL(VecRestoreArray(ps->b, &a));
  PCALL(KSPSolve(ps->ksp, ps->b, ps->x));
  KSPConvergedReason reason;
  PetscInt its;
  PCALL(KSPGetConvergedReason(ps->ksp, &reason));
  PCALL(KSPGetIterationNumber(ps->ksp, &its));
  if (!ps->solved) MICA_CALL(check_options_used(ps, solver->krylov.petsc_where));
  ps->solved = 1;
  if (reason < 0) return report_divergence(ps, reason, its);
  PetscReal bnorm, rnorm; /* the true residual, once */
  PCALL(MatMult(ps->A, ps->x, ps->r));
  PCALL(VecAYPX(ps->r, -1.0, ps->b));
  PCALL(VecNorm(ps->r, NORM_2, &rnorm));
  PCALL(VecNorm(ps->b, NORM_2, &bnorm));
  PCALL(VecScatterBegin(ps->to_all, ps->x, ps->all, INSERT_VALUES, SCATTER_FORWARD));
  PCALL(VecScatterEnd(ps->to_all, ps->x, ps->all, INSERT_VALUES, SCATTER_FORWARD));
  const PetscScalar *all;
  PCALL(VecGetArrayRead(ps->all, &all));
  if (ps->local) memcpy(x, all, sizeof(double) * (size_t)ps->n);
  else
    for (long i = 0; i < ps->n; i++) x[i] = all[ps->row_of_dof[i]];
  PCALL(VecRestoreArrayRead(ps->all, &all));
  MicaLinearSolverStats *st = &solver->stats;
  st->krylov_iterations += its;
  if (its > st->krylov_iterations_max) st->krylov_iterations_max = its;
  st->krylov_residual = bnorm > 0 ? (double)(rnorm / bnorm) : 0.0;
  st->krylov_cpu += mica_cputime() - cpu;
  if (solver->krylov.verbose) {
    char levels[32] = "";
    if (st->multigrid_levels) snprintf(levels, sizeof levels, ", %d levels", st->multigrid_levels);
    printf("    petsc (%s%s): %d iterations, |b - Ax| / |b| %.3e, %.3g s\n",
           solver->krylov.petsc_preset[0] ? solver->krylov.petsc_preset : "mumps", levels, (int)its,
           st->krylov_residual, mica_wtime() - start);
  }
  return MICA_SUCCESS;
}

/* ---- settings -------------------------------------------------------------------------------------------- */

static const MicaDeckKey petsc_keys[] = {
    {.path = "petsc", .type = MICA_KEY_CHOICE, .def = "\"mumps\"", .min = 1.0, .max = 0.0,
     .choices = "mumps|gamg|gmg|hypre|asm-cholmod|asm-umfpack|bjacobi-cholmod|none",
     .help = "PETSc's method: mumps (distributed Cholesky / LU), gamg or hypre (algebraic multigrid; CG, GMRES for "
             "unsymmetric tangents), gmg (geometric multigrid on lattices over the particles, for particles that "
             "fill a box), asm-cholmod, asm-umfpack, bjacobi-cholmod (additive Schwarz or block Jacobi "
             "with CHOLMOD / UMFPACK subdomains), none (solver.petsc_options alone)"},
    {.path = "petsc_options", .type = MICA_KEY_STRING, .def = "\"\"", .min = 1.0, .max = 0.0,
     .help = "PETSc options applied over solver.petsc's, e.g. \"-pc_gamg_threshold 0.02 -ksp_monitor\"; one PETSc "
             "does not use is an error"},
    {0},
};

static int petsc_from_settings(const MicaType *type, const MicaSettings *settings, const char *group,
                               void *options) {
  (void)type;
  MicaKrylovOptions *k = options;
  const char *preset, *text;
  char where[256];
  MICA_CALL(mica_settings_string(settings, group, "petsc", &preset));
  MICA_CALL(mica_settings_string(settings, group, "petsc_options", &text));
  mica_settings_where(settings, group, "petsc_options", where, sizeof where);
  MICA_CHECK(strlen(text) < sizeof k->petsc_options, MICA_ERR_INPUT, "%s: solver.petsc_options is longer than %zu "
             "characters", where, sizeof k->petsc_options - 1);
  MICA_CHECK(!(strcmp(preset, "none") == 0 && !text[0]), MICA_ERR_INPUT,
             "%s: solver.petsc = \"none\" takes the method from solver.petsc_options alone, which is empty", where);
  snprintf(k->petsc_preset, sizeof k->petsc_preset, "%s", preset);
  snprintf(k->petsc_options, sizeof k->petsc_options, "%s", text);
  snprintf(k->petsc_where, sizeof k->petsc_where, "%s", where);
  const Preset *p = find_preset(preset);
  mica_settings_where(settings, group, "petsc", where, sizeof where);
  snprintf(k->petsc_preset_where, sizeof k->petsc_preset_where, "%s", where);
  MICA_CHECK(p && ((k->spd && p->spd) || p->general), MICA_ERR_INPUT,
             "%s: solver.petsc = \"%s\" needs a symmetric positive definite tangent (CG with Cholesky subdomains), "
             "which this problem does not give; use \"asm-umfpack\", \"gamg\" or \"mumps\"", where, preset);
  MICA_CHECK(!(p->iterative && k->saddle), MICA_ERR_INPUT,
             "%s: solver.petsc = \"%s\": the Lagrange multipliers make the tangent a saddle point (a zero diagonal "
             "block), which this iterative method cannot precondition; use solver.petsc = \"mumps\" (LU), or "
             "bc.method = \"nitsche\" or \"penalty\"", where, preset);
  return MICA_SUCCESS;
}

const MicaLinearSolverOps mica_linear_petsc = {
    {"petsc", "PETSc KSP on a distributed AIJ matrix (MUMPS, GAMG, hypre, ASM; serial or under MPI)",
     MICA_LINEAR_DISTRIBUTED, petsc_keys, petsc_from_settings},
    petsc_create, petsc_factor, petsc_solve, petsc_destroy};
