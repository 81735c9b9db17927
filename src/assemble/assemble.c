/* Residual and tangent of the solid (docs/theory.md §solids), total Lagrangian:
 *   R_Ia = ∫ P_aJ N_I,J dV − ∫ b_a N_I dV − ∫ t̄_a N_I dΓ + (boundary-method terms),
 *   K_IaKb = ∫ N_I,J A_aJbL N_K,L dV + (boundary-method terms),
 * with F = I + Σ_I u_I ⊗ ∇N_I at each quadrature point and P, A from the model's point kernel. Local
 * blocks are scattered straight into the fixed sparsity pattern. */
#include <math.h>
#include <string.h>

#include "mica/solid.h"

void mica_solid_deformation_gradient(const MicaSolid *s, const MicaShapeCache *c, long p, const double *u, double *F) {
  const int dim = s->dim;
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = a == J ? 1.0 : 0.0;
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
    const double *ue = u + c->index[e] * dim, *dN = c->dN + e * dim;
    for (int a = 0; a < dim; a++)
      for (int J = 0; J < dim; J++) F[a * dim + J] += ue[a] * dN[J];
  }
}

void mica_solid_interpolate(const MicaSolid *s, const MicaShapeCache *c, const double *u, double *uh, double *grad) {
  const int dim = s->dim;
  for (long p = 0; p < c->npoints; p++) {
    double *up = uh ? uh + p * dim : NULL, *gp = grad ? grad + p * dim * dim : NULL;
    if (up) memset(up, 0, sizeof(double) * (size_t)dim);
    if (gp) memset(gp, 0, sizeof(double) * (size_t)(dim * dim));
    for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++) {
      const double *ue = u + c->index[e] * dim, *dN = c->dN + e * dim;
      for (int a = 0; a < dim; a++) {
        if (up) up[a] += c->N[e] * ue[a];
        if (gp)
          for (int J = 0; J < dim; J++) gp[a * dim + J] += ue[a] * dN[J];
      }
    }
  }
}

/* Load scaling: with ramping, every load and prescribed value grows with the load factor t. */
static double load_scale(const MicaSolid *s, double t) { return s->opt.ramp ? t : 1.0; }

/* Internal force of one point: R_ka += w P_aJ N_k,J. */
static void add_internal_force(int dim, long n, const long *idx, const double *dN, const double *P, double w,
                               double *R) {
  for (long k = 0; k < n; k++)
    for (int a = 0; a < dim; a++) {
      double f = 0;
      for (int J = 0; J < dim; J++) f += P[a * dim + J] * dN[k * dim + J];
      R[idx[k] * dim + a] += w * f;
    }
}

/* Ke[(k a),(l b)] = w Σ_JL N_k,J A_aJbL N_l,L via G_k[a][b][L] = Σ_J N_k,J A_aJbL: n dim⁴ + n² dim³. */
static void element_stiffness(int dim, long n, const double *dN, const double *A, double w, double *G, double *Ke) {
  const int d2 = dim * dim, d3 = d2 * dim;
  for (long k = 0; k < n; k++)
    for (int a = 0; a < dim; a++)
      for (int b = 0; b < dim; b++)
        for (int L = 0; L < dim; L++) {
          double g = 0;
          for (int J = 0; J < dim; J++) g += dN[k * dim + J] * A[((a * dim + J) * dim + b) * dim + L];
          G[k * d3 + (a * dim + b) * dim + L] = g;
        }
  const long m = n * dim;
  for (long k = 0; k < n; k++)
    for (int a = 0; a < dim; a++)
      for (long l = 0; l < n; l++)
        for (int b = 0; b < dim; b++) {
          const double *g = G + k * d3 + (a * dim + b) * dim, *dNl = dN + l * dim;
          double v = 0;
          for (int L = 0; L < dim; L++) v += g[L] * dNl[L];
          Ke[(k * dim + a) * m + l * dim + b] = w * v;
        }
}

static int add_body_force(const MicaSolid *s, long p, double t, double scale, double *R) {
  const MicaShapeCache *c = s->volume;
  const int dim = s->dim;
  double x[3] = {0, 0, 0}, b[3];
  memcpy(x, s->disc->qx + p * dim, sizeof(double) * (size_t)dim);
  for (int a = 0; a < dim; a++) b[a] = s->opt.body[a] ? scale * mica_function_eval(s->opt.body[a], x, t) : 0.0;
  const double w = s->disc->qw[p];
  for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
    for (int a = 0; a < dim; a++) R[c->index[e] * dim + a] -= w * c->N[e] * b[a];
  return MICA_SUCCESS;
}

static int assemble_volume(MicaSolid *s, double t, const double *u, double *R, MicaSparse *K) {
  const MicaShapeCache *c = s->volume;
  const int dim = s->dim, has_body = s->opt.body[0] || s->opt.body[1] || s->opt.body[2];
  const double scale = load_scale(s, t);
  double F[9], P[9], A[81], W;
  double *Ke = s->work, *G = NULL;
  for (long p = 0; p < c->npoints; p++) {
    const long n = c->ptr[p + 1] - c->ptr[p], *idx = c->index + c->ptr[p];
    const double *dN = c->dN + c->ptr[p] * dim, w = s->disc->qw[p];
    mica_solid_deformation_gradient(s, c, p, u, F);
    int ierr = s->opt.model->eval(&s->opt.material, dim, F, &W, P, K ? A : NULL);
    if (ierr) {
      mica_error_prefix("volume quadrature point %ld", p + 1);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
    add_internal_force(dim, n, idx, dN, P, w, R);
    if (has_body) MICA_CALL(add_body_force(s, p, t, scale, R));
    if (!K) continue;
    G = Ke + (n * dim) * (n * dim);
    element_stiffness(dim, n, dN, A, w, G, Ke);
    MICA_CALL(mica_sparse_add_clique(K, n, idx, Ke));
  }
  return MICA_SUCCESS;
}

/* Dead tractions: R_ka −= ∫ t̄_a N_k dΓ. */
static int assemble_tractions(const MicaSolid *s, double t, double *R) {
  const int dim = s->dim;
  const double scale = load_scale(s, t);
  for (int i = 0; i < s->ntraction; i++) {
    const MicaTraction *tr = &s->traction[i];
    const MicaBoundarySet *set = &s->disc->sets[tr->set];
    const MicaShapeCache *c = s->boundary[tr->set];
    for (long p = 0; p < c->npoints; p++) {
      double x[3] = {0, 0, 0}, tv[3] = {0, 0, 0};
      memcpy(x, set->x + p * dim, sizeof(double) * (size_t)dim);
      for (int a = 0; a < dim; a++) tv[a] = tr->value[a] ? scale * mica_function_eval(tr->value[a], x, t) : 0.0;
      for (long e = c->ptr[p]; e < c->ptr[p + 1]; e++)
        for (int a = 0; a < dim; a++) R[c->index[e] * dim + a] -= set->w[p] * c->N[e] * tv[a];
    }
  }
  return MICA_SUCCESS;
}

int mica_solid_assemble(MicaSolid *s, double t, const double *u, double *R, MicaSparse *K) {
  memset(R, 0, sizeof(double) * (size_t)s->ndof);
  if (K) mica_sparse_zero(K);
  MICA_CALL(assemble_volume(s, t, u, R, K));
  MICA_CALL(assemble_tractions(s, t, R));
  for (int c = 0; c < s->ndirichlet; c++) MICA_CALL(s->opt.bc_method->add(s, &s->dirichlet[c], t, u, R, K));
  return MICA_SUCCESS;
}
