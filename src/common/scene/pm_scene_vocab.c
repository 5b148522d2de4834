/* pm_scene_vocab: the shared scene vocabulary as key tables (each key once,
 * with its default, range, unit and meaning), the readers of the keys a
 * table cannot describe alone (materials, whose keys depend on their
 * model; fibres), and the checks across keys. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_scene_vocab.h"

/* ---- names -------------------------------------------------------------- */

static const pm_name ramp_names[] = {{"smooth", PM_RAMP_SMOOTH},
                                     {"linear", PM_RAMP_LINEAR},
                                     {"none", PM_RAMP_NONE},
                                     {NULL, 0}};
static const pm_name qs_names[] = {
    {"none", PM_QS_NONE},
    {"dynamic-relaxation", PM_QS_DYNAMIC_RELAXATION},
    {"damping", PM_QS_DAMPING},
    {"static", PM_QS_STATIC},
    {NULL, 0}};
static const pm_name linear_names[] = {
    {"direct", PM_LINEAR_DIRECT},       {"gmres-gamg", PM_LINEAR_GMRES_GAMG},
    {"cg-jacobi", PM_LINEAR_CG_JACOBI}, {"gmres-ilu", PM_LINEAR_GMRES_ILU},
    {"cg-gamg", PM_LINEAR_CG_GAMG},     {NULL, 0}};
static const pm_name dt_rule_names[] = {
    {"paper", PM_DT_PAPER}, {"spectral", PM_DT_SPECTRAL}, {NULL, 0}};
static const pm_name field_names[] = {
    {"displacement", PM_FIELD_DISPLACEMENT},
    {"velocity", PM_FIELD_VELOCITY},
    {"stress", PM_FIELD_STRESS},
    {"strain_energy_density", PM_FIELD_STRAIN_ENERGY_DENSITY},
    {"jacobian", PM_FIELD_JACOBIAN},
    {"force", PM_FIELD_FORCE},
    {NULL, 0}};

#define S(field) offsetof(pm_scene, field)
#define B(field) offsetof(pm_scene_body, field)
#define C(field) offsetof(pm_scene_bc, field)

/* ---- custom readers ----------------------------------------------------- */

static pm_err read_dimension(pm_reader *r, int id, const char *path,
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
static pm_err read_fibres(pm_reader *r, int id, const char *path,
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
static pm_err read_region(pm_reader *r, int id, const char *path,
                          const pm_key *k, void *dst) {
  (void)k;
  pm_scene_body *b = (pm_scene_body *)((char *)dst - B(region));
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

static void release_expr(void *dst) {
  pm_expr_destroy(*(pm_expr **)dst);
  *(pm_expr **)dst = NULL;
}

/* ---- tables ------------------------------------------------------------- */

static const pm_key box_keys[] = {{.name = "min",
                                   .type = PM_KEY_POINT,
                                   .offset = S(box_min),
                                   .flags = PM_KEY_REQUIRED,
                                   .unit = "m",
                                   .doc = "lower corner"},
                                  {.name = "max",
                                   .type = PM_KEY_POINT,
                                   .offset = S(box_max),
                                   .flags = PM_KEY_REQUIRED,
                                   .unit = "m",
                                   .doc = "upper corner"},
                                  {0}};

static const pm_key domain_keys[] = {
    {.name = "box",
     .type = PM_KEY_MAPPING,
     .flags = PM_KEY_REQUIRED,
     .keys = box_keys,
     .doc = "FPM: the block meshed; MPM: the grid (faces on grid planes)"},
    {0}};

static const pm_key discretization_keys[] = {
    {.name = "mesh_size",
     .type = PM_KEY_NUMBER,
     .offset = S(mesh_size),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "m",
     .doc = "FPM: gmsh element size; MPM: cell size"},
    {0}};

static const pm_key body_box_keys[] = {{.name = "min",
                                        .type = PM_KEY_POINT,
                                        .offset = B(a),
                                        .flags = PM_KEY_REQUIRED,
                                        .unit = "m"},
                                       {.name = "max",
                                        .type = PM_KEY_POINT,
                                        .offset = B(b),
                                        .flags = PM_KEY_REQUIRED,
                                        .unit = "m"},
                                       {0}};
static const pm_key sphere_keys[] = {{.name = "center",
                                      .type = PM_KEY_POINT,
                                      .offset = B(a),
                                      .flags = PM_KEY_REQUIRED,
                                      .unit = "m"},
                                     {.name = "radius",
                                      .type = PM_KEY_NUMBER,
                                      .offset = B(radius),
                                      .flags = PM_KEY_REQUIRED,
                                      .range = PM_RANGE_GT,
                                      .unit = "m"},
                                     {0}};
static const pm_key cylinder_keys[] = {
    {.name = "base",
     .type = PM_KEY_NUMBERS,
     .offset = B(a),
     .flags = PM_KEY_REQUIRED,
     .min_count = 3,
     .max_count = 3,
     .count_offset = B(n_cylinder),
     .unit = "m",
     .doc = "centre of the base face"},
    {.name = "axis",
     .type = PM_KEY_NUMBERS,
     .offset = B(b),
     .flags = PM_KEY_REQUIRED,
     .min_count = 3,
     .max_count = 3,
     .count_offset = B(n_cylinder),
     .unit = "m",
     .doc = "from the base face's centre to the top face's"},
    {.name = "radius",
     .type = PM_KEY_NUMBER,
     .offset = B(radius),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "m"},
    {0}};

static const pm_key membrane_sphere_keys[] = {
    {.name = "center",
     .type = PM_KEY_POINT,
     .offset = B(a),
     .flags = PM_KEY_REQUIRED,
     .unit = "m"},
    {.name = "radius",
     .type = PM_KEY_NUMBER,
     .offset = B(radius),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "m"},
    {.name = "refinement",
     .type = PM_KEY_INTEGER,
     .offset = B(membrane.refinement),
     .def = "4",
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 0,
     .hi = 9,
     .doc = "icosahedron subdivisions: 10 4^r + 2 points (6: 40962)"},
    {0}};
static const pm_key membrane_rectangle_keys[] = {
    {.name = "origin",
     .type = PM_KEY_POINT,
     .offset = B(a),
     .flags = PM_KEY_REQUIRED,
     .unit = "m",
     .doc = "a corner"},
    {.name = "edge_u",
     .type = PM_KEY_POINT,
     .offset = B(b),
     .flags = PM_KEY_REQUIRED,
     .unit = "m",
     .doc = "first edge from the corner"},
    {.name = "edge_v",
     .type = PM_KEY_POINT,
     .offset = B(membrane.edge_v),
     .flags = PM_KEY_REQUIRED,
     .unit = "m",
     .doc = "second edge from the corner (normal along edge_u x edge_v)"},
    {.name = "points",
     .type = PM_KEY_NUMBERS,
     .offset = B(membrane.points),
     .count_offset = B(membrane.n_points),
     .flags = PM_KEY_REQUIRED | PM_KEY_WHOLE,
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 2,
     .hi = 1e5,
     .min_count = 2,
     .max_count = 2,
     .doc = "[nu, nv] points along the edges"},
    {0}};
const pm_name pm_normals_names[] = {
    {"connectivity", PM_NORMALS_CONNECTIVITY},
    {"isosurface-linear", PM_NORMALS_ISO_LINEAR},
    {"isosurface-quadratic", PM_NORMALS_ISO_QUADRATIC},
    {"hybrid", PM_NORMALS_HYBRID},
    {"hybrid-quadratic", PM_NORMALS_HYBRID_QUADRATIC},
    {NULL, 0}};
static const pm_key membrane_curve_keys[] = {
    {.name = "x",
     .type = PM_KEY_EXPR,
     .offset = B(membrane.curve[0]),
     .flags = PM_KEY_REQUIRED | PM_KEY_NO_XYZ,
     .unit = "m",
     .doc = "x(t) of the curve's parameter t"},
    {.name = "y",
     .type = PM_KEY_EXPR,
     .offset = B(membrane.curve[1]),
     .flags = PM_KEY_REQUIRED | PM_KEY_NO_XYZ,
     .unit = "m",
     .doc = "y(t)"},
    {.name = "from",
     .type = PM_KEY_NUMBER,
     .offset = B(membrane.curve_range[0]),
     .def = "0",
     .doc = "first t"},
    {.name = "to",
     .type = PM_KEY_NUMBER,
     .offset = B(membrane.curve_range[1]),
     .def = "1",
     .doc = "last t"},
    {.name = "points",
     .type = PM_KEY_INTEGER,
     .offset = B(membrane.curve_points),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 2,
     .hi = 1e7,
     .doc = "points, at equal arc length"},
    {.name = "closed",
     .type = PM_KEY_BOOL,
     .offset = B(membrane.closed),
     .def = "false",
     .doc = "the curve returns to its start"},
    {0}};
static const pm_key membrane_keys[] = {
    {.name = "thickness",
     .type = PM_KEY_NUMBER,
     .offset = B(membrane.thickness),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "m",
     .doc = "one point through it: mass = density thickness area"},
    {.name = "sphere",
     .type = PM_KEY_MAPPING,
     .keys = membrane_sphere_keys,
     .doc = "{center, radius, refinement}: a subdivided icosahedron"},
    {.name = "rectangle",
     .type = PM_KEY_MAPPING,
     .keys = membrane_rectangle_keys,
     .doc = "{origin, edge_u, edge_v, points}: a flat triangulated "
            "rectangle"},
    {.name = "file",
     .type = PM_KEY_STRING,
     .offset = B(membrane.file),
     .doc = "a gmsh-readable surface (.msh, .stl, ...), relative to the "
            "scene"},
    {.name = "curve",
     .type = PM_KEY_MAPPING,
     .keys = membrane_curve_keys,
     .doc = "{x, y, from, to, points, closed}: a line of points (2D)"},
    {.name = "points",
     .type = PM_KEY_STRING,
     .offset = B(membrane.file),
     .doc = "a point cloud (.csv or .xyz: x y [z] [area per point]), "
            "relative to the scene; no connectivity"},
    {.name = "area",
     .type = PM_KEY_NUMBER,
     .offset = B(membrane.area),
     .def = "0",
     .range = PM_RANGE_GE,
     .unit = "m^2",
     .doc = "points: total area (2D: length, m) shared equally, when the "
            "file gives none per point"},
    {.name = "normals",
     .type = PM_KEY_ENUM,
     .offset = B(membrane.normals),
     .def = "connectivity",
     .names = pm_normals_names,
     .doc = "connectivity (triangles, or neighbours along a curve), "
            "isosurface-linear, isosurface-quadratic, hybrid (the paper's "
            "rule) or hybrid-quadratic (default for points)"},
    {0}};
static const pm_key motion_keys[] = {
    {.name = "velocity",
     .type = PM_KEY_COMPONENTS,
     .offset = B(motion),
     .count_offset = B(motion_mask),
     .flags = PM_KEY_REQUIRED | PM_KEY_NO_XYZ,
     .unit = "m/s",
     .doc = "{x, y, z}: velocity f(t) of the rigid body (unset: 0)"},
    {0}};

/* image: a labelled volumetric image, one body per intensity range.  Raw
 * volumes and point files are given their size. */
#define IMAGE_SIZE_KEY                                                         \
  {                                                                            \
    .name = "size", .type = PM_KEY_NUMBERS, .offset = B(image.size),           \
    .count_offset = B(image.n_size), .flags = PM_KEY_REQUIRED | PM_KEY_WHOLE,  \
    .range = PM_RANGE_GE, .lo = 1, .min_count = 2, .max_count = 3,             \
    .doc = "[nx, ny(, nz)] voxels"                                             \
  }
static const pm_name image_bits_names[] = {{"8", 8}, {"16", 16}, {NULL, 0}};
static const pm_key image_raw_keys[] = {
    {.name = "file",
     .type = PM_KEY_STRING,
     .offset = B(image.file),
     .flags = PM_KEY_REQUIRED,
     .doc = "nx ny nz values (x fastest, little-endian, no header), relative "
            "to the scene"},
    IMAGE_SIZE_KEY,
    {.name = "bits",
     .type = PM_KEY_ENUM,
     .offset = B(image.bits),
     .def = "8",
     .names = image_bits_names,
     .doc = "8 or 16 bits per voxel"},
    {0}};
static const pm_key image_points_keys[] = {
    {.name = "file",
     .type = PM_KEY_STRING,
     .offset = B(image.file),
     .flags = PM_KEY_REQUIRED,
     .doc = "one voxel centre per line (x y [z]; '#' comments), relative to "
            "the scene: those voxels 255, the others 0"},
    IMAGE_SIZE_KEY,
    {.name = "unit",
     .type = PM_KEY_NUMBER,
     .offset = B(image.unit),
     .def = "1",
     .range = PM_RANGE_GT,
     .unit = "m",
     .doc = "metres per unit of the file (1e-6: micrometres)"},
    {0}};
static const pm_key image_crop_keys[] = {
    {.name = "min",
     .type = PM_KEY_NUMBERS,
     .offset = B(image.crop_min),
     .count_offset = B(image.n_crop_min),
     .flags = PM_KEY_REQUIRED | PM_KEY_WHOLE,
     .range = PM_RANGE_GE,
     .lo = 0,
     .min_count = 2,
     .max_count = 3,
     .doc = "[i0, j0(, k0)]: the first voxel"},
    {.name = "max",
     .type = PM_KEY_NUMBERS,
     .offset = B(image.crop_max),
     .count_offset = B(image.n_crop_max),
     .flags = PM_KEY_REQUIRED | PM_KEY_WHOLE,
     .range = PM_RANGE_GE,
     .lo = 1,
     .min_count = 2,
     .max_count = 3,
     .doc = "[i1, j1(, k1)]: one past the last"},
    {0}};
static const pm_key image_keys[] = {
    {.name = "file",
     .type = PM_KEY_STRING,
     .offset = B(image.file),
     .doc = "a multi-page TIFF, or a folder of TIFFs (read in the order of "
            "their names), 8- or 16-bit grey; relative to the scene"},
    {.name = "raw",
     .type = PM_KEY_MAPPING,
     .keys = image_raw_keys,
     .doc = "{file, size, bits}: a raw volume (instead of file)"},
    {.name = "points",
     .type = PM_KEY_MAPPING,
     .keys = image_points_keys,
     .doc = "{file, size, unit}: a point file of voxel centres (instead of "
            "file)"},
    {.name = "voxel",
     .type = PM_KEY_NUMBERS,
     .offset = B(image.voxel),
     .count_offset = B(image.n_voxel),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .min_count = 2,
     .max_count = 3,
     .unit = "m",
     .doc = "voxel size [dx, dy(, dz)] (in 2D, dz only places a point file's "
            "centres)"},
    {.name = "origin",
     .type = PM_KEY_NUMBERS,
     .offset = B(image.origin),
     .count_offset = B(image.n_origin),
     .def = "0, 0, 0",
     .min_count = 2,
     .max_count = 3,
     .unit = "m",
     .doc = "the corner of voxel (0, 0, 0) (in 2D, z only places a point "
            "file's centres; the particles are at z = 0)"},
    {.name = "crop",
     .type = PM_KEY_MAPPING,
     .keys = image_crop_keys,
     .doc = "{min, max}: voxel indices, half-open (default: the whole "
            "image; in 2D one slice)"},
    {.name = "label",
     .type = PM_KEY_NUMBERS,
     .offset = B(image.label),
     .count_offset = B(image.n_label),
     .flags = PM_KEY_REQUIRED | PM_KEY_WHOLE,
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 0,
     .hi = 65535,
     .min_count = 2,
     .max_count = 2,
     .doc = "[lo, hi]: the intensities of this body's voxels, inclusive; "
            "one body per range maps labels to materials"},
    {.name = "particles_per_voxel",
     .type = PM_KEY_INTEGER,
     .offset = B(image.per_voxel),
     .def = "1",
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 1,
     .hi = 16,
     .doc = "n per direction: n^d particles at the sub-voxel centres, each "
            "of 1/n^d of the voxel's volume"},
    {0}};

static const pm_key body_keys[] = {
    {.name = "name",
     .type = PM_KEY_STRING,
     .offset = B(name),
     .doc = "what inside and outside call a membrane body"},
    {.name = "material",
     .type = PM_KEY_STRING,
     .offset = B(material_name),
     .flags = PM_KEY_REQUIRED,
     .doc = "the name of a material"},
    {.name = "region",
     .type = PM_KEY_CUSTOM,
     .offset = B(region),
     .read = read_region,
     .what = "an expression in x, y, z, or domain",
     .release = release_expr,
     .doc = "inside where f(x, y, z) > 0 (or: domain)"},
    {.name = "box",
     .type = PM_KEY_MAPPING,
     .keys = body_box_keys,
     .doc = "{min, max}"},
    {.name = "sphere",
     .type = PM_KEY_MAPPING,
     .keys = sphere_keys,
     .doc = "{center, radius} (a disk in 2D)"},
    {.name = "cylinder",
     .type = PM_KEY_MAPPING,
     .keys = cylinder_keys,
     .doc = "{base, axis, radius} (3D)"},
    {.name = "mesh",
     .type = PM_KEY_STRING,
     .offset = B(mesh),
     .doc = "a gmsh-readable volume (.msh .geo .step .brep), relative to the "
            "scene"},
    {.name = "membrane",
     .type = PM_KEY_MAPPING,
     .keys = membrane_keys,
     .doc = "{thickness, sphere | rectangle | file | curve | points, normals}: "
            "a membrane (MPM)"},
    {.name = "image",
     .type = PM_KEY_MAPPING,
     .keys = image_keys,
     .doc = "{file | raw | points, voxel, origin, crop, label, "
            "particles_per_voxel}: the voxels of a labelled image whose "
            "intensity is in label (MPM), seeded per voxel, not per cell, "
            "apart from other bodies' precedence"},
    {.name = "inside",
     .type = PM_KEY_STRING,
     .offset = B(inside),
     .doc = "the inside of the closed membrane body of this name"},
    {.name = "outside",
     .type = PM_KEY_STRING,
     .offset = B(outside),
     .doc = "the domain outside the closed membrane body of this name"},
    {.name = "velocity",
     .type = PM_KEY_POINT,
     .offset = B(velocity),
     .unit = "m/s",
     .doc = "initial velocity (MPM)"},
    {.name = "motion",
     .type = PM_KEY_MAPPING,
     .keys = motion_keys,
     .doc = "{velocity: {x, y, z}}: prescribed rigid motion (MPM)"},
    {.name = "particles_per_cell",
     .type = PM_KEY_NUMBERS,
     .offset = B(ppc),
     .count_offset = B(n_ppc),
     .flags = PM_KEY_WHOLE,
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 1,
     .hi = 64,
     .min_count = 1,
     .max_count = 3,
     .doc = "this body's [n] or [nx, ny(, nz)] (MPM; default "
            "mpm.particles_per_cell)"},
    {.name = "density",
     .type = PM_KEY_NUMBER,
     .offset = B(density),
     .def = "nan",
     .range = PM_RANGE_GT,
     .unit = "kg/m^3",
     .doc = "initial density (MPM; default: the material's)"},
    {.name = "pressure",
     .type = PM_KEY_NUMBER,
     .offset = B(pressure),
     .def = "nan",
     .unit = "Pa",
     .doc = "initial pressure (fluids)"},
    {.name = "fibres",
     .type = PM_KEY_CUSTOM,
     .offset = B(point),
     .read = read_fibres,
     .what = "a list of 1 or 2 directions [ax, ay, az]",
     .doc = "fibre directions [[ax, ay, az], ...] (anisotropic models)"},
    {0}};

static const pm_key bc_keys[] = {
    {.name = "on",
     .type = PM_KEY_STRING,
     .offset = C(surface),
     .doc = "xmin, xmax, ymin, ymax, zmin, zmax, or a named surface"},
    {.name = "region",
     .type = PM_KEY_EXPR,
     .offset = C(region),
     .flags = PM_KEY_NO_T,
     .doc = "the boundary where f(x, y, z) > 0 (instead of on)"},
    {.name = "displacement",
     .type = PM_KEY_COMPONENTS,
     .offset = C(disp),
     .count_offset = C(disp_mask),
     .unit = "m",
     .doc = "prescribed components at full load, f(x, y, z, t)"},
    {.name = "traction",
     .type = PM_KEY_COMPONENTS,
     .offset = C(traction),
     .count_offset = C(traction_mask),
     .unit = "Pa",
     .doc = "nominal traction at full load (FPM)"},
    {.name = "velocity",
     .type = PM_KEY_COMPONENTS,
     .offset = C(velocity),
     .count_offset = C(velocity_mask),
     .unit = "m/s",
     .doc = "prescribed velocity (MPM)"},
    {.name = "absorbing",
     .type = PM_KEY_BOOL,
     .offset = C(absorbing),
     .def = "false",
     .doc = "viscous (absorbing) boundary (MPM)"},
    {.name = "ramp",
     .type = PM_KEY_ENUM,
     .offset = C(ramp),
     .def = "smooth",
     .names = ramp_names,
     .doc = "smooth: 10 s^3 - 15 s^4 + 6 s^5; linear: s; none: 1"},
    {.name = "ramp_time",
     .type = PM_KEY_NUMBER,
     .offset = C(ramp_time),
     .def = "nan",
     .range = PM_RANGE_GT,
     .unit = "s",
     .doc = "ramp duration (default: time.ramp)"},
    {0}};

static const pm_key quasi_static_keys[] = {
    {.name = "method",
     .type = PM_KEY_ENUM,
     .offset = S(time.qs),
     .def = "none",
     .names = qs_names,
     .doc = "none, dynamic-relaxation (adaptive damping), damping, or "
            "static (equilibrium by Newton's method in load steps)"},
    {.name = "tolerance",
     .type = PM_KEY_NUMBER,
     .offset = S(time.qs_tolerance),
     .def = "1e-8",
     .range = PM_RANGE_GT,
     .unit = "",
     .doc = "stop when the residual over the reactions falls below it"},
    {.name = "damping",
     .type = PM_KEY_NUMBER,
     .offset = S(time.qs_damping),
     .def = "0",
     .range = PM_RANGE_GE,
     .unit = "1/s",
     .doc = "mass-proportional damping rate (method damping)"},
    {.name = "load_steps",
     .type = PM_KEY_INTEGER,
     .offset = S(time.qs_load_steps),
     .def = "10",
     .range = PM_RANGE_GE,
     .lo = 1,
     .unit = "",
     .doc = "method static: load steps along the scene's ramps (a step that "
            "fails is halved and retried)"},
    {.name = "max_iterations",
     .type = PM_KEY_INTEGER,
     .offset = S(time.qs_max_iterations),
     .def = "25",
     .range = PM_RANGE_GE,
     .lo = 1,
     .unit = "",
     .doc = "method static: Newton iterations per load step"},
    {.name = "linear_solver",
     .type = PM_KEY_ENUM,
     .offset = S(time.qs_linear),
     .def = "direct",
     .names = linear_names,
     .doc = "method static and mpm-implicit: direct (LU), gmres-gamg, "
            "gmres-ilu, cg-jacobi or cg-gamg (symmetric problems)"},
    {.name = "solver_options",
     .type = PM_KEY_STRING,
     .offset = S(time.qs_solver_options),
     .def = "nan",
     .doc = "method static: PETSc options with prefix pm_ (e.g. "
            "\"-pm_snes_monitor -pm_ksp_type bcgs\")"},
    {0}};

static const pm_key time_keys[] = {
    {.name = "end",
     .type = PM_KEY_NUMBER,
     .offset = S(time.end),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "s",
     .doc = "the longest a run may go"},
    {.name = "dt",
     .type = PM_KEY_NUMBER,
     .offset = S(time.dt),
     .def = "0",
     .range = PM_RANGE_GE,
     .unit = "s",
     .doc = "> 0 forces a step; 0: the stable step"},
    {.name = "dt_safety",
     .type = PM_KEY_NUMBER,
     .offset = S(time.dt_safety),
     .def = "nan",
     .range = PM_RANGE_GT | PM_RANGE_LE,
     .hi = 1,
     .unit = "",
     .doc = "dt = dt_safety x stable step (default: the method's)"},
    {.name = "dt_rule",
     .type = PM_KEY_ENUM,
     .offset = S(time.dt_rule),
     .def = "paper",
     .names = dt_rule_names,
     .doc = "paper: the method's bound; spectral: measured (FPM)"},
    {.name = "ramp",
     .type = PM_KEY_NUMBER,
     .offset = S(time.ramp),
     .def = "nan",
     .range = PM_RANGE_GT,
     .unit = "s",
     .doc = "default ramp duration (default: end / 2)"},
    {.name = "max_steps",
     .type = PM_KEY_INTEGER,
     .offset = S(time.max_steps),
     .def = "0",
     .range = PM_RANGE_GE,
     .doc = "0: no limit"},
    {.name = "quasi_static",
     .type = PM_KEY_MAPPING,
     .keys = quasi_static_keys,
     .doc = "{method, tolerance, damping}"},
    {0}};

static const pm_key checkpoint_keys[] = {
    {.name = "every",
     .type = PM_KEY_INTEGER,
     .offset = S(output.checkpoint.every),
     .def = "0",
     .range = PM_RANGE_GE,
     .doc = "a checkpoint every N steps (0: none); `pointmech resume OUT` "
            "continues from the last"},
    {.name = "minutes",
     .type = PM_KEY_NUMBER,
     .offset = S(output.checkpoint.minutes),
     .def = "0",
     .range = PM_RANGE_GE,
     .unit = "min",
     .doc = "a checkpoint every M minutes of wall time (0: none)"},
    {0}};

static const pm_key output_keys[] = {
    {.name = "every",
     .type = PM_KEY_INTEGER,
     .offset = S(output.every),
     .def = "100",
     .range = PM_RANGE_GT,
     .doc = "a frame every N steps"},
    {.name = "fields",
     .type = PM_KEY_FLAGS,
     .offset = S(output.fields),
     .def = "displacement, stress, strain_energy_density",
     .min_count = 1,
     .names = field_names,
     .doc = "fields written in each frame"},
    {.name = "checkpoint",
     .type = PM_KEY_MAPPING,
     .keys = checkpoint_keys,
     .doc = "{every, minutes}: the whole state, written atomically (SIGINT "
            "and SIGTERM write one too)"},
    {0}};

static const pm_key stability_keys[] = {
    {.name = "min_jacobian",
     .type = PM_KEY_NUMBER,
     .offset = S(stability.min_jacobian),
     .def = "0",
     .range = PM_RANGE_GE | PM_RANGE_LT,
     .hi = 1,
     .unit = "",
     .doc = "stop when some J falls to or below it"},
    {.name = "max_energy_error",
     .type = PM_KEY_NUMBER,
     .offset = S(stability.max_energy_error),
     .def = "0.1",
     .range = PM_RANGE_GT,
     .unit = "",
     .doc = "stop when the energy-balance error exceeds it (FPM)"},
    {0}};

static const pm_key reference_keys[] = {
    {.name = "displacement",
     .type = PM_KEY_COMPONENTS,
     .offset = S(reference),
     .count_offset = S(reference_mask),
     .unit = "m",
     .doc = "analytic u(x, y, z, t): NRMSE in summary and history"},
    {.name = "fe",
     .type = PM_KEY_STRING,
     .offset = S(reference_fe),
     .doc = "a folder of finite-element reference data (cases/fe/CASE), "
            "relative to the scene: the default referee of convergence"},
    {0}};

const pm_key pm_scene_keys[] = {
    {.name = "name",
     .type = PM_KEY_STRING,
     .offset = S(name),
     .flags = PM_KEY_REQUIRED,
     .doc = "the output folder's name"},
    {.name = "method",
     .type = PM_KEY_STRING,
     .offset = S(method),
     .flags = PM_KEY_REQUIRED,
     .doc = "a registered method (fpm, mpm, mpm-implicit)"},
    {.name = "dimension",
     .type = PM_KEY_CUSTOM,
     .offset = S(dimension),
     .flags = PM_KEY_REQUIRED,
     .read = read_dimension,
     .what = "2 or 3",
     .doc = "3, or 2 for plane strain"},
    {.name = "domain",
     .type = PM_KEY_MAPPING,
     .flags = PM_KEY_REQUIRED,
     .keys = domain_keys,
     .doc = "{box: {min, max}}"},
    {.name = "discretization",
     .type = PM_KEY_MAPPING,
     .flags = PM_KEY_REQUIRED,
     .keys = discretization_keys,
     .doc = "{mesh_size}"},
    {.name = "materials",
     .type = PM_KEY_CUSTOM,
     .offset = S(materials),
     .flags = PM_KEY_REQUIRED,
     .read = pm_scene_read_materials,
     .what = "a list of materials (below)",
     .doc = "[{name, model, density, ...the model's keys}]"},
    {.name = "bodies",
     .type = PM_KEY_LIST,
     .offset = S(bodies),
     .count_offset = S(n_bodies),
     .elem_size = sizeof(pm_scene_body),
     .min_count = 1,
     .keys = body_keys,
     .doc = "[{material, shape, ...}]; later bodies take precedence"},
    {.name = "time",
     .type = PM_KEY_MAPPING,
     .flags = PM_KEY_REQUIRED,
     .keys = time_keys,
     .doc = "{end, dt, dt_safety, ...}"},
    {.name = "boundary",
     .type = PM_KEY_LIST,
     .offset = S(bcs),
     .count_offset = S(n_bcs),
     .elem_size = sizeof(pm_scene_bc),
     .keys = bc_keys,
     .doc = "[{on, displacement | traction | ...}]"},
    {.name = "gravity",
     .type = PM_KEY_POINT,
     .offset = S(gravity),
     .unit = "m/s^2",
     .doc = "body force per mass (MPM)"},
    {.name = "output",
     .type = PM_KEY_MAPPING,
     .keys = output_keys,
     .doc = "{every, fields}"},
    {.name = "stability",
     .type = PM_KEY_MAPPING,
     .keys = stability_keys,
     .doc = "{min_jacobian, max_energy_error}"},
    {.name = "reference",
     .type = PM_KEY_MAPPING,
     .keys = reference_keys,
     .doc = "{displacement: {x, y, z}, fe: DIR}"},
    {0}};
