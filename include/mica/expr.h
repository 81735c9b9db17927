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
int mica_function_destroy(MicaFunction **f);

/* Evaluates a constant expression of the parameters only (numeric settings given as strings). */
int mica_constant_eval(const char *text, int nparams, const char *const *param_names,
                       const double *param_values, double *value);

#endif
