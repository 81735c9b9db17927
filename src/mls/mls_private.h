/* Private to src/mls: the MLS approximation object shared by approx.c (setup) and shape.c (evaluation). */
#ifndef MICA_MLS_PRIVATE_H
#define MICA_MLS_PRIVATE_H

#include "mica/mls.h"

enum { MLS_MAX_TERMS = 64 }; /* Lagrange/Bernstein order 3 in 3-D */

struct MlsApprox {
  int dim, m;
  long n;
  MlsOptions opt;
  double *x;       /* [n*dim] particles */
  double *radii;   /* [n*dim] support radius per particle and axis */
  double *spacing; /* [n*dim] local particle spacing */
  double *wparam;  /* [n*dim] weight shape parameter ρ_id / c_i (exponential weight only) */
  /* The basis and its derivatives at s = 0, in scaled coordinates: the right-hand sides of eqs 3.12-3.14
   * with the basis centered at the evaluation point. */
  double p0[MLS_MAX_TERMS], dp0[MLS_MAX_DIM * MLS_MAX_TERMS], ddp0[MLS_MAX_HESS * MLS_MAX_TERMS];
  MlsSearch *search;
};

#endif
