/* Symmetric eigenproblems for stability studies (small dense eigenproblems with LAPACK, larger
 * ones by shift-invert with the sparse factorization; docs/theory.md §stability).
 *
 * Dense: LAPACK dsyevr (all eigenvalues, optionally all eigenvectors) and dsygvd (A x = λ B x, B symmetric
 * positive definite). Sparse: the eigenvalues nearest a shift σ of a symmetric MicaSparse by shift-invert
 * block Krylov iteration with Rayleigh–Ritz: V = orth[X, A⁻¹X, A⁻²X, A⁻³X] with A = K − σI (factored once,
 * CHOLMOD or UMFPACK), Ritz pairs of K on span V, restarted from the block of Ritz vectors nearest σ until
 * every wanted pair has ‖K x − θ x‖ ≤ tol · scale. A block method, so an eigenvalue of multiplicity m (the
 * rigid-body modes of a free body) is found m times — a single-vector Lanczos would see it once.
 * Matrices are column-major; eigenvalues come out ascending.
 */
#ifndef MICA_EIGEN_H
#define MICA_EIGEN_H

#include "mica/sparse.h"

/* All eigenvalues w[n] (ascending) of the symmetric A (n×n, lower triangle read, destroyed) and, if Z is not
 * NULL, the orthonormal eigenvectors as the columns of Z (n×n). */
int mica_eigen_dense(int n, double *A, double *w, double *Z);

/* All eigenvalues of A x = λ B x, B symmetric positive definite (A, B n×n, destroyed). B not positive
 * definite is a MICA_ERR_NUMERIC error that says so. */
int mica_eigen_dense_generalized(int n, double *A, double *B, double *w);

/* The sparse matrix as a dense column-major n×n array (both triangles as stored). */
int mica_sparse_to_dense(const MicaSparse *A, double *dense);

typedef struct MicaEigenOptions {
  int nev;            /* eigenvalues wanted: the nev nearest sigma */
  int guard;          /* extra vectors in the block (0: max(nev/2, 8)); the block must be at least as wide as
                         the largest multiplicity among the wanted eigenvalues */
  double sigma;       /* shift; K − σI must be nonsingular */
  double tol;         /* converged: ‖K x − θ x‖ ≤ tol · scale for the nev wanted pairs */
  double scale;       /* the residual's scale (> 0), e.g. an estimate of λ_max */
  int max_iterations; /* restarts */
  unsigned long seed; /* of the random start block */
  const MicaLinearSolverOps *linear; /* NULL: CHOLMOD, falling back to UMFPACK if K − σI is indefinite */
} MicaEigenOptions;

typedef struct MicaEigenStats {
  int iterations;        /* restarts */
  long solves;           /* with the factor of K − σI */
  double max_residual;   /* of the wanted pairs, / scale */
  double time_factor, time_iterate;
  const char *linear_name;
  long nnz_factor;
} MicaEigenStats;

/* The opt->nev eigenvalues of the symmetric K nearest opt->sigma, ascending, into lambda[nev] and (if not
 * NULL) their orthonormal eigenvectors into vectors (n×nev, column-major). Not converged within
 * max_iterations is a MICA_ERR_NUMERIC error giving the residual reached. */
int mica_eigen_shift_invert(const MicaSparse *K, const MicaEigenOptions *opt, double *lambda, double *vectors,
                            MicaEigenStats *stats);

/* The largest eigenvalue of the symmetric K by Lanczos with full reorthogonalization (steps ≤ n Krylov
 * vectors from a seeded random start): a lower bound, exact once steps = n. It converges slowly where the
 * top of the spectrum is clustered (1-D Laplacian, n = 400: 1.6e-3 low after 20 steps, 1.5e-4 after 100):
 * good for a scale (a zero threshold), not for the value itself. */
int mica_eigen_largest(const MicaSparse *K, int steps, unsigned long seed, double *lambda_max);

#endif
