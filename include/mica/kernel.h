/* The stiffness kernel of a classical (gradient-only) model at one quadrature point (src/assemble/kernel.c,
 * docs/performance.md §kernel). With n supporting particles, gradients N_I,J and the tangent A_aJbL = ∂P_aJ/∂F_bL,
 *   K_(I a)(K b) = w Σ_JL N_I,J A_aJbL N_K,L
 * is computed in two steps, never through the (dim² × n·dim) matrix B with its zeros:
 *   G_I[a][b][L] = w Σ_J N_I,J A_aJbL                        n·dim⁴ multiply-adds,
 *   K_(I a)(K b) = Σ_L G_I[a][b][L] N_K,L   for K ≤ I         n(n+1)/2 · dim³ multiply-adds (half),
 * the second as dim² contiguous loops over K (gradients stored per axis, padded with zeros to a multiple of
 * MICA_KERNEL_PAD particles), which the compiler vectorizes; built for AVX-512, AVX2 + FMA and the baseline,
 * chosen at run time. Symmetric: A has the major symmetry of a hyperelastic tangent and the test functions are
 * the trial functions, so the blocks K > I are the transposes of blocks K < I. Row (I a) over K ≤ I is column
 * (I a) of the upper triangle: mica_sparse_add_clique_upper adds it as such, with two (three) contiguous reads
 * per block, and mica_sparse_mirror_upper fills the lower triangle of the matrix once per assembly.
 *
 * Layout of Ke ("planar"): row r = I·dim + a, then for each b a row of np = mica_kernel_padded(n) entries over K:
 *   Ke[r·(dim·np) + b·np + K] = K_(I a)(K b),  valid for K ≤ I (MICA_KERNEL_HALF) or every K < n;
 * other entries of the row are scratch. */
#ifndef MICA_KERNEL_H
#define MICA_KERNEL_H

#define MICA_KERNEL_PAD 8

/* n rounded up to a multiple of MICA_KERNEL_PAD. */
static inline long mica_kernel_padded(long n) { return (n + MICA_KERNEL_PAD - 1) / MICA_KERNEL_PAD * MICA_KERNEL_PAD; }

/* Doubles of scratch the kernel needs for n particles in dim dimensions (gradients per axis and G). */
static inline long mica_kernel_work_size(int dim, long n) { return dim * mica_kernel_padded(n) + n * dim * dim * dim; }

/* Doubles of Ke for n particles in dim dimensions. */
static inline long mica_kernel_ke_size(int dim, long n) { return n * dim * dim * mica_kernel_padded(n); }

#define MICA_KERNEL_HALF 1 /* the blocks K ≤ I only */
#define MICA_KERNEL_ADD 2  /* add into Ke instead of overwriting it */

/* Ke (planar layout above) for dim = 2 or 3, n particles with gradients dN[n·dim] (entry I·dim + J, as the shape
 * cache stores them), A[(a·dim + J)·dim² + b·dim + L] (dim² × dim², row-major) and weight w; flags a combination
 * of MICA_KERNEL_HALF and MICA_KERNEL_ADD; work as sized by mica_kernel_work_size(dim, n). */
void mica_kernel_classical(int dim, long n, const double *dN, const double *A, double w, int flags, double *work,
                           double *Ke);

/* The same into a larger matrix over u ≥ n particles (a background cell's supports together): particle I of
 * this point is particle loc[I] of Ke (loc ascending), which has np = mica_kernel_padded(u) columns per row and
 * component; work as sized by mica_kernel_work_size(dim, u). With MICA_KERNEL_ADD, points sharing a cell add
 * into one matrix that is scattered once. */
void mica_kernel_classical_mapped(int dim, long n, const double *dN, const long *loc, long u, const double *A,
                                  double w, int flags, double *work, double *Ke);

/* The instruction set the kernel runs with on this CPU: "avx512", "avx2" (with FMA) or "baseline". */
const char *mica_kernel_isa(void);
/* Runs the kernel with a narrower instruction set ("baseline", "avx2", "avx512") from now on, for tests and
 * benchmarks; returns 0 (and changes nothing) if this CPU cannot run it. */
int mica_kernel_use_isa(const char *isa);

/* Useful floating-point operations of one call (a multiply-add counts 2): the two steps above, half or full. */
double mica_kernel_flops(int dim, long n, int flags);

#endif
