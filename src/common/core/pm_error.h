/* pm_error: error codes (one X-macro list) and the macros that carry context.
 * Every function that can fail returns pm_err; the first failure records a
 * message, callers add a trace frame as the error travels up. */
#ifndef PM_ERROR_H
#define PM_ERROR_H

#include <stdarg.h>
#include <stddef.h>

/* X(code, short message).  Codes and messages cannot drift apart. */
#define PM_ERROR_LIST(X)                                                       \
  X(PM_SUCCESS, "success")                                                     \
  X(PM_ERR_MEMORY, "out of memory")                                            \
  X(PM_ERR_IO, "input/output error")                                           \
  X(PM_ERR_ARG, "invalid argument")                                            \
  X(PM_ERR_SCENE, "invalid scene")                                             \
  X(PM_ERR_EXPR, "invalid expression")                                         \
  X(PM_ERR_MESH, "meshing failed")                                             \
  X(PM_ERR_GEOMETRY, "degenerate geometry")                                    \
  X(PM_ERR_LINALG, "linear algebra failure")                                   \
  X(PM_ERR_HDF5, "HDF5 failure")                                               \
  X(PM_ERR_UNSTABLE, "numerical instability")                                  \
  X(PM_ERR_NOT_CONVERGED, "not converged")                                     \
  X(PM_ERR_UNSUPPORTED, "not supported")                                       \
  X(PM_ERR_INTERRUPTED, "interrupted by a signal")                             \
  X(PM_ERR_INTERNAL, "internal error")

typedef enum {
#define PM_X_ENUM(code, msg) code,
  PM_ERROR_LIST(PM_X_ENUM)
#undef PM_X_ENUM
      PM_ERR_COUNT
} pm_err;

/* Short fixed message for a code ("out of memory"). */
const char *pm_err_string(pm_err code);
/* Name of a code ("PM_ERR_MEMORY"). */
const char *pm_err_name(pm_err code);

/* Record a failure: formats the message (printf-style) into the calling
 * thread's error state, replacing any earlier one, and returns code. */
pm_err pm_error_set(pm_err code, const char *file, int line, const char *func,
                    const char *fmt, ...) __attribute__((format(printf, 5, 6)));
/* Append a trace frame (where an error passed through).  Returns code. */
pm_err pm_error_trace(pm_err code, const char *file, int line, const char *func,
                      const char *what);
/* The message of the last recorded failure ("" if none). */
const char *pm_error_message(void);
/* The trace frames of the last failure, one per line ("" if none). */
const char *pm_error_traceback(void);
/* Code of the last recorded failure (PM_SUCCESS if none). */
pm_err pm_error_code(void);
/* Forget the last failure. */
void pm_error_clear(void);

/* Fail with code and a formatted message: return from the function. */
#define PM_ERROR(code, ...)                                                    \
  pm_error_set((code), __FILE__, __LINE__, __func__, __VA_ARGS__)
/* User-input check, always on: return an error when cond is false. */
#define PM_CHECK(cond, code, ...)                                              \
  do {                                                                         \
    if (!(cond)) return PM_ERROR((code), __VA_ARGS__);                         \
  } while (0)
/* Propagate a failure of a call, adding a trace frame. */
#define PM_CALL(expr)                                                          \
  do {                                                                         \
    pm_err pm_call_err_ = (expr);                                              \
    if (pm_call_err_ != PM_SUCCESS)                                            \
      return pm_error_trace(pm_call_err_, __FILE__, __LINE__, __func__,        \
                            #expr);                                            \
  } while (0)

/* Variants for functions with one exit that release resources: they need a
 * local `pm_err ret` and a label `done`. */
#define PM_TRY(expr)                                                           \
  do {                                                                         \
    ret = (expr);                                                              \
    if (ret != PM_SUCCESS) {                                                   \
      pm_error_trace(ret, __FILE__, __LINE__, __func__, #expr);                \
      goto done;                                                               \
    }                                                                          \
  } while (0)
#define PM_FAIL(code, ...)                                                     \
  do {                                                                         \
    ret = PM_ERROR((code), __VA_ARGS__);                                       \
    goto done;                                                                 \
  } while (0)
#define PM_ENSURE(cond, code, ...)                                             \
  do {                                                                         \
    if (!(cond)) PM_FAIL((code), __VA_ARGS__);                                 \
  } while (0)

/* Allocation helpers: zeroed arrays; fail with PM_ERR_MEMORY naming what. */
pm_err pm_calloc(void **ptr, size_t count, size_t size, const char *what);
#define PM_ALLOC(ptr, count, what)                                             \
  pm_calloc((void **)&(ptr), (size_t)(count), sizeof(*(ptr)), (what))

/* Resize *ptr to count elements (at least one), keeping its contents (new
 * elements uninitialised); *ptr unchanged on failure (PM_ERR_MEMORY). */
pm_err pm_realloc(void **ptr, size_t count, size_t size, const char *what);
#define PM_REALLOC(ptr, count, what)                                           \
  pm_realloc((void **)&(ptr), (size_t)(count), sizeof(*(ptr)), (what))

/* Internal invariant (not user input): compiled out with NDEBUG. */
#ifdef NDEBUG
#define PM_ASSERT(cond) ((void)0)
#else
#include <assert.h>
#define PM_ASSERT(cond) assert(cond)
#endif

#endif
