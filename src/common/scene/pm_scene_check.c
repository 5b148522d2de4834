/* pm_scene_check: what the key tables cannot say alone: defaults that
 * depend on other keys, names resolved to indices, and checks across keys,
 * each failing at the key at fault. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_scene_vocab.h"

/* discretization.refine: faces of the box's dimension, one of size (at most
 * the mesh size) and size_ratio, and for FPM a box it meshes (not a mesh
 * file).  MPM's grid stays uniform at mesh_size: its backend notes the key
 * and does not refuse it, so that one scene serves both methods. */
static pm_err finish_refine(pm_reader *r, pm_scene *s) {
  if (!pm_reader_has(r, "discretization.refine")) return PM_SUCCESS;
  char what[128];
  if (s->refine.near >= (1u << (2 * s->dimension)))
    return pm_reader_expected(r, "discretization.refine.near",
                              "a list of names from xmin, xmax, ymin, ymax "
                              "(dimension 2)");
  const bool size = pm_reader_has(r, "discretization.refine.size");
  const bool ratio = pm_reader_has(r, "discretization.refine.size_ratio");
  /* size_ratio: 1 is the uniform cloud whatever else refine says, so that
   * one override makes any scene's cloud uniform, graded or not. */
  if (ratio && !size && s->refine.size_ratio == 1.0) return PM_SUCCESS;
  if (!s->refine.near)
    return pm_reader_fail(r, "discretization.refine", true,
                          "expected near: [faces] (or size_ratio: 1, the "
                          "uniform cloud)");
  if (size == ratio)
    return pm_reader_fail(r, "discretization.refine", true,
                          "expected one of size (m) and size_ratio (of the "
                          "far size), got %s",
                          size ? "both" : "neither");
  if (!pm_reader_has(r, "discretization.refine.distance"))
    return pm_reader_fail(r, "discretization.refine", true,
                          "expected distance: a number > 0 (m)");
  if (!s->method || strcmp(s->method, "fpm") != 0) return PM_SUCCESS;
  if (size && s->refine.size > s->mesh_size) {
    snprintf(what, sizeof what, "a number <= discretization.mesh_size (%g)",
             s->mesh_size);
    return pm_reader_expected(r, "discretization.refine.size", what);
  }
  if (s->n_bodies == 1 && s->bodies[0].shape == PM_BODY_MESH)
    return pm_reader_fail(r, "discretization.refine", true,
                          "expected a box domain: the body's mesh file sets "
                          "its own sizes");
  return PM_SUCCESS;
}

/* A path given relative to the scene file's folder, made usable from the
 * working directory (an absolute path is kept). */
static pm_err relative_to_scene(const pm_scene *s, char **path) {
  const char *slash = strrchr(s->path, '/');
  size_t dir = ((*path)[0] != '/' && slash) ? (size_t)(slash - s->path) : 0;
  if (!dir) return PM_SUCCESS;
  size_t len = dir + 1 + strlen(*path) + 1;
  char *full = malloc(len);
  PM_CHECK(full, PM_ERR_MEMORY, "cannot copy the path '%s'", *path);
  snprintf(full, len, "%.*s/%s", (int)dir, s->path, *path);
  free(*path);
  *path = full;
  return PM_SUCCESS;
}

/* Which of keys[0 .. n) the mapping at path holds, in *given: one at
 * most (two fail: "expected one WHAT, got A and B", at the second);
 * none is -1, or, with missing, fails as the missing key(s) missing. */
static pm_err one_key(pm_reader *r, const char *path, const char *const *keys,
                      int n, const char *what, const char *missing,
                      int *given) {
  char p[2 * PM_SDOC_PATH];
  *given = -1;
  for (int k = 0; k < n; k++) {
    if (!pm_reader_has(r, PM_PATH(p, "%s.%s", path, keys[k]))) continue;
    if (*given >= 0)
      return pm_reader_fail(r, p, true, "expected one %s, got %s and %s", what,
                            keys[*given], keys[k]);
    *given = k;
  }
  if (*given < 0 && missing)
    return pm_reader_fail(r, path, false, "missing required key %s", missing);
  return PM_SUCCESS;
}

/* A membrane: exactly one surface (sphere, rectangle, file in 3D; curve in
 * 2D; points in either), and a normal method it can use. */
static pm_err finish_membrane(pm_reader *r, pm_scene *s, int i,
                              pm_scene_body *b) {
  static const char *const keys[] = {"sphere", "rectangle", "file", "curve",
                                     "points"};
  char p[PM_SDOC_PATH];
  int given;
  PM_CALL(one_key(r, PM_PATH(p, "bodies.%d.membrane", i), keys, 5,
                  "surface (sphere, rectangle, file, curve or points)",
                  "sphere, rectangle, file, curve or points (the membrane's "
                  "surface)",
                  &given));
  b->membrane.surface = (pm_surface_kind)given;
  const bool curve = b->membrane.surface == PM_SURFACE_CURVE;
  const bool cloud = b->membrane.surface == PM_SURFACE_POINTS;
  if (!cloud && (s->dimension == 3) == curve)
    return pm_reader_fail(
        r, PM_PATH(p, "bodies.%d.membrane.%s", i, keys[given]), true,
        "expected %s in dimension %d, got %s",
        s->dimension == 3 ? "a surface (sphere, rectangle, file or points)"
                          : "a curve or points",
        s->dimension, keys[given]);
  const bool normals_given =
      pm_reader_has(r, PM_PATH(p, "bodies.%d.membrane.normals", i));
  if (cloud && !normals_given)
    b->membrane.normals = PM_NORMALS_HYBRID_QUADRATIC;
  if (cloud && b->membrane.normals == PM_NORMALS_CONNECTIVITY)
    return pm_reader_fail(r, p, true,
                          "expected isosurface-linear, isosurface-quadratic, "
                          "hybrid or hybrid-quadratic (a point cloud has no "
                          "connectivity to take normals from), got "
                          "connectivity");
  if (pm_reader_has(r, PM_PATH(p, "bodies.%d.membrane.area", i)) && !cloud)
    return pm_reader_fail(r, p, true,
                          "expected area only with points (a surface or "
                          "curve gives each point its share)");
  if (curve && !(b->membrane.curve_range[1] != b->membrane.curve_range[0]))
    return pm_reader_expected(
        r, PM_PATH(p, "bodies.%d.membrane.curve.to", i),
        "a number other than curve.from (the curve's parameter range)");
  if (b->membrane.surface == PM_SURFACE_RECTANGLE) {
    double n[3];
    pm_v_cross(b->b, b->membrane.edge_v, n);
    if (!(pm_v_norm(n) > 0))
      return pm_reader_expected(
          r, PM_PATH(p, "bodies.%d.membrane.rectangle.edge_v", i),
          "an edge not parallel to edge_u");
  }
  if (b->membrane.surface == PM_SURFACE_FILE || cloud)
    return relative_to_scene(s, &b->membrane.file);
  return PM_SUCCESS;
}

/* An image: exactly one source (file, raw or points), as many numbers as
 * the dimension asks (2 or 3 in 2D, where z is unused or selects a slice),
 * a crop of at least one voxel and a label range lo <= hi.  What needs
 * the image itself (a crop inside it, a label matching some voxel) is
 * checked when it is read. */
static pm_err finish_image(pm_reader *r, pm_scene *s, int i, pm_scene_body *b) {
  static const char *const keys[] = {"file", "raw", "points"};
  char p[PM_SDOC_PATH];
  int given;
  PM_CALL(one_key(r, PM_PATH(p, "bodies.%d.image", i), keys, 3,
                  "source (file, raw or points)",
                  "file, raw or points (the image's voxels)", &given));
  b->image.source = (pm_image_source)given;
  const struct {
    const char *key;
    int n;
  } counts[] = {
      {"voxel", b->image.n_voxel},
      {"origin", b->image.n_origin},
      {"crop.min", b->image.n_crop_min},
      {"crop.max", b->image.n_crop_max},
      {given == PM_IMAGE_RAW ? "raw.size" : "points.size", b->image.n_size}};
  for (int k = 0; k < 5; k++)
    if (counts[k].n != 0 && counts[k].n < s->dimension)
      return pm_reader_fail(r,
                            PM_PATH(p, "bodies.%d.image.%s", i, counts[k].key),
                            false, "expected %d numbers (dimension %d), got %d",
                            s->dimension, s->dimension, counts[k].n);
  if (b->image.n_crop_max != b->image.n_crop_min)
    return pm_reader_fail(r, PM_PATH(p, "bodies.%d.image.crop.max", i), false,
                          "expected %d numbers like crop.min, got %d",
                          b->image.n_crop_min, b->image.n_crop_max);
  for (int c = 0; c < b->image.n_crop_min; c++)
    if (!(b->image.crop_max[c] > b->image.crop_min[c]))
      return pm_reader_expected(
          r, PM_PATH(p, "bodies.%d.image.crop.max.%d", i, c),
          "an index > crop.min (a crop of at least one voxel)");
  if (b->image.label[1] < b->image.label[0])
    return pm_reader_fail(r, PM_PATH(p, "bodies.%d.image.label", i), false,
                          "expected [lo, hi] with lo <= hi, got [%g, %g]",
                          b->image.label[0], b->image.label[1]);
  return relative_to_scene(s, &b->image.file);
}

/* Exactly one shape key; the shape's own checks. */
static pm_err finish_shape(pm_reader *r, pm_scene *s, int i, pm_scene_body *b) {
  static const char *const keys[] = {"region",   "box",     "sphere",
                                     "cylinder", "mesh",    "membrane",
                                     "inside",   "outside", "image"};
  static const pm_body_shape shapes[] = {
      PM_BODY_REGION,   PM_BODY_BOX,     PM_BODY_SPHERE,
      PM_BODY_CYLINDER, PM_BODY_MESH,    PM_BODY_MEMBRANE,
      PM_BODY_INSIDE,   PM_BODY_OUTSIDE, PM_BODY_IMAGE};
  enum { N_SHAPES = sizeof shapes / sizeof shapes[0] };
  char p[PM_SDOC_PATH];
  int given;
  PM_CALL(one_key(r, PM_PATH(p, "bodies.%d", i), keys, N_SHAPES,
                  "shape (region, box, sphere, cylinder, mesh, membrane, "
                  "inside, outside or image)",
                  NULL, &given));
  if (given < 0) {
    b->shape = PM_BODY_DOMAIN;
    return PM_SUCCESS;
  }
  if (given > 0) b->shape = shapes[given]; /* region: set by its reader */
  switch (b->shape) {
  case PM_BODY_BOX:
    for (int c = 0; c < s->dimension; c++)
      if (!(b->b[c] > b->a[c]))
        return pm_reader_expected(r, PM_PATH(p, "bodies.%d.box.max.%d", i, c),
                                  "a number > the box's min");
    return PM_SUCCESS;
  case PM_BODY_CYLINDER:
    if (s->dimension != 3)
      return pm_reader_fail(r, PM_PATH(p, "bodies.%d.cylinder", i), true,
                            "expected box, sphere, region or mesh (dimension "
                            "2), got cylinder");
    if (!(pm_v_norm(b->b) > 0))
      return pm_reader_expected(r, PM_PATH(p, "bodies.%d.cylinder.axis", i),
                                "a non-zero vector (base to top face)");
    return PM_SUCCESS;
  case PM_BODY_MESH: return relative_to_scene(s, &b->mesh);
  case PM_BODY_MEMBRANE: return finish_membrane(r, s, i, b);
  case PM_BODY_IMAGE: return finish_image(r, s, i, b);
  default: return PM_SUCCESS;
  }
}

/* Body names are unique; inside and outside name a membrane body. */
static pm_err finish_body_names(pm_reader *r, pm_scene *s) {
  char p[PM_SDOC_PATH];
  for (int i = 0; i < s->n_bodies; i++) {
    pm_scene_body *b = &s->bodies[i];
    for (int j = 0; b->name && j < i; j++)
      if (s->bodies[j].name && strcmp(s->bodies[j].name, b->name) == 0)
        return pm_reader_expected(r, PM_PATH(p, "bodies.%d.name", i),
                                  "a name not used by an earlier body");
    if (b->shape != PM_BODY_INSIDE && b->shape != PM_BODY_OUTSIDE) continue;
    const char *want = b->shape == PM_BODY_INSIDE ? b->inside : b->outside;
    const char *key = b->shape == PM_BODY_INSIDE ? "inside" : "outside";
    b->surface_body = -1;
    for (int j = 0; j < s->n_bodies; j++)
      if (s->bodies[j].name && strcmp(s->bodies[j].name, want) == 0)
        b->surface_body = j;
    PM_PATH(p, "bodies.%d.%s", i, key);
    if (b->surface_body < 0)
      return pm_reader_expected(r, p,
                                "the name of a membrane body (bodies.N.name)");
    if (s->bodies[b->surface_body].shape != PM_BODY_MEMBRANE)
      return pm_reader_fail(r, p, true,
                            "expected the name of a membrane body, got %s "
                            "(bodies.%d is not a membrane)",
                            want, b->surface_body);
  }
  return PM_SUCCESS;
}

/* The initial state a body's material needs: density, pressure for
 * fluids, fibres for anisotropic models. */
static pm_err finish_body_state(pm_reader *r, int i, pm_scene_body *b,
                                const pm_scene_material *mat) {
  char p[PM_SDOC_PATH];
  const pm_model *md = mat->mat.model;
  bool fluid = pm_material_is_fluid(&mat->mat);
  if (isnan(b->density)) b->density = mat->mat.density;
  if (pm_reader_has(r, PM_PATH(p, "bodies.%d.pressure", i))) {
    if (!fluid)
      return pm_reader_fail(r, p, true,
                            "expected a key of a solid body (material, shape, "
                            "velocity, density, fibres), got pressure "
                            "(material %s is not a fluid)",
                            mat->name);
    if (!(b->pressure + mat->mat.fluid.p_inf > 0))
      return pm_reader_expected(r, p, "a pressure > -p_inf of the material");
  } else if (fluid) {
    return pm_reader_fail(r, PM_PATH(p, "bodies.%d", i), false,
                          "missing required key pressure (a body of fluid "
                          "%s needs its initial pressure, Pa)",
                          mat->name);
  }
  int nf = b->point.n_fibres;
  if (nf > md->fibres_max) {
    if (md->fibres_max == 0)
      return pm_reader_fail(r, PM_PATH(p, "bodies.%d.fibres", i), true,
                            "expected no fibres (model %s of material %s "
                            "takes none), got %d",
                            md->name, mat->name, nf);
    return pm_reader_fail(r, PM_PATH(p, "bodies.%d.fibres", i), false,
                          "expected at most %d fibre directions (model %s), "
                          "got %d",
                          md->fibres_max, md->name, nf);
  }
  if (nf < md->fibres_min)
    return pm_reader_fail(r, PM_PATH(p, "bodies.%d", i), false,
                          "missing required key fibres (model %s of material "
                          "%s needs %d to %d fibre directions)",
                          md->name, mat->name, md->fibres_min, md->fibres_max);
  return PM_SUCCESS;
}

static pm_err finish_bodies(pm_reader *r, pm_scene *s) {
  char p[PM_SDOC_PATH], what[PM_SDOC_WHERE];
  if (s->n_bodies == 0) {
    /* materials[0] over the whole domain. */
    const pm_scene_material *mat = &s->materials[0];
    if (pm_material_is_fluid(&mat->mat))
      return pm_reader_fail(r, "materials.0", false,
                            "expected bodies: a fluid needs a body with its "
                            "initial pressure (bodies: [{material: %s, "
                            "pressure: ...}])",
                            mat->name);
    PM_CALL(PM_ALLOC(s->bodies, 1, "scene bodies"));
    s->n_bodies = 1;
    s->bodies[0].density = NAN;
    s->bodies[0].pressure = NAN;
    return finish_body_state(r, 0, &s->bodies[0], mat);
  }
  for (int i = 0; i < s->n_bodies; i++) {
    pm_scene_body *b = &s->bodies[i];
    int m = 0;
    while (m < s->n_materials && strcmp(s->materials[m].name, b->material_name))
      m++;
    if (m == s->n_materials) {
      size_t used = (size_t)snprintf(what, sizeof what, "a material name (");
      for (int j = 0; j < s->n_materials && used < sizeof what; j++)
        used += (size_t)snprintf(what + used, sizeof what - used, "%s%s",
                                 j ? ", " : "", s->materials[j].name);
      if (used < sizeof what) snprintf(what + used, sizeof what - used, ")");
      return pm_reader_expected(r, PM_PATH(p, "bodies.%d.material", i), what);
    }
    b->material = m;
    b->mark = pm_sdoc_mark(
        r->doc, pm_sdoc_find(r->doc, PM_PATH(p, "bodies.%d", i), false));
    PM_CALL(finish_shape(r, s, i, b));
    b->moving = pm_reader_has(r, PM_PATH(p, "bodies.%d.motion", i));
    PM_CALL(finish_body_state(r, i, b, &s->materials[m]));
  }
  return finish_body_names(r, s);
}

static pm_err finish_time(pm_reader *r, pm_scene *s) {
  if (isnan(s->time.ramp)) s->time.ramp = s->time.end / 2;
  if (s->time.qs == PM_QS_DAMPING && !(s->time.qs_damping > 0)) {
    if (pm_reader_has(r, "time.quasi_static.damping"))
      return pm_reader_expected(r, "time.quasi_static.damping",
                                "a number > 0 (method damping)");
    return pm_reader_fail(r, "time.quasi_static.damping", false,
                          "missing required key (method damping needs a "
                          "damping rate > 0, 1/s)");
  }
  return PM_SUCCESS;
}

/* A rigid body of boundary i (plate or sphere, given as key): neither on
 * nor region, nor tractions, velocities or absorbing; its normal made
 * unit; its motion a function of t alone, the components not given 0; its
 * name (default KEY.<i>) as the label of its reactions. */
static pm_err finish_rigid(pm_reader *r, pm_scene *s, int i, pm_scene_bc *bc,
                           const char *key) {
  char p[PM_SDOC_PATH];
  (void)s;
  if (bc->surface || bc->region)
    return pm_reader_fail(
        r, PM_PATH(p, "boundary.%d.%s", i, bc->surface ? "on" : "region"), true,
        "expected no %s with %s (a rigid body acts where it touches), "
        "got %s",
        bc->surface ? "on" : "region", key, bc->surface ? "on" : "region");
  static const char *const other[] = {"traction", "velocity", "absorbing",
                                      "pressure", "force",    "at"};
  const bool has[] = {bc->traction_mask != 0,
                      bc->velocity_mask != 0,
                      bc->absorbing,
                      bc->pressure != NULL,
                      bc->force_mask != 0,
                      pm_reader_has(r, PM_PATH(p, "boundary.%d.at", i))};
  for (int k = 0; k < 6; k++)
    if (has[k])
      return pm_reader_fail(r, PM_PATH(p, "boundary.%d.%s", i, other[k]), true,
                            "expected displacement only with %s (its rigid "
                            "motion, f(t)), got %s",
                            key, other[k]);
  if (bc->on == PM_ON_PLATE) {
    double len = pm_v_norm(bc->rigid_normal);
    if (!(len > 0) || !isfinite(len))
      return pm_reader_expected(r, PM_PATH(p, "boundary.%d.plate.normal", i),
                                "a direction of non-zero length");
    for (int a = 0; a < 3; a++) bc->rigid_normal[a] /= len;
  }
  for (int c = 0; c < 3; c++) {
    PM_PATH(p, "boundary.%d.displacement.%c", i, "xyz"[c]);
    if (!bc->disp[c]) {
      PM_CALL(pm_reader_expr(r, p, "0", "t", &bc->disp[c]));
      continue;
    }
    for (int v = 0; v < 3; v++)
      if (pm_expr_uses(bc->disp[c], "xyz"[v]))
        return pm_reader_fail(r, p, false,
                              "expected a function of t only (a rigid "
                              "body's motion), got %s, which uses %c",
                              pm_expr_text(bc->disp[c]), "xyz"[v]);
  }
  bc->disp_mask = r->dimension == 2 ? 3u : 7u;
  if (bc->name) {
    bc->surface = strdup(bc->name);
  } else {
    char label[32];
    snprintf(label, sizeof label, "%s.%d", key, i);
    bc->surface = strdup(label);
  }
  if (!bc->surface) return PM_ERROR(PM_ERR_MEMORY, "out of memory");
  return PM_SUCCESS;
}

/* Where the condition acts: on a face or a named surface, or a region. */
static pm_err finish_on(pm_reader *r, pm_scene *s, int i, pm_scene_bc *bc) {
  char p[PM_SDOC_PATH];
  const bool plate = pm_reader_has(r, PM_PATH(p, "boundary.%d.plate", i)),
             sphere = pm_reader_has(r, PM_PATH(p, "boundary.%d.sphere", i));
  if (plate && sphere)
    return pm_reader_fail(r, PM_PATH(p, "boundary.%d.sphere", i), true,
                          "expected plate or sphere, got both");
  if (plate || sphere) {
    bc->on = plate ? PM_ON_PLATE : PM_ON_SPHERE;
    return finish_rigid(r, s, i, bc, plate ? "plate" : "sphere");
  }
  static const char *const rigid_only[] = {"contact", "penalty", "name"};
  for (int k = 0; k < 3; k++)
    if (pm_reader_has(r, PM_PATH(p, "boundary.%d.%s", i, rigid_only[k])))
      return pm_reader_fail(r, p, true,
                            "expected %s only with a plate or a sphere, got "
                            "it with %s",
                            rigid_only[k], bc->region ? "region" : "on");
  bool has_on = bc->surface != NULL, has_region = bc->region != NULL;
  if (pm_reader_has(r, PM_PATH(p, "boundary.%d.at", i))) {
    if (has_on || has_region)
      return pm_reader_fail(r, p, true, "expected at or %s, got both",
                            has_on ? "on" : "region");
    if (!bc->force_mask || bc->disp_mask || bc->traction_mask || bc->pressure)
      return pm_reader_fail(r, p, true,
                            "expected at only with a force (and no "
                            "displacement, traction or pressure: a point "
                            "has no face), got at");
    bc->on = PM_ON_POINT;
    return PM_SUCCESS;
  }
  if (has_on == has_region) {
    if (has_on)
      return pm_reader_fail(r, PM_PATH(p, "boundary.%d.region", i), true,
                            "expected on or region, got both");
    return pm_reader_fail(r, PM_PATH(p, "boundary.%d", i), false,
                          "missing required key on (a face xmin ... zmax or "
                          "a named surface), region or at");
  }
  if (has_region) {
    bc->on = PM_ON_REGION;
    return PM_SUCCESS;
  }
  bc->on = PM_ON_SURFACE;
  for (int f = 0; f < PM_FACE_COUNT; f++)
    if (strcmp(bc->surface, pm_face_name(f)) == 0) {
      if (f >= 2 * s->dimension)
        return pm_reader_expected(r, PM_PATH(p, "boundary.%d.on", i),
                                  "one of xmin, xmax, ymin, ymax (dimension "
                                  "2)");
      bc->on = PM_ON_FACE;
      bc->face = (pm_face)f;
    }
  return PM_SUCCESS;
}

/* A symmetry plane (boundary i with symmetry: true): on a face of the
 * domain's box, nothing else prescribed there; its normal component held
 * at 0 from the start, and the plane recorded as a mirror of the scene. */
static pm_err finish_symmetry(pm_reader *r, pm_scene *s, int i,
                              pm_scene_bc *bc) {
  char p[PM_SDOC_PATH];
  if (bc->on != PM_ON_FACE) {
    const char *key = PM_BC_RIGID(bc)
                          ? (bc->on == PM_ON_PLATE ? "plate" : "sphere")
                      : bc->on == PM_ON_SURFACE ? "on"
                                                : "symmetry";
    return pm_reader_fail(
        r, PM_PATH(p, "boundary.%d.%s", i, key), true,
        "expected symmetry on a face xmin ... zmax (a plane normal to an "
        "axis; elsewhere prescribe the normal component: displacement: "
        "{x: 0}), got %s",
        PM_BC_RIGID(bc)           ? "a rigid body"
        : bc->on == PM_ON_SURFACE ? bc->surface
                                  : "no face");
  }
  static const char *const other[] = {"displacement", "traction", "pressure",
                                      "force",        "velocity", "absorbing",
                                      "curve",        "ramp",     "ramp_time"};
  const bool has[] = {bc->disp_mask != 0,
                      bc->traction_mask != 0,
                      bc->pressure != NULL,
                      bc->force_mask != 0,
                      bc->velocity_mask != 0,
                      bc->absorbing,
                      bc->curve != NULL,
                      pm_reader_has(r, PM_PATH(p, "boundary.%d.ramp", i)),
                      pm_reader_has(r, PM_PATH(p, "boundary.%d.ramp_time", i))};
  for (int k = 0; k < 9; k++)
    if (has[k])
      return pm_reader_fail(r, PM_PATH(p, "boundary.%d.%s", i, other[k]), true,
                            "expected symmetry alone (the plane holds the "
                            "normal component at 0), got %s with it",
                            other[k]);
  const int a = pm_face_axis(bc->face);
  if (s->mirror_mask >> a & 1u)
    return pm_reader_fail(r, PM_PATH(p, "boundary.%d.on", i), true,
                          "expected one symmetry plane normal to %c, got a "
                          "second (%s)",
                          "xyz"[a], bc -> surface);
  PM_CALL(pm_reader_expr(r, PM_PATH(p, "boundary.%d.symmetry", i), "0", "xyzt",
                         &bc->disp[a]));
  bc->disp_mask = 1u << a;
  bc->ramp = PM_RAMP_NONE;
  s->mirror_mask |= 1u << a;
  s->mirror_at[a] = pm_face_plane(bc->face, s->box_min, s->box_max);
  return PM_SUCCESS;
}

static pm_err finish_bcs(pm_reader *r, pm_scene *s) {
  char p[PM_SDOC_PATH];
  for (int i = 0; i < s->n_bcs; i++) {
    pm_scene_bc *bc = &s->bcs[i];
    bc->mark = pm_sdoc_mark(
        r->doc, pm_sdoc_find(r->doc, PM_PATH(p, "boundary.%d", i), false));
    PM_CALL(finish_on(r, s, i, bc));
    if (bc->symmetry) PM_CALL(finish_symmetry(r, s, i, bc));
    if (!bc->disp_mask && !bc->traction_mask && !bc->velocity_mask &&
        !bc->force_mask && !bc->pressure && !bc->absorbing)
      return pm_reader_fail(r, PM_PATH(p, "boundary.%d", i), false,
                            "expected a displacement, traction, pressure, "
                            "force or velocity component, or absorbing: "
                            "true, got none");
    static const char *const other[] = {"velocity", "traction"};
    unsigned both[2] = {bc->disp_mask & bc->velocity_mask,
                        bc->disp_mask & bc->traction_mask};
    for (int k = 0; k < 2; k++)
      for (int c = 0; c < 3; c++)
        if (both[k] & (1u << c))
          return pm_reader_fail(
              r, PM_PATH(p, "boundary.%d.%s.%c", i, other[k], "xyz"[c]), true,
              "expected a component not prescribed as displacement, got %c "
              "(also in boundary.%d.displacement)",
              "xyz"[c], i);
    if (isnan(bc->ramp_time)) bc->ramp_time = s->time.ramp;
  }
  /* A symmetry plane's face carries no other condition: it would move the
   * plane or load the part alone. */
  for (int i = 0; i < s->n_bcs; i++) {
    const pm_scene_bc *bc = &s->bcs[i];
    if (bc->symmetry || bc->on != PM_ON_FACE) continue;
    for (int j = 0; j < s->n_bcs; j++)
      if (s->bcs[j].symmetry && s->bcs[j].face == bc->face)
        return pm_reader_fail(r, PM_PATH(p, "boundary.%d.on", i), true,
                              "expected no other condition on %s, a "
                              "symmetry plane (boundary.%d), got one",
                              bc->surface, j);
  }
  return PM_SUCCESS;
}

pm_err pm_scene_finish(pm_reader *r, pm_scene *s) {
  PM_CALL(finish_bodies(r, s));
  PM_CALL(pm_scene_finish_domain(r, s));
  PM_CALL(finish_refine(r, s));
  PM_CALL(finish_time(r, s));
  PM_CALL(finish_bcs(r, s));
  if (s->reference_fe) PM_CALL(relative_to_scene(s, &s->reference_fe));
  s->has_gravity = pm_v_norm(s->gravity) > 0;
  return PM_SUCCESS;
}
