/* The stiffness kernel against DGEMM (issue 7, item 3; docs/performance.md §kernel).
 *
 * Part 1, one quadrature point with n supporting particles, random gradients and a random symmetric tangent:
 *   half     mica_kernel_classical with the blocks K ≤ I, one point,
 *   full     the same kernel over all blocks,
 *   chunk    the blocks K ≤ I of 8 points staged together and added into Ke once (mica_kernel_chunk_*: what the
 *            assembly runs for the points of a background cell), time per point,
 *   general  mica_solid_element_stiffness, the slot-based Bᵀ D B (axisymmetric solids, VCI),
 *   dgemm    cblas_dgemm of the same BLAS, (m × k)·(k × m) with m = n·dim, k = dim²: the dense product
 *            Bᵀ (D B) that gives the same matrix.
 * Flops are the kernel's useful ones (mica_kernel_flops: 2 n dim⁴ + 2 dim³ × blocks, a multiply-add counting 2);
 * DGEMM's are 2 m² k. "ratio" is the one-point kernel's rate over DGEMM's, "chunk ratio" the chunked kernel's.
 * Part 2, whole tangent assemblies of a 2-D and a 3-D problem (no boundary conditions), classical kernel
 * against the general one in the same process: microseconds per quadrature point, and memory per dof.
 * CPU time (CLOCK_PROCESS_CPUTIME_ID), best of 3, one BLAS thread. Never fails on time. */
#include <cblas.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mica/kernel.h"
#include "mica/bc.h"

#define CHUNK_POINTS 8 /* points per chunk in the "chunk" column, as the assembly stages them */

static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double uniform(unsigned *state) {
  *state = *state * 1103515245u + 12345u;
  return (double)((*state >> 8) & 0xffffff) / (double)0xffffff * 2.0 - 1.0;
}

typedef struct {
  int dim;
  long n;
  double *dN, *A, *D, *X, *Ke, *Kg, *G, *work, *chunk_work, *B, *DB, *C;
  MicaShapeCache cache;
  MicaSolid solid;
} Point;

/* Random gradients, A = M Mᵀ (major symmetry, positive), D with A in its gradient block. */
static void point_init(Point *pt, int dim, long n) {
  unsigned seed = 12345u + (unsigned)(n * 7 + dim);
  const int dd = dim * dim, nq = dim + dd;
  const long m = n * dim;
  memset(pt, 0, sizeof *pt);
  pt->dim = dim, pt->n = n;
  pt->dN = malloc(sizeof(double) * (size_t)(n * dim));
  pt->A = calloc((size_t)(dd * dd), sizeof(double));
  pt->D = calloc((size_t)(nq * nq), sizeof(double));
  pt->Ke = malloc(sizeof(double) * (size_t)mica_kernel_ke_size(dim, n));
  pt->work = malloc(sizeof(double) * (size_t)mica_kernel_work_size(dim, dim, n));
  pt->chunk_work = malloc(sizeof(double) * (size_t)mica_kernel_chunk_size(dim, dim, n, CHUNK_POINTS));
  pt->Kg = malloc(sizeof(double) * (size_t)(m * m));
  pt->G = malloc(sizeof(double) * (size_t)(m * nq));
  pt->B = malloc(sizeof(double) * (size_t)(m * dd));
  pt->DB = malloc(sizeof(double) * (size_t)(m * dd));
  pt->C = malloc(sizeof(double) * (size_t)(m * m));
  for (long i = 0; i < n * dim; i++) pt->dN[i] = uniform(&seed);
  double M[81];
  for (int i = 0; i < dd * dd; i++) M[i] = uniform(&seed);
  for (int r = 0; r < dd; r++)
    for (int c = 0; c < dd; c++) {
      double s = r == c ? dd : 0;
      for (int k = 0; k < dd; k++) s += M[r * dd + k] * M[c * dd + k];
      pt->A[r * dd + c] = s;
      pt->D[(dim + r) * nq + dim + c] = s;
    }
  for (long i = 0; i < m * dd; i++) pt->B[i] = uniform(&seed), pt->DB[i] = uniform(&seed);
  /* a one-point cache and a classical 2-D/3-D solid around it, for the general element stiffness */
  static long ptr[2], index[512];
  static double N[512];
  for (long k = 0; k < n; k++) index[k] = k, N[k] = 1.0 / (double)n;
  ptr[0] = 0, ptr[1] = n;
  pt->cache = (MicaShapeCache){.dim = dim, .order = 1, .npoints = 1, .ptr = ptr, .index = index, .N = N, .dN = pt->dN};
  pt->solid.dim = pt->solid.model_dim = pt->solid.ncomp = dim;
  pt->solid.nq = nq;
  pt->solid.opt.field.ops = &mica_field_classical;
}

static void point_free(Point *pt) {
  double *arrays[] = {pt->dN, pt->A, pt->D, pt->Ke, pt->work, pt->chunk_work, pt->Kg, pt->G, pt->B, pt->DB, pt->C};
  for (size_t i = 0; i < sizeof arrays / sizeof *arrays; i++) free(arrays[i]);
}

typedef enum { RUN_HALF, RUN_FULL, RUN_CHUNK, RUN_GENERAL, RUN_DGEMM } RunKind;

static void run_once(Point *pt, RunKind kind) {
  const int dim = pt->dim, dd = dim * dim;
  const long m = pt->n * dim;
  switch (kind) {
  case RUN_HALF: mica_kernel_classical(dim, pt->n, pt->dN, pt->A, 0.7, 1, pt->work, pt->Ke); break;
  case RUN_FULL: mica_kernel_classical(dim, pt->n, pt->dN, pt->A, 0.7, 0, pt->work, pt->Ke); break;
  case RUN_CHUNK: { /* CHUNK_POINTS points staged, one update of Ke: what the assembly runs per cell */
    MicaKernelChunk ch;
    mica_kernel_chunk_init(&ch, dim, dim, pt->n, CHUNK_POINTS, pt->chunk_work);
    for (int p = 0; p < CHUNK_POINTS; p++) mica_kernel_chunk_add(&ch, pt->n, pt->dN, NULL, pt->A, 0.7);
    mica_kernel_chunk_flush(&ch, MICA_KERNEL_HALF | MICA_KERNEL_ADD, pt->Ke);
    break;
  }
  case RUN_GENERAL: mica_solid_element_stiffness(&pt->solid, &pt->cache, 0, pt->D, 0.7, pt->G, pt->Kg); break;
  case RUN_DGEMM:
    cblas_dgemm(CblasRowMajor, CblasTrans, CblasNoTrans, (int)m, (int)m, dd, 1.0, pt->B, (int)m, pt->DB, (int)m, 0.0,
                pt->C, (int)m);
    break;
  }
}

/* Seconds per call: repeated for ≥ 0.05 s, best of 3. */
static double time_per_call(Point *pt, RunKind kind) {
  long reps = 1;
  for (;;) {
    const double start = cpu_now();
    for (long r = 0; r < reps; r++) run_once(pt, kind);
    if (cpu_now() - start > 0.02) break;
    reps *= 2;
  }
  double best = 1e30;
  for (int trial = 0; trial < 3; trial++) {
    const double start = cpu_now();
    for (long r = 0; r < reps; r++) run_once(pt, kind);
    best = fmin(best, (cpu_now() - start) / (double)reps);
  }
  return best;
}

/* Largest |half − general| over the blocks K ≤ I, relative to max |general|. */
static double half_vs_general(Point *pt) {
  run_once(pt, RUN_HALF);
  run_once(pt, RUN_GENERAL);
  const int dim = pt->dim;
  const long n = pt->n, np = mica_kernel_padded(n), m = n * dim;
  double diff = 0, scale = 0;
  for (long row = 0; row < n; row++)
    for (int a = 0; a < dim; a++)
      for (long col = 0; col <= row; col++)
        for (int b = 0; b < dim; b++) {
          const double g = pt->Kg[(row * dim + a) * m + col * dim + b];
          const double h = pt->Ke[(row * dim + a) * dim * np + b * np + col];
          diff = fmax(diff, fabs(g - h));
          scale = fmax(scale, fabs(g));
        }
  return diff / scale;
}

static void kernel_row(int dim, long n) {
  Point pt;
  point_init(&pt, dim, n);
  const long m = n * dim;
  const double t_half = time_per_call(&pt, RUN_HALF), t_full = time_per_call(&pt, RUN_FULL);
  const double t_chunk = time_per_call(&pt, RUN_CHUNK) / CHUNK_POINTS;
  const double t_gen = time_per_call(&pt, RUN_GENERAL), t_gemm = time_per_call(&pt, RUN_DGEMM);
  const double f_half = mica_kernel_flops(dim, dim, n, 1), f_full = mica_kernel_flops(dim, dim, n, 0);
  const double f_gemm = 2.0 * (double)m * (double)m * dim * dim;
  const double r_half = f_half / t_half * 1e-9, r_gemm = f_gemm / t_gemm * 1e-9;
  const double r_chunk = f_half / t_chunk * 1e-9;
  printf("%d-D n %3ld  half %7.2f us %6.2f GF/s  full %7.2f us %6.2f GF/s  chunk %7.2f us %6.2f GF/s  "
         "general %8.2f us  dgemm %3ldx%dx%-3ld %7.2f us %6.2f GF/s  ratio %5.2f  chunk ratio %5.2f  diff %.1e\n",
         dim, n, t_half * 1e6, r_half, t_full * 1e6, f_full / t_full * 1e-9, t_chunk * 1e6, r_chunk, t_gen * 1e6,
         m, dim * dim, m, t_gemm * 1e6, r_gemm, r_half / r_gemm, r_chunk / r_gemm, half_vs_general(&pt));
  point_free(&pt);
}

/* ---- part 2: whole assemblies ---- */

static void check(int ierr) {
  if (ierr) {
    fprintf(stderr, "bench_kernel: %s\n", mica_error_message());
    exit(1);
  }
}

static double time_assembly(MicaSolid *s, double *u, double *R, int general, int tangent) {
  s->opt.general_kernel = general;
  double best = 1e30;
  for (int trial = 0; trial < 3; trial++) {
    const double start = cpu_now();
    check(mica_solid_assemble(s, 1.0, u, R, tangent ? s->K : NULL));
    best = fmin(best, cpu_now() - start);
  }
  return best;
}

static void assembly_row(const char *label, const MicaShapeSpec *shape, const long *count, int order, double dilation,
                         int gauss) {
  const MicaLayoutSpec layout = {.kind = MICA_LAYOUT_REGULAR, .count = {count[0], count[1], count[2]},
                                 .grading = {1, 1, 1}};
  const MicaCellSpec cells = {.order = gauss};
  MicaDiscretization *disc = NULL;
  MlsApprox *mls = NULL;
  MicaSolid *s = NULL;
  MlsOptions mopt;
  check(mica_discretization_create(shape, &layout, &cells, &disc));
  mls_options_default(&mopt);
  mopt.order = order, mopt.dilation = dilation;
  check(mls_create(disc->dim, disc->nparticles, disc->x, &mopt, &mls));
  MicaSolidOptions opt;
  memset(&opt, 0, sizeof opt);
  MicaMaterial mat;
  check(mica_material_set(&mica_model_linear, 1000, 0.3, disc->dim == 2 ? MICA_PLANE_STRESS : MICA_PLANE_NONE, &mat));
  check(mica_field_classical_set(&opt.field, &mica_model_linear, &mat));
  opt.bc_method = &mica_bc_nitsche;
  const MicaApprox approx = {&mica_approx_mls, mls};
  check(mica_solid_create(disc, &approx, &opt, 0, NULL, 0, NULL, &s));
  double *u = calloc((size_t)s->ndof, sizeof *u), *R = malloc(sizeof(double) * (size_t)s->ndof);
  unsigned seed = 99;
  for (long i = 0; i < s->ndof; i++) u[i] = 1e-3 * uniform(&seed);
  const double np = (double)s->volume->npoints;
  const double t_res = time_assembly(s, u, R, 0, 0), t_fast = time_assembly(s, u, R, 0, 1);
  const double t_gen = time_assembly(s, u, R, 1, 1);
  const double cache = (double)mica_shape_cache_bytes(s->volume) / (double)s->ndof;
  const double matrix = (double)(s->K->nnz * 16 + (s->K->n + 1) * 8) / (double)s->ndof;
  printf("%-6s %6ld dofs %7ld points  support %5.1f  residual %6.2f us/pt  tangent: classical %6.2f us/pt  general "
         "%7.2f us/pt  (%.2fx)  bytes/dof: cache %6.0f  matrix %6.0f\n",
         label, s->ndof, s->volume->npoints, (double)s->volume->ptr[s->volume->npoints] / np, t_res / np * 1e6,
         t_fast / np * 1e6, t_gen / np * 1e6, t_gen / t_fast, cache, matrix);
  free(u);
  free(R);
  mica_solid_destroy(&s);
  mls_destroy(&mls);
  mica_discretization_destroy(&disc);
}

int main(void) {
  printf("stiffness kernel per quadrature point vs DGEMM (one core, CPU time, best of 3; kernel ISA: %s)\n",
         mica_kernel_isa());
  printf("flops: kernel 2 n dim^4 + 2 dim^3 x blocks (half: n(n+1)/2, full: n^2); "
         "dgemm 2 m^2 k, m = n dim, k = dim^2\n");
  const long n2[] = {20, 32, 40}, n3[] = {30, 60, 90, 120};
  for (int i = 0; i < 3; i++) kernel_row(2, n2[i]);
  for (int i = 0; i < 4; i++) kernel_row(3, n3[i]);
  printf("(ratio = kernel GF/s / dgemm GF/s; time = kernel time / dgemm time; "
         "diff = max |half - general| / max |general|)\n");
  printf("whole assemblies, linear elasticity, no boundary conditions (classical kernel + upper scatter + mirror vs "
         "general Ke + full scatter)\n");
  const MicaShapeSpec beam = {.kind = MICA_SHAPE_BOX, .dim = 2, .lower = {0, -6}, .upper = {48, 6}};
  const MicaShapeSpec block = {.kind = MICA_SHAPE_BOX, .dim = 3, .lower = {0, 0, 0}, .upper = {4, 1, 1}};
  assembly_row("2-D", &beam, (long[]){49, 13, 0}, 2, 3.0, 5);
  assembly_row("3-D", &block, (long[]){17, 5, 5}, 1, 2.0, 4);
  assembly_row("3-D", &block, (long[]){17, 5, 5}, 1, 2.5, 4);
  return 0;
}
