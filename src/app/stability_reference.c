/* The reference spectrum of `mica stability` (docs/theory.md §Stability studies, "low-energy modes").
 *
 * Direct nodal integration and SCNI with MLS shape functions have no exact zero modes beyond the rigid ones,
 * but they can have a band of modes whose energy is far below what the same approximation has when it is
 * integrated adequately. To tell such modes from the low end of a stable spectrum the deck is built a second
 * time with the same particles and MLS (or elements) and an adequate Gauss rule: quadrature.mode = "gauss",
 * quadrature.order = max(deck's, stability.reference_order), no VCI. Its tangent K_ref at u = 0 and its lowest
 * nonzero eigenvalue λ₁,ref are the scale against which stability_eigen counts low-energy modes. A deck that
 * already integrates so is its own reference (no second problem). The eigenvalues of K alone (unit parameter
 * norm) depend on the MLS support as much as on the integration — a wide support smooths oscillating
 * parameter vectors into fields of little strain — so the reference must share the deck's approximation.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/eigen.h"
#include "stability.h"

/* Is the deck's own rule an adequate reference? Gauss points (or elements), order ≥ the reference order. */
static int deck_is_reference(const StabilityOptions *o, const MicaDeck *deck, int *self) {
  unsigned mode;
  long order;
  int vci;
  const char *word;
  MICA_CALL(run_integration_flags(deck, &mode));
  MICA_CALL(mica_deck_int(deck, "quadrature.order", &order));
  MICA_CALL(mica_deck_bool_or_word(deck, "quadrature.vci", &vci, &word)); /* "auto": off in mica stability */
  *self = !(mode & RUN_INTEGRATION_NODAL) && order >= o->reference_order && vci != 1;
  return MICA_SUCCESS;
}

/* The deck with the user's overrides and the reference rule on top. */
static int reference_deck(const StabilityOptions *o, const MicaDeck *deck, MicaDeck **out) {
  long order;
  char text[3][96];
  MICA_CALL(mica_deck_int(deck, "quadrature.order", &order));
  snprintf(text[0], sizeof text[0], "quadrature.mode=gauss");
  snprintf(text[1], sizeof text[1], "quadrature.order=%ld", order > o->reference_order ? order : o->reference_order);
  snprintf(text[2], sizeof text[2], "quadrature.vci=false");
  const int nuser = mica_deck_override_count(deck), total = nuser + 3;
  const char **all = NULL;
  MICA_CALL(MICA_MALLOC(all, total));
  for (int i = 0; i < nuser; i++) all[i] = mica_deck_override_text(deck, i);
  for (int i = 0; i < 3; i++) all[nuser + i] = text[i];
  const int ierr = mica_deck_load(mica_deck_path(deck), mica_run_schema, total, all, out);
  free(all);
  return ierr;
}

/* The reference must have the deck's unknowns at the deck's particles, or its modes are other fields. */
static int check_same_unknowns(const RunProblem *rp, const RunProblem *ref) {
  const long np = rp->disc->nparticles;
  const int dim = rp->disc->dim;
  MICA_CHECK(ref->disc->nparticles == np && ref->solid->ndof == rp->solid->ndof, MICA_ERR_NUMERIC,
             "stability reference: the Gauss-integrated deck has %ld particles and %ld unknowns, the deck %ld and %ld",
             ref->disc->nparticles, ref->solid->ndof, np, rp->solid->ndof);
  for (long i = 0; i < np * dim; i++)
    MICA_CHECK(ref->disc->x[i] == rp->disc->x[i], MICA_ERR_NUMERIC,
               "stability reference: particle %ld lies elsewhere in the Gauss-integrated deck", i / dim + 1);
  return MICA_SUCCESS;
}

int stability_reference_create(const StabilityOptions *o, RunProblem *rp, StabilityReference *ref) {
  double *u = NULL, *R = NULL;
  int ierr = MICA_SUCCESS;
  memset(ref, 0, sizeof *ref);
  ref->lambda1 = NAN;
  MICA_CALL(deck_is_reference(o, rp->deck, &ref->self));
  if (ref->self) {
    ref->K = rp->solid->K;
    return MICA_SUCCESS;
  }
  MICA_CALL(reference_deck(o, rp->deck, &ref->deck));
  MICA_CALL(run_problem_build(ref->deck, &ref->rp));
  ref->built = 1;
  MICA_CALL(check_same_unknowns(rp, &ref->rp));
  const long n = ref->rp.solid->ndof;
  MICA_CALL_CLEANUP(MICA_CALLOC(u, n));
  MICA_CALL_CLEANUP(MICA_CALLOC(R, n));
  MICA_CALL_CLEANUP(mica_solid_assemble(ref->rp.solid, 1.0, u, R, ref->rp.solid->K));
  ref->K = ref->rp.solid->K;
cleanup:
  free(u), free(R);
  return ierr;
}

void stability_reference_destroy(StabilityReference *ref) {
  if (ref->built) run_problem_free(&ref->rp);
  mica_deck_destroy(&ref->deck);
  memset(ref, 0, sizeof *ref);
}

/* λ₁,ref of a reference that is not the deck: dense, all eigenvalues; sparse, the nrigid + 4 lowest by
 * shift-invert (enough when the reference has no spurious zero modes, which is checked). */
int stability_reference_spectrum(const StabilityOptions *o, int dense, int nrigid, StabilityReference *ref) {
  const MicaSparse *K = ref->K;
  const long n = K->n;
  double *lambda = NULL, *A = NULL;
  int nvalues = 0, ierr = MICA_SUCCESS;
  if (dense) {
    MICA_CALL_CLEANUP(MICA_MALLOC(A, (size_t)n * n));
    MICA_CALL_CLEANUP(MICA_MALLOC(lambda, n));
    MICA_CALL_CLEANUP(mica_sparse_to_dense(K, A));
    MICA_CALL_CLEANUP(mica_eigen_dense((int)n, A, lambda, NULL));
    nvalues = (int)n;
    ref->lambda_max = lambda[n - 1];
  } else {
    MICA_CALL_CLEANUP(mica_eigen_largest(K, 80, 11, &ref->lambda_max));
    MicaEigenOptions eo = {0};
    MicaEigenStats st;
    eo.nev = (int)(nrigid + 4 < n ? nrigid + 4 : n);
    eo.sigma = -o->shift * ref->lambda_max;
    eo.tol = o->tol, eo.scale = ref->lambda_max, eo.max_iterations = (int)o->max_iterations, eo.seed = 7;
    MICA_CALL_CLEANUP(MICA_MALLOC(lambda, eo.nev));
    MICA_CALL_CLEANUP(mica_eigen_shift_invert(K, &eo, lambda, NULL, &st));
    nvalues = eo.nev;
  }
  const double threshold = o->zero_tol * ref->lambda_max;
  while (ref->zero < nvalues && fabs(lambda[ref->zero]) <= threshold) ref->zero++;
  if (ref->zero > nrigid || ref->zero == nvalues) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_NUMERIC,
                          "stability reference (Gauss order %ld): %d zero modes, more than the %d rigid motions: the "
                          "reference rule is not adequate for this approximation; raise stability.reference_order "
                          "or set stability.reference = \"none\"", o->reference_order, ref->zero, nrigid);
    goto cleanup;
  }
  ref->lambda1 = lambda[ref->zero];
cleanup:
  free(lambda), free(A);
  return ierr;
}

double stability_reference_energy(const StabilityReference *ref, const double *v, double *work) {
  const long n = ref->K->n;
  double e = 0, norm = 0;
  mica_sparse_matvec(ref->K, v, work);
  for (long i = 0; i < n; i++) e += v[i] * work[i], norm += v[i] * v[i];
  return norm > 0 ? e / norm : 0;
}
