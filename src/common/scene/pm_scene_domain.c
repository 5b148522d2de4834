/* pm_scene_domain: domain.box, given or, for FPM, taken from the body
 * whose geometry bounds it (a gmsh volume, or a box). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pm_scene_vocab.h"

static pm_scene_file_bounds_fn file_bounds;

void pm_scene_set_file_bounds(pm_scene_file_bounds_fn fn) { file_bounds = fn; }

static pm_err given_box(pm_reader *r, pm_scene *s) {
  char p[PM_SDOC_PATH], what[128];
  for (int c = 0; c < s->dimension; c++)
    if (!(s->box_max[c] > s->box_min[c])) {
      snprintf(what, sizeof what, "a number > domain.box.min.%d (%g)", c,
               s->box_min[c]);
      return pm_reader_expected(r, PM_PATH(p, "domain.box.max.%d", c), what);
    }
  return PM_SUCCESS;
}

/* The one body that bounds an FPM scene without domain: a gmsh volume
 * (FPM meshes it, not a box) or, alone, a box (the box FPM meshes). */
static int bounding_body(const pm_scene *s) {
  int mesh = -1;
  for (int i = 0; i < s->n_bodies; i++)
    if (s->bodies[i].shape == PM_BODY_MESH) mesh = mesh < 0 ? i : -2;
  if (mesh != -1) return mesh;
  return s->n_bodies == 1 && s->bodies[0].shape == PM_BODY_BOX ? 0 : -1;
}

pm_err pm_scene_finish_domain(pm_reader *r, pm_scene *s) {
  if (pm_reader_has(r, "domain")) return given_box(r, s);
  char p[PM_SDOC_PATH];
  if (s->method && strncmp(s->method, "mpm", 3) == 0)
    return pm_reader_fail(r, "domain", false,
                          "expected domain: {box: {min, max}} for method %s: "
                          "the box is the grid, which must leave the bodies "
                          "room to move",
                          s->method);
  const int i = bounding_body(s);
  if (i < 0)
    return pm_reader_fail(r, "domain", false,
                          "expected domain: {box: {min, max}}: without it "
                          "the scene's geometry must be one gmsh volume "
                          "(bodies.N.mesh) or one box body, which bounds it");
  const pm_scene_body *b = &s->bodies[i];
  if (b->shape == PM_BODY_BOX) {
    memcpy(s->box_min, b->a, sizeof s->box_min);
    memcpy(s->box_max, b->b, sizeof s->box_max);
  } else {
    PM_CHECK(file_bounds, PM_ERR_ARG,
             "%s: domain is not given and no reader of gmsh files bounds "
             "bodies.%d.mesh (pm_scene_set_file_bounds)",
             s->path, i);
    pm_err e = file_bounds(b->mesh, s->dimension, s->box_min, s->box_max);
    if (e)
      return pm_reader_fail(r, PM_PATH(p, "bodies.%d.mesh", i), false,
                            "the bounds of '%s' (domain is not given): %s",
                            b->mesh, pm_error_message());
  }
  if (s->dimension == 2) s->box_min[2] = s->box_max[2] = 0;
  for (int c = 0; c < s->dimension; c++)
    if (!(s->box_max[c] > s->box_min[c]))
      return pm_reader_fail(r, PM_PATH(p, "bodies.%d", i), false,
                            "expected a body of some extent along %c to "
                            "bound the domain (domain is not given), got "
                            "[%g, %g]",
                            "xyz"[c], s -> box_min[c], s -> box_max[c]);
  s->domain_from_body = true;
  return PM_SUCCESS;
}
