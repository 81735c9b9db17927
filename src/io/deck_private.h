/* Internals shared by the deck files: deck.c (loading, overrides, defaults, variants, output),
 * deck_check.c (schema checks), deck_get.c (getters and locations), deck_tree.c (libconfig helpers),
 * deck_text.c (the text libconfig parses: includes expanded, integer literals kept whole). */
#ifndef MICA_DECK_PRIVATE_H
#define MICA_DECK_PRIVATE_H

#include <libconfig.h>
#include <stddef.h>

#include "mica/deck.h"

enum { DECK_PATH_MAX = 512, DECK_MESSAGE_MAX = 1024 };

/* One --set as given, and the setting path it replaced. */
typedef struct {
  char *path; /* "mls.order" */
  char *text; /* "mls.order=3" */
} DeckOverride;

/* The evaluated parameters, in definition order. */
typedef struct {
  int count;
  const char **names; /* borrowed from the config's setting names */
  double *values;
} DeckParams;

/* ---- deck_text.c: the text libconfig parses ---- */

/* Where a line of the expanded text came from: files[file], line `line`. */
typedef struct {
  int file, line;
} DeckLine;

typedef struct {
  char *text; /* the deck with its @includes in place and its integers rewritten */
  size_t length, capacity;
  DeckLine *lines; /* lines[k]: origin of line k + 1 of text */
  int nlines, lines_capacity;
  char **files; /* the deck, then each included file as opened */
  int nfiles;
} DeckText;

/* Reads the deck at path, expands its @include lines (relative to include_dir) and rewrites the integer
 * literals libconfig 1.5 would wrap: past 32 bits they get an L, past 64 bits a ".0" (a real number); a hex
 * or L literal past 64 bits is an error "file:line: ...". */
int deck_text_read(const char *path, const char *include_dir, DeckText *text);
/* The same rewriting for the value of --set `set` (errors say "--set SET: ..."); *rewritten is malloc'd, or NULL
 * when the value holds a string where libconfig expects none (it is no libconfig value). In a deck such a
 * string is an error "file:line: ...": libconfig 1.5's parser would leak it. */
int deck_text_value(const char *set, const char *value, char **rewritten);
/* Origin of line `line` (1-based) of the text; {0, 0} if out of range. */
DeckLine deck_text_line(const DeckText *text, int line);
void deck_text_free(DeckText *text);

struct MicaDeck {
  config_t *config;           /* owned by the base deck; a variant borrows its base's */
  const MicaDeckKey *schema; /* the composed keys: the base deck's own, a variant's its base's */
  MicaSchema *composed;       /* base deck only: owns schema */
  char *path;                 /* the deck file as given on the command line */
  char *name;                 /* file stem, or the variant's name */
  char *include_dir;          /* the deck's directory, for @include */
  char **files;               /* base deck: the deck and its included files, named by the settings' origins */
  int nfiles;
  DeckOverride *overrides;    /* base deck only */
  int noverrides;
  DeckParams params;          /* for a variant: the base's with the element's parameters merged in */
  const MicaDeck *base;       /* variant: the deck it came from; NULL for a base deck */
  config_setting_t *element;  /* variant: its element of the overlay list */
  char *list_path;            /* variant: "study.variants" */
  int index;                  /* variant: element index */
};

/* ---- deck_tree.c: the schema and the libconfig tree ---- */

/* The key whose path is path exactly ("output.probes.[].name"; indices written as []). */
const MicaDeckKey *deck_schema_find(const MicaDeckKey *schema, const char *schema_path);
/* 1 if some key lies below path (path is a group implied by the schema). */
int deck_schema_has_children(const MicaDeckKey *schema, const char *schema_path);
/* The PARAMETERS key (the first one; NULL if the schema has none). */
const MicaDeckKey *deck_schema_parameters(const MicaDeckKey *schema);
/* path with every [N] written as [] . */
void deck_schema_path(const char *path, char *buf, size_t size);
/* 1 if a equals b or is a whole-segment prefix of it ("mls" of "mls.order", not "ml"). */
int deck_path_within(const char *a, const char *b);

/* "output.probes.[1].name" for a setting (libconfig's path syntax). */
void deck_setting_path(const config_setting_t *setting, char *buf, size_t size);
/* The setting at path below start, [N] indexing lists; NULL if absent. *fallback is set to 1 when the
 * walk stopped at a missing group member (so a variant may look in its base), 0 otherwise. */
config_setting_t *deck_walk(config_setting_t *start, const char *path, int *fallback);
/* A libconfig type name for messages: "an integer", "a string", ... */
const char *deck_type_name(const config_setting_t *setting);
int deck_is_number(const config_setting_t *setting);
double deck_number_value(const config_setting_t *setting);

/* Parses one value in libconfig syntax into scratch (initialized by the caller) as setting "v".
 * Returns 0 and sets *value, or -1 with libconfig's message in scratch. */
int deck_parse_value(config_t *scratch, const char *text, config_setting_t **value);
/* Copies src as member name of parent (name NULL in a list or array), replacing in place a member of
 * that name; keep_lines carries source lines over (else they are 0: not from the deck file). */
int deck_tree_put(config_setting_t *parent, const char *name, const config_setting_t *src, int keep_lines);
/* Member name of group, created as an empty group if absent; NULL if it exists and is no group. */
int deck_tree_group(config_setting_t *group, const char *name, config_setting_t **member);
/* Copies src's members into dst, recursing into groups both hold and replacing everything else. */
int deck_tree_merge(config_setting_t *dst, const config_setting_t *src, const char *skip_member);

/* ---- deck_get.c ---- */

/* "deck.cfg:12", "--set mls.order=3" or "deck.cfg (default)". */
void deck_where(const MicaDeck *deck, const config_setting_t *setting, char *buf, size_t size);
/* Raises MICA_ERR_INPUT "WHERE: message" about setting. */
int deck_fail(const MicaDeck *deck, const config_setting_t *setting, const char *file, int line,
              const char *func, const char *fmt, ...) MICA_PRINTF(6, 7);
/* A type's setting given while its chooser names another type: refused (deck_check.c). */
int deck_check_owners(const MicaDeck *deck);
#define DECK_FAIL(deck, setting, ...) deck_fail((deck), (setting), __FILE__, __LINE__, __func__, __VA_ARGS__)
/* Puts "WHERE: path: " in front of the current error message (an expression error, say). */
void deck_prefix_error(const MicaDeck *deck, const config_setting_t *setting);
/* Evaluates a number or string expression with the deck's parameters and checks it against key. */
int deck_eval_number(const MicaDeck *deck, const DeckParams *params, const MicaDeckKey *key,
                     const config_setting_t *setting, int integer, double *value);
/* Shortest text that reads back as value. */
void deck_format_number(double value, char *buf, size_t size);

/* ---- deck_check.c ---- */

/* Evaluates the parameters group (and, for a variant, its element's) into params. */
int deck_params_build(const MicaDeck *deck, const config_setting_t *base_group,
                      const config_setting_t *element_group, DeckParams *params);
void deck_params_free(DeckParams *params);
/* Checks every setting of the deck against the schema. */
int deck_check(const MicaDeck *deck);

#endif
