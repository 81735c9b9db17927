/* Reference Lagrange elements on [−1, 1]^dim and the isoparametric map (docs/theory.md §finite elements).
 * 1-D Lagrange polynomials on the nodes −1, 1 (order 1) or −1, 0, 1 (order 2):
 *   order 1: ℓ_0 = (1 − ξ)/2,  ℓ_1 = (1 + ξ)/2;
 *   order 2: ℓ_0 = ξ(ξ − 1)/2, ℓ_1 = 1 − ξ²,  ℓ_2 = ξ(ξ + 1)/2;
 * and their tensor products N_a(ξ) = Π_d ℓ_{a_d}(ξ_d), axis 0 fastest. */
#include <math.h>
#include <string.h>

#include "mica/fe.h"

int mica_fe_element_nodes(int dim, int order) {
  int n = 1;
  for (int d = 0; d < dim; d++) n *= order + 1;
  return n;
}

const char *mica_fe_element_name(int dim, int order) {
  if (dim == 2) return order == 1 ? "Q1" : "Q2";
  return order == 1 ? "hex8" : "hex27";
}

/* 1-D values and derivatives of the order + 1 Lagrange polynomials at t. */
static void lagrange_1d(int order, double t, double *l, double *dl) {
  if (order == 1) {
    l[0] = 0.5 * (1 - t), l[1] = 0.5 * (1 + t);
    dl[0] = -0.5, dl[1] = 0.5;
  } else {
    l[0] = 0.5 * t * (t - 1), l[1] = 1 - t * t, l[2] = 0.5 * t * (t + 1);
    dl[0] = t - 0.5, dl[1] = -2 * t, dl[2] = t + 0.5;
  }
}

void mica_fe_reference_nodes(int dim, int order, double *xi) {
  const int nen = mica_fe_element_nodes(dim, order);
  for (int a = 0; a < nen; a++)
    for (int d = 0, rest = a; d < dim; d++, rest /= order + 1) xi[a * dim + d] = -1 + 2.0 * (rest % (order + 1)) / order;
}

void mica_fe_reference_eval(int dim, int order, const double *xi, double *N, double *dN) {
  const int n1 = order + 1, nen = mica_fe_element_nodes(dim, order);
  double l[3][3], dl[3][3];
  for (int d = 0; d < dim; d++) lagrange_1d(order, xi[d], l[d], dl[d]);
  for (int a = 0; a < nen; a++) {
    int idx[3] = {0, 0, 0};
    for (int d = 0, rest = a; d < dim; d++, rest /= n1) idx[d] = rest % n1;
    double value = 1;
    for (int d = 0; d < dim; d++) value *= l[d][idx[d]];
    N[a] = value;
    if (!dN) continue;
    for (int j = 0; j < dim; j++) {
      double g = 1;
      for (int d = 0; d < dim; d++) g *= d == j ? dl[d][idx[d]] : l[d][idx[d]];
      dN[j * nen + a] = g;
    }
  }
}

static double det_of(int dim, const double *J) {
  if (dim == 2) return J[0] * J[3] - J[1] * J[2];
  return J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) + J[2] * (J[3] * J[7] - J[4] * J[6]);
}

void mica_fe_cofactor_column(int dim, const double *J, int a, double *col) {
  if (dim == 2) { /* cof(J) = [[J11, −J10], [−J01, J00]] */
    if (a == 0) col[0] = J[3], col[1] = -J[1];
    else col[0] = -J[2], col[1] = J[0];
    return;
  }
  /* column a = (J e_{a+1}) × (J e_{a+2}), indices cyclic */
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  const double u[3] = {J[b], J[3 + b], J[6 + b]}, v[3] = {J[c], J[3 + c], J[6 + c]};
  col[0] = u[1] * v[2] - u[2] * v[1];
  col[1] = u[2] * v[0] - u[0] * v[2];
  col[2] = u[0] * v[1] - u[1] * v[0];
}

int mica_fe_gradients(int dim, int nen, const double *xe, const double *dNref, double *jac, double *det,
                      double *dNdx) {
  double J[9] = {0}, inv[9];
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) {
      double s = 0;
      for (int a = 0; a < nen; a++) s += xe[a * dim + i] * dNref[j * nen + a];
      J[i * dim + j] = s;
    }
  const double D = det_of(dim, J);
  if (jac) memcpy(jac, J, sizeof(double) * (size_t)(dim * dim));
  *det = D;
  MICA_CHECK(D != 0 && isfinite(D), MICA_ERR_NUMERIC, "degenerate element: det J = %g", D);
  /* J⁻¹ = cof(J)ᵀ / det: (J⁻¹)_jd = cof(J)_dj / det */
  for (int j = 0; j < dim; j++) {
    double col[3];
    mica_fe_cofactor_column(dim, J, j, col);
    for (int d = 0; d < dim; d++) inv[j * dim + d] = col[d] / D;
  }
  for (int a = 0; a < nen; a++)
    for (int d = 0; d < dim; d++) {
      double s = 0;
      for (int j = 0; j < dim; j++) s += dNref[j * nen + a] * inv[j * dim + d];
      dNdx[a * dim + d] = s;
    }
  return MICA_SUCCESS;
}
