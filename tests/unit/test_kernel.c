/* The stiffness kernel (src/assemble/kernel.c, mica/kernel.h) and its scatter (src/solve/sparse.c).
 *
 * 1. On random gradients and a random tangent with the major symmetry (A = M Mᵀ + d I), 2-D and 3-D, supports
 *    of 1 to 45 particles (multiples of the padding 8 and not): the kernel's blocks equal the general slot-based
 *    Bᵀ D B (mica_solid_element_stiffness) to 1e-12 relative to max |Ke| — the half (K ≤ I, what the assembly
 *    uses), the full matrix, accumulation (MICA_KERNEL_ADD: twice the same point gives twice the matrix), and
 *    the mapped form into a larger union of particles (rows and columns land at loc[I], zero elsewhere).
 * 2. The field kernel (generalized continua: 2-D and 3-D Cosserat with values and gradients, 2-D strain gradient
 *    with gradients and Hessians), on a random symmetric D with zeros: one point equals the general Bᵀ D B to
 *    1e-12, and a chunk of three points (two flushes) over a union equals the sum of their general matrices.
 * 3. Scatter: a random symmetric clique matrix added through mica_sparse_add_clique_upper (upper blocks from
 *    the lower rows) and mica_sparse_mirror_upper equals mica_sparse_add_clique of the full matrix to 1e-14,
 *    and the mirrored matrix is exactly symmetric; a union of two cliques whose cross pairs are outside the
 *    pattern is accepted when those blocks are zero and refused (MICA_ERR_ARGUMENT) when one is not.
 * 4. Petrov–Galerkin (VCI: test gradients differ from the trial ones): classical 2-D and 3-D and Cosserat 3-D,
 *    a chunk of three points over a union through mica_kernel_chunk_add_pair (trial entries in the rows, test
 *    entries in the columns, Aᵀ) and mica_sparse_add_clique_columns equals the general unsymmetric Bᵀ D B
 *    (rows test, columns trial) scattered with mica_sparse_add_clique, to 1e-12 of max |K|. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mica/kernel.h"
#include "mica/random.h"
#include "mica/solid.h"
#include "mica/cosserat.h"
#include "mica/model.h"

static double symmetric_uniform(MicaRandom *rng) { return 2.0 * mica_random_uniform(rng) - 1.0; }

typedef struct {
  int dim, nq;
  long n;
  double *dN, *A, *D, *general, *G, *Ke, *work;
  long ptr[2], index[64];
  double N[64];
  MicaShapeCache cache;
  MicaSolid solid;
} Case;

/* Random gradients, A = M Mᵀ + dim² I, D holding A in its gradient block (values block zero). */
static void case_init(Case *c, int dim, long n, long u, uint64_t seed) {
  MicaRandom rng = mica_random_seed(seed);
  const int dd = dim * dim;
  memset(c, 0, sizeof *c);
  c->dim = dim, c->n = n, c->nq = dim + dd;
  const long m = n * dim;
  c->dN = malloc(sizeof(double) * (size_t)(n * dim));
  c->A = calloc((size_t)(dd * dd), sizeof(double));
  c->D = calloc((size_t)(c->nq * c->nq), sizeof(double));
  c->general = malloc(sizeof(double) * (size_t)(m * m));
  c->G = malloc(sizeof(double) * (size_t)(m * c->nq));
  c->Ke = calloc((size_t)mica_kernel_ke_size(dim, u), sizeof(double));
  c->work = malloc(sizeof(double) * (size_t)mica_kernel_work_size(dim, dim, u));
  assert_true(c->dN && c->A && c->D && c->general && c->G && c->Ke && c->work);
  for (long i = 0; i < n * dim; i++) c->dN[i] = symmetric_uniform(&rng);
  double M[81];
  for (int i = 0; i < dd * dd; i++) M[i] = symmetric_uniform(&rng);
  for (int r = 0; r < dd; r++)
    for (int col = 0; col < dd; col++) {
      double s = r == col ? dd : 0.0;
      for (int k = 0; k < dd; k++) s += M[r * dd + k] * M[col * dd + k];
      c->A[r * dd + col] = s;
      c->D[(dim + r) * c->nq + dim + col] = s;
    }
  for (long k = 0; k < n; k++) c->index[k] = k, c->N[k] = symmetric_uniform(&rng);
  c->ptr[0] = 0, c->ptr[1] = n;
  c->cache = (MicaShapeCache){.dim = dim, .order = 1, .npoints = 1, .ptr = c->ptr, .index = c->index, .N = c->N,
                              .dN = c->dN};
  c->solid.dim = c->solid.model_dim = c->solid.ncomp = dim;
  c->solid.nq = c->nq;
  c->solid.opt.field.ops = &mica_field_classical;
  mica_solid_element_stiffness(&c->solid, &c->cache, 0, c->D, 0.37, c->G, c->general);
}

static void case_free(Case *c) {
  free(c->dN), free(c->A), free(c->D), free(c->general), free(c->G), free(c->Ke), free(c->work);
}

/* max |factor · general − kernel| / max |general| over the blocks (I, K) with K ≤ I (half) or all, rows and
 * columns of the kernel's matrix at loc (or the identity) with np columns per component. */
static double difference(const Case *c, const long *loc, long np, int half, double factor) {
  const int dim = c->dim;
  const long n = c->n, m = n * dim;
  double diff = 0, scale = 0;
  for (long row = 0; row < n; row++)
    for (int a = 0; a < dim; a++)
      for (long col = 0; col < (half ? row + 1 : n); col++)
        for (int b = 0; b < dim; b++) {
          const double g = c->general[(row * dim + a) * m + col * dim + b];
          const long r = loc ? loc[row] : row, k = loc ? loc[col] : col;
          const double h = c->Ke[(r * dim + a) * dim * np + b * np + k];
          diff = fmax(diff, fabs(factor * g - h));
          scale = fmax(scale, fabs(g));
        }
  return diff / scale;
}

static const char *const isas[] = {"baseline", "avx2", "avx512"}; /* each variant this CPU runs */

static void test_kernel_equals_general(void **state) {
  (void)state;
  const long sizes[] = {1, 5, 8, 13, 16, 24, 31, 32, 40, 45};
  for (int v = 0; v < 3; v++) {
    if (!mica_kernel_use_isa(isas[v])) continue;
    for (int dim = 2; dim <= 3; dim++)
    for (size_t i = 0; i < sizeof sizes / sizeof *sizes; i++) {
      Case c;
      const long n = sizes[i], np = mica_kernel_padded(n);
      case_init(&c, dim, n, n, 100 + (uint64_t)(dim * 64 + n));
      mica_kernel_classical(dim, n, c.dN, c.A, 0.37, MICA_KERNEL_HALF, c.work, c.Ke);
      const double half = difference(&c, NULL, np, 1, 1.0);
      mica_kernel_classical(dim, n, c.dN, c.A, 0.37, 0, c.work, c.Ke);
      const double full = difference(&c, NULL, np, 0, 1.0);
      mica_kernel_classical(dim, n, c.dN, c.A, 0.37, MICA_KERNEL_HALF | MICA_KERNEL_ADD, c.work, c.Ke);
      const double twice = difference(&c, NULL, np, 1, 2.0);
      print_message("%d-D n %2ld: half %.1e, full %.1e, accumulated %.1e (ISA %s)\n", dim, n, half, full, twice,
                    mica_kernel_isa());
      assert_true(half <= 1e-12);
      assert_true(full <= 1e-12);
      assert_true(twice <= 1e-12);
      case_free(&c);
    }
  }
}

/* The point's n particles spread over a union of u = 2n + 3 (every other position, ascending). */
static void test_kernel_mapped(void **state) {
  (void)state;
  for (int v = 0; v < 3; v++) {
    if (!mica_kernel_use_isa(isas[v])) continue;
    for (int dim = 2; dim <= 3; dim++)
    for (long n = 3; n <= 33; n += 10) {
      const long u = 2 * n + 3, np = mica_kernel_padded(u);
      long loc[64];
      for (long k = 0; k < n; k++) loc[k] = 2 * k + 1;
      Case c;
      case_init(&c, dim, n, u, 900 + (uint64_t)n);
      mica_kernel_classical_mapped(dim, n, c.dN, loc, u, c.A, 0.37, MICA_KERNEL_HALF | MICA_KERNEL_ADD, c.work, c.Ke);
      const double diff = difference(&c, loc, np, 1, 1.0);
      double outside = 0; /* rows and columns of union members that are not the point's particles */
      for (long r = 0; r < u; r++)
        for (int a = 0; a < dim; a++)
          for (int b = 0; b < dim; b++)
            for (long k = 0; k <= r; k++)
              if (r % 2 == 0 || k % 2 == 0 || r > 2 * n || k > 2 * n)
                outside = fmax(outside, fabs(c.Ke[(r * dim + a) * dim * np + b * np + k]));
      print_message("%d-D n %2ld in a union of %ld: difference %.1e, entries outside %.1e (ISA %s)\n", dim, n, u, diff,
                    outside, mica_kernel_isa());
      assert_true(diff <= 1e-12);
      assert_true(outside == 0.0);
      case_free(&c);
    }
  }
}

/* ---- the field kernel: generalized continua ---- */

/* A field model's point: n particles with values, gradients and Hessians, a random symmetric D over q with a
 * quarter of its entries zero (the kernel skips A's zeros), and the general element matrix. */
typedef struct {
  int nc, nd, nq, dim;
  long n;
  double N[48], dN[48 * 3], ddN[48 * 6], beta[48 * 10], D[128 * 128], A[60 * 60], general[144 * 144], G[144 * 128];
  long ptr[2], index[48];
  MicaShapeCache cache;
  MicaSolid solid;
} FieldCase;

/* The slots of model.h's q layout: value c; gradient ncomp + c·dim + J; Hessian ncomp(1 + dim) + c·nh + h —
 * written here from the layout's definition, not taken from the assembly. */
static int field_slot(const FieldCase *f, int comp, int i) {
  const int values = mica_type_has(&f->solid.opt.field.ops->type, MICA_FIELD_USES_VALUES), nh = f->dim * (f->dim + 1) / 2;
  if (values && i == 0) return comp;
  i -= values;
  if (i < f->dim) return f->nc + comp * f->dim + i;
  return f->nc * (1 + f->dim) + comp * nh + (i - f->dim);
}

static void field_case_init(FieldCase *f, const MicaFieldModelOps *ops, int dim, long n, uint64_t seed) {
  MicaRandom rng = mica_random_seed(seed);
  memset(f, 0, sizeof *f);
  const int nh = dim * (dim + 1) / 2;
  f->dim = dim, f->n = n, f->nc = ops->ncomp(dim);
  f->nd = mica_type_has(&ops->type, MICA_FIELD_USES_VALUES) + dim + (ops->order >= 2 ? nh : 0);
  f->nq = f->nc * (1 + dim + (ops->order >= 2 ? nh : 0));
  for (long k = 0; k < n; k++) {
    f->index[k] = k, f->N[k] = symmetric_uniform(&rng);
    for (int J = 0; J < dim; J++) f->dN[k * dim + J] = symmetric_uniform(&rng);
    for (int h = 0; h < nh; h++) f->ddN[k * nh + h] = symmetric_uniform(&rng);
  }
  for (int i = 0; i < f->nq; i++)
    for (int j = 0; j <= i; j++)
      f->D[i * f->nq + j] = f->D[j * f->nq + i] = mica_random_uniform(&rng) < 0.25 ? 0.0 : symmetric_uniform(&rng);
  f->ptr[0] = 0, f->ptr[1] = n;
  f->cache = (MicaShapeCache){.dim = dim, .order = ops->order, .npoints = 1, .ptr = f->ptr, .index = f->index,
                              .N = f->N, .dN = f->dN, .ddN = f->ddN};
  f->solid.dim = f->solid.model_dim = dim;
  f->solid.ncomp = f->nc, f->solid.nq = f->nq;
  f->solid.opt.field.ops = ops;
  for (long k = 0; k < n; k++) /* β in the kernel's order: value, gradient, Hessian */
    for (int i = 0; i < f->nd; i++) {
      const int slot = field_slot(f, 0, i);
      f->beta[k * f->nd + i] = slot == 0 ? f->N[k] : slot < f->nc + dim ? f->dN[k * dim + slot - f->nc]
                                                                         : f->ddN[k * nh + slot - f->nc * (1 + dim)];
    }
  const int width = f->nc * f->nd;
  for (int a = 0; a < f->nc; a++)
    for (int i = 0; i < f->nd; i++)
      for (int b = 0; b < f->nc; b++)
        for (int j = 0; j < f->nd; j++)
          f->A[(a * f->nd + i) * width + b * f->nd + j] = f->D[field_slot(f, a, i) * f->nq + field_slot(f, b, j)];
  mica_solid_element_stiffness(&f->solid, &f->cache, 0, f->D, 0.37, f->G, f->general);
}

/* max |factor · general − Ke| / max |general| over the blocks K ≤ I, particle I of the case at loc[I]. */
static double field_difference(const FieldCase *f, const long *loc, long np, double factor, const double *Ke) {
  const int nc = f->nc;
  const long m = f->n * nc;
  double diff = 0, scale = 0;
  for (long row = 0; row < f->n; row++)
    for (int a = 0; a < nc; a++)
      for (long col = 0; col <= row; col++)
        for (int b = 0; b < nc; b++) {
          const double g = f->general[(row * nc + a) * m + col * nc + b];
          const double h = Ke[(loc[row] * nc + a) * nc * np + b * np + loc[col]];
          diff = fmax(diff, fabs(factor * g - h));
          scale = fmax(scale, fabs(g));
        }
  return diff / scale;
}

/* 2-D and 3-D Cosserat (values and gradients), 2-D strain gradient (gradients and Hessians): the field kernel
 * equals the general Bᵀ D B to 1e-12 for one point, and a chunk of three points (capacity 2: one flush in
 * between) over a union equals the sum of their general matrices. */
static void test_field_kernel_equals_general(void **state) {
  (void)state;
  const struct { const MicaFieldModelOps *ops; int dim; } models[] = {
      {&mica_field_cosserat, 2}, {&mica_field_cosserat, 3}, {&mica_field_strain_gradient, 2}};
  for (int v = 0; v < 3; v++) {
    if (!mica_kernel_use_isa(isas[v])) continue;
    for (size_t mi = 0; mi < sizeof models / sizeof *models; mi++) {
      const long n = 21, u = 2 * n + 3, np = mica_kernel_padded(u);
      static FieldCase f[3];
      long loc[3][48];
      for (int p = 0; p < 3; p++) {
        field_case_init(&f[p], models[mi].ops, models[mi].dim, n, 40 + (uint64_t)(10 * mi + p));
        for (long k = 0; k < n; k++) loc[p][k] = 2 * k + p % 2; /* even or odd members of the union */
      }
      const int nc = f[0].nc, nd = f[0].nd;
      double *Ke = calloc((size_t)mica_kernel_ke_size(nc, u), sizeof(double));
      double *work = malloc(sizeof(double) * (size_t)mica_kernel_chunk_size(nc, nd, u, 2));
      assert_true(Ke && work);
      mica_kernel_field_mapped(nc, nd, n, f[0].beta, loc[0], u, f[0].A, 0.37, MICA_KERNEL_HALF, work, Ke);
      const double one = field_difference(&f[0], loc[0], np, 1.0, Ke);
      /* the chunk: points 0 and 2 on the even members, 1 on the odd ones */
      memset(Ke, 0, sizeof(double) * (size_t)mica_kernel_ke_size(nc, u));
      MicaKernelChunk ch;
      mica_kernel_chunk_init(&ch, nc, nd, u, 2, work);
      for (int p = 0; p < 3; p++) {
        if (ch.count == ch.capacity) mica_kernel_chunk_flush(&ch, MICA_KERNEL_HALF | MICA_KERNEL_ADD, Ke);
        mica_kernel_chunk_add(&ch, n, f[p].beta, loc[p], f[p].A, 0.37);
      }
      mica_kernel_chunk_flush(&ch, MICA_KERNEL_HALF | MICA_KERNEL_ADD, Ke);
      for (long e = 0; e < (long)n * nc * n * nc; e++) f[0].general[e] += f[2].general[e]; /* same members */
      const double even = field_difference(&f[0], loc[0], np, 1.0, Ke), odd = field_difference(&f[1], loc[1], np, 1.0, Ke);
      print_message("%s %d-D (nc %d, nd %d): one point %.1e; chunk of 3, even members %.1e, odd %.1e (ISA %s)\n",
                    models[mi].ops->type.name, models[mi].dim, nc, nd, one, even, odd, mica_kernel_isa());
      assert_true(one <= 1e-12);
      assert_true(even <= 1e-12);
      assert_true(odd <= 1e-12);
      free(Ke), free(work);
    }
  }
}

/* ---- Petrov–Galerkin ---- */

/* Test gradients of f's particles (the trial ones perturbed, as VCI's correction does) into dN_test, their β into
 * beta_test, and f->general recomputed with them in the rows. */
static void field_case_test_functions(FieldCase *f, double *dN_test, double *beta_test, uint64_t seed) {
  MicaRandom rng = mica_random_seed(seed);
  for (long k = 0; k < f->n * f->dim; k++) dN_test[k] = f->dN[k] + 0.3 * symmetric_uniform(&rng);
  for (long k = 0; k < f->n; k++)
    for (int i = 0; i < f->nd; i++) {
      const int slot = field_slot(f, 0, i), grad = slot >= f->nc && slot < f->nc + f->dim;
      beta_test[k * f->nd + i] = grad ? dN_test[k * f->dim + slot - f->nc] : f->beta[k * f->nd + i];
    }
  f->cache.dN_test = dN_test;
  mica_solid_element_stiffness(&f->solid, &f->cache, 0, f->D, 0.37, f->G, f->general);
}

static void test_petrov_galerkin(void **state) {
  (void)state;
  const struct { const MicaFieldModelOps *ops; int dim; } models[] = {
      {&mica_field_classical, 2}, {&mica_field_classical, 3}, {&mica_field_cosserat, 3}};
  for (int v = 0; v < 3; v++) {
    if (!mica_kernel_use_isa(isas[v])) continue;
    for (size_t mi = 0; mi < sizeof models / sizeof *models; mi++) {
      enum { N = 7, U = 2 * N + 1 };
      const long n = N, u = U, np = mica_kernel_padded(u);
      static FieldCase f[3];
      static double dN_test[3][48 * 3], beta_test[3][48 * 10], At[60 * 60];
      long loc[3][N], nodes[3][N];
      const long all[U] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14};
      for (int p = 0; p < 3; p++) {
        field_case_init(&f[p], models[mi].ops, models[mi].dim, n, 70 + (uint64_t)(10 * mi + p));
        field_case_test_functions(&f[p], dN_test[p], beta_test[p], 90 + (uint64_t)(10 * mi + p));
        for (long k = 0; k < n; k++) loc[p][k] = nodes[p][k] = 2 * k + p % 2; /* even or odd members */
      }
      const int nc = f[0].nc, nd = f[0].nd, width = nc * nd;
      const long cliques_ptr[] = {0, N, 2 * N}, cliques[] = {0, 2, 4, 6, 8, 10, 12, 1, 3, 5, 7, 9, 11, 13};
      MicaSparse *general = NULL, *kernel = NULL;
      assert_int_equal(mica_sparse_create(u, nc, 2, cliques_ptr, cliques, &general), MICA_SUCCESS);
      assert_int_equal(mica_sparse_create(u, nc, 2, cliques_ptr, cliques, &kernel), MICA_SUCCESS);
      double *Kc = calloc((size_t)mica_kernel_ke_size(nc, u), sizeof(double));
      double *work = malloc(sizeof(double) * (size_t)mica_kernel_chunk_size(nc, nd, u, 2));
      assert_true(Kc && work);
      MicaKernelChunk ch;
      mica_kernel_chunk_init(&ch, nc, nd, u, 2, work);
      int flags = 0;
      for (int p = 0; p < 3; p++) {
        for (int r = 0; r < width; r++)
          for (int c = 0; c < width; c++) At[r * width + c] = f[p].A[c * width + r];
        if (ch.count == ch.capacity) mica_kernel_chunk_flush(&ch, flags, Kc), flags = MICA_KERNEL_ADD;
        mica_kernel_chunk_add_pair(&ch, n, f[p].beta, beta_test[p], loc[p], At, 0.37);
        assert_int_equal(mica_sparse_add_clique(general, n, nodes[p], f[p].general), MICA_SUCCESS);
      }
      mica_kernel_chunk_flush(&ch, flags, Kc);
      assert_int_equal(mica_sparse_add_clique_columns(kernel, u, all, Kc, np), MICA_SUCCESS);
      double diff = 0, scale = 0;
      for (long e = 0; e < general->nnz; e++)
        diff = fmax(diff, fabs(general->val[e] - kernel->val[e])), scale = fmax(scale, fabs(general->val[e]));
      print_message("Petrov-Galerkin %s %d-D: chunk of 3 against the general matrices %.1e, asymmetry %.2f (ISA %s)\n",
                    models[mi].ops->type.name, models[mi].dim, diff / scale, mica_sparse_asymmetry(general),
                    mica_kernel_isa());
      assert_true(diff <= 1e-12 * scale);
      assert_true(mica_sparse_asymmetry(general) > 1e-2); /* the case is unsymmetric */
      free(Kc), free(work);
      mica_sparse_destroy(&general), mica_sparse_destroy(&kernel);
    }
  }
}

/* ---- the scatter ---- */

/* Nodes 0..nnodes-1 with ndof = dim, two cliques {0..5} and {4..9}: nodes 0 and 9 are not coupled. */
static MicaSparse *two_cliques(int dim) {
  const long ptr[] = {0, 6, 12}, nodes[] = {0, 1, 2, 3, 4, 5, 4, 5, 6, 7, 8, 9};
  MicaSparse *A = NULL;
  assert_int_equal(mica_sparse_create(10, dim, 2, ptr, nodes, &A), MICA_SUCCESS);
  return A;
}

static void test_scatter_upper_mirror(void **state) {
  (void)state;
  for (int dim = 2; dim <= 3; dim++) {
    MicaRandom rng = mica_random_seed(7 + (uint64_t)dim);
    const long n = 6, m = n * dim, np = mica_kernel_padded(n);
    const long clique[2][6] = {{0, 1, 2, 3, 4, 5}, {4, 5, 6, 7, 8, 9}};
    MicaSparse *full = two_cliques(dim), *half = two_cliques(dim);
    double *K = malloc(sizeof(double) * (size_t)(m * m)), *P = calloc((size_t)(m * dim * np), sizeof(double));
    assert_true(K && P);
    for (int q = 0; q < 2; q++) {
      for (long i = 0; i < m; i++) /* random symmetric */
        for (long j = 0; j <= i; j++) K[i * m + j] = K[j * m + i] = symmetric_uniform(&rng);
      for (long r = 0; r < n; r++) /* its lower blocks in the planar layout */
        for (int a = 0; a < dim; a++)
          for (int b = 0; b < dim; b++)
            for (long k = 0; k <= r; k++) P[(r * dim + a) * dim * np + b * np + k] = K[(r * dim + a) * m + k * dim + b];
      assert_int_equal(mica_sparse_add_clique(full, n, clique[q], K), MICA_SUCCESS);
      assert_int_equal(mica_sparse_add_clique_upper(half, n, clique[q], P, np), MICA_SUCCESS);
    }
    mica_sparse_mirror_upper(half);
    double diff = 0;
    for (long p = 0; p < full->nnz; p++) diff = fmax(diff, fabs(full->val[p] - half->val[p]));
    print_message("%d-D scatter: upper + mirror against full, max difference %.1e, asymmetry %.1e\n", dim, diff,
                  mica_sparse_asymmetry(half));
    assert_true(diff <= 1e-14);
    assert_true(mica_sparse_asymmetry(half) == 0.0);

    /* the union {0..9} of both cliques: pairs (0..3, 6..9) are outside the pattern */
    const long all[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    const long nu = 10, npu = mica_kernel_padded(nu);
    double *U = calloc((size_t)(nu * dim * dim * npu), sizeof(double));
    assert_non_null(U);
    U[(5 * dim) * dim * npu + 2] = 1.0; /* pair (2, 5): coupled */
    assert_int_equal(mica_sparse_add_clique_upper(half, nu, all, U, npu), MICA_SUCCESS);
    U[(8 * dim) * dim * npu + 1] = 1.0; /* pair (1, 8): not coupled, nonzero */
    assert_int_equal(mica_sparse_add_clique_upper(half, nu, all, U, npu), MICA_ERR_ARGUMENT);
    mica_error_clear();
    free(U);
    free(K);
    free(P);
    mica_sparse_destroy(&full);
    mica_sparse_destroy(&half);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_kernel_equals_general),
      cmocka_unit_test(test_kernel_mapped),
      cmocka_unit_test(test_field_kernel_equals_general),
      cmocka_unit_test(test_scatter_upper_mirror),
      cmocka_unit_test(test_petrov_galerkin),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
