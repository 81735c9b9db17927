/* The material of a run deck: which model (classical, Cosserat, gradient micromorph, strain gradient,
 * couple stress: the registry of continuum models, mica/model.h) and its constants, each checked with the
 * deck's line (docs/input.md §run, docs/theory.md). */
#include <string.h>

#include "run.h"

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

/* The model material.model names, from the registry of continuum models (src/models/settings.c reads its
 * constants); a model of second derivatives then checks that the approximation has them. */
int run_read_material(const MicaDeck *deck, int dim, MicaSolidOptions *opt) {
  const char *name;
  MICA_CALL(mica_deck_string(deck, "material.model", &name));
  MicaSettings settings;
  mica_deck_settings(deck, &settings);
  MICA_CALL(mica_field_model_from_settings(name, &settings, "material", dim, &opt->field));
  if (opt->field.ops->order >= 2) MICA_CALL(check_second_derivatives(deck));
  return MICA_SUCCESS;
}
