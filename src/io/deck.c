/* Decks (deck.h): a libconfig file, read, overridden by --set, completed with the schema's defaults,
 * its parameters evaluated, and checked strictly (deck_check.c). Variants view one element of an
 * overlay list laid over the base deck; getters are in deck_get.c. */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "deck_private.h"
#include "mica/files.h"
#include "mica/registry.h"
#include "mica/text.h"

static int copy_text(const char *text, size_t length, char **copy) {
  MICA_CALL(MICA_MALLOC(*copy, length + 1));
  memcpy(*copy, text, length);
  (*copy)[length] = '\0';
  return MICA_SUCCESS;
}

/* ---- reading ---- */

/* "input/mls_skatulla.cfg" -> "mls_skatulla" */
static int file_stem(const char *path, char **stem) {
  const char *slash = strrchr(path, '/');
  const char *start = slash ? slash + 1 : path;
  const char *dot = strrchr(start, '.');
  size_t length = dot && dot != start ? (size_t)(dot - start) : strlen(start);
  MICA_CALL(copy_text(start, length, stem));
  return MICA_SUCCESS;
}

static int directory_of(const char *path, char **dir) {
  const char *slash = strrchr(path, '/');
  if (!slash) MICA_CALL(copy_text(".", 1, dir));
  else MICA_CALL(copy_text(path, slash == path ? 1 : (size_t)(slash - path), dir));
  return MICA_SUCCESS;
}

/* libconfig's "mismatched element type in array" needs a hint: [1, 2.5] mixes an integer and a float. */
static const char *syntax_hint(const char *libconfig_text) {
  if (libconfig_text && strstr(libconfig_text, "mismatched element type"))
    return " (write every element alike, 1.0 and 2.5, or use a list ( ... ) to mix numbers and strings)";
  return "";
}

/* Every setting's origin, from its line of the expanded text back to its file and line. libconfig has no
 * setter for them; the fields are public. */
static void restore_origins(config_setting_t *setting, const DeckText *text) {
  DeckLine origin = deck_text_line(text, (int)setting->line);
  setting->line = (unsigned)origin.line;
  setting->file = origin.line ? text->files[origin.file] : NULL;
  for (int i = 0; config_setting_is_aggregate(setting) && i < config_setting_length(setting); i++)
    restore_origins(config_setting_get_elem(setting, (unsigned)i), text);
}

static int read_file(MicaDeck *deck) {
  DeckText text;
  MICA_CALL(deck_text_read(deck->path, deck->include_dir, &text));
  int ierr = MICA_SUCCESS;
  if (config_read_string(deck->config, text.text)) {
    restore_origins(config_root_setting(deck->config), &text);
  } else {
    DeckLine origin = deck_text_line(&text, config_error_line(deck->config));
    const char *reason = config_error_text(deck->config);
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%s:%d: %s%s", text.files[origin.file],
                          origin.line, reason, syntax_hint(reason));
  }
  deck->files = text.files, deck->nfiles = text.nfiles; /* the settings' origins point into them */
  text.files = NULL, text.nfiles = 0;
  deck_text_free(&text);
  return ierr;
}

/* ---- overrides ---- */

/* libconfig's names: a letter or '*', then letters, digits, '-', '_', '*'; or a list index [N]. */
static int valid_segment(const char *segment, size_t length) {
  if (length == 0) return 0;
  if (segment[0] == '[') {
    size_t digits = 1;
    while (digits < length && isdigit((unsigned char)segment[digits])) digits++;
    return digits > 1 && digits == length - 1 && segment[length - 1] == ']';
  }
  if (!isalpha((unsigned char)segment[0]) && segment[0] != '*') return 0;
  for (size_t i = 1; i < length; i++)
    if (!isalnum((unsigned char)segment[i]) && !strchr("-_*", segment[i])) return 0;
  return 1;
}

static int valid_path(const char *path) {
  for (const char *segment = path;; segment += strcspn(segment, ".") + 1) {
    if (!valid_segment(segment, strcspn(segment, "."))) return 0;
    if (!segment[strcspn(segment, ".")]) return 1;
  }
}

/* Splits "path=value" and records it, so that errors about the setting can quote it. */
static int record_override(MicaDeck *deck, const char *text) {
  const char *equals = strchr(text, '=');
  MICA_CHECK(equals, MICA_ERR_INPUT, "--set %s: expected path=value, like mls.order=2", text);
  DeckOverride *record = &deck->overrides[deck->noverrides];
  MICA_CALL(copy_text(text, (size_t)(equals - text), &record->path));
  int ierr = copy_text(text, strlen(text), &record->text);
  if (ierr) {
    MICA_FREE(record->path);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  deck->noverrides++;
  MICA_CHECK(valid_path(record->path), MICA_ERR_INPUT,
             "--set %s: '%s' is not a setting path (names separated by dots, like mls.order)", text, record->path);
  MICA_CHECK(equals[1], MICA_ERR_INPUT, "--set %s: no value after '='", text);
  return MICA_SUCCESS;
}

/* The value in libconfig syntax; a bare word (cubic, x^2) that is no libconfig value is a string. What
 * starts like a string, array, list or group but does not parse is a mistake, not a word. */
static int parse_override_value(const char *text, const char *value_text, config_t *scratch,
                                config_setting_t **value) {
  char *rewritten;
  MICA_CALL(deck_text_value(text, value_text, &rewritten));
  *value = NULL; /* stays NULL when the text is no libconfig value (rewritten NULL) */
  int ierr = rewritten ? deck_parse_value(scratch, rewritten, value) : MICA_SUCCESS;
  free(rewritten);
  MICA_CALL(ierr);
  if (*value) return MICA_SUCCESS;
  const char *start = value_text + strspn(value_text, " \t");
  if (strchr("[({\"", *start) && *start) {
    const char *reason = config_error_text(scratch) ? config_error_text(scratch) : "more than one value";
    MICA_ERROR(MICA_ERR_INPUT, "--set %s: cannot read the value: %s%s", text, reason, syntax_hint(reason));
  }
  config_destroy(scratch);
  config_init(scratch);
  *value = config_setting_add(config_root_setting(scratch), "v", CONFIG_TYPE_STRING);
  MICA_CHECK(*value && config_setting_set_string(*value, value_text), MICA_ERR_LIBRARY,
             "libconfig could not hold the value of --set %s", text);
  return MICA_SUCCESS;
}

/* One step of an override's path: an existing member of any kind, a new group, or a list element. */
static int override_step(const DeckOverride *override, config_setting_t *current, const char *segment,
                         size_t length, config_setting_t **next) {
  char name[DECK_PATH_MAX], walked[DECK_PATH_MAX];
  snprintf(name, sizeof name, "%.*s", (int)length, segment);
  snprintf(walked, sizeof walked, "%.*s", (int)(segment + length - override->path), override->path);
  *next = NULL;
  if (name[0] == '[') {
    *next = deck_walk(current, name, NULL);
    MICA_CHECK(*next, MICA_ERR_INPUT, "--set %s: there is no %s", override->text, walked);
    return MICA_SUCCESS;
  }
  MICA_CHECK(config_setting_is_group(current), MICA_ERR_INPUT, "--set %s: %.*s is %s, not a group", override->text,
             (int)(segment - override->path - 1), override->path, deck_type_name(current));
  *next = config_setting_get_member(current, name);
  if (!*next) MICA_CALL(deck_tree_group(current, name, next));
  return MICA_SUCCESS;
}

/* The group that holds the override's last segment, creating groups on the way. */
static int override_parent(MicaDeck *deck, const DeckOverride *override, config_setting_t **parent,
                           const char **last) {
  config_setting_t *current = config_root_setting(deck->config);
  const char *segment = override->path;
  for (size_t length = strcspn(segment, "."); segment[length]; length = strcspn(segment, ".")) {
    MICA_CALL(override_step(override, current, segment, length, &current));
    segment += length + 1;
  }
  int indexable = config_setting_is_list(current) || config_setting_is_array(current);
  MICA_CHECK(segment[0] != '[' || !indexable, MICA_ERR_INPUT,
             "--set %s: set the whole list or array, not one element", override->text);
  MICA_CHECK(config_setting_is_group(current), MICA_ERR_INPUT, "--set %s: %.*s is %s, not a group", override->text,
             (int)(segment - override->path - 1), override->path, deck_type_name(current));
  *parent = current;
  *last = segment;
  return MICA_SUCCESS;
}

static int apply_override(MicaDeck *deck, const char *text) {
  MICA_CALL(record_override(deck, text));
  const DeckOverride *override = &deck->overrides[deck->noverrides - 1];
  config_t scratch;
  config_init(&scratch);
  config_setting_t *value = NULL, *parent = NULL;
  const char *last = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(parse_override_value(text, strchr(text, '=') + 1, &scratch, &value));
  MICA_CALL_CLEANUP(override_parent(deck, override, &parent, &last));
  MICA_CALL_CLEANUP(deck_tree_put(parent, last, value, 0));
cleanup:
  config_destroy(&scratch);
  return ierr;
}

/* ---- defaults ---- */

static int add_default(config_setting_t *group, const char *name, const MicaDeckKey *key) {
  config_t scratch;
  config_init(&scratch);
  config_setting_t *value;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(deck_parse_value(&scratch, key->def, &value));
  if (!value) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT,
                          "schema: default of %s (%s) is not a libconfig value", key->path, key->def);
    goto cleanup;
  }
  MICA_CALL_CLEANUP(deck_tree_put(group, name, value, 0));
cleanup:
  config_destroy(&scratch);
  return ierr;
}

/* Puts key's default at path below group unless a setting is there. A path through a list ("a.[].b")
 * gets the default in every element. Where the deck has something else than a group on the way, the
 * default is left out: the check reports the deck's mistake. */
static int fill_default(config_setting_t *group, const char *path, const MicaDeckKey *key) {
  const char *through_list = strstr(path, ".[].");
  if (through_list) {
    char list_path[DECK_PATH_MAX];
    snprintf(list_path, sizeof list_path, "%.*s", (int)(through_list - path), path);
    config_setting_t *list = deck_walk(group, list_path, NULL);
    for (int i = 0; list && config_setting_is_list(list) && i < config_setting_length(list); i++) {
      config_setting_t *element = config_setting_get_elem(list, (unsigned)i);
      if (config_setting_is_group(element)) MICA_CALL(fill_default(element, through_list + 4, key));
    }
    return MICA_SUCCESS;
  }
  size_t length = strcspn(path, ".");
  char name[DECK_PATH_MAX];
  snprintf(name, sizeof name, "%.*s", (int)length, path);
  if (!path[length]) return config_setting_get_member(group, name) ? MICA_SUCCESS : add_default(group, name, key);
  config_setting_t *member;
  MICA_CALL(deck_tree_group(group, name, &member));
  if (member) MICA_CALL(fill_default(member, path + length + 1, key));
  return MICA_SUCCESS;
}

static int fill_defaults(MicaDeck *deck) {
  for (const MicaDeckKey *key = deck->schema; key->path; key++)
    if (key->def) MICA_CALL(fill_default(config_root_setting(deck->config), key->path, key));
  return MICA_SUCCESS;
}

/* ---- life cycle ---- */

static int evaluate_parameters(MicaDeck *deck) {
  const MicaDeckKey *key = deck_schema_parameters(deck->schema);
  const config_setting_t *group = key ? deck_walk(config_root_setting(deck->config), key->path, NULL) : NULL;
  MICA_CALL(deck_params_build(deck, group, NULL, &deck->params));
  return MICA_SUCCESS;
}

static int deck_create(const char *path, const MicaDeckKey *schema, int noverrides, MicaDeck **deck) {
  MICA_CALL(MICA_CALLOC(*deck, 1));
  MICA_CALL(mica_schema_compose(schema, &(*deck)->composed));
  (*deck)->schema = mica_schema_keys((*deck)->composed);
  MICA_CALL(copy_text(path, strlen(path), &(*deck)->path));
  MICA_CALL(file_stem(path, &(*deck)->name));
  MICA_CALL(directory_of(path, &(*deck)->include_dir));
  MICA_CALL(MICA_CALLOC((*deck)->overrides, noverrides > 0 ? noverrides : 1));
  MICA_CALL(MICA_CALLOC((*deck)->config, 1));
  config_init((*deck)->config);
  return MICA_SUCCESS;
}

int mica_deck_load(const char *path, const MicaDeckKey *schema, int noverrides, const char *const *overrides,
                   MicaDeck **deck) {
  MICA_CHECK(path && schema && deck && noverrides >= 0 && (overrides || !noverrides), MICA_ERR_ARGUMENT,
             "mica_deck_load: bad argument");
  *deck = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(deck_create(path, schema, noverrides, deck));
  MICA_CALL_CLEANUP(read_file(*deck));
  for (int i = 0; i < noverrides; i++) MICA_CALL_CLEANUP(apply_override(*deck, overrides[i]));
  MICA_CALL_CLEANUP(fill_defaults(*deck));
  MICA_CALL_CLEANUP(evaluate_parameters(*deck));
  MICA_CALL_CLEANUP(deck_check(*deck));
  return MICA_SUCCESS;
cleanup:
  mica_deck_destroy(deck);
  return ierr;
}

int mica_deck_destroy(MicaDeck **deck) {
  if (!deck || !*deck) return MICA_SUCCESS;
  MicaDeck *d = *deck;
  if (!d->base && d->config) {
    config_destroy(d->config);
    free(d->config);
  }
  mica_schema_destroy(&d->composed);
  for (int i = 0; i < d->noverrides; i++) {
    free(d->overrides[i].path);
    free(d->overrides[i].text);
  }
  free(d->overrides);
  deck_params_free(&d->params);
  free(d->path);
  free(d->name);
  free(d->include_dir);
  for (int i = 0; i < d->nfiles; i++) free(d->files[i]);
  free(d->files);
  free(d->list_path);
  MICA_FREE(*deck);
  return MICA_SUCCESS;
}

/* ---- variants ---- */

static int variant_name(const config_setting_t *element, int index, char **name) {
  const char *given;
  if (config_setting_lookup_string(element, "name", &given)) {
    MICA_CALL(copy_text(given, strlen(given), name));
    return MICA_SUCCESS;
  }
  char numbered[32];
  snprintf(numbered, sizeof numbered, "variant %d", index + 1);
  MICA_CALL(copy_text(numbered, strlen(numbered), name));
  return MICA_SUCCESS;
}

static int variant_parameters(MicaDeck *variant) {
  const MicaDeckKey *key = deck_schema_parameters(variant->schema);
  if (!key) return MICA_SUCCESS;
  const config_setting_t *base_group = deck_walk(config_root_setting(variant->config), key->path, NULL);
  const config_setting_t *element_group = deck_walk(variant->element, key->path, NULL);
  MICA_CALL(deck_params_build(variant, base_group, element_group, &variant->params));
  return MICA_SUCCESS;
}

int mica_deck_variant(const MicaDeck *base, const char *list_path, int i, MicaDeck **variant) {
  MICA_CHECK(base && list_path && variant && !base->base, MICA_ERR_ARGUMENT, "mica_deck_variant: bad argument");
  *variant = NULL;
  config_setting_t *list = deck_walk(config_root_setting(base->config), list_path, NULL);
  config_setting_t *element = list && config_setting_is_list(list) && i >= 0
                                  ? config_setting_get_elem(list, (unsigned)i) : NULL;
  MICA_CHECK(element && config_setting_is_group(element), MICA_ERR_ARGUMENT,
             "mica_deck_variant: %s has no element %d", list_path, i);
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(*variant, 1));
  MicaDeck *v = *variant;
  v->config = base->config;
  v->schema = base->schema;
  v->base = base;
  v->element = element;
  v->index = i;
  MICA_CALL_CLEANUP(copy_text(base->path, strlen(base->path), &v->path));
  MICA_CALL_CLEANUP(copy_text(list_path, strlen(list_path), &v->list_path));
  MICA_CALL_CLEANUP(variant_name(element, i, &v->name));
  MICA_CALL_CLEANUP(variant_parameters(v));
  MICA_CALL_CLEANUP(deck_check_owners(v));
  return MICA_SUCCESS;
cleanup:
  mica_deck_destroy(variant);
  return ierr;
}

const char *mica_deck_name(const MicaDeck *deck) { return deck ? deck->name : NULL; }
const char *mica_deck_path(const MicaDeck *deck) { return deck ? deck->path : NULL; }

int mica_deck_override_count(const MicaDeck *deck) {
  return deck ? (deck->base ? deck->base : deck)->noverrides : 0;
}

const char *mica_deck_override_text(const MicaDeck *deck, int i) {
  const MicaDeck *base = deck ? (deck->base ? deck->base : deck) : NULL;
  return base && i >= 0 && i < base->noverrides ? base->overrides[i].text : NULL;
}

/* ---- the resolved deck ---- */

/* A variant's resolved deck is the base with the element laid over it and without the overlay list:
 * a deck that runs that variant alone. */
static int merge_variant(const MicaDeck *variant, config_t *merged) {
  config_setting_t *root = config_root_setting(merged);
  MICA_CALL(deck_tree_merge(root, config_root_setting(variant->config), NULL));
  MICA_CALL(deck_tree_merge(root, variant->element, "name"));
  char parent_path[DECK_PATH_MAX];
  snprintf(parent_path, sizeof parent_path, "%s", variant->list_path);
  char *dot = strrchr(parent_path, '.');
  const char *list_name = dot ? variant->list_path + (dot - parent_path) + 1 : variant->list_path;
  *(dot ? dot : parent_path) = '\0';
  config_setting_t *parent = deck_walk(root, parent_path, NULL);
  if (parent) config_setting_remove(parent, list_name);
  return MICA_SUCCESS;
}

static void write_header(const MicaDeck *deck, FILE *stream) {
  const MicaDeck *base = deck->base ? deck->base : deck;
  fprintf(stream, "# resolved by mica from %s", base->path);
  if (deck->base) fprintf(stream, ", variant \"%s\" (%s.[%d])", deck->name, deck->list_path, deck->index);
  for (int i = 0; i < base->noverrides; i++) fprintf(stream, "%s --set %s", i ? "" : " with", base->overrides[i].text);
  fprintf(stream, "\n# (overrides applied, defaults filled in)\n");
}

int mica_deck_write_resolved(const MicaDeck *deck, const char *path) {
  MICA_CHECK(deck && path, MICA_ERR_ARGUMENT, "mica_deck_write_resolved: NULL argument");
  config_t merged;
  config_init(&merged);
  MicaOutFile out = {NULL, NULL, NULL};
  int ierr = MICA_SUCCESS;
  const config_t *source = deck->config;
  if (deck->base) {
    MICA_CALL_CLEANUP(merge_variant(deck, &merged));
    source = &merged;
  }
  MICA_CALL_CLEANUP(mica_out_open(path, &out));
  write_header(deck, out.fp);
  config_write(source, out.fp);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  config_destroy(&merged);
  return ierr;
}

/* ---- the schema as a table ---- */

static void key_type(const MicaDeckKey *key, char *buf, size_t size) {
  static const char *const names[] = {"int",  "float",    "bool",  "string", "choice",  "ints",
                                      "floats", "function", "group", "list",   "overlay", "parameters"};
  const char *name = names[key->type];
  if ((key->type == MICA_KEY_INTS || key->type == MICA_KEY_FLOATS) && key->len_max <= 0 && key->len_min > 0)
    snprintf(buf, size, "%s[%d+]", name, key->len_min); /* no most: as many as wanted */
  else if ((key->type == MICA_KEY_INTS || key->type == MICA_KEY_FLOATS) && key->len_max > key->len_min)
    snprintf(buf, size, "%s[%d-%d]", name, key->len_min, key->len_max);
  else if (key->type == MICA_KEY_INTS || key->type == MICA_KEY_FLOATS)
    snprintf(buf, size, "%s[%d]", name, key->len_min);
  else
    snprintf(buf, size, "%s", name);
}

static void key_range(const MicaDeckKey *key, char *buf, size_t size) {
  buf[0] = '\0';
  if (key->type == MICA_KEY_CHOICE && key->choices) {
    snprintf(buf, size, "%s", key->choices);
  } else if (key->type == MICA_KEY_BOOL && key->choices) {
    snprintf(buf, size, "true|false|%s", key->choices);
  } else if (key->min <= key->max) {
    char low[32], high[32];
    deck_format_number(key->min, low, sizeof low);
    deck_format_number(key->max, high, sizeof high);
    snprintf(buf, size, "[%s, %s]", low, high);
  }
}

typedef struct {
  char type[32], range[256];
  const char *def;
} KeyColumns;

static KeyColumns key_columns(const MicaDeckKey *key) {
  KeyColumns columns;
  key_type(key, columns.type, sizeof columns.type);
  key_range(key, columns.range, sizeof columns.range);
  columns.def = key->def ? key->def : "-";
  return columns;
}

static int widest(int width, const char *text) {
  int w = mica_text_width(text, SIZE_MAX);
  return w > width ? w : width;
}

enum { HELP_INDENT = 4 }; /* a setting's description, under its line */

/* path, type and default in columns, then the range from column `at`, wrapped there after a '|' */
static void print_key_line(const char *path, const char *type, const char *def, const char *range,
                           const int widths[3], int width, FILE *stream) {
  const int at = widths[0] + widths[1] + widths[2] + 6;
  mica_text_pad(stream, path, widths[0] + 2);
  mica_text_pad(stream, type, widths[1] + 2);
  if (!range[0]) {
    fprintf(stream, "%s\n", def);
    return;
  }
  mica_text_pad(stream, def, widths[2] + 2);
  mica_text_wrap(stream, range, at, at, width, "|");
}

static void print_key_help(const char *help, int width, FILE *stream) {
  if (!help || !help[0]) return;
  fprintf(stream, "%*s", HELP_INDENT, "");
  mica_text_wrap(stream, help, HELP_INDENT, HELP_INDENT, width, NULL);
}

/* A chooser's types under its help, one "name: description" each (the registry's words for them), so that
 * a type an extension registers is explained where it is offered. */
static void print_key_types(const MicaDeckKey *key, int width, FILE *stream) {
  if (key->type != MICA_KEY_CHOICE || !key->registry) return;
  for (int i = 0; i < mica_registry_count(key->registry); i++) {
    const MicaType *type = mica_registry_type(key->registry, i);
    if (!type->description || !type->description[0]) continue;
    char line[1024];
    snprintf(line, sizeof line, "%s: %s", type->name, type->description);
    fprintf(stream, "%*s", 2 * HELP_INDENT, "");
    mica_text_wrap(stream, line, 2 * HELP_INDENT, 3 * HELP_INDENT, width, NULL);
  }
}

/* Under the first key of a type of a registry fragment (output.vtu), the type's family, name and description,
 * so that an output an extension registers is explained with its settings. */
static void print_family_type(const MicaDeckKey *key, const MicaDeckKey *previous, int width, FILE *stream) {
  if (!key->family || (previous && previous->owner == key->owner)) return;
  const MicaType *type = mica_registry_find(key->family, key->owner);
  if (!type || !type->description || !type->description[0]) return;
  char line[1024];
  snprintf(line, sizeof line, "%s %s: %s", key->family->family, type->name, type->description);
  fprintf(stream, "%*s", 2 * HELP_INDENT, "");
  mica_text_wrap(stream, line, 2 * HELP_INDENT, 3 * HELP_INDENT, width, NULL);
}

int mica_deck_print_schema(const MicaDeckKey *base, int width, FILE *stream) {
  MicaSchema *composed;
  MICA_CALL(mica_schema_compose(base, &composed));
  const MicaDeckKey *schema = mica_schema_keys(composed);
  int widths[3] = {7, 4, 7}; /* the headings' lengths */
  for (const MicaDeckKey *key = schema; key->path; key++) {
    KeyColumns columns = key_columns(key);
    widths[0] = widest(widths[0], key->path);
    widths[1] = widest(widths[1], columns.type);
    widths[2] = widest(widths[2], columns.def);
  }
  print_key_line("setting", "type", "default", "range", widths, width, stream);
  print_key_help("description", width, stream);
  for (const MicaDeckKey *key = schema; key->path; key++) {
    KeyColumns columns = key_columns(key);
    print_key_line(key->path, columns.type, columns.def, columns.range, widths, width, stream);
    print_key_help(key->help, width, stream);
    print_key_types(key, width, stream);
    print_family_type(key, key == schema ? NULL : key - 1, width, stream);
  }
  return mica_schema_destroy(&composed);
}

/* ---- the schema as Markdown (docs/input.md's tables) ---- */

/* A path under group ("mls" holds "mls" and "mls.order", not "mlsx"); every path with no group. */
static int in_group(const char *path, const char *group) {
  if (!group || !group[0]) return 1;
  const size_t n = strlen(group);
  return !strncmp(path, group, n) && (path[n] == '\0' || path[n] == '.');
}

/* '<' before a letter, '/' or '!': what Markdown would take for an HTML tag. */
static int opens_tag(const char *c) {
  const char next = (char)(c[1] | 0x20);
  return c[0] == '<' && (c[1] == '/' || c[1] == '!' || (next >= 'a' && next <= 'z'));
}

/* Text in a table cell, as it reads: '|' would end the cell, '*' and '\\' would be markup, a tag would vanish
 * and a newline would end the row. */
static void markdown_text(const char *text, FILE *stream) {
  for (const char *c = text; *c; c++) {
    if (*c == '|' || *c == '*' || *c == '\\') fputc('\\', stream);
    if (opens_tag(c)) fputs("&lt;", stream);
    else fputc(*c == '\n' ? ' ' : *c, stream);
  }
}

/* After the meaning, what the text help prints under it: a chooser's types, a family type's description. */
static void markdown_types(const MicaDeckKey *key, const MicaDeckKey *previous, FILE *stream) {
  for (int i = 0; key->type == MICA_KEY_CHOICE && key->registry && i < mica_registry_count(key->registry); i++) {
    const MicaType *type = mica_registry_type(key->registry, i);
    if (!type->description || !type->description[0]) continue;
    fprintf(stream, "<br>`%s`: ", type->name);
    markdown_text(type->description, stream);
  }
  if (!key->family || (previous && previous->owner == key->owner)) return;
  const MicaType *type = mica_registry_find(key->family, key->owner);
  if (!type || !type->description || !type->description[0]) return;
  fprintf(stream, "<br>%s `%s`: ", key->family->family, type->name);
  markdown_text(type->description, stream);
}

static void markdown_row(const MicaDeckKey *key, const MicaDeckKey *previous, FILE *stream) {
  KeyColumns columns = key_columns(key);
  fprintf(stream, "| `%s` | %s | ", key->path, columns.type);
  markdown_text(columns.def, stream);
  fputs(" | ", stream);
  markdown_text(columns.range, stream);
  fputs(" | ", stream);
  markdown_text(key->help ? key->help : "", stream);
  markdown_types(key, previous, stream);
  fputs(" |\n", stream);
}

static int print_markdown(const MicaDeckKey *schema, const char *group, FILE *stream) {
  const MicaDeckKey *previous = NULL;
  long rows = 0;
  for (const MicaDeckKey *key = schema; key->path; key++) rows += in_group(key->path, group);
  MICA_CHECK(rows > 0, MICA_ERR_INPUT, "no setting is in the group '%s' (a group is a setting's path up to a dot: mls "
             "of mls.order)", group);
  fputs("| setting | type | default | range | meaning |\n|---|---|---|---|---|\n", stream);
  for (const MicaDeckKey *key = schema; key->path; previous = key++)
    if (in_group(key->path, group)) markdown_row(key, previous, stream);
  return MICA_SUCCESS;
}

int mica_deck_print_schema_markdown(const MicaDeckKey *base, const char *group, FILE *stream) {
  MicaSchema *composed;
  MICA_CALL(mica_schema_compose(base, &composed));
  int ierr = print_markdown(mica_schema_keys(composed), group, stream);
  mica_schema_destroy(&composed);
  return ierr;
}

const MicaDeckKey *mica_deck_schema(const MicaDeck *deck) { return deck->schema; }
