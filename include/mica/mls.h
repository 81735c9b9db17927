/* The MLS approximation library: moving-least-squares shape functions and their derivatives.
 *
 * Standalone: depends on libc, LAPACK and mica/error.h only (src/util/error.c), so it can be used and
 * tested without the solver. Formulas: docs/theory.md §MLS (seed 001, eqs 3.1-3.18, 3.26-3.40).
 *
 *   N_I(x) = P(0)ᵀ M(x)⁻¹ P((x − x_I)/s) Φ_I(x),   M(x) = Σ_I P((x − x_I)/s) P((x − x_I)/s)ᵀ Φ_I(x)
 *
 * with the basis shifted to the evaluation point and scaled per axis by s (twice the weighted spread of the
 * supporting particles, so the particles that carry weight have scaled coordinates in about [−1, 1]). For
 * bases whose span is invariant under per-axis affine maps (all of ours), N does not depend on s: the
 * scaling only keeps M well conditioned. M is equilibrated (Jacobi scaling, so that the condition estimate does not depend on how
 * a basis is scaled) and factored once per point (Cholesky); the derivatives of
 * b = M⁻¹P(0) follow from the same factor (eqs 3.17, 3.18). M⁻¹ is never formed.
 *
 * Typical use:
 *   MlsOptions opt; mls_options_default(&opt); opt.order = 2; opt.dilation = 2.5;
 *   MlsApprox *mls; MICA_CALL(mls_create(3, n, xyz, &opt, &mls));
 *   MlsShape *sh;   MICA_CALL(mls_shape_create(mls, &sh));
 *   MICA_CALL(mls_eval(mls, point, MLS_HESSIAN, sh));   // sh->n, sh->index, sh->N, sh->dN, sh->ddN
 */
#ifndef MICA_MLS_H
#define MICA_MLS_H

#include "mica/error.h"
#include "mica/registry.h"

#define MLS_MAX_DIM 3
#define MLS_MAX_HESS 6 /* packed symmetric second derivatives in 3-D */

/* Number of packed second derivatives in dim dimensions, and their order (Voigt):
 * 1-D: xx;  2-D: xx, yy, xy;  3-D: xx, yy, zz, yz, xz, xy. */
static inline int mls_num_hess(int dim) { return dim * (dim + 1) / 2; }
static inline int mls_hess_index(int dim, int i, int j) {
  if (i == j) return i;
  if (dim == 2) return 2;
  return 6 - i - j; /* 3-D: (1,2)->3, (0,2)->4, (0,1)->5 */
}

/* ---- Bases (ops table) ----------------------------------------------------------------------------
 * A basis is evaluated at the scaled, shifted coordinate s = (x − x_I)/scale, mostly in [−1, 1]^dim. Pascal:
 * complete polynomials of total degree ≤ order (order 0-3). Lagrange, Bernstein: tensor products of 1-D
 * polynomials of degree ≤ order per axis (order 1-3); Lagrange on equally spaced nodes in [−1, 1],
 * Bernstein in t = (s + 1)/2 ∈ [0, 1] (eq 3.40 with x^I for the misprinted x). */
typedef struct MlsBasisOps {
  MicaType type; /* name, description (no flags or settings of its own: mls.order is every basis's) */
  int min_order, max_order;
  int (*size)(int dim, int order); /* number of terms m */
  /* p[a] = P_a(s); if dp: dp[d*m + a] = ∂P_a/∂s_d; if ddp: ddp[h*m + a] = ∂²P_a/∂s_i∂s_j, h packed. */
  void (*eval)(int dim, int order, const double *s, double *p, double *dp, double *ddp);
} MlsBasisOps;

extern const MlsBasisOps mls_basis_pascal, mls_basis_lagrange, mls_basis_bernstein;
/* The bases: `mls.basis` chooses one; the default is named here only. */
extern MicaRegistry mls_basis_registry;
static inline const MlsBasisOps *mls_basis_of(const MicaType *type) { return (const MlsBasisOps *)type; }
/* The i-th registered basis (NULL past the last), and lookup by name (NULL if unknown). */
const MlsBasisOps *mls_basis_at(int i);
const MlsBasisOps *mls_basis_find(const char *name);

/* ---- Weights (ops table) --------------------------------------------------------------------------
 * A 1-D kernel w(r) of the normalized distance r = |x − x_I|/ρ ≥ 0, zero for r ≥ 1. Box supports use
 * Φ = Π_d w(r_d) (eq 3.29), ball supports Φ = w(|x − x_I|/ρ). */
/* Capability flags of a weight (MicaType.flags). */
enum {
  MLS_WEIGHT_ADAPTIVE = 1u << 0 /* uses the per-particle shape parameter (exponential): reads mls.alpha */
};

typedef struct MlsWeightOps {
  MicaType type;  /* name, description, MLS_WEIGHT_* flags, own settings (under mls.) */
  int continuity; /* C^k; −1 for the truncated Gaussian, which does not vanish at r = 1 */
  /* w[0] = w(r), w[1] = dw/dr, w[2] = d²w/dr², for r ≥ 0. param: the particle's ρ/c (exponential). */
  void (*eval)(double r, double param, double w[3]);
} MlsWeightOps;

extern const MlsWeightOps mls_weight_cubic, mls_weight_quartic, mls_weight_quartic_c3, mls_weight_gauss,
    mls_weight_exponential;
/* The weights: `mls.weight` chooses one; the default is named here only. */
extern MicaRegistry mls_weight_registry;
static inline const MlsWeightOps *mls_weight_of(const MicaType *type) { return (const MlsWeightOps *)type; }
/* The i-th registered weight (NULL past the last), and lookup by name (NULL if unknown). */
const MlsWeightOps *mls_weight_at(int i);
const MlsWeightOps *mls_weight_find(const char *name);

/* ---- Neighbor search ------------------------------------------------------------------------------
 * Which particles' supports contain a point, with a radius per particle (and per axis for boxes). */
typedef enum { MLS_SUPPORT_BOX = 0, MLS_SUPPORT_BALL = 1 } MlsSupportKind;
typedef enum { MLS_SEARCH_KDTREE = 0, MLS_SEARCH_CELLS = 1 } MlsSearchKind;

typedef struct MlsSearch MlsSearch;

/* The support shapes, search structures and spacing rules as registries of tiny types (`mls.support`,
 * `mls.search`, `mls.spacing` choose one; each registry names its default once): a name, a description and
 * the enum value the library takes (MlsSupportKind, MlsSearchKind, MlsSpacingRule). */
typedef struct MlsKindOps {
  MicaType type;
  int value;
} MlsKindOps;

extern MicaRegistry mls_support_registry, mls_search_registry, mls_spacing_registry;
static inline int mls_kind_value(const MicaType *type) { return ((const MlsKindOps *)type)->value; }

/* Builds the search structure over n particles x[n*dim] (copied). */
int mls_search_create(int dim, long n, const double *x, MlsSearchKind kind, MlsSearch **search);
int mls_search_destroy(MlsSearch **search);
/* Sets the supports: radii[i*dim + d] is particle i's radius along axis d (ball: radii[i*dim] is used).
 * Particle i supports x when max_d |x_d − x_id|/ρ_id < 1 (box) or |x − x_i|/ρ_i0 < 1 (ball). */
int mls_search_set_supports(MlsSearch *search, MlsSupportKind support, const double *radii);
/* Fills *index (capacity *cap, grown with realloc when needed) with the particles whose supports contain
 * x, in ascending order; *count is set to their number. */
int mls_search_query(const MlsSearch *search, const double *x, long **index, long *count, long *cap);
/* The k nearest other particles of particle i (k ≤ n − 1), nearest first; dist2 may be NULL. */
int mls_search_knn(const MlsSearch *search, long i, int k, long *index, double *dist2);
/* Which side's neighbor sets the local spacing along an axis (docs/theory.md §supports): on each side of a
 * particle the nearest particle whose offset points mainly along d (|Δx_d| ≥ |Δx_e| for all e);
 *   NEAR: the nearer of the two (the nearest such particle on either side),
 *   FAR:  the farther, if it is at most twice as far as the nearer (else the nearer), so that in a graded
 *         cloud supports reach as far toward the coarse side as the coarse neighbors reach back. */
typedef enum { MLS_SPACING_NEAR, MLS_SPACING_FAR } MlsSpacingRule;

/* Local spacing h[i*dim + d] per particle and axis by the rule. Regular grids give their spacing everywhere,
 * boundaries and corners included, under either rule. An axis with no such neighbor takes the largest of the
 * other axes. */
int mls_search_local_spacing_rule(const MlsSearch *search, MlsSpacingRule rule, double *h);
/* The same with MLS_SPACING_NEAR. */
int mls_search_local_spacing(const MlsSearch *search, double *h);

/* ---- The approximation ----------------------------------------------------------------------------- */
typedef struct MlsOptions {
  const MlsBasisOps *basis;   /* default pascal */
  int order;                  /* default 1 */
  const MlsWeightOps *weight; /* default quartic-c3 */
  MlsSupportKind support;     /* default box */
  double radius[MLS_MAX_DIM]; /* absolute radius per axis (ball: radius[0]); used when dilation <= 0 */
  double dilation;            /* > 0: ρ_id = dilation × h_id (box), ρ_i = dilation × max_d h_id (ball) */
  double alpha;               /* exponential weight: c_I = alpha × (largest distance from x_I to the
                                 particles whose supports contain x_I), eqs 3.34-3.36; default 1 */
  double rcond_min;           /* reciprocal condition of M below this is an error; default 1e-13 */
  MlsSearchKind search;       /* default kdtree */
  MlsSpacingRule spacing;     /* the local spacing a dilation multiplies; default near */
  const double *spacing_points; /* NULL, or [spacing_count*dim] positions the local spacing is measured on
                                   instead of the particles' (a jittered or irregular cloud's grid); particle I
                                   takes the spacing of point spacing_index[I] (NULL: point I, spacing_count =
                                   n); read by mls_create only */
  long spacing_count;           /* the number of spacing_points; 0 means n */
  const long *spacing_index;    /* NULL, or [n]: the spacing point of each particle */
} MlsOptions;

/* The defaults of mls_keys (settings.c) and of the registries, which are where they live. */
void mls_options_default(MlsOptions *opt);
/* The dilation when neither mls.radius nor mls.dilation is given: order + 1 (docs/theory.md §supports). */
static inline double mls_default_dilation(int order) { return order + 1.0; }
/* The settings of an MLS approximation, as a schema fragment (a command's schema inserts it as "mls"), and
 * their reader: the options from the settings under group, checked against each other with the deck's lines. */
extern const MicaDeckKey mls_keys[];
int mls_options_from_settings(const MicaSettings *settings, const char *group, int dim, MlsOptions *opt);

typedef struct MlsApprox MlsApprox;

/* Copies the particles x[n*dim], builds the search, and sets the radii from opt (absolute or dilation ×
 * local spacing). Checks the options (basis order range, positive radii, 1 ≤ dim ≤ 3). */
int mls_create(int dim, long n, const double *x, const MlsOptions *opt, MlsApprox **mls);
int mls_destroy(MlsApprox **mls);
/* Replaces the radii: radii[i*dim + d] (ball: radii[i*dim]). */
int mls_set_radii(MlsApprox *mls, const double *radii);
/* Replaces the local spacings (mls_spacing) without changing the radii: an approximation on a subset of a larger
 * set of particles (an MPI rank's block and ghosts) takes the whole set's, which its truncated neighborhoods
 * would not reproduce at the subset's edge. */
int mls_set_spacing(MlsApprox *mls, const double *spacing);
/* Replaces the weight's per-particle shape parameters (mls_weight_params; an adaptive weight's come from the
 * particles whose supports cover each one, which a subset's edge would truncate, as for the spacings). Call it
 * after mls_set_radii, which recomputes them. */
int mls_set_weight_params(MlsApprox *mls, const double *wparam);

int mls_dim(const MlsApprox *mls);
long mls_num_particles(const MlsApprox *mls);
int mls_num_terms(const MlsApprox *mls);
const double *mls_particles(const MlsApprox *mls); /* [n*dim] */
const double *mls_radii(const MlsApprox *mls);     /* [n*dim] */
const MlsOptions *mls_options(const MlsApprox *mls); /* as created (spacing_points NULL: it was read then) */
const double *mls_spacing(const MlsApprox *mls);   /* [n*dim], local spacing h */
const double *mls_weight_params(const MlsApprox *mls); /* [n*dim], ρ_id / c_i (adaptive weights), else 1 */
/* The neighbor search with the supports set, and the support kind (src/parallel finds supports with them). */
const MlsSearch *mls_search(const MlsApprox *mls);
MlsSupportKind mls_support_kind(const MlsApprox *mls);

/* What to compute at a point: values only, with gradients, or with gradients and Hessians. */
enum { MLS_VALUES = 0, MLS_GRADIENT = 1, MLS_HESSIAN = 2 };

/* Shape functions at one point. The arrays are owned by the shape and grow when a point has more
 * supporting particles than any before it; index, N, dN, ddN stay valid until the next mls_eval. */
typedef struct MlsShape {
  int dim, nderiv;
  long n;        /* supporting particles */
  long *index;   /* [n] particle indices, ascending */
  double *N;     /* [n] */
  double *dN;    /* [dim][n]: dN[d*n + k] = ∂N_k/∂x_d            (nderiv ≥ 1) */
  double *ddN;   /* [nhess][n]: ddN[h*n + k], h = mls_hess_index (nderiv = 2) */
  double rcond;  /* reciprocal 1-norm condition estimate of M at this point */
  long cap;      /* capacity of the per-particle arrays */
  double time_search; /* seconds spent in the neighbor search, summed over mls_eval calls (profiles) */
  void *work;    /* private workspace */
} MlsShape;

int mls_shape_create(const MlsApprox *mls, MlsShape **shape);
int mls_shape_destroy(MlsShape **shape);

/* Evaluates N (and ∇N, ∇∇N for nderiv = MLS_GRADIENT, MLS_HESSIAN) at x[dim]. A point with no support,
 * or whose moment matrix is singular or has rcond < opt.rcond_min, is a MICA_ERR_NUMERIC error naming the
 * point, its number of supporting particles, the condition estimate and the remedy. */
int mls_eval(const MlsApprox *mls, const double *x, int nderiv, MlsShape *shape);

/* The 2-norm condition number λ_max/λ_min of the equilibrated moment matrix D M D at x (D = diag(M_aa)^(−1/2):
 * the matrix mls_eval factors, whose 1-norm estimate is 1/shape->rcond), from its eigenvalues (LAPACK). Uses
 * the shape's workspace (its N, dN are not computed). A point without support or with a singular M is the
 * same MICA_ERR_NUMERIC error as mls_eval's. */
int mls_moment_condition(const MlsApprox *mls, const double *x, MlsShape *shape, double *cond);

/* u_h = Σ N_k u[index_k] and, when asked, its gradient and Hessian, for one scalar field u[n]. */
void mls_shape_apply(const MlsShape *shape, const double *u, double *uh, double *grad, double *hess);

#endif
