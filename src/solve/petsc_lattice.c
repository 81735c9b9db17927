/* solver.petsc = "gmg": geometric multigrid for particles, PETSc's PCMG with coarse spaces of our own.
 *
 * Why: on the 3-D cube, GAMG's setup (its aggregation of a matrix of ≈ 240 couplings per row and the smoothing
 * of its prolongators) costs as much as its iterations, and it needs 30–35 of them (docs/performance.md). The
 * particles of a solid fill a box-like region, and a regular lattice over them is a coarse space that multigrid
 * for elliptic problems is built for: multilinear interpolation from a lattice of twice the particle spacing
 * reproduces every linear field, so the rigid motions and the constant strains are in it without a near-null
 * space, and the interpolation is known from the coordinates alone (no aggregation). Measured on the 33³ cube
 * (docs/performance.md §Geometric multigrid): 10 CG iterations against GAMG's 35, and setup plus iterations
 * 0.44 of GAMG's.
 *
 * The levels: level 0 the particles (the matrix's rows); level 1 a lattice over the particles' bounding box with
 * spacing about twice the mean particle spacing h̄ = (box volume / particles)^(1/dim); each further lattice has
 * ceil((m − 1) / 2) + 1 nodes per axis of the m of the one below, until at most COARSEST nodes remain, whose
 * operator PCMG factors (LU; redundantly on every rank under MPI). Interpolation P_l from lattice l to the level
 * below it: the row of unknown c at a point x holds the multilinear weights of the 2^dim nodes of the lattice cell
 * around x, at the same component c (each of the ndof unknowns interpolated alone: displacements, rotations,
 * micro-deformations alike), as PETSc's MAIJ of the scalar interpolation. Coarse operators: Galerkin, PᵀAP,
 * made here through PETSc's MatProduct (not PCMG's own -pc_mg_galerkin, whose parallel algorithm cannot be chosen
 * from a prefix), the symbolic phase once per matrix pattern and the numeric one at every new tangent; the
 * interpolations are made once per matrix pattern.
 *
 * Ownership: lattice node (i, j, k) has the number i + m₀ (j + m₁ k) and rank r owns the numbers
 * [r M / P, (r + 1) M / P) of the M nodes: computed, not stored, so no rank holds an array of the lattice's size.
 *
 * Lattice nodes no point of the level below is near (in a hole, outside Cook's trapezoid) would give the coarse
 * operator zero rows: each lattice keeps its active nodes only, those with a positive weight in some row (Pᵀ1 >
 * 0, summed at the nodes' owners), renumbered consecutively rank by rank; the next lattice's rows are these. */
#include <math.h>
#include <stdio.h>

#include "petsc_private.h"

enum { COARSEST = 512, MAX_LEVELS = 16, MAX_CORNERS = 8 };

typedef struct {
  int dim;
  double lo[3], h[3];
  PetscInt m[3];
  PetscInt count;         /* nodes */
  PetscInt first, nowned; /* this rank's numbers */
} Lattice;

static void lattice_own(Lattice *g, int rank, int size) {
  g->count = 1;
  for (int d = 0; d < g->dim; d++) g->count *= g->m[d];
  g->first = (PetscInt)((long long)g->count * rank / size);
  g->nowned = (PetscInt)((long long)g->count * (rank + 1) / size) - g->first;
}

static void lattice_point(const Lattice *g, PetscInt node, double *x) {
  for (int d = 0; d < g->dim; d++) {
    x[d] = g->lo[d] + g->h[d] * (double)(node % g->m[d]);
    node /= g->m[d];
  }
}

/* The 2^dim nodes of the cell around x and their multilinear weights (x outside the box: the nearest cell,
 * clamped weights); returns how many weights are nonzero, which it lists. */
static int lattice_weights(const Lattice *g, const double *x, PetscInt *node, double *weight) {
  PetscInt base[3] = {0, 0, 0};
  double f[3] = {0, 0, 0};
  for (int d = 0; d < g->dim; d++) {
    const double t = (x[d] - g->lo[d]) / g->h[d];
    PetscInt i = (PetscInt)floor(t);
    if (i < 0) i = 0;
    if (i > g->m[d] - 2) i = g->m[d] - 2;
    f[d] = fmin(fmax(t - (double)i, 0.0), 1.0);
    base[d] = i;
  }
  int count = 0;
  for (int corner = 0; corner < 1 << g->dim; corner++) {
    double w = 1;
    PetscInt index = 0, stride = 1;
    for (int d = 0; d < g->dim; d++) {
      const int up = corner >> d & 1;
      w *= up ? f[d] : 1 - f[d];
      index += (base[d] + up) * stride;
      stride *= g->m[d];
    }
    if (w == 0) continue;
    node[count] = index, weight[count] = w, count++;
  }
  return count;
}

/* One level's interpolation rows: each row point's lattice nodes (MAX_CORNERS, unused ones −1) and weights. */
typedef struct {
  PetscInt npoints;
  PetscInt *node;
  double *weight;
} Rows;

static int rows_create(const Lattice *g, PetscInt npoints, const double *points, const Lattice *below,
                       const PetscInt *below_nodes, Rows *r) {
  r->npoints = npoints;
  MICA_CALL(MICA_MALLOC(r->node, (long)npoints * MAX_CORNERS + 1));
  MICA_CALL(MICA_MALLOC(r->weight, (long)npoints * MAX_CORNERS + 1));
  double x[3];
  for (PetscInt p = 0; p < npoints; p++) {
    if (below) lattice_point(below, below_nodes[p], x);
    PetscInt *node = r->node + (long)p * MAX_CORNERS;
    double *weight = r->weight + (long)p * MAX_CORNERS;
    const int count = lattice_weights(g, below ? x : points + (long)p * g->dim, node, weight);
    for (int e = count; e < MAX_CORNERS; e++) node[e] = -1, weight[e] = 0;
  }
  return MICA_SUCCESS;
}

static void rows_destroy(Rows *r) {
  free(r->node), free(r->weight);
  r->node = NULL, r->weight = NULL;
}

/* The lattice's active nodes, those with a positive weight in some row of any rank (Σ of the rows' weights,
 * Pᵀ1, at their owners): this rank's of them (*active, original numbers, ascending), their count and the first
 * one's number in the active numbering (*first); *ids: the active number of each of the lattice's nodes (−1:
 * none), distributed as the lattice. */
static int activate(MPI_Comm comm, const Lattice *g, const Rows *r, Vec *ids, PetscInt **active, PetscInt *nactive,
                    PetscInt *first, PetscInt *total) {
  Vec sums;
  PCALL(VecCreateMPI(comm, g->nowned, g->count, &sums));
  PCALL(VecSetOption(sums, VEC_IGNORE_NEGATIVE_INDICES, PETSC_TRUE));
  PCALL(VecSetValues(sums, r->npoints * MAX_CORNERS, r->node, r->weight, ADD_VALUES));
  PCALL(VecAssemblyBegin(sums));
  PCALL(VecAssemblyEnd(sums));
  PCALL(VecDuplicate(sums, ids));
  const PetscScalar *s;
  PetscScalar *id;
  PCALL(VecGetArrayRead(sums, &s));
  PetscInt count = 0;
  for (PetscInt i = 0; i < g->nowned; i++) count += s[i] > 0;
  int ierr = MICA_MALLOC(*active, count + 1);
  PetscInt offset = 0;
  int rank;
  MPI_Comm_rank(comm, &rank);
  MPI_Exscan(&count, &offset, 1, MPIU_INT, MPI_SUM, comm);
  if (rank == 0) offset = 0; /* MPI_Exscan leaves rank 0's result undefined */
  PCALL(VecGetArray(*ids, &id));
  for (PetscInt i = 0, k = 0; i < g->nowned && !ierr; i++) {
    id[i] = s[i] > 0 ? (PetscScalar)(offset + k) : -1.0;
    if (s[i] > 0) (*active)[k++] = g->first + i;
  }
  PCALL(VecRestoreArray(*ids, &id));
  PCALL(VecRestoreArrayRead(sums, &s));
  PCALL(VecDestroy(&sums));
  MICA_CALL(ierr);
  *nactive = count, *first = offset;
  MPI_Allreduce(&count, total, 1, MPIU_INT, MPI_SUM, comm);
  return MICA_SUCCESS;
}

/* The rows' nodes in the active numbering: the ids of the distinct nodes they name, fetched from their owners. */
static int renumber(const Rows *r, Vec ids) {
  const long entries = (long)r->npoints * MAX_CORNERS;
  PetscInt *names = NULL, count = 0;
  MICA_CALL(MICA_MALLOC(names, entries + 1));
  for (long e = 0; e < entries; e++)
    if (r->node[e] >= 0) names[count++] = r->node[e];
  PetscErrorCode code = PetscSortRemoveDupsInt(&count, names);
  IS is = NULL;
  Vec fetched = NULL;
  VecScatter scatter = NULL;
  if (!code) code = ISCreateGeneral(PETSC_COMM_SELF, count, names, PETSC_USE_POINTER, &is);
  if (!code) code = VecCreateSeq(PETSC_COMM_SELF, count, &fetched);
  if (!code) code = VecScatterCreate(ids, is, fetched, NULL, &scatter);
  if (!code) code = VecScatterBegin(scatter, ids, fetched, INSERT_VALUES, SCATTER_FORWARD);
  if (!code) code = VecScatterEnd(scatter, ids, fetched, INSERT_VALUES, SCATTER_FORWARD);
  const PetscScalar *id = NULL;
  if (!code) code = VecGetArrayRead(fetched, &id);
  for (long e = 0; e < entries && !code; e++) {
    if (r->node[e] < 0) continue;
    PetscInt at;
    PetscFindInt(r->node[e], count, names, &at);
    r->node[e] = (PetscInt)id[at]; /* ≥ 0: a node with a weight in a row is active */
  }
  if (id) VecRestoreArrayRead(fetched, &id);
  VecScatterDestroy(&scatter), VecDestroy(&fetched), ISDestroy(&is);
  free(names);
  PCALL(code);
  return MICA_SUCCESS;
}

/* P: the rows' ndof unknowns each, columns the active nodes' (this rank's: nactive from first on). The weights are
 * the same for every unknown of a node, so P is PETSc's MAIJ of the scalar interpolation (one row per point):
 * ndof times fewer entries, and Galerkin products that know the interlaced blocks. */
static int interpolation(MPI_Comm comm, int ndof, const Rows *r, PetscInt nactive, PetscInt first, Mat *P) {
  PetscInt *d_nnz = NULL, *o_nnz = NULL;
  MICA_CALL(MICA_CALLOC(d_nnz, (long)r->npoints + 1));
  int ierr = MICA_CALLOC(o_nnz, (long)r->npoints + 1);
  for (PetscInt p = 0; p < r->npoints && !ierr; p++) {
    const PetscInt *node = r->node + (long)p * MAX_CORNERS;
    PetscInt diagonal = 0, count = 0;
    for (int e = 0; e < MAX_CORNERS && node[e] >= 0; e++) count++, diagonal += node[e] >= first && node[e] < first + nactive;
    d_nnz[p] = diagonal, o_nnz[p] = count - diagonal;
  }
  Mat scalar = NULL;
  PetscErrorCode code = ierr ? 0 : MatCreateAIJ(comm, r->npoints, nactive, PETSC_DETERMINE, PETSC_DETERMINE, 0, d_nnz,
                                                0, o_nnz, &scalar);
  free(d_nnz), free(o_nnz);
  MICA_CALL(ierr);
  PCALL(code);
  PetscInt row0;
  code = MatGetOwnershipRange(scalar, &row0, NULL);
  for (PetscInt p = 0; p < r->npoints && !code; p++) {
    const PetscInt *node = r->node + (long)p * MAX_CORNERS, row = row0 + p;
    int count = 0;
    while (count < MAX_CORNERS && node[count] >= 0) count++;
    code = MatSetValues(scalar, 1, &row, count, node, r->weight + (long)p * MAX_CORNERS, INSERT_VALUES);
  }
  if (!code) code = MatAssemblyBegin(scalar, MAT_FINAL_ASSEMBLY);
  if (!code) code = MatAssemblyEnd(scalar, MAT_FINAL_ASSEMBLY);
  if (!code) code = MatCreateMAIJ(scalar, ndof, P);
  MatDestroy(&scalar); /* P holds its own reference */
  PCALL(code);
  return MICA_SUCCESS;
}

/* Level 1 from the bounding box of all ranks' points and their number. */
static int first_lattice(MPI_Comm comm, int dim, PetscInt npoints, const double *points, long nglobal,
                         const char *where, Lattice *g) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (PetscInt p = 0; p < npoints; p++)
    for (int d = 0; d < dim; d++) {
      lo[d] = fmin(lo[d], points[(long)p * dim + d]);
      hi[d] = fmax(hi[d], points[(long)p * dim + d]);
    }
  MPI_Allreduce(MPI_IN_PLACE, lo, dim, MPI_DOUBLE, MPI_MIN, comm);
  MPI_Allreduce(MPI_IN_PLACE, hi, dim, MPI_DOUBLE, MPI_MAX, comm);
  double volume = 1;
  for (int d = 0; d < dim; d++) volume *= hi[d] - lo[d];
  MICA_CHECK(volume > 0 && nglobal > 1, MICA_ERR_INPUT,
             "%s: solver.petsc = \"gmg\": the particles span no %d-D box (they lie on a plane or a line); use "
             "solver.petsc = \"gamg\"", where, dim);
  /* the particles' own volume is unknown here (a hole, a trapezoid): the box's overestimates the spacing, and a
   * coarser first lattice only makes the first coarsening a larger step */
  const double spacing = pow(volume / (double)nglobal, 1.0 / dim);
  g->dim = dim;
  for (int d = 0; d < dim; d++) {
    g->lo[d] = lo[d];
    g->m[d] = (PetscInt)floor((hi[d] - lo[d]) / (2 * spacing) + 0.5) + 1;
    if (g->m[d] < 2) g->m[d] = 2;
    g->h[d] = (hi[d] - lo[d]) / (double)(g->m[d] - 1);
  }
  return MICA_SUCCESS;
}

/* The next coarser lattice: about half the nodes per axis, over the same box; 0 when none is coarser. */
static int coarser_lattice(const Lattice *g, Lattice *c) {
  *c = *g;
  int changed = 0;
  for (int d = 0; d < g->dim; d++) {
    c->m[d] = g->m[d] / 2 + 1; /* ceil((m − 1) / 2) + 1 */
    changed |= c->m[d] != g->m[d];
    c->h[d] = g->h[d] * (double)(g->m[d] - 1) / (double)(c->m[d] - 1);
  }
  return changed;
}

/* Lattice l: its rows (the active nodes of the level below, or the particles), its active nodes and P. */
static int make_level(MPI_Comm comm, int ndof, const Lattice *g, PetscInt npoints, const double *points,
                      const Lattice *below, const PetscInt *below_active, PetscInt **active, PetscInt *nactive,
                      PetscInt *total, Mat *P) {
  Rows rows = {0};
  Vec ids = NULL;
  PetscInt first = 0;
  int ierr = rows_create(g, npoints, points, below, below_active, &rows);
  if (!ierr) ierr = activate(comm, g, &rows, &ids, active, nactive, &first, total);
  if (!ierr) ierr = renumber(&rows, ids);
  if (!ierr) ierr = interpolation(comm, ndof, &rows, *nactive, first, P);
  VecDestroy(&ids);
  rows_destroy(&rows);
  return ierr;
}

struct MicaLatticeMG {
  PC pc;                 /* borrowed: the PCMG these levels are */
  int count;             /* lattices */
  int size;              /* ranks */
  Mat P[MAX_LEVELS];     /* P[l]: from lattice l + 1 to the level below (l = 0: the particles) */
  Mat coarse[MAX_LEVELS]; /* coarse[l] = P[l]ᵀ (level below) P[l]: the operator of lattice l + 1 */
};

int mica_petsc_lattice_mg_create(PC pc, MPI_Comm comm, int dim, int ndof, PetscInt nrows_local, const double *points,
                                 long nglobal_nodes, const char *where, MicaLatticeMG **out) {
  int rank, size;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  MICA_CHECK(dim >= 1 && dim <= 3 && ndof > 0 && nrows_local % ndof == 0, MICA_ERR_ARGUMENT,
             "petsc gmg: %d-D, %d unknowns per node, %d rows", dim, ndof, (int)nrows_local);
  Lattice lattice[MAX_LEVELS];
  PetscInt *active[MAX_LEVELS] = {NULL}, nactive[MAX_LEVELS], total = 0;
  MICA_CALL(first_lattice(comm, dim, nrows_local / ndof, points, nglobal_nodes, where, &lattice[0]));
  MicaLatticeMG *mg = NULL;
  MICA_CALL(MICA_CALLOC(mg, 1));
  mg->pc = pc, mg->size = size;
  int ierr = MICA_SUCCESS;
  do {
    Lattice *g = &lattice[mg->count];
    lattice_own(g, rank, size);
    const Lattice *below = mg->count ? &lattice[mg->count - 1] : NULL;
    ierr = make_level(comm, ndof, g, below ? nactive[mg->count - 1] : nrows_local / ndof, points, below,
                      below ? active[mg->count - 1] : NULL, &active[mg->count], &nactive[mg->count], &total,
                      &mg->P[mg->count]);
    if (ierr) break;
    mg->count++;
  } while (total > COARSEST && mg->count < MAX_LEVELS &&
           coarser_lattice(&lattice[mg->count - 1], &lattice[mg->count]));
  for (int l = 0; l < MAX_LEVELS; l++) free(active[l]);
  /* PCMG's numbering: level 0 the coarsest lattice, level count the particles; the coarse operators are ours
   * (mica_petsc_lattice_mg_operators), not PCMG's Galerkin products, so that their algorithm is chosen */
  PetscErrorCode code = 0;
  if (!ierr) code = PCSetType(pc, PCMG);
  if (!ierr && !code) code = PCMGSetLevels(pc, mg->count + 1, NULL);
  if (!ierr && !code) code = PCMGSetGalerkin(pc, PC_MG_GALERKIN_NONE);
  for (int l = 0; l < mg->count && !ierr && !code; l++) code = PCMGSetInterpolation(pc, mg->count - l, mg->P[l]);
  if (!ierr && code) ierr = mica_petsc_error(code, "PCMG", __FILE__, __LINE__);
  if (ierr) {
    mica_petsc_lattice_mg_destroy(&mg);
    return ierr;
  }
  *out = mg;
  return MICA_SUCCESS;
}

int mica_petsc_lattice_mg_levels(const MicaLatticeMG *mg) { return mg ? mg->count + 1 : 0; }

int mica_petsc_lattice_mg_operators(MicaLatticeMG *mg, Mat A) {
  Mat fine = A;
  for (int l = 0; l < mg->count; l++) {
    if (!mg->coarse[l]) { /* the first tangent of this pattern: the products' symbolic phase, once */
      PCALL(MatProductCreate(fine, mg->P[l], NULL, &mg->coarse[l]));
      PCALL(MatProductSetType(mg->coarse[l], MATPRODUCT_PtAP));
      /* several ranks: PETSc's "backend" PᵀAP (local products of the rank's blocks, assembled by COO) — its
       * default parallel one took 3.3 s symbolic against 0.5 s serially on the 33³ speed-up cube at P = 2,
       * "backend" 1.0 s (docs/performance.md §Geometric multigrid) */
      PCALL(MatProductSetAlgorithm(mg->coarse[l], mg->size > 1 ? "backend" : MATPRODUCTALGORITHMDEFAULT));
      PCALL(MatProductSetFill(mg->coarse[l], PETSC_DEFAULT));
      PCALL(MatProductSetFromOptions(mg->coarse[l]));
      PCALL(MatProductSymbolic(mg->coarse[l]));
      KSP smoother;
      PCALL(PCMGGetSmoother(mg->pc, mg->count - 1 - l, &smoother));
      PCALL(KSPSetOperators(smoother, mg->coarse[l], mg->coarse[l]));
    }
    PCALL(MatProductNumeric(mg->coarse[l]));
    fine = mg->coarse[l];
  }
  return MICA_SUCCESS;
}

void mica_petsc_lattice_mg_destroy(MicaLatticeMG **mg) {
  if (!*mg) return;
  for (int l = 0; l < MAX_LEVELS; l++) MatDestroy(&(*mg)->P[l]), MatDestroy(&(*mg)->coarse[l]);
  free(*mg);
  *mg = NULL;
}
