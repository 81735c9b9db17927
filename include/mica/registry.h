/* Registries of types: the one idiom of every extension point (bases, weights, supports, models, boundary
 * methods, integration modes, linear solvers, approximations, commands), after PETSc's XxxRegister /
 * XxxSetFromOptions (docs/architecture.md §registries).
 *
 * A type's ops table starts with a MicaType: its name (the word the deck uses), a one-line description, its
 * capability flags and its own settings. A registry lists the types of one family and names the default
 * once. Code asks a type's flags (mica_type_has), never compares ops pointers; a deck key that chooses a
 * type names the registry (MicaDeckKey.registry), so its choices, its default and the types' settings come
 * from here. Adding a type is its file and one line in its family's registry.
 * This header uses libc only. */
#ifndef MICA_REGISTRY_H
#define MICA_REGISTRY_H

#include "mica/schema.h"

typedef struct MicaType {
  const char *name;         /* "exponential" */
  const char *description;  /* one line for `mica help` and docs/input.md */
  unsigned flags;           /* the family's capability flags (each family's header names its bits) */
  const MicaDeckKey *keys;  /* the type's own settings, paths relative to the chooser's group; NULL: none */
  /* Reads and checks those settings (group: the chooser's group, "mls") into the family's options struct
   * (MlsOptions for weights); NULL for a type without settings. */
  int (*from_settings)(const struct MicaType *type, const MicaSettings *settings, const char *group, void *options);
} MicaType;

typedef struct MicaRegistry {
  const char *family;            /* "weight function": for messages and help */
  const char *def;               /* the default type's name: the one place the default lives */
  const MicaType *const *builtin; /* NULL-terminated; each the first member of its ops table */
  /* types added at run time by mica_registry_add (an extension's file), after the built-in ones */
  const MicaType **added;
  int nadded;
  /* NULL, or a registry whose types come first, before this one's: a family that extends another (the
   * deck's continuum models are the classical models, which a field-model adapter lifts, then the field
   * models). Lookup, counting and choices see both; mica_registry_add adds to this registry only. */
  const struct MicaRegistry *base;
} MicaRegistry;

/* Adds a type (an extension: one file that defines the ops table and calls this, e.g. from a constructor).
 * A name already taken is MICA_ERR_ARGUMENT. The registry keeps the pointer: the type must outlive it. */
int mica_registry_add(MicaRegistry *registry, const MicaType *type);
/* Number of types, and the i-th (the base registry's first, then the built-in ones in their order, then the
 * added ones). */
int mica_registry_count(const MicaRegistry *registry);
const MicaType *mica_registry_type(const MicaRegistry *registry, int i);
/* The type of that name, or NULL. */
const MicaType *mica_registry_find(const MicaRegistry *registry, const char *name);
/* The default type (never NULL for a well-formed registry). */
const MicaType *mica_registry_default(const MicaRegistry *registry);
/* "a|b|c": the type names in registry order, into buf; MICA_ERR_ARGUMENT if it does not fit. */
int mica_registry_choices(const MicaRegistry *registry, char *buf, size_t size);
/* The type of that name, or MICA_ERR_ARGUMENT naming the family: for names a checked deck gave. */
int mica_registry_get(const MicaRegistry *registry, const char *name, const MicaType **type);

/* The type's own key of that path (relative to its chooser's group, "alpha"), or NULL. */
const MicaDeckKey *mica_type_key(const MicaType *type, const char *path);
/* A number setting of the type, for its from_settings: the deck's value if given, else the default the type
 * declares in its keys (several types may declare one key with different defaults: bc.alpha). */
int mica_type_float(const MicaType *type, const MicaSettings *settings, const char *group, const char *name,
                    double *value);

static inline int mica_type_has(const MicaType *type, unsigned flag) { return (type->flags & flag) == flag; }

#endif
