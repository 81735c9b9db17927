/* JSON writer (json.h): an ordered tree built in memory, serialized pretty-printed (one member per line,
 * two-space indent) and written atomically. Only finite numbers are accepted, so no output ever holds
 * NaN or Infinity, which JSON cannot represent. */
#include "mica/json.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/files.h"

typedef enum { JSON_NUMBER, JSON_INT, JSON_BOOL, JSON_STRING, JSON_OBJECT, JSON_ARRAY } JsonKind;

typedef struct JsonNode {
  JsonKind kind;
  char *key; /* member name in an object, NULL for an array element */
  union {
    double number;
    long integer;
    int boolean;
    char *string;
  } value;
  struct JsonNode **items; /* members of an object or elements of an array, in insertion order */
  int nitems, capacity;
  int *slots; /* an object of many members: open-addressing hash of their keys (item index, -1 empty), so that
               * adding n members costs n, not n² (a summary holds one per probe) */
  int nslots; /* 0 or a power of two, more than twice nitems */
  struct JsonNode *parent;
} JsonNode;

struct MicaJson {
  JsonNode *root;
  JsonNode *open; /* innermost container still open: new values go here */
};

/* Growable text for serialization. */
typedef struct {
  char *data;
  size_t length, capacity;
} Buffer;

static void node_destroy(JsonNode *node) {
  if (!node) return;
  for (int i = 0; i < node->nitems; i++) node_destroy(node->items[i]);
  free(node->items);
  free(node->slots);
  if (node->kind == JSON_STRING) free(node->value.string);
  free(node->key);
  free(node);
}

static int copy_string(const char *text, char **copy) {
  MICA_CALL(MICA_MALLOC(*copy, strlen(text) + 1));
  memcpy(*copy, text, strlen(text) + 1);
  return MICA_SUCCESS;
}

static int node_create(JsonKind kind, const char *key, JsonNode **node) {
  MICA_CALL(MICA_CALLOC(*node, 1));
  (*node)->kind = kind;
  if (key && copy_string(key, &(*node)->key) != MICA_SUCCESS) {
    MICA_FREE(*node);
    return mica_error_trace(__FILE__, __LINE__, __func__, MICA_ERR_MEMORY);
  }
  return MICA_SUCCESS;
}

int mica_json_create(MicaJson **json) {
  MICA_CHECK(json, MICA_ERR_ARGUMENT, "mica_json_create: json is NULL");
  MICA_CALL(MICA_CALLOC(*json, 1));
  int ierr = node_create(JSON_OBJECT, NULL, &(*json)->root);
  if (ierr) {
    MICA_FREE(*json);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  (*json)->open = (*json)->root;
  return MICA_SUCCESS;
}

int mica_json_destroy(MicaJson **json) {
  if (!json || !*json) return MICA_SUCCESS;
  node_destroy((*json)->root);
  MICA_FREE(*json);
  return MICA_SUCCESS;
}

/* An object member needs a key and an array element must not have one: a caller's bug otherwise. */
static int check_key(const MicaJson *json, const char *key) {
  MICA_CHECK(json, MICA_ERR_ARGUMENT, "json is NULL");
  if (json->open->kind == JSON_OBJECT)
    MICA_CHECK(key, MICA_ERR_ARGUMENT, "a member of a JSON object needs a key");
  else
    MICA_CHECK(!key, MICA_ERR_ARGUMENT, "an element of a JSON array takes no key (got '%s')", key);
  return MICA_SUCCESS;
}

enum { HASHED_FROM = 16 }; /* members; a short object is searched in order */

static unsigned hash_key(const char *key) {
  unsigned h = 2166136261u; /* FNV-1a */
  for (const unsigned char *c = (const unsigned char *)key; *c; c++) h = (h ^ *c) * 16777619u;
  return h;
}

/* The slot of key: the one holding its member, or the empty one where it would go. */
static int slot_of(const JsonNode *object, const char *key) {
  const unsigned mask = (unsigned)object->nslots - 1;
  unsigned slot = hash_key(key) & mask;
  while (object->slots[slot] >= 0 && strcmp(object->items[object->slots[slot]]->key, key) != 0)
    slot = (slot + 1) & mask;
  return (int)slot;
}

static int find_member(const JsonNode *object, const char *key) {
  if (object->nslots) return object->slots[slot_of(object, key)];
  for (int i = 0; i < object->nitems; i++)
    if (strcmp(object->items[i]->key, key) == 0) return i;
  return -1;
}

/* Makes the hash fit nitems + 1 members: rebuilt at twice the size when half full. */
static int grow_slots(JsonNode *object) {
  if (object->nitems + 1 < HASHED_FROM || 2 * (object->nitems + 1) < object->nslots) return MICA_SUCCESS;
  int nslots = object->nslots ? 2 * object->nslots : 4 * HASHED_FROM;
  int *slots;
  MICA_CALL(MICA_MALLOC(slots, nslots));
  free(object->slots);
  object->slots = slots, object->nslots = nslots;
  for (int i = 0; i < nslots; i++) slots[i] = -1;
  for (int i = 0; i < object->nitems; i++) slots[slot_of(object, object->items[i]->key)] = i;
  return MICA_SUCCESS;
}

/* Adds node to the open container; in an object, a member with the same key is replaced in place. */
static int attach(MicaJson *json, JsonNode *node) {
  JsonNode *open = json->open;
  node->parent = open;
  int existing = open->kind == JSON_OBJECT ? find_member(open, node->key) : -1;
  if (existing >= 0) {
    node_destroy(open->items[existing]);
    open->items[existing] = node;
    return MICA_SUCCESS;
  }
  if (open->nitems == open->capacity) {
    int grown = open->capacity ? 2 * open->capacity : 8;
    int ierr = MICA_REALLOC(open->items, grown);
    if (ierr) {
      node_destroy(node);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
    open->capacity = grown;
  }
  if (open->kind == JSON_OBJECT) {
    int ierr = grow_slots(open);
    if (ierr) {
      node_destroy(node);
      return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
    }
  }
  if (open->nslots) open->slots[slot_of(open, node->key)] = open->nitems;
  open->items[open->nitems++] = node;
  return MICA_SUCCESS;
}

/* Creates a node of kind under key in the open container; *node is owned by the tree afterwards. */
static int add_node(MicaJson *json, const char *key, JsonKind kind, JsonNode **node) {
  MICA_CALL(check_key(json, key));
  MICA_CALL(node_create(kind, key, node));
  MICA_CALL(attach(json, *node));
  return MICA_SUCCESS;
}

int mica_json_number(MicaJson *json, const char *key, double value) {
  MICA_CALL(check_key(json, key));
  if (!isfinite(value)) {
    const char *array_key = json->open->key ? json->open->key : "(root)";
    if (key) MICA_ERROR(MICA_ERR_NUMERIC, "'%s' is %g: JSON output holds finite numbers only", key, value);
    MICA_ERROR(MICA_ERR_NUMERIC, "an element of '%s' is %g: JSON output holds finite numbers only",
               array_key, value);
  }
  JsonNode *node;
  MICA_CALL(add_node(json, key, JSON_NUMBER, &node));
  node->value.number = value;
  return MICA_SUCCESS;
}

int mica_json_int(MicaJson *json, const char *key, long value) {
  JsonNode *node;
  MICA_CALL(add_node(json, key, JSON_INT, &node));
  node->value.integer = value;
  return MICA_SUCCESS;
}

int mica_json_bool(MicaJson *json, const char *key, int value) {
  JsonNode *node;
  MICA_CALL(add_node(json, key, JSON_BOOL, &node));
  node->value.boolean = value != 0;
  return MICA_SUCCESS;
}

int mica_json_string(MicaJson *json, const char *key, const char *value) {
  MICA_CHECK(value, MICA_ERR_ARGUMENT, "mica_json_string: value of '%s' is NULL", key ? key : "element");
  char *copy;
  MICA_CALL(copy_string(value, &copy));
  JsonNode *node;
  int ierr = add_node(json, key, JSON_STRING, &node);
  if (ierr) {
    free(copy);
    return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  }
  node->value.string = copy;
  return MICA_SUCCESS;
}

static int open_container(MicaJson *json, const char *key, JsonKind kind) {
  JsonNode *node;
  MICA_CALL(add_node(json, key, kind, &node));
  json->open = node;
  return MICA_SUCCESS;
}

int mica_json_open_object(MicaJson *json, const char *key) { return open_container(json, key, JSON_OBJECT); }
int mica_json_open_array(MicaJson *json, const char *key) { return open_container(json, key, JSON_ARRAY); }

int mica_json_close(MicaJson *json) {
  MICA_CHECK(json, MICA_ERR_ARGUMENT, "json is NULL");
  MICA_CHECK(json->open != json->root, MICA_ERR_ARGUMENT, "mica_json_close: nothing open but the root");
  json->open = json->open->parent;
  return MICA_SUCCESS;
}

/* Root-level lookup only: summaries are flat where their numbers are. */
int mica_json_get_number(const MicaJson *json, const char *key, double *value) {
  MICA_CHECK(json && key && value, MICA_ERR_ARGUMENT, "mica_json_get_number: NULL argument");
  const int i = find_member(json->root, key);
  MICA_CHECK(i >= 0, MICA_ERR_ARGUMENT, "the summary has no member '%s'", key);
  const JsonNode *node = json->root->items[i];
  MICA_CHECK(node->kind == JSON_NUMBER || node->kind == JSON_INT, MICA_ERR_ARGUMENT,
             "the summary's member '%s' is not a number", key);
  *value = node->kind == JSON_NUMBER ? node->value.number : (double)node->value.integer;
  return MICA_SUCCESS;
}

int mica_json_get_string(const MicaJson *json, const char *key, const char **value) {
  MICA_CHECK(json && key && value, MICA_ERR_ARGUMENT, "mica_json_get_string: NULL argument");
  const int i = find_member(json->root, key);
  MICA_CHECK(i >= 0, MICA_ERR_ARGUMENT, "the summary has no member '%s'", key);
  const JsonNode *node = json->root->items[i];
  MICA_CHECK(node->kind == JSON_STRING, MICA_ERR_ARGUMENT, "the summary's member '%s' is not a string", key);
  *value = node->value.string;
  return MICA_SUCCESS;
}

/* ---- serialization ---- */

static int buffer_append(Buffer *buffer, const char *text, size_t length) {
  if (buffer->length + length + 1 > buffer->capacity) {
    size_t grown = buffer->capacity ? buffer->capacity : 256;
    while (grown < buffer->length + length + 1) grown *= 2;
    MICA_CALL(MICA_REALLOC(buffer->data, grown));
    buffer->capacity = grown;
  }
  memcpy(buffer->data + buffer->length, text, length);
  buffer->length += length;
  buffer->data[buffer->length] = '\0';
  return MICA_SUCCESS;
}

static int buffer_print(Buffer *buffer, const char *fmt, ...) MICA_PRINTF(2, 3);
static int buffer_print(Buffer *buffer, const char *fmt, ...) {
  char text[64];
  va_list ap;
  va_start(ap, fmt);
  int length = vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  MICA_CHECK(length >= 0 && (size_t)length < sizeof text, MICA_ERR_ARGUMENT, "number too long for JSON");
  MICA_CALL(buffer_append(buffer, text, (size_t)length));
  return MICA_SUCCESS;
}

/* Quotes and escapes text: the two characters JSON reserves and every control character. Other bytes,
 * UTF-8 included, pass through. */
static int append_quoted(Buffer *buffer, const char *text) {
  MICA_CALL(buffer_append(buffer, "\"", 1));
  for (const unsigned char *c = (const unsigned char *)text; *c; c++) {
    const char *escape = NULL;
    switch (*c) {
    case '"': escape = "\\\""; break;
    case '\\': escape = "\\\\"; break;
    case '\n': escape = "\\n"; break;
    case '\r': escape = "\\r"; break;
    case '\t': escape = "\\t"; break;
    case '\b': escape = "\\b"; break;
    case '\f': escape = "\\f"; break;
    default: break;
    }
    if (escape)
      MICA_CALL(buffer_append(buffer, escape, strlen(escape)));
    else if (*c < 0x20)
      MICA_CALL(buffer_print(buffer, "\\u%04x", (unsigned)*c));
    else
      MICA_CALL(buffer_append(buffer, (const char *)c, 1));
  }
  MICA_CALL(buffer_append(buffer, "\"", 1));
  return MICA_SUCCESS;
}

/* The shortest of %.15g, %.16g, %.17g that reads back as the same double: exact, and 0.1 stays 0.1. */
static int append_number(Buffer *buffer, double value) {
  char text[32];
  for (int digits = 15; digits <= 17; digits++) {
    snprintf(text, sizeof text, "%.*g", digits, value);
    if (strtod(text, NULL) == value) break;
  }
  MICA_CALL(buffer_append(buffer, text, strlen(text)));
  return MICA_SUCCESS;
}

static int append_indent(Buffer *buffer, int depth) {
  for (int i = 0; i < depth; i++) MICA_CALL(buffer_append(buffer, "  ", 2));
  return MICA_SUCCESS;
}

static int append_node(Buffer *buffer, const JsonNode *node, int depth);

static int append_container(Buffer *buffer, const JsonNode *node, int depth) {
  const char *brackets = node->kind == JSON_OBJECT ? "{}" : "[]";
  MICA_CALL(buffer_append(buffer, brackets, 1));
  for (int i = 0; i < node->nitems; i++) {
    MICA_CALL(buffer_append(buffer, i ? ",\n" : "\n", i ? 2 : 1));
    MICA_CALL(append_indent(buffer, depth + 1));
    if (node->kind == JSON_OBJECT) {
      MICA_CALL(append_quoted(buffer, node->items[i]->key));
      MICA_CALL(buffer_append(buffer, ": ", 2));
    }
    MICA_CALL(append_node(buffer, node->items[i], depth + 1));
  }
  if (node->nitems) {
    MICA_CALL(buffer_append(buffer, "\n", 1));
    MICA_CALL(append_indent(buffer, depth));
  }
  MICA_CALL(buffer_append(buffer, brackets + 1, 1));
  return MICA_SUCCESS;
}

static int append_node(Buffer *buffer, const JsonNode *node, int depth) {
  switch (node->kind) {
  case JSON_NUMBER: MICA_CALL(append_number(buffer, node->value.number)); break;
  case JSON_INT: MICA_CALL(buffer_print(buffer, "%ld", node->value.integer)); break;
  case JSON_BOOL:
    MICA_CALL(buffer_append(buffer, node->value.boolean ? "true" : "false", node->value.boolean ? 4 : 5));
    break;
  case JSON_STRING: MICA_CALL(append_quoted(buffer, node->value.string)); break;
  case JSON_OBJECT:
  case JSON_ARRAY: MICA_CALL(append_container(buffer, node, depth)); break;
  }
  return MICA_SUCCESS;
}

int mica_json_text(const MicaJson *json, char **text) {
  MICA_CHECK(json && text, MICA_ERR_ARGUMENT, "mica_json_text: NULL argument");
  MICA_CHECK(json->open == json->root, MICA_ERR_ARGUMENT, "JSON object or array '%s' is still open",
             json->open->key ? json->open->key : "(element)");
  Buffer buffer = {NULL, 0, 0};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(append_node(&buffer, json->root, 0));
  MICA_CALL_CLEANUP(buffer_append(&buffer, "\n", 1));
  *text = buffer.data;
  return MICA_SUCCESS;
cleanup:
  free(buffer.data);
  return ierr;
}

int mica_json_write(const MicaJson *json, const char *path) {
  char *text = NULL;
  MicaOutFile out = {NULL, NULL, NULL};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(mica_json_text(json, &text));
  MICA_CALL_CLEANUP(mica_out_open(path, &out));
  fputs(text, out.fp);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  free(text);
  return ierr;
}
