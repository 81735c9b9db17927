/* Which rigid motions of the body the Dirichlet conditions hold, from their geometry alone, before anything is
 * assembled. A body that one of them can move without strain has a singular tangent: CHOLMOD may then stop at a
 * zero pivot, or (round-off keeping the pivots nonzero) factor it and leave Newton to fail with a residual that
 * does not go down; either names nothing the user can act on.
 *
 * The rigid motions m_j: translations e_a, and rotations about the axes through x0, u = e_k × (x − x0) / L,
 * together with φ_k = 1 for models that carry micro-rotations (Cosserat, the micromorph kind R(Φ): their rigid
 * rotation turns u and φ together). Axisymmetric sections keep two: u_z = 1 and u_θ = r / L (with φ_z = 1).
 * A condition holds the motions that are nonzero in one of its prescribed components at one of its boundary
 * points, so the free ones are the null space of
 *   G_ij = Σ_(conditions, points p, prescribed components c) w_p m_i,c(x_p) m_j,c(x_p) / Σ w_p,
 * a matrix of at most 6 × 6. x0 is first the conditions' centroid, then (center_on_free_rotation) a point on the
 * axis of a free rotation, so that the null vectors are the free motions themselves, which the message names. */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mica/bc.h"
#include "mica/parallel.h"

enum { MAX_MODES = 6 };

/* An unknown as the deck names it: kind 'u' (displacement) or 'p' (micro-rotation), and its axis (x, y, z, or
 * axisymmetric r, θ, z: 0, 1, 2). */
typedef struct {
  char kind;
  int axis;
} Component;

typedef struct {
  int nmodes, ncomp, dim, axisymmetric;
  int rotation[MAX_MODES], axis[MAX_MODES]; /* mode j: a translation along, or a rotation about, axis[j] */
  Component comp[MICA_MAX_COMP];
  double x0[3], length;
  int across_ranks; /* the sets are this rank's share of a distributed body: every sum is over all ranks */
} RigidModes;

static int axis_of(const char *suffix) {
  if (!strcmp(suffix, "x") || !strcmp(suffix, "r")) return 0;
  if (!strcmp(suffix, "y") || !strcmp(suffix, "theta")) return 1;
  return 2;
}

static void parse_components(RigidModes *M, const char *const *names) {
  for (int c = 0; c < M->ncomp; c++) {
    const int rotation = !strncmp(names[c], "phi", 3);
    M->comp[c].kind = rotation ? 'p' : 'u';
    M->comp[c].axis = axis_of(names[c] + (rotation ? 3 : 1));
  }
}

static void add_mode(RigidModes *M, int rotation, int axis) {
  M->rotation[M->nmodes] = rotation, M->axis[M->nmodes] = axis;
  M->nmodes++;
}

static void list_modes(RigidModes *M) {
  if (M->axisymmetric) { /* along the axis (u_z) and about it (u_θ ∝ r) */
    add_mode(M, 0, 2);
    add_mode(M, 1, 2);
    return;
  }
  for (int a = 0; a < M->dim; a++) add_mode(M, 0, a);
  if (M->dim == 2) add_mode(M, 1, 2);
  else
    for (int k = 0; k < 3; k++) add_mode(M, 1, k);
}

/* Component c of mode j at x. */
static double mode_value(const RigidModes *M, int j, int c, const double *x) {
  const Component *k = &M->comp[c];
  const int a = M->axis[j];
  if (!M->rotation[j]) return k->kind == 'u' && k->axis == a ? 1.0 : 0.0;
  if (k->kind == 'p') return k->axis == a ? 1.0 : 0.0;
  if (M->axisymmetric) return k->axis == 1 ? x[0] / M->length : 0.0; /* u_θ = r about the axis r = 0 */
  const int i = k->axis;
  if (i == a) return 0.0;
  const int other = 3 - i - a;
  const double r = other < M->dim ? (x[other] - M->x0[other]) / M->length : 0.0;
  return (a - i + 3) % 3 == 1 ? r : -r; /* (e_a × r)_i = ε_(i a other) r_other */
}

/* Sums (and, as −min, maxima) over all ranks when the sets are shares of a distributed body: a few numbers each. */
static int reduce_sum(const RigidModes *M, double *v, long n) {
  return M->across_ranks ? mica_parallel_sum(MICA_SUCCESS, v, n) : MICA_SUCCESS;
}

static int reduce_max(const RigidModes *M, double *v, long n) {
  return M->across_ranks ? mica_parallel_max(MICA_SUCCESS, v, n) : MICA_SUCCESS;
}

/* x0: the conditions' centroid; L: the largest extent of the boundary (a length of the body). */
static int place_modes(RigidModes *M, const MicaDiscretization *disc, int ndirichlet, const MicaDirichlet *dirichlet) {
  double sums[4] = {0, 0, 0, 0}, extent[6]; /* Σ w x, Σ w; max x, max −x */
  for (int i = 0; i < 6; i++) extent[i] = -INFINITY;
  for (int c = 0; c < ndirichlet; c++) {
    const MicaBoundarySet *set = &disc->sets[dirichlet[c].set];
    for (long p = 0; p < set->n; p++) {
      for (int i = 0; i < M->dim; i++) sums[i] += set->w[p] * set->x[p * M->dim + i];
      sums[3] += set->w[p];
    }
  }
  MICA_CALL(reduce_sum(M, sums, 4));
  for (int i = 0; i < M->dim; i++) M->x0[i] = sums[3] > 0 ? sums[i] / sums[3] : 0.0;
  for (int s = 0; s < disc->nsets; s++)
    for (long p = 0; p < disc->sets[s].n; p++)
      for (int i = 0; i < M->dim; i++) {
        extent[i] = fmax(extent[i], disc->sets[s].x[p * M->dim + i]);
        extent[3 + i] = fmax(extent[3 + i], -disc->sets[s].x[p * M->dim + i]);
      }
  MICA_CALL(reduce_max(M, extent, 6));
  M->length = 0;
  for (int i = 0; i < M->dim; i++) M->length = fmax(M->length, extent[i] + extent[3 + i]);
  if (!(M->length > 0)) M->length = 1.0;
  return MICA_SUCCESS;
}

static int gram(const RigidModes *M, const MicaDiscretization *disc, int ndirichlet, const MicaDirichlet *dirichlet,
                 double *G) {
  const int n = M->nmodes;
  double sums[MAX_MODES * MAX_MODES + 1], row[MAX_MODES]; /* G, then Σ w */
  memset(sums, 0, sizeof sums);
  for (int c = 0; c < ndirichlet; c++) {
    const MicaBoundarySet *set = &disc->sets[dirichlet[c].set];
    for (long p = 0; p < set->n; p++)
      for (int k = 0; k < M->ncomp; k++) {
        if (!(dirichlet[c].mask & (1 << k))) continue;
        for (int j = 0; j < n; j++) row[j] = mode_value(M, j, k, set->x + p * M->dim);
        for (int i = 0; i < n; i++)
          for (int j = 0; j < n; j++) sums[i * n + j] += set->w[p] * row[i] * row[j];
        sums[n * n] += set->w[p];
      }
  }
  MICA_CALL(reduce_sum(M, sums, n * n + 1));
  for (int i = 0; i < n * n; i++) G[i] = sums[n * n] > 0 ? sums[i] / sums[n * n] : sums[i];
  return MICA_SUCCESS;
}

static const char *const AXIS_NAMES[] = {"x", "y", "z"};

static void mode_label(const RigidModes *M, int j, char *buf, size_t size) {
  if (M->axisymmetric) snprintf(buf, size, "%s the axis", M->rotation[j] ? "rotation about" : "translation along");
  else snprintf(buf, size, "%s %s", M->rotation[j] ? "rotation about" : "translation in", AXIS_NAMES[M->axis[j]]);
}

/* Whether prescribing component c can hold mode j (somewhere: a rotation's displacements vanish on its axis). */
static int mode_moves(const RigidModes *M, int j, int c) {
  const Component *k = &M->comp[c];
  const int a = M->axis[j];
  if (!M->rotation[j]) return k->kind == 'u' && k->axis == a;
  if (k->kind == 'p') return k->axis == a;
  return M->axisymmetric ? k->axis == 1 : k->axis != a && k->axis < M->dim;
}

static void append(char *buf, size_t size, const char *separator, const char *text) {
  const size_t used = strlen(buf);
  if (used < size) snprintf(buf + used, size - used, "%s%s", used ? separator : "", text);
}

/* The free modes (P_jj = Σ_free z_j² of the null space's projector) and the components that would hold them. */
static int report_free(const RigidModes *M, const double *Z, const int *is_free, int nfree, const char *const *names,
                       const char *where) {
  char modes[256] = "", holds[256] = "", label[64];
  int held_by[MICA_MAX_COMP] = {0};
  for (int j = 0; j < M->nmodes; j++) {
    double projection = 0;
    for (int v = 0; v < M->nmodes; v++)
      if (is_free[v]) projection += Z[j + v * M->nmodes] * Z[j + v * M->nmodes];
    if (projection < 1e-2) continue;
    mode_label(M, j, label, sizeof label);
    append(modes, sizeof modes, ", ", label);
    for (int c = 0; c < M->ncomp; c++) held_by[c] |= mode_moves(M, j, c);
  }
  for (int c = 0; c < M->ncomp; c++)
    if (held_by[c]) append(holds, sizeof holds, ", ", names[c]);
  MICA_ERROR(MICA_ERR_INPUT, "%s: the body can move freely: %d rigid mode%s %s not held (%s); add Dirichlet "
             "conditions on %s", where, nfree, nfree == 1 ? "" : "s", nfree == 1 ? "is" : "are", modes, holds);
}

/* G's eigenvalues (ascending) and eigenvectors (columns of G, overwritten); is_free marks the null space. G's
 * entries are averages of products of O(1) values: a held mode's eigenvalue is at least of the order of (the
 * extent of the conditions / L)², a free one's is round-off. *nfree: the number of free modes. */
static int null_space(const RigidModes *M, const MicaDiscretization *disc, int ndirichlet,
                      const MicaDirichlet *dirichlet, double *G, int *is_free, int *nfree) {
  double eig[MAX_MODES];
  MICA_CALL(gram(M, disc, ndirichlet, dirichlet, G));
  MICA_CHECK(LAPACKE_dsyev(LAPACK_COL_MAJOR, 'V', 'U', M->nmodes, G, M->nmodes, eig) == 0, MICA_ERR_LIBRARY,
             "LAPACKE_dsyev on the rigid modes' Gram matrix failed");
  *nfree = 0;
  for (int v = 0; v < M->nmodes; v++) *nfree += is_free[v] = eig[v] <= 1e-11 * fmax(1.0, eig[M->nmodes - 1]);
  return MICA_SUCCESS;
}

/* Moves x0 onto the axis of the free motion that turns most: u = t + ω × (x − x0) / L is a rotation about the
 * axis through x0 + L (ω × t) / |ω|² (plus a slide along ω), so that null vector becomes the rotation alone and
 * the message names it, not a mix of it and translations. */
static void center_on_free_rotation(RigidModes *M, const double *Z, const int *is_free) {
  int best = -1;
  double best_turn = 1e-6;
  for (int v = 0; v < M->nmodes; v++) {
    double turn = 0;
    for (int j = 0; j < M->nmodes; j++) turn += M->rotation[j] ? Z[j + v * M->nmodes] * Z[j + v * M->nmodes] : 0;
    if (is_free[v] && turn > best_turn) best = v, best_turn = turn;
  }
  if (best < 0 || M->axisymmetric) return; /* the axisymmetric rotation is about the axis already */
  double t[3] = {0, 0, 0}, w[3] = {0, 0, 0};
  for (int j = 0; j < M->nmodes; j++) (M->rotation[j] ? w : t)[M->axis[j]] = Z[j + best * M->nmodes];
  const double d[3] = {w[1] * t[2] - w[2] * t[1], w[2] * t[0] - w[0] * t[2], w[0] * t[1] - w[1] * t[0]};
  for (int i = 0; i < M->dim; i++) M->x0[i] += M->length * d[i] / best_turn;
}

int mica_dirichlet_check_rigid(const MicaDiscretization *disc, int axisymmetric, int across_ranks, int ncomp,
                               const char *const *names, int ndirichlet, const MicaDirichlet *dirichlet,
                               const char *where) {
  MICA_CHECK(disc && names && (dirichlet || !ndirichlet) && where, MICA_ERR_ARGUMENT,
             "mica_dirichlet_check_rigid: NULL argument");
  RigidModes M;
  memset(&M, 0, sizeof M);
  M.ncomp = ncomp, M.dim = disc->dim, M.axisymmetric = axisymmetric, M.across_ranks = across_ranks;
  parse_components(&M, names);
  list_modes(&M);
  MICA_CALL(place_modes(&M, disc, ndirichlet, dirichlet));
  double Z[MAX_MODES * MAX_MODES];
  int is_free[MAX_MODES], nfree;
  MICA_CALL(null_space(&M, disc, ndirichlet, dirichlet, Z, is_free, &nfree));
  if (nfree > 0 && nfree < M.nmodes) { /* the count stays; the null vectors become the motions themselves */
    center_on_free_rotation(&M, Z, is_free);
    MICA_CALL(null_space(&M, disc, ndirichlet, dirichlet, Z, is_free, &nfree));
  }
  if (!nfree) return MICA_SUCCESS;
  return report_free(&M, Z, is_free, nfree, names, where);
}

/* A micro-rotation turns with the rigid rotation of the displacements: φ_k = 1 / L beside u = e_k × (x − x0) / L
 * (mode_value's φ = 1 only says which components a rotation moves, which is all the check needs). */
static double motion_value(const RigidModes *M, int j, int c, const double *x, const char *name) {
  if (name[0] != 'u' && strncmp(name, "phi", 3)) return 0.0;
  const double v = mode_value(M, j, c, x);
  return M->comp[c].kind == 'p' && M->rotation[j] ? v / M->length : v;
}

int mica_rigid_motions(const double *x, long nparticles, int dim, int axisymmetric, int ncomp,
                       const char *const *names, long n, int *count, double **modes) {
  MICA_CHECK(x && names && count && modes && n >= nparticles * ncomp, MICA_ERR_ARGUMENT,
             "mica_rigid_motions: bad argument");
  RigidModes M;
  memset(&M, 0, sizeof M);
  M.ncomp = ncomp, M.dim = dim, M.axisymmetric = axisymmetric;
  parse_components(&M, names);
  list_modes(&M);
  double lower[3] = {INFINITY, INFINITY, INFINITY}, upper[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (long p = 0; p < nparticles; p++)
    for (int i = 0; i < dim; i++) {
      M.x0[i] += x[p * dim + i] / (double)nparticles;
      lower[i] = fmin(lower[i], x[p * dim + i]), upper[i] = fmax(upper[i], x[p * dim + i]);
    }
  M.length = 0;
  for (int i = 0; i < dim; i++) M.length = fmax(M.length, upper[i] - lower[i]);
  if (!(M.length > 0)) M.length = 1.0;
  MICA_CALL(MICA_CALLOC(*modes, (long)M.nmodes * n));
  for (int j = 0; j < M.nmodes; j++)
    for (long p = 0; p < nparticles; p++)
      for (int c = 0; c < ncomp; c++)
        (*modes)[(long)j * n + p * ncomp + c] = motion_value(&M, j, c, x + p * dim, names[c]);
  *count = M.nmodes;
  return MICA_SUCCESS;
}
