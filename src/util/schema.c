/* Schemas (mica/schema.h): expanding a base schema's registries and fragments into the keys a deck is
 * checked against, and reading settings through the reader a deck provides. */
#include "mica/schema.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/registry.h"

struct MicaSchema {
  MicaDeckKey *keys; /* nkeys + the {NULL} end */
  long nkeys, capacity;
  char **strings; /* the paths, choices, defaults and help texts the composition made */
  long nstrings, string_capacity;
};

static int keep_string(MicaSchema *schema, char *text) {
  if (schema->nstrings == schema->string_capacity) {
    const long grown = schema->string_capacity ? 2 * schema->string_capacity : 64;
    int ierr = MICA_REALLOC(schema->strings, grown);
    if (ierr) {
      free(text);
      return ierr;
    }
    schema->string_capacity = grown;
  }
  schema->strings[schema->nstrings++] = text;
  return MICA_SUCCESS;
}

/* A new string made by printf, kept by the schema. */
static int format(MicaSchema *schema, const char **out, const char *fmt, ...) MICA_PRINTF(3, 4);
static int format(MicaSchema *schema, const char **out, const char *fmt, ...) {
  va_list args;
  va_start(args, fmt);
  const int n = vsnprintf(NULL, 0, fmt, args);
  va_end(args);
  char *text;
  MICA_CALL(MICA_MALLOC(text, (size_t)n + 1));
  va_start(args, fmt);
  vsnprintf(text, (size_t)n + 1, fmt, args);
  va_end(args);
  MICA_CALL(keep_string(schema, text));
  *out = text;
  return MICA_SUCCESS;
}

static int append_key(MicaSchema *schema, const MicaDeckKey *key) {
  if (schema->nkeys + 1 >= schema->capacity) {
    const long grown = schema->capacity ? 2 * schema->capacity : 128;
    MICA_CALL(MICA_REALLOC(schema->keys, grown));
    schema->capacity = grown;
  }
  schema->keys[schema->nkeys++] = *key;
  memset(&schema->keys[schema->nkeys], 0, sizeof *schema->keys);
  return MICA_SUCCESS;
}

static MicaDeckKey *find_composed(MicaSchema *schema, const char *path) {
  for (long i = 0; i < schema->nkeys; i++)
    if (!strcmp(schema->keys[i].path, path)) return &schema->keys[i];
  return NULL;
}

/* "mls" of "mls.weight", "" of "method". */
static void group_of(const char *path, char *group, size_t size) {
  const char *dot = strrchr(path, '.');
  snprintf(group, size, "%.*s", dot ? (int)(dot - path) : 0, path);
}

/* Marks key as a setting of type too and says so in its help: "with mls.weight = exponential: <help>"; a
 * key that several types of one chooser declare ("alpha" of two weights) names them all, "= a or b". */
static int add_owner(MicaSchema *schema, MicaDeckKey *key, const char *type, const char *help) {
  const char *owners = type;
  if (key->owner) {
    help = strstr(key->help, ": ") + 2; /* the help as the first owner declared it */
    MICA_CALL(format(schema, &owners, "%s|%s", key->owner, type));
  }
  char names[1024]; /* owners "a|b" read as "a or b" */
  size_t used = 0;
  for (const char *c = owners; *c && used + 5 < sizeof names; c++) {
    if (*c != '|') names[used++] = *c;
    else memcpy(names + used, " or ", 4), used += 4;
  }
  names[used] = '\0';
  key->owner = owners;
  return format(schema, &key->help, "with %s = %s: %s", key->chooser, names, help ? help : "");
}

static int add_type_keys(MicaSchema *schema, const char *chooser, const MicaType *type) {
  char group[512];
  group_of(chooser, group, sizeof group);
  for (const MicaDeckKey *own = type->keys; own && own->path; own++) {
    const char *path;
    MICA_CALL(format(schema, &path, "%s%s%s", group, group[0] ? "." : "", own->path));
    MicaDeckKey *key = find_composed(schema, path);
    if (!key) {
      MicaDeckKey copy = *own;
      copy.path = path;
      copy.owner = NULL;
      copy.chooser = chooser;
      MICA_CALL(append_key(schema, &copy));
      key = &schema->keys[schema->nkeys - 1];
    }
    MICA_CHECK(key->chooser && !strcmp(key->chooser, chooser), MICA_ERR_ARGUMENT,
               "schema: %s is declared by the %s type '%s' and by another key", path, chooser, type->name);
    MICA_CALL(add_owner(schema, key, type->name, own->help));
  }
  return MICA_SUCCESS;
}

/* A key that several types declare with different defaults (bc.alpha: 1e3 with penalty, 100 with nitsche)
 * has none in the schema, since the default depends on the chooser: its help lists them, and each type
 * reads its own (mica_type_float). */
static int note_type_defaults(MicaSchema *schema, MicaDeckKey *key, const MicaRegistry *registry) {
  char group[512];
  group_of(key->chooser, group, sizeof group);
  const char *relative = key->path + strlen(group) + (group[0] != '\0');
  char list[1024] = "";
  size_t used = 0;
  int differ = 0;
  for (int i = 0; i < mica_registry_count(registry); i++) {
    const MicaType *type = mica_registry_type(registry, i);
    const MicaDeckKey *own = mica_type_key(type, relative);
    if (!own) continue;
    differ |= (own->def == NULL) != (key->def == NULL) || (own->def && key->def && strcmp(own->def, key->def));
    used += (size_t)snprintf(list + used, used < sizeof list ? sizeof list - used : 0, "%s%s with %s",
                             used ? ", " : "", own->def ? own->def : "none", type->name);
  }
  if (!differ) return MICA_SUCCESS;
  MICA_CHECK(used < sizeof list, MICA_ERR_ARGUMENT, "schema: the defaults of %s do not fit", key->path);
  key->def = NULL;
  return format(schema, &key->help, "%s (default: %s)", key->help, list);
}

/* A choice key with a registry: the type names as its choices, the registry's default, then each type's
 * own keys. */
static int add_chooser(MicaSchema *schema, const MicaDeckKey *base, const char *path) {
  const MicaRegistry *registry = base->registry;
  MicaDeckKey key = *base;
  key.path = path;
  char choices[2048];
  MICA_CALL(mica_registry_choices(registry, choices, sizeof choices));
  /* words of the key's own before the types' ("auto" of solver.linear: a choice that picks a type) */
  MICA_CALL(format(schema, &key.choices, "%s%s%s", base->choices ? base->choices : "", base->choices ? "|" : "",
                   choices));
  MICA_CHECK(mica_registry_default(registry), MICA_ERR_ARGUMENT, "registry of %s: no default type '%s'",
             registry->family, registry->def ? registry->def : "(null)");
  if (!key.def) MICA_CALL(format(schema, &key.def, "\"%s\"", registry->def));
  MICA_CALL(append_key(schema, &key));
  for (int i = 0; i < mica_registry_count(registry); i++)
    MICA_CALL(add_type_keys(schema, path, mica_registry_type(registry, i)));
  for (long k = 0; k < schema->nkeys; k++)
    if (schema->keys[k].chooser == path) MICA_CALL(note_type_defaults(schema, &schema->keys[k], registry));
  return MICA_SUCCESS;
}

static int compose(MicaSchema *schema, const MicaDeckKey *base, const char *prefix);

/* A fragment of a registry: every type's keys under prefix, in registry order, each marked with the type that
 * declares it (`owner`, for help) but with no chooser: the deck enables the types side by side. */
static int add_family(MicaSchema *schema, const MicaRegistry *registry, const char *prefix) {
  for (int i = 0; i < mica_registry_count(registry); i++) {
    const MicaType *type = mica_registry_type(registry, i);
    if (!type->keys) continue;
    const long first = schema->nkeys;
    MICA_CALL(compose(schema, type->keys, prefix));
    for (long k = first; k < schema->nkeys; k++) {
      MICA_CHECK(find_composed(schema, schema->keys[k].path) == &schema->keys[k], MICA_ERR_ARGUMENT,
                 "schema: %s is declared twice (by the %s type '%s' too)", schema->keys[k].path, registry->family,
                 type->name);
      schema->keys[k].owner = type->name;
      schema->keys[k].family = registry;
    }
  }
  return MICA_SUCCESS;
}

static int compose(MicaSchema *schema, const MicaDeckKey *base, const char *prefix) {
  for (const MicaDeckKey *key = base; key->path; key++) {
    const char *path = key->path;
    if (prefix[0]) MICA_CALL(format(schema, &path, "%s%s%s", prefix, key->path[0] ? "." : "", key->path));
    if (key->type == MICA_KEY_FRAGMENT && key->registry) {
      MICA_CALL(add_family(schema, key->registry, path));
    } else if (key->type == MICA_KEY_FRAGMENT) {
      MICA_CHECK(key->fragment, MICA_ERR_ARGUMENT, "schema: fragment %s has no keys", path);
      MICA_CALL(compose(schema, key->fragment, path));
    } else if (key->type == MICA_KEY_CHOICE && key->registry) {
      MICA_CALL(add_chooser(schema, key, path));
    } else {
      MicaDeckKey copy = *key;
      copy.path = path;
      MICA_CALL(append_key(schema, &copy));
    }
  }
  return MICA_SUCCESS;
}

int mica_schema_compose(const MicaDeckKey *base, MicaSchema **schema) {
  MICA_CHECK(base && schema, MICA_ERR_ARGUMENT, "mica_schema_compose: bad argument");
  MICA_CALL(MICA_CALLOC(*schema, 1));
  int ierr = MICA_SUCCESS;
  MicaDeckKey end = {0};
  MICA_CALL_CLEANUP(append_key(*schema, &end)); /* so an empty base gives {NULL} */
  (*schema)->nkeys = 0;
  MICA_CALL_CLEANUP(compose(*schema, base, ""));
  return MICA_SUCCESS;
cleanup:
  mica_schema_destroy(schema);
  return ierr;
}

int mica_schema_destroy(MicaSchema **schema) {
  if (!schema || !*schema) return MICA_SUCCESS;
  for (long i = 0; i < (*schema)->nstrings; i++) free((*schema)->strings[i]);
  free((*schema)->strings);
  free((*schema)->keys);
  MICA_FREE(*schema);
  return MICA_SUCCESS;
}

const MicaDeckKey *mica_schema_keys(const MicaSchema *schema) { return schema->keys; }

const MicaDeckKey *mica_schema_find(const MicaDeckKey *keys, const char *path) {
  for (const MicaDeckKey *key = keys; key->path; key++)
    if (!strcmp(key->path, path)) return key;
  return NULL;
}

double mica_schema_default_number(const MicaDeckKey *keys, const char *path) {
  const MicaDeckKey *key = keys ? mica_schema_find(keys, path) : NULL;
  return key && key->def ? strtod(key->def, NULL) : 0.0;
}

/* ---- the reader ---- */

static void settings_path(const char *group, const char *name, char *path, size_t size) {
  snprintf(path, size, "%s%s%s", group ? group : "", group && group[0] ? "." : "", name);
}

#define SETTINGS_PATH(path)                                                                                 \
  char path[512];                                                                                           \
  settings_path(group, name, path, sizeof path)

int mica_settings_has(const MicaSettings *s, const char *group, const char *name) {
  SETTINGS_PATH(path);
  return s->ops->has(s->ctx, path);
}

int mica_settings_int(const MicaSettings *s, const char *group, const char *name, long *value) {
  SETTINGS_PATH(path);
  return s->ops->get_int(s->ctx, path, value);
}

int mica_settings_float(const MicaSettings *s, const char *group, const char *name, double *value) {
  SETTINGS_PATH(path);
  return s->ops->get_float(s->ctx, path, value);
}

int mica_settings_bool(const MicaSettings *s, const char *group, const char *name, int *value) {
  SETTINGS_PATH(path);
  return s->ops->get_bool(s->ctx, path, value);
}

int mica_settings_string(const MicaSettings *s, const char *group, const char *name, const char **value) {
  SETTINGS_PATH(path);
  return s->ops->get_string(s->ctx, path, value);
}

int mica_settings_floats(const MicaSettings *s, const char *group, const char *name, double *values, int max,
                         int *count) {
  SETTINGS_PATH(path);
  return s->ops->get_floats(s->ctx, path, values, max, count);
}

int mica_settings_where(const MicaSettings *s, const char *group, const char *name, char *buf, int size) {
  SETTINGS_PATH(path);
  return s->ops->where(s->ctx, path, buf, size);
}
