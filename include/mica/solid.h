/* The solid-mechanics problem: discretization, MLS shape-function cache, model, boundary conditions,
 * assembly and Newton's method (docs/theory.md §solids).
 *
 * Total Lagrangian: shape functions and their gradients are computed once per quadrature point and cached
 * (MicaShapeCache); the unknowns are the particle parameters u_I (not the displacements at the particles:
 * MLS does not interpolate). Boundary conditions are imposed weakly on boundary quadrature points through
 * the boundary-method ops table (penalty, Nitsche, Lagrange multipliers).
 */
#ifndef MICA_SOLID_H
#define MICA_SOLID_H

#include "mica/expr.h"
#include "mica/geom.h"
#include "mica/mls.h"
#include "mica/model.h"
#include "mica/newton.h"
#include "mica/registry.h"
#include "mica/sparse.h"

/* ---- Shape-function cache ------------------------------------------------------------------------------ */

/* N, ∇N and (for second-gradient models) ∇∇N of the supporting particles at a list of points, in CSR form:
 * point p's supports are index[ptr[p] .. ptr[p+1]), with N[e], dN[e*dim + d] and ddN[e*nh + h] for entry e. */
typedef struct MicaShapeCache {
  int dim, order;  /* order 1: N, ∇N; order 2: also ∇∇N */
  long npoints;
  double *x;    /* [npoints*dim] the points (axisymmetric kinematics need their radius) */
  long *ptr;    /* [npoints+1] */
  long *index;  /* [nnz] particle indices, ascending per point */
  double *N;    /* [nnz] */
  double *dN;   /* [nnz*dim] */
  double *ddN;  /* [nnz*nh] packed Hessians (order 2), else NULL */
  double *dN_test; /* [nnz*dim] VCI-corrected gradients of the test functions (mica_vci_correct), else NULL:
                      the test functions are the trial functions */
  long max_support;
  double rcond_min;   /* MLS: the smallest reciprocal condition estimate of a moment matrix (0 unless MLS) */
  double time_search; /* seconds of neighbor search while it was built (profiles; 0 unless MLS) */
  int shares;   /* holders beyond the first (0 when allocated): the solids of consecutive runs may share a
                   cache (mica_shape_cache_share) */
} MicaShapeCache;

#define MICA_MAX_COMP 6 /* unknowns per particle: 3-D Cosserat */

/* ---- Approximations: where the shape functions come from (a registry of types) --------------------------- */

/* An approximation fills shape caches: MLS (EFG, mica_approx_mls, ctx a const MlsApprox *) or finite
 * elements on the same nodes (mica_approx_fe of mica/fe.h, ctx a const MicaFe *). The solid, the boundary
 * methods and the outputs see only the caches. */
enum {
  MICA_APPROX_INTERPOLATING = 1u << 0, /* N_I(x_J) = δ_IJ: the unknowns are the values at the particles (FE) */
  MICA_APPROX_MLS = 1u << 1            /* ctx is a const MlsApprox * (VCI corrects its gradients; it extends
                                          beyond the body; nodal integration at its particles) */
};

typedef struct MicaApproxOps {
  MicaType type;      /* "efg", "fe": problem.method; flags MICA_APPROX_* */
  int max_order;      /* highest derivative order it provides: 2 (MLS, Hessians), 1 (C0 finite elements) */
  /* N, ∇N (order 2: and ∇∇N) at x[npoints*dim]; cell[p] is the cell (element) point p lies in, or cell is
   * NULL and the approximation finds it if it needs it; an error names the point (label and number). */
  int (*points)(const void *ctx, long npoints, const double *x, const long *cell, int order, const char *label,
                MicaShapeCache **cache);
  /* The same at the particles (outputs). */
  int (*particles)(const void *ctx, int order, MicaShapeCache **cache);
  /* [nparticles*dim] local particle spacing per axis (penalty and Nitsche scale with 1/h). */
  const double *(*spacing)(const void *ctx);
} MicaApproxOps;

typedef struct MicaApprox {
  const MicaApproxOps *ops;
  const void *ctx;
} MicaApprox;

extern const MicaApproxOps mica_approx_mls;
/* The registry of approximations (problem.method) is mica_approx_registry of mica/fe.h, in src/fe: above both
 * types' folders. */
static inline int mica_approx_has(const MicaApproxOps *ops, unsigned flag) { return mica_type_has(&ops->type, flag); }

/* Evaluates shape functions with gradients (order 1) or with gradients and Hessians (order 2) at
 * x[npoints*dim]; an MLS failure names the point (label and number). */
int mica_shape_cache_create(const MlsApprox *mls, long npoints, const double *x, int order, const char *label,
                            MicaShapeCache **cache);
/* An empty order-1 cache for npoints points and nnz entries in all (ptr zeroed; x, index, N, dN, and dN_test when
 * with_test, uninitialized), for code that fills its own points: NSNI's, finite elements'. On failure *cache holds
 * what was allocated, for mica_shape_cache_destroy. */
int mica_shape_cache_alloc(int dim, long npoints, long nnz, int with_test, MicaShapeCache **cache);
/* Releases the caller's hold (NULLs *cache); the cache is freed when its last holder releases it. */
int mica_shape_cache_destroy(MicaShapeCache **cache);
/* Adds a holder and returns the cache: shape functions are read-only once built, so solids on the same
 * discretization and MLS may share them. */
MicaShapeCache *mica_shape_cache_share(MicaShapeCache *cache);
size_t mica_shape_cache_bytes(const MicaShapeCache *cache);

/* Variationally consistent integration (docs/theory.md §VCI; Chen, Hillman & Rüter 2013): fills
 * volume->dN_test with ∇̃N_I = ∇N_I + Σ_β ξ_Iβ q_β, q_β the monomials of degree ≤ n − 1 (n = consistency,
 * the MLS basis order, at least 1), with ξ such that every particle satisfies the discrete divergence identity
 *   Σ_vol w (∇̃N_I p + N_I ∇p) = Σ_∂Ω w N_I p n   for every monomial p of degree ≤ n − 1.
 * volume must be the cache at disc's volume points; the boundary sum runs over all of disc's sets, which
 * must cover the boundary once (disc->boundary_uncovered = 0). First derivatives only (a cache of order 2
 * keeps its Hessians uncorrected). A particle whose support holds too few volume points to fix ξ is a
 * MICA_ERR_NUMERIC error naming it. */
int mica_vci_correct(const MicaDiscretization *disc, const MlsApprox *mls, int n, MicaShapeCache *volume);
struct MicaDistribution;
struct MicaNsni;
/* Collective. The same on a rank's share of distributed data (parallel.data = "distributed": disc, mls and volume
 * the rank's, its particles owned first), with NSNI's stabilization points (the rank's; NULL: none) in the
 * constraint: each particle's sums are added at its owner (the ghost plan's reverse exchange), solved there, and ξ
 * copied into the ghosts before the rank's points are corrected. */
int mica_vci_correct_owned(const MicaDiscretization *disc, const MlsApprox *mls, int n, MicaShapeCache *volume,
                           const struct MicaNsni *nsni, struct MicaDistribution *dist);
/* The same with NSNI's stabilization points (nsni may be NULL) in the constraint: their terms of the Galerkin
 * residual, Σ w (H_I g)·∂_g σ, join the volume sum (docs/theory.md §NSNI). */
int mica_vci_correct_stabilized(const MicaDiscretization *disc, const MlsApprox *mls, int n, MicaShapeCache *volume,
                                const struct MicaNsni *nsni);
/* NSNI with a linear basis: one correction of the gradients, for trial and test functions alike (volume->dN is
 * corrected in place, no dN_test: the tangent stays symmetric), that satisfies the constraint above for the
 * monomials of degree ≤ 1 with the stabilization points' terms and keeps the corrected gradients reproducing
 * linear fields at every point (docs/theory.md §NSNI, "symmetric VCI"). MICA_ERR_NUMERIC if a point's support
 * does not determine a linear field or the constraints cannot be met to 1e-10 relative. dist: NULL for the whole
 * problem (CHOLMOD solves the constraint's system), or distributed data (collective: the rank's share, the system
 * assembled over the ranks and factored by MUMPS, the outcome the same on every rank). */
int mica_vci_correct_symmetric(const MicaDiscretization *disc, const MlsApprox *mls, MicaShapeCache *volume,
                               const struct MicaNsni *nsni, struct MicaDistribution *dist);

/* Stabilized conforming nodal integration (docs/theory.md §nodal integration; Chen, Wu, Yoon & You 2001): a
 * cache of order 1 at the particles (disc's volume points after mica_discretization_nodal) whose dN is the
 * smoothed gradient ∇̃N_J(x_I) = (1/|Ω_I|) Σ_b N_J(x_b) (w n)_b over the boundary points of particle I's nodal
 * cell, whose supports are the union of the supports of x_I and of those points, and whose N is N_J(x_I). */
int mica_scni_cache_create(const MicaDiscretization *disc, const MlsApprox *mls, MicaShapeCache **cache);

/* Naturally stabilized nodal integration (docs/theory.md §NSNI; Hillman & Chen 2016): dim stabilization points
 * per particle of a nodal discretization (mica_discretization_nodal), point I·dim + k at x_I with weight w and
 * unit direction g = dir + (I·dim + k)·dim from the Cholesky factor of the cell's second moments
 * (Σ_k w_k g_k ⊗ g_k = M_I), and as shape functions the directional derivatives of the MLS ones: N = g·∇N_J(x_I),
 * dN = H_J(x_I) g. The supports are those of x_I (a linear basis: of a quadratic fit with radii 3/2 as wide). */
typedef struct MicaNsni {
  MicaShapeCache *cache; /* order 1, npoints = cells × dim */
  double *w;             /* [npoints] */
  double *dir;           /* [npoints × dim] */
  double *grad;          /* [entries × dim]: ∇N_J(x_I) of each entry (with_gradients), else NULL */
  MicaShapeCache *pairs; /* the paired rule (mica_nsni_pairs_create), else NULL */
  double *pair_w;        /* [pairs->npoints] */
} MicaNsni;
/* One stabilization point set per nodal cell (disc->nodal->n = disc->nquad points; with distributed data a rank's
 * cells, fewer than its particles, which include the ghosts). */
int mica_nsni_create(const MicaDiscretization *disc, const MlsApprox *mls, int with_gradients, MicaNsni **nsni);
int mica_nsni_destroy(MicaNsni **nsni);
/* NSNI's paired rule for a model without a quadratic energy (docs/theory.md §NSNI, "the paired rule"): for each
 * stabilization point p = I·dim + k, two points whose shape functions are the nodal point's moved along the
 * expansion, N ± h ∂_g N and ∇N ± h H g (and VCI's test gradients ∇̃N ± h H g), each of weight |Ω_I| / (2 dim),
 * h² = dim w_p / |Ω_I|. With them in place of the nodal points and the stabilization points, the model's own energy
 * integrated over the 2 dim points equals NSNI's |Ω_I| W(q_I) + ½ Σ_k w_k q̇_kᵀ D q̇_k exactly for a quadratic W, and
 * extends it to any W. volume: the nodal points' cache after VCI, volume_w their weights |Ω_I|; the supports are the
 * stabilization points' (which hold the nodal ones). */
int mica_nsni_pairs_create(MicaNsni *nsni, const MicaShapeCache *volume, const double *volume_w);
/* The Hessians' support radii over the MLS ones for a basis of this order (3/2 for a linear basis, whose Hessians
 * come from a quadratic fit; 1 otherwise): how far from its points a rank's particles must reach (own.c). */
double mica_nsni_hessian_reach(int basis_order);

/* ---- Boundary conditions ------------------------------------------------------------------------------- */

typedef struct MicaDirichlet {
  int set;                  /* index into the discretization's boundary sets */
  int mask;                 /* bit c set: component c of the model's unknowns is prescribed */
  MicaFunction *value[MICA_MAX_COMP]; /* prescribed value of component c (x, y, z, t), for c in mask */
  char where[160];          /* deck location, for messages */
} MicaDirichlet;

typedef struct MicaTraction {
  int set;
  MicaFunction *value[MICA_MAX_COMP]; /* generalized traction conjugate to component c (force, couple), per
                                         unit reference length/area (dead load), or NULL */
  char where[160];
} MicaTraction;

struct MicaSolid;

/* Ways to impose Dirichlet conditions weakly: the interface the solid calls (the types, their registry and
 * bc.method's reading are src/bc's, mica/bc.h). Each adds its terms for one Dirichlet condition to the residual
 * and tangent; Lagrange multipliers also own extra unknowns. */
enum {
  MICA_BC_SYMMETRIC_DEFINITE = 1u << 0, /* the tangent stays symmetric positive definite (CHOLMOD can be used) */
  MICA_BC_MULTIPLIERS = 1u << 1,        /* multiplier nodes on the constrained sets */
  MICA_BC_MODEL_TRACTION = 1u << 2,     /* uses the model's traction s·n (Nitsche): first-order models only */
  MICA_BC_COLLOCATION = 1u << 3,        /* replaces the equations of the set's particles (collocation points at the
                                           set's vertices, which must be particles); one process only, since a
                                           replaced row is not the sum of the ranks' contributions */
};

typedef struct MicaBoundaryMethodOps {
  MicaType type; /* "penalty", "nitsche", "lagrange"; flags MICA_BC_* */
  /* Adds the residual (into R, over all dofs) and, if K, the tangent of condition c at load factor t. */
  int (*add)(struct MicaSolid *s, const MicaDirichlet *c, double t, const double *u, double *R, MicaSparse *K);
} MicaBoundaryMethodOps;

static inline int mica_bc_method_has(const MicaBoundaryMethodOps *ops, unsigned flag) {
  return mica_type_has(&ops->type, flag);
}

/* ---- The problem ---------------------------------------------------------------------------------------- */

/* ---- Volumetric treatment: the pressure space (material.pressure; src/assemble/pressure.c) ----------------
 * "none" (the default): the displacement form, whose pressure is λ div u (or λ ln J) at every quadrature point.
 * "cell-constant" / "cell-linear": a pressure constant / linear in each background cell, condensed cell by cell:
 * B-bar (small strain) or F-bar (finite strain) with the dilatation projected onto the cell's polynomials, the
 * energy Σ_q w_q W(F̄_q) (docs/theory.md §Nearly incompressible solids). Capability flags (MicaType.flags): */
enum {
  MICA_PRESSURE_CELLS = 1u << 0 /* couples the points of each background cell through its mean dilatation */
};
typedef struct MicaPressureOps {
  MicaType type; /* "none", "cell-constant", "cell-linear"; MICA_PRESSURE_* flags */
  int degree;    /* of the polynomial pressure in a cell (0: constant, 1: linear), a number like a basis order */
} MicaPressureOps;
extern const MicaPressureOps mica_pressure_none, mica_pressure_cell_constant, mica_pressure_cell_linear;
extern MicaRegistry mica_pressure_registry;

typedef struct MicaSolidOptions {
  MicaFieldModel field;         /* the model: classical (adapting a MicaModelOps kernel) or generalized */
  const MicaPressureOps *pressure; /* the pressure space; NULL is the default's "none" (displacement form) */
  const MicaBoundaryMethodOps *bc_method;
  double bc_alpha;              /* stabilization / penalty factor α (Nitsche β = α E / h; penalty β = α E (L/h)^(p−1) / h) */
  int basis_order;              /* MLS basis order p (the penalty's scaling) */
  MicaFunction *body[MICA_MAX_COMP]; /* body load conjugate to each unknown (forces, couples) per unit
                                        reference volume, or NULL */
  int ramp;                     /* 1: every load and prescribed value is multiplied by the load factor t */
  int axisymmetric;             /* 1: a 2-D (r, z) section of a body of revolution; the model is evaluated in
                                   3-D with cylindrical components (r, θ, z), torsion included (docs/theory.md
                                   §axisymmetric); quadrature weights must already carry 2πr */
  int vci;                      /* 1: variationally consistent test gradients in the volume (Petrov–Galerkin:
                                   the tangent is unsymmetric), first-order models only */
  int scni;                     /* 1: smoothed (SCNI) gradients at the particles: disc must be nodal
                                   (mica_discretization_nodal); first-order, non-axisymmetric models only */
  int nsni;                     /* 1: NSNI's stabilization points (mica_nsni_create): disc must be nodal;
                                   first-order plane or 3-D models; finite-strain classical ones are stabilized
                                   with the linear model of their E, ν (docs/theory.md §NSNI) */
  int general_kernel;           /* 1: the slot-based element stiffness even where the classical kernel applies
                                   (mica/kernel.h; tests and benchmarks compare the two) */
  struct MicaDistribution *parallel; /* NULL: serial. Else (src/parallel, mica/parallel.h) the discretization
                                   holds this rank's share of the quadrature points: residuals are summed over
                                   the ranks, terms added once per problem come from rank 0, and Newton solves
                                   through the distributed solver */
} MicaSolidOptions;

typedef struct MicaSolid {
  const MicaDiscretization *disc;
  MicaApprox approx;              /* where the shape functions come from */
  const MlsApprox *mls;           /* approx's MlsApprox if it is MLS (VCI needs it), else NULL */
  MicaSolidOptions opt;
  int dim;                        /* of the geometry and the particles */
  int model_dim;                  /* of the model's kinematics: dim, or 3 for an axisymmetric solid */
  int ncomp;                      /* unknowns per particle (and per multiplier node) */
  int nq;                         /* length of the generalized kinematics q at a point */
  long nparticles;
  long ndof;                      /* ncomp × (particles + multiplier nodes) */
  MicaShapeCache *volume;         /* at the volume quadrature points */
  MicaNsni *nsni;                 /* NSNI's stabilization points, or NULL */
  int vci_symmetric;              /* 1: VCI corrected trial and test gradients alike (NSNI, linear basis:
                                     mica_vci_correct_symmetric); 0: test gradients only, or no VCI */
  MicaFieldModel stab_model;      /* the quadratic energy of those points (opt.nsni): the model, or its linear form */
  int stab_green;                 /* 1: stab_model is applied to Ė = sym(Fᵀ ∂_g F), frame-invariant (a finite-strain
                                     model; mica_nsni_green_assemble); 0: to ∂_g ∇u (a quadratic model) */
  int stab_pairs;                 /* 1: the paired rule (a finite model other than a classical one: nsni->pairs in
                                     place of the nodal and stabilization points); stab_model unused */
  MicaShapeCache **boundary;      /* [nsets], at each set's boundary quadrature points (NULL if unused) */
  double **boundary_h;            /* [nsets][n]: local particle spacing at each boundary point */
  int ndirichlet, ntraction;
  MicaDirichlet *dirichlet;
  MicaTraction *traction;
  long *multiplier_offset;        /* [ndirichlet]: first multiplier node of condition c (lagrange) */
  MicaShapeCache **collocation;   /* [ndirichlet] (collocation): shape functions at the set's vertices */
  long **collocation_particle;    /* [ndirichlet][vertices]: the particle at each vertex, whose rows are replaced */
  double **collocation_scale;     /* [ndirichlet][vertices]: E h^(dim−2) at that particle, the rows' scale */
  int *collocation_last;          /* [nparticles·ncomp]: the last condition whose vertex replaces row (I, a) — the
                                     one that writes it, as serially each overwrites the previous ones — or −1;
                                     with distributed data over every rank that holds particle I */
  double *collocation_share;      /* [nparticles·ncomp]: 1 / the ranks that write row (I, a) (a vertex on two
                                     ranks' faces: each writes half; 1 serially) */
  long nmultiplier_nodes;
  MicaSparse *K;                  /* the tangent, pattern built once */
  double time_vci;                /* seconds spent on the VCI correction (0 without it, or shared) */
  double time_shape, time_search, time_pattern; /* seconds: caches built for this solid (shape functions, of
                                   which neighbor search) and the sparsity pattern (profiles) */
  int caches_built, caches_shared; /* shape-function caches computed for this solid / taken from a donor */
  double *work;                   /* per-point scratch: element matrices */
  long *work_nodes;               /* per-point scratch: clique node lists */
  /* classical kernel (mica/kernel.h): the points of a background cell add into one matrix over the union of
   * their supports (at most cell_cap particles), scattered once per cell */
  long cell_cap;
  double *cell_matrix;            /* planar lower blocks over the union, and the kernel's scratch */
  int chunk_points;               /* points the kernel stages before it updates the group matrix */
  long *cell_nodes;               /* [cell_cap] the union, ascending */
  long *cell_slot;                /* [nparticles] position of a particle in the union, −1 outside it */
  /* material.pressure = cell-constant (pressure.c): the volume points of each background cell, the largest
   * union of a cell's supports and points per cell, and the scratch of one cell */
  long npcells;
  long *pcell_ptr, *pcell_point;  /* cell c's points: pcell_point[pcell_ptr[c] .. pcell_ptr[c+1]) */
  long pcell_cap, pcell_maxpoints;
  long *pcell_nodes;              /* [pcell_cap] a cell's union, ascending */
  double *pcell_work;
} MicaSolid;

/* NSNI's stabilization at finite strain (docs/theory.md §NSNI, "frame-invariant stabilization"): at each
 * stabilization point the directional derivative of the Green strain, Ė = sym(Fᵀ G) with G = ∂_g F = Σ_J u_J ⊗
 * H_J g, in the energy ½ w Ė : C : Ė of the stabilization model (the material's linear form, C at E = 0); its
 * residual into R and, if K, its tangent into K: upper blocks, then K's lower triangle overwritten by its upper one
 * (mica_sparse_mirror_upper), so it runs first on a zeroed K. Needs s->nsni built with gradients. */
int mica_nsni_green_assemble(MicaSolid *s, const double *u, double *R, MicaSparse *K);

/* The pressure space of material.pressure (group "material"), into opt->pressure. */
int mica_pressure_from_settings(const MicaSettings *settings, MicaSolidOptions *opt);
/* 1 if the solid's pressure lives on the background cells (MICA_PRESSURE_CELLS). */
int mica_solid_pressure_cells(const MicaSolid *s);
/* Builds the cells' point lists and scratch (mica_solid_create calls it); MICA_ERR_INPUT when the solid cannot
 * have a cell pressure (a message without location: the caller adds the deck line). */
int mica_pressure_cells_build(MicaSolid *s);
void mica_pressure_cells_free(MicaSolid *s);
/* The volume terms of a cell pressure: R += Σ_q w_q P_eff : ∇N and K += the cells' condensed tangents (full
 * blocks, both triangles), K may be NULL. No body force (the caller adds it). */
int mica_pressure_assemble(MicaSolid *s, const double *u, double *R, MicaSparse *K);
/* Π = Σ_q w_q W(F̄_q) at u (the energy whose gradient and Hessian mica_pressure_assemble gives; tests). */
int mica_pressure_energy(MicaSolid *s, const double *u, double *energy);
/* The pressure polynomials of cell c at its points (in pcell_point order): psi[i·m + k] = ψ_k(x_i) and
 * Minv_psi = M⁻¹ψ at each point (M the cell's moment matrix Σ w ψ ψᵀ), modes = m = 1 + degree·dim (psi and
 * Minv_psi hold points × 4). For the inf-sup test (G = Σ_c B_cᵀ M_c⁻¹ B_c). */
int mica_pressure_cell_basis(MicaSolid *s, long c, double *psi, double *Minv_psi, int *modes);
/* The cell-averaged dilatation Θ_c of cell c at u (J̄ = mean det F at finite strain, mean div u at small
 * strain), and the cell's volume; for output and tests. */
void mica_pressure_cell_dilatation(const MicaSolid *s, long c, const double *u, double *theta, double *volume);

/* Builds the caches (volume and the boundary sets that carry conditions) from the approximation, the
 * multiplier nodes, and the sparsity pattern. Takes ownership of the condition arrays (allocated with
 * MICA_MALLOC), their functions and the body-force functions, whether it succeeds or fails. */
int mica_solid_create(const MicaDiscretization *disc, const MicaApprox *approx, const MicaSolidOptions *opt,
                      int ndirichlet, MicaDirichlet *dirichlet, int ntraction, MicaTraction *traction,
                      MicaSolid **solid);
/* The same, taking the shape-function caches (volume, and boundary sets) from donor where donor was built on
 * the same discretization and approximation with the same derivative order (and, for the volume, the same VCI
 * setting): a run that changes only the model's constants, the loads or the conditions computes no shape
 * function. The caches are shared, so donor may be destroyed before or after the new solid. */
int mica_solid_create_sharing(const MicaDiscretization *disc, const MicaApprox *approx, const MicaSolidOptions *opt,
                              int ndirichlet, MicaDirichlet *dirichlet, int ntraction, MicaTraction *traction,
                              const MicaSolid *donor, MicaSolid **solid);
int mica_solid_destroy(MicaSolid **solid);
/* Destroys what mica_solid_create takes: the body-force functions body[MICA_MAX_COMP] (body may be NULL), the
 * conditions' functions and the two arrays (NULLed; either may be NULL): for a caller whose conditions never
 * reached a solid, and for the solid itself. */
void mica_solid_conditions_free(MicaFunction **body, int ndirichlet, MicaDirichlet **dirichlet, int ntraction,
                                MicaTraction **traction);

/* 1 if the tangent is symmetric positive definite (CHOLMOD applies): the boundary method keeps it so and the
 * test functions are the trial functions (no VCI). */
int mica_solid_symmetric_definite(const MicaSolid *s);
/* The tangent is unsymmetric only by VCI's corrected test gradients and the boundary method is SPD: its
 * symmetric part is (close to) the SPD Galerkin tangent, and cholmod-sym solves it (solid_newton.c). */
int mica_solid_nearly_symmetric(const MicaSolid *s);

/* 1 if the residual is affine in u, R(u) = K u − f, so that R(u + Δu) = R(u) + K Δu exactly (Newton takes the
 * residual after a solve from the tangent, mica_newton_solve): a model with linear kinematics and a quadratic
 * energy (classical "linear", small-strain Cosserat, strain gradient), dead loads, and the weak boundary
 * methods (all linear in u); serial runs only (in parallel the tangent is distributed). */
int mica_solid_linear(const MicaSolid *s);

/* Residual R(u; t) = internal − external forces + boundary-method terms, and (if K != NULL) the tangent
 * into K (zeroed first). */
int mica_solid_assemble(MicaSolid *s, double t, const double *u, double *R, MicaSparse *K);

/* Shape-function entries per unknown in the model's q (mica/model.h): the value if the energy uses it, the dim
 * first derivatives, and the Hessian's dim(dim+1)/2 entries for a second-order model — the field kernel's nd
 * (mica/kernel.h); dim for a classical model. */
int mica_solid_shape_entries(const MicaSolid *s);

/* The general (slot-based) element stiffness at point p of cache c: Ke[(k c)(l d)] = w Σ_ij B_i(k,c) D_ij B_j(l,d),
 * row-major m × m (m = support × ncomp), rows test functions; G is m × nq scratch. The classical kernel
 * (mica/kernel.h) must agree with it (tests/unit/test_kernel.c). */
void mica_solid_element_stiffness(const MicaSolid *s, const MicaShapeCache *c, long p, const double *D, double w,
                                  double *G, double *Ke);

/* The generalized kinematics q (values, gradients, Hessians of the ncomp unknowns; layout of mica/model.h)
 * at point p of cache c for particle parameters u. */
void mica_solid_kinematics(const MicaSolid *s, const MicaShapeCache *c, long p, const double *u, double *q);

/* Deformation gradient F = I + ∇u (the first dim components) at point p of cache c. */
void mica_solid_deformation_gradient(const MicaSolid *s, const MicaShapeCache *c, long p, const double *u, double *F);


/* ---- Newton -------------------------------------------------------------------------------------------- */

/* The solid as a problem for Newton (src/assemble/solid_newton.c): residual and tangent by mica_solid_assemble,
 * affine by mica_solid_linear, the linear solver on the run's distribution under MPI, CHOLMOD preferred when the
 * tangent is symmetric positive definite (UMFPACK its fallback if it is not), and the deck error of a singular
 * first tangent. Holds pointers into s only. */
void mica_solid_nonlinear_problem(MicaSolid *s, MicaNonlinearProblem *problem);

/* mica_nonlinear_solve (mica/newton.h) on mica_solid_nonlinear_problem(s). */
int mica_newton_solve(MicaSolid *s, const MicaNewtonOptions *opt, double *u,
                      int (*on_step)(void *ctx, int step, double t, const double *u), void *ctx,
                      MicaNewtonStats *stats);

#endif
