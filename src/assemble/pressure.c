/* The pressure space of a solid (material.pressure; docs/theory.md §Nearly incompressible solids).
 *
 * "none": the displacement form. "cell-constant", "cell-linear": a pressure and a dilatation that are
 * polynomials of degree 0 or 1 in each background cell, condensed statically cell by cell (Simo, Taylor &
 * Pister's mean dilatation for degree 0; seed 004 §3.2 condenses its particle-wise pressure and dilation the
 * same way). With the cell's polynomials ψ (1, and (x − x̄)/h for degree 1), its moment matrix
 * M = Σ_{q∈c} w_q ψ_q ψ_qᵀ and the L2 projection of the points' dilatations onto them,
 *   Θ_q = ψ_qᵀ M⁻¹ Σ_{q'} w_q' ψ_q' j(F_q'),   j(F) = det F (finite strain) or tr F − d (small strain),
 * every point sees the modified gradient
 *   F̄ = (Θ / det F)^(1/d) F              (F-bar, finite strain: det F̄ = Θ)
 *   F̄ = F + (Θ − j(F))/d · I              (B-bar, small strain: tr(F̄ − I) = Θ)
 * (d = dim: in plane strain F_33 = 1 and J is the in-plane determinant), and the energy is
 *   Π = Σ_q w_q W(F̄_q),
 * a function of u alone: its residual and tangent (the Hessian) are exact and symmetric, and the global
 * tangent keeps the displacement form's size, so CHOLMOD still factors it. The volumetric part of W then
 * sees the projected Θ only: 1 + degree·d constraints per cell instead of one per quadrature point. For linear
 * elasticity this is exactly the two-field form with the cell-polynomial pressure p = κ_d Θ condensed.
 *
 * Per point, φ(F, Θ) = w W(F̄(F, Θ)) with y = (F, Θ) (d² + 1 entries) and the chain rule
 *   φ_y  = w D_yᵀ P̄,     φ_yy = w [D_yᵀ Ā D_y + Σ_m P̄_m ∂²F̄_m/∂y∂y],     D_y = ∂F̄/∂y;
 * and per cell, with s = Σ_q φ_Θ,q ψ_q and λ_q = w_q ψ_qᵀ M⁻¹ s (the condensed pressure's weight at q),
 *   R_Ia = Σ_q (φ_F,q + λ_q j_F(F_q)) : ∇N_I
 *   K    = Σ_q B_qᵀ (φ_FF,q + λ_q j_FF(F_q)) B_q + Σ_k (c_k g_kᵀ + g_k c_kᵀ) + Σ_kl H_kl g_k g_lᵀ,
 *   g_k  = Σ_q (M⁻¹ψ_q)_k w_q B_qᵀ j_F(F_q)  (∂Θ_q/∂u = Σ_k ψ_qk g_k),   c_k = Σ_q ψ_qk B_qᵀ φ_FΘ,q,
 *   H_kl = Σ_q φ_ΘΘ,q ψ_qk ψ_ql,
 * with B_q the gradients of point q's supports (∂F_q/∂u). Degree 0: ψ = 1, M = V, λ_q = w_q Σ φ_Θ / V. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mica/solid.h"

const MicaPressureOps mica_pressure_none = {
    {"none", "the displacement form: the pressure λ div u (λ ln J) at every quadrature point; locks as ν → 0.5",
     0, NULL, NULL},
    0};
const MicaPressureOps mica_pressure_cell_constant = {
    {"cell-constant",
     "one pressure per background cell, condensed: B-bar (small strain) or F-bar (finite strain) with the cell's "
     "mean dilatation; classical plane-strain and 3-D models, Gauss cells",
     MICA_PRESSURE_CELLS, NULL, NULL},
    0};

const MicaPressureOps mica_pressure_cell_linear = {
    {"cell-linear",
     "a pressure linear in each background cell (1 + dim unknowns), condensed: B-bar / F-bar with the dilatation "
     "projected onto the cell's linear polynomials; inf-sup stable on cells of 2 particle spacings",
     MICA_PRESSURE_CELLS, NULL, NULL},
    1};

static const MicaType *const builtin_pressures[] = {&mica_pressure_none.type, &mica_pressure_cell_constant.type,
                                                    &mica_pressure_cell_linear.type, NULL};
MicaRegistry mica_pressure_registry = {"pressure space", "none", builtin_pressures, NULL, 0, NULL};

int mica_pressure_from_settings(const MicaSettings *settings, MicaSolidOptions *opt) {
  const char *name;
  const MicaType *type;
  MICA_CALL(mica_settings_string(settings, "material", "pressure", &name));
  MICA_CALL(mica_registry_get(&mica_pressure_registry, name, &type));
  opt->pressure = (const MicaPressureOps *)type;
  if (type->from_settings) MICA_CALL(type->from_settings(type, settings, "material", opt));
  return MICA_SUCCESS;
}

int mica_solid_pressure_cells(const MicaSolid *s) {
  return s->opt.pressure && mica_type_has(&s->opt.pressure->type, MICA_PRESSURE_CELLS);
}

/* ---- the cells ------------------------------------------------------------------------------------------- */

/* What a cell pressure needs of the solid; the app layer names the deck line. */
static int check_cells(const MicaSolid *s) {
  const MicaSolidOptions *o = &s->opt;
  MICA_CHECK(mica_type_has(&o->field.ops->type, MICA_FIELD_CLASSICAL), MICA_ERR_INPUT,
             "a cell pressure needs a classical model (its W(F)); model '%s' is a field model", o->field.ops->type.name);
  MICA_CHECK(o->field.material.plane != MICA_PLANE_STRESS, MICA_ERR_INPUT,
             "a cell pressure constrains the in-plane dilatation, which plane stress leaves free (ε_33 takes it up): "
             "use material.plane = \"strain\"");
  MICA_CHECK(!o->axisymmetric, MICA_ERR_INPUT, "a cell pressure is not available for axisymmetric sections (the "
             "dilatation has the hoop term u_r/r)");
  MICA_CHECK(!o->vci && !o->scni, MICA_ERR_INPUT, "a cell pressure needs the Gauss points of the background cells, "
             "without %s", o->vci ? "quadrature.vci (its Petrov–Galerkin test functions)" : "SCNI's nodal cells");
  MICA_CHECK(!o->parallel, MICA_ERR_INPUT, "a cell pressure couples the points of a cell, which a parallel run "
             "deals to several ranks: run on one process");
  MICA_CHECK(s->disc->qcell != NULL && s->disc->nquad > 0, MICA_ERR_INPUT,
             "a cell pressure needs the background cell of every volume point, which this discretization does not "
             "record (nodal integration has no cells)");
  return MICA_SUCCESS;
}

/* pcell_ptr, pcell_point: the points of each cell (a counting sort of disc->qcell), and the largest union. */
static int group_points(MicaSolid *s) {
  const MicaDiscretization *disc = s->disc;
  const MicaShapeCache *c = s->volume;
  long ncells = 0;
  for (long p = 0; p < disc->nquad; p++) ncells = disc->qcell[p] + 1 > ncells ? disc->qcell[p] + 1 : ncells;
  s->npcells = ncells;
  MICA_CALL(MICA_CALLOC(s->pcell_ptr, ncells + 1));
  MICA_CALL(MICA_MALLOC(s->pcell_point, disc->nquad));
  for (long p = 0; p < disc->nquad; p++) s->pcell_ptr[disc->qcell[p] + 1]++;
  for (long k = 0; k < ncells; k++) s->pcell_ptr[k + 1] += s->pcell_ptr[k];
  long *fill = NULL;
  MICA_CALL(MICA_MALLOC(fill, ncells + 1));
  memcpy(fill, s->pcell_ptr, sizeof(long) * (size_t)(ncells + 1));
  for (long p = 0; p < disc->nquad; p++) s->pcell_point[fill[disc->qcell[p]]++] = p;
  MICA_FREE(fill);
  /* the largest union of a cell's supports (its dense tangent is that squared), counted with a marker */
  long *mark = NULL;
  MICA_CALL(MICA_MALLOC(mark, s->nparticles + 1));
  for (long I = 0; I < s->nparticles; I++) mark[I] = -1;
  s->pcell_cap = 1, s->pcell_maxpoints = 1;
  for (long k = 0; k < ncells; k++) {
    long nu = 0;
    for (long i = s->pcell_ptr[k]; i < s->pcell_ptr[k + 1]; i++)
      for (long e = c->ptr[s->pcell_point[i]]; e < c->ptr[s->pcell_point[i] + 1]; e++)
        if (mark[c->index[e]] != k) mark[c->index[e]] = k, nu++;
    s->pcell_cap = nu > s->pcell_cap ? nu : s->pcell_cap;
    const long npts = s->pcell_ptr[k + 1] - s->pcell_ptr[k];
    s->pcell_maxpoints = npts > s->pcell_maxpoints ? npts : s->pcell_maxpoints;
  }
  MICA_FREE(mark);
  return MICA_SUCCESS;
}

/* Doubles per point kept over a cell: F, j_F, φ_F, φ_FΘ (d² each), j_FF, φ_FF (d⁴ each), φ_Θ, φ_ΘΘ, w, φ, the
 * cell polynomials ψ (up to MAX_MODES) and Θ. */
enum { POINT_DATA = 4 * 9 + 2 * 81 + 4 + 5, MAX_MODES = 4 };

static long cell_work_size(const MicaSolid *s) {
  const long m = s->pcell_cap * s->dim;
  return s->pcell_maxpoints * POINT_DATA + m * m + 2 * MAX_MODES * m + (long)s->dim * 9 * s->volume->max_support;
}

/* Pressure unknowns per cell: 1 + degree·dim. */
static int cell_modes(const MicaSolid *s) { return 1 + s->opt.pressure->degree * s->dim; }

int mica_pressure_cells_build(MicaSolid *s) {
  if (!mica_solid_pressure_cells(s)) return MICA_SUCCESS;
  MICA_CALL(check_cells(s));
  MICA_CALL(group_points(s));
  MICA_CALL(MICA_MALLOC(s->pcell_nodes, s->pcell_cap));
  MICA_CALL(MICA_MALLOC(s->pcell_work, cell_work_size(s)));
  return MICA_SUCCESS;
}

void mica_pressure_cells_free(MicaSolid *s) {
  MICA_FREE(s->pcell_ptr);
  MICA_FREE(s->pcell_point);
  MICA_FREE(s->pcell_nodes);
  MICA_FREE(s->pcell_work);
}

/* ---- one point: F̄(F, Θ) and φ's derivatives ------------------------------------------------------------- */

static double det_d(int d, const double *F) {
  if (d == 2) return F[0] * F[3] - F[1] * F[2];
  return F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
}

/* F⁻¹ (row-major) of an F with determinant J ≠ 0. */
static void inverse_d(int d, const double *F, double J, double *Fi) {
  if (d == 2) {
    Fi[0] = F[3] / J, Fi[1] = -F[1] / J, Fi[2] = -F[2] / J, Fi[3] = F[0] / J;
    return;
  }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) { /* cofactor of F_ji over J */
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      Fi[i * 3 + j] = (F[r0 * 3 + c0] * F[r1 * 3 + c1] - F[r0 * 3 + c1] * F[r1 * 3 + c0]) / J;
    }
}

/* j(F) and its first and second derivatives (jFF may be NULL). */
static double dilatation(int finite, int d, const double *F, double *jF, double *jFF) {
  const int n = d * d;
  if (!finite) {
    double tr = 0;
    for (int a = 0; a < d; a++) tr += F[a * d + a];
    for (int m = 0; m < n; m++) jF[m] = m % (d + 1) == 0;
    if (jFF) memset(jFF, 0, sizeof(double) * (size_t)(n * n));
    return tr - d;
  }
  const double J = det_d(d, F);
  double Fi[9];
  inverse_d(d, F, J, Fi);
  for (int a = 0; a < d; a++)
    for (int A = 0; A < d; A++) jF[a * d + A] = J * Fi[A * d + a];
  if (jFF)
    for (int a = 0; a < d; a++)
      for (int A = 0; A < d; A++)
        for (int b = 0; b < d; b++)
          for (int B = 0; B < d; B++)
            jFF[(a * d + A) * n + b * d + B] = J * (Fi[A * d + a] * Fi[B * d + b] - Fi[A * d + b] * Fi[B * d + a]);
  return J;
}

typedef struct {
  double *F, *jF, *phiF, *phiFT, *jFF, *phiFF, *phiT, *phiTT, *w, *phi, *psi, *theta;
} PointData;

static PointData point_data(double *base, long i) {
  double *x = base + i * POINT_DATA;
  PointData pd = {x, x + 9, x + 18, x + 27, x + 36, x + 117, x + 198, x + 199, x + 200, x + 201, x + 202, x + 206};
  return pd;
}

/* φ = w W(F̄(F, Θ)): φ_F, φ_Θ always; φ_FF, φ_FΘ, φ_ΘΘ when tangent. The model's error (det F̄ ≤ 0) passes up. */
static int point_phi(const MicaSolid *s, int finite, double theta, int tangent, PointData *pd) {
  const int d = s->dim, n = d * d, ny = n + 1;
  const double *F = pd->F, w = *pd->w;
  double Fb[9], P[9], A[81], W, Dy[9 * 10], g[10] = {0}, H[100] = {0}, alpha = 1, PF = 0;
  memset(Dy, 0, sizeof Dy);
  if (finite) {
    const double J = det_d(d, F);
    MICA_CHECK(J > 0 && theta > 0, MICA_ERR_NUMERIC, "F-bar: det F = %g, cell mean %g: not positive", J, theta);
    double Fi[9];
    inverse_d(d, F, J, Fi);
    alpha = pow(theta / J, 1.0 / d);
    for (int m = 0; m < n; m++) Fb[m] = alpha * F[m];
    for (int b = 0; b < d; b++)
      for (int L = 0; L < d; L++) g[b * d + L] = -Fi[L * d + b] / d;
    g[n] = 1.0 / (d * theta);
    for (int b = 0; b < d; b++)
      for (int L = 0; L < d; L++)
        for (int c = 0; c < d; c++)
          for (int M = 0; M < d; M++) H[(b * d + L) * ny + c * d + M] = Fi[L * d + c] * Fi[M * d + b] / d;
    H[n * ny + n] = -1.0 / (d * theta * theta);
    for (int m = 0; m < n; m++)
      for (int k = 0; k < ny; k++) Dy[m * ny + k] = alpha * (g[k] * F[m] + (k == m));
  } else {
    double tr = 0;
    for (int a = 0; a < d; a++) tr += F[a * d + a];
    memcpy(Fb, F, sizeof(double) * (size_t)n);
    for (int a = 0; a < d; a++) Fb[a * d + a] += (theta - (tr - d)) / d;
    for (int m = 0; m < n; m++) {
      const int dm = m % (d + 1) == 0;
      for (int k = 0; k < n; k++) Dy[m * ny + k] = (k == m) - (dm && k % (d + 1) == 0) / (double)d;
      Dy[m * ny + n] = dm / (double)d;
    }
  }
  MICA_CALL(s->opt.field.classical->eval(&s->opt.field.material, d, Fb, &W, P, tangent ? A : NULL));
  *pd->phi = w * W;
  double phiy[10];
  for (int k = 0; k < ny; k++) {
    double sum = 0;
    for (int m = 0; m < n; m++) sum += Dy[m * ny + k] * P[m];
    phiy[k] = w * sum;
  }
  memcpy(pd->phiF, phiy, sizeof(double) * (size_t)n);
  *pd->phiT = phiy[n];
  if (!tangent) return MICA_SUCCESS;
  for (int m = 0; m < n; m++) PF += P[m] * F[m];
  double AD[9 * 10];
  for (int m = 0; m < n; m++)
    for (int l = 0; l < ny; l++) {
      double sum = 0;
      for (int r = 0; r < n; r++) sum += A[m * n + r] * Dy[r * ny + l];
      AD[m * ny + l] = sum;
    }
  for (int k = 0; k < ny; k++)
    for (int l = 0; l < ny; l++) {
      double sum = 0;
      for (int m = 0; m < n; m++) sum += Dy[m * ny + k] * AD[m * ny + l];
      if (finite) { /* Σ_m P̄_m ∂²(α F_m)/∂y_k ∂y_l, with P̄_Θ = 0 */
        const double Pk = k < n ? P[k] : 0, Pl = l < n ? P[l] : 0;
        sum += alpha * ((g[k] * g[l] + H[k * ny + l]) * PF + g[k] * Pl + g[l] * Pk);
      }
      const double v = w * sum;
      if (k < n && l < n) pd->phiFF[k * n + l] = v;
      else if (k < n) pd->phiFT[k] = v;
      else if (l == n) *pd->phiTT = v;
    }
  return MICA_SUCCESS;
}

/* ---- one cell ---------------------------------------------------------------------------------------------- */

static void point_gradient(const MicaSolid *s, long p, const double *u, double *F) {
  mica_solid_deformation_gradient(s, s->volume, p, u, F);
}

void mica_pressure_cell_dilatation(const MicaSolid *s, long c, const double *u, double *theta, double *volume) {
  const int finite = mica_type_has(&s->opt.field.classical->type, MICA_MODEL_FINITE_STRAIN);
  double V = 0, sum = 0, F[9], jF[9];
  for (long i = s->pcell_ptr[c]; i < s->pcell_ptr[c + 1]; i++) {
    const long p = s->pcell_point[i];
    point_gradient(s, p, u, F);
    const double w = s->disc->qw[p];
    V += w, sum += w * dilatation(finite, s->dim, F, jF, NULL);
  }
  *theta = V > 0 ? sum / V : 0, *volume = V;
}

/* The union of the cell's supports into s->pcell_nodes (ascending) and s->cell_slot. */
static long cell_union(MicaSolid *s, long c) {
  const MicaShapeCache *sc = s->volume;
  long nu = 0;
  for (long i = s->pcell_ptr[c]; i < s->pcell_ptr[c + 1]; i++) {
    const long p = s->pcell_point[i];
    for (long e = sc->ptr[p]; e < sc->ptr[p + 1]; e++)
      if (s->cell_slot[sc->index[e]] < 0) s->cell_slot[sc->index[e]] = 0, s->pcell_nodes[nu++] = sc->index[e];
  }
  for (long i = 1; i < nu; i++) {
    const long node = s->pcell_nodes[i];
    long j = i;
    for (; j > 0 && s->pcell_nodes[j - 1] > node; j--) s->pcell_nodes[j] = s->pcell_nodes[j - 1];
    s->pcell_nodes[j] = node;
  }
  for (long i = 0; i < nu; i++) s->cell_slot[s->pcell_nodes[i]] = i;
  return nu;
}

/* y[(slot(I) a)] += Σ_J v[a·d + J] N_I,J over point p's supports (B_pᵀ v). */
static void add_bt(const MicaSolid *s, long p, const double *v, double scale, double *y) {
  const MicaShapeCache *sc = s->volume;
  const int d = s->dim;
  for (long e = sc->ptr[p]; e < sc->ptr[p + 1]; e++) {
    const double *dN = sc->dN + e * d;
    const long I = s->cell_slot[sc->index[e]];
    for (int a = 0; a < d; a++) {
      double sum = 0;
      for (int J = 0; J < d; J++) sum += v[a * d + J] * dN[J];
      y[I * d + a] += scale * sum;
    }
  }
}

/* Kc += B_pᵀ Ã B_p over the union (row-major, m = nu·d columns); G: scratch of n·d·d² doubles. */
static void add_btab(const MicaSolid *s, long p, const double *At, long m, double *G, double *Kc) {
  const MicaShapeCache *sc = s->volume;
  const int d = s->dim, n2 = d * d;
  const long first = sc->ptr[p], n = sc->ptr[p + 1] - first;
  for (long k = 0; k < n; k++) /* G[(k a)][(b L)] = Σ_J N_k,J Ã[(a J)(b L)] */
    for (int a = 0; a < d; a++)
      for (int r = 0; r < n2; r++) {
        double sum = 0;
        for (int J = 0; J < d; J++) sum += sc->dN[(first + k) * d + J] * At[(a * d + J) * n2 + r];
        G[(k * d + a) * n2 + r] = sum;
      }
  for (long k = 0; k < n; k++) {
    const long I = s->cell_slot[sc->index[first + k]];
    for (int a = 0; a < d; a++) {
      const double *g = G + (k * d + a) * n2;
      double *row = Kc + (I * d + a) * m;
      for (long l = 0; l < n; l++) {
        const long K = s->cell_slot[sc->index[first + l]];
        const double *dN = sc->dN + (first + l) * d;
        for (int b = 0; b < d; b++) {
          double sum = 0;
          for (int L = 0; L < d; L++) sum += g[b * d + L] * dN[L];
          row[K * d + b] += sum;
        }
      }
    }
  }
}

/* Cholesky of the cell's m × m moment matrix (m ≤ MAX_MODES, SPD: the cell's points are not all on a line) and
 * solves with it: x = M⁻¹ b in place. */
static int moment_factor(int m, double *M) {
  const double scale = M[0]; /* the cell's volume: ψ_0 = 1 */
  for (int j = 0; j < m; j++) {
    double d = M[j * m + j];
    for (int k = 0; k < j; k++) d -= M[j * m + k] * M[j * m + k];
    MICA_CHECK(d > 1e-12 * scale, MICA_ERR_NUMERIC, "a background cell's pressure moment matrix is singular");
    M[j * m + j] = sqrt(d);
    for (int i = j + 1; i < m; i++) {
      double v = M[i * m + j];
      for (int k = 0; k < j; k++) v -= M[i * m + k] * M[j * m + k];
      M[i * m + j] = v / M[j * m + j];
    }
  }
  return MICA_SUCCESS;
}

static void moment_solve(int m, const double *L, double *x) {
  for (int i = 0; i < m; i++) {
    for (int k = 0; k < i; k++) x[i] -= L[i * m + k] * x[k];
    x[i] /= L[i * m + i];
  }
  for (int i = m - 1; i >= 0; i--) {
    for (int k = i + 1; k < m; k++) x[i] -= L[k * m + i] * x[k];
    x[i] /= L[i * m + i];
  }
}

/* The cell's points: F, w, j(F) and its derivatives, ψ, and the projected Θ_q; L: the factor of M. */
static int cell_points(MicaSolid *s, long c, int finite, const double *u, int second, double *L, double *V) {
  const int d = s->dim, m = cell_modes(s);
  const long first = s->pcell_ptr[c], npts = s->pcell_ptr[c + 1] - first;
  double xbar[3] = {0, 0, 0}, rhs[MAX_MODES] = {0}, jq;
  *V = 0;
  for (long i = 0; i < npts; i++) {
    const long p = s->pcell_point[first + i];
    const double w = s->disc->qw[p];
    *V += w;
    for (int a = 0; a < d; a++) xbar[a] += w * s->disc->qx[p * d + a];
  }
  if (!(*V > 0)) return MICA_SUCCESS;
  const double h = pow(*V, 1.0 / d);
  for (int a = 0; a < d; a++) xbar[a] /= *V;
  memset(L, 0, sizeof(double) * MAX_MODES * MAX_MODES);
  for (long i = 0; i < npts; i++) {
    const long p = s->pcell_point[first + i];
    PointData pd = point_data(s->pcell_work, i);
    point_gradient(s, p, u, pd.F);
    *pd.w = s->disc->qw[p];
    pd.psi[0] = 1;
    for (int a = 0; a + 1 < m; a++) pd.psi[1 + a] = (s->disc->qx[p * d + a] - xbar[a]) / h;
    jq = dilatation(finite, d, pd.F, pd.jF, second ? pd.jFF : NULL);
    for (int k = 0; k < m; k++) {
      rhs[k] += *pd.w * pd.psi[k] * jq;
      for (int l = 0; l < m; l++) L[k * m + l] += *pd.w * pd.psi[k] * pd.psi[l];
    }
  }
  MICA_CALL(moment_factor(m, L));
  moment_solve(m, L, rhs); /* the projection's coefficients */
  for (long i = 0; i < npts; i++) {
    PointData pd = point_data(s->pcell_work, i);
    *pd.theta = 0;
    for (int k = 0; k < m; k++) *pd.theta += pd.psi[k] * rhs[k];
  }
  return MICA_SUCCESS;
}

/* φ and its derivatives at every point of the cell (after cell_points), with the point named on failure. */
static int cell_phi(MicaSolid *s, long c, int finite, int tangent) {
  for (long i = 0; i < s->pcell_ptr[c + 1] - s->pcell_ptr[c]; i++) {
    PointData pd = point_data(s->pcell_work, i);
    const int ierr = point_phi(s, finite, *pd.theta, tangent, &pd);
    if (ierr) {
      mica_error_prefix("volume quadrature point %ld (background cell %ld)", s->pcell_point[s->pcell_ptr[c] + i] + 1,
                        c + 1);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
  }
  return MICA_SUCCESS;
}

/* The cell's tangent over the union of its supports into K (after the residual: cell_points, cell_phi, lam). */
static int cell_tangent(MicaSolid *s, long c, const double *L, const double *lam, MicaSparse *K) {
  const int d = s->dim, n2 = d * d, m = cell_modes(s);
  const long first = s->pcell_ptr[c], npts = s->pcell_ptr[c + 1] - first;
  const long nu = cell_union(s, c), mu = nu * d;
  double *Kc = s->pcell_work + s->pcell_maxpoints * POINT_DATA, *g = Kc + mu * mu, *cv = g + MAX_MODES * mu,
         *G = cv + MAX_MODES * mu, H[MAX_MODES * MAX_MODES] = {0};
  memset(Kc, 0, sizeof(double) * (size_t)(mu * mu + 2 * MAX_MODES * mu));
  for (long i = 0; i < npts; i++) {
    const long p = s->pcell_point[first + i];
    PointData pd = point_data(s->pcell_work, i);
    double At[81], a[MAX_MODES];
    for (int r = 0; r < n2 * n2; r++) At[r] = pd.phiFF[r] + lam[i] * pd.jFF[r];
    add_btab(s, p, At, mu, G, Kc);
    memcpy(a, pd.psi, sizeof(double) * (size_t)m);
    moment_solve(m, L, a);
    for (int k = 0; k < m; k++) {
      add_bt(s, p, pd.jF, a[k] * *pd.w, g + k * mu);
      add_bt(s, p, pd.phiFT, pd.psi[k], cv + k * mu);
      for (int l = 0; l < m; l++) H[k * m + l] += *pd.phiTT * pd.psi[k] * pd.psi[l];
    }
  }
  for (int k = 0; k < m; k++) {
    const double *gk = g + k * mu, *ck = cv + k * mu;
    for (long r = 0; r < mu; r++)
      for (long q = 0; q < mu; q++) {
        double v = ck[r] * gk[q] + gk[r] * ck[q];
        for (int l = 0; l < m; l++) v += H[k * m + l] * gk[r] * g[l * mu + q];
        Kc[r * mu + q] += v;
      }
  }
  const int ierr = mica_sparse_add_clique(K, nu, s->pcell_nodes, Kc);
  for (long i = 0; i < nu; i++) s->cell_slot[s->pcell_nodes[i]] = -1;
  return ierr;
}

static int assemble_one_cell(MicaSolid *s, long c, int finite, const double *u, double *R, MicaSparse *K) {
  const int d = s->dim, m = cell_modes(s);
  const long first = s->pcell_ptr[c], npts = s->pcell_ptr[c + 1] - first;
  const MicaShapeCache *sc = s->volume;
  double V, L[MAX_MODES * MAX_MODES], sv[MAX_MODES] = {0}, lam[64 * 64];
  MICA_CHECK(npts <= 64 * 64, MICA_ERR_ARGUMENT, "a background cell holds more than 4096 quadrature points");
  MICA_CALL(cell_points(s, c, finite, u, K != NULL, L, &V));
  if (!(V > 0)) return MICA_SUCCESS;
  MICA_CALL(cell_phi(s, c, finite, K != NULL));
  for (long i = 0; i < npts; i++) {
    PointData pd = point_data(s->pcell_work, i);
    for (int k = 0; k < m; k++) sv[k] += *pd.phiT * pd.psi[k];
  }
  moment_solve(m, L, sv); /* λ_q = w_q ψ_qᵀ M⁻¹ s */
  for (long i = 0; i < npts; i++) { /* R_Ia += (φ_F + λ_q j_F) : ∇N_I */
    const long p = s->pcell_point[first + i];
    PointData pd = point_data(s->pcell_work, i);
    lam[i] = 0;
    for (int k = 0; k < m; k++) lam[i] += *pd.w * pd.psi[k] * sv[k];
    for (long e = sc->ptr[p]; e < sc->ptr[p + 1]; e++) {
      const double *dN = sc->dN + e * d;
      for (int a = 0; a < d; a++) {
        double sum = 0;
        for (int J = 0; J < d; J++) sum += (pd.phiF[a * d + J] + lam[i] * pd.jF[a * d + J]) * dN[J];
        R[sc->index[e] * d + a] += sum;
      }
    }
  }
  return K ? cell_tangent(s, c, L, lam, K) : MICA_SUCCESS;
}

int mica_pressure_energy(MicaSolid *s, const double *u, double *energy) {
  const int finite = mica_type_has(&s->opt.field.classical->type, MICA_MODEL_FINITE_STRAIN);
  *energy = 0;
  for (long c = 0; c < s->npcells; c++) {
    double V, L[MAX_MODES * MAX_MODES];
    MICA_CALL(cell_points(s, c, finite, u, 0, L, &V));
    if (!(V > 0)) continue;
    MICA_CALL(cell_phi(s, c, finite, 0));
    for (long i = 0; i < s->pcell_ptr[c + 1] - s->pcell_ptr[c]; i++) *energy += *point_data(s->pcell_work, i).phi;
  }
  return MICA_SUCCESS;
}

int mica_pressure_assemble(MicaSolid *s, const double *u, double *R, MicaSparse *K) {
  const int finite = mica_type_has(&s->opt.field.classical->type, MICA_MODEL_FINITE_STRAIN);
  for (long c = 0; c < s->npcells; c++) MICA_CALL(assemble_one_cell(s, c, finite, u, R, K));
  return MICA_SUCCESS;
}

int mica_pressure_cell_basis(MicaSolid *s, long c, double *psi, double *Minv_psi, int *modes) {
  const int m = cell_modes(s);
  *modes = m;
  const long npts = s->pcell_ptr[c + 1] - s->pcell_ptr[c];
  double V, L[MAX_MODES * MAX_MODES];
  double *zero = NULL;
  MICA_CALL(MICA_CALLOC(zero, s->ndof));
  const int ierr = cell_points(s, c, 0, zero, 0, L, &V);
  MICA_FREE(zero);
  MICA_CALL(ierr);
  for (long i = 0; i < npts; i++) {
    const PointData pd = point_data(s->pcell_work, i);
    memcpy(psi + i * m, pd.psi, sizeof(double) * (size_t)m);
    memcpy(Minv_psi + i * m, pd.psi, sizeof(double) * (size_t)m);
    moment_solve(m, L, Minv_psi + i * m);
  }
  return MICA_SUCCESS;
}
