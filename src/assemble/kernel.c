/* The stiffness kernel of a classical model at one quadrature point (mica/kernel.h).
 *
 * Why this shape: K_(I a)(K b) = Σ_L G_I[a][b][L] N_K,L has 2·dim flops per entry, so the kernel is bound by
 * writing Ke, not by arithmetic. Each (I, a, b) is one loop over K that loads dim contiguous gradient rows
 * and stores one contiguous row: with the gradients stored per axis and padded to a multiple of 8 particles
 * the loop has whole vectors only (trip counts of 8, which -O2's cheap vectorizer accepts without peeling).
 * The functions are compiled for AVX-512, AVX2 + FMA and the baseline x86-64, chosen when the program
 * loads (GCC target_clones), since the default build targets the baseline ISA only. */
#include "mica/kernel.h"

#include <string.h>

/* Multiply-adds may be fused (FMA): the result differs from separate rounding by round-off only. */
#pragma GCC optimize("fp-contract=fast")

/* Gradients per axis in the rows' column order, zero elsewhere up to np: X[L*np + col(K)] = N_K,L with
 * col(K) = loc[K] (or K without a map). */
static void gradients_per_axis(int dim, long n, const long *loc, long np, const double *dN, double *X) {
  memset(X, 0, sizeof(double) * (size_t)(dim * np));
  for (int L = 0; L < dim; L++) {
    double *x = X + L * np;
    for (long K = 0; K < n; K++) x[loc ? loc[K] : K] = dN[K * dim + L];
  }
}

/* G_I[a][b][L] = w Σ_J N_I,J A_aJbL, stored G[((I·dim + a)·dim + b)·dim + L]. */
static void project_tangent(int dim, long n, const double *dN, const double *A, double w, double *G) {
  const int dd = dim * dim;
  for (long I = 0; I < n; I++) {
    const double *g = dN + I * dim;
    double *out = G + I * dim * dd;
    for (int a = 0; a < dim; a++)
      for (int bL = 0; bL < dd; bL++) {
        double sum = 0;
        for (int J = 0; J < dim; J++) sum += g[J] * A[(a * dim + J) * dd + bL];
        out[a * dd + bL] = w * sum;
      }
  }
}

/* Rows of the kernel: for every (I, a, b), row r = col(I): out[k] (+)= Σ_L g_L X_L[k] for k up to r's block of
 * 8 (half) or all np columns. DIM is a constant in each instance, so the sum over L is unrolled. */
static inline __attribute__((always_inline)) void rows(const int DIM, long n, const long *loc, long np, int flags,
                                                       const double *restrict X, const double *restrict G,
                                                       double *restrict Ke) {
  const double *restrict x0 = X, *restrict x1 = X + np, *restrict x2 = X + (DIM == 3 ? 2 * np : np);
  const int add = flags & MICA_KERNEL_ADD;
  for (long I = 0; I < n; I++) {
    const long r = loc ? loc[I] : I, k1 = flags & MICA_KERNEL_HALF ? (r + 8) / 8 * 8 : np;
    for (int a = 0; a < DIM; a++)
      for (int b = 0; b < DIM; b++) {
        const double *g = G + ((I * DIM + a) * DIM + b) * DIM;
        const double g0 = g[0], g1 = g[1], g2 = DIM == 3 ? g[2] : 0.0;
        double *restrict out = Ke + (r * DIM + a) * DIM * np + b * np;
        if (add)
          for (long k = 0; k < k1; k += 8)
            for (int v = 0; v < 8; v++)
              out[k + v] += g0 * x0[k + v] + g1 * x1[k + v] + (DIM == 3 ? g2 * x2[k + v] : 0.0);
        else
          for (long k = 0; k < k1; k += 8)
            for (int v = 0; v < 8; v++)
              out[k + v] = g0 * x0[k + v] + g1 * x1[k + v] + (DIM == 3 ? g2 * x2[k + v] : 0.0);
      }
  }
}

/* The rows compiled for one instruction set each; the default build targets x86-64 without AVX, so the vector
 * versions are chosen at run time from the CPU's features (GCC's own target_clones dispatch goes by the CPU
 * model, which a virtual machine may not report: it then picks the baseline). */
typedef void RowsFn(long n, const long *loc, long np, int flags, const double *X, const double *G, double *Ke);

#define ROWS_VARIANT(name, attributes)                                                                            \
  attributes static void name##_2d(long n, const long *loc, long np, int flags, const double *X, const double *G, \
                                   double *Ke) {                                                                  \
    rows(2, n, loc, np, flags, X, G, Ke);                                                                         \
  }                                                                                                               \
  attributes static void name##_3d(long n, const long *loc, long np, int flags, const double *X, const double *G, \
                                   double *Ke) {                                                                  \
    rows(3, n, loc, np, flags, X, G, Ke);                                                                         \
  }

ROWS_VARIANT(rows_base, )
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define KERNEL_DISPATCH 1
ROWS_VARIANT(rows_avx2, __attribute__((target("avx2,fma"))))
ROWS_VARIANT(rows_avx512, __attribute__((target("avx512f,fma,prefer-vector-width=512"))))
#endif

/* The widest variant this CPU runs: "avx512", "avx2" or "baseline". */
static const char *rows_isa(void) {
#ifdef KERNEL_DISPATCH
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return "avx512";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "avx2";
#endif
  return "baseline";
}

static const char *chosen_isa; /* NULL until the first call: then rows_isa(), or what mica_kernel_use_isa set */

static RowsFn *rows_for(int dim) {
  if (!chosen_isa) chosen_isa = rows_isa();
#ifdef KERNEL_DISPATCH
  if (!strcmp(chosen_isa, "avx512")) return dim == 3 ? rows_avx512_3d : rows_avx512_2d;
  if (!strcmp(chosen_isa, "avx2")) return dim == 3 ? rows_avx2_3d : rows_avx2_2d;
#endif
  return dim == 3 ? rows_base_3d : rows_base_2d;
}

const char *mica_kernel_isa(void) {
  if (!chosen_isa) chosen_isa = rows_isa();
  return chosen_isa;
}

int mica_kernel_use_isa(const char *isa) {
  static const char *const order[] = {"baseline", "avx2", "avx512"}; /* each runs where the next does */
  const char *best = rows_isa();
  int wanted = -1, available = 0;
  for (int i = 0; i < 3; i++) {
    if (!strcmp(isa, order[i])) wanted = i;
    if (!strcmp(best, order[i])) available = i;
  }
  if (wanted < 0 || wanted > available) return 0;
  chosen_isa = order[wanted];
  return 1;
}

void mica_kernel_classical_mapped(int dim, long n, const double *dN, const long *loc, long u, const double *A,
                                  double w, int flags, double *work, double *Ke) {
  const long np = mica_kernel_padded(u);
  double *X = work, *G = work + dim * np;
  gradients_per_axis(dim, n, loc, np, dN, X);
  project_tangent(dim, n, dN, A, w, G);
  rows_for(dim)(n, loc, np, flags, X, G, Ke);
}

void mica_kernel_classical(int dim, long n, const double *dN, const double *A, double w, int flags, double *work,
                           double *Ke) {
  mica_kernel_classical_mapped(dim, n, dN, NULL, n, A, w, flags, work, Ke);
}

double mica_kernel_flops(int dim, long n, int flags) {
  const double d = dim, blocks = flags & MICA_KERNEL_HALF ? 0.5 * (double)n * (double)(n + 1) : (double)n * (double)n;
  return 2.0 * (double)n * d * d * d * d + blocks * d * d * 2.0 * d;
}
