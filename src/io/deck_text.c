/* The text libconfig parses (deck_private.h): the deck file with its @include files expanded in place,
 * a map from each line of that text back to its file and line, and the integer literals libconfig 1.5
 * would silently wrap rewritten so that they keep their value.
 *
 * Why: libconfig 1.5 reads a plain integer literal into 32 bits (4294967301 becomes 5, 200000000000000000000
 * becomes -1), a hex literal likewise (0x100000000 becomes 0), and an L literal saturates at 2^63 - 1. So
 * before libconfig sees the text: a decimal integer beyond 32 bits that fits in 64 gets an L (it stays an
 * integer, and the schema's range check sees its true value); one beyond 64 bits gets a ".0" (a real number:
 * right for a float setting, refused with its line by an integer one); a hex literal beyond 32 bits gets an
 * L, and a hex or L literal beyond 64 bits is an error here, with its line. Expanding @include ourselves
 * (libconfig's rule: a line starting with @include "file", relative to the deck's directory) lets the same
 * rewriting reach included files; the line map puts their own names and lines back on the settings. */
#include <ctype.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "deck_private.h"

enum { INCLUDE_DEPTH_MAX = 10, /* libconfig's own limit */
       NESTING_MAX = 256 };   /* brackets tracked for the place of strings; deeper ones are not judged */
#define DECK_BYTES_MAX ((size_t)64 << 20) /* the longest deck file read */
#define DECK_BYTES_TEXT "64 MB"

typedef struct {
  DeckText *text;
  const char *include_dir;
  int file;        /* index in text->files of the file being expanded; -1 for a --set value */
  int line;        /* its current line */
  const char *set; /* the --set text, for messages about a value */
  /* Inside an array [ ... ] (libconfig wants its elements of one type): where each 32-bit integer ends in
   * the text, so that they get an L too when another element needs one. */
  int in_array, promote;
  size_t *ends;
  int nends, ends_capacity;
  /* Where a string may stand (libconfig 1.5 leaks a string its parser does not expect, so such a string is
   * refused here): the last token that is no comment or space ('=', ':', ',', a bracket; 's' a string, 'n' a
   * name, 'v' a number; 0 at the start), the brackets open around it, and whether a --set value held one. */
  char previous;
  char open[NESTING_MAX];
  int nopen, misplaced;
} Expander;

/* ---- the growing text and its line map ---- */

static int append(DeckText *text, const char *piece, size_t n) {
  if (text->length + n + 1 > text->capacity) {
    size_t grown = text->capacity ? text->capacity : 4096;
    while (text->length + n + 1 > grown) grown *= 2;
    MICA_CALL(MICA_REALLOC(text->text, grown));
    text->capacity = grown;
  }
  memcpy(text->text + text->length, piece, n);
  text->length += n;
  text->text[text->length] = '\0';
  return MICA_SUCCESS;
}

/* Line text->nlines + 1 of the text starts here, at line `line` of file `file`. */
static int begin_line(DeckText *text, int file, int line) {
  if (text->nlines == text->lines_capacity) {
    int grown = text->lines_capacity ? 2 * text->lines_capacity : 1024;
    MICA_CALL(MICA_REALLOC(text->lines, grown));
    text->lines_capacity = grown;
  }
  text->lines[text->nlines++] = (DeckLine){file, line};
  return MICA_SUCCESS;
}

static int newline(Expander *x) {
  MICA_CALL(append(x->text, "\n", 1));
  x->line++;
  if (x->file >= 0) MICA_CALL(begin_line(x->text, x->file, x->line));
  return MICA_SUCCESS;
}

/* Copies src[0..n) whose newlines are lines of the current file. */
static int copy_lines(Expander *x, const char *src, size_t n) {
  for (size_t start = 0, i = 0; i <= n; i++) {
    if (i < n && src[i] != '\n') continue;
    MICA_CALL(append(x->text, src + start, i - start));
    if (i < n) MICA_CALL(newline(x));
    start = i + 1;
  }
  return MICA_SUCCESS;
}

static int literal_error(const Expander *x, const char *literal, size_t n, const char *why) {
  if (x->file < 0)
    MICA_ERROR(MICA_ERR_INPUT, "--set %s: %.*s %s", x->set, (int)n, literal, why);
  MICA_ERROR(MICA_ERR_INPUT, "%s:%d: %.*s %s", x->text->files[x->file], x->line, (int)n, literal, why);
}

/* ---- numbers ---- */

/* The length of the number at s (libconfig's forms: 12, -3, 0x1F, 12L, 1.5, .5, 2e3, 1.5e-3). */
static size_t number_length(const char *s, int *hex, int *integer, int *suffix) {
  size_t i = (s[0] == '+' || s[0] == '-');
  *hex = s[i] == '0' && (s[i + 1] == 'x' || s[i + 1] == 'X');
  *integer = 1;
  if (*hex) {
    i += 2;
    while (isxdigit((unsigned char)s[i])) i++;
  } else {
    while (isdigit((unsigned char)s[i])) i++;
    if (s[i] == '.') {
      *integer = 0;
      for (i++; isdigit((unsigned char)s[i]);) i++;
    }
    /* look past the exponent letter only when there is one: s[i] may be the string's NUL */
    int exponent = s[i] == 'e' || s[i] == 'E';
    size_t e = exponent ? i + 1 + (s[i + 1] == '+' || s[i + 1] == '-') : i;
    if (exponent && isdigit((unsigned char)s[e])) {
      *integer = 0;
      for (i = e; isdigit((unsigned char)s[i]);) i++;
    }
  }
  *suffix = 0;
  while (*integer && s[i + (size_t)*suffix] == 'L' && *suffix < 2) (*suffix)++;
  return i;
}

/* A 32-bit integer just written: inside an array it may need an L later. */
static int note_small(Expander *x) {
  if (!x->in_array) return MICA_SUCCESS;
  if (x->nends == x->ends_capacity) {
    int grown = x->ends_capacity ? 2 * x->ends_capacity : 16;
    MICA_CALL(MICA_REALLOC(x->ends, grown));
    x->ends_capacity = grown;
  }
  x->ends[x->nends++] = x->text->length;
  return MICA_SUCCESS;
}

/* At the array's "]": if one element became 64-bit, every integer before it in the array does too. */
static int close_array(Expander *x) {
  DeckText *text = x->text;
  if (x->in_array && x->promote && x->nends > 0) {
    const size_t n = (size_t)x->nends;
    if (text->length + n + 1 > text->capacity) {
      MICA_CALL(MICA_REALLOC(text->text, text->length + n + 1));
      text->capacity = text->length + n + 1;
    }
    size_t to = text->length + n, from = text->length;
    for (size_t k = n; k-- > 0;) { /* from the back, each piece moves by the Ls inserted before it */
      size_t piece = from - x->ends[k];
      to -= piece, from -= piece;
      memmove(text->text + to, text->text + from, piece);
      text->text[--to] = 'L';
    }
    text->length += n;
    text->text[text->length] = '\0';
  }
  x->in_array = 0, x->promote = 0, x->nends = 0;
  return MICA_SUCCESS;
}

/* Rewrites one integer literal (without its L suffix, of length n) as described at the top. */
static int put_integer(Expander *x, const char *s, size_t n, int hex, int suffix) {
  errno = 0;
  if (hex) {
    unsigned long long value = strtoull(s, NULL, 16);
    if (errno == ERANGE) return literal_error(x, s, n, "does not fit in 64 bits");
    MICA_CALL(append(x->text, s, n));
    if (!suffix && value > INT32_MAX) MICA_CALL(append(x->text, "L", 1));
    else if (!suffix) MICA_CALL(note_small(x));
    x->promote |= suffix || value > INT32_MAX;
  } else {
    long long value = strtoll(s, NULL, 10);
    if (errno == ERANGE && suffix)
      return literal_error(x, s, n, "does not fit in a 64-bit integer (-2^63 to 2^63 - 1)");
    MICA_CALL(append(x->text, s, n));
    if (errno == ERANGE) MICA_CALL(append(x->text, ".0", 2)); /* a real number; integer settings refuse it */
    else if (!suffix && (value < INT32_MIN || value > INT32_MAX)) MICA_CALL(append(x->text, "L", 1));
    else if (!suffix) MICA_CALL(note_small(x));
    x->promote |= errno != ERANGE && (suffix || value < INT32_MIN || value > INT32_MAX);
  }
  for (int i = 0; i < suffix; i++) MICA_CALL(append(x->text, "L", 1));
  return MICA_SUCCESS;
}

static int put_number(Expander *x, const char *s, size_t *used) {
  int hex, integer, suffix;
  size_t n = number_length(s, &hex, &integer, &suffix);
  *used = n + (size_t)suffix;
  if (!integer) return append(x->text, s, n);
  return put_integer(x, s, n, hex, suffix);
}

static int starts_number(const char *s) {
  if (s[0] == '+' || s[0] == '-') s++;
  return isdigit((unsigned char)s[0]) || (s[0] == '.' && isdigit((unsigned char)s[1]));
}

/* ---- where strings may stand ---- */

/* A string is a value: after '=' or ':', an element after '[', '(' or ',' inside an array or list, or the next
 * piece of a string written in pieces ("a" "b"). Anywhere else libconfig's parser fails on it. */
static int string_allowed(const Expander *x) {
  if (x->previous == '=' || x->previous == ':' || x->previous == 's') return 1;
  if (x->nopen > NESTING_MAX) return 1; /* not tracked so deep: libconfig judges */
  const char inner = x->nopen > 0 ? x->open[x->nopen - 1] : 0;
  return strchr("[(,", x->previous) && x->previous && (inner == '[' || inner == '(');
}

/* Notes the token at s (not a comment or a space) for string_allowed. */
static void note_token(Expander *x, char kind) {
  if (kind == '{' || kind == '[' || kind == '(') {
    if (x->nopen < NESTING_MAX) x->open[x->nopen] = kind;
    x->nopen++;
  } else if ((kind == '}' || kind == ']' || kind == ')') && x->nopen > 0) {
    x->nopen--;
  }
  x->previous = kind;
}

/* A string where libconfig expects none: in the deck, an error naming its line; in a --set value, a mark that
 * the value is no libconfig value (parse_override_value in deck.c takes it as a word). */
static int check_string(Expander *x, const char *s, size_t n) {
  if (string_allowed(x)) return MICA_SUCCESS;
  if (x->file < 0) {
    x->misplaced = 1;
    return MICA_SUCCESS;
  }
  const int shown = n > 40 ? 40 : (int)n;
  MICA_ERROR(MICA_ERR_INPUT, "%s:%d: syntax error: unexpected string %.*s%s (a string is the value of a setting, "
             "name = \"text\";, or an element of an array or list)", x->text->files[x->file], x->line, shown, s,
             shown < (int)n ? "...\"" : "");
}

/* ---- the scanner ---- */

static int expand_file(Expander *x, const char *path, int depth);

/* Skips a string "..." (escapes included) or a comment; returns its length, 0 if s starts neither. */
static size_t skipped_length(const char *s) {
  if (s[0] == '"') {
    size_t i = 1;
    while (s[i] && s[i] != '"') i += (s[i] == '\\' && s[i + 1]) ? 2 : 1;
    return s[i] ? i + 1 : i;
  }
  if (s[0] == '#' || (s[0] == '/' && s[1] == '/')) return strcspn(s, "\n");
  if (s[0] == '/' && s[1] == '*') {
    const char *end = strstr(s + 2, "*/");
    return end ? (size_t)(end + 2 - s) : strlen(s);
  }
  return 0;
}

/* An @include line: the included file replaces it, on lines of its own. */
static int include_line(Expander *x, const char *s, size_t *used, int depth) {
  const char *quote = s + strlen("@include");
  quote += strspn(quote, " \t");
  const char *end = strchr(quote + 1, '"');
  size_t stop = strcspn(quote + 1, "\n");
  if (!end || (size_t)(end - quote - 1) > stop) {
    *used = 0;
    return MICA_SUCCESS; /* not an include libconfig knows; its parser will say so */
  }
  char *name = NULL;
  int ierr = MICA_SUCCESS;
  size_t length = (size_t)(end - quote - 1);
  MICA_CALL(MICA_MALLOC(name, length + 1));
  memcpy(name, quote + 1, length);
  name[length] = '\0';
  const int file = x->file, line = x->line;
  MICA_CALL_CLEANUP(append(x->text, "\n", 1));
  MICA_CALL_CLEANUP(expand_file(x, name, depth + 1));
  x->file = file, x->line = line;
  MICA_CALL_CLEANUP(append(x->text, "\n", 1));
  MICA_CALL_CLEANUP(begin_line(x->text, file, line));
  *used = (size_t)(end + 1 - s);
cleanup:
  free(name);
  return ierr;
}

static int is_include(const char *s) {
  return strncmp(s, "@include", 8) == 0 && (s[8] == ' ' || s[8] == '\t');
}

/* Copies src, rewriting its integers and expanding its @includes (depth < 0: a --set value, no includes). */
static int scan(Expander *x, const char *src, int depth) {
  int line_start = 1;
  for (const char *s = src; *s;) {
    size_t used = skipped_length(s);
    if (!used && line_start && depth >= 0 && is_include(s)) {
      MICA_CALL(include_line(x, s, &used, depth));
      s += used;
      line_start = used == 0;
      if (used) continue; /* the included file is in place */
    }
    if (used) {
      if (*s == '"') MICA_CALL(check_string(x, s, used));
      if (*s == '"') note_token(x, 's');
      MICA_CALL(copy_lines(x, s, used));
    } else if (isalpha((unsigned char)*s) || *s == '*' || *s == '_') { /* a name, digits and all */
      used = 1;
      while (s[used] && (isalnum((unsigned char)s[used]) || strchr("-_*", s[used]))) used++;
      MICA_CALL(append(x->text, s, used));
      note_token(x, 'n');
    } else if (starts_number(s)) {
      MICA_CALL(put_number(x, s, &used));
      note_token(x, 'v');
    } else {
      used = 1;
      MICA_CALL(*s == '\n' ? newline(x) : append(x->text, s, 1));
      if (*s == '[' || *s == ']') MICA_CALL(close_array(x));
      x->in_array |= *s == '[';
      if (!isspace((unsigned char)*s)) note_token(x, *s);
    }
    if (*s == '\n' || (used && memchr(s, '\n', used))) line_start = 1;
    else if (!isspace((unsigned char)*s)) line_start = 0;
    s += used;
  }
  return MICA_SUCCESS;
}

/* ---- files ---- */

/* The whole file, NUL-terminated; -1 with *why saying what is wrong. Only a regular file or a pipe (mica run
 * <(...), a FIFO) is read: a directory would read as an empty deck, a device such as /dev/zero for ever. No
 * deck is DECK_BYTES_MAX long: a longer stream is refused before it fills the memory. */
static int slurp(const char *path, char **content, const char **why) {
  struct stat st;
  FILE *stream = fopen(path, "rb");
  *why = NULL;
  if (!stream || fstat(fileno(stream), &st) != 0) *why = strerror(errno);
  else if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode))
    *why = S_ISDIR(st.st_mode) ? "it is a directory, not a deck file" : "it is a device, not a deck file";
  if (*why) {
    if (stream) fclose(stream);
    return -1;
  }
  size_t size = 0, capacity = 4096;
  int ierr = MICA_MALLOC(*content, capacity);
  while (!ierr) {
    size += fread(*content + size, 1, capacity - size - 1, stream);
    if (size > DECK_BYTES_MAX) *why = "it is longer than " DECK_BYTES_TEXT ": not a deck";
    if (*why || size + 1 < capacity) break;
    capacity *= 2;
    ierr = MICA_REALLOC(*content, capacity);
  }
  if (!ierr && !*why && ferror(stream)) *why = strerror(errno);
  fclose(stream);
  if (ierr) return mica_error_trace(__FILE__, __LINE__, __func__, ierr);
  if (*why) {
    MICA_FREE(*content);
    return -1;
  }
  (*content)[size] = '\0';
  return MICA_SUCCESS;
}

static int add_file(DeckText *text, const char *path, int *index) {
  MICA_CALL(MICA_REALLOC(text->files, text->nfiles + 1));
  size_t length = strlen(path);
  MICA_CALL(MICA_MALLOC(text->files[text->nfiles], length + 1));
  memcpy(text->files[text->nfiles], path, length + 1);
  *index = text->nfiles++;
  return MICA_SUCCESS;
}

/* An included name, relative to the include directory as libconfig reads it. */
static int include_path(const Expander *x, const char *name, char **path) {
  size_t size = strlen(name) + (x->include_dir ? strlen(x->include_dir) : 0) + 2;
  MICA_CALL(MICA_MALLOC(*path, size));
  if (x->include_dir && name[0] != '/' && strcmp(x->include_dir, ".") != 0) snprintf(*path, size, "%s/%s", x->include_dir, name);
  else snprintf(*path, size, "%s", name);
  return MICA_SUCCESS;
}

static int expand_file(Expander *x, const char *name, int depth) {
  const int parent = x->file, parent_line = x->line;
  if (depth > INCLUDE_DEPTH_MAX)
    MICA_ERROR(MICA_ERR_INPUT, "%s:%d: @include \"%s\": includes nested more than %d deep (does a file include "
               "itself?)", x->text->files[parent], parent_line, name, INCLUDE_DEPTH_MAX);
  char *path = NULL, *content = NULL;
  const char *why = NULL;
  int ierr = MICA_SUCCESS, file;
  if (depth == 0) MICA_CALL_CLEANUP(add_file(x->text, name, &file));
  else MICA_CALL_CLEANUP(include_path(x, name, &path));
  if (depth > 0) MICA_CALL_CLEANUP(add_file(x->text, path, &file));
  ierr = slurp(x->text->files[file], &content, &why);
  if (ierr < 0) {
    ierr = depth == 0 ? mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "cannot read deck '%s': %s",
                                       name, why)
                      : mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                                       "%s:%d: cannot read included file '%s': %s", x->text->files[parent],
                                       parent_line, x->text->files[file], why);
    goto cleanup;
  }
  if (ierr) goto cleanup;
  x->file = file, x->line = 1;
  MICA_CALL_CLEANUP(begin_line(x->text, file, 1));
  MICA_CALL_CLEANUP(scan(x, content, depth));
cleanup:
  free(path);
  free(content);
  return ierr;
}

int deck_text_read(const char *path, const char *include_dir, DeckText *text) {
  *text = (DeckText){0};
  Expander x = {.text = text, .include_dir = include_dir, .file = -1};
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(append(text, "", 0));
  MICA_CALL_CLEANUP(expand_file(&x, path, 0));
  free(x.ends);
  return MICA_SUCCESS;
cleanup:
  free(x.ends);
  deck_text_free(text);
  return ierr;
}

int deck_text_value(const char *set, const char *value, char **rewritten) {
  DeckText text = {0};
  Expander x = {.text = &text, .file = -1, .set = set};
  x.previous = '='; /* deck_parse_value reads the value as "v = VALUE;" */
  *rewritten = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(append(&text, "", 0));
  MICA_CALL_CLEANUP(scan(&x, value, -1));
  if (!x.misplaced) {
    *rewritten = text.text;
    text.text = NULL;
  }
cleanup:
  free(x.ends);
  deck_text_free(&text);
  return ierr;
}

DeckLine deck_text_line(const DeckText *text, int line) {
  if (line < 1 || line > text->nlines) return (DeckLine){0, 0};
  return text->lines[line - 1];
}

void deck_text_free(DeckText *text) {
  free(text->text);
  free(text->lines);
  for (int i = 0; i < text->nfiles; i++) free(text->files[i]);
  free(text->files);
  *text = (DeckText){0};
}
