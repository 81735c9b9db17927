/* The material of a run deck: which model (classical, Cosserat, gradient micromorph, strain gradient,
 * couple stress: the registry of continuum models, mica/model.h) and its constants, each checked with the
 * deck's line (docs/input.md §run, docs/theory.md). */
#include <string.h>

#include "mica/parallel.h"
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

/* material.pressure (src/assemble/pressure.c): the pressure space. A cell pressure is a classical
 * plane-strain or 3-D solid on Gauss cells, serial; anything else is refused with the setting's line (the
 * choice would have no effect, or a meaning the code does not give it). Called after the integration settings. */
int run_read_pressure(const MicaDeck *deck, const RunProblem *rp, MicaSolidOptions *opt) {
  MicaSettings settings;
  mica_deck_settings(deck, &settings);
  MICA_CALL(mica_pressure_from_settings(&settings, opt));
  if (!mica_type_has(&opt->pressure->type, MICA_PRESSURE_CELLS)) return MICA_SUCCESS;
  char where[256];
  const char *name = opt->pressure->type.name;
  mica_deck_where(deck, "material.pressure", where, sizeof where);
  MICA_CHECK(mica_type_has(&opt->field.ops->type, MICA_FIELD_CLASSICAL), MICA_ERR_INPUT,
             "%s: material.pressure = \"%s\" modifies the deformation gradient of a classical model; model '%s' is a "
             "field model: use material.pressure = \"none\"", where, name, opt->field.ops->type.name);
  MICA_CHECK(opt->field.material.plane != MICA_PLANE_STRESS, MICA_ERR_INPUT,
             "%s: material.pressure = \"%s\" constrains the in-plane dilatation, which plane stress leaves free "
             "(ε_33 takes it up, so nothing locks): use material.plane = \"strain\" or material.pressure = \"none\"",
             where, name);
  MICA_CHECK(!rp->axisymmetric, MICA_ERR_INPUT,
             "%s: material.pressure = \"%s\" is not available for axisymmetric sections (the dilatation has the hoop "
             "term u_r/r): use material.pressure = \"none\"", where, name);
  MICA_CHECK(!opt->vci, MICA_ERR_INPUT,
             "%s: material.pressure = \"%s\" does not combine with quadrature.vci (a Petrov–Galerkin form; the cell "
             "energy's tangent is the symmetric Hessian): set quadrature.vci = false", where, name);
  MICA_CHECK(!strcmp(rp->integration, "gauss"), MICA_ERR_INPUT,
             "%s: material.pressure = \"%s\" lives on the background cells' Gauss points, and quadrature.mode = "
             "\"%s\" has none: use quadrature.mode = \"gauss\"", where, name, rp->integration);
  MICA_CHECK(!mica_parallel_active(), MICA_ERR_INPUT,
             "%s: material.pressure = \"%s\" couples the points of a cell, which a parallel run deals to several "
             "ranks: run on one process", where, name);
  MICA_CHECK(rp->disc->qcell != NULL, MICA_ERR_INPUT,
             "%s: material.pressure = \"%s\" needs the background cell of every volume point, which this "
             "discretization does not record", where, name);
  return MICA_SUCCESS;
}
