/* Boundary methods (src/bc): the types that impose Dirichlet conditions weakly — penalty, Nitsche, Lagrange
 * multipliers — their registry and the reading of bc.method, and the check that the conditions hold the body's
 * rigid motions. The interface they implement (MicaBoundaryMethodOps, flags MICA_BC_*) is the solid's,
 * mica/solid.h, which calls it. */
#ifndef MICA_BC_H
#define MICA_BC_H

#include "mica/solid.h"

/* bc.method: penalty, nitsche (the default), lagrange, collocation (src/bc/bc.c). */
extern MicaRegistry mica_bc_method_registry;
extern const MicaBoundaryMethodOps mica_bc_penalty, mica_bc_nitsche, mica_bc_lagrange, mica_bc_collocation;

/* The rigid motions (translations, rotations; axisymmetric: along and about the axis) that no Dirichlet condition
 * holds, from the conditions' geometry alone (src/bc/rigid.c): a motion is held when one of its prescribed
 * components is nonzero at one of a condition's boundary points. names: the deck names of the ncomp unknowns (ux,
 * uy, phiz, ...; axisymmetric ur, utheta, uz, ...). A free motion is a MICA_ERR_INPUT error, "WHERE: the body can
 * move freely: N rigid modes are not held (...); add Dirichlet conditions on ...". across_ranks: disc is this MPI
 * rank's share of a distributed body (parallel.data = "distributed"); the sums are then over all ranks (collective),
 * so that no rank needs the whole boundary. */
int mica_dirichlet_check_rigid(const MicaDiscretization *disc, int axisymmetric, int across_ranks, int ncomp,
                               const char *const *names, int ndirichlet, const MicaDirichlet *dirichlet,
                               const char *where);
/* The rigid motions themselves, as vectors over n unknowns (nparticles particles at x[nparticles*dim], ncomp
 * unknowns each, node-major; the unknowns beyond the particles', multipliers, are 0): the near-null space of an
 * unconstrained tangent, for algebraic multigrid. Translations are 1 in their component; a rotation about axis k
 * through the particles' centroid is u = e_k × (x − x0) / L with φ_k = 1 / L (its micro-rotation turns with it),
 * L the particles' extent. Unknowns other than displacements and micro-rotations (micromorph, strain gradient)
 * are 0 in every motion. *modes: [*count][n], MICA_MALLOC'ed, the caller's to free. */
int mica_rigid_motions(const double *x, long nparticles, int dim, int axisymmetric, int ncomp,
                       const char *const *names, long n, int *count, double **modes);
const MicaBoundaryMethodOps *mica_bc_method_find(const char *name);
/* The method chosen by bc.method and its own settings (bc.alpha: penalty and nitsche, each with its default,
 * read by the type's from_settings) into opt (bc_method, bc_alpha: 0 for a method without one). */
int mica_bc_method_from_settings(const MicaSettings *settings, MicaSolidOptions *opt);

#endif
