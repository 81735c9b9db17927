/* A small JSON writer for summary.json: an ordered tree of objects and arrays built in memory and
 * written atomically. Non-finite numbers are refused (MICA_ERR_NUMERIC naming the key): no NaN in output. */
#ifndef MICA_JSON_H
#define MICA_JSON_H

#include "mica/error.h"

typedef struct MicaJson MicaJson;

int mica_json_create(MicaJson **json); /* an empty root object, open */
int mica_json_destroy(MicaJson **json);
/* Members of the innermost open object (key) or array (key must be NULL). Setting an existing key of
 * the root object replaces its value. */
int mica_json_number(MicaJson *json, const char *key, double value);
int mica_json_int(MicaJson *json, const char *key, long value);
int mica_json_bool(MicaJson *json, const char *key, int value);
int mica_json_string(MicaJson *json, const char *key, const char *value);
int mica_json_open_object(MicaJson *json, const char *key);
int mica_json_open_array(MicaJson *json, const char *key);
int mica_json_close(MicaJson *json);
/* Reads back a number (or integer) member of the root object: MICA_ERR_ARGUMENT if key is absent or holds
 * something else (used by `mica sweep` to collect each run's probes). */
int mica_json_get_number(const MicaJson *json, const char *key, double *value);
/* Reads back a string member of the root object (the command line reads "status"); *value points into json. */
int mica_json_get_string(const MicaJson *json, const char *key, const char **value);
/* Serializes (all containers must be closed but the root) and writes path atomically. */
int mica_json_write(const MicaJson *json, const char *path);
/* The serialized text, for tests and printing; caller frees. */
int mica_json_text(const MicaJson *json, char **text);

#endif
