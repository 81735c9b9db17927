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

/* Eight doubles as one value (GCC vector extension): one AVX-512 register, two AVX2 or four SSE2 registers, as
 * the instance's target decides; loads and stores through memcpy, which compiles to unaligned vector moves. */
typedef double V8 __attribute__((vector_size(64)));
#define ZERO8 ((V8){0, 0, 0, 0, 0, 0, 0, 0})
#define LOAD8(v, p) memcpy(&(v), (p), sizeof(V8))
#define STORE8(p, v) memcpy((p), &(v), sizeof(V8))

/* Rows of the kernel over the union: for every (I, a, b), out[k] (+)= Σ_t G_(I a b)[t] X_t[k] for k up to I's
 * block of 8 (half) or all np columns, t over the staged points' entries. T is a constant in the specialized
 * instances (one point of a classical or Cosserat model), so the sum over t is unrolled; the eight lanes stay in
 * registers, so each entry of Ke is loaded and stored once per chunk, not once per point. */
static inline __attribute__((always_inline)) void rows(const int T, int nc, long u, long np, long stride, int flags,
                                                       const double *restrict X, const double *restrict G,
                                                       double *restrict Ke) {
  const int add = flags & MICA_KERNEL_ADD;
  for (long I = 0; I < u; I++) {
    const long k1 = flags & MICA_KERNEL_HALF ? (I + 8) / 8 * 8 : np;
    for (int a = 0; a < nc; a++)
      for (int b = 0; b < nc; b++) {
        const double *restrict g = G + ((I * nc + a) * nc + b) * stride;
        double *restrict out = Ke + (I * nc + a) * nc * np + b * np;
        long k = 0;
        for (; k + 32 <= k1; k += 32) { /* four independent sums: an FMA's latency is hidden behind the others */
          V8 acc0 = ZERO8, acc1 = ZERO8, acc2 = ZERO8, acc3 = ZERO8;
          if (add) LOAD8(acc0, out + k), LOAD8(acc1, out + k + 8), LOAD8(acc2, out + k + 16), LOAD8(acc3, out + k + 24);
          for (int t = 0; t < T; t++) {
            const double *restrict x = X + t * np + k;
            const double gs = g[t];
            const V8 gt = {gs, gs, gs, gs, gs, gs, gs, gs};
            V8 x0, x1, x2, x3;
            LOAD8(x0, x), LOAD8(x1, x + 8), LOAD8(x2, x + 16), LOAD8(x3, x + 24);
            acc0 += gt * x0, acc1 += gt * x1, acc2 += gt * x2, acc3 += gt * x3;
          }
          STORE8(out + k, acc0), STORE8(out + k + 8, acc1), STORE8(out + k + 16, acc2), STORE8(out + k + 24, acc3);
        }
        for (; k < k1; k += 8) {
          V8 acc = ZERO8;
          if (add) LOAD8(acc, out + k);
          for (int t = 0; t < T; t++) {
            V8 x;
            LOAD8(x, X + t * np + k);
            const double gs = g[t];
            acc += (V8){gs, gs, gs, gs, gs, gs, gs, gs} * x;
          }
          STORE8(out + k, acc);
        }
      }
  }
}

/* The rows compiled for one instruction set each; the default build targets x86-64 without AVX, so the vector
 * versions are chosen at run time from the CPU's features (GCC's own target_clones dispatch goes by the CPU
 * model, which a virtual machine may not report: it then picks the baseline). Each set has instances for
 * T = 2, 3, 4, 5 (one point: classical 2-D and 3-D, Cosserat, strain gradient in 2-D) and one for any T. */
typedef void RowsFn(int T, int nc, long u, long np, long stride, int flags, const double *X, const double *G,
                    double *Ke);

#define ROWS_INSTANCE(name, attributes, TT)                                                                       \
  attributes static void name(int T, int nc, long u, long np, long stride, int flags, const double *X,            \
                              const double *G, double *Ke) {                                                      \
    (void)T;                                                                                                      \
    rows(TT, nc, u, np, stride, flags, X, G, Ke);                                                                 \
  }
#define ROWS_VARIANT(name, attributes)                                                                            \
  ROWS_INSTANCE(name##_2, attributes, 2)                                                                          \
  ROWS_INSTANCE(name##_3, attributes, 3)                                                                          \
  ROWS_INSTANCE(name##_4, attributes, 4)                                                                          \
  ROWS_INSTANCE(name##_5, attributes, 5)                                                                          \
  ROWS_INSTANCE(name##_any, attributes, T)                                                                       \
  static RowsFn *const name[6] = {name##_any, name##_any, name##_2, name##_3, name##_4, name##_5};

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

void mica_kernel_chunk_add(MicaKernelChunk *ch, long n, const double *beta, const long *loc, const double *A,
                           double w) {
  stage_entries(ch, n, loc, beta);
  stage_projection(ch, n, loc, beta, A, w);
  ch->count++;
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
