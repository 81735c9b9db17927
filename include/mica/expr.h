/* Expressions in decks: functions of x, y, z, t with the deck's parameters bound as constants.
 *
 * Parsing, evaluation and symbolic differentiation are GNU libmatheval's; mica adds only the binding of
 * parameters (their values are substituted as numeric constants before parsing, so that derivatives treat
 * them as constants) and the checking of names. */
#ifndef MICA_EXPR_H
#define MICA_EXPR_H

#include "mica/error.h"

typedef struct MicaFunction MicaFunction;

/* The longest expression text, in bytes. libmatheval's parser takes time quadratic in a run of blanks
 * (a 2 MB expression: seconds; 50 MB: most of an hour) and recurses once per operator (a chain of some
 * 10^5 terms overflows the stack), so longer text is refused before libmatheval sees it. Decks' longest
 * formulas are a few hundred bytes. */
enum { MICA_EXPR_TEXT_MAX = 4096 };

/* Compiles text. Names other than x, y, z, t and the given parameters are a MICA_ERR_INPUT error that
 * lists the names allowed; so is text libmatheval cannot parse, and text longer than MICA_EXPR_TEXT_MAX. */
int mica_function_create(const char *text, int nparams, const char *const *param_names,
                         const double *param_values, MicaFunction **f);
/* The exact derivative d f / d var, var = 0, 1, 2, 3 for x, y, z, t. */
int mica_function_derivative(const MicaFunction *f, int var, MicaFunction **df);
double mica_function_eval(const MicaFunction *f, const double x[3], double t);
const char *mica_function_text(const MicaFunction *f); /* as written, before substitution */
/* Where f comes from, for messages: its deck location ("deck.cfg:12") and setting ("loads.by"); copied
 * (truncated to fit). mica_deck_function sets it; a derivative inherits it as "the x-derivative of SETTING". */
void mica_function_set_origin(MicaFunction *f, const char *where, const char *setting);
/* f at (x, t) into *value, with a check: a value that is not finite is a MICA_ERR_INPUT error,
 *   "WHERE: SETTING \"TEXT\" is VALUE at (x, y[, z]) = (...), load factor T; write an expression that is finite ON",
 * naming the point (dim coordinates) and load factor where it failed; on says where the expression must be finite
 * ("on the whole set", "in the whole body"). Loads, prescribed values and exact solutions go through it. */
int mica_function_eval_finite(const MicaFunction *f, const char *on, int dim, const double x[3], double t,
                              double *value);
int mica_function_destroy(MicaFunction **f);

/* Evaluates a constant expression of the parameters only (numeric settings given as strings). */
int mica_constant_eval(const char *text, int nparams, const char *const *param_names,
                       const double *param_values, double *value);

#endif
