/* mica error codes, their propagation macro, and typed allocation.
 *
 * Every function that can fail returns an int error code (MICA_SUCCESS = 0). The first failure records a
 * message with mica_error_set(); each caller on the way up wraps the call in MICA_CALL(), which returns the
 * code unchanged (PETSc's PetscCall, libCEED's CeedCall). The command line maps the code to an exit status.
 * This header depends on libc only, so the standalone MLS library can use it.
 */
#ifndef MICA_ERROR_H
#define MICA_ERROR_H

#include <stddef.h>
#include <stdlib.h> /* free, for MICA_FREE */

typedef enum {
  MICA_SUCCESS = 0,
  MICA_ERR_INPUT = 2,    /* bad deck or command line: the user must change the input (exit code 2) */
  MICA_ERR_NUMERIC = 3,  /* singular moment matrix, no support, non-finite result (exit code 3) */
  MICA_ERR_MEMORY = 4,   /* allocation failed */
  MICA_ERR_ARGUMENT = 5, /* a caller broke an API contract: a bug, not a user error */
  MICA_ERR_LIBRARY = 6,  /* an external library (LAPACK, libconfig, gnuplot, ...) failed */
  MICA_ERR_IO = 7        /* a file could not be read or written */
} MicaErrorCode;

#if defined(__GNUC__)
#define MICA_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define MICA_PRINTF(a, b)
#endif

/* Records the message of a new error and returns code. */
int mica_error_set(const char *file, int line, const char *func, int code, const char *fmt, ...)
    MICA_PRINTF(5, 6);
/* Records one frame of the call stack (printed with MICA_TRACE=1) and returns code. */
int mica_error_trace(const char *file, int line, const char *func, int code);
/* Puts context in front of the current message: "sample 12 of the line: <message>". */
void mica_error_prefix(const char *fmt, ...) MICA_PRINTF(1, 2);
const char *mica_error_message(void);
int mica_error_code(void);
void mica_error_clear(void);
/* Changes whenever an error is set or cleared: tells one error from the next (src/parallel agrees on each
 * error once). */
unsigned long mica_error_generation(void);
/* Prints the message (and, with MICA_TRACE=1 in the environment, the stack) to stderr. */
void mica_error_report(const char *program);
/* Exit status for an error code: 0, 2 (input), 3 (numerical), 1 (anything else). */
int mica_exit_status(int code);

/* Propagate: evaluate expr, return its error code from the calling function if it failed. */
#define MICA_CALL(expr)                                                        \
  do {                                                                         \
    int mica_ierr_ = (expr);                                                   \
    if (mica_ierr_ != MICA_SUCCESS)                                            \
      return mica_error_trace(__FILE__, __LINE__, __func__, mica_ierr_);       \
  } while (0)

/* Propagate inside a function that owns resources: needs `int ierr` and a `cleanup:` label. */
#define MICA_CALL_CLEANUP(expr)                                                \
  do {                                                                         \
    ierr = (expr);                                                             \
    if (ierr != MICA_SUCCESS) {                                                \
      mica_error_trace(__FILE__, __LINE__, __func__, ierr);                    \
      goto cleanup;                                                            \
    }                                                                          \
  } while (0)

/* Raise a new error from the current function. */
#define MICA_ERROR(code, ...) return mica_error_set(__FILE__, __LINE__, __func__, (code), __VA_ARGS__)
#define MICA_CHECK(cond, code, ...)                                            \
  do {                                                                         \
    if (!(cond)) MICA_ERROR((code), __VA_ARGS__);                              \
  } while (0)

/* Typed allocation: MICA_CALL(MICA_MALLOC(ptr, count)) allocates count elements of *ptr's type.
 * The count is checked for overflow; a zero count gives a valid, freeable pointer. */
int mica_alloc_(size_t count, size_t size, int zero, void **ptr, const char *file, int line,
                const char *func);
int mica_realloc_(size_t count, size_t size, void **ptr, const char *file, int line, const char *func);
#define MICA_MALLOC(ptr, count)                                                \
  mica_alloc_((size_t)(count), sizeof(*(ptr)), 0, (void **)&(ptr), __FILE__, __LINE__, __func__)
#define MICA_CALLOC(ptr, count)                                                \
  mica_alloc_((size_t)(count), sizeof(*(ptr)), 1, (void **)&(ptr), __FILE__, __LINE__, __func__)
#define MICA_REALLOC(ptr, count)                                               \
  mica_realloc_((size_t)(count), sizeof(*(ptr)), (void **)&(ptr), __FILE__, __LINE__, __func__)
#define MICA_FREE(ptr)                                                         \
  do {                                                                         \
    free(ptr);                                                                 \
    (ptr) = NULL;                                                              \
  } while (0)

#endif
