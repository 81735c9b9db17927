/* Error recording and typed allocation (libc only: part of the standalone MLS library). */
#include "mica/error.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MESSAGE_MAX = 2048, TRACE_MAX = 32 };

typedef struct {
  const char *file, *func;
  int line;
} TraceFrame;

/* One error at a time per thread: the first failure sets it, callers only append frames. */
static _Thread_local struct {
  int code;
  char message[MESSAGE_MAX];
  TraceFrame frames[TRACE_MAX];
  int nframes;
  unsigned long generation; /* counts mica_error_set and mica_error_clear calls */
} current;

static void push_frame(const char *file, int line, const char *func) {
  if (current.nframes < TRACE_MAX)
    current.frames[current.nframes++] = (TraceFrame){file, func, line};
}

int mica_error_set(const char *file, int line, const char *func, int code, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(current.message, sizeof current.message, fmt, ap);
  va_end(ap);
  current.code = code;
  current.nframes = 0;
  current.generation++;
  push_frame(file, line, func);
  return code;
}

int mica_error_trace(const char *file, int line, const char *func, int code) {
  push_frame(file, line, func);
  return code;
}

void mica_error_prefix(const char *fmt, ...) {
  char prefix[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(prefix, sizeof prefix, fmt, ap);
  va_end(ap);
  /* shift the message right and put "prefix: " in front, truncating the message's tail if needed */
  const size_t plen = strlen(prefix) + 2;
  size_t mlen = strlen(current.message);
  if (plen + mlen >= MESSAGE_MAX) mlen = MESSAGE_MAX - 1 - plen;
  memmove(current.message + plen, current.message, mlen);
  memcpy(current.message, prefix, plen - 2);
  current.message[plen - 2] = ':';
  current.message[plen - 1] = ' ';
  current.message[plen + mlen] = '\0';
}

const char *mica_error_message(void) { return current.message; }
int mica_error_code(void) { return current.code; }

unsigned long mica_error_generation(void) { return current.generation; }

void mica_error_clear(void) {
  current.generation++;
  current.code = MICA_SUCCESS;
  current.message[0] = '\0';
  current.nframes = 0;
}

void mica_error_report(const char *program) {
  fprintf(stderr, "%s: %s\n", program, current.message);
  const char *trace = getenv("MICA_TRACE");
  if (trace && trace[0] == '1')
    for (int i = 0; i < current.nframes; i++)
      fprintf(stderr, "  at %s (%s:%d)\n", current.frames[i].func, current.frames[i].file,
              current.frames[i].line);
}

int mica_exit_status(int code) {
  switch (code) {
  case MICA_SUCCESS: return 0;
  case MICA_ERR_INPUT: return 2;
  case MICA_ERR_NUMERIC: return 3;
  default: return 1;
  }
}

int mica_alloc_(size_t count, size_t size, int zero, void **ptr, const char *file, int line,
                const char *func) {
  *ptr = NULL;
  if (size && count > SIZE_MAX / size)
    return mica_error_set(file, line, func, MICA_ERR_MEMORY, "allocation of %zu x %zu bytes overflows",
                          count, size);
  size_t bytes = (count > 0 && size > 0) ? count * size : 1;
  *ptr = zero ? calloc(1, bytes) : malloc(bytes);
  if (!*ptr)
    return mica_error_set(file, line, func, MICA_ERR_MEMORY, "out of memory allocating %zu bytes",
                          bytes);
  return MICA_SUCCESS;
}

int mica_realloc_(size_t count, size_t size, void **ptr, const char *file, int line, const char *func) {
  if (size && count > SIZE_MAX / size)
    return mica_error_set(file, line, func, MICA_ERR_MEMORY, "allocation of %zu x %zu bytes overflows",
                          count, size);
  size_t bytes = (count > 0 && size > 0) ? count * size : 1;
  void *grown = realloc(*ptr, bytes);
  if (!grown)
    return mica_error_set(file, line, func, MICA_ERR_MEMORY, "out of memory growing to %zu bytes",
                          bytes);
  *ptr = grown;
  return MICA_SUCCESS;
}
