/* pm_scene_readers: the readers of the scene keys a table cannot describe
 * alone (the dimension, which later keys depend on; fibre directions,
 * normalized; a body's region, an expression or the word domain) and the
 * release of a key's expression. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "pm_scene_vocab.h"

pm_err pm_scene_read_dimension(pm_reader *r, int id, const char *path,
                               const pm_key *k, void *dst) {
  (void)k;
  const char *v = pm_sdoc_scalar(r->doc, id);
  if (!v || (strcmp(v, "2") && strcmp(v, "3")))
    return pm_reader_expected(r, path, "2 or 3");
  *(int *)dst = v[0] - '0';
  r->dimension = *(int *)dst;
  return PM_SUCCESS;
}

/* fibres: [[ax, ay, az], ...]: 1 to PM_FIBRES_MAX non-zero directions,
 * normalized. */
pm_err pm_scene_read_fibres(pm_reader *r, int id, const char *path,
                            const pm_key *k, void *dst) {
  (void)k;
  typedef struct {
    double v[3];
    int n;
  } dir3;
  static const pm_key dir = {.name = "fibre",
                             .type = PM_KEY_NUMBERS,
                             .count_offset = offsetof(dir3, n),
                             .min_count = 3,
                             .max_count = 3};
  pm_material_point *pt = dst;
  char sub[PM_SDOC_PATH];
  int n = pm_sdoc_count(r->doc, id);
  if (pm_sdoc_kind_of(r->doc, id) != PM_SDOC_LIST || n < 1 || n > PM_FIBRES_MAX)
    return pm_reader_expected(r, path,
                              "a list of 1 or 2 directions [ax, ay, az]");
  pt->n_fibres = n;
  for (int f = 0; f < n; f++) {
    dir3 d;
    snprintf(sub, sizeof sub, "%s.%d", path, f);
    PM_CALL(pm_reader_value(r, pm_sdoc_item(r->doc, id, f), sub, &dir, &d));
    double len = pm_v_norm(d.v);
    if (!(len > 0)) return pm_reader_expected(r, sub, "a non-zero direction");
    for (int c = 0; c < 3; c++) pt->fibres[f][c] = d.v[c] / len;
  }
  return PM_SUCCESS;
}

/* region: an expression in x, y, z (inside where > 0), or the word
 * domain. */
pm_err pm_scene_read_region(pm_reader *r, int id, const char *path,
                            const pm_key *k, void *dst) {
  (void)k;
  pm_scene_body *b =
      (pm_scene_body *)((char *)dst - offsetof(pm_scene_body, region));
  const char *text = pm_sdoc_scalar(r->doc, id);
  if (!text || !text[0])
    return pm_reader_expected(r, path, "an expression in x, y, z, or domain");
  if (strcmp(text, "domain") == 0) {
    b->shape = PM_BODY_DOMAIN;
    return PM_SUCCESS;
  }
  b->shape = PM_BODY_REGION;
  return pm_reader_expr(r, path, text, "xyz", &b->region);
}

pm_err pm_scene_read_curve(pm_reader *r, int id, const char *path,
                           const pm_key *k, void *dst) {
  (void)k;
  const char *text = pm_sdoc_scalar(r->doc, id);
  if (!text || !text[0])
    return pm_reader_expected(r, path, "an expression of t or a .csv table");
  char dir[PM_SDOC_PATH * 4] = "";
  const char *scene = r->doc->path, *slash = scene ? strrchr(scene, '/') : NULL;
  if (slash && (size_t)(slash - scene) < sizeof dir)
    snprintf(dir, sizeof dir, "%.*s", (int)(slash - scene), scene);
  pm_curve *c = NULL;
  if (pm_curve_create(text, dir, &c) == PM_SUCCESS) {
    for (int v = 0; c->expr && v < 3; v++)
      if (pm_expr_uses(c->expr, "xyz"[v])) {
        pm_curve_destroy(c);
        return pm_reader_fail(r, path, false,
                              "expected a function of t only, got %s, which "
                              "uses %c",
                              text, "xyz"[v]);
      }
    *(pm_curve **)dst = c;
    return PM_SUCCESS;
  }
  /* the table's FILE:LINE, or the expression's complaint, at the key */
  char why[512];
  snprintf(why, sizeof why, "%s", pm_error_message());
  pm_error_clear();
  return pm_reader_fail(r, path, false,
                        "expected an expression of t or a "
                        ".csv table of rows t, factor: %s",
                        why);
}

void pm_scene_release_curve(void *dst) {
  pm_curve_destroy(*(pm_curve **)dst);
  *(pm_curve **)dst = NULL;
}

void pm_scene_release_expr(void *dst) {
  pm_expr_destroy(*(pm_expr **)dst);
  *(pm_expr **)dst = NULL;
}
