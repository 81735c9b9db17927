/* solver.parallel = schwarz: overlapping additive Schwarz preconditioned CG (symmetric positive definite
 * tangents, CHOLMOD in the subdomains) or restarted GMRES (otherwise, UMFPACK in the subdomains).
 *
 * Subdomain s: the particles of part s plus `overlap` layers of graph neighbors (particles sharing a
 * quadrature point), and the extra nodes (Lagrange multipliers) coupled to a particle of part s. Its matrix
 * A_s = R_s A R_sᵀ is assembled on rank s from every rank's contributions (redistribute.c) and factored
 * once per Newton iteration, with the symbolic analysis reused. The preconditioner is
 *   M⁻¹ r = Σ_s R_sᵀ A_s⁻¹ R_s r   (symmetric: CG may use it),
 * the matrix-vector product y = Σ_r L_r x with L_r rank r's contributions. Vectors are replicated: each
 * product and each preconditioning is one reduction of an n-vector (MPI_Reduce + MPI_Bcast, so every rank
 * holds bitwise the same vectors and takes the same decisions). */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/timer.h"
#include "parallel_private.h"

enum { RESTART = 30 };

typedef struct {
  long n;            /* global dofs */
  long nsub;         /* dofs of this rank's subdomain */
  long *dofs;        /* [nsub] their global numbers */
  double *rs, *zs;   /* [nsub] restricted vectors */
  double *work;      /* Krylov vectors */
} Krylov;

static void krylov_free(Krylov *k) {
  if (!k) return;
  free(k->dofs), free(k->rs), free(k->zs), free(k->work);
  k->dofs = NULL, k->rs = k->zs = k->work = NULL;
}

/* member[s]: the node sets of all subdomains (every rank computes all of them: the graph is replicated). */
static int subdomain_sets(ParallelSolver *ps, const MicaSparse *L, char **member, int ierr) {
  const MicaPartition *p = ps->dist->partition;
  const int P = mica_parallel_size(), ndof = L->ndof;
  const long nnodes = L->n / ndof, nextra = nnodes - p->n;
  for (int s = 0; s < P && !ierr && member; s++) {
    ierr = MICA_CALLOC(member[s], nnodes + 1);
    if (!ierr) ierr = mica_partition_overlap(p, s, ps->dist->opt.overlap, member[s]);
  }
  unsigned char *coupled = NULL; /* [P][nextra]: extra node coupled to a particle of part s */
  if (!ierr && nextra > 0) ierr = MICA_CALLOC(coupled, (long)P * nextra);
  ierr = mica_parallel_agree(ierr); /* before the reduction below */
  if (ierr || nextra <= 0) {
    free(coupled);
    return ierr;
  }
  for (long m = 0; m < nextra; m++) {
    const long j = (p->n + m) * ndof;
    for (long q = L->colptr[j]; q < L->colptr[j + 1]; q++) {
      const long node = L->rowind[q] / ndof;
      if (node < p->n) coupled[(long)p->part[node] * nextra + m] = 1;
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, coupled, (int)((long)P * nextra), MPI_UNSIGNED_CHAR, MPI_MAX, mica_parallel_comm());
  for (long m = 0; m < nextra; m++) {
    int any = 0;
    for (int s = 0; s < P; s++) any |= member[s][p->n + m] = coupled[(long)s * nextra + m];
    if (!any) member[0][p->n + m] = 1;
  }
  free(coupled);
  return MICA_SUCCESS;
}

static int schwarz_setup(ParallelSolver *ps, const MicaSparse *L) {
  const int P = mica_parallel_size(), me = mica_parallel_rank(), ndof = L->ndof;
  const long nnodes = L->n / ndof;
  char **member = NULL;
  Krylov *k = ps->krylov;
  int ierr = MICA_SUCCESS;
  redistribution_destroy(&ps->rd);
  mica_linear_solver_destroy(&ps->inner);
  if (!k) {
    ierr = MICA_CALLOC(k, 1);
    ps->krylov = k;
  }
  krylov_free(k);
  if (!ierr) ierr = MICA_CALLOC(member, P);
  ierr = subdomain_sets(ps, L, member, ierr); /* collective */
  if (!ierr) ierr = redistribution_create(L, (const char *const *)member, nnodes, &ps->rd);
  if (!ierr) {
    k->n = L->n;
    k->nsub = 0;
    for (long i = 0; i < nnodes; i++) k->nsub += member[me][i] ? ndof : 0;
    ierr = MICA_MALLOC(k->dofs, k->nsub + 1);
    if (!ierr) ierr = MICA_MALLOC(k->rs, k->nsub + 1);
    if (!ierr) ierr = MICA_MALLOC(k->zs, k->nsub + 1);
    /* CG keeps 4 vectors, GMRES(m) 2m + 4 (64 n doubles: 0.5 GB per rank at 10⁶ dofs) */
    const long nvectors = mica_linear_solver_has(ps->inner_ops, MICA_LINEAR_SPD_ONLY) ? 4 : 2L * RESTART + 4;
    if (!ierr) ierr = MICA_MALLOC(k->work, nvectors * L->n);
    long d = 0;
    for (long i = 0; i < nnodes && !ierr; i++)
      if (member[me][i])
        for (int c = 0; c < ndof; c++) k->dofs[d++] = i * ndof + c;
  }
  if (member)
    for (int s = 0; s < P; s++) free(member[s]);
  free(member);
  MICA_CALL(mica_parallel_agree(ierr));
  long range[2] = {k->nsub, -k->nsub};
  MPI_Allreduce(MPI_IN_PLACE, range, 2, MPI_LONG, MPI_MAX, mica_parallel_comm());
  ps->dist->stats.subdomain_dofs_max = range[0];
  ps->dist->stats.subdomain_dofs_min = -range[1];
  ps->pattern_n = L->n, ps->pattern_nnz = L->nnz;
  return MICA_SUCCESS;
}

static int schwarz_factor(MicaLinearSolver *solver, const MicaSparse *L) {
  ParallelSolver *ps = solver->data;
  if (!ps->rd || ps->pattern_n != L->n || ps->pattern_nnz != L->nnz) MICA_CALL(schwarz_setup(ps, L));
  const double start = mica_wtime();
  MICA_CALL(redistribution_move(ps->rd, mica_parallel_inject("solve"), L));
  ps->dist->stats.time_gather += mica_wtime() - start;
  ps->L = L;
  int ierr = MICA_SUCCESS;
  if (!ps->inner) ierr = mica_linear_solver_create(ps->inner_ops, &ps->inner);
  if (!ierr) {
    const double before = ps->inner->stats.time_analyze;
    ierr = mica_linear_solver_factor(ps->inner, ps->rd->A);
    solver->stats.time_analyze += ps->inner->stats.time_analyze - before;
    solver->stats.analyses = ps->inner->stats.analyses;
    solver->stats.nnz_factor = ps->inner->stats.nnz_factor; /* rank 0's subdomain */
    solver->stats.flops = ps->inner->stats.flops;
  }
  if (ierr) mica_error_prefix("subdomain of rank %d", mica_parallel_rank());
  MICA_CALL(mica_parallel_agree(ierr));
  return MICA_SUCCESS;
}

/* ---- the operators ---------------------------------------------------------------------------------------- */

static int apply_matrix(ParallelSolver *ps, const double *x, double *y) {
  mica_sparse_matvec(ps->L, x, y);
  return mica_parallel_sum(MICA_SUCCESS, y, ps->L->n);
}

static int apply_preconditioner(ParallelSolver *ps, const double *r, double *z) {
  Krylov *k = ps->krylov;
  for (long i = 0; i < k->nsub; i++) k->rs[i] = r[k->dofs[i]];
  int ierr = mica_linear_solver_solve(ps->inner, k->rs, k->zs);
  memset(z, 0, sizeof(double) * (size_t)k->n);
  if (!ierr)
    for (long i = 0; i < k->nsub; i++) z[k->dofs[i]] = k->zs[i];
  return mica_parallel_sum(ierr, z, k->n);
}

static double dot(long n, const double *a, const double *b) {
  double s = 0;
  for (long i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

/* ---- CG ----------------------------------------------------------------------------------------------------- */

static int cg(ParallelSolver *ps, const double *b, double *x, double tol, int max_it, int *iterations,
              double *residual) {
  const long n = ps->L->n;
  double *r = ((Krylov *)ps->krylov)->work, *z = r + n, *p = z + n, *q = p + n;
  memset(x, 0, sizeof(double) * (size_t)n);
  memcpy(r, b, sizeof(double) * (size_t)n);
  double rnorm = sqrt(dot(n, r, r));
  *iterations = 0;
  *residual = rnorm;
  if (rnorm <= tol) return MICA_SUCCESS;
  MICA_CALL(apply_preconditioner(ps, r, z));
  memcpy(p, z, sizeof(double) * (size_t)n);
  double rz = dot(n, r, z);
  for (int it = 1; it <= max_it; it++) {
    MICA_CALL(apply_matrix(ps, p, q));
    const double pq = dot(n, p, q);
    if (!(pq > 0)) MICA_ERROR(MICA_ERR_NUMERIC, "Schwarz-CG: the tangent is not positive definite (pᵀAp = %g)", pq);
    const double alpha = rz / pq;
    for (long i = 0; i < n; i++) x[i] += alpha * p[i], r[i] -= alpha * q[i];
    rnorm = sqrt(dot(n, r, r));
    *iterations = it;
    *residual = rnorm;
    if (rnorm <= tol) return MICA_SUCCESS;
    MICA_CALL(apply_preconditioner(ps, r, z));
    const double rz_new = dot(n, r, z), beta = rz_new / rz;
    rz = rz_new;
    for (long i = 0; i < n; i++) p[i] = z[i] + beta * p[i];
  }
  MICA_ERROR(MICA_ERR_NUMERIC, "Schwarz-CG did not converge in %d iterations (|r| %.3e, wanted %.3e)", max_it, rnorm,
             tol);
}

/* ---- GMRES(m), right preconditioned: the residual it monitors is the true one ----------------------------- */

static int gmres(ParallelSolver *ps, const double *b, double *x, double tol, int max_it, int *iterations,
                 double *residual) {
  const long n = ps->L->n;
  const int m = RESTART;
  double *V = ((Krylov *)ps->krylov)->work, *Z = V + (long)(m + 1) * n, *w = Z + (long)m * n;
  double H[RESTART + 1][RESTART], g[RESTART + 1], cs[RESTART], sn[RESTART], y[RESTART];
  memset(x, 0, sizeof(double) * (size_t)n);
  *iterations = 0;
  double rnorm = sqrt(dot(n, b, b));
  *residual = rnorm;
  if (rnorm <= tol) return MICA_SUCCESS;
  int total = 0;
  while (total < max_it) {
    /* r = b − A x into V[0] */
    MICA_CALL(apply_matrix(ps, x, w));
    for (long i = 0; i < n; i++) V[i] = b[i] - w[i];
    const double beta = sqrt(dot(n, V, V));
    if (beta <= tol) {
      *residual = beta;
      return MICA_SUCCESS;
    }
    for (long i = 0; i < n; i++) V[i] /= beta;
    memset(g, 0, sizeof g);
    g[0] = beta;
    int j = 0;
    for (; j < m && total < max_it; j++) {
      double *vj = V + (long)j * n, *zj = Z + (long)j * n, *vn = V + (long)(j + 1) * n;
      MICA_CALL(apply_preconditioner(ps, vj, zj));
      MICA_CALL(apply_matrix(ps, zj, vn));
      for (int i = 0; i <= j; i++) { /* modified Gram–Schmidt */
        const double *vi = V + (long)i * n;
        H[i][j] = dot(n, vn, vi);
        for (long l = 0; l < n; l++) vn[l] -= H[i][j] * vi[l];
      }
      H[j + 1][j] = sqrt(dot(n, vn, vn));
      if (H[j + 1][j] > 0)
        for (long l = 0; l < n; l++) vn[l] /= H[j + 1][j];
      for (int i = 0; i < j; i++) { /* earlier rotations */
        const double t = cs[i] * H[i][j] + sn[i] * H[i + 1][j];
        H[i + 1][j] = -sn[i] * H[i][j] + cs[i] * H[i + 1][j];
        H[i][j] = t;
      }
      const double r = hypot(H[j][j], H[j + 1][j]);
      cs[j] = r > 0 ? H[j][j] / r : 1.0;
      sn[j] = r > 0 ? H[j + 1][j] / r : 0.0;
      H[j][j] = r;
      H[j + 1][j] = 0;
      g[j + 1] = -sn[j] * g[j];
      g[j] = cs[j] * g[j];
      total++;
      rnorm = fabs(g[j + 1]);
      if (rnorm <= tol) {
        j++;
        break;
      }
    }
    for (int i = j - 1; i >= 0; i--) { /* H y = g, upper triangular */
      double s = g[i];
      for (int l = i + 1; l < j; l++) s -= H[i][l] * y[l];
      if (H[i][i] == 0) MICA_ERROR(MICA_ERR_NUMERIC, "Schwarz-GMRES broke down (singular Hessenberg matrix)");
      y[i] = s / H[i][i];
    }
    for (int i = 0; i < j; i++) {
      const double *zi = Z + (long)i * n;
      for (long l = 0; l < n; l++) x[l] += y[i] * zi[l];
    }
    *iterations = total;
    *residual = rnorm;
    if (rnorm <= tol) return MICA_SUCCESS;
  }
  MICA_ERROR(MICA_ERR_NUMERIC, "Schwarz-GMRES did not converge in %d iterations (|r| %.3e, wanted %.3e)", max_it,
             rnorm, tol);
}

static int schwarz_solve(MicaLinearSolver *solver, const double *b, double *x) {
  ParallelSolver *ps = solver->data;
  MicaParallelStats *st = &ps->dist->stats;
  const MicaParallelOptions *opt = &ps->dist->opt;
  const int use_cg = mica_linear_solver_has(ps->inner_ops, MICA_LINEAR_SPD_ONLY); /* SPD subdomains: CG */
  const double tol = opt->rtol * sqrt(dot(ps->L->n, b, b));
  int iterations = 0;
  double residual = 0;
  const int ierr = (use_cg ? cg : gmres)(ps, b, x, tol, opt->max_iterations, &iterations, &residual);
  st->krylov_solves++;
  st->krylov_iterations += iterations;
  if (iterations > st->krylov_max_iterations) st->krylov_max_iterations = iterations;
  st->krylov_last_residual = residual;
  if (opt->verbose)
    printf("    schwarz-%s: %d iterations, |r| %.3e (tolerance %.3e)\n", use_cg ? "cg" : "gmres", iterations, residual,
           tol);
  return mica_parallel_agree(ierr); /* the same on every rank: the same steps on the same vectors */
}

static void schwarz_destroy(MicaLinearSolver *solver) {
  ParallelSolver *ps = solver->data;
  if (ps) krylov_free(ps->krylov);
  parallel_solver_destroy(solver);
}

const MicaLinearSolverOps mica_linear_schwarz = {
    {"schwarz", "additive Schwarz CG (SPD subdomains) or GMRES", MICA_LINEAR_ITERATIVE, NULL, NULL},
    parallel_solver_create, schwarz_factor, schwarz_solve,
                                                 schwarz_destroy};
