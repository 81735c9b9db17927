/* The continuum models of a deck (`material.model`, docs/input.md §run): their registry, which lists the
 * classical models first, and the readers of the material.* settings of each, through the settings reader
 * of mica/schema.h (the deck implements it), each value checked with its setting's line. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mica/cosserat.h"
#include "mica/micromorph.h"
#include "models_private.h"

static const MicaType *const builtin_field_models[] = {
    &mica_field_cosserat.type,        &mica_field_cosserat_finite.type, &mica_field_micromorph.type,
    &mica_field_strain_gradient.type, &mica_field_couple_stress.type,   NULL,
};

MicaRegistry mica_field_model_registry = {"continuum model", "linear", builtin_field_models, NULL, 0,
                                          &mica_model_registry};

/* ierr with the setting's line in front of its message. */
static int at_setting(int ierr, const MicaSettings *s, const char *group, const char *name) {
  if (!ierr) return MICA_SUCCESS;
  char where[256];
  if (name[0]) mica_settings_where(s, group, name, where, sizeof where);
  else mica_settings_where(s, "", group, where, sizeof where); /* the group's own line */
  mica_error_prefix("%s", where);
  return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
}

static int optional_float(const MicaSettings *s, const char *group, const char *name, double fallback,
                          double *value) {
  *value = fallback;
  if (mica_settings_has(s, group, name)) MICA_CALL(mica_settings_float(s, group, name, value));
  return MICA_SUCCESS;
}

int mica_model_material_from_settings(const MicaModelOps *model, const MicaSettings *s, const char *group, int dim,
                                      MicaMaterial *material) {
  const char *plane;
  double E, nu;
  char where[256];
  mica_settings_where(s, "", group, where, sizeof where); /* the group's own line */
  MICA_CHECK(mica_settings_has(s, group, "E") && mica_settings_has(s, group, "nu"), MICA_ERR_INPUT,
             "%s: material needs E and nu", where);
  MICA_CALL(mica_settings_float(s, group, "E", &E));
  MICA_CALL(mica_settings_float(s, group, "nu", &nu));
  MICA_CALL(mica_settings_string(s, group, "plane", &plane));
  MicaPlaneKind kind = dim == 3 ? MICA_PLANE_NONE : !strcmp(plane, "stress") ? MICA_PLANE_STRESS : MICA_PLANE_STRAIN;
  const char *culprit = !(E > 0 && isfinite(E)) ? "E" : !(nu > -1 && nu < 0.5) ? "nu" : "plane";
  return at_setting(mica_material_set(model, E, nu, kind, material), s, group, culprit);
}

/* Cosserat: technical constants (G, ν, N, l | l_t, l_b, Ψ) when G is given, else Eringen's. */
static int read_cosserat(const MicaSettings *s, const char *group, int dim, MicaFieldModel *field) {
  char where[256];
  mica_settings_where(s, "", group, where, sizeof where); /* the group's own line */
  int ierr;
  if (mica_settings_has(s, group, "G")) {
    double G, nu, N, l, lt, lb, psi;
    MICA_CALL(optional_float(s, group, "G", 0, &G));
    MICA_CALL(optional_float(s, group, "nu", 0, &nu));
    MICA_CALL(optional_float(s, group, "N", -1, &N));
    MICA_CALL(optional_float(s, group, "l", 0, &l));
    MICA_CALL(optional_float(s, group, "l_t", l, &lt));
    MICA_CALL(optional_float(s, group, "l_b", l, &lb));
    MICA_CALL(optional_float(s, group, "psi", 1.0, &psi));
    MICA_CHECK(mica_settings_has(s, group, "N") && (dim == 3 || mica_settings_has(s, group, "l")), MICA_ERR_INPUT,
               "%s: Cosserat technical constants need G, nu, N and %s", where, dim == 2 ? "l" : "l_t, l_b, psi");
    ierr = mica_cosserat_set_technical(field, dim, G, nu, N, lt, lb, psi);
  } else {
    double lambda, mu, kappa, alpha, beta, gamma;
    MICA_CHECK(mica_settings_has(s, group, "lambda") && mica_settings_has(s, group, "mu") &&
                   mica_settings_has(s, group, "kappa") && mica_settings_has(s, group, "gamma"),
               MICA_ERR_INPUT, "%s: a Cosserat material needs G, nu, N, l (technical constants) or lambda, mu, kappa, "
               "gamma (and alpha, beta in 3-D; Eringen's constants)", where);
    MICA_CALL(mica_settings_float(s, group, "lambda", &lambda));
    MICA_CALL(mica_settings_float(s, group, "mu", &mu));
    MICA_CALL(mica_settings_float(s, group, "kappa", &kappa));
    MICA_CALL(mica_settings_float(s, group, "alpha", &alpha));
    MICA_CALL(mica_settings_float(s, group, "beta", &beta));
    MICA_CALL(mica_settings_float(s, group, "gamma", &gamma));
    ierr = mica_cosserat_set_eringen(field, dim, lambda, mu, kappa, alpha, beta, gamma);
  }
  return at_setting(ierr, s, group, "");
}

int mica_cosserat_from_settings_(const MicaType *type, const MicaSettings *s, const char *group, void *options) {
  const MicaFieldModelRead *read = options;
  (void)type;
  return read_cosserat(s, group, read->dim, read->model);
}

/* The same constants, then finite rotations. */
int mica_cosserat_finite_from_settings_(const MicaType *type, const MicaSettings *s, const char *group,
                                        void *options) {
  const MicaFieldModelRead *read = options;
  (void)type;
  MICA_CALL(read_cosserat(s, group, read->dim, read->model));
  return mica_cosserat_finite_set(read->model);
}

/* The kind of χ (micro_kind): F, J^(−1/3) F or R(Φ) with the coupling number N. */
static int set_micromorph_kind(const MicaSettings *s, const char *group, int dim, const MicaModelOps *micro,
                               const MicaMaterial *material, const double *sizes, MicaFieldModel *field) {
  const char *kind;
  char where[256];
  MICA_CALL(mica_settings_string(s, group, "micro_kind", &kind));
  if (!strcmp(kind, "F")) return mica_micromorph_set(field, dim, micro, material, sizes);
  if (!strcmp(kind, "isochoric")) return mica_micromorph_isochoric_set(field, dim, micro, material, sizes);
  mica_settings_where(s, group, "micro_kind", where, sizeof where);
  MICA_CHECK(mica_settings_has(s, group, "N"), MICA_ERR_INPUT,
             "%s: micro_kind = \"rotation\" needs the coupling number material.N in [0, 1) (κ_c = 2GN²/(1 − N²))",
             where);
  double N;
  MICA_CALL(mica_settings_float(s, group, "N", &N));
  const int no_axes = sizes[0] == 0 && sizes[1] == 0 && sizes[2] == 0;
  return at_setting(mica_micromorph_rotation_set(field, dim, micro, material, sizes, N), s, group,
                    no_axes ? "micro_kind" : "N");
}

/* Gradient micromorph: a classical micro energy (micro_model with E, ν) averaged over the micro space, one
 * size per axis named in micro_axes. */
int mica_micromorph_from_settings_(const MicaType *type, const MicaSettings *s, const char *group, void *options) {
  const MicaFieldModelRead *read = options;
  const int dim = read->dim;
  const char *micro_name, *axes;
  char where[256];
  (void)type;
  MICA_CALL(mica_settings_string(s, group, "micro_model", &micro_name));
  MICA_CALL(mica_settings_string(s, group, "micro_axes", &axes));
  const MicaModelOps *micro = mica_model_find(micro_name);
  MICA_CHECK(micro, MICA_ERR_ARGUMENT, "schema and model registry disagree on '%s'", micro_name);
  MicaMaterial material;
  MICA_CALL(mica_model_material_from_settings(micro, s, group, dim, &material));
  double given[3] = {0, 0, 0}, sizes[3] = {0, 0, 0};
  int n = 0;
  const int naxes = (int)strlen(axes);
  if (naxes) MICA_CALL(mica_settings_floats(s, group, "micro_sizes", given, 3, &n));
  mica_settings_where(s, group, naxes ? "micro_sizes" : "micro_axes", where, sizeof where);
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
  return set_micromorph_kind(s, group, dim, micro, &material, sizes, read->model);
}

/* Strain gradient / modified couple stress: E, ν (plane strain in 2-D) and the length l. */
static int read_strain_gradient(const MicaSettings *s, const char *group, int dim, int couple_stress,
                                MicaFieldModel *field) {
  char where[256];
  const char *plane;
  MICA_CALL(mica_settings_string(s, group, "plane", &plane));
  mica_settings_where(s, group, "plane", where, sizeof where);
  MICA_CHECK(dim == 3 || strcmp(plane, "stress"), MICA_ERR_INPUT, "%s: the gradient models are plane strain in 2-D",
             where);
  MicaMaterial material;
  MICA_CALL(mica_model_material_from_settings(&mica_model_linear, s, group, dim, &material));
  mica_settings_where(s, "", group, where, sizeof where); /* the group's own line */
  MICA_CHECK(mica_settings_has(s, group, "l"), MICA_ERR_INPUT, "%s: the %s model needs its length material.l", where,
             couple_stress ? "couple-stress" : "strain-gradient");
  double l;
  MICA_CALL(mica_settings_float(s, group, "l", &l));
  return at_setting(mica_strain_gradient_set(field, &material, l, couple_stress), s, group, "l");
}

int mica_strain_gradient_from_settings_(const MicaType *type, const MicaSettings *s, const char *group,
                                        void *options) {
  const MicaFieldModelRead *read = options;
  (void)type;
  return read_strain_gradient(s, group, read->dim, 0, read->model);
}

int mica_couple_stress_from_settings_(const MicaType *type, const MicaSettings *s, const char *group, void *options) {
  const MicaFieldModelRead *read = options;
  (void)type;
  return read_strain_gradient(s, group, read->dim, 1, read->model);
}

int mica_field_model_from_settings(const char *name, const MicaSettings *settings, const char *group, int dim,
                                   MicaFieldModel *model) {
  const MicaModelOps *classical = mica_model_find(name); /* the registry's base: lifted by the adapter */
  if (classical) {
    MicaMaterial material;
    MICA_CALL(mica_model_material_from_settings(classical, settings, group, dim, &material));
    return mica_field_classical_set(model, classical, &material);
  }
  const MicaType *type;
  MICA_CALL(mica_registry_get(&mica_field_model_registry, name, &type));
  MICA_CHECK(type->from_settings, MICA_ERR_ARGUMENT, "the continuum model '%s' reads no settings", name);
  MicaFieldModelRead read = {dim, model};
  return type->from_settings(type, settings, group, &read);
}
