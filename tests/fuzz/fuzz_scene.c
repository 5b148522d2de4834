/* fuzz_scene: the scene loader under a fuzzer.  An input is a scene's YAML
 * text, then optionally a NUL byte and --set overrides, one KEY=VALUE per
 * line; each override's VALUE is also compiled and evaluated as an
 * expression.  The scene is loaded and checked, never simulated, and
 * everything is freed, so a leak is a finding. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pm_app.h"
#include "pm_expr.h"
#include "pm_scene.h"

/* More overrides than this add nothing a fuzzer can reach with fewer. */
#define FUZZ_OVERRIDES 16

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Compile the text after the first '=' of an override as an expression and
 * evaluate it once, to reach the expression compiler without the keys. */
static void fuzz_expression(const char *kv) {
  const char *eq = strchr(kv, '=');
  pm_expr *e = NULL;
  if (eq && pm_expr_create(eq + 1, &e) == PM_SUCCESS) {
    volatile double v = pm_expr_eval(e, 0.25, 0.5, 0.75, 1.0);
    (void)v;
  }
  pm_expr_destroy(e);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static bool registered = false;
  const char *sets[FUZZ_OVERRIDES];
  int n_sets = 0;
  char *rest = NULL;
  if (!registered) {
    if (pm_app_init() != PM_SUCCESS) abort();
    registered = true;
  }
  const uint8_t *nul = memchr(data, '\0', size);
  size_t yaml_len = nul ? (size_t)(nul - data) : size;
  if (nul) {
    /* The override lines as NUL-terminated strings (further NULs end a
     * line early, as they would on a command line). */
    size_t n = size - yaml_len - 1;
    rest = malloc(n + 1);
    if (!rest) return 0;
    memcpy(rest, nul + 1, n);
    rest[n] = '\0';
    for (char *line = rest, *next; line && n_sets < FUZZ_OVERRIDES;
         line = next) {
      next = strchr(line, '\n');
      if (next) *next++ = '\0';
      if (line[0]) sets[n_sets++] = line;
    }
  }
  for (int k = 0; k < n_sets; k++) fuzz_expression(sets[k]);
  pm_scene *s = NULL;
  if (pm_scene_load_text((const char *)data, yaml_len, "fuzz/scene.yaml",
                         n_sets, sets, &s) == PM_SUCCESS) {
    /* What callers read from a loaded scene. */
    volatile double end = pm_scene_load_end(s);
    (void)end;
    (void)pm_scene_section(s, "fpm");
    (void)pm_scene_has(s, "time.dt");
  }
  pm_scene_destroy(s);
  pm_error_clear();
  free(rest);
  return 0;
}
