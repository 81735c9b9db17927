/* Reading a checked deck (deck.h getters) and saying where a setting came from: "deck.cfg:12",
 * "--set mls.order=3", or "deck.cfg (default)". A variant looks in its overlay element first. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "deck_private.h"

static const MicaDeck *base_of(const MicaDeck *deck) { return deck->base ? deck->base : deck; }

/* The last --set whose path covers the setting's path, or that the setting's path covers (an
 * intermediate group the override created). */
static const DeckOverride *covering_override(const MicaDeck *deck, const char *setting_path) {
  const MicaDeck *base = base_of(deck);
  for (int i = base->noverrides - 1; i >= 0; i--) {
    const char *path = base->overrides[i].path;
    if (deck_path_within(path, setting_path) || deck_path_within(setting_path, path)) return &base->overrides[i];
  }
  return NULL;
}

void deck_where(const MicaDeck *deck, const config_setting_t *setting, char *buf, size_t size) {
  const char *file = config_setting_source_file(setting);
  if (!file) file = deck->path;
  if (config_setting_source_line(setting) > 0) {
    snprintf(buf, size, "%s:%u", file, config_setting_source_line(setting));
    return;
  }
  char path[DECK_PATH_MAX];
  deck_setting_path(setting, path, sizeof path);
  const DeckOverride *override = covering_override(deck, path);
  if (override)
    snprintf(buf, size, "--set %s", override->text);
  else
    snprintf(buf, size, "%s (default)", deck->path);
}

int deck_fail(const MicaDeck *deck, const config_setting_t *setting, const char *file, int line,
              const char *func, const char *fmt, ...) {
  char where[DECK_PATH_MAX], message[DECK_MESSAGE_MAX];
  deck_where(deck, setting, where, sizeof where);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(message, sizeof message, fmt, ap);
  va_end(ap);
  return mica_error_set(file, line, func, MICA_ERR_INPUT, "%s: %s", where, message);
}

void deck_prefix_error(const MicaDeck *deck, const config_setting_t *setting) {
  char where[DECK_PATH_MAX], path[DECK_PATH_MAX];
  deck_where(deck, setting, where, sizeof where);
  deck_setting_path(setting, path, sizeof path);
  mica_error_prefix("%s: %s", where, path);
}

void deck_format_number(double value, char *buf, size_t size) {
  if (value == nearbyint(value) && fabs(value) < 1e15) { /* 100000, not 1e+05 */
    snprintf(buf, size, "%.0f", value);
    return;
  }
  for (int digits = 1; digits <= 17; digits++) {
    snprintf(buf, size, "%.*g", digits, value);
    if (strtod(buf, NULL) == value) return;
  }
}

static void format_range(const MicaDeckKey *key, char *buf, size_t size) {
  char low[32], high[32];
  deck_format_number(key->min, low, sizeof low);
  deck_format_number(key->max, high, sizeof high);
  snprintf(buf, size, "[%s, %s]", isinf(key->min) ? "-inf" : low, isinf(key->max) ? "inf" : high);
}

/* "mls.order = 7" or, for an expression, "geometry.upper.[0] = \"L\" = 48". */
static void describe_value(const config_setting_t *setting, double value, char *buf, size_t size) {
  char path[DECK_PATH_MAX], number[32];
  deck_setting_path(setting, path, sizeof path);
  deck_format_number(value, number, sizeof number);
  if (config_setting_type(setting) == CONFIG_TYPE_STRING)
    snprintf(buf, size, "%s = \"%s\" = %s", path, config_setting_get_string(setting), number);
  else
    snprintf(buf, size, "%s = %s", path, number);
}

static int check_range(const MicaDeck *deck, const MicaDeckKey *key, const config_setting_t *setting, double value) {
  if (!key || key->min > key->max || (value >= key->min && value <= key->max)) return MICA_SUCCESS;
  char described[DECK_MESSAGE_MAX], range[80];
  describe_value(setting, value, described, sizeof described);
  format_range(key, range, sizeof range);
  return DECK_FAIL(deck, setting, "%s is out of range %s", described, range);
}

static int evaluate_string(const MicaDeck *deck, const DeckParams *params, const config_setting_t *setting,
                           const char *expected, double *value) {
  const char *text = config_setting_get_string(setting);
  int ierr = mica_constant_eval(text, params->count, params->names, params->values, value);
  if (ierr == MICA_SUCCESS) return MICA_SUCCESS;
  char where[DECK_PATH_MAX], path[DECK_PATH_MAX];
  deck_where(deck, setting, where, sizeof where);
  deck_setting_path(setting, path, sizeof path);
  mica_error_prefix("%s: %s must be %s, not a string", where, path, expected);
  return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
}

/* An integer setting written as 2.0 is refused: the author may have meant a length, not a count. A
 * whole number out of range says so first: 200000000000000000000 reaches here as a float (deck_text.c). */
static int refuse_float(const MicaDeck *deck, const MicaDeckKey *key, const config_setting_t *setting) {
  char path[DECK_PATH_MAX], number[32];
  double value = config_setting_get_float(setting);
  if (value == nearbyint(value)) MICA_CALL(check_range(deck, key, setting, value));
  deck_setting_path(setting, path, sizeof path);
  deck_format_number(value, number, sizeof number);
  if (value == nearbyint(value) && fabs(value) < 1e15)
    return DECK_FAIL(deck, setting, "%s must be an integer like %s, not a float (%s.0)", path, number, number);
  return DECK_FAIL(deck, setting, "%s must be an integer, not a float (%s)", path, number);
}

int deck_eval_number(const MicaDeck *deck, const DeckParams *params, const MicaDeckKey *key,
                     const config_setting_t *setting, int integer, double *value) {
  const char *expected = integer ? "an integer" : "a number";
  int type = config_setting_type(setting);
  if (integer && type == CONFIG_TYPE_FLOAT) return refuse_float(deck, key, setting);
  if (type == CONFIG_TYPE_STRING) {
    MICA_CALL(evaluate_string(deck, params, setting, expected, value));
  } else if (deck_is_number(setting)) {
    *value = deck_number_value(setting);
  } else { /* the path only for the message: naming a list element costs libconfig a search of the list */
    char path[DECK_PATH_MAX];
    deck_setting_path(setting, path, sizeof path);
    return DECK_FAIL(deck, setting, "%s must be %s, not %s", path, expected, deck_type_name(setting));
  }
  if (integer && *value != nearbyint(*value)) {
    char described[DECK_MESSAGE_MAX];
    describe_value(setting, *value, described, sizeof described);
    return DECK_FAIL(deck, setting, "%s is not an integer", described);
  }
  if (integer && !(fabs(*value) < 0x1p63)) { /* a long holds it */
    char described[DECK_MESSAGE_MAX];
    describe_value(setting, *value, described, sizeof described);
    return DECK_FAIL(deck, setting, "%s does not fit in a 64-bit integer", described);
  }
  MICA_CALL(check_range(deck, key, setting, *value));
  return MICA_SUCCESS;
}

/* ---- lookup ---- */

/* A variant's element owns a path once the walk got past its groups: a list the element sets is
 * not completed from the base's. */
static config_setting_t *lookup(const MicaDeck *deck, const char *path) {
  if (deck->element) {
    int fallback;
    config_setting_t *found = deck_walk(deck->element, path, &fallback);
    if (found || !fallback) return found;
  }
  return deck_walk(config_root_setting(deck->config), path, NULL);
}

static int find_key(const MicaDeck *deck, const char *path, const char *getter, const MicaDeckKey **key) {
  char schema_path[DECK_PATH_MAX];
  deck_schema_path(path, schema_path, sizeof schema_path);
  *key = deck_schema_find(deck->schema, schema_path);
  MICA_CHECK(*key, MICA_ERR_ARGUMENT, "%s: '%s' is not a setting of this schema", getter, path);
  return MICA_SUCCESS;
}

/* The nearest setting on the way to path that exists, for a message about a missing one. */
static const config_setting_t *nearest(const MicaDeck *deck, const char *path) {
  char prefix[DECK_PATH_MAX];
  snprintf(prefix, sizeof prefix, "%s", path);
  for (char *dot = strrchr(prefix, '.'); dot; dot = strrchr(prefix, '.')) {
    *dot = '\0';
    const config_setting_t *found = lookup(deck, prefix);
    if (found) return found;
  }
  return NULL;
}

static int missing(const MicaDeck *deck, const char *path, const MicaDeckKey *key) {
  const config_setting_t *ancestor = nearest(deck, path);
  const char *help = key->help ? key->help : "no default";
  if (ancestor) return DECK_FAIL(deck, ancestor, "%s is not set; add it (%s)", path, help);
  MICA_ERROR(MICA_ERR_INPUT, "%s: %s is not set; add it (%s)", deck->path, path, help);
}

/* The setting at path and its key; a missing setting is the deck's problem, an unknown path the caller's. */
static int get_setting(const MicaDeck *deck, const char *path, const char *getter, const MicaDeckKey **key,
                       const config_setting_t **setting) {
  MICA_CHECK(deck && path, MICA_ERR_ARGUMENT, "%s: NULL argument", getter);
  MICA_CALL(find_key(deck, path, getter, key));
  *setting = lookup(deck, path);
  if (!*setting) return missing(deck, path, *key);
  return MICA_SUCCESS;
}

/* parameters.NAME reads the evaluated parameter. */
static int parameter_value(const MicaDeck *deck, const char *path, double *value) {
  const MicaDeckKey *key = deck_schema_parameters(deck->schema);
  if (!key || !deck_path_within(key->path, path) || strlen(path) <= strlen(key->path)) return 0;
  const char *name = path + strlen(key->path) + 1;
  for (int i = deck->params.count - 1; i >= 0; i--)
    if (strcmp(deck->params.names[i], name) == 0) {
      *value = deck->params.values[i];
      return 1;
    }
  return 0;
}

int mica_deck_has(const MicaDeck *deck, const char *path) { return deck && path && lookup(deck, path) != NULL; }

int mica_deck_float(const MicaDeck *deck, const char *path, double *value) {
  if (deck && path && parameter_value(deck, path, value)) return MICA_SUCCESS;
  const MicaDeckKey *key;
  const config_setting_t *setting;
  MICA_CALL(get_setting(deck, path, "mica_deck_float", &key, &setting));
  MICA_CALL(deck_eval_number(deck, &deck->params, key, setting, 0, value));
  return MICA_SUCCESS;
}

int mica_deck_int(const MicaDeck *deck, const char *path, long *value) {
  const MicaDeckKey *key;
  const config_setting_t *setting;
  double number;
  MICA_CALL(get_setting(deck, path, "mica_deck_int", &key, &setting));
  MICA_CALL(deck_eval_number(deck, &deck->params, key, setting, 1, &number));
  *value = (long)number;
  return MICA_SUCCESS;
}

int mica_deck_bool(const MicaDeck *deck, const char *path, int *value) {
  const MicaDeckKey *key;
  const config_setting_t *setting;
  MICA_CALL(get_setting(deck, path, "mica_deck_bool", &key, &setting));
  if (config_setting_type(setting) != CONFIG_TYPE_BOOL)
    return DECK_FAIL(deck, setting, "%s must be true or false, not %s", path, deck_type_name(setting));
  *value = config_setting_get_bool(setting);
  return MICA_SUCCESS;
}

int mica_deck_bool_or_word(const MicaDeck *deck, const char *path, int *value, const char **word) {
  const MicaDeckKey *key;
  const config_setting_t *setting;
  MICA_CALL(get_setting(deck, path, "mica_deck_bool_or_word", &key, &setting));
  *word = NULL, *value = -1;
  if (config_setting_type(setting) == CONFIG_TYPE_STRING) {
    *word = config_setting_get_string(setting);
    return MICA_SUCCESS;
  }
  return mica_deck_bool(deck, path, value);
}

int mica_deck_string(const MicaDeck *deck, const char *path, const char **value) {
  const MicaDeckKey *key;
  const config_setting_t *setting;
  MICA_CALL(get_setting(deck, path, "mica_deck_string", &key, &setting));
  if (config_setting_type(setting) != CONFIG_TYPE_STRING)
    return DECK_FAIL(deck, setting, "%s must be a string, not %s", path, deck_type_name(setting));
  *value = config_setting_get_string(setting);
  return MICA_SUCCESS;
}

/* Reads the values of an array, a list or a single scalar. */
static int get_numbers(const MicaDeck *deck, const char *path, const char *getter, int integer, double *values,
                       int max, int *count) {
  const MicaDeckKey *key;
  const config_setting_t *setting;
  MICA_CHECK(values && count && max >= 0, MICA_ERR_ARGUMENT, "%s: bad argument", getter);
  MICA_CALL(get_setting(deck, path, getter, &key, &setting));
  if (!config_setting_is_aggregate(setting)) {
    MICA_CHECK(max >= 1, MICA_ERR_ARGUMENT, "%s: no room for %s", getter, path);
    MICA_CALL(deck_eval_number(deck, &deck->params, key, setting, integer, values));
    *count = 1;
    return MICA_SUCCESS;
  }
  int length = config_setting_length(setting);
  MICA_CHECK(length <= max, MICA_ERR_ARGUMENT, "%s: %s has %d values, room for %d", getter, path, length, max);
  for (int i = 0; i < length; i++)
    MICA_CALL(deck_eval_number(deck, &deck->params, key, config_setting_get_elem(setting, (unsigned)i), integer,
                               &values[i]));
  *count = length;
  return MICA_SUCCESS;
}

int mica_deck_floats(const MicaDeck *deck, const char *path, double *values, int max, int *count) {
  MICA_CALL(get_numbers(deck, path, "mica_deck_floats", 0, values, max, count));
  return MICA_SUCCESS;
}

int mica_deck_ints(const MicaDeck *deck, const char *path, long *values, int max, int *count) {
  double *numbers = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(MICA_MALLOC(numbers, max > 0 ? max : 1));
  MICA_CALL_CLEANUP(get_numbers(deck, path, "mica_deck_ints", 1, numbers, max, count));
  for (int i = 0; i < *count; i++) values[i] = (long)numbers[i];
cleanup:
  free(numbers);
  return ierr;
}

int mica_deck_function(const MicaDeck *deck, const char *path, MicaFunction **f) {
  const MicaDeckKey *key;
  const config_setting_t *setting;
  MICA_CHECK(f, MICA_ERR_ARGUMENT, "mica_deck_function: f is NULL");
  *f = NULL;
  MICA_CALL(get_setting(deck, path, "mica_deck_function", &key, &setting));
  char number[40];
  const char *text = number;
  if (config_setting_type(setting) == CONFIG_TYPE_STRING)
    text = config_setting_get_string(setting);
  else if (deck_is_number(setting))
    snprintf(number, sizeof number, "%.17g", deck_number_value(setting));
  else
    return DECK_FAIL(deck, setting, "%s must be an expression (a string), not %s", path, deck_type_name(setting));
  int ierr = mica_function_create(text, deck->params.count, deck->params.names, deck->params.values, f);
  if (ierr) {
    deck_prefix_error(deck, setting);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  char where[DECK_PATH_MAX];
  deck_where(deck, setting, where, sizeof where); /* for a value that turns out not finite where it is evaluated */
  mica_function_set_origin(*f, where, path);
  return MICA_SUCCESS;
}

int mica_deck_list_length(const MicaDeck *deck, const char *path) {
  const config_setting_t *setting = deck && path ? lookup(deck, path) : NULL;
  if (!setting || !(config_setting_is_list(setting) || config_setting_is_array(setting))) return 0;
  return config_setting_length(setting);
}

int mica_deck_where(const MicaDeck *deck, const char *path, char *buf, int size) {
  MICA_CHECK(deck && path && buf && size > 0, MICA_ERR_ARGUMENT, "mica_deck_where: bad argument");
  const config_setting_t *setting = lookup(deck, path);
  if (!setting) setting = nearest(deck, path);
  if (setting)
    deck_where(deck, setting, buf, (size_t)size);
  else
    snprintf(buf, (size_t)size, "%s", deck->path);
  return MICA_SUCCESS;
}

/* ---- fingerprints ---- */

/* Appends "path=value;" to the growing text (*text, *length, *capacity). */
static int append_text(char **text, size_t *length, size_t *capacity, const char *piece) {
  const size_t n = strlen(piece);
  if (*length + n + 1 > *capacity) {
    size_t grown = *capacity ? *capacity : 256;
    while (*length + n + 1 > grown) grown *= 2;
    char *bigger = realloc(*text, grown);
    MICA_CHECK(bigger, MICA_ERR_MEMORY, "cannot grow a deck fingerprint to %zu bytes", grown);
    *text = bigger, *capacity = grown;
  }
  memcpy(*text + *length, piece, n + 1);
  *length += n;
  return MICA_SUCCESS;
}

/* The resolved value of one scalar or array setting as text: numbers as the getters evaluate them. */
static int value_text(const MicaDeck *deck, const MicaDeckKey *key, char *buf, size_t size) {
  if (!mica_deck_has(deck, key->path)) {
    snprintf(buf, size, "-");
    return MICA_SUCCESS;
  }
  double values[64];
  long ints[64];
  const char *word;
  int count = 0, flag;
  size_t used = 0;
  buf[0] = '\0';
  switch (key->type) {
  case MICA_KEY_BOOL:
    MICA_CALL(mica_deck_bool_or_word(deck, key->path, &flag, &word));
    if (word) snprintf(buf, size, "\"%s\"", word);
    else snprintf(buf, size, "%d", flag);
    return MICA_SUCCESS;
  case MICA_KEY_STRING:
  case MICA_KEY_CHOICE:
  case MICA_KEY_FUNCTION:
    MICA_CALL(mica_deck_string(deck, key->path, &word));
    snprintf(buf, size, "\"%s\"", word);
    return MICA_SUCCESS;
  case MICA_KEY_INT:
  case MICA_KEY_INTS:
    MICA_CALL(mica_deck_ints(deck, key->path, ints, 64, &count));
    for (int i = 0; i < count; i++) values[i] = (double)ints[i];
    break;
  case MICA_KEY_FLOAT:
  case MICA_KEY_FLOATS:
    MICA_CALL(mica_deck_floats(deck, key->path, values, 64, &count));
    break;
  default:
    return MICA_SUCCESS; /* groups and lists: their members are keys of their own */
  }
  for (int i = 0; i < count && used + 32 < size; i++) {
    char number[32];
    deck_format_number(values[i], number, sizeof number);
    used += (size_t)snprintf(buf + used, size - used, "%s%s", i ? "," : "", number);
  }
  return MICA_SUCCESS;
}

int mica_deck_fingerprint(const MicaDeck *deck, int nscopes, const char *const *scopes, char **text) {
  size_t length = 0, capacity = 0;
  *text = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(append_text(text, &length, &capacity, ""));
  for (const MicaDeckKey *key = deck->schema; key->path; key++) {
    int inside = 0;
    for (int i = 0; i < nscopes; i++) inside |= deck_path_within(scopes[i], key->path);
    if (!inside || strstr(key->path, "[]")) continue;
    char value[2048], piece[2600];
    MICA_CALL_CLEANUP(value_text(deck, key, value, sizeof value));
    snprintf(piece, sizeof piece, "%s=%s;", key->path, value);
    MICA_CALL_CLEANUP(append_text(text, &length, &capacity, piece));
  }
  return MICA_SUCCESS;
cleanup:
  free(*text);
  *text = NULL;
  return ierr;
}

/* ---- given or default; the reader for types below the deck layer ---- */

int mica_deck_given(const MicaDeck *deck, const char *path) {
  const config_setting_t *setting = deck && path ? lookup(deck, path) : NULL;
  if (!setting) return 0;
  if (config_setting_source_line(setting) > 0) return 1;
  char full[DECK_PATH_MAX];
  deck_setting_path(setting, full, sizeof full);
  return covering_override(deck, full) != NULL;
}

static int settings_has(const void *ctx, const char *path) { return mica_deck_has(ctx, path); }
static int settings_int(const void *ctx, const char *path, long *v) { return mica_deck_int(ctx, path, v); }
static int settings_float(const void *ctx, const char *path, double *v) { return mica_deck_float(ctx, path, v); }
static int settings_bool(const void *ctx, const char *path, int *v) { return mica_deck_bool(ctx, path, v); }
static int settings_string(const void *ctx, const char *path, const char **v) {
  return mica_deck_string(ctx, path, v);
}
static int settings_floats(const void *ctx, const char *path, double *v, int max, int *count) {
  return mica_deck_floats(ctx, path, v, max, count);
}
static int settings_where(const void *ctx, const char *path, char *buf, int size) {
  return mica_deck_where(ctx, path, buf, size);
}

static const MicaSettingsOps deck_settings_ops = {settings_has,    settings_int,    settings_float, settings_bool,
                                                  settings_string, settings_floats, settings_where};

void mica_deck_settings(const MicaDeck *deck, MicaSettings *settings) {
  settings->ops = &deck_settings_ops;
  settings->ctx = deck;
}
