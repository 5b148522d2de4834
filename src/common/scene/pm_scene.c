/* pm_scene: loading a scene: the text, the --set overrides, one pass of the
 * key reader over the shared vocabulary and every registered backend's
 * section, the checks across keys, and the scene's backend's own check. */
#include "pm_scene.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_backend.h"
#include "pm_files.h"
#include "pm_par.h"
#include "pm_scene_vocab.h"

/* Keep the overrides in the scene, and as comment lines at the end of its
 * text, so that the text stored with the results reproduces the run. */
static pm_err keep_overrides(pm_scene *s, int n, const char *const *kv) {
  if (n == 0) return PM_SUCCESS;
  PM_CALL(PM_ALLOC(s->overrides, n, "scene overrides"));
  s->n_overrides = n;
  size_t extra = 64;
  for (int k = 0; k < n; k++) {
    s->overrides[k] = strdup(kv[k]);
    PM_CHECK(s->overrides[k], PM_ERR_MEMORY, "cannot copy override %s", kv[k]);
    extra += strlen(kv[k]) + 16;
  }
  size_t len = strlen(s->text);
  char *text = realloc(s->text, len + extra);
  PM_CHECK(text, PM_ERR_MEMORY, "cannot extend the scene text");
  s->text = text;
  size_t at = len;
  if (at > 0 && text[at - 1] != '\n') text[at++] = '\n';
  at += (size_t)snprintf(text + at, len + extra - at,
                         "# command-line overrides:\n");
  for (int k = 0; k < n; k++)
    at +=
        (size_t)snprintf(text + at, len + extra - at, "#   --set %s\n", kv[k]);
  return PM_SUCCESS;
}

/* The sections of the registered backends, as one-key tables. */
typedef struct {
  int n;
  pm_key keys[PM_BACKENDS_MAX][2];
  const pm_section *section[PM_BACKENDS_MAX];
} section_tables;

static void gather_sections(section_tables *t) {
  memset(t, 0, sizeof *t);
  for (int k = 0; k < pm_backend_count() && t->n < PM_BACKENDS_MAX; k++) {
    const pm_section *sec = pm_backend_at(k)->section;
    if (!sec) continue;
    t->section[t->n] = sec;
    t->keys[t->n][0] = (pm_key){.name = sec->name,
                                .type = PM_KEY_MAPPING,
                                .keys = sec->keys,
                                .doc = "options of that method"};
    t->n++;
  }
}

static pm_err resolve_method(pm_reader *r, pm_scene *s) {
  char names[256], what[300];
  s->backend = pm_backend_find(s->method);
  if (s->backend) return PM_SUCCESS;
  pm_backend_names(names, sizeof names);
  PM_CHECK(pm_backend_count() > 0, PM_ERR_INTERNAL,
           "%s: no method is registered (pm_backend_register)", s->path);
  snprintf(what, sizeof what, "one of %s", names);
  return pm_reader_expected(r, "method", what);
}

/* Read the document into s. */
static pm_err read_scene(pm_scene *s) {
  section_tables st;
  const pm_key *tables[1 + PM_BACKENDS_MAX];
  void *bases[1 + PM_BACKENDS_MAX];
  pm_reader r = {.doc = &s->doc, .dimension = 3};
  gather_sections(&st);
  tables[0] = pm_scene_keys;
  bases[0] = s;
  for (int k = 0; k < st.n; k++) {
    PM_CALL(pm_calloc(&s->section_opts[k], 1, st.section[k]->size,
                      st.section[k]->name));
    tables[1 + k] = st.keys[k];
    bases[1 + k] = s->section_opts[k];
  }
  PM_CALL(pm_reader_mapping(&r, pm_sdoc_root(&s->doc), "", 1 + st.n, tables,
                            bases, NULL));
  PM_CALL(pm_scene_finish(&r, s));
  PM_CALL(resolve_method(&r, s));
  if (isnan(s->time.dt_safety)) s->time.dt_safety = s->backend->dt_safety;
  for (int k = 0; k < st.n; k++)
    if (st.section[k]->check)
      PM_CALL(st.section[k]->check(s, s->section_opts[k]));
  if (pm_par_active() && !s->backend->ranks)
    return pm_scene_fail(s, "method", false,
                         "method %s runs on one process (this run has %d "
                         "ranks): run it without mpirun, or with -np 1",
                         s->method, pm_par_size());
  if (s->output.ranks == PM_OUTPUT_AUTO) /* pieces where they apply */
    s->output.ranks = s->backend->pieces && (!s->backend->pieces_apply ||
                                             s->backend->pieces_apply(s))
                          ? PM_OUTPUT_PIECES
                          : PM_OUTPUT_GATHER;
  if (pm_par_active() && s->output.ranks == PM_OUTPUT_PIECES &&
      !s->backend->pieces)
    return pm_scene_fail(s, "output.ranks", false,
                         "method %s writes each frame gathered into rank 0 "
                         "(this run has %d ranks): take gather",
                         s->method, pm_par_size());
  if (s->backend->check) PM_CALL(s->backend->check(s));
  return PM_SUCCESS;
}

/* The steps after the text is in s: parse, override, read, check. */
static pm_err load_scene(pm_scene *s, size_t len, int n_overrides,
                         const char *const *overrides) {
  PM_CALL(pm_sdoc_parse(&s->doc, s->path, s->text, len));
  PM_CALL(pm_sdoc_apply_overrides(&s->doc, n_overrides, overrides));
  PM_CALL(read_scene(s));
  PM_CALL(keep_overrides(s, n_overrides, overrides));
  /* Messages after loading name overrides from the scene's own copy. */
  s->doc.overrides = (const char *const *)s->overrides;
  return PM_SUCCESS;
}

/* A new scene named path (for messages and relative paths), its text from
 * the file path (text NULL) or a copy of text[0..len). */
static pm_err load(const char *path, const char *text, size_t len,
                   int n_overrides, const char *const *overrides,
                   pm_scene **out) {
  pm_err ret = PM_SUCCESS;
  pm_scene *s = NULL;
  PM_ENSURE(out, PM_ERR_ARG, "pm_scene_load: out is NULL");
  *out = NULL;
  PM_ENSURE(path, PM_ERR_ARG, "pm_scene_load: no scene path");
  PM_ENSURE(n_overrides == 0 || overrides, PM_ERR_ARG,
            "pm_scene_load: %d overrides but no array", n_overrides);
  PM_TRY(PM_ALLOC(s, 1, "scene"));
  s->path = strdup(path);
  PM_ENSURE(s->path, PM_ERR_MEMORY, "cannot copy scene path");
  if (text) {
    PM_TRY(PM_ALLOC(s->text, len + 1, "scene text"));
    memcpy(s->text, text, len);
  } else {
    PM_TRY(pm_read_text(path, "scene", &s->text, &len));
  }
  PM_TRY(load_scene(s, len, n_overrides, overrides));
  *out = s;
  s = NULL;
done:
  pm_scene_destroy(s);
  return ret;
}

pm_err pm_scene_load(const char *path, int n_overrides,
                     const char *const *overrides, pm_scene **out) {
  return load(path, NULL, 0, n_overrides, overrides, out);
}

pm_err pm_scene_load_text(const char *text, size_t len, const char *name,
                          int n_overrides, const char *const *overrides,
                          pm_scene **out) {
  if (!text && out) *out = NULL;
  PM_CHECK(text, PM_ERR_ARG, "pm_scene_load_text: no text");
  return load(name, text, len, n_overrides, overrides, out);
}

void pm_scene_destroy(pm_scene *s) {
  if (!s) return;
  section_tables st;
  gather_sections(&st);
  for (int k = 0; k < st.n; k++) {
    if (s->section_opts[k])
      pm_reader_release(st.section[k]->keys, s->section_opts[k]);
    free(s->section_opts[k]);
  }
  for (int i = 0; i < s->n_materials; i++) free(s->materials[i].name);
  free(s->materials);
  s->materials = NULL;
  pm_reader_release(pm_scene_keys, s);
  pm_sdoc_free(&s->doc);
  for (int k = 0; k < s->n_overrides; k++) free(s->overrides[k]);
  free(s->overrides);
  free(s->text);
  free(s->path);
  free(s);
}

const void *pm_scene_section(const pm_scene *s, const char *name) {
  section_tables st;
  gather_sections(&st);
  for (int k = 0; k < st.n; k++)
    if (strcmp(st.section[k]->name, name) == 0) return s->section_opts[k];
  return NULL;
}

bool pm_scene_has(const pm_scene *s, const char *path) {
  return pm_sdoc_find(&s->doc, path, false) != 0;
}

pm_err pm_scene_fail(const pm_scene *s, const char *path, bool key,
                     const char *fmt, ...) {
  char what[PM_SDOC_WHERE];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  return pm_sdoc_fail(&s->doc, path, key, "%s", what);
}

pm_err pm_scene_expected(const pm_scene *s, const char *path,
                         const char *what) {
  return pm_sdoc_expected(&s->doc, path, what);
}

void pm_scene_print_keys(FILE *out) {
  char names[512];
  fprintf(out, "Scene keys (SI units).  A list entry is written KEY.N.\n\n");
  pm_key_print(out, pm_scene_keys, "");
  pm_key_print(out, pm_scene_material_keys, "materials.N.");
  pm_model_names(names, sizeof names);
  fprintf(out, "\nModels (materials.N.model: %s) and their keys:\n", names);
  for (int k = 0; k < pm_model_count(); k++) {
    const pm_model *m = pm_model_at(k);
    fprintf(out, "\n%s: %s\n", m->name, m->formula);
    if (m->key_sets) fprintf(out, "  takes %s\n", m->key_sets);
    if (m->fibres_max > 0)
      fprintf(out, "  bodies give %d to %d fibre directions (fibres)\n",
              m->fibres_min, m->fibres_max);
    pm_key_print(out, m->keys, "  ");
  }
  for (int k = 0; k < pm_backend_count(); k++) {
    const pm_backend *b = pm_backend_at(k);
    if (!b->section) continue;
    fprintf(out, "\nSection %s (method %s: %s):\n", b->section->name, b->method,
            b->description);
    char prefix[64];
    snprintf(prefix, sizeof prefix, "%s.", b->section->name);
    pm_key_print(out, b->section->keys, prefix);
  }
}

double pm_scene_load_end(const pm_scene *s) {
  double end = 0;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *bc = &s->bcs[b];
    if (!(bc->disp_mask | bc->traction_mask | bc->velocity_mask |
          bc->force_mask) &&
        !bc->pressure)
      continue;
    /* a table's last row, where its factor stops changing */
    if (pm_curve_end(bc->curve) > end) end = pm_curve_end(bc->curve);
    if (bc->ramp == PM_RAMP_NONE) continue;
    if (bc->ramp_time > end) end = bc->ramp_time;
  }
  if (pm_curve_end(s->body_curve) > end) end = pm_curve_end(s->body_curve);
  return end;
}

double pm_scene_shear_wave_speed(const pm_scene *s) {
  double c = 0;
  for (int i = 0; i < s->n_materials; i++) {
    const pm_material *m = &s->materials[i].mat;
    if (pm_material_is_fluid(m) || !(m->shear_modulus > 0) || !(m->density > 0))
      continue;
    const double ci = sqrt(m->shear_modulus / m->density);
    if (c == 0 || ci < c) c = ci;
  }
  return c;
}

double pm_bc_factor(const pm_scene_bc *bc, double t) {
  return pm_curve_at(bc->curve, t) * pm_ramp_factor(bc->ramp, bc->ramp_time, t);
}

double pm_ramp_factor(pm_ramp kind, double T, double t) {
  if (kind == PM_RAMP_NONE) return 1.0;
  if (t <= 0) return 0.0;
  if (!(T > 0) || t >= T) return 1.0;
  double x = t / T;
  if (kind == PM_RAMP_LINEAR) return x;
  return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}
