/* The material of a run deck: which model (classical, Cosserat, gradient micromorph, strain gradient,
 * couple stress) and its constants, each checked with the deck's line (docs/input.md §run, docs/theory.md). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mica/cosserat.h"
#include "mica/micromorph.h"
#include "run.h"

/* A classical model: E and ν, plane strain or stress in 2-D, adapted as a field model. */
static int read_classical(const MicaDeck *deck, int dim, const MicaModelOps *model, MicaFieldModel *field) {
  const char *plane;
  double E, nu;
  char where[256];
  mica_deck_where(deck, "material", where, sizeof where);
  MICA_CHECK(mica_deck_has(deck, "material.E") && mica_deck_has(deck, "material.nu"), MICA_ERR_INPUT,
             "%s: material needs E and nu", where);
  MICA_CALL(mica_deck_float(deck, "material.E", &E));
  MICA_CALL(mica_deck_float(deck, "material.nu", &nu));
  MICA_CALL(mica_deck_string(deck, "material.plane", &plane));
  MicaPlaneKind kind = dim == 3 ? MICA_PLANE_NONE : !strcmp(plane, "stress") ? MICA_PLANE_STRESS : MICA_PLANE_STRAIN;
  mica_deck_where(deck, !(E > 0 && isfinite(E)) ? "material.E" : !(nu > -1 && nu < 0.5) ? "material.nu" : "material.plane", where,
                  sizeof where);
  MicaMaterial mat;
  int ierr = mica_material_set(model, E, nu, kind, &mat);
  if (ierr) {
    mica_error_prefix("%s", where);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  return mica_field_classical_set(field, model, &mat);
}

static int optional_float(const MicaDeck *deck, const char *path, double fallback, double *value) {
  *value = fallback;
  if (mica_deck_has(deck, path)) MICA_CALL(mica_deck_float(deck, path, value));
  return MICA_SUCCESS;
}

/* Cosserat: technical constants (G, ν, N, l | l_t, l_b, Ψ) when material.G is given, else Eringen's. */
static int read_cosserat(const MicaDeck *deck, int dim, MicaFieldModel *field) {
  char where[256];
  mica_deck_where(deck, "material", where, sizeof where);
  int ierr;
  if (mica_deck_has(deck, "material.G")) {
    double G, nu, N, l, lt, lb, psi;
    MICA_CALL(optional_float(deck, "material.G", 0, &G));
    MICA_CALL(optional_float(deck, "material.nu", 0, &nu));
    MICA_CALL(optional_float(deck, "material.N", -1, &N));
    MICA_CALL(optional_float(deck, "material.l", 0, &l));
    MICA_CALL(optional_float(deck, "material.l_t", l, &lt));
    MICA_CALL(optional_float(deck, "material.l_b", l, &lb));
    MICA_CALL(optional_float(deck, "material.psi", 1.0, &psi));
    MICA_CHECK(mica_deck_has(deck, "material.N") && (dim == 3 || mica_deck_has(deck, "material.l")), MICA_ERR_INPUT,
               "%s: Cosserat technical constants need G, nu, N and %s", where, dim == 2 ? "l" : "l_t, l_b, psi");
    ierr = mica_cosserat_set_technical(field, dim, G, nu, N, lt, lb, psi);
  } else {
    double lambda, mu, kappa, alpha, beta, gamma;
    MICA_CHECK(mica_deck_has(deck, "material.lambda") && mica_deck_has(deck, "material.mu") &&
                   mica_deck_has(deck, "material.kappa") && mica_deck_has(deck, "material.gamma"),
               MICA_ERR_INPUT, "%s: a Cosserat material needs G, nu, N, l (technical constants) or lambda, mu, kappa, "
               "gamma (and alpha, beta in 3-D; Eringen's constants)", where);
    MICA_CALL(mica_deck_float(deck, "material.lambda", &lambda));
    MICA_CALL(mica_deck_float(deck, "material.mu", &mu));
    MICA_CALL(mica_deck_float(deck, "material.kappa", &kappa));
    MICA_CALL(mica_deck_float(deck, "material.alpha", &alpha));
    MICA_CALL(mica_deck_float(deck, "material.beta", &beta));
    MICA_CALL(mica_deck_float(deck, "material.gamma", &gamma));
    ierr = mica_cosserat_set_eringen(field, dim, lambda, mu, kappa, alpha, beta, gamma);
  }
  if (ierr) {
    mica_error_prefix("%s", where);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  return MICA_SUCCESS;
}

/* The kind of χ (material.micro_kind): F, J^(−1/3) F or R(Φ) with the coupling number material.N. */
static int set_micromorph_kind(const MicaDeck *deck, int dim, const MicaModelOps *micro, const MicaMaterial *material,
                               const double *sizes, MicaFieldModel *field) {
  const char *kind;
  char where[256];
  MICA_CALL(mica_deck_string(deck, "material.micro_kind", &kind));
  if (!strcmp(kind, "F")) return mica_micromorph_set(field, dim, micro, material, sizes);
  if (!strcmp(kind, "isochoric")) return mica_micromorph_isochoric_set(field, dim, micro, material, sizes);
  mica_deck_where(deck, "material.micro_kind", where, sizeof where);
  MICA_CHECK(mica_deck_has(deck, "material.N"), MICA_ERR_INPUT,
             "%s: micro_kind = \"rotation\" needs the coupling number material.N in [0, 1) (κ_c = 2GN²/(1 − N²))", where);
  double N;
  MICA_CALL(mica_deck_float(deck, "material.N", &N));
  const int no_axes = sizes[0] == 0 && sizes[1] == 0 && sizes[2] == 0;
  mica_deck_where(deck, no_axes ? "material.micro_kind" : "material.N", where, sizeof where);
  int ierr = mica_micromorph_rotation_set(field, dim, micro, material, sizes, N);
  if (ierr) {
    mica_error_prefix("%s", where);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  return MICA_SUCCESS;
}

/* Gradient micromorph (χ = F, J^(−1/3) F or R(Φ)): a classical micro energy (material.micro_model with E, ν) averaged over the
 * micro space: one size per axis named in material.micro_axes. */
static int read_micromorph(const MicaDeck *deck, int dim, MicaFieldModel *field) {
  const char *micro_name, *axes;
  char where[256];
  MICA_CALL(mica_deck_string(deck, "material.micro_model", &micro_name));
  MICA_CALL(mica_deck_string(deck, "material.micro_axes", &axes));
  const MicaModelOps *micro = mica_model_find(micro_name);
  MICA_CHECK(micro, MICA_ERR_ARGUMENT, "schema and model registry disagree on '%s'", micro_name);
  MicaFieldModel classical;
  MICA_CALL(read_classical(deck, dim, micro, &classical));
  double given[3] = {0, 0, 0}, sizes[3] = {0, 0, 0};
  int n = 0;
  const int naxes = (int)strlen(axes);
  if (naxes) MICA_CALL(mica_deck_floats(deck, "material.micro_sizes", given, 3, &n));
  mica_deck_where(deck, naxes ? "material.micro_sizes" : "material.micro_axes", where, sizeof where);
  MICA_CHECK(n == naxes, MICA_ERR_INPUT, "%s: material.micro_axes = \"%s\" needs %d sizes in material.micro_sizes, "
             "not %d", where, axes, naxes, n);
  for (int i = 0; i < naxes; i++) {
    const int K = axes[i] - 'x';
    MICA_CHECK(K >= 0 && K < dim && sizes[K] == 0, MICA_ERR_INPUT, "%s: micro_axes \"%s\": '%c' is not an axis of "
               "this %d-D body, or appears twice", where, axes, axes[i], dim);
    MICA_CHECK(given[i] > 0, MICA_ERR_INPUT, "%s: the micro-space axis %c has size %g; give a positive size (or leave "
               "the axis out of material.micro_axes)", where, axes[i], given[i]);
    sizes[K] = given[i];
  }
  return set_micromorph_kind(deck, dim, micro, &classical.material, sizes, field);
}

/* Strain gradient / modified couple stress: E, ν (plane strain in 2-D) and the length material.l. */
static int read_strain_gradient(const MicaDeck *deck, int dim, int couple_stress, MicaFieldModel *field) {
  char where[256];
  const char *plane;
  MICA_CALL(mica_deck_string(deck, "material.plane", &plane));
  mica_deck_where(deck, "material.plane", where, sizeof where);
  MICA_CHECK(dim == 3 || strcmp(plane, "stress"), MICA_ERR_INPUT, "%s: the gradient models are plane strain in 2-D",
             where);
  MicaFieldModel classical;
  MICA_CALL(read_classical(deck, dim, &mica_model_linear, &classical));
  mica_deck_where(deck, "material", where, sizeof where);
  MICA_CHECK(mica_deck_has(deck, "material.l"), MICA_ERR_INPUT, "%s: the %s model needs its length material.l", where,
             couple_stress ? "couple-stress" : "strain-gradient");
  double l;
  MICA_CALL(mica_deck_float(deck, "material.l", &l));
  mica_deck_where(deck, "material.l", where, sizeof where);
  int ierr = mica_strain_gradient_set(field, &classical.material, l, couple_stress);
  if (ierr) {
    mica_error_prefix("%s", where);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  return MICA_SUCCESS;
}

/* A gradient model needs second derivatives of the unknowns: a basis of order ≥ 2 and a weight that is at
 * least C² (the cubic, quartic and quartic C³ splines). */
static int check_second_derivatives(const MicaDeck *deck) {
  long order;
  const char *weight, *method;
  char where[256];
  MICA_CALL(mica_deck_string(deck, "problem.method", &method));
  mica_deck_where(deck, "material.model", where, sizeof where);
  MICA_CHECK(strcmp(method, "fe"), MICA_ERR_INPUT,
             "%s: a gradient model needs second derivatives of C1 shape functions; the finite elements of "
             "problem.method = \"fe\" are C0: use problem.method = \"efg\"", where);
  MICA_CALL(mica_deck_int(deck, "mls.order", &order));
  MICA_CALL(mica_deck_string(deck, "mls.weight", &weight));
  const MlsWeightOps *w = mls_weight_find(weight);
  mica_deck_where(deck, order < 2 ? "mls.order" : "mls.weight", where, sizeof where);
  MICA_CHECK(order >= 2 && w && w->continuity >= 2, MICA_ERR_INPUT,
             "%s: a gradient model needs second derivatives: mls.order >= 2 and a weight that is at least C2 (cubic, "
             "quartic, quartic-c3), not order %ld with the %s weight", where, order, weight);
  return MICA_SUCCESS;
}

int run_read_material(const MicaDeck *deck, int dim, MicaSolidOptions *opt) {
  const char *name;
  MICA_CALL(mica_deck_string(deck, "material.model", &name));
  if (!strcmp(name, "cosserat")) return read_cosserat(deck, dim, &opt->field);
  if (!strcmp(name, "cosserat-finite")) { /* the same constants, then finite rotations */
    MICA_CALL(read_cosserat(deck, dim, &opt->field));
    return mica_cosserat_finite_set(&opt->field);
  }
  if (!strcmp(name, "micromorph")) {
    const char *kind;
    MICA_CALL(mica_deck_string(deck, "material.micro_kind", &kind));
    if (strcmp(kind, "rotation")) MICA_CALL(check_second_derivatives(deck)); /* the rotation kind is first order */
    return read_micromorph(deck, dim, &opt->field);
  }
  if (!strcmp(name, "strain-gradient") || !strcmp(name, "couple-stress")) {
    MICA_CALL(check_second_derivatives(deck));
    return read_strain_gradient(deck, dim, !strcmp(name, "couple-stress"), &opt->field);
  }
  const MicaModelOps *model = mica_model_find(name);
  MICA_CHECK(model, MICA_ERR_ARGUMENT, "schema and model registry disagree on '%s'", name);
  return read_classical(deck, dim, model, &opt->field);
}

