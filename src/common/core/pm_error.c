/* pm_error: per-thread record of the last failure and its trace. */
#include "pm_error.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PM_MSG_LEN 2048
#define PM_TRACE_LEN 4096

static _Thread_local pm_err last_code = PM_SUCCESS;
static _Thread_local char last_msg[PM_MSG_LEN];
static _Thread_local char last_trace[PM_TRACE_LEN];

static const char *const err_strings[] = {
#define PM_X_STR(code, msg) msg,
    PM_ERROR_LIST(PM_X_STR)
#undef PM_X_STR
};
static const char *const err_names[] = {
#define PM_X_NAME(code, msg) #code,
    PM_ERROR_LIST(PM_X_NAME)
#undef PM_X_NAME
};

const char *pm_err_string(pm_err code) {
  if ((int)code < 0 || code >= PM_ERR_COUNT) return "unknown error";
  return err_strings[code];
}

const char *pm_err_name(pm_err code) {
  if ((int)code < 0 || code >= PM_ERR_COUNT) return "PM_ERR_UNKNOWN";
  return err_names[code];
}

pm_err pm_error_set(pm_err code, const char *file, int line, const char *func,
                    const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(last_msg, sizeof last_msg, fmt, ap);
  va_end(ap);
  last_code = code;
  snprintf(last_trace, sizeof last_trace, "  %s (%s:%d)\n", func, file, line);
  return code;
}

pm_err pm_error_trace(pm_err code, const char *file, int line, const char *func,
                      const char *what) {
  size_t used = strlen(last_trace);
  if (last_code == PM_SUCCESS) {
    /* A failure that recorded no message (should not happen): name it. */
    last_code = code;
    snprintf(last_msg, sizeof last_msg, "%s", pm_err_string(code));
  }
  if (used + 1 < sizeof last_trace)
    snprintf(last_trace + used, sizeof last_trace - used, "  %s (%s:%d): %s\n",
             func, file, line, what);
  return code;
}

const char *pm_error_message(void) { return last_msg; }
const char *pm_error_traceback(void) { return last_trace; }
pm_err pm_error_code(void) { return last_code; }

void pm_error_clear(void) {
  last_code = PM_SUCCESS;
  last_msg[0] = '\0';
  last_trace[0] = '\0';
}

pm_err pm_calloc(void **ptr, size_t count, size_t size, const char *what) {
  *ptr = NULL;
  if (count == 0) return PM_SUCCESS;
  if (size != 0 && count > (size_t)-1 / size)
    return PM_ERROR(PM_ERR_MEMORY, "%s: %zu x %zu bytes overflows", what, count,
                    size);
  *ptr = calloc(count, size);
  if (!*ptr)
    return PM_ERROR(PM_ERR_MEMORY, "cannot allocate %zu bytes for %s",
                    count * size, what);
  return PM_SUCCESS;
}

pm_err pm_realloc(void **ptr, size_t count, size_t size, const char *what) {
  if (count == 0) count = 1;
  if (size != 0 && count > (size_t)-1 / size)
    return PM_ERROR(PM_ERR_MEMORY, "%s: %zu x %zu bytes overflows", what, count,
                    size);
  void *q = realloc(*ptr, count * size);
  if (!q)
    return PM_ERROR(PM_ERR_MEMORY, "cannot allocate %zu bytes for %s",
                    count * size, what);
  *ptr = q;
  return PM_SUCCESS;
}
