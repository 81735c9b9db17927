/* A finite-element baseline on mica's own nodes (docs/theory.md §finite elements): Lagrange quadrilaterals
 * and hexahedra — Q1 (4 nodes) and Q2 (9 nodes) in 2-D, hex8 and hex27 in 3-D — on the logical grid of the
 * particles of a structured layout. The particles are the nodes, the background cells between them are the
 * elements (Q2: pairs of particle intervals per axis), element Gauss points replace the cell points. It is
 * a measuring stick for EFG, not a second product: the shape functions go into the same MicaShapeCache as
 * MLS's (through the approximation ops table of mica/solid.h), and the solid, the boundary methods and the
 * outputs use them unchanged.
 *
 * Element nodes are numbered lexicographically, axis 0 fastest: local node a = a_0 + (p+1)(a_1 + (p+1) a_2)
 * sits at reference coordinate ξ_d = −1 + 2 a_d / p on [−1, 1]^dim (p = the order, 1 or 2).
 */
#ifndef MICA_FE_H
#define MICA_FE_H

#include "mica/geom.h"
#include "mica/solid.h"

enum { MICA_FE_MAX_NODES = 27 }; /* hex27 */

/* ---- reference elements (src/fe/fe.c) ------------------------------------------------------------------ */

/* Nodes per element: (p+1)^dim. */
int mica_fe_element_nodes(int dim, int order);
/* A name for summaries: "Q1", "Q2" (2-D), "hex8", "hex27" (3-D). */
const char *mica_fe_element_name(int dim, int order);
/* Reference coordinates of the nodes, xi[a*dim + d]. */
void mica_fe_reference_nodes(int dim, int order, double *xi);
/* Tensor-product Lagrange shape functions at reference point xi: N[a] and dN[d*nen + a] = ∂N_a/∂ξ_d
 * (dN may be NULL). */
void mica_fe_reference_eval(int dim, int order, const double *xi, double *N, double *dN);
/* The isoparametric map of an element with node coordinates xe[a*dim + d] at a point whose reference
 * gradients are dNref (layout of mica_fe_reference_eval): J_ij = Σ_a xe_ai ∂N_a/∂ξ_j into jac (may be NULL),
 * det J into *det, and the physical gradients dNdx[a*dim + d] = Σ_j ∂N_a/∂ξ_j (J⁻¹)_jd (the cache's layout).
 * MICA_ERR_NUMERIC if det J = 0 (a degenerate element). */
int mica_fe_gradients(int dim, int nen, const double *xe, const double *dNref, double *jac, double *det,
                      double *dNdx);
/* Column a of the cofactor matrix det(J) J⁻ᵀ (Nanson: the area vector of the face ξ_a = const). */
void mica_fe_cofactor_column(int dim, const double *jac, int a, double *col);

/* ---- the mesh on a structured layout (src/fe/fe_mesh.c) -------------------------------------------------- */

typedef struct MicaFe {
  int dim, order, nen;     /* nen = (order+1)^dim */
  long count[3];           /* nodes per axis (axis 0 fastest); 1 beyond dim */
  long nel[3];             /* elements per axis: (count − 1) / order */
  long nelements, nnodes;
  double *x;               /* [nnodes*dim] node coordinates (a copy of the particles) */
  long *conn;              /* [nelements*nen] global node of each local node */
  double *box;             /* [nelements*2*dim] padded bounding box of each element (point location) */
  double *spacing;         /* [nnodes*dim] local spacing: widest adjacent element along each axis / order */
} MicaFe;

/* Elements of order 1 or 2 on nodes x[nnodes*dim] that form a logical grid count[0] × count[1] (× count[2]),
 * axis 0 fastest. MICA_ERR_INPUT if nnodes ≠ Π count, or (order 2) a count is even. */
int mica_fe_create(int dim, int order, const long count[3], long nnodes, const double *x, MicaFe **fe);
int mica_fe_destroy(MicaFe **fe);
/* The element containing x and the reference coordinates there. A point outside every element by at most
 * MICA_FE_OUTSIDE in reference coordinates (points on a curved boundary that the isoparametric chord cuts
 * off) is assigned to the nearest element and extrapolated; farther out is MICA_ERR_INPUT. */
#define MICA_FE_OUTSIDE 0.25
int mica_fe_locate(const MicaFe *fe, const double *x, long *element, double *xi);
/* Reference coordinates of x in a given element (Newton on the isoparametric map); *excess is how far xi
 * lies outside [−1, 1]^dim (0 inside). MICA_ERR_NUMERIC if Newton fails. */
int mica_fe_inverse_map(const MicaFe *fe, long element, const double *x, double *xi, double *excess);

/* The finite-element discretization of a built-in shape: the same particles, the element Gauss points
 * (order per direction; weights from the isoparametric Jacobian) as volume points with qcell = their
 * element, and for every boundary set of `like` (same names and order) the element faces on it, with
 * boundary_order Gauss points per direction, isoparametric positions, weights (Nanson) and normals, the
 * faces' corner nodes as multiplier vertices, and cell = the element of each point. A face belongs to the
 * set of `like` whose boundary element lies nearest to the face's center. MICA_ERR_INPUT for an element
 * that is inverted or degenerate at one of its Gauss points (too much jitter). */
int mica_fe_discretize(const MicaFe *fe, const MicaDiscretization *like, int order, int boundary_order,
                       MicaDiscretization **disc);

/* ---- the approximation (src/fe/fe_approx.c) ---------------------------------------------------------- */

/* ctx: a const MicaFe *. Points: the element's nodes as supports, N and ∇N through the isoparametric map,
 * first derivatives only. Particles: N_I(x_J) = δ_IJ, ∇N the average over the elements around the node. */
extern const MicaApproxOps mica_approx_fe;
/* problem.method: efg (mica_approx_mls, the default), fe. Here, above both types' folders. */
extern MicaRegistry mica_approx_registry;

#endif
