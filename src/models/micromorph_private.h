/* Private to the gradient micromorph kinds (src/models/micromorph*.c): the micro-space Gauss points and the
 * param[] layout they share (docs/theory.md §micromorph).
 *
 * param[] layout: the MICRO_* slots below. */
#ifndef MICA_MICROMORPH_PRIVATE_H
#define MICA_MICROMORPH_PRIVATE_H

#include "mica/model.h"

enum { MICRO_MAX_POINTS = 27, MICRO_GAUSS = 3 };

/* The slots of MicaFieldModel.param of the micromorph kinds. */
enum {
  MICRO_SIZE = 0,       /* [MICRO_SIZE + K], K = 0, 1, 2: the micro size along axis x, y, z (0: no extent) */
  MICRO_POINTS = 3,     /* micro Gauss points per axis (MICRO_GAUSS) */
  MICRO_COUPLING = 4,   /* the rotation kind's coupling modulus κ_c */
  MICRO_COUPLING_N = 5  /* the rotation kind's coupling number N */
};

/* The packed Hessian slot of ∂²/∂X_J∂X_K (mls_hess_index of mica/mls.h: 2-D 00, 11, 01; 3-D 00, 11, 22, 12, 02, 01),
 * repeated here because src/models does not depend on src/mls. */
static inline int micro_hess_index(int dim, int J, int K) { return J == K ? J : (dim == 2 ? 2 : 6 - J - K); }

/* Micro Gauss points Y_g (3 components; zero along axes without extent) and weights w_g summing to 1 over the
 * micro box; returns their number (1 for a micro space of dimension 0). */
int mica_micromorph_points_(const MicaFieldModel *m, int dim, double (*Y)[3], double *w);

/* Checks the sizes (≥ 0, finite) and fills the common part of m: ops, micro energy, material, sizes. */
int mica_micromorph_init_(MicaFieldModel *m, const MicaFieldModelOps *ops, int dim, const MicaModelOps *micro_energy,
                          const MicaMaterial *material, const double *sizes);

#endif
