/* Shared by the boundary methods: what each needs at a boundary quadrature point. */
#ifndef MICA_BC_PRIVATE_H
#define MICA_BC_PRIVATE_H

#include "mica/bc.h"

/* One boundary quadrature point of a Dirichlet condition, gathered for the methods. */
typedef struct {
  long n;            /* supporting particles */
  const long *index; /* their indices (ascending) */
  const double *N, *dN;
  double x[3], normal[3], w, h;
  double uh[MICA_MAX_COMP];       /* the unknowns' approximation at the point */
  double residual[MICA_MAX_COMP]; /* u_h − ū for the prescribed components, 0 for the others */
} BcPoint;

/* Gathers point p of condition c at load factor t; a prescribed value that is not finite there is a deck error
 * naming its expression, line and the point. */
int bc_point(const MicaSolid *s, const MicaDirichlet *c, long p, double t, const double *u, BcPoint *bp);

/* β = α E / h: the penalty or Nitsche stabilization at a point. */
static inline double bc_beta(const MicaSolid *s, const BcPoint *bp) {
  return s->opt.bc_alpha * s->opt.field.material.E / bp->h;
}

/* bc.alpha, which penalty and nitsche declare each with its own default ("1e3", "100"), and the
 * from_settings both use: the factor into MicaSolidOptions.bc_alpha. */
#define BC_ALPHA_KEY(value)                                                                                   \
  {.path = "alpha", .type = MICA_KEY_FLOAT, .def = value, .min = 1e-6, .max = 1e12,                            \
   .help = "penalty / Nitsche factor α in β = α E / h (Cosserat and other field models: β_b = α k_b / h per "  \
           "unknown, docs/theory.md)"}
int bc_alpha_from_settings(const MicaType *type, const MicaSettings *settings, const char *group, void *options);

/* Symmetric Nitsche for first-order field models (nitsche_field.c): the generalized tractions from the
 * model's s and D. */
int bc_nitsche_field_add(MicaSolid *s, const MicaDirichlet *c, double t, const double *u, double *R, MicaSparse *K);

#endif
