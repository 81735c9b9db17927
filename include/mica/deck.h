/* Decks: libconfig files checked strictly against a schema, with --set overrides, parameters and
 * expressions (docs/input.md).
 *
 * Every problem with a deck is a MICA_ERR_INPUT error whose message starts with "deck.cfg:LINE: " (or
 * "--set path=value: " for an override) and says what to do. Numeric settings may be numbers or string
 * expressions of the deck's parameters (`size = ["L", "D"]`). */
#ifndef MICA_DECK_H
#define MICA_DECK_H

#include <stdio.h>

#include "mica/error.h"
#include "mica/expr.h"
#include "mica/schema.h"

/* The longest string setting, in bytes, unless its key's len_max allows more (file paths, word lists): a
 * deck's names and titles are at most this, refused when longer before anything runs (docs/input.md). */
enum { MICA_DECK_TEXT_MAX = 200, MICA_DECK_LONG_TEXT_MAX = 1024 };

/* A schema is an array of keys ending with a {NULL} entry (mica/schema.h); its registries and fragments are
 * expanded when a deck is loaded against it. */

typedef struct MicaDeck MicaDeck;

/* Reads path, applies the overrides ("path=value", value in libconfig syntax, a bare word taken as a
 * string), fills defaults, and checks every setting against the schema: unknown keys (with "did you
 * mean"), types, ranges, array lengths, choices, expressions. */
int mica_deck_load(const char *path, const MicaDeckKey *schema, int noverrides,
                   const char *const *overrides, MicaDeck **deck);
int mica_deck_destroy(MicaDeck **deck);
/* The composed keys the deck was checked against (registries and fragments expanded). */
const MicaDeckKey *mica_deck_schema(const MicaDeck *deck);
/* A reader of the deck's settings for types below the deck layer (mica/schema.h); valid while deck lives. */
void mica_deck_settings(const MicaDeck *deck, MicaSettings *settings);
/* 1 if the deck file or a --set gave the setting, 0 if it is absent or its default. */
int mica_deck_given(const MicaDeck *deck, const char *path);

/* The deck as seen by variant i of the overlay list at list_path: the element's settings replace the
 * base deck's. The variant shares the base deck's storage and must be destroyed before it. */
int mica_deck_variant(const MicaDeck *base, const char *list_path, int i, MicaDeck **variant);
/* Number of elements of a list or overlay setting (0 if absent). */
int mica_deck_list_length(const MicaDeck *deck, const char *path);
/* The variant's name (the element's `name`, or "variant <i+1>"); the base deck's name is its file stem. */
const char *mica_deck_name(const MicaDeck *deck);
const char *mica_deck_path(const MicaDeck *deck);
/* The --set overrides the deck was loaded with, as given ("path=value"), in order (a variant's are its
 * base's): a command that loads the deck again with more overrides (mica sweep) passes these first. */
int mica_deck_override_count(const MicaDeck *deck);
const char *mica_deck_override_text(const MicaDeck *deck, int i);

/* Getters: the setting at path (defaults filled in). A missing setting without default is an error
 * naming the setting. Schema types are already checked, so a getter fails only for a caller's bug or
 * a value that needs the parameters to be checked (an expression out of range). */
int mica_deck_has(const MicaDeck *deck, const char *path);
int mica_deck_int(const MicaDeck *deck, const char *path, long *value);
int mica_deck_float(const MicaDeck *deck, const char *path, double *value);
int mica_deck_bool(const MicaDeck *deck, const char *path, int *value);
int mica_deck_string(const MicaDeck *deck, const char *path, const char **value);
/* A boolean key that also takes the words of its `choices` ("auto"): *word is the word (and *value −1), or
 * NULL and *value the boolean. */
int mica_deck_bool_or_word(const MicaDeck *deck, const char *path, int *value, const char **word);
/* Arrays: up to max values; *count is set to the number read. A scalar reads as one value. */
int mica_deck_ints(const MicaDeck *deck, const char *path, long *values, int max, int *count);
int mica_deck_floats(const MicaDeck *deck, const char *path, double *values, int max, int *count);
int mica_deck_function(const MicaDeck *deck, const char *path, MicaFunction **f);

/* "deck.cfg:12" for a setting (or "--set mls.order=3" for an override), for messages that concern
 * a value the checks could not see (a radius too small for the basis, say). */
int mica_deck_where(const MicaDeck *deck, const char *path, char *buf, int size);

/* The resolved values of every setting that lies within one of the scopes (groups such as "geometry" or
 * single paths such as "bc.method"; lists of groups are left out), as text "path=value;...", numbers as the
 * getters evaluate them (parameters applied, defaults filled). Equal texts mean equal settings: a sweep
 * compares them to know what it may reuse. The caller frees *text. */
int mica_deck_fingerprint(const MicaDeck *deck, int nscopes, const char *const *scopes, char **text);

/* Writes the resolved deck (overrides applied, defaults filled) to path, atomically. */
int mica_deck_write_resolved(const MicaDeck *deck, const char *path);

/* Prints the schema for a terminal `width` columns wide: per setting a line of path, type, default and
 * range or choices (a long list wrapped after a '|', under the range column), then its help indented by
 * four spaces and wrapped. */
int mica_deck_print_schema(const MicaDeckKey *schema, int width, FILE *stream);
/* Prints the schema as a Markdown table (docs/input.md): a row per setting, in schema order, of path, type,
 * default, range or choices and meaning (its help, then the descriptions the text help prints under it: a
 * chooser's types, a registry fragment's type), the same columns and words as mica_deck_print_schema. Only
 * the settings under group ("study": study and study.*; NULL or "": all); a group with none is bad input. */
int mica_deck_print_schema_markdown(const MicaDeckKey *schema, const char *group, FILE *stream);

#endif
