/* The stiffness kernel of a classical or field model at one quadrature point (mica/kernel.h).
 *
 * Why this shape: K_(I a)(K b) = Σ_j G_I[a][b][j] β_K[j] has 2·nd flops per entry, so the kernel is bound by
 * writing Ke, not by arithmetic. Each (I, a, b) is one loop over K that loads nd contiguous rows of
 * shape-function entries and stores one contiguous row: with the entries stored per slot and padded to a
 * multiple of 8 particles the loop has whole vectors only (trip counts of 8, which -O2's cheap vectorizer accepts
 * without peeling). The rows are compiled for AVX-512, AVX2 + FMA and the baseline x86-64 (GCC target
 * attributes) and chosen at the first call from the CPU's features (rows_for), since the default build targets
 * the baseline ISA only. */
#include "mica/kernel.h"

#include <string.h>

/* Multiply-adds may be fused (FMA): the result differs from separate rounding by round-off only. */
#pragma GCC optimize("fp-contract=fast")

/* Stages point t of the chunk: rows t·nd .. t·nd + nd − 1 of X hold its entries per slot in the union's columns,
 * X[(t·nd + i)·np + loc[K]] = β_K[i], zero elsewhere up to np. */
static void stage_entries(MicaKernelChunk *ch, long n, const long *loc, const double *beta) {
  const int nd = ch->nd;
  double *X = ch->X + (long)ch->count * nd * ch->np;
  memset(X, 0, sizeof(double) * (size_t)(nd * ch->np));
  for (int i = 0; i < nd; i++) {
    double *x = X + i * ch->np;
    for (long K = 0; K < n; K++) x[loc ? loc[K] : K] = beta[K * nd + i];
  }
}

/* Stages point t's projection G_I[a][b][j] = w Σ_i β_I[i] A_(a i)(b j) in the columns t·nd + j of the rows
 * ((col(I)·nc + a)·nc + b) of G, each row ch->stride long; union members outside the support get zeros. Every
 * entry is written once. A's zeros (a model's energy rarely couples every entry: Cosserat's displacement values
 * to nothing) are skipped: per output (a, b, j) the nonzero w A_(a i)(b j) are listed once per point. */
static void stage_projection(MicaKernelChunk *ch, long n, const long *loc, const double *beta, const double *A,
                             double w) {
  enum { MAX_OUT = MICA_KERNEL_MAX_WIDTH * MICA_KERNEL_MAX_WIDTH }; /* outputs nc² nd and nonzeros ≤ width² */
  const int nc = ch->nc, nd = ch->nd, width = nc * nd, nout = nc * nc * nd; /* A is width × width */
  const long stride = ch->stride, block = (long)nc * nc * stride; /* a particle's rows of G */
  double *G = ch->G + (long)ch->count * nd;
  long offset[MAX_OUT];                       /* output o = (a, b, j): its place in a particle's rows */
  int first[MAX_OUT + 1], slot[MAX_OUT]; /* its nonzeros: i, w A */
  double value[MAX_OUT];
  int o = 0, e = 0;
  for (int a = 0; a < nc; a++)
    for (int b = 0; b < nc; b++)
      for (int j = 0; j < nd; j++, o++) {
        offset[o] = (a * nc + b) * stride + j, first[o] = e;
        for (int i = 0; i < nd; i++) {
          const double entry = A[(a * nd + i) * width + b * nd + j];
          if (entry != 0.0) slot[e] = i, value[e++] = w * entry;
        }
      }
  first[nout] = e;
  long K = 0; /* loc ascending: walk the union and the support together */
  for (long r = 0; r < ch->u; r++) {
    double *out = G + r * block;
    if (K >= n || (loc ? loc[K] : K) != r) {
      for (o = 0; o < nout; o++) out[offset[o]] = 0.0;
      continue;
    }
    const double *g = beta + K * nd;
    for (o = 0; o < nout; o++) {
      double sum = 0;
      for (e = first[o]; e < first[o + 1]; e++) sum += g[slot[e]] * value[e];
      out[offset[o]] = sum;
    }
    K++;
  }
}

/* Vectors of the instruction set's width (GCC vector extension): two doubles for the baseline (SSE2), four for AVX2,
 * eight for AVX-512; loads and stores through memcpy, which compiles to unaligned vector moves. Why not eight for
 * all: GCC splits a vector wider than the target's registers into pieces and, in a loop whose trip count is not a
 * constant (the chunks' sums over t), keeps the pieces on the stack — the AVX2 rows ran at 1.1–1.8 GFLOP/s so,
 * slower than the slot-based general path (docs/performance.md §kernel). */
typedef double V2 __attribute__((vector_size(16)));
typedef double V4 __attribute__((vector_size(32)));
typedef double V8 __attribute__((vector_size(64)));

/* Rows of the kernel over the union: for every (I, a, b), out[k] (+)= Σ_t G_(I a b)[t] X_t[k] for k up to I's
 * block of 8 (half) or all np columns, t over the staged points' entries. T is a constant in the specialized
 * instances (one point of a classical or Cosserat model), so the sum over t is unrolled; the sums stay in
 * registers, so each entry of Ke is loaded and stored once per chunk, not once per point. Four independent sums
 * of VT (W doubles) per tile: with one, every multiply-add waited for the previous one (latency 4 cycles). The
 * same multiply-adds in the same order for every width: the same bits. */
#define ROWS_OF_WIDTH(VT, W)                                                                                      \
  static inline __attribute__((always_inline)) void rows_##VT(const int T, int nc, long u, long np, long stride,   \
                                                             int flags, const double *restrict X,               \
                                                             const double *restrict G, double *restrict Ke) {   \
    const int add = flags & MICA_KERNEL_ADD;                                                                      \
    for (long I = 0; I < u; I++) {                                                                                \
      const long k1 = flags & MICA_KERNEL_HALF ? (I + 8) / 8 * 8 : np;                                           \
      for (int a = 0; a < nc; a++)                                                                                \
        for (int b = 0; b < nc; b++) {                                                                            \
          const double *restrict g = G + ((I * nc + a) * nc + b) * stride;                                       \
          double *restrict out = Ke + (I * nc + a) * nc * np + b * np;                                            \
          long k = 0;                                                                                             \
          for (; k + 4 * (W) <= k1; k += 4 * (W)) {                                                               \
            VT acc0 = {0}, acc1 = {0}, acc2 = {0}, acc3 = {0};                                                    \
            if (add) {                                                                                            \
              memcpy(&acc0, out + k, sizeof(VT)), memcpy(&acc1, out + k + (W), sizeof(VT));                       \
              memcpy(&acc2, out + k + 2 * (W), sizeof(VT)), memcpy(&acc3, out + k + 3 * (W), sizeof(VT));         \
            }                                                                                                     \
            for (int t = 0; t < T; t++) {                                                                         \
              const double *restrict x = X + t * np + k;                                                          \
              const double gt = g[t];                                                                             \
              VT x0, x1, x2, x3;                                                                                  \
              memcpy(&x0, x, sizeof(VT)), memcpy(&x1, x + (W), sizeof(VT));                                       \
              memcpy(&x2, x + 2 * (W), sizeof(VT)), memcpy(&x3, x + 3 * (W), sizeof(VT));                         \
              acc0 += gt * x0, acc1 += gt * x1, acc2 += gt * x2, acc3 += gt * x3;                                 \
            }                                                                                                     \
            memcpy(out + k, &acc0, sizeof(VT)), memcpy(out + k + (W), &acc1, sizeof(VT));                         \
            memcpy(out + k + 2 * (W), &acc2, sizeof(VT)), memcpy(out + k + 3 * (W), &acc3, sizeof(VT));           \
          }                                                                                                       \
          for (; k < k1; k += (W)) { /* np and k1 are multiples of 8, so of W */                                  \
            VT acc = {0};                                                                                         \
            if (add) memcpy(&acc, out + k, sizeof(VT));                                                           \
            for (int t = 0; t < T; t++) {                                                                         \
              VT x;                                                                                               \
              memcpy(&x, X + t * np + k, sizeof(VT));                                                             \
              acc += g[t] * x;                                                                                    \
            }                                                                                                     \
            memcpy(out + k, &acc, sizeof(VT));                                                                    \
          }                                                                                                       \
        }                                                                                                         \
    }                                                                                                             \
  }
ROWS_OF_WIDTH(V2, 2)
ROWS_OF_WIDTH(V4, 4)
ROWS_OF_WIDTH(V8, 8)

/* The rows compiled for one instruction set each; the default build targets x86-64 without AVX, so the vector
 * versions are chosen at run time from the CPU's features (GCC's own target_clones dispatch goes by the CPU
 * model, which a virtual machine may not report: it then picks the baseline). Each set has instances for
 * T = 2, 3, 4, 5 (one point: classical 2-D and 3-D, Cosserat, strain gradient in 2-D) and one for any T. */
typedef void RowsFn(int T, int nc, long u, long np, long stride, int flags, const double *X, const double *G,
                    double *Ke);

#define ROWS_INSTANCE(name, attributes, VT, TT)                                                                   \
  attributes static void name(int T, int nc, long u, long np, long stride, int flags, const double *X,            \
                              const double *G, double *Ke) {                                                      \
    (void)T;                                                                                                      \
    rows_##VT(TT, nc, u, np, stride, flags, X, G, Ke);                                                            \
  }
#define ROWS_VARIANT(name, attributes, VT)                                                                        \
  ROWS_INSTANCE(name##_2, attributes, VT, 2)                                                                      \
  ROWS_INSTANCE(name##_3, attributes, VT, 3)                                                                      \
  ROWS_INSTANCE(name##_4, attributes, VT, 4)                                                                      \
  ROWS_INSTANCE(name##_5, attributes, VT, 5)                                                                      \
  ROWS_INSTANCE(name##_any, attributes, VT, T)                                                                    \
  static RowsFn *const name[6] = {name##_any, name##_any, name##_2, name##_3, name##_4, name##_5};

ROWS_VARIANT(rows_base, , V2)
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define KERNEL_DISPATCH 1
ROWS_VARIANT(rows_avx2, __attribute__((target("avx2,fma"))), V4)
ROWS_VARIANT(rows_avx512, __attribute__((target("avx512f,fma,prefer-vector-width=512"))), V8)
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

static RowsFn *rows_for(int T) {
  if (!chosen_isa) chosen_isa = rows_isa();
  const int instance = T <= 5 ? T : 0;
#ifdef KERNEL_DISPATCH
  if (!strcmp(chosen_isa, "avx512")) return rows_avx512[instance];
  if (!strcmp(chosen_isa, "avx2")) return rows_avx2[instance];
#endif
  return rows_base[instance];
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

void mica_kernel_chunk_init(MicaKernelChunk *ch, int nc, int nd, long u, int capacity, double *scratch) {
  const long np = mica_kernel_padded(u);
  const long stride = (long)capacity * nd;
  *ch = (MicaKernelChunk){nc, nd, capacity, 0, u, np, stride, scratch, scratch + u * nc * nc * stride};
}

void mica_kernel_chunk_add_pair(MicaKernelChunk *ch, long n, const double *beta_row, const double *beta_col,
                                const long *loc, const double *A, double w) {
  stage_entries(ch, n, loc, beta_col);
  stage_projection(ch, n, loc, beta_row, A, w);
  ch->count++;
}

void mica_kernel_chunk_add(MicaKernelChunk *ch, long n, const double *beta, const long *loc, const double *A,
                           double w) {
  mica_kernel_chunk_add_pair(ch, n, beta, beta, loc, A, w);
}

void mica_kernel_chunk_flush(MicaKernelChunk *ch, int flags, double *Ke) {
  if (!ch->count) return;
  const int T = ch->count * ch->nd;
  rows_for(T)(T, ch->nc, ch->u, ch->np, ch->stride, flags, ch->X, ch->G, Ke);
  ch->count = 0;
}

void mica_kernel_field_mapped(int nc, int nd, long n, const double *beta, const long *loc, long u, const double *A,
                              double w, int flags, double *work, double *Ke) {
  MicaKernelChunk ch;
  mica_kernel_chunk_init(&ch, nc, nd, u, 1, work);
  mica_kernel_chunk_add(&ch, n, beta, loc, A, w);
  mica_kernel_chunk_flush(&ch, flags, Ke);
}

void mica_kernel_classical_mapped(int dim, long n, const double *dN, const long *loc, long u, const double *A,
                                  double w, int flags, double *work, double *Ke) {
  mica_kernel_field_mapped(dim, dim, n, dN, loc, u, A, w, flags, work, Ke);
}

void mica_kernel_classical(int dim, long n, const double *dN, const double *A, double w, int flags, double *work,
                           double *Ke) {
  mica_kernel_field_mapped(dim, dim, n, dN, NULL, n, A, w, flags, work, Ke);
}

double mica_kernel_flops(int nc, int nd, long n, int flags) {
  const double c = nc, d = nd;
  const double blocks = flags & MICA_KERNEL_HALF ? 0.5 * (double)n * (double)(n + 1) : (double)n * (double)n;
  return 2.0 * (double)n * c * c * d * d + blocks * c * c * 2.0 * d;
}
