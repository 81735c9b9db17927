/* Small-strain gradient elasticity (docs/theory.md §strain gradient), unknowns u, order 2:
 *  - strain-gradient: first strain-gradient elasticity with one length l,
 *      W = ½ ε:C:ε + ½ l² Σ_K ∂_K ε : C : ∂_K ε,    ε = sym ∇u;
 *  - couple-stress: the modified couple-stress theory (Yang et al. 2002),
 *      W = ½ ε:C:ε + μ l² χ:χ,    χ = sym ∇θ,   θ = ½ curl u.
 * Both are quadratic in q = [u | ∇u | ∇∇u], so W = ½ qᵀDq, s = Dq, and D follows exactly from W by
 * polarization: D_ij = W(e_i + e_j) − W(e_i) − W(e_j). Natural boundary conditions: the traction and the
 * double traction (T n n with T = ∂W/∂∇∇u), zero on free surfaces.
 * param[] layout: the GRADIENT_* slots below.
 */
#include <math.h>
#include <string.h>

#include "models_private.h"

/* The slots of MicaFieldModel.param of the gradient models, and the values of the kind slot. */
enum {
  GRADIENT_LENGTH = 0, /* the length scale l */
  GRADIENT_KIND = 1    /* GRADIENT_STRAIN or GRADIENT_COUPLE_STRESS */
};
enum { GRADIENT_STRAIN = 0, GRADIENT_COUPLE_STRESS = 1 };

static int sg_ncomp(int dim) { return dim; }

static const char *const *sg_components(int dim) {
  static const char *const names[] = {"ux", "uy", "uz", NULL};
  (void)dim;
  return names;
}

static const char *const *sg_tractions(int dim) {
  static const char *const names[] = {"tx", "ty", "tz", NULL};
  (void)dim;
  return names;
}

static int hess_slot(int dim, int J, int K) { return J == K ? J : (dim == 2 ? 2 : 6 - J - K); }

/* e:C:e for an isotropic C (λ, μ); e is dim × dim. In 2-D, plane strain. */
static double contract(int dim, const MicaMaterial *mat, const double *e) {
  double tr = 0, ee = 0;
  for (int i = 0; i < dim; i++) tr += e[i * dim + i];
  for (int i = 0; i < dim * dim; i++) ee += e[i] * e[i];
  return mat->lambda * tr * tr + 2 * mat->mu * ee;
}

/* u_a,JK from the packed Hessian slots of q. */
static double second(const double *q, int dim, int a, int J, int K) {
  const int nh = dim * (dim + 1) / 2;
  return q[dim * (1 + dim) + a * nh + hess_slot(dim, J, K)];
}

static double energy(const MicaFieldModel *m, int dim, const double *q) {
  const double l = m->param[GRADIENT_LENGTH];
  double eps[9] = {0};
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) eps[i * dim + j] = 0.5 * (q[dim + i * dim + j] + q[dim + j * dim + i]);
  double W = 0.5 * contract(dim, &m->material, eps);
  if (m->param[GRADIENT_KIND] == GRADIENT_STRAIN) { /* strain gradient: ∂_K ε_ij = ½ (u_i,jK + u_j,iK) */
    for (int K = 0; K < dim; K++) {
      double deps[9] = {0};
      for (int i = 0; i < dim; i++)
        for (int j = 0; j < dim; j++) deps[i * dim + j] = 0.5 * (second(q, dim, i, j, K) + second(q, dim, j, i, K));
      W += 0.5 * l * l * contract(dim, &m->material, deps);
    }
    return W;
  }
  /* couple stress: θ_i = ½ e_ijk u_k,j; ∂_L θ_i = ½ e_ijk u_k,jL; χ = sym ∇θ (3-D; 2-D has θ_z only) */
  double gtheta[3][3] = {{0}}; /* gtheta[i][L] = ∂_L θ_i */
  for (int L = 0; L < dim; L++) {
    if (dim == 2) {
      gtheta[2][L] = 0.5 * (second(q, dim, 1, 0, L) - second(q, dim, 0, 1, L));
      continue;
    }
    gtheta[0][L] = 0.5 * (second(q, dim, 2, 1, L) - second(q, dim, 1, 2, L));
    gtheta[1][L] = 0.5 * (second(q, dim, 0, 2, L) - second(q, dim, 2, 0, L));
    gtheta[2][L] = 0.5 * (second(q, dim, 1, 0, L) - second(q, dim, 0, 1, L));
  }
  double chichi = 0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      const double chi = 0.5 * (gtheta[i][j] + gtheta[j][i]);
      chichi += chi * chi;
    }
  return W + m->material.mu * l * l * chichi;
}

static int sg_eval(const MicaFieldModel *m, int dim, const double *q, double *W, double *s, double *D) {
  const int nq = mica_field_model_nq(m, dim);
  double Dl[64 * 64], e[64];
  memset(e, 0, sizeof(double) * (size_t)nq);
  double diag[64];
  for (int i = 0; i < nq; i++) {
    e[i] = 1;
    diag[i] = energy(m, dim, e); /* ½ D_ii */
    e[i] = 0;
  }
  for (int i = 0; i < nq; i++)
    for (int j = i; j < nq; j++) {
      if (i == j) {
        Dl[i * nq + i] = 2 * diag[i];
        continue;
      }
      e[i] = e[j] = 1;
      Dl[i * nq + j] = Dl[j * nq + i] = energy(m, dim, e) - diag[i] - diag[j];
      e[i] = e[j] = 0;
    }
  if (W) *W = energy(m, dim, q);
  if (s)
    for (int i = 0; i < nq; i++) {
      double sum = 0;
      for (int j = 0; j < nq; j++) sum += Dl[i * nq + j] * q[j];
      s[i] = sum;
    }
  if (D) memcpy(D, Dl, sizeof(double) * (size_t)(nq * nq));
  return MICA_SUCCESS;
}

/* Output: the Cauchy stress of the local part, σ = C:ε (the double stress is not reported). */
static int sg_stress(const MicaFieldModel *m, int dim, const double *q, double *sigma, double *couple) {
  double F[9], strain[9];
  for (int a = 0; a < dim; a++)
    for (int J = 0; J < dim; J++) F[a * dim + J] = (a == J) + q[dim + a * dim + J];
  if (couple) memset(couple, 0, sizeof(double) * 9);
  return mica_model_stress_strain(&mica_model_linear, &m->material, dim, F, sigma, strain);
}

const MicaFieldModelOps mica_field_strain_gradient = {
    {"strain-gradient", "first strain gradient elasticity, small strain, length material.l", 0, NULL,
     mica_strain_gradient_from_settings_},
    2, sg_ncomp, sg_components, sg_tractions, sg_eval, sg_stress, NULL,
};

/* The modified couple-stress theory: the same kernel with param[GRADIENT_KIND] = GRADIENT_COUPLE_STRESS. As a deck's type it only reads the
 * settings: the model it makes has the strain-gradient table (mica_strain_gradient_set). */
const MicaFieldModelOps mica_field_couple_stress = {
    {"couple-stress", "modified couple-stress theory, small strain, length material.l", 0, NULL,
     mica_couple_stress_from_settings_},
    2, sg_ncomp, sg_components, sg_tractions, sg_eval, sg_stress, NULL,
};

int mica_strain_gradient_set(MicaFieldModel *m, const MicaMaterial *material, double l, int couple_stress) {
  MICA_CHECK(l > 0 && isfinite(l), MICA_ERR_INPUT, "the length scale l = %g must be positive", l);
  memset(m, 0, sizeof *m);
  m->ops = &mica_field_strain_gradient;
  m->classical = &mica_model_linear;
  m->material = *material;
  m->param[GRADIENT_LENGTH] = l;
  m->param[GRADIENT_KIND] = couple_stress ? GRADIENT_COUPLE_STRESS : GRADIENT_STRAIN;
  return MICA_SUCCESS;
}
