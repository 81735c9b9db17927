/* The stiffness kernel at one quadrature point (src/assemble/kernel.c,
 * docs/performance.md §kernel). With n supporting particles, gradients N_I,J and the tangent A_aJbL = ∂P_aJ/∂F_bL,
 *   K_(I a)(K b) = w Σ_JL N_I,J A_aJbL N_K,L
 * is computed in two steps, never through the (dim² × n·dim) matrix B with its zeros:
 *   G_I[a][b][L] = w Σ_J N_I,J A_aJbL                        n·dim⁴ multiply-adds,
 *   K_(I a)(K b) = Σ_L G_I[a][b][L] N_K,L   for K ≤ I         n(n+1)/2 · dim³ multiply-adds (half),
 * the second as dim² contiguous loops over K (gradients stored per axis, padded with zeros to a multiple of
 * MICA_KERNEL_PAD particles), which the compiler vectorizes; built for AVX-512, AVX2 + FMA and the baseline,
 * chosen at run time. Symmetric: A has the major symmetry of a hyperelastic tangent and the test functions are
 * the trial functions, so the blocks K > I are the transposes of blocks K < I. Generalized continua use the same
 * two steps with their shape-function entries β in place of ∇N (mica_kernel_field_mapped below). Row (I a) over
 * K ≤ I is column (I a) of the upper triangle: mica_sparse_add_clique_upper adds it as such, with two (three)
 * contiguous reads per block, and mica_sparse_mirror_upper fills the lower triangle of the matrix once per
 * assembly.
 *
 * Layout of Ke ("planar"): row r = I·nc + a (nc unknowns per particle: dim for a classical model), then for each
 * b a row of np = mica_kernel_padded(n) entries over K:
 *   Ke[r·(nc·np) + b·np + K] = K_(I a)(K b),  valid for K ≤ I (MICA_KERNEL_HALF) or every K < n;
 * other entries of the row are scratch. */
#ifndef MICA_KERNEL_H
#define MICA_KERNEL_H

#define MICA_KERNEL_PAD 8

/* n rounded up to a multiple of MICA_KERNEL_PAD. */
static inline long mica_kernel_padded(long n) { return (n + MICA_KERNEL_PAD - 1) / MICA_KERNEL_PAD * MICA_KERNEL_PAD; }

/* Doubles of Ke for n particles with nc unknowns each. */
static inline long mica_kernel_ke_size(int nc, long n) { return n * nc * nc * mica_kernel_padded(n); }

/* Largest nc·nd (unknowns × shape-function entries of a particle): MICA_MAX_COMP (6) × (value, 3 first and 6
 * second derivatives). */
#define MICA_KERNEL_MAX_WIDTH 60

#define MICA_KERNEL_HALF 1 /* the blocks K ≤ I only */
#define MICA_KERNEL_ADD 2  /* add into Ke instead of overwriting it */

/* Ke (planar layout above) for dim = 2 or 3, n particles with gradients dN[n·dim] (entry I·dim + J, as the shape
 * cache stores them), A[(a·dim + J)·dim² + b·dim + L] (dim² × dim², row-major) and weight w; flags a combination
 * of MICA_KERNEL_HALF and MICA_KERNEL_ADD; work as sized by mica_kernel_work_size(dim, dim, n). */
void mica_kernel_classical(int dim, long n, const double *dN, const double *A, double w, int flags, double *work,
                           double *Ke);

/* The same into a larger matrix over u ≥ n particles (a background cell's supports together): particle I of
 * this point is particle loc[I] of Ke (loc ascending), which has np = mica_kernel_padded(u) columns per row and
 * component; work as sized by mica_kernel_work_size(dim, dim, u). With MICA_KERNEL_ADD, points sharing a cell
 * add into one matrix that is scattered once. */
void mica_kernel_classical_mapped(int dim, long n, const double *dN, const long *loc, long u, const double *A,
                                  double w, int flags, double *work, double *Ke);

/* The field kernel: a model whose q holds, for each of its nc unknowns c, the same nd shape-function entries
 * β_K = (N_K | N_K,J | N_K,h) in slots of c (Cosserat: value and gradient, nd = 1 + dim; strain gradient:
 * gradient and Hessian). With A[(a·nd + i)·(nc·nd) + b·nd + j] = D[slot(a, i), slot(b, j)],
 *   K_(I a)(K b) = w Σ_ij β_I[i] A_(a i)(b j) β_K[j],
 * in the same two steps and planar layout as the classical kernel (which is nc = nd = dim, β = ∇N).
 * beta[K·nd + i]; work as sized by mica_kernel_work_size(nc, nd, u). */
void mica_kernel_field_mapped(int nc, int nd, long n, const double *beta, const long *loc, long u, const double *A,
                              double w, int flags, double *work, double *Ke);

/* Chunks: the points of a background cell staged together, so that Ke (in cache, not in registers) is loaded and
 * stored once per chunk instead of once per point; the flops are the same,
 *   K_(I a)(K b) += Σ_t G_(I a b)[t] X_t[K],  t over the staged points' entries (count·nd),
 * a product with a longer inner dimension. The scratch (mica_kernel_chunk_size doubles) holds G and X over the
 * union of u particles; capacity is the points per chunk. */
typedef struct MicaKernelChunk {
  int nc, nd, capacity, count; /* unknowns and entries per particle; points per chunk, staged now */
  long u, np, stride;          /* union size, its padded width, the length of a row of G (capacity·nd) */
  double *G;                   /* [u·nc·nc rows × stride]: the projections, per point nd columns */
  double *X;                   /* [stride rows × np]: the entries per slot, per point nd rows */
} MicaKernelChunk;

static inline long mica_kernel_chunk_size(int nc, int nd, long u, int capacity) {
  return (long)capacity * nd * (mica_kernel_padded(u) + u * nc * nc);
}

/* Doubles of scratch one point needs (a chunk of one) for n particles with nd shape-function entries each and nc
 * unknowns per particle; the classical kernel has nc = nd = dim. */
static inline long mica_kernel_work_size(int nc, int nd, long n) { return mica_kernel_chunk_size(nc, nd, n, 1); }

void mica_kernel_chunk_init(MicaKernelChunk *ch, int nc, int nd, long u, int capacity, double *scratch);
/* Stages one point (n particles at union positions loc, ascending; NULL: 0..n−1), flushing first is the
 * caller's job when count == capacity. */
void mica_kernel_chunk_add(MicaKernelChunk *ch, long n, const double *beta, const long *loc, const double *A,
                           double w);
/* The same with different entries for the rows and the columns, K_(I a)(K b) = w Σ_ij β_row_I[i] A_(a i)(b j)
 * β_col_K[j] (Petrov–Galerkin: test and trial functions differ, K is unsymmetric; flush without
 * MICA_KERNEL_HALF). */
void mica_kernel_chunk_add_pair(MicaKernelChunk *ch, long n, const double *beta_row, const double *beta_col,
                                const long *loc, const double *A, double w);
/* Ke (=, or += with MICA_KERNEL_ADD) the staged points' blocks (K ≤ I with MICA_KERNEL_HALF); empties the chunk. */
void mica_kernel_chunk_flush(MicaKernelChunk *ch, int flags, double *Ke);

/* The instruction set the kernel runs with on this CPU: "avx512", "avx2" (with FMA) or "baseline". */
const char *mica_kernel_isa(void);
/* Runs the kernel with a narrower instruction set ("baseline", "avx2", "avx512") from now on, for tests and
 * benchmarks; returns 0 (and changes nothing) if this CPU cannot run it. */
int mica_kernel_use_isa(const char *isa);

/* Useful floating-point operations of one call (a multiply-add counts 2): the two steps above, half or full,
 * for nc unknowns and nd entries per particle (classical: nc = nd = dim). */
double mica_kernel_flops(int nc, int nd, long n, int flags);

#endif
