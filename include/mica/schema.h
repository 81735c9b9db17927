/* Schemas: the settings a command accepts (path, type, default, range or choices, help), and how the
 * registries of types add theirs (docs/architecture.md §registries).
 *
 * A command declares a base schema: an array of keys ending with {NULL}. Two kinds of key are expanded
 * when a deck is loaded against it (mica_schema_compose):
 *   - a CHOICE key with a `registry`: its choices are the registry's type names, its default the
 *     registry's default, and each type's own keys follow it, under the key's group, marked as owned by
 *     that type (`owner`, `chooser`): "mls.weight" chooses, the exponential weight owns "mls.alpha". The
 *     key's own `choices`, if any, come before the types' ("auto" of solver.linear), and its own `def`, if
 *     any, wins. A key that several types declare with different defaults has none (its help lists them);
 *     each type reads its own with mica_type_float;
 *   - a FRAGMENT key: the keys of `fragment` are inserted in its place, each path under the key's path
 *     (the mls.* keys, which the run and mls commands share, are declared once this way); with a `registry`
 *     instead, the keys of every one of its types, in registry order: a family whose types the deck enables
 *     side by side rather than choosing one (the outputs, output.*: mica/output.h). Each such key names its
 *     type (`owner`) and the registry (`family`) but has no chooser: each type reads its own settings.
 * So a choice list, a default and a type's settings are written once, by the type, and the help, the
 * checks and docs/input.md follow. This header uses libc only: the registries of the MLS library use it.
 */
#ifndef MICA_SCHEMA_H
#define MICA_SCHEMA_H

#include <stddef.h>

#include "mica/error.h"

typedef enum {
  MICA_KEY_INT,      /* integer (or an expression of the parameters that evaluates to an integer) */
  MICA_KEY_FLOAT,    /* number (or expression of the parameters) */
  MICA_KEY_BOOL,
  MICA_KEY_STRING,
  MICA_KEY_CHOICE,   /* one of the words in `choices`, "a|b|c" (or of a registry's types) */
  MICA_KEY_INTS,     /* array of len_min..len_max integers */
  MICA_KEY_FLOATS,   /* array of len_min..len_max numbers; a single number is accepted when len_min <= 1 */
  MICA_KEY_FUNCTION, /* string expression of x, y, z, t and the parameters */
  MICA_KEY_GROUP,    /* a group whose members are listed in the schema as "path.member" */
  MICA_KEY_LIST,     /* a list of groups; members of each element are listed as "path.[].member" */
  MICA_KEY_OVERLAY,  /* a list of groups, each holding any settings of the schema (study variants) and an
                        optional `name` */
  MICA_KEY_PARAMETERS, /* the `parameters` group: any names, each a number or an expression of earlier ones */
  MICA_KEY_FRAGMENT  /* base schemas only: the keys of `fragment` (or of every type of `registry`), each under
                        this key's path */
} MicaKeyType;

struct MicaRegistry;

typedef struct MicaDeckKey {
  const char *path;    /* "mls.order", "output.probes.[].name"; in a type's keys, relative to its chooser's group */
  MicaKeyType type;
  const char *def;     /* default in libconfig syntax ("2", "\"pascal\"", "[1.0, 1.0]"), NULL: none */
  double min, max;     /* inclusive range for numbers and array elements (min > max: unchecked) */
  const char *choices; /* MICA_KEY_CHOICE: the words; with a registry, words before its types' ("auto");
                        MICA_KEY_BOOL: words it takes besides true and false ("auto" of quadrature.vci) */
  int len_min, len_max; /* values of INTS/FLOATS/LIST; for STRING len_max is the most bytes (0: MICA_DECK_TEXT_MAX) */
  const char *help;    /* one line for `mica help <command>` and docs/input.md */
  const struct MicaRegistry *registry; /* MICA_KEY_CHOICE: choose one of its types; MICA_KEY_FRAGMENT: all */
  const struct MicaDeckKey *fragment;  /* MICA_KEY_FRAGMENT: the keys inserted here */
  /* Set by the composition on a type's keys: the type's name and the path of the key that chooses it. A
   * deck that gives the key while the chooser names another type is refused: it would have no effect. */
  const char *owner, *chooser;
  /* Set by the composition on the keys of a registry fragment: the registry; owner names the type, chooser is
   * NULL. */
  const struct MicaRegistry *family;
} MicaDeckKey;

/* A file of schema tables starts with this: its keys list the nine common fields positionally and leave the
 * registry fields zero (a chooser or a fragment names them with designated initializers). */
#define MICA_SCHEMA_TABLES _Pragma("GCC diagnostic ignored \"-Wmissing-field-initializers\"")

/* A composed schema: the base with its registries and fragments expanded. */
typedef struct MicaSchema MicaSchema;

int mica_schema_compose(const MicaDeckKey *base, MicaSchema **schema);
int mica_schema_destroy(MicaSchema **schema);
/* The composed keys, ending with {NULL}; valid while the schema lives. */
const MicaDeckKey *mica_schema_keys(const MicaSchema *schema);
/* The key with this exact path ("output.probes.[].name"), or NULL. */
const MicaDeckKey *mica_schema_find(const MicaDeckKey *keys, const char *path);
/* A numeric key's default as a number (0 if the key or its default is missing): for a library's own
 * defaults, so that they live in the schema only (mls_options_default). */
double mica_schema_default_number(const MicaDeckKey *keys, const char *path);

/* ---- Reading settings below the deck layer ------------------------------------------------------------
 * A type reads its own settings through this reader, which the deck implements (mica_deck_settings), so
 * that the MLS library and the models read settings without linking the deck layer (libconfig). Paths are
 * "group.name": the type is told its group ("mls") and names its keys as it declared them ("alpha"). */
typedef struct MicaSettingsOps {
  int (*has)(const void *ctx, const char *path);
  int (*get_int)(const void *ctx, const char *path, long *value);
  int (*get_float)(const void *ctx, const char *path, double *value);
  int (*get_bool)(const void *ctx, const char *path, int *value);
  int (*get_string)(const void *ctx, const char *path, const char **value);
  int (*get_floats)(const void *ctx, const char *path, double *values, int max, int *count);
  /* "deck.cfg:12" (or "--set path=value") for messages about a setting */
  int (*where)(const void *ctx, const char *path, char *buf, int size);
} MicaSettingsOps;

typedef struct MicaSettings {
  const MicaSettingsOps *ops;
  const void *ctx;
} MicaSettings;

int mica_settings_has(const MicaSettings *s, const char *group, const char *name);
int mica_settings_int(const MicaSettings *s, const char *group, const char *name, long *value);
int mica_settings_float(const MicaSettings *s, const char *group, const char *name, double *value);
int mica_settings_bool(const MicaSettings *s, const char *group, const char *name, int *value);
int mica_settings_string(const MicaSettings *s, const char *group, const char *name, const char **value);
int mica_settings_floats(const MicaSettings *s, const char *group, const char *name, double *values, int max,
                         int *count);
int mica_settings_where(const MicaSettings *s, const char *group, const char *name, char *buf, int size);

#endif
