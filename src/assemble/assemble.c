/* Residual and tangent of the solid (docs/theory.md §solids), total Lagrangian, for any field model:
 *   q = [values | gradients | Hessians] of the ncomp unknowns at a quadrature point (mica/model.h),
 *   R_kc = Σ_q w Σ_j s_j B_j(k,c) − (body forces, tractions) + (boundary-method terms),
 *   K_(kc)(ld) = Σ_q w Σ_ij B_i(k,c) D_ij B_j(l,d) + (boundary-method terms),
 * where B_j(k,c) is N_k, N_k,J or N_k,h in the slots of component c and zero elsewhere, and s, D come from
 * the model's point kernel. For a classical model only the gradient slots are used and this is
 * R_Ia = ∫ P_aJ N_I,J, K = ∫ N_I,J A_aJbL N_K,L. Local blocks are scattered straight into the fixed pattern. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mica/cosserat.h"
#include "mica/kernel.h"
#include "mica/parallel.h"
#include "mica/solid.h"

/* Slots of q (model.h layout): value of c at c; ∂_J of c at ncomp + c*dim + J; ∂_h of c after the gradients.
 * dim is the model's dimension, gdim the geometry's: they differ only for axisymmetric solids (3 and 2). */
typedef struct {
  int ncomp, dim, gdim, nh, order, values, axisymmetric;
} Layout;

static Layout layout_of(const MicaSolid *s) {
  const int dim = s->model_dim;
  Layout L = {s->ncomp, dim, s->dim, dim * (dim + 1) / 2, s->opt.field.ops->order,
              mica_type_has(&s->opt.field.ops->type, MICA_FIELD_USES_VALUES), s->opt.axisymmetric};
  return L;
}

static inline int grad_slot(const Layout *L, int comp, int J) { return L->ncomp + comp * L->dim + J; }

/* Axisymmetric B entries of component comp (docs/theory.md §axisymmetric): the unknowns come in vectors of
 * three cylindrical components (r, θ, z) that depend on (r, z) only; in the local basis (e_r, e_θ, e_z) the
 * 3-D gradient of such a vector v is
 *   ∂v_a/∂r, ∂v_a/∂z in columns r and z, and in column θ: (∇v)_rθ = −v_θ/r, (∇v)_θθ = v_r/r, (∇v)_zθ = 0. */
static int b_entries_axisymmetric(const Layout *L, const MicaShapeCache *c, const double *dN_all, long e, double r,
                                  int comp, int *slot, double *value) {
  const int local = comp % 3, first = comp - local; /* r, θ or z within its vector */
  const double N = c->N[e], *dN = dN_all + e * 2;
  /* On the axis (output at particles with r = 0; never a quadrature point) v_r and v_θ vanish for a regular
   * field and v/r tends to ∂v/∂r. */
  const double N_over_r = r > 0 ? N / r : dN[0];
  int n = 0;
  if (L->values) slot[n] = comp, value[n++] = N;
  slot[n] = grad_slot(L, comp, 0), value[n++] = dN[0];
  slot[n] = grad_slot(L, comp, 2), value[n++] = dN[1];
  if (local == 0) slot[n] = grad_slot(L, first + 1, 1), value[n++] = N_over_r;  /* (∇v)_θθ = v_r/r */
  if (local == 1) slot[n] = grad_slot(L, first + 0, 1), value[n++] = -N_over_r; /* (∇v)_rθ = −v_θ/r */
  return n;
}

/* The nonzero B entries of particle entry e (at point p) for component c, with gradients dN (the trial
 * functions' c->dN, or the test functions', which VCI corrects): their slots in q and their values. */
static int b_entries(const Layout *L, const MicaShapeCache *c, const double *dN, long p, long e, int comp, int *slot,
                     double *value) {
  if (L->axisymmetric) return b_entries_axisymmetric(L, c, dN, e, c->x[p * 2], comp, slot, value);
  int n = 0;
  if (L->values) slot[n] = comp, value[n++] = c->N[e];
  for (int J = 0; J < L->dim; J++) slot[n] = grad_slot(L, comp, J), value[n++] = dN[e * L->dim + J];
  if (L->order >= 2)
    for (int h = 0; h < L->nh; h++)
      slot[n] = L->ncomp * (1 + L->dim) + comp * L->nh + h, value[n++] = c->ddN[e * L->nh + h];
  return n;
}

/* q = Σ_e B_e u_e of a plane or 3-D layout (values, gradients, nh Hessian entries), q zeroed before. */
static inline __attribute__((always_inline)) void kinematics_direct(const MicaShapeCache *c, long p, const double *u,
                                                                    double *q, int ncomp, int dim, int nh) {
  double *grad = q + ncomp, *hess = grad + ncomp * dim;
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
    const double *ue = u + c->index[e] * ncomp, *dN = c->dN + e * dim;
    for (int k = 0; k < ncomp; k++) {
      q[k] += c->N[e] * ue[k];
      for (int J = 0; J < dim; J++) grad[k * dim + J] += ue[k] * dN[J];
      for (int h = 0; h < nh; h++) hess[k * nh + h] += ue[k] * c->ddN[e * nh + h];
    }
  }
}

void mica_solid_kinematics(const MicaSolid *s, const MicaShapeCache *c, long p, const double *u, double *q) {
  const Layout L = layout_of(s);
  memset(q, 0, sizeof(double) * (size_t)s->nq);
  if (L.axisymmetric) { /* q = Σ B u through the entries, which carry the hoop terms; values always */
    Layout with_values = L;
    with_values.values = 1;
    int slot[16];
    double b[16];
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
      for (int k = 0; k < L.ncomp; k++) {
        const int n = b_entries(&with_values, c, c->dN, p, e, k, slot, b);
        for (int i = 0; i < n; i++) q[slot[i]] += b[i] * u[c->index[e] * L.ncomp + k];
      }
    return;
  }
  /* the classical models' counts as constants (their residual passes run this at every point), else generic */
  const int nh = L.order >= 2 ? L.nh : 0;
  if (L.ncomp == 2 && L.dim == 2 && !nh)
    kinematics_direct(c, p, u, q, 2, 2, 0);
  else if (L.ncomp == 3 && L.dim == 3 && !nh)
    kinematics_direct(c, p, u, q, 3, 3, 0);
  else
    kinematics_direct(c, p, u, q, L.ncomp, L.dim, nh);
}

void mica_solid_deformation_gradient(const MicaSolid *s, const MicaShapeCache *c, long p, const double *u, double *F) {
  const int dim = s->dim, ncomp = s->ncomp;
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = a == J ? 1.0 : 0.0;
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
    const double *ue = u + c->index[e] * ncomp, *dN = c->dN + e * dim;
    for (int a = 0; a < dim; a++)
      for (int J = 0; J < dim; J++) F[a * dim + J] += ue[a] * dN[J];
  }
}

/* Gradients of the test functions: VCI's corrected ones when the cache has them (Petrov–Galerkin), else the
 * MLS gradients, which the trial functions always use (they keep the reproducing property). */
static const double *test_gradients(const MicaShapeCache *c) { return c->dN_test ? c->dN_test : c->dN; }

/* R_kc += w Σ_j s_j B_j(k,c) for a plane or 3-D layout, reading the cache directly instead of through b_entries'
 * slot lists (a third of a nonlinear assembly went there; docs/performance.md §leaner supports): the products in
 * b_entries' order (value, gradient, Hessian), so the same sums. Inlined with the layout's counts as constants
 * for the classical models (the residual passes of Newton), generic otherwise. */
static inline __attribute__((always_inline)) void internal_force_direct(const MicaShapeCache *c, const double *dN,
                                                                        long p, const double *sq, double w, double *R,
                                                                        int ncomp, int dim, int values, int nh) {
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
    const double *de = dN + e * dim;
    double *Re = R + c->index[e] * ncomp;
    for (int comp = 0; comp < ncomp; comp++) {
      const double *sg = sq + ncomp + comp * dim;
      double f = 0;
      if (values) f += sq[comp] * c->N[e];
      for (int J = 0; J < dim; J++) f += sg[J] * de[J];
      if (nh) {
        const double *sh = sq + ncomp * (1 + dim) + comp * nh, *he = c->ddN + e * nh;
        for (int h = 0; h < nh; h++) f += sh[h] * he[h];
      }
      Re[comp] += w * f;
    }
  }
}

static void add_internal_force(const Layout *L, const MicaShapeCache *c, long p, const double *sq, double w, double *R) {
  if (!L->axisymmetric) {
    const double *dN = test_gradients(c);
    const int nh = L->order >= 2 ? L->nh : 0;
    if (L->ncomp == 2 && L->dim == 2 && !L->values && !nh)
      internal_force_direct(c, dN, p, sq, w, R, 2, 2, 0, 0);
    else if (L->ncomp == 3 && L->dim == 3 && !L->values && !nh)
      internal_force_direct(c, dN, p, sq, w, R, 3, 3, 0, 0);
    else
      internal_force_direct(c, dN, p, sq, w, R, L->ncomp, L->dim, L->values, nh);
    return;
  }
  int slot[16];
  double b[16];
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
    for (int comp = 0; comp < L->ncomp; comp++) {
      const int n = b_entries(L, c, test_gradients(c), p, e, comp, slot, b);
      double f = 0;
      for (int i = 0; i < n; i++) f += sq[slot[i]] * b[i];
      R[c->index[e] * L->ncomp + comp] += w * f;
    }
}

/* Ke[(k c),(l d)] = w Σ_ij B_i(k,c) D_ij B_j(l,d) through G_(k c)[j] = Σ_i B_i(k,c) D_ij; rows are test
 * functions, columns trial functions. lower = 1: only the blocks of row particle k ≥ column particle l (a
 * symmetric Ke's other half is their transpose). */
static void element_stiffness(const Layout *L, const MicaShapeCache *c, long p, int nq, const double *D, double w,
                              int lower, double *G, double *Ke) {
  int slot[16];
  double b[16];
  const long first = c->ptr[p], n = c->ptr[p + 1] - first, m = n * L->ncomp;
  for (long k = 0; k < n; k++)
    for (int comp = 0; comp < L->ncomp; comp++) {
      const int nb = b_entries(L, c, test_gradients(c), p, first + k, comp, slot, b);
      double *g = G + (k * L->ncomp + comp) * nq;
      for (int j = 0; j < nq; j++) {
        double sum = 0;
        for (int i = 0; i < nb; i++) sum += b[i] * D[slot[i] * nq + j];
        g[j] = sum;
      }
    }
  for (long l = 0; l < n; l++)
    for (int d = 0; d < L->ncomp; d++) {
      const int nb = b_entries(L, c, c->dN, p, first + l, d, slot, b);
      for (long row = lower ? l * L->ncomp : 0; row < m; row++) {
        const double *g = G + row * nq;
        double sum = 0;
        for (int j = 0; j < nb; j++) sum += g[slot[j]] * b[j];
        Ke[row * m + l * L->ncomp + d] = w * sum;
      }
    }
}

void mica_solid_element_stiffness(const MicaSolid *s, const MicaShapeCache *c, long p, const double *D, double w,
                                  double *G, double *Ke) {
  const Layout L = layout_of(s);
  element_stiffness(&L, c, p, s->nq, D, w, 0, G, Ke);
}

/* Load scaling: with ramping, every load and prescribed value grows with the load factor t. */
static double load_scale(const MicaSolid *s, double t) { return s->opt.ramp ? t : 1.0; }

/* A load expression (f, maybe NULL) at x and t, times scale; one that is not finite there is a deck error that
 * names it (mica_function_eval_finite), here rather than later as a non-finite residual that names nothing. */
static int load_value(const MicaFunction *f, const char *on, int dim, const double x[3], double t, double scale,
                      double *value) {
  *value = 0.0;
  if (!f) return MICA_SUCCESS;
  MICA_CALL(mica_function_eval_finite(f, on, dim, x, t, value));
  *value *= scale;
  return MICA_SUCCESS;
}

/* Body loads, conjugate to each unknown (forces on displacements, couples on micro-rotations). */
static int add_body_force(const MicaSolid *s, long p, double t, double scale, double *R) {
  const MicaShapeCache *c = s->volume;
  const int dim = s->dim, ncomp = s->ncomp;
  double x[3] = {0, 0, 0}, b[MICA_MAX_COMP];
  memcpy(x, s->disc->qx + p * dim, sizeof(double) * (size_t)dim);
  for (int a = 0; a < ncomp; a++) MICA_CALL(load_value(s->opt.body[a], "in the whole body", dim, x, t, scale, &b[a]));
  const double w = s->disc->qw[p];
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
    for (int a = 0; a < ncomp; a++) R[c->index[e] * ncomp + a] -= w * c->N[e] * b[a];
  return MICA_SUCCESS;
}

/* NSNI's expansion of the body load at stabilization point p (docs/theory.md §NSNI): R_J −= w (g·∇N_J)(g·∇b)(x_I),
 * the load's derivative along g by a central difference over 10⁻³ of the cell's length ℓ = (w/|Ω_I|)^½ (exact for
 * the linear loads of the patch tests up to round-off). Without it the value terms of a Cosserat model, whose
 * balance N_J (s_φ − c) = 0 holds pointwise, would not cancel at these points. */
static int add_body_derivative(const MicaSolid *s, long p, double t, double scale, double *R) {
  const MicaNsni *n = s->nsni;
  const MicaShapeCache *c = n->cache;
  const int dim = s->dim, ncomp = s->ncomp;
  const double *g = n->dir + p * dim, step = 1e-3 * sqrt(n->w[p] / s->disc->qw[p / dim]);
  double xp[3] = {0, 0, 0}, xm[3] = {0, 0, 0}, db[MICA_MAX_COMP];
  for (int d = 0; d < dim; d++) xp[d] = c->x[p * dim + d] + step * g[d], xm[d] = c->x[p * dim + d] - step * g[d];
  for (int a = 0; a < ncomp; a++) {
    double bp, bm;
    MICA_CALL(load_value(s->opt.body[a], "in the whole body", dim, xp, t, scale, &bp));
    MICA_CALL(load_value(s->opt.body[a], "in the whole body", dim, xm, t, scale, &bm));
    db[a] = (bp - bm) / (2 * step);
  }
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
    for (int a = 0; a < ncomp; a++) R[c->index[e] * ncomp + a] -= n->w[p] * c->N[e] * db[a];
  return MICA_SUCCESS;
}

/* What every volume point contributes before its stiffness: the model at q(u), the internal force and body load
 * into R, and (with_tangent) D into s->work. The points: the volume cache with the quadrature weights and the
 * solid's model, or NSNI's stabilization points with their weights and energy (no body load). */
typedef struct {
  const Layout *L;
  double t, scale;
  int has_body;
  const MicaShapeCache *c;
  const double *w;
  const MicaFieldModel *model;
} VolumeTerms;

static int point_residual(MicaSolid *s, const VolumeTerms *v, long p, const double *u, double *R, int with_tangent) {
  const MicaShapeCache *c = v->c;
  double q[128], sq[128], W;
  mica_solid_kinematics(s, c, p, u, q);
  const int ierr = v->model->ops->eval(v->model, v->L->dim, q, &W, sq, with_tangent ? s->work : NULL);
  if (ierr) {
    mica_error_prefix(c == s->volume ? "volume quadrature point %ld" : "NSNI stabilization point %ld", p + 1);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  add_internal_force(v->L, c, p, sq, v->w[p], R);
  if (v->has_body && c == s->volume) MICA_CALL(add_body_force(s, p, v->t, v->scale, R));
  if (v->has_body && c != s->volume) MICA_CALL(add_body_derivative(s, p, v->t, v->scale, R));
  return MICA_SUCCESS;
}

/* ---- the general path: one full element matrix per point (VCI: Petrov–Galerkin, unsymmetric) ---- */

static int assemble_points_general(MicaSolid *s, const VolumeTerms *v, const double *u, double *R, MicaSparse *K) {
  const MicaShapeCache *c = v->c;
  const int nq = s->nq;
  for (long p = 0; p < c->npoints; p++) {
    MICA_CALL(point_residual(s, v, p, u, R, K != NULL));
    if (!K) continue;
    const long n = c->ptr[p + 1] - c->ptr[p], m = n * v->L->ncomp;
    double *D = s->work, *Ke = D + nq * nq, *G = Ke + m * m;
    element_stiffness(v->L, c, p, nq, D, v->w[p], 0, G, Ke);
    MICA_CALL(mica_sparse_add_clique(K, n, c->index + c->ptr[p], Ke));
  }
  return MICA_SUCCESS;
}

/* ---- the kernel path: symmetric half, points of a background cell together ---- */

/* The kernel (mica/kernel.h) serves plane and 3-D models. Where the test functions are the trial functions K is
 * symmetric and only its upper blocks are computed and scattered; VCI's corrected test gradients (Petrov–Galerkin)
 * make it unsymmetric, and the kernel computes every block (petrov_galerkin). Axisymmetric hoop terms (entries
 * that differ per component) take the slot-based element_stiffness. */
static int kernel_applies(const MicaSolid *s) { return !s->opt.axisymmetric && !s->opt.general_kernel; }

static int petrov_galerkin(const MicaShapeCache *c) { return c->dN_test != NULL; }

_Static_assert(MICA_MAX_COMP * 10 <= MICA_KERNEL_MAX_WIDTH, "the kernel's A holds (unknowns × entries)²");

static int shape_entries(const Layout *L) { return L->values + L->dim + (L->order >= 2 ? L->nh : 0); }

int mica_solid_shape_entries(const MicaSolid *s) {
  const Layout L = layout_of(s);
  return shape_entries(&L);
}

/* slot[c·nd + i]: the slot in q of shape-function entry i of unknown c (value, gradient, Hessian; b_entries'
 * order). */
static void entry_slots(const Layout *L, int *slot) {
  const int nd = shape_entries(L);
  for (int comp = 0; comp < L->ncomp; comp++) {
    int *out = slot + comp * nd, i = 0;
    if (L->values) out[i++] = comp;
    for (int J = 0; J < L->dim; J++) out[i++] = grad_slot(L, comp, J);
    if (L->order >= 2)
      for (int h = 0; h < L->nh; h++) out[i++] = L->ncomp * (1 + L->dim) + comp * L->nh + h;
  }
}

/* The kernel's A_(a i)(b j) = D[slot(a, i), slot(b, j)], (nc·nd) × (nc·nd) row-major; transposed: its transpose,
 * for the Petrov–Galerkin blocks computed with the trial functions in the rows (assemble_cell). */
static void kernel_tangent(int width, const int *slot, const double *D, int nq, int transposed, double *A) {
  for (int r = 0; r < width; r++)
    for (int col = 0; col < width; col++)
      A[r * width + col] = transposed ? D[slot[col] * nq + slot[r]] : D[slot[r] * nq + slot[col]];
}

/* β of point p's particles, beta[K·nd + i] (b_entries' order) with gradients dN (the trial functions' c->dN or
 * VCI's test gradients): the gradients themselves when they are all of it (classical models), else gathered into
 * scratch. */
static const double *point_entries(const Layout *L, const MicaShapeCache *c, const double *dN, long p,
                                   double *scratch) {
  const long first = c->ptr[p], n = c->ptr[p + 1] - first;
  if (!L->values && L->order < 2) return dN + first * L->dim;
  const int nd = shape_entries(L);
  for (long K = 0; K < n; K++) {
    double *out = scratch + K * nd;
    int i = 0;
    if (L->values) out[i++] = c->N[first + K];
    for (int J = 0; J < L->dim; J++) out[i++] = dN[(first + K) * L->dim + J];
    if (L->order >= 2)
      for (int h = 0; h < L->nh; h++) out[i++] = c->ddN[(first + K) * L->nh + h];
  }
  return scratch;
}

/* Consecutive points first, first + 1, ... whose supports together hold at most 1/8 more particles than the
 * first one's (and at most cell_cap): the Gauss points of a background cell are stored together, and on a
 * regular grid with a whole-number dilation their supports coincide. The union goes to cell_nodes, ascending,
 * and each member's position to cell_slot. Returns the point after the group. Why: the group's matrix is
 * scattered once instead of once per point (25 or 64 times), and the scatter is what costs; the bound keeps
 * each point's share of the group matrix (rows over the union) close to its own support
 * (docs/performance.md §kernel). */
static long cell_group(MicaSolid *s, const MicaShapeCache *c, long first, long *nunion_out) {
  const long n_first = c->ptr[first + 1] - c->ptr[first];
  const long bound = n_first + n_first / 8 < s->cell_cap ? n_first + n_first / 8 : s->cell_cap;
  long nunion = 0, p = first;
  for (; p < c->npoints; p++) {
    long extra = 0;
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) extra += s->cell_slot[c->index[e]] < 0;
    if (p > first && nunion + extra > bound) break;
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
      if (s->cell_slot[c->index[e]] < 0) s->cell_slot[c->index[e]] = 0, s->cell_nodes[nunion++] = c->index[e];
  }
  for (long i = 1; i < nunion; i++) { /* insertion sort: the union is short and mostly ascending already */
    const long node = s->cell_nodes[i];
    long j = i;
    for (; j > 0 && s->cell_nodes[j - 1] > node; j--) s->cell_nodes[j] = s->cell_nodes[j - 1];
    s->cell_nodes[j] = node;
  }
  for (long i = 0; i < nunion; i++) s->cell_slot[s->cell_nodes[i]] = i;
  *nunion_out = nunion;
  return p;
}

/* The symmetric half needs a symmetric D: every model's D is the Hessian of its energy W(q), symmetric up to
 * round-off; a D that is not would make the mirrored matrix wrong, so it is an error, not a silent answer. */
static int check_symmetric(const double *D, int nq, long p) {
  double largest = 0, asymmetry = 0;
  for (int i = 0; i < nq; i++)
    for (int j = 0; j < nq; j++) {
      largest = fmax(largest, fabs(D[i * nq + j]));
      asymmetry = fmax(asymmetry, fabs(D[i * nq + j] - D[j * nq + i]));
    }
  MICA_CHECK(asymmetry <= 1e-10 * largest, MICA_ERR_NUMERIC,
             "volume quadrature point %ld: the model's tangent D is not symmetric (%.2e relative), which the "
             "symmetric assembly requires", p + 1, largest > 0 ? asymmetry / largest : 0.0);
  return MICA_SUCCESS;
}

/* A group of points through the kernel into one planar matrix, scattered once. nunion: the particles of the
 * union of the group's supports (s->cell_nodes[0..nunion), cell_group), the rows and columns of that matrix,
 * which every point of the group adds into at its particles' positions in the union; u: the unknowns.
 * Symmetric: the lower blocks, scattered as the upper ones. Petrov–Galerkin (VCI): every block of the transpose,
 * trial functions in the rows, test functions in the columns and Aᵀ, so that a row of the planar matrix is a
 * column of K (mica_sparse_add_clique_columns' contiguous runs). */
static int assemble_cell(MicaSolid *s, const VolumeTerms *v, long first, long last, long nunion, const double *u,
                         double *R, MicaSparse *K) {
  const MicaShapeCache *c = v->c;
  const int nc = s->ncomp, nd = shape_entries(v->L), width = nc * nd, pg = petrov_galerkin(c);
  double *Kc = s->cell_matrix, *staging = Kc + mica_kernel_ke_size(nc, nunion);
  double *A = staging + mica_kernel_chunk_size(nc, nd, nunion, s->chunk_points), *beta = A + width * width;
  double *beta_test = beta + s->cell_cap * nd;
  const int classical = mica_type_has(&v->model->ops->type, MICA_FIELD_CLASSICAL);
  int slot[MICA_MAX_COMP * 10];
  long *loc = s->work_nodes;
  MicaKernelChunk chunk;
  mica_kernel_chunk_init(&chunk, nc, nd, nunion, s->chunk_points, staging);
  entry_slots(v->L, slot);
  int flags = pg ? 0 : MICA_KERNEL_HALF; /* the first flush writes Kc, the later ones add: no clearing of Kc */
  for (long p = first; p < last; p++) {
    MICA_CALL(point_residual(s, v, p, u, R, 1));
    /* the half needs a symmetric A; a classical one is by construction */
    if (!classical && !pg) MICA_CALL(check_symmetric(s->work, s->nq, p));
    const long n = c->ptr[p + 1] - c->ptr[p];
    for (long k = 0; k < n; k++) loc[k] = s->cell_slot[c->index[c->ptr[p] + k]];
    kernel_tangent(width, slot, s->work, s->nq, pg, A);
    if (chunk.count == chunk.capacity) {
      mica_kernel_chunk_flush(&chunk, flags, Kc);
      flags |= MICA_KERNEL_ADD;
    }
    const double *trial = point_entries(v->L, c, c->dN, p, beta);
    if (pg)
      mica_kernel_chunk_add_pair(&chunk, n, trial, point_entries(v->L, c, c->dN_test, p, beta_test), loc, A, v->w[p]);
    else
      mica_kernel_chunk_add(&chunk, n, trial, loc, A, v->w[p]);
  }
  mica_kernel_chunk_flush(&chunk, flags, Kc);
  const long np = mica_kernel_padded(nunion);
  return pg ? mica_sparse_add_clique_columns(K, nunion, s->cell_nodes, Kc, np)
            : mica_sparse_add_clique_upper(K, nunion, s->cell_nodes, Kc, np);
}

/* Lower blocks (K ≤ I) of a row-major Ke over the point's n particles into the group's planar matrix at loc. */
static void add_lower_blocks(int nc, long n, const long *loc, long npu, const double *Ke, double *Kc) {
  const long m = n * nc;
  for (long I = 0; I < n; I++)
    for (int a = 0; a < nc; a++) {
      const double *krow = Ke + (I * nc + a) * m;
      double *crow = Kc + (loc[I] * nc + a) * nc * npu;
      for (long K = 0; K <= I; K++)
        for (int b = 0; b < nc; b++) crow[b * npu + loc[K]] += krow[K * nc + b];
    }
}

/* A group of points through the general element stiffness, lower half, into one matrix scattered once:
 * axisymmetric solids (test = trial functions), whose hoop entries differ per component. */
static int assemble_cell_general(MicaSolid *s, const VolumeTerms *v, long first, long last, long nunion, const double *u,
                                 double *R, MicaSparse *K) {
  const MicaShapeCache *c = v->c;
  const int nc = s->ncomp, nq = s->nq;
  const long npu = mica_kernel_padded(nunion);
  double *Kc = s->cell_matrix;
  long *loc = s->work_nodes;
  memset(Kc, 0, sizeof(double) * (size_t)mica_kernel_ke_size(nc, nunion));
  for (long p = first; p < last; p++) {
    MICA_CALL(point_residual(s, v, p, u, R, 1));
    MICA_CALL(check_symmetric(s->work, nq, p));
    const long n = c->ptr[p + 1] - c->ptr[p], m = n * nc;
    double *D = s->work, *Ke = D + nq * nq, *G = Ke + m * m;
    element_stiffness(v->L, c, p, nq, D, v->w[p], 1, G, Ke);
    for (long k = 0; k < n; k++) loc[k] = s->cell_slot[c->index[c->ptr[p] + k]];
    add_lower_blocks(nc, n, loc, npu, Ke, Kc);
  }
  return mica_sparse_add_clique_upper(K, nunion, s->cell_nodes, Kc, npu);
}

static int assemble_points_grouped(MicaSolid *s, const VolumeTerms *v, int kernel, const double *u, double *R,
                                   MicaSparse *K) {
  const MicaShapeCache *c = v->c;
  for (long first = 0, last, nunion; first < c->npoints; first = last) {
    last = cell_group(s, c, first, &nunion);
    const int ierr = kernel ? assemble_cell(s, v, first, last, nunion, u, R, K)
                               : assemble_cell_general(s, v, first, last, nunion, u, R, K);
    for (long i = 0; i < nunion; i++) s->cell_slot[s->cell_nodes[i]] = -1;
    MICA_CALL(ierr);
  }
  /* before the boundary terms, which add full (and for some methods unsymmetric) blocks */
  if (!petrov_galerkin(c)) mica_sparse_mirror_upper(K);
  return MICA_SUCCESS;
}

/* A cell pressure (pressure.c): the cells' condensed terms, then the body load point by point. */
static int assemble_volume_cells(MicaSolid *s, const VolumeTerms *v, const double *u, double *R, MicaSparse *K) {
  MICA_CALL(mica_pressure_assemble(s, u, R, K));
  for (long p = 0; v->has_body && p < s->volume->npoints; p++) MICA_CALL(add_body_force(s, p, v->t, v->scale, R));
  return MICA_SUCCESS;
}

/* One set of points: through the kernel, grouped, or point by point (VCI's Petrov–Galerkin, residual only). */
static int assemble_point_set(MicaSolid *s, const VolumeTerms *v, const double *u, double *R, MicaSparse *K) {
  if (K && kernel_applies(s)) return assemble_points_grouped(s, v, 1, u, R, K);
  /* symmetric (test = trial functions) and one scatter per group, unless VCI's Petrov–Galerkin */
  if (K && !v->c->dN_test && !s->opt.general_kernel) return assemble_points_grouped(s, v, 0, u, R, K);
  return assemble_points_general(s, v, u, R, K);
}

static int assemble_volume(MicaSolid *s, double t, const double *u, double *R, MicaSparse *K) {
  const Layout L = layout_of(s);
  VolumeTerms v = {&L, t, load_scale(s, t), 0, s->volume, s->disc->qw, &s->opt.field};
  for (int a = 0; a < s->ncomp; a++) v.has_body |= s->opt.body[a] != NULL;
  if (mica_solid_pressure_cells(s)) return assemble_volume_cells(s, &v, u, R, K);
  if (s->nsni && s->stab_pairs) { /* the paired rule's points replace the nodal ones; the body load as NSNI's */
    const VolumeTerms pairs = {&L, t, v.scale, 0, s->nsni->pairs, s->nsni->pair_w, &s->opt.field};
    MICA_CALL(assemble_point_set(s, &pairs, u, R, K));
    for (long p = 0; v.has_body && p < s->volume->npoints; p++) MICA_CALL(add_body_force(s, p, t, v.scale, R));
    for (long p = 0; v.has_body && p < s->nsni->cache->npoints; p++)
      MICA_CALL(add_body_derivative(s, p, t, v.scale, R));
    return MICA_SUCCESS;
  }
  if (s->nsni && s->stab_green) { /* first: it mirrors K's upper half, as the grouped path below does */
    MICA_CALL(mica_nsni_green_assemble(s, u, R, K));
    for (long p = 0; v.has_body && p < s->nsni->cache->npoints; p++)
      MICA_CALL(add_body_derivative(s, p, t, v.scale, R));
  } else if (s->nsni) { /* first: its grouped path mirrors K's upper half, which a Petrov–Galerkin volume's would not */
    const VolumeTerms stab = {&L, t, v.scale, v.has_body, s->nsni->cache, s->nsni->w, &s->stab_model};
    MICA_CALL(assemble_point_set(s, &stab, u, R, K));
  }
  return assemble_point_set(s, &v, u, R, K);
}

/* Dead generalized tractions (forces on displacements, couples on rotations): R_kc −= ∫ t̄_c N_k dΓ. */
static int assemble_tractions(const MicaSolid *s, double t, double *R) {
  const int dim = s->dim, ncomp = s->ncomp;
  const double scale = load_scale(s, t);
  for (int i = 0; i < s->ntraction; i++) {
    const MicaTraction *tr = &s->traction[i];
    const MicaBoundarySet *set = &s->disc->sets[tr->set];
    const MicaShapeCache *c = s->boundary[tr->set];
    for (long p = 0; p < c->npoints; p++) {
      double x[3] = {0, 0, 0}, tv[MICA_MAX_COMP] = {0};
      memcpy(x, set->x + p * dim, sizeof(double) * (size_t)dim);
      for (int a = 0; a < ncomp; a++) MICA_CALL(load_value(tr->value[a], "on the whole set", dim, x, t, scale, &tv[a]));
      for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
        for (int a = 0; a < ncomp; a++) R[c->index[e] * ncomp + a] -= set->w[p] * c->N[e] * tv[a];
    }
  }
  return MICA_SUCCESS;
}

static int assemble_points(MicaSolid *s, double t, const double *u, double *R, MicaSparse *K) {
  MICA_CALL(assemble_volume(s, t, u, R, K));
  MICA_CALL(assemble_tractions(s, t, R));
  for (int c = 0; c < s->ndirichlet; c++) MICA_CALL(s->opt.bc_method->add(s, &s->dirichlet[c], t, u, R, K));
  return MICA_SUCCESS;
}

int mica_solid_linear(const MicaSolid *s) {
  return mica_field_model_quadratic(&s->opt.field) && !s->opt.parallel;
}

int mica_solid_assemble(MicaSolid *s, double t, const double *u, double *R, MicaSparse *K) {
  memset(R, 0, sizeof(double) * (size_t)s->ndof);
  if (K) mica_sparse_zero(K);
  const int ierr = assemble_points(s, t, u, R, K);
  /* parallel: this rank's points only; the residual is summed over the ranks (K stays distributed): whole with
   * replicated data, at the owned particles (and copied into the ghosts) with distributed data */
  MicaDistribution *dist = s->opt.parallel;
  if (dist && dist->owned) MICA_CALL(mica_owned_residual(dist, ierr, R, s->ncomp));
  else if (dist) MICA_CALL(mica_parallel_residual(ierr, R, s->ndof));
  return ierr;
}
