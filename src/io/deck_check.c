/* Strict checking of a deck against its schema: every setting must be a key of the schema (else
 * "unknown setting ...; did you mean ...?"), of the key's type, in its range, of its length, one of its
 * choices; expressions are evaluated and functions compiled here, so that their errors carry the line.
 * Also evaluates the `parameters` group, in order, each value seeing only the ones before it. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/text.h"
#include "deck_private.h"

typedef struct {
  const MicaDeck *deck;
  const DeckParams *params; /* the base's, or a variant's inside an overlay element */
  int in_overlay;
} CheckContext;

static int check_setting(const CheckContext *context, const config_setting_t *setting, const char *schema_path);

/* ---- suggestions ---- */

static int close_enough(int distance, const char *word) {
  int allowed = (int)strlen(word) / 3;
  return distance <= (allowed > 2 ? allowed : 2);
}

static const char *last_segment(const char *path) {
  const char *dot = strrchr(path, '.');
  return dot ? dot + 1 : path;
}

/* The member names the schema allows in the group at prefix ("" for the root). */
static const char *child_name(const char *key_path, const char *prefix, char *buf, size_t size) {
  if (prefix[0] && !(deck_path_within(prefix, key_path) && key_path[strlen(prefix)] == '.')) return NULL;
  const char *start = prefix[0] ? key_path + strlen(prefix) + 1 : key_path;
  size_t length = strcspn(start, ".");
  if (length >= size) return NULL;
  memcpy(buf, start, length);
  buf[length] = '\0';
  return buf;
}

/* A suggestion: the first prefix_length characters of the unknown setting's path, then name. */
typedef struct {
  int prefix_length;
  char name[DECK_PATH_MAX];
} Suggestion;

/* A sibling of the unknown name in the same group, else any key whose path or last name is close. */
static int suggest_key(const MicaDeckKey *schema, const char *schema_path, const char *display_path,
                       Suggestion *suggestion) {
  char prefix[DECK_PATH_MAX], name[DECK_PATH_MAX];
  snprintf(prefix, sizeof prefix, "%s", schema_path);
  char *dot = strrchr(prefix, '.');
  *(dot ? dot : prefix) = '\0';
  const char *unknown = last_segment(schema_path);
  int best = INT_MAX;
  for (const MicaDeckKey *key = schema; key->path; key++) {
    const char *sibling = child_name(key->path, prefix, name, sizeof name);
    int distance = sibling ? mica_text_distance(unknown, sibling) : INT_MAX;
    if (distance < best && close_enough(distance, unknown)) {
      best = distance;
      suggestion->prefix_length = (int)(last_segment(display_path) - display_path);
      snprintf(suggestion->name, sizeof suggestion->name, "%s", sibling);
    }
  }
  if (best < INT_MAX) return 1;
  for (const MicaDeckKey *key = schema; key->path; key++) {
    if (strstr(key->path, "[]")) continue;
    int whole = mica_text_distance(schema_path, key->path), tail = mica_text_distance(unknown, last_segment(key->path));
    int distance = close_enough(whole, schema_path) ? whole : close_enough(tail, unknown) ? tail : INT_MAX;
    if (distance < best) {
      best = distance;
      suggestion->prefix_length = 0;
      snprintf(suggestion->name, sizeof suggestion->name, "%s", key->path);
    }
  }
  return best < INT_MAX;
}

static int unknown_setting(const CheckContext *context, const config_setting_t *setting, const char *schema_path) {
  char path[DECK_PATH_MAX];
  Suggestion suggestion;
  deck_setting_path(setting, path, sizeof path);
  if (suggest_key(context->deck->schema, schema_path, path, &suggestion))
    return DECK_FAIL(context->deck, setting, "unknown setting '%s'; did you mean '%.*s%s'?", path,
                     suggestion.prefix_length, path, suggestion.name);
  return DECK_FAIL(context->deck, setting, "unknown setting '%s'", path);
}

/* ---- one check per kind of key ---- */

static int check_type(const CheckContext *context, const config_setting_t *setting, int type, const char *expected) {
  if (config_setting_type(setting) == type) return MICA_SUCCESS;
  char path[DECK_PATH_MAX];
  deck_setting_path(setting, path, sizeof path);
  return DECK_FAIL(context->deck, setting, "%s must be %s, not %s", path, expected, deck_type_name(setting));
}

/* A string of at most key->len_max bytes (MICA_DECK_TEXT_MAX when the key sets none): names and titles end in
 * fixed buffers of charts, summaries and messages, so a longer one is refused here, with its line, rather than
 * cut short somewhere in the run. The value itself is not echoed: it is the thing too long to show. */
static int check_string(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting) {
  MICA_CALL(check_type(context, setting, CONFIG_TYPE_STRING, "a string"));
  const size_t most = key && key->len_max > 0 ? (size_t)key->len_max : MICA_DECK_TEXT_MAX;
  const size_t length = strlen(config_setting_get_string(setting));
  if (length <= most) return MICA_SUCCESS;
  char path[DECK_PATH_MAX];
  deck_setting_path(setting, path, sizeof path);
  return DECK_FAIL(context->deck, setting, "%s is %zu bytes long; at most %zu are allowed: shorten it", path, length,
                   most);
}

static int check_number(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting,
                        int integer) {
  double value;
  MICA_CALL(deck_eval_number(context->deck, context->params, key, setting, integer, &value));
  return MICA_SUCCESS;
}

/* "exactly 3", "1 to 3", "at least 1" values. */
static void describe_length(const MicaDeckKey *key, char *buf, size_t size) {
  if (key->len_max <= 0)
    snprintf(buf, size, "at least %d", key->len_min);
  else if (key->len_min == key->len_max)
    snprintf(buf, size, "exactly %d", key->len_min);
  else
    snprintf(buf, size, "%d to %d", key->len_min, key->len_max);
}

static int check_length(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting) {
  int length = config_setting_length(setting);
  if (length >= key->len_min && (key->len_max <= 0 || length <= key->len_max)) return MICA_SUCCESS;
  char path[DECK_PATH_MAX], needed[64];
  deck_setting_path(setting, path, sizeof path);
  describe_length(key, needed, sizeof needed);
  return DECK_FAIL(context->deck, setting, "%s has %d value%s; it needs %s", path, length, length == 1 ? "" : "s",
                   needed);
}

/* INTS and FLOATS: an array or list of numbers or expressions; a lone value when one may do. */
static int check_numbers(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting) {
  int integer = key->type == MICA_KEY_INTS;
  const char *kind = integer ? "integers" : "numbers";
  int single = deck_is_number(setting) || config_setting_type(setting) == CONFIG_TYPE_STRING;
  if (single && key->len_min <= 1)
    return check_number(context, key, setting, integer);
  if (!config_setting_is_array(setting) && !config_setting_is_list(setting)) {
    char path[DECK_PATH_MAX], needed[64];
    deck_setting_path(setting, path, sizeof path);
    describe_length(key, needed, sizeof needed);
    return DECK_FAIL(context->deck, setting, "%s must be an array of %s %s, not %s", path, needed, kind,
                     deck_type_name(setting));
  }
  MICA_CALL(check_length(context, key, setting));
  for (int i = 0; i < config_setting_length(setting); i++)
    MICA_CALL(check_number(context, key, config_setting_get_elem(setting, (unsigned)i), integer));
  return MICA_SUCCESS;
}

/* Finds word among "a|b|c"; else the closest choice within the suggestion distance, or NULL. */
static int find_choice(const char *choices, const char *word, char *closest, size_t size) {
  int best = INT_MAX;
  closest[0] = '\0';
  for (const char *choice = choices; *choice;) {
    size_t length = strcspn(choice, "|");
    char candidate[128];
    snprintf(candidate, sizeof candidate, "%.*s", (int)length, choice);
    if (strcmp(candidate, word) == 0) return 1;
    int distance = mica_text_distance(word, candidate);
    if (distance < best && close_enough(distance, word)) {
      best = distance;
      snprintf(closest, size, "%s", candidate);
    }
    choice += length + (choice[length] == '|');
  }
  return 0;
}

static int check_choice(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting) {
  char expected[DECK_MESSAGE_MAX / 2], closest[128], path[DECK_PATH_MAX];
  const char *choices = key->choices ? key->choices : "";
  snprintf(expected, sizeof expected, "one of %s (a string)", choices);
  MICA_CALL(check_type(context, setting, CONFIG_TYPE_STRING, expected));
  const char *word = config_setting_get_string(setting);
  if (find_choice(choices, word, closest, sizeof closest)) return MICA_SUCCESS;
  deck_setting_path(setting, path, sizeof path);
  if (closest[0])
    return DECK_FAIL(context->deck, setting, "%s = \"%s\" is not one of %s; did you mean \"%s\"?", path, word,
                     choices, closest);
  return DECK_FAIL(context->deck, setting, "%s = \"%s\" is not one of %s", path, word, choices);
}

/* true or false; a boolean key with `choices` also takes those words (quadrature.vci = "auto"). */
static int check_bool(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting) {
  if (!key->choices || config_setting_type(setting) != CONFIG_TYPE_STRING)
    return check_type(context, setting, CONFIG_TYPE_BOOL, "true or false");
  char closest[128], path[DECK_PATH_MAX];
  const char *word = config_setting_get_string(setting);
  if (find_choice(key->choices, word, closest, sizeof closest)) return MICA_SUCCESS;
  deck_setting_path(setting, path, sizeof path);
  return DECK_FAIL(context->deck, setting, "%s = \"%s\" is not true, false or \"%s\"", path, word, key->choices);
}

/* Compiled now, with the parameters in force, so a bad name is reported with its line. */
static int check_function(const CheckContext *context, const config_setting_t *setting) {
  if (deck_is_number(setting)) return MICA_SUCCESS;
  MICA_CALL(check_type(context, setting, CONFIG_TYPE_STRING, "an expression of x, y, z, t (a string)"));
  const DeckParams *params = context->params;
  MicaFunction *f = NULL;
  int ierr = mica_function_create(config_setting_get_string(setting), params->count, params->names,
                                  params->values, &f);
  mica_function_destroy(&f);
  if (ierr) {
    deck_prefix_error(context->deck, setting);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  return MICA_SUCCESS;
}

static int check_members(const CheckContext *context, const config_setting_t *group, const char *prefix) {
  for (int i = 0; i < config_setting_length(group); i++) {
    const config_setting_t *member = config_setting_get_elem(group, (unsigned)i);
    char schema_path[DECK_PATH_MAX];
    snprintf(schema_path, sizeof schema_path, "%s%s%s", prefix, prefix[0] ? "." : "", config_setting_name(member));
    MICA_CALL(check_setting(context, member, schema_path));
  }
  return MICA_SUCCESS;
}

static int check_group(const CheckContext *context, const config_setting_t *setting, const char *schema_path) {
  MICA_CALL(check_type(context, setting, CONFIG_TYPE_GROUP, "a group { name = value; ... }"));
  MICA_CALL(check_members(context, setting, schema_path));
  return MICA_SUCCESS;
}

/* LIST and OVERLAY hold groups: "( { ... }, { ... } )"; an empty array [] passes for an empty list. */
static int check_list_shape(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting) {
  int empty_array = config_setting_is_array(setting) && config_setting_length(setting) == 0;
  if (!empty_array) MICA_CALL(check_type(context, setting, CONFIG_TYPE_LIST, "a list of groups ( { ... }, ... )"));
  if (key->len_min > 0 || key->len_max > 0) MICA_CALL(check_length(context, key, setting));
  for (int i = 0; i < config_setting_length(setting); i++)
    MICA_CALL(check_type(context, config_setting_get_elem(setting, (unsigned)i), CONFIG_TYPE_GROUP,
                         "a group { name = value; ... }"));
  return MICA_SUCCESS;
}

static int check_list(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting) {
  char prefix[DECK_PATH_MAX];
  snprintf(prefix, sizeof prefix, "%s.[]", key->path);
  MICA_CALL(check_list_shape(context, key, setting));
  for (int i = 0; i < config_setting_length(setting); i++)
    MICA_CALL(check_members(context, config_setting_get_elem(setting, (unsigned)i), prefix));
  return MICA_SUCCESS;
}

/* A variant's name names its output: it must be a string and differ from the names before it. */
static int check_variant_name(const CheckContext *context, const config_setting_t *list, int index) {
  const config_setting_t *name = config_setting_get_member(config_setting_get_elem(list, (unsigned)index), "name");
  if (!name) return MICA_SUCCESS;
  MICA_CALL(check_string(context, NULL, name));
  for (int j = 0; j < index; j++) {
    const char *earlier;
    if (config_setting_lookup_string(config_setting_get_elem(list, (unsigned)j), "name", &earlier) &&
        strcmp(earlier, config_setting_get_string(name)) == 0) {
      char path[DECK_PATH_MAX];
      deck_setting_path(name, path, sizeof path);
      return DECK_FAIL(context->deck, name, "%s = \"%s\" is taken by variant %d; variant names must differ", path,
                       earlier, j + 1);
    }
  }
  return MICA_SUCCESS;
}

/* An element holds any settings of the schema, relative to the deck's root, checked with the variant's
 * parameters (the base's, with the element's own `parameters` merged in). */
static int check_variant(const CheckContext *context, const config_setting_t *element) {
  const MicaDeckKey *parameters_key = deck_schema_parameters(context->deck->schema);
  const config_setting_t *base_group = NULL, *element_group = NULL;
  if (parameters_key) {
    base_group = deck_walk(config_root_setting(context->deck->config), parameters_key->path, NULL);
    element_group = deck_walk((config_setting_t *)element, parameters_key->path, NULL);
  }
  DeckParams params = {0, NULL, NULL};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(deck_params_build(context->deck, base_group, element_group, &params));
  CheckContext variant = {context->deck, &params, 1};
  for (int i = 0; i < config_setting_length(element); i++) {
    const config_setting_t *member = config_setting_get_elem(element, (unsigned)i);
    if (strcmp(config_setting_name(member), "name") == 0) continue;
    MICA_CALL_CLEANUP(check_setting(&variant, member, config_setting_name(member)));
  }
cleanup:
  deck_params_free(&params);
  return ierr;
}

static int check_overlay(const CheckContext *context, const MicaDeckKey *key, const config_setting_t *setting) {
  if (context->in_overlay) {
    char path[DECK_PATH_MAX];
    deck_setting_path(setting, path, sizeof path);
    return DECK_FAIL(context->deck, setting, "%s: a variant cannot hold variants of its own", path);
  }
  MICA_CALL(check_list_shape(context, key, setting));
  for (int i = 0; i < config_setting_length(setting); i++) {
    MICA_CALL(check_variant_name(context, setting, i));
    MICA_CALL(check_variant(context, config_setting_get_elem(setting, (unsigned)i)));
  }
  return MICA_SUCCESS;
}

static int check_setting(const CheckContext *context, const config_setting_t *setting, const char *schema_path) {
  const MicaDeckKey *key = deck_schema_find(context->deck->schema, schema_path);
  if (!key) {
    if (deck_schema_has_children(context->deck->schema, schema_path))
      return check_group(context, setting, schema_path);
    return unknown_setting(context, setting, schema_path);
  }
  switch (key->type) {
  case MICA_KEY_INT: return check_number(context, key, setting, 1);
  case MICA_KEY_FLOAT: return check_number(context, key, setting, 0);
  case MICA_KEY_BOOL: return check_bool(context, key, setting);
  case MICA_KEY_STRING: return check_string(context, key, setting);
  case MICA_KEY_CHOICE: return check_choice(context, key, setting);
  case MICA_KEY_INTS:
  case MICA_KEY_FLOATS: return check_numbers(context, key, setting);
  case MICA_KEY_FUNCTION: return check_function(context, setting);
  case MICA_KEY_GROUP: return check_group(context, setting, schema_path);
  case MICA_KEY_LIST: return check_list(context, key, setting);
  case MICA_KEY_OVERLAY: return check_overlay(context, key, setting);
  case MICA_KEY_PARAMETERS: return MICA_SUCCESS; /* checked as they were evaluated */
  case MICA_KEY_FRAGMENT: break; /* expanded by the composition: never in a deck's schema */
  }
  return MICA_SUCCESS;
}

/* 1 if word is one of "a|b|c". */
static int among(const char *word, const char *words) {
  const size_t n = strlen(word);
  for (const char *c = words; c; c = strchr(c, '|') ? strchr(c, '|') + 1 : NULL)
    if (!strncmp(c, word, n) && (c[n] == '|' || c[n] == '\0')) return 1;
  return 0;
}

/* A type's setting given while its chooser names another type would have no effect: refused. */
int deck_check_owners(const MicaDeck *deck) {
  for (const MicaDeckKey *key = deck->schema; key->path; key++) {
    if (!key->chooser || strstr(key->path, "[]") || !mica_deck_given(deck, key->path)) continue;
    const char *chosen;
    MICA_CALL(mica_deck_string(deck, key->chooser, &chosen));
    if (among(chosen, key->owner)) continue;
    char where[DECK_MESSAGE_MAX], names[DECK_MESSAGE_MAX];
    mica_deck_where(deck, key->path, where, sizeof where);
    snprintf(names, sizeof names, "%s", key->owner);
    for (char *bar = strchr(names, '|'); bar; bar = strchr(bar, '|')) *bar = '/';
    MICA_ERROR(MICA_ERR_INPUT,
               "%s: %s is a setting of %s = \"%s\" only, and %s is \"%s\" here: it would have no effect; remove "
               "it or set %s = \"%s\"",
               where, key->path, key->chooser, names, key->chooser, chosen, key->chooser, names);
  }
  return MICA_SUCCESS;
}

int deck_check(const MicaDeck *deck) {
  CheckContext context = {deck, &deck->params, 0};
  MICA_CALL(check_members(&context, config_root_setting(deck->config), ""));
  MICA_CALL(deck_check_owners(deck));
  return MICA_SUCCESS;
}

/* ---- parameters ---- */

void deck_params_free(DeckParams *params) {
  MICA_FREE(params->names);
  MICA_FREE(params->values);
  params->count = 0;
}

static int check_parameters_group(const MicaDeck *deck, const config_setting_t *group) {
  if (!group || config_setting_is_group(group)) return MICA_SUCCESS;
  char path[DECK_PATH_MAX];
  deck_setting_path(group, path, sizeof path);
  return DECK_FAIL(deck, group, "%s must be a group { name = value; ... }, not %s", path, deck_type_name(group));
}

static int evaluate_parameter(const MicaDeck *deck, const config_setting_t *setting, DeckParams *params) {
  char path[DECK_PATH_MAX];
  const char *name = config_setting_name(setting);
  double *value = &params->values[params->count];
  deck_setting_path(setting, path, sizeof path);
  if (strlen(name) == 1 && strchr("xyzt", name[0]))
    return DECK_FAIL(deck, setting, "%s: x, y, z and t are the coordinates and time; choose another name", path);
  if (deck_is_number(setting)) {
    *value = deck_number_value(setting);
  } else if (config_setting_type(setting) == CONFIG_TYPE_STRING) {
    int ierr = mica_constant_eval(config_setting_get_string(setting), params->count, params->names, params->values,
                                  value);
    if (ierr) {
      deck_prefix_error(deck, setting);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
  } else {
    return DECK_FAIL(deck, setting, "%s must be a number or an expression of the parameters before it, not %s",
                     path, deck_type_name(setting));
  }
  params->names[params->count++] = name;
  return MICA_SUCCESS;
}

/* The parameters in order: the base's (each replaced by the element's of the same name), then the
 * element's new ones. */
static int order_parameters(const config_setting_t *base_group, const config_setting_t *element_group,
                            const config_setting_t **ordered, int *count) {
  *count = 0;
  for (int i = 0; base_group && i < config_setting_length(base_group); i++) {
    const config_setting_t *member = config_setting_get_elem(base_group, (unsigned)i);
    const config_setting_t *replacement =
        element_group ? config_setting_get_member(element_group, config_setting_name(member)) : NULL;
    ordered[(*count)++] = replacement ? replacement : member;
  }
  for (int i = 0; element_group && i < config_setting_length(element_group); i++) {
    const config_setting_t *member = config_setting_get_elem(element_group, (unsigned)i);
    if (!base_group || !config_setting_get_member(base_group, config_setting_name(member)))
      ordered[(*count)++] = member;
  }
  return MICA_SUCCESS;
}

int deck_params_build(const MicaDeck *deck, const config_setting_t *base_group,
                      const config_setting_t *element_group, DeckParams *params) {
  *params = (DeckParams){0, NULL, NULL};
  MICA_CALL(check_parameters_group(deck, base_group));
  MICA_CALL(check_parameters_group(deck, element_group));
  int most = (base_group ? config_setting_length(base_group) : 0) +
             (element_group ? config_setting_length(element_group) : 0);
  const config_setting_t **ordered = NULL;
  int count, ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(ordered, most));
  MICA_CALL_CLEANUP(MICA_MALLOC(params->names, most));
  MICA_CALL_CLEANUP(MICA_MALLOC(params->values, most));
  MICA_CALL_CLEANUP(order_parameters(base_group, element_group, ordered, &count));
  for (int i = 0; i < count; i++) MICA_CALL_CLEANUP(evaluate_parameter(deck, ordered[i], params));
cleanup:
  free(ordered);
  if (ierr) deck_params_free(params);
  return ierr;
}
