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
 * micro-deformations alike), as PETSc's MAIJ of the scalar interpolation. Coarse operators: Galerkin, PᵀAP — the
 * first lattice's made by mica from each rank's own tangent K_r (Σ_r Pᵀ K_r P, FirstProduct below), the coarser
 * ones through PETSc's MatProduct (not PCMG's own -pc_mg_galerkin, whose parallel algorithm cannot be chosen from a
 * prefix) — the symbolic phases once per matrix pattern and the numeric ones at every new tangent; the
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
#include <stdlib.h>
#include <string.h>

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

/* Lattice l: its rows (the active nodes of the level below, or the particles), its active nodes (this rank's
 * from *first on) and P. extra (the first lattice only, or NULL): more rows renumbered alike (K's nodes). */
static int make_level(MPI_Comm comm, int ndof, const Lattice *g, PetscInt npoints, const double *points,
                      const Lattice *below, const PetscInt *below_active, PetscInt **active, PetscInt *nactive,
                      PetscInt *first, PetscInt *total, Mat *P, Rows *extra) {
  Rows rows = {0};
  Vec ids = NULL;
  int ierr = rows_create(g, npoints, points, below, below_active, &rows);
  if (!ierr) ierr = activate(comm, g, &rows, &ids, active, nactive, first, total);
  if (!ierr) ierr = renumber(&rows, ids);
  if (!ierr && extra) ierr = renumber(extra, ids);
  if (!ierr) ierr = interpolation(comm, ndof, &rows, *nactive, *first, P);
  VecDestroy(&ids);
  rows_destroy(&rows);
  return ierr;
}

/* The first coarse operator made by mica (mica_petsc_lattice_mg_first): C = Σ over the ranks of Pᵀ K_r P, each
 * rank's K_r (its own points' contributions, owned and ghost nodes) times the interpolation rows of its K's nodes,
 * which it computes from their coordinates; C's rows of coarse nodes another rank owns go to it through a fill
 * (petsc_fill.c), as the tangent's do.
 *
 * Why: PETSc's parallel PᵀAP on the MAIJ interpolation converts it to AIJ and hashes every entry of its symbolic
 * phase (33³ cube, P = 2: 0.95 s a rank, against 0.44 s serially for twice the rows), and keeps the intermediate
 * products for reuse (gmg's excess memory per rank). Here: no P_oth exchange (a rank has its ghosts' coordinates),
 * no hashing (marker arrays over the rank's coarse nodes), the interlaced 3 × 3 blocks kept, nothing held but C. */
typedef struct {
  long nfine;              /* K's nodes */
  PetscInt nc;             /* the coarse nodes this rank's C has: those K's nodes interpolate from, and its own */
  PetscInt *cid;           /* [nc] their active numbers, ascending */
  PetscInt *sn;            /* [nfine · MAX_CORNERS] a K node's coarse nodes (index into cid; −1: none): K_rows.node,
                            * renumbered in place */
  const double *sw;        /* [nfine · MAX_CORNERS] their weights: K_rows.weight */
  int unusable;            /* K is not in whole node blocks on some rank: PETSc's product instead */
  MicaSparse *C;           /* the rank's part of the coarse operator (its nodes' numbering); with symmetric values
                            * its row indices are dropped once the fill is made (C's node rows below serve) */
  long *cnode_ptr;         /* [nc + 1] C's columns' node rows: column block cj lists cnode_rows[cnode_ptr[cj] ..] */
  PetscInt *cnode_rows;
  MicaPetscFill *fill;     /* C into coarse[0] */
  PetscInt *row_of_dof;    /* [nc · ndof] C's unknowns as PETSc's rows */
  double *W;               /* [nc · ndof²] a fine node's column of Pᵀ K, by coarse node */
  PetscInt *touched;       /* [nc] the coarse nodes W holds */
  long *mark, *posmap;     /* [nc] */
} FirstProduct;

struct MicaLatticeMG {
  PC pc;                 /* borrowed: the PCMG these levels are */
  MPI_Comm comm;
  int count;             /* lattices */
  int size;              /* ranks */
  int ndof, symmetric;
  Mat P[MAX_LEVELS];     /* P[l]: from lattice l + 1 to the level below (l = 0: the particles) */
  Mat coarse[MAX_LEVELS]; /* coarse[l] = P[l]ᵀ (level below) P[l]: the operator of lattice l + 1 */
  Rows K_rows;           /* the first lattice's interpolation rows of K's nodes (active numbers) */
  PetscInt first, nactive, total; /* the first lattice's active nodes: this rank's from first on, all */
  FirstProduct fp;
  int made_first;        /* coarse[0] holds this tangent's C (mica_petsc_lattice_mg_first) */
};

int mica_petsc_lattice_mg_create(PC pc, MPI_Comm comm, int dim, int ndof, PetscInt nrows_local, const double *points,
                                 long nglobal_nodes, long nnodes_K, const double *coords_K, int symmetric,
                                 const char *where, MicaLatticeMG **out) {
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
  mg->pc = pc, mg->comm = comm, mg->size = size, mg->ndof = ndof, mg->symmetric = symmetric;
  int ierr = rows_create(&lattice[0], (PetscInt)nnodes_K, coords_K, NULL, NULL, &mg->K_rows);
  while (!ierr) {
    Lattice *g = &lattice[mg->count];
    lattice_own(g, rank, size);
    const Lattice *below = mg->count ? &lattice[mg->count - 1] : NULL;
    PetscInt first = 0;
    ierr = make_level(comm, ndof, g, below ? nactive[mg->count - 1] : nrows_local / ndof, points, below,
                      below ? active[mg->count - 1] : NULL, &active[mg->count], &nactive[mg->count], &first, &total,
                      &mg->P[mg->count], below ? NULL : &mg->K_rows);
    if (ierr) break;
    if (!below) mg->first = first, mg->nactive = nactive[0], mg->total = total;
    mg->count++;
    if (!(total > COARSEST && mg->count < MAX_LEVELS && coarser_lattice(&lattice[mg->count - 1], &lattice[mg->count])))
      break;
  }
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

/* ---- the first coarse operator, from K ------------------------------------------------------------------- */

/* The rank's coarse nodes (those its K's nodes interpolate from, and its own active ones) and each K node's
 * coarse nodes as indices into them (K_rows renumbered in place: it serves nothing else). */
static int first_nodes(MicaLatticeMG *mg, FirstProduct *fp) {
  const long entries = fp->nfine * MAX_CORNERS;
  PetscInt *ids = NULL, count = 0;
  MICA_CALL(MICA_MALLOC(ids, entries + mg->nactive + 1));
  for (long e = 0; e < entries; e++)
    if (mg->K_rows.node[e] >= 0) ids[count++] = mg->K_rows.node[e];
  for (PetscInt k = 0; k < mg->nactive; k++) ids[count++] = mg->first + k;
  PetscErrorCode code = PetscSortRemoveDupsInt(&count, ids);
  if (code) free(ids);
  PCALL(code);
  fp->cid = ids, fp->nc = count;
  fp->sn = mg->K_rows.node, fp->sw = mg->K_rows.weight;
  for (long e = 0; e < entries; e++)
    if (fp->sn[e] >= 0) PetscFindInt(fp->sn[e], count, ids, &fp->sn[e]);
  return MICA_SUCCESS;
}

/* Whether K's columns list their rows in whole node blocks (ndof consecutive rows from a multiple of ndof), as
 * K's pattern from cliques of nodes does: the product walks them a node at a time. */
static int node_blocks(const MicaSparse *K, int ndof) {
  if (K->ndof != ndof || K->n % ndof) return 0;
  for (long c = 0; c < K->n; c++) {
    if ((K->colptr[c + 1] - K->colptr[c]) % ndof) return 0;
    for (long q = K->colptr[c]; q < K->colptr[c + 1]; q += ndof)
      if (K->rowind[q] % ndof || K->rowind[q + ndof - 1] != K->rowind[q] + ndof - 1) return 0;
  }
  return 1;
}

/* C's node graph: R(j), the coarse nodes of fine node j's neighbors (the columns of K's row j after P), then
 * column J of C = ∪ R(j) over the fine nodes j that interpolate from J. */
static int first_pattern(const MicaSparse *K, int ndof, FirstProduct *fp, long **cptr_out, long **cadj_out) {
  const long nfine = fp->nfine, nc = fp->nc;
  long *rptr = NULL, rcap = 0, count = 0, *tptr = NULL, *tlist = NULL, *cptr = NULL, *cadj = NULL, ccap = 0;
  PetscInt *radj = NULL; /* 4 bytes: Σ |R(j)| entries, the symbolic phase's largest array (0.1 GB serially at 47³) */
  int ierr = MICA_CALLOC(rptr, nfine + 1);
  if (!ierr) ierr = MICA_CALLOC(tptr, nc + 2);
  for (long i = 0; i < nc && !ierr; i++) fp->mark[i] = -1;
  for (long j = 0; j < nfine && !ierr; j++) {
    const long c = j * ndof;
    for (long q = K->colptr[c]; q < K->colptr[c + 1] && !ierr; q += ndof) {
      const PetscInt *S = fp->sn + K->rowind[q] / ndof * MAX_CORNERS;
      for (int e = 0; e < MAX_CORNERS && S[e] >= 0 && !ierr; e++) {
        if (fp->mark[S[e]] == j) continue;
        fp->mark[S[e]] = j;
        if (count == rcap) ierr = MICA_REALLOC(radj, rcap = rcap ? 2 * rcap : 1 << 16);
        if (!ierr) radj[count++] = S[e];
      }
    }
    rptr[j + 1] = count;
    for (int e = 0; e < MAX_CORNERS && fp->sn[j * MAX_CORNERS + e] >= 0; e++) tptr[fp->sn[j * MAX_CORNERS + e] + 2]++;
  }
  /* the transpose of the fine nodes' coarse nodes: the fine nodes of each coarse node */
  for (long ci = 0; ci < nc && !ierr; ci++) tptr[ci + 2] += tptr[ci + 1];
  if (!ierr) ierr = MICA_MALLOC(tlist, tptr[nc + 1] + 1);
  for (long j = 0; j < nfine && !ierr; j++)
    for (int e = 0; e < MAX_CORNERS && fp->sn[j * MAX_CORNERS + e] >= 0; e++) tlist[tptr[fp->sn[j * MAX_CORNERS + e] + 1]++] = j;
  if (!ierr) ierr = MICA_CALLOC(cptr, nc + 1);
  for (long i = 0; i < nc && !ierr; i++) fp->mark[i] = -1;
  count = 0;
  for (long cj = 0; cj < nc && !ierr; cj++) {
    for (long t = tptr[cj]; t < tptr[cj + 1] && !ierr; t++)
      for (long r = rptr[tlist[t]]; r < rptr[tlist[t] + 1] && !ierr; r++) {
        if (fp->mark[radj[r]] == cj) continue;
        fp->mark[radj[r]] = cj;
        if (count == ccap) ierr = MICA_REALLOC(cadj, ccap = ccap ? 2 * ccap : 1 << 16);
        if (!ierr) cadj[count++] = radj[r];
      }
    cptr[cj + 1] = count;
  }
  free(rptr), free(radj), free(tptr), free(tlist);
  if (ierr) free(cptr), free(cadj);
  else *cptr_out = cptr, *cadj_out = cadj;
  return ierr;
}

/* Once per pattern: the coarse nodes, C's pattern and the fill that makes coarse[0] of C. */
static int first_symbolic(MicaLatticeMG *mg, const MicaSparse *K) {
  FirstProduct *fp = &mg->fp;
  const int ndof = mg->ndof;
  fp->nfine = K->n / ndof;
  MICA_CALL(first_nodes(mg, fp));
  MICA_CALL(MICA_MALLOC(fp->mark, fp->nc + 1));
  MICA_CALL(MICA_MALLOC(fp->posmap, fp->nc + 1));
  MICA_CALL(MICA_MALLOC(fp->touched, fp->nc + 1));
  MICA_CALL(MICA_MALLOC(fp->W, (long)fp->nc * ndof * ndof + 1));
  MICA_CALL(MICA_MALLOC(fp->row_of_dof, (long)fp->nc * ndof + 1));
  for (PetscInt ci = 0; ci < fp->nc; ci++)
    for (int a = 0; a < ndof; a++) fp->row_of_dof[(long)ci * ndof + a] = fp->cid[ci] * ndof + a;
  long *cptr = NULL, *cadj = NULL;
  MICA_CALL(first_pattern(K, ndof, fp, &cptr, &cadj));
  int ierr = mica_sparse_create_graph(fp->nc, ndof, cptr, cadj, &fp->C);
  free(cptr), free(cadj);
  MICA_CALL(ierr);
  /* C is ours and read by nothing after its fill: lent, so that the fill rearranges it in place */
  MICA_CALL(mica_petsc_fill_create(mg->comm, fp->C, fp->row_of_dof, mg->nactive * ndof, mg->total * ndof, ndof,
                                   mg->symmetric, 1, &mg->coarse[0], &fp->fill));
  MicaSparse *C = fp->C;
  MICA_CALL(MICA_MALLOC(fp->cnode_ptr, fp->nc + 1));
  MICA_CALL(MICA_MALLOC(fp->cnode_rows, C->nnz / ndof / ndof + 1));
  fp->cnode_ptr[0] = 0;
  for (PetscInt cj = 0; cj < fp->nc; cj++) {
    const long first = C->colptr[(long)cj * ndof], nodes = (C->colptr[(long)cj * ndof + 1] - first) / ndof;
    for (long k = 0; k < nodes; k++) fp->cnode_rows[fp->cnode_ptr[cj] + k] = (PetscInt)(C->rowind[first + k * ndof] / ndof);
    fp->cnode_ptr[cj + 1] = fp->cnode_ptr[cj] + nodes;
  }
  /* the fill of symmetric values reads C's column pointers and values only: its row indices (8 bytes an entry,
   * 96 MB serially at 47³) go */
  if (mg->symmetric) free(C->rowind), C->rowind = NULL;
  KSP smoother;
  PCALL(PCMGGetSmoother(mg->pc, mg->count - 1, &smoother));
  PCALL(KSPSetOperators(smoother, mg->coarse[0], mg->coarse[0]));
  return MICA_SUCCESS;
}

/* C(I, J) += Σ over K's entries (i, j) of w_iI K_ij w_jJ, a fine node j (K's column block) at a time: its column
 * of Pᵀ K into W by coarse node, then W times each of j's weights into C's columns of j's coarse nodes. */
static void first_numeric(const MicaLatticeMG *mg, FirstProduct *fp, const MicaSparse *K) {
  const int ndof = mg->ndof, nd2 = ndof * ndof;
  MicaSparse *C = fp->C;
  mica_sparse_zero(C);
  for (long ci = 0; ci < fp->nc; ci++) fp->mark[ci] = -1;
  for (long j = 0; j < fp->nfine; j++) {
    long ntouched = 0;
    for (int a = 0; a < ndof; a++) {
      const long c = j * ndof + a;
      for (long q = K->colptr[c]; q < K->colptr[c + 1]; q += ndof) {
        const long i = K->rowind[q] / ndof;
        const PetscInt *S = fp->sn + i * MAX_CORNERS;
        const double *w = fp->sw + i * MAX_CORNERS, *v = K->val + q;
        for (int e = 0; e < MAX_CORNERS && S[e] >= 0; e++) {
          double *Wi = fp->W + (long)S[e] * nd2;
          if (fp->mark[S[e]] != j) {
            fp->mark[S[e]] = j, fp->touched[ntouched++] = S[e];
            memset(Wi, 0, sizeof(double) * (size_t)nd2);
          }
          for (int b = 0; b < ndof; b++) Wi[b * ndof + a] += w[e] * v[b];
        }
      }
    }
    const PetscInt *S = fp->sn + j * MAX_CORNERS;
    for (int e = 0; e < MAX_CORNERS && S[e] >= 0; e++) {
      const long cj = S[e];
      const double s = fp->sw[j * MAX_CORNERS + e];
      for (long k = fp->cnode_ptr[cj]; k < fp->cnode_ptr[cj + 1]; k++) fp->posmap[fp->cnode_rows[k]] = k - fp->cnode_ptr[cj];
      for (long t = 0; t < ntouched; t++) {
        const PetscInt ci = fp->touched[t];
        const double *Wi = fp->W + (long)ci * nd2;
        for (int a = 0; a < ndof; a++) {
          double *col = C->val + C->colptr[cj * ndof + a] + fp->posmap[ci] * ndof;
          for (int b = 0; b < ndof; b++) col[b] += s * Wi[b * ndof + a];
        }
      }
    }
  }
}

/* PETSc log events of the product (-log_view lists them; tests/cli/petsc.sh counts them) */
static PetscLogEvent event_symbolic = -1, event_numeric = -1;

static int register_events(void) {
  if (event_symbolic >= 0) return MICA_SUCCESS;
  PCALL(PetscLogEventRegister("MicaGalerkinSym", PC_CLASSID, &event_symbolic));
  PCALL(PetscLogEventRegister("MicaGalerkinNum", PC_CLASSID, &event_numeric));
  return MICA_SUCCESS;
}

int mica_petsc_lattice_mg_first(MicaLatticeMG *mg, const MicaSparse *K) {
  mg->made_first = 0;
  if (!mg->count || mg->fp.unusable) return MICA_SUCCESS;
  MICA_CALL(register_events());
  if (!mg->fp.C) {
    MICA_CHECK(K->n / mg->ndof == (long)mg->K_rows.npoints, MICA_ERR_ARGUMENT,
               "petsc gmg: a tangent of %ld nodes for %ld coordinates", K->n / mg->ndof, (long)mg->K_rows.npoints);
    /* collective decision: a rank whose K is not in node blocks would leave the others waiting in the fill */
    int blocks = node_blocks(K, mg->ndof);
    MPI_Allreduce(MPI_IN_PLACE, &blocks, 1, MPI_INT, MPI_MIN, mg->comm);
    mg->fp.unusable = !blocks;
    if (!blocks) return MICA_SUCCESS; /* PETSc's product then (mica_petsc_lattice_mg_operators), for this pattern */
    PCALL(PetscLogEventBegin(event_symbolic, 0, 0, 0, 0));
    const int ierr = first_symbolic(mg, K);
    PCALL(PetscLogEventEnd(event_symbolic, 0, 0, 0, 0));
    MICA_CALL(ierr);
  }
  PCALL(PetscLogEventBegin(event_numeric, 0, 0, 0, 0));
  first_numeric(mg, &mg->fp, K);
  const int ierr = mica_petsc_fill_values(mg->fp.fill, mg->fp.C, mg->coarse[0]);
  PCALL(PetscLogEventEnd(event_numeric, 0, 0, 0, 0));
  MICA_CALL(ierr);
  mg->made_first = 1;
  return MICA_SUCCESS;
}

/* -mica_gmg_check_galerkin (a diagnostic under the solver's prefix): mica's first coarse operator against PETSc's
 * PᵀAP of the same tangent; an error when they differ by more than 1e-12 relative (Frobenius). */
static int check_first(MicaLatticeMG *mg, Mat A) {
  const char *prefix = NULL;
  PetscBool check = PETSC_FALSE;
  PCALL(PCGetOptionsPrefix(mg->pc, &prefix));
  PCALL(PetscOptionsGetBool(NULL, prefix, "-mica_gmg_check_galerkin", &check, NULL));
  if (!check) return MICA_SUCCESS;
  Mat reference, difference;
  PetscReal norm, diff;
  PCALL(MatPtAP(A, mg->P[0], MAT_INITIAL_MATRIX, PETSC_DEFAULT, &reference));
  PCALL(MatDuplicate(reference, MAT_COPY_VALUES, &difference));
  PCALL(MatAXPY(difference, -1.0, mg->coarse[0], DIFFERENT_NONZERO_PATTERN));
  PCALL(MatNorm(reference, NORM_FROBENIUS, &norm));
  PCALL(MatNorm(difference, NORM_FROBENIUS, &diff));
  MatDestroy(&reference), MatDestroy(&difference);
  PetscInt rows;
  PCALL(MatGetSize(mg->coarse[0], &rows, NULL));
  int rank;
  MPI_Comm_rank(mg->comm, &rank);
  if (rank == 0)
    printf("gmg: the first coarse operator (%ld rows), mica's against PETSc's PᵀAP: relative difference %.3e\n",
           (long)rows, (double)(diff / norm));
  MICA_CHECK(diff <= 1e-12 * norm, MICA_ERR_ARGUMENT, "gmg: the first coarse operator differs from PETSc's PᵀAP by "
             "%.3e relative", (double)(diff / norm));
  return MICA_SUCCESS;
}

int mica_petsc_lattice_mg_operators(MicaLatticeMG *mg, Mat A) {
  Mat fine = A;
  for (int l = 0; l < mg->count; l++) {
    if (l == 0 && mg->made_first) { /* mica's own (mica_petsc_lattice_mg_first) */
      MICA_CALL(check_first(mg, A));
      fine = mg->coarse[0];
      continue;
    }
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
  FirstProduct *fp = &(*mg)->fp; /* after coarse[0], which is made on the fill's arrays */
  mica_petsc_fill_destroy(&fp->fill);
  mica_sparse_destroy(&fp->C);
  free(fp->cid), free(fp->row_of_dof), free(fp->W), free(fp->touched); /* sn, sw: K_rows's */
  free(fp->mark), free(fp->posmap), free(fp->cnode_ptr), free(fp->cnode_rows);
  rows_destroy(&(*mg)->K_rows);
  free(*mg);
  *mg = NULL;
}
