/* pm_scene_materials: the materials of a scene: the keys every material
 * has, and each entry read against those and its model's own keys (they
 * depend on the model it names), then checked by its model. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "pm_scene_vocab.h"

#define M(field) offsetof(pm_scene_material, field)
#define S(field) offsetof(pm_scene, field)

static const pm_key av_keys[] = {{.name = "c0",
                                  .type = PM_KEY_NUMBER,
                                  .offset = M(av_c0),
                                  .def = "0",
                                  .range = PM_RANGE_GE,
                                  .unit = "",
                                  .doc = "quadratic coefficient of eq. 32"},
                                 {.name = "c1",
                                  .type = PM_KEY_NUMBER,
                                  .offset = M(av_c1),
                                  .def = "0",
                                  .range = PM_RANGE_GE,
                                  .unit = "",
                                  .doc = "linear coefficient of eq. 32"},
                                 {0}};

#define D(field) M(damage) + offsetof(pm_scene_damage, field)
static const pm_key damage_keys[] = {
    {.name = "c0",
     .type = PM_KEY_NUMBER,
     .offset = D(c0),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GE,
     .unit = "",
     .doc = "c0 of eq. 39: E^d = 2 c0 E^e (exp(-c1 omega) - 1)"},
    {.name = "c1",
     .type = PM_KEY_NUMBER,
     .offset = D(c1),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GE,
     .unit = "",
     .doc = "c1 of eq. 39"},
    {.name = "elastic_limit",
     .type = PM_KEY_NUMBER,
     .offset = D(elastic_limit),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "",
     .doc = "S_L of eq. 40: largest principal strain at the elastic limit"},
    {.name = "failure_strain",
     .type = PM_KEY_NUMBER,
     .offset = D(failure),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "",
     .doc = "largest principal strain at which a point fails (its stress "
            "is zero from then on)"},
    {0}};

/* The keys every material has; the rest are its model's. */
const pm_key pm_scene_material_keys[] = {
    {.name = "name",
     .type = PM_KEY_STRING,
     .offset = M(name),
     .flags = PM_KEY_REQUIRED,
     .doc = "what bodies call it"},
    {.name = "model",
     .type = PM_KEY_CUSTOM,
     .flags = PM_KEY_REQUIRED,
     .read = NULL, /* read first, by read_material */
     .what = "a model of the table (below)",
     .doc = "an entry of the table of constitutive models"},
    {.name = "density",
     .type = PM_KEY_NUMBER,
     .offset = M(mat) + offsetof(pm_material, density),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "kg/m^3",
     .doc = "reference density"},
    {.name = "artificial_viscosity",
     .type = PM_KEY_MAPPING,
     .keys = av_keys,
     .doc = "shock viscosity of eq. 32 {c0, c1} (MPM)"},
    {.name = "damage",
     .type = PM_KEY_MAPPING,
     .keys = damage_keys,
     .doc = "membrane elastodamage of eqs. 38-41 {c0, c1, elastic_limit, "
            "failure_strain} (MPM membranes)"},
    {0}};

static pm_err skip_value(pm_reader *r, int id, const char *path,
                         const pm_key *k, void *dst) {
  (void)r, (void)id, (void)path, (void)k, (void)dst;
  return PM_SUCCESS;
}

/* One material: its model first (the keys it takes depend on it), then
 * every key against the common and the model's tables, then the model's
 * checks, located at the key they name. */
static pm_err read_material(pm_reader *r, int id, const char *path,
                            pm_scene_material *out) {
  char sub[PM_SDOC_PATH], names[512], expected[1024];
  if (pm_sdoc_kind_of(r->doc, id) != PM_SDOC_MAPPING)
    return pm_reader_expected(r, path, "a mapping");
  out->mark = pm_sdoc_mark(r->doc, id);
  snprintf(sub, sizeof sub, "%s.model", path);
  int mid = pm_sdoc_child(r->doc, id, "model");
  if (!mid) return pm_reader_fail(r, sub, false, "missing required key");
  const char *model = pm_sdoc_scalar(r->doc, mid);
  pm_model_names(names, sizeof names);
  if (!model || !pm_model_find(model)) {
    snprintf(expected, sizeof expected, "one of %s", names);
    return pm_reader_expected(r, sub, expected);
  }
  PM_CALL(pm_material_begin(&out->mat, model, NAN));
  const pm_model *md = out->mat.model;
  pm_key common[PM_MATERIAL_KEYS];
  memcpy(common, pm_scene_material_keys, sizeof common);
  common[1].read = skip_value;
  size_t used = (size_t)snprintf(expected, sizeof expected,
                                 "name, model, density, "
                                 "artificial_viscosity, damage, and model "
                                 "%s's ",
                                 md->name);
  for (const pm_key *k = md->keys; k->type != PM_KEY_END; k++)
    used += (size_t)snprintf(expected + used, sizeof expected - used, "%s%s",
                             k == md->keys ? "" : ", ", k->name);
  const pm_key *tables[2] = {common, md->keys};
  void *bases[2] = {out, &out->mat};
  PM_CALL(pm_reader_mapping(r, id, path, 2, tables, bases, expected));
  snprintf(sub, sizeof sub, "%s.damage", path);
  out->damage.given = pm_reader_has(r, sub);
  if (out->damage.given && !(out->damage.failure >= out->damage.elastic_limit))
    return pm_reader_expected(
        r, PM_PATH(sub, "%s.damage.failure_strain", path),
        "a strain >= damage.elastic_limit (failure follows the elastic "
        "limit)");
  const char *bad = NULL;
  if (md->init(&out->mat, &bad) != PM_SUCCESS) {
    char msg[PM_SDOC_WHERE];
    snprintf(msg, sizeof msg, "%s", pm_error_message());
    if (bad) {
      snprintf(sub, sizeof sub, "%s.%s", path, bad);
      return pm_reader_fail(r, sub, false, "%s", msg);
    }
    return pm_reader_fail(r, path, false, "%s (model %s takes %s)", msg,
                          md->name, md->key_sets ? md->key_sets : "its keys");
  }
  return PM_SUCCESS;
}

pm_err pm_scene_read_materials(pm_reader *r, int id, const char *path,
                               const pm_key *k, void *dst) {
  (void)k;
  pm_scene *s = (pm_scene *)((char *)dst - S(materials));
  char sub[PM_SDOC_PATH];
  if (pm_sdoc_kind_of(r->doc, id) != PM_SDOC_LIST ||
      pm_sdoc_count(r->doc, id) < 1)
    return pm_reader_expected(r, path, "a list of at least one material");
  int n = pm_sdoc_count(r->doc, id);
  PM_CALL(PM_ALLOC(s->materials, n, "scene materials"));
  s->n_materials = n;
  for (int i = 0; i < n; i++) {
    snprintf(sub, sizeof sub, "%s.%d", path, i);
    PM_CALL(
        read_material(r, pm_sdoc_item(r->doc, id, i), sub, &s->materials[i]));
    for (int j = 0; j < i; j++)
      if (strcmp(s->materials[j].name, s->materials[i].name) == 0) {
        snprintf(sub, sizeof sub, "%s.%d.name", path, i);
        return pm_reader_expected(r, sub,
                                  "a name not used by an earlier material");
      }
  }
  return PM_SUCCESS;
}
