/* Registries of types (mica/registry.h): lookup by name, the default, the choice list, run-time additions. */
#include "mica/registry.h"

#include <stdlib.h>
#include <string.h>

int mica_registry_count(const MicaRegistry *registry) {
  int n = 0;
  while (registry->builtin && registry->builtin[n]) n++;
  return n + registry->nadded + (registry->base ? mica_registry_count(registry->base) : 0);
}

const MicaType *mica_registry_type(const MicaRegistry *registry, int i) {
  const int nbase = registry->base ? mica_registry_count(registry->base) : 0;
  if (i >= 0 && i < nbase) return mica_registry_type(registry->base, i);
  i -= nbase;
  int nbuiltin = 0;
  while (registry->builtin && registry->builtin[nbuiltin]) nbuiltin++;
  if (i < 0 || i >= nbuiltin + registry->nadded) return NULL;
  return i < nbuiltin ? registry->builtin[i] : registry->added[i - nbuiltin];
}

const MicaType *mica_registry_find(const MicaRegistry *registry, const char *name) {
  if (!registry || !name) return NULL;
  const int n = mica_registry_count(registry);
  for (int i = 0; i < n; i++)
    if (!strcmp(mica_registry_type(registry, i)->name, name)) return mica_registry_type(registry, i);
  return NULL;
}

const MicaType *mica_registry_default(const MicaRegistry *registry) {
  return mica_registry_find(registry, registry->def);
}

int mica_registry_add(MicaRegistry *registry, const MicaType *type) {
  MICA_CHECK(registry && type && type->name && type->name[0], MICA_ERR_ARGUMENT, "mica_registry_add: bad argument");
  MICA_CHECK(!mica_registry_find(registry, type->name), MICA_ERR_ARGUMENT,
             "a %s called '%s' is already registered", registry->family, type->name);
  MICA_CALL(MICA_REALLOC(registry->added, registry->nadded + 1));
  registry->added[registry->nadded++] = type;
  return MICA_SUCCESS;
}

int mica_registry_choices(const MicaRegistry *registry, char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  const int n = mica_registry_count(registry);
  for (int i = 0; i < n; i++) {
    const char *name = mica_registry_type(registry, i)->name;
    const size_t length = strlen(name);
    MICA_CHECK(used + length + (i > 0) < size, MICA_ERR_ARGUMENT, "the %s names do not fit in %zu bytes",
               registry->family, size);
    if (i > 0) buf[used++] = '|';
    memcpy(buf + used, name, length + 1);
    used += length;
  }
  return MICA_SUCCESS;
}

int mica_registry_get(const MicaRegistry *registry, const char *name, const MicaType **type) {
  *type = mica_registry_find(registry, name);
  MICA_CHECK(*type, MICA_ERR_ARGUMENT, "no %s is called '%s' (the deck's schema and the registry disagree)",
             registry->family, name ? name : "(null)");
  return MICA_SUCCESS;
}

const MicaDeckKey *mica_type_key(const MicaType *type, const char *path) {
  for (const MicaDeckKey *key = type->keys; key && key->path; key++)
    if (!strcmp(key->path, path)) return key;
  return NULL;
}

int mica_type_float(const MicaType *type, const MicaSettings *settings, const char *group, const char *name,
                    double *value) {
  if (mica_settings_has(settings, group, name)) return mica_settings_float(settings, group, name, value);
  const MicaDeckKey *key = mica_type_key(type, name);
  MICA_CHECK(key && key->def, MICA_ERR_ARGUMENT, "the %s type '%s' declares no default for %s", group, type->name,
             name);
  char *end;
  *value = strtod(key->def, &end);
  MICA_CHECK(end != key->def && *end == '\0', MICA_ERR_ARGUMENT, "the default of %s.%s of '%s' is not a number: %s",
             group, name, type->name, key->def);
  return MICA_SUCCESS;
}
