/* Deck helpers over the schema and libconfig's tree: finding keys, naming settings by path, walking
 * paths with list indices, and copying values between configs (libconfig 1.5 has no copy, and can only
 * append a member to a group, so replacing one in place means rebuilding the members after it). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "deck_private.h"

const MicaDeckKey *deck_schema_find(const MicaDeckKey *schema, const char *schema_path) {
  for (const MicaDeckKey *key = schema; key->path; key++)
    if (strcmp(key->path, schema_path) == 0) return key;
  return NULL;
}

int deck_path_within(const char *a, const char *b) {
  size_t length = strlen(a);
  return strncmp(a, b, length) == 0 && (b[length] == '\0' || b[length] == '.' || length == 0);
}

int deck_schema_has_children(const MicaDeckKey *schema, const char *schema_path) {
  for (const MicaDeckKey *key = schema; key->path; key++)
    if (strcmp(key->path, schema_path) != 0 && deck_path_within(schema_path, key->path)) return 1;
  return 0;
}

const MicaDeckKey *deck_schema_parameters(const MicaDeckKey *schema) {
  for (const MicaDeckKey *key = schema; key->path; key++)
    if (key->type == MICA_KEY_PARAMETERS) return key;
  return NULL;
}

void deck_schema_path(const char *path, char *buf, size_t size) {
  size_t used = 0;
  for (const char *c = path; *c && used + 1 < size; c++) {
    buf[used++] = *c;
    if (*c == '[') /* drop the index digits */
      while (c[1] >= '0' && c[1] <= '9') c++;
  }
  buf[used] = '\0';
}

static size_t append_setting_path(const config_setting_t *setting, char *buf, size_t size) {
  const config_setting_t *parent = config_setting_parent(setting);
  if (!parent) {
    buf[0] = '\0';
    return 0;
  }
  size_t used = append_setting_path(parent, buf, size);
  const char *dot = used ? "." : "";
  int written = config_setting_is_group(parent)
                    ? snprintf(buf + used, size - used, "%s%s", dot, config_setting_name(setting))
                    : snprintf(buf + used, size - used, "%s[%d]", dot, config_setting_index(setting));
  used += written > 0 ? (size_t)written : 0;
  return used < size ? used : size - 1;
}

void deck_setting_path(const config_setting_t *setting, char *buf, size_t size) {
  if (size) append_setting_path(setting, buf, size);
}

/* One step of a walk: segment is a member name or "[N]". */
static config_setting_t *step(config_setting_t *current, const char *segment, size_t length, int *fallback) {
  if (segment[0] == '[') {
    char *end;
    long index = strtol(segment + 1, &end, 10);
    int valid = end == segment + length - 1 && *end == ']' && index >= 0;
    int indexable = config_setting_is_list(current) || config_setting_is_array(current);
    return valid && indexable ? config_setting_get_elem(current, (unsigned)index) : NULL;
  }
  if (!config_setting_is_group(current) || length >= DECK_PATH_MAX) return NULL;
  char name[DECK_PATH_MAX];
  memcpy(name, segment, length);
  name[length] = '\0';
  config_setting_t *member = config_setting_get_member(current, name);
  if (!member && fallback) *fallback = 1;
  return member;
}

config_setting_t *deck_walk(config_setting_t *start, const char *path, int *fallback) {
  config_setting_t *current = start;
  const char *rest = path;
  if (fallback) *fallback = 0;
  while (current && *rest) {
    size_t length = strcspn(rest, ".");
    current = length ? step(current, rest, length, fallback) : NULL;
    rest += length;
    if (*rest == '.') rest++;
  }
  return current;
}

const char *deck_type_name(const config_setting_t *setting) {
  switch (config_setting_type(setting)) {
  case CONFIG_TYPE_INT:
  case CONFIG_TYPE_INT64: return "an integer";
  case CONFIG_TYPE_FLOAT: return "a number";
  case CONFIG_TYPE_STRING: return "a string";
  case CONFIG_TYPE_BOOL: return "a boolean";
  case CONFIG_TYPE_GROUP: return "a group";
  case CONFIG_TYPE_ARRAY: return "an array";
  case CONFIG_TYPE_LIST: return "a list";
  default: return "nothing";
  }
}

int deck_is_number(const config_setting_t *setting) { return config_setting_is_number(setting); }

double deck_number_value(const config_setting_t *setting) {
  if (config_setting_type(setting) == CONFIG_TYPE_FLOAT) return config_setting_get_float(setting);
  return (double)config_setting_get_int64(setting);
}

int deck_parse_value(config_t *scratch, const char *text, config_setting_t **value) {
  *value = NULL;
  size_t size = strlen(text) + sizeof "v = ;\n";
  char *statement;
  MICA_CALL(MICA_MALLOC(statement, size));
  snprintf(statement, size, "v = %s;\n", text);
  int parsed = config_read_string(scratch, statement);
  free(statement);
  /* Exactly one setting: "1; w = 2" must not sneak a second one in. */
  config_setting_t *root = config_root_setting(scratch);
  if (parsed && config_setting_length(root) == 1) *value = config_setting_get_elem(root, 0);
  return MICA_SUCCESS;
}

static int copy_scalar(config_setting_t *copy, const config_setting_t *src) {
  int ok = CONFIG_TRUE;
  switch (config_setting_type(src)) {
  case CONFIG_TYPE_INT: ok = config_setting_set_int(copy, config_setting_get_int(src)); break;
  case CONFIG_TYPE_INT64: ok = config_setting_set_int64(copy, config_setting_get_int64(src)); break;
  case CONFIG_TYPE_FLOAT: ok = config_setting_set_float(copy, config_setting_get_float(src)); break;
  case CONFIG_TYPE_BOOL: ok = config_setting_set_bool(copy, config_setting_get_bool(src)); break;
  case CONFIG_TYPE_STRING: ok = config_setting_set_string(copy, config_setting_get_string(src)); break;
  default: break;
  }
  config_setting_set_format(copy, config_setting_get_format(src));
  MICA_CHECK(ok, MICA_ERR_LIBRARY, "libconfig could not copy a setting");
  return MICA_SUCCESS;
}

static int copy_setting(config_setting_t *parent, const char *name, const config_setting_t *src, int keep_lines) {
  config_setting_t *copy = config_setting_add(parent, name, config_setting_type(src));
  MICA_CHECK(copy, MICA_ERR_LIBRARY, "libconfig could not add setting '%s'", name ? name : "(element)");
  /* libconfig has no setter for a setting's origin; the fields are public, and messages need them. */
  copy->line = keep_lines ? src->line : 0;
  copy->file = keep_lines ? src->file : NULL;
  if (!config_setting_is_aggregate(src)) {
    MICA_CALL(copy_scalar(copy, src));
    return MICA_SUCCESS;
  }
  int group = config_setting_is_group(src);
  for (int i = 0; i < config_setting_length(src); i++) {
    const config_setting_t *member = config_setting_get_elem(src, (unsigned)i);
    MICA_CALL(copy_setting(copy, group ? config_setting_name(member) : NULL, member, keep_lines));
  }
  return MICA_SUCCESS;
}

/* Replaces member index of group by a copy of src, keeping the order of members: the members after it
 * are parked in a scratch config, removed, and appended again after the new value. */
static int replace_member(config_setting_t *group, int index, const config_setting_t *src, int keep_lines) {
  config_t parking;
  config_init(&parking);
  config_setting_t *parked = config_root_setting(&parking);
  int count = config_setting_length(group), ierr = MICA_SUCCESS;
  char name[DECK_PATH_MAX];
  snprintf(name, sizeof name, "%s", config_setting_name(config_setting_get_elem(group, (unsigned)index)));
  for (int i = index + 1; i < count; i++) {
    const config_setting_t *member = config_setting_get_elem(group, (unsigned)i);
    MICA_CALL_CLEANUP(copy_setting(parked, config_setting_name(member), member, 1));
  }
  for (int i = count - 1; i >= index; i--) config_setting_remove_elem(group, (unsigned)i);
  MICA_CALL_CLEANUP(copy_setting(group, name, src, keep_lines));
  for (int i = 0; i < config_setting_length(parked); i++) {
    const config_setting_t *member = config_setting_get_elem(parked, (unsigned)i);
    MICA_CALL_CLEANUP(copy_setting(group, config_setting_name(member), member, 1));
  }
cleanup:
  config_destroy(&parking);
  return ierr;
}

int deck_tree_put(config_setting_t *parent, const char *name, const config_setting_t *src, int keep_lines) {
  MICA_CHECK(config_setting_is_group(parent) && name, MICA_ERR_ARGUMENT, "deck_tree_put: parent is no group");
  config_setting_t *existing = config_setting_get_member(parent, name);
  if (existing) MICA_CALL(replace_member(parent, config_setting_index(existing), src, keep_lines));
  else MICA_CALL(copy_setting(parent, name, src, keep_lines));
  return MICA_SUCCESS;
}

int deck_tree_group(config_setting_t *group, const char *name, config_setting_t **member) {
  *member = config_setting_get_member(group, name);
  if (*member) {
    if (!config_setting_is_group(*member)) *member = NULL;
    return MICA_SUCCESS;
  }
  *member = config_setting_add(group, name, CONFIG_TYPE_GROUP);
  MICA_CHECK(*member, MICA_ERR_INPUT, "'%s' is not a valid setting name", name);
  return MICA_SUCCESS;
}

int deck_tree_merge(config_setting_t *dst, const config_setting_t *src, const char *skip_member) {
  for (int i = 0; i < config_setting_length(src); i++) {
    const config_setting_t *member = config_setting_get_elem(src, (unsigned)i);
    const char *name = config_setting_name(member);
    if (skip_member && strcmp(name, skip_member) == 0) continue;
    config_setting_t *target = config_setting_get_member(dst, name);
    if (target && config_setting_is_group(target) && config_setting_is_group(member))
      MICA_CALL(deck_tree_merge(target, member, NULL));
    else
      MICA_CALL(deck_tree_put(dst, name, member, 1));
  }
  return MICA_SUCCESS;
}
