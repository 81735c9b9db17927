/* Internal interface of `mica stability` (src/app/stability*.c; docs/theory.md §stability).
 *
 *   stability.c        the command: options, the eigen-mode analysis, the moment-matrix conditioning
 *   stability_patch.c  linear and quadratic patch tests on the deck's discretization and method
 *   stability_infsup.c the numerical inf-sup test (Chapelle & Bathe 1993) over a refinement series
 *   stability_reference.c the deck integrated by an adequate Gauss rule: the scale of low-energy modes
 *   stability_output.c eigenvalues.csv, inf_sup.csv, their charts, the VTU files of mode shapes
 */
#ifndef MICA_STABILITY_H
#define MICA_STABILITY_H

#include "run.h"

typedef enum { STABILITY_DENSE = 0, STABILITY_SPARSE = 1, STABILITY_AUTO = 2 } StabilitySolver;

typedef struct StabilityOptions {
  int eigen, patch, inf_sup, conditioning, chart;
  StabilitySolver solver;
  long dense_max_dofs, modes, max_iterations, vtu_modes;
  double zero_tol, shift, tol;
  int reference;             /* stability.reference = "gauss" (1) or "none" (0) */
  long reference_order;      /* Gauss points per direction per cell of the reference, at least */
  double low_energy_ratio;   /* ρ: a mode below λ₁,ref is a low-energy spurious one when λ < ρ · its reference energy */
  long *inf_sup_counts; /* [ninf_sup], owned: stability_free_options */
  int ninf_sup;
} StabilityOptions;

/* Kinds of eigenvalues in eigenvalues.csv. Within the zero cluster the first rigid_modes rows are called
 * rigid and the rest spurious: the cluster's eigenvalues are round-off, so only the counts mean something. */
typedef enum { MODE_RIGID = 0, MODE_SPURIOUS = 1, MODE_NONZERO = 2, MODE_LOW_ENERGY = 3 } ModeKind;

typedef struct EigenResult {
  long ndof;
  int nvalues;        /* eigenvalues computed (dense: all) */
  double *lambda;     /* [nvalues], ascending */
  ModeKind *kind;     /* [nvalues] */
  double lambda_max;  /* dense: the largest eigenvalue; sparse: a Lanczos estimate (a lower bound) */
  int zero, rigid, spurious_zero; /* spurious_zero = zero − rigid */
  int low_energy;     /* low-energy spurious modes: nonzero, λ < λ₁,ref and energy ratio < ρ (docs/theory.md) */
  int spurious;       /* spurious_zero + low_energy */
  double band;        /* λ₁,ref: the top of the band where low-energy modes are sought (0: no reference) */
  double *energy_ratio; /* [nvalues]: λ_k / (v_kᵀ K_ref v_k) for the nonzero modes in the band, NAN elsewhere */
  double ratio_min;   /* the smallest energy ratio in the band (NAN: no mode in it) */
  int in_band;        /* nonzero modes below λ₁,ref */
  double rigid_cos_min; /* smallest cosine between a rigid motion and the zero space (1: all inside) */
} EigenResult;

/* The deck's approximation integrated by an adequate Gauss rule (stability_reference.c). */
typedef struct StabilityReference {
  int self;               /* the deck's own rule is adequate: it is the reference */
  int built;              /* rp holds a problem to free */
  MicaDeck *deck;         /* the reference deck (NULL when self) */
  RunProblem rp;          /* the reference problem (when not self) */
  const MicaSparse *K;    /* the reference tangent at u = 0 */
  double lambda_max;
  int zero;               /* its zero modes */
  double lambda1;         /* its lowest nonzero eigenvalue λ₁,ref */
} StabilityReference;

typedef struct InfSupRow {
  long count[3];   /* particles per axis */
  long particles, constrained, nfree, nquad;
  int zero;        /* zero eigenvalues of G v = λ S v (divergence-free discrete fields) */
  double beta;     /* sqrt of the smallest nonzero eigenvalue */
  double lambda_max;
  long pressure_modes; /* k − (n_u − n_p + 1) with n_p = nquad (docs/theory.md §stability) */
} InfSupRow;

int stability_read_options(const MicaDeck *deck, StabilityOptions *opt);
void stability_free_options(StabilityOptions *opt);

int stability_eigen(const StabilityOptions *opt, RunProblem *rp, const char *outdir, MicaJson *summary);
int stability_conditioning(RunProblem *rp, MicaJson *summary);
int stability_patch(const StabilityOptions *opt, RunProblem *rp, MicaJson *summary);
int stability_inf_sup(const StabilityOptions *opt, const MicaDeck *deck, const char *outdir, MicaJson *summary);

int stability_reference_create(const StabilityOptions *opt, RunProblem *rp, StabilityReference *ref);
void stability_reference_destroy(StabilityReference *ref);
/* λ₁,ref (and the reference's zero modes) when the reference is not the deck itself; nrigid: rigid motions. */
int stability_reference_spectrum(const StabilityOptions *opt, int dense, int nrigid, StabilityReference *ref);
/* The Rayleigh quotient vᵀ K_ref v / vᵀ v (work: n doubles). */
double stability_reference_energy(const StabilityReference *ref, const double *v, double *work);

/* Outputs (stability_output.c). */
int stability_write_eigenvalues(const EigenResult *r, double zero_tol, const char *outdir, int chart);
int stability_write_inf_sup(const InfSupRow *rows, int nrows, const char *outdir, int chart);
/* A mode (particle parameters u, ndof) as VTU at the particles: u_h(x_I) = Σ N_J(x_I) u_J, scaled to a largest
 * displacement of 1, in DIR/name. */
int stability_write_mode(RunProblem *rp, const double *u, const char *outdir, const char *name, double eigenvalue);

#endif
