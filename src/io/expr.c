/* Expressions over GNU libmatheval (expr.h).
 *
 * mica checks the text with its own small scanner before libmatheval sees it, for three reasons:
 * libmatheval's parser leaks its partial tree on some syntax errors, its lexer echoes characters it does
 * not know to stdout, and it accepts any name as a variable. The scanner also binds the parameters: each
 * parameter name is replaced by its value in parentheses, so libmatheval differentiates them as constants
 * (x^P would otherwise go through log(x)). */
#include "mica/expr.h"

#include <ctype.h>
#include <math.h>
#include <matheval.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct MicaFunction {
  void *evaluator; /* libmatheval's compiled tree */
  char *text;      /* as written by the user (or "d(...)/dx" for a derivative) */
  char where[256];   /* deck location, "" when not from a deck */
  char setting[160]; /* the deck setting it was read from, "" when not from a deck */
};

/* libmatheval takes char *, not const char *. */
static char name_x[] = "x", name_y[] = "y", name_z[] = "z", name_t[] = "t";
static char *const variable_names[4] = {name_x, name_y, name_z, name_t};

/* The functions and constants libmatheval 1.1 knows. */
static const char *const known_functions[] = {
    "exp",  "log",   "sqrt",  "sin",   "cos",   "tan",   "cot",   "sec",   "csc",   "asin",     "acos",
    "atan", "acot",  "asec",  "acsc",  "sinh",  "cosh",  "tanh",  "coth",  "sech",  "csch",     "asinh",
    "acosh", "atanh", "acoth", "asech", "acsch", "abs",  "step",  "delta", "nandelta", "erf", NULL};
static const char *const known_constants[] = {"e",  "log2e", "log10e", "ln2",   "ln10",    "pi",     "pi_2",
                                              "pi_4", "sqrt2", "sqrt1_2", "2_pi", "2_sqrtpi", "1_pi", NULL};

/* mica's own functions, which libmatheval lacks (the closed forms of size effects need them): the modified
 * Bessel functions K0, K1, I0, I1, each written out as a quadrature of its integral representation, a sum
 * libmatheval evaluates and differentiates like any other (docs/theory.md §Modified Bessel functions). */
typedef struct {
  const char *name;
  char kind; /* 'K' or 'I' */
  int order;
} SpecialFunction;
static const SpecialFunction special_functions[] = {
    {"besselk0", 'K', 0}, {"besselk1", 'K', 1}, {"besseli0", 'I', 0}, {"besseli1", 'I', 1}, {NULL, 0, 0}};

/* ---- scanning ---- */

typedef enum { TOKEN_END, TOKEN_NUMBER, TOKEN_NAME, TOKEN_OPERATOR, TOKEN_OPEN, TOKEN_CLOSE, TOKEN_BAD } TokenKind;

typedef struct {
  TokenKind kind;
  const char *start;
  size_t length;
} Token;

/* Parameters as given to mica_function_create / mica_constant_eval. */
typedef struct {
  int count;
  const char *const *names;
  const double *values;
  int allow_variables; /* x, y, z, t are names of a function, unknown in a constant */
} Bindings;

/* What the syntax check found wrong, for the message. */
typedef struct {
  const char *text;
  const char *position;
  Token token;
  char problem[160];
} Scanner;

static const char *skip_digits(const char *c) {
  while (isdigit((unsigned char)*c)) c++;
  return c;
}

/* A number as libmatheval reads it: 12, 1.5, .5, 3., 2e5, 1.5E-3. */
static const char *scan_number(const char *c) {
  c = skip_digits(c);
  if (*c == '.') c = skip_digits(c + 1);
  if (*c == 'e' || *c == 'E') {
    const char *exponent = c + 1;
    if (*exponent == '+' || *exponent == '-') exponent++;
    if (isdigit((unsigned char)*exponent)) c = skip_digits(exponent);
  }
  return c;
}

static int is_name_char(char c) { return isalnum((unsigned char)c) || c == '_'; }

static Token next_token(const char *c) {
  while (isspace((unsigned char)*c)) c++;
  Token token = {TOKEN_BAD, c, 1};
  if (!*c) {
    token.kind = TOKEN_END;
    token.length = 0;
  } else if (isdigit((unsigned char)*c) && *skip_digits(c) == '_') {
    token.kind = TOKEN_NAME; /* libmatheval's constants 1_pi, 2_pi, 2_sqrtpi */
    const char *end = c;
    while (is_name_char(*end)) end++;
    token.length = (size_t)(end - c);
  } else if (isdigit((unsigned char)*c) || (*c == '.' && isdigit((unsigned char)c[1]))) {
    token.kind = TOKEN_NUMBER;
    token.length = (size_t)(scan_number(c) - c);
  } else if (isalpha((unsigned char)*c) || *c == '_') {
    const char *end = c;
    while (is_name_char(*end)) end++;
    token.kind = TOKEN_NAME;
    token.length = (size_t)(end - c);
  } else if (strchr("+-*/^", *c)) {
    token.kind = TOKEN_OPERATOR;
  } else if (*c == '(') {
    token.kind = TOKEN_OPEN;
  } else if (*c == ')') {
    token.kind = TOKEN_CLOSE;
  }
  return token;
}

static void advance(Scanner *scanner) {
  scanner->position = scanner->token.start + scanner->token.length;
  scanner->token = next_token(scanner->position);
}

static int token_is(const Token *token, const char *word) {
  return token->length == strlen(word) && strncmp(token->start, word, token->length) == 0;
}

static int in_list(const Token *token, const char *const *list) {
  for (int i = 0; list[i]; i++)
    if (token_is(token, list[i])) return 1;
  return 0;
}

static const SpecialFunction *special_find(const Token *token) {
  for (const SpecialFunction *f = special_functions; f->name; f++)
    if (token_is(token, f->name)) return f;
  return NULL;
}

static int is_function(const Token *token) { return in_list(token, known_functions) || special_find(token); }

static int syntax_problem(Scanner *scanner, const char *what) {
  if (scanner->token.kind == TOKEN_END)
    snprintf(scanner->problem, sizeof scanner->problem, "%s at the end", what);
  else
    snprintf(scanner->problem, sizeof scanner->problem, "%s at '%.*s' (column %d)", what,
             (int)scanner->token.length, scanner->token.start, (int)(scanner->token.start - scanner->text) + 1);
  return -1;
}

static int parse_sum(Scanner *scanner);

/* operand := '-' operand | number | name | function '(' sum ')' | '(' sum ')' */
static int parse_operand(Scanner *scanner) {
  Token token = scanner->token;
  if (token.kind == TOKEN_OPERATOR && *token.start == '-') {
    advance(scanner);
    return parse_operand(scanner);
  }
  if (token.kind == TOKEN_NUMBER) {
    advance(scanner);
    return 0;
  }
  if (token.kind == TOKEN_NAME) {
    advance(scanner);
    int called = scanner->token.kind == TOKEN_OPEN;
    if (!called && !is_function(&token)) return 0;
    if (!called) return syntax_problem(scanner, "expected '(' after a function name");
    if (!is_function(&token)) {
      scanner->token = token;
      return syntax_problem(scanner, "unknown function");
    }
  } else if (token.kind != TOKEN_OPEN) {
    return syntax_problem(scanner, "expected a number, a name or '('");
  }
  advance(scanner); /* past '(' */
  if (parse_sum(scanner)) return -1;
  if (scanner->token.kind != TOKEN_CLOSE) return syntax_problem(scanner, "expected ')'");
  advance(scanner);
  return 0;
}

/* sum := operand { operator operand }; precedence does not matter for a syntax check. */
static int parse_sum(Scanner *scanner) {
  if (parse_operand(scanner)) return -1;
  while (scanner->token.kind == TOKEN_OPERATOR) {
    advance(scanner);
    if (parse_operand(scanner)) return -1;
  }
  return 0;
}

static int check_syntax(const char *text) {
  Scanner scanner = {text, text, next_token(text), ""};
  int bad = parse_sum(&scanner);
  if (!bad && scanner.token.kind != TOKEN_END) bad = syntax_problem(&scanner, "unexpected text");
  if (bad) MICA_ERROR(MICA_ERR_INPUT, "cannot parse expression \"%s\": %s", text, scanner.problem);
  return MICA_SUCCESS;
}

/* ---- names ---- */

static int find_parameter(const Bindings *bindings, const Token *token) {
  for (int i = bindings->count - 1; i >= 0; i--) /* a later definition shadows an earlier one */
    if (token_is(token, bindings->names[i])) return i;
  return -1;
}

static int is_variable_name(const char *name) {
  return !strcmp(name, "x") || !strcmp(name, "y") || !strcmp(name, "z") || !strcmp(name, "t");
}

static int unknown_name(const char *text, const char *name, int length, const Bindings *bindings) {
  char allowed[512] = "";
  size_t used = 0;
  for (int i = 0; i < bindings->count && used < sizeof allowed; i++)
    used += (size_t)snprintf(allowed + used, sizeof allowed - used, "%s%s", i ? ", " : "", bindings->names[i]);
  const char *subject = bindings->allow_variables ? "an expression may use x, y, z, t"
                                                  : "a constant expression may use numbers";
  if (bindings->count)
    MICA_ERROR(MICA_ERR_INPUT, "unknown name '%.*s' in \"%s\"; %s and the parameters (%s)", length, name, text,
               subject, allowed);
  MICA_ERROR(MICA_ERR_INPUT, "unknown name '%.*s' in \"%s\"; %s (no parameters are defined)", length, name,
             text, subject);
}

/* Every name must be a function (checked by the syntax pass), a constant, a parameter or a variable. */
static int check_names(const char *text, const Bindings *bindings) {
  for (Token token = next_token(text); token.kind != TOKEN_END; token = next_token(token.start + token.length)) {
    if (token.kind != TOKEN_NAME || is_function(&token) || in_list(&token, known_constants) ||
        find_parameter(bindings, &token) >= 0)
      continue;
    int is_variable = token.length == 1 && strchr("xyzt", *token.start);
    if (!is_variable || !bindings->allow_variables)
      MICA_CALL(unknown_name(text, token.start, (int)token.length, bindings));
  }
  return MICA_SUCCESS;
}

static int check_bindings(const Bindings *bindings) {
  for (int i = 0; i < bindings->count; i++) {
    MICA_CHECK(bindings->names && bindings->names[i] && bindings->values, MICA_ERR_ARGUMENT,
               "parameter %d has no name or value", i);
    MICA_CHECK(!is_variable_name(bindings->names[i]), MICA_ERR_INPUT,
               "parameter '%s' has the name of a coordinate; x, y, z and t are reserved", bindings->names[i]);
    MICA_CHECK(isfinite(bindings->values[i]), MICA_ERR_INPUT, "parameter '%s' is %g, not a finite number",
               bindings->names[i], bindings->values[i]);
  }
  return MICA_SUCCESS;
}

/* ---- substitution and compilation ---- */

static int append(char **out, size_t *length, size_t *capacity, const char *piece, size_t piece_length) {
  if (*length + piece_length + 1 > *capacity) {
    size_t grown = 2 * (*length + piece_length + 1);
    MICA_CALL(MICA_REALLOC(*out, grown));
    *capacity = grown;
  }
  memcpy(*out + *length, piece, piece_length);
  *length += piece_length;
  (*out)[*length] = '\0';
  return MICA_SUCCESS;
}

static int append_text(char **out, size_t *length, size_t *capacity, const char *text) {
  return append(out, length, capacity, text, strlen(text));
}

static int append_number(char **out, size_t *length, size_t *capacity, double v) {
  char text[40];
  snprintf(text, sizeof text, "%.17g", v);
  return append_text(out, length, capacity, text);
}

/* K_n(u) = ∫_0^∞ exp(−u cosh t) cosh(n t) dt with t = s g, g = 1/sqrt(1 + u) (the integrand's width in s
 * stays near 1 for every u), by the trapezoidal rule in s with step 1/4 on [0, 16]: geometric convergence
 * for this analytic, even integrand; relative error below 1e-13 for 1e-5 <= u <= 700. g is written
 * sqrt(u)/sqrt(u + u^2), so that u <= 0, where K_n is not defined, gives NaN. */
enum { K_STEPS = 64, I_POINTS = 128 };
static const double K_STEP = 0.25;

static int expand_besselk(const char *u, int order, char **out, size_t *length, size_t *capacity) {
  const size_t need = 3 * strlen(u) + 32;
  char *gtext = NULL;
  MICA_CALL(MICA_MALLOC(gtext, need));
  snprintf(gtext, need, "(sqrt(%s)/sqrt(%s+(%s)^2))", u, u, u);
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(append_number(out, length, capacity, K_STEP));
  MICA_CALL_CLEANUP(append_text(out, length, capacity, "*"));
  MICA_CALL_CLEANUP(append_text(out, length, capacity, gtext));
  MICA_CALL_CLEANUP(append_text(out, length, capacity, "*(0.5*exp(-"));
  MICA_CALL_CLEANUP(append_text(out, length, capacity, u));
  MICA_CALL_CLEANUP(append_text(out, length, capacity, ")"));
  for (int i = 1; i <= K_STEPS; i++) {
    char s[48];
    snprintf(s, sizeof s, "%.17g*", i * K_STEP);
    MICA_CALL_CLEANUP(append_text(out, length, capacity, "+exp(-"));
    MICA_CALL_CLEANUP(append_text(out, length, capacity, u));
    MICA_CALL_CLEANUP(append_text(out, length, capacity, "*cosh("));
    MICA_CALL_CLEANUP(append_text(out, length, capacity, s));
    MICA_CALL_CLEANUP(append_text(out, length, capacity, gtext));
    MICA_CALL_CLEANUP(append_text(out, length, capacity, "))"));
    if (order) {
      MICA_CALL_CLEANUP(append_text(out, length, capacity, "*cosh("));
      MICA_CALL_CLEANUP(append_text(out, length, capacity, s));
      MICA_CALL_CLEANUP(append_text(out, length, capacity, gtext));
      MICA_CALL_CLEANUP(append_text(out, length, capacity, ")"));
    }
  }
  MICA_CALL_CLEANUP(append_text(out, length, capacity, ")"));
cleanup:
  free(gtext);
  return ierr;
}

/* I_n(u) = (1/2π) ∫_0^2π exp(u cos θ) cos(n θ) dθ by the trapezoidal rule on 128 points (65 distinct by
 * symmetry): the rule on a periodic integrand is exact but for the aliased I_(128−n)(u)/I_n(u), below
 * 1e-9 for |u| <= 300. */
static int expand_besseli(const char *u, int order, char **out, size_t *length, size_t *capacity) {
  const double pi = acos(-1.0);
  MICA_CALL(append_text(out, length, capacity, "("));
  for (int j = 0; j <= I_POINTS / 2; j++) {
    const double theta = 2 * pi * j / I_POINTS, weight = (j == 0 || j == I_POINTS / 2 ? 1.0 : 2.0) / I_POINTS;
    if (j) MICA_CALL(append_text(out, length, capacity, "+"));
    MICA_CALL(append_number(out, length, capacity, weight * cos(order * theta)));
    MICA_CALL(append_text(out, length, capacity, "*exp("));
    MICA_CALL(append_text(out, length, capacity, u));
    MICA_CALL(append_text(out, length, capacity, "*"));
    MICA_CALL(append_number(out, length, capacity, cos(theta)));
    MICA_CALL(append_text(out, length, capacity, ")"));
  }
  return append_text(out, length, capacity, ")");
}

static int substitute(const char *text, const Bindings *bindings, char **out);

/* A special function's call at name (its '(' follows): the argument substituted, then the sum in its place.
 * Returns the end of the call (past its ')'). */
static int expand_special(const SpecialFunction *f, const Token *name, const Bindings *bindings, char **out,
                          size_t *length, size_t *capacity, const char **end) {
  Token open = next_token(name->start + name->length), token = open;
  int depth = 0; /* the syntax check saw the parentheses balanced */
  do {
    depth += token.kind == TOKEN_OPEN ? 1 : token.kind == TOKEN_CLOSE ? -1 : 0;
    if (depth) token = next_token(token.start + token.length);
  } while (depth && token.kind != TOKEN_END);
  MICA_CHECK(token.kind == TOKEN_CLOSE, MICA_ERR_ARGUMENT, "%s: unbalanced parentheses", f->name);
  const size_t inner = (size_t)(token.start - (open.start + 1));
  char *argument = NULL, *u = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(argument, inner + 1));
  memcpy(argument, open.start + 1, inner);
  argument[inner] = '\0';
  MICA_CALL_CLEANUP(substitute(argument, bindings, &u));
  const size_t n = strlen(u) + 3;
  MICA_CALL_CLEANUP(MICA_REALLOC(argument, n));
  snprintf(argument, n, "(%s)", u);
  MICA_CALL_CLEANUP(append_text(out, length, capacity, "("));
  if (f->kind == 'K') MICA_CALL_CLEANUP(expand_besselk(argument, f->order, out, length, capacity));
  else MICA_CALL_CLEANUP(expand_besseli(argument, f->order, out, length, capacity));
  MICA_CALL_CLEANUP(append_text(out, length, capacity, ")"));
  *end = token.start + token.length;
cleanup:
  free(argument);
  free(u);
  return ierr;
}

/* Copies text with each parameter name (not followed by '(') replaced by "(value)" and each call of a
 * special function by its sum. */
static int substitute(const char *text, const Bindings *bindings, char **out) {
  size_t length = 0, capacity = strlen(text) + 1;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_MALLOC(*out, capacity));
  (*out)[0] = '\0';
  const char *copied = text;
  for (Token token = next_token(text); token.kind != TOKEN_END; token = next_token(token.start + token.length)) {
    const SpecialFunction *special = token.kind == TOKEN_NAME ? special_find(&token) : NULL;
    if (special && next_token(token.start + token.length).kind == TOKEN_OPEN) {
      const char *end = token.start;
      MICA_CALL_CLEANUP(append(out, &length, &capacity, copied, (size_t)(token.start - copied)));
      MICA_CALL_CLEANUP(expand_special(special, &token, bindings, out, &length, &capacity, &end));
      copied = end;
      token.start = end, token.length = 0;
      continue;
    }
    int index = token.kind == TOKEN_NAME ? find_parameter(bindings, &token) : -1;
    if (index < 0 || next_token(token.start + token.length).kind == TOKEN_OPEN) continue;
    char value[40];
    int value_length = snprintf(value, sizeof value, "(%.17g)", bindings->values[index]);
    MICA_CALL_CLEANUP(append(out, &length, &capacity, copied, (size_t)(token.start - copied)));
    MICA_CALL_CLEANUP(append(out, &length, &capacity, value, (size_t)value_length));
    copied = token.start + token.length;
  }
  MICA_CALL_CLEANUP(append(out, &length, &capacity, copied, strlen(copied)));
  return MICA_SUCCESS;
cleanup:
  MICA_FREE(*out);
  return ierr;
}

/* libmatheval reports the variables left after simplification: a second line of defence. */
static int check_evaluator_variables(void *evaluator, const char *text, const Bindings *bindings) {
  char **names;
  int count;
  evaluator_get_variables(evaluator, &names, &count);
  for (int i = 0; i < count; i++)
    if (!bindings->allow_variables || !is_variable_name(names[i]))
      MICA_CALL(unknown_name(text, names[i], (int)strlen(names[i]), bindings));
  return MICA_SUCCESS;
}

static int compile(const char *text, const Bindings *bindings, void **evaluator) {
  *evaluator = NULL;
  MICA_CHECK(text, MICA_ERR_ARGUMENT, "expression text is NULL");
  const size_t length = strnlen(text, (size_t)MICA_EXPR_TEXT_MAX + 1);
  MICA_CHECK(length <= MICA_EXPR_TEXT_MAX, MICA_ERR_INPUT,
             "the expression is longer than %d bytes (it starts \"%.40s\"); shorten it", MICA_EXPR_TEXT_MAX, text);
  MICA_CALL(check_bindings(bindings));
  MICA_CALL(check_syntax(text));
  MICA_CALL(check_names(text, bindings));
  char *substituted = NULL;
  MICA_CALL(substitute(text, bindings, &substituted));
  *evaluator = evaluator_create(substituted);
  free(substituted);
  MICA_CHECK(*evaluator, MICA_ERR_INPUT, "cannot parse expression \"%s\"", text);
  int ierr = check_evaluator_variables(*evaluator, text, bindings);
  if (ierr) {
    evaluator_destroy(*evaluator);
    *evaluator = NULL;
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  return MICA_SUCCESS;
}

static int function_wrap(void *evaluator, const char *text, MicaFunction **f) {
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(*f, 1));
  MICA_CALL_CLEANUP(MICA_MALLOC((*f)->text, strlen(text) + 1));
  memcpy((*f)->text, text, strlen(text) + 1);
  (*f)->evaluator = evaluator;
  return MICA_SUCCESS;
cleanup:
  if (*f) MICA_FREE(*f);
  evaluator_destroy(evaluator);
  return ierr;
}

int mica_function_create(const char *text, int nparams, const char *const *param_names,
                         const double *param_values, MicaFunction **f) {
  MICA_CHECK(f && nparams >= 0, MICA_ERR_ARGUMENT, "mica_function_create: bad argument");
  *f = NULL;
  Bindings bindings = {nparams, param_names, param_values, 1};
  void *evaluator;
  MICA_CALL(compile(text, &bindings, &evaluator));
  MICA_CALL(function_wrap(evaluator, text, f));
  return MICA_SUCCESS;
}

int mica_function_derivative(const MicaFunction *f, int var, MicaFunction **df) {
  MICA_CHECK(f && df, MICA_ERR_ARGUMENT, "mica_function_derivative: NULL argument");
  MICA_CHECK(var >= 0 && var < 4, MICA_ERR_ARGUMENT, "mica_function_derivative: var %d is not 0..3", var);
  *df = NULL;
  void *derivative = evaluator_derivative(f->evaluator, variable_names[var]);
  MICA_CHECK(derivative, MICA_ERR_LIBRARY, "libmatheval could not differentiate \"%s\"", f->text);
  size_t size = strlen(f->text) + 16;
  char *text;
  int ierr = MICA_MALLOC(text, size);
  if (ierr) {
    evaluator_destroy(derivative);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  snprintf(text, size, "d(%s)/d%s", f->text, variable_names[var]);
  ierr = function_wrap(derivative, text, df);
  free(text);
  if (ierr) return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  if (f->setting[0]) {
    char setting[sizeof f->setting + 32];
    snprintf(setting, sizeof setting, "the %s-derivative of %s", variable_names[var], f->setting);
    mica_function_set_origin(*df, f->where, setting);
  }
  return MICA_SUCCESS;
}

double mica_function_eval(const MicaFunction *f, const double x[3], double t) {
  double values[4] = {x[0], x[1], x[2], t};
  return evaluator_evaluate(f->evaluator, 4, (char **)variable_names, values);
}

const char *mica_function_text(const MicaFunction *f) { return f ? f->text : NULL; }

/* strlcpy: as much of src as fits, always terminated. */
static void copy_truncated(char *dst, size_t size, const char *src) {
  size_t n = src ? strlen(src) : 0;
  if (n >= size) n = size - 1;
  if (n) memcpy(dst, src, n);
  dst[n] = '\0';
}

void mica_function_set_origin(MicaFunction *f, const char *where, const char *setting) {
  copy_truncated(f->where, sizeof f->where, where);
  copy_truncated(f->setting, sizeof f->setting, setting);
}

static int not_finite(const MicaFunction *f, const char *on, int dim, const double x[3], double t, double value) {
  char point[128];
  if (dim == 3)
    snprintf(point, sizeof point, "(x, y, z) = (%g, %g, %g)", x[0], x[1], x[2]);
  else
    snprintf(point, sizeof point, "(x, y) = (%g, %g)", x[0], x[1]);
  char number[32] = "NaN"; /* printf's "-nan" says nothing more */
  if (!isnan(value)) snprintf(number, sizeof number, "%g", value);
  const char *setting = f->setting[0] ? f->setting : "the expression";
  if (f->where[0])
    MICA_ERROR(MICA_ERR_INPUT, "%s: %s \"%s\" is %s at %s, load factor %g; write an expression that is finite %s",
               f->where, setting, f->text, number, point, t, on);
  MICA_ERROR(MICA_ERR_INPUT, "%s \"%s\" is %s at %s, load factor %g; write an expression that is finite %s", setting,
             f->text, number, point, t, on);
}

int mica_function_eval_finite(const MicaFunction *f, const char *on, int dim, const double x[3], double t,
                              double *value) {
  *value = mica_function_eval(f, x, t);
  return isfinite(*value) ? MICA_SUCCESS : not_finite(f, on, dim, x, t, *value);
}

int mica_function_destroy(MicaFunction **f) {
  if (!f || !*f) return MICA_SUCCESS;
  evaluator_destroy((*f)->evaluator);
  free((*f)->text);
  MICA_FREE(*f);
  return MICA_SUCCESS;
}

int mica_constant_eval(const char *text, int nparams, const char *const *param_names,
                       const double *param_values, double *value) {
  MICA_CHECK(value && nparams >= 0, MICA_ERR_ARGUMENT, "mica_constant_eval: bad argument");
  Bindings bindings = {nparams, param_names, param_values, 0};
  void *evaluator;
  MICA_CALL(compile(text, &bindings, &evaluator));
  *value = evaluator_evaluate(evaluator, 0, NULL, NULL);
  evaluator_destroy(evaluator);
  MICA_CHECK(isfinite(*value), MICA_ERR_INPUT, "\"%s\" evaluates to %g, not a finite number", text, *value);
  return MICA_SUCCESS;
}
