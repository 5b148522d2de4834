/* pm_scene_vocab: the shared scene vocabulary as key tables (each key once,
 * with its default, range, unit and meaning).  The readers of the keys a
 * table cannot describe alone are in pm_scene_readers.c, the materials in
 * pm_scene_materials.c, the checks across keys in pm_scene_check.c. */
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
static const pm_name contact_names[] = {
    {"frictionless", PM_CONTACT_FRICTIONLESS},
    {"sticking", PM_CONTACT_STICKING},
    {"glued", PM_CONTACT_GLUED},
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
static const pm_name line_search_names[] = {
    {"auto", PM_QS_LS_AUTO},
    {"backtracking", PM_QS_LS_BACKTRACKING},
    {"secant", PM_QS_LS_SECANT},
    {"whole-then-secant", PM_QS_LS_FULL_SECANT},
    {NULL, 0}};
static const pm_name amg_operator_names[] = {{"support", PM_AMG_SUPPORT},
                                             {"support2", PM_AMG_SUPPORT2},
                                             {"tangent", PM_AMG_TANGENT},
                                             {NULL, 0}};
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

static const pm_name face_names[] = {{"xmin", 1u << PM_FACE_XMIN},
                                     {"xmax", 1u << PM_FACE_XMAX},
                                     {"ymin", 1u << PM_FACE_YMIN},
                                     {"ymax", 1u << PM_FACE_YMAX},
                                     {"zmin", 1u << PM_FACE_ZMIN},
                                     {"zmax", 1u << PM_FACE_ZMAX},
                                     {NULL, 0}};
const pm_name pm_mesh_sizes_names[] = {{"scale", PM_MESH_SIZES_SCALE},
                                       {"replace", PM_MESH_SIZES_REPLACE},
                                       {"file", PM_MESH_SIZES_FILE},
                                       {NULL, 0}};
const pm_name pm_output_ranks_names[] = {{"auto", PM_OUTPUT_AUTO},
                                         {"gather", PM_OUTPUT_GATHER},
                                         {"pieces", PM_OUTPUT_PIECES},
                                         {NULL, 0}};
const pm_name pm_refine_to_names[] = {
    {"faces", PM_REFINE_FACES}, {"edges", PM_REFINE_EDGES}, {NULL, 0}};
static const pm_key refine_keys[] = {
    {.name = "near",
     .type = PM_KEY_FLAGS,
     .offset = S(refine.near),
     .min_count = 1,
     .names = face_names,
     .doc = "faces of domain.box the mesh is graded toward (required but "
            "with size_ratio 1 alone, the uniform cloud)"},
    {.name = "size_ratio",
     .type = PM_KEY_NUMBER,
     .offset = S(refine.size_ratio),
     .range = PM_RANGE_GT | PM_RANGE_LE,
     .lo = 0,
     .hi = 1,
     .doc = "element size on those faces over the size far from them (one "
            "of size_ratio, size); mesh_size then stays the point budget: "
            "the far size is set so that the cloud has about the points of "
            "the uniform one at mesh_size, at every rung of a mesh_size "
            "ladder; 1: the uniform cloud"},
    {.name = "size",
     .type = PM_KEY_NUMBER,
     .offset = S(refine.size),
     .range = PM_RANGE_GT,
     .unit = "m",
     .doc = "element size on those faces, at most mesh_size, which is then "
            "the size far from them (one of size, size_ratio)"},
    {.name = "distance",
     .type = PM_KEY_NUMBER,
     .offset = S(refine.distance),
     .range = PM_RANGE_GT,
     .unit = "m",
     .doc = "distance from the nearest of them where the size, growing "
            "linearly, reaches the far size (required but with size_ratio 1); "
            "fixed in metres, so that a mesh_size ladder is a self-similar "
            "family"},
    {.name = "to",
     .type = PM_KEY_ENUM,
     .offset = S(refine.to),
     .def = "faces",
     .names = pm_refine_to_names,
     .doc = "what size and distance are measured to: faces (the named "
            "faces, whole) or edges (the edges bounding them, where a "
            "clamped face meets the free ones: singular lines; the corners "
            "in 2D)"},
    {0}};

static const pm_key discretization_keys[] = {
    {.name = "mesh_size",
     .type = PM_KEY_NUMBER,
     .offset = S(mesh_size),
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .unit = "m",
     .doc = "FPM: gmsh element size; MPM: cell size"},
    {.name = "mesh_sizes",
     .type = PM_KEY_ENUM,
     .offset = S(mesh_sizes),
     .def = "scale",
     .names = pm_mesh_sizes_names,
     .doc = "how the element sizes a gmsh geometry sets itself (.geo point "
            "sizes, size fields, Mesh options) meet mesh_size where gmsh "
            "meshes it: scale (all of them times one factor, so that the "
            "longest edge of the mesh of its curves at the file's own sizes "
            "becomes mesh_size, and at most mesh_size: its grading kept, its "
            "level set by mesh_size; a file without sizes is meshed at "
            "mesh_size), replace (mesh_size everywhere, the file's sizes "
            "ignored) or file (the file's sizes as written; mesh_size then "
            "sizes MPM's grid alone).  A file that holds a mesh (.msh) is "
            "used as it is"},
    {.name = "refine",
     .type = PM_KEY_MAPPING,
     .keys = refine_keys,
     .doc = "FPM box domain: a mesh graded toward faces (singular edges "
            "of clamped faces); unset: uniform at mesh_size.  MPM's grid "
            "stays uniform at mesh_size (noted, not refused)"},
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
     .read = pm_scene_read_region,
     .what = "an expression in x, y, z, or domain",
     .release = pm_scene_release_expr,
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
     .doc = "a gmsh-readable volume (.msh .geo .step .brep, or .stl: a closed "
            "surface), relative to the "
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
     .read = pm_scene_read_fibres,
     .what = "a list of 1 or 2 directions [ax, ay, az]",
     .doc = "fibre directions [[ax, ay, az], ...] (anisotropic models)"},
    {0}};

/* The rigid bodies of boundary: (contact). */
static const pm_key plate_keys[] = {
    {.name = "point",
     .type = PM_KEY_POINT,
     .offset = C(rigid_point),
     .flags = PM_KEY_REQUIRED,
     .unit = "m",
     .doc = "a point of the plane at t = 0"},
    {.name = "normal",
     .type = PM_KEY_POINT,
     .offset = C(rigid_normal),
     .flags = PM_KEY_REQUIRED,
     .doc = "its normal, pointing to the body's side (any length > 0)"},
    {0}};

static const pm_key sphere_bc_keys[] = {{.name = "center",
                                         .type = PM_KEY_POINT,
                                         .offset = C(rigid_point),
                                         .flags = PM_KEY_REQUIRED,
                                         .unit = "m",
                                         .doc = "its centre at t = 0"},
                                        {.name = "radius",
                                         .type = PM_KEY_NUMBER,
                                         .offset = C(rigid_radius),
                                         .flags = PM_KEY_REQUIRED,
                                         .range = PM_RANGE_GT,
                                         .unit = "m",
                                         .doc = "its radius"},
                                        {0}};

static const pm_key bc_keys[] = {
    {.name = "on",
     .type = PM_KEY_STRING,
     .offset = C(surface),
     .doc = "xmin, xmax, ymin, ymax, zmin, zmax, or a named surface (MPM: "
            "the particles at it carry its loads and hold its motion)"},
    {.name = "region",
     .type = PM_KEY_EXPR,
     .offset = C(region),
     .flags = PM_KEY_NO_T,
     .doc = "the boundary where f(x, y, z) > 0 (instead of on); MPM: a "
            "grip, the particles where f > 0 at t = 0, held"},
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
     .doc = "nominal traction at full load (FPM; MPM on a face or a named "
            "surface or edge of a gmsh body: the particles at it carry it)"},
    {.name = "pressure",
     .type = PM_KEY_EXPR,
     .offset = C(pressure),
     .unit = "Pa",
     .doc = "follower pressure at full load, f(x, y, z, t): normal to the "
            "deformed face, pushing on it (FPM: with on or region; MPM: on a "
            "face or a named surface or edge, the particles at it carry it)"},
    {.name = "force",
     .type = PM_KEY_COMPONENTS,
     .offset = C(force),
     .count_offset = C(force_mask),
     .unit = "N",
     .doc = "concentrated force at full load, f(x, y, z, t) at the point: "
            "on the point nearest at, or shared equally among the points "
            "of the facets on or region selects (FPM)"},
    {.name = "at",
     .type = PM_KEY_POINT,
     .offset = C(at),
     .unit = "m",
     .doc = "force: the position whose nearest point carries it (instead "
            "of on or region)"},
    {.name = "curve",
     .type = PM_KEY_CUSTOM,
     .offset = C(curve),
     .read = pm_scene_read_curve,
     .release = pm_scene_release_curve,
     .what = "an expression of t or a .csv table",
     .doc = "load curve multiplying the values (and the ramp): an "
            "expression of t, or FILE.csv of rows t, factor (relative to "
            "the scene; linear between rows, held outside them); default 1"},
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
    {.name = "symmetry",
     .type = PM_KEY_BOOL,
     .offset = C(symmetry),
     .def = "false",
     .doc = "on a face xmin ... zmax: a symmetry plane (the normal "
            "displacement held at 0, the tangential free); the scene is then "
            "the part of a body mirrored about it, and the loaded face's "
            "reaction and the comparisons with a referee are the whole "
            "body's"},
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
    {.name = "plate",
     .type = PM_KEY_MAPPING,
     .keys = plate_keys,
     .doc = "{point, normal}: a rigid plane (instead of on) that pushes the "
            "body where it touches, moved by displacement f(t) (FPM "
            "dynamic relaxation or explicit; method mpm: in the grid's "
            "contact)"},
    {.name = "sphere",
     .type = PM_KEY_MAPPING,
     .keys = sphere_bc_keys,
     .doc = "{center, radius}: a rigid sphere (instead of on), likewise"},
    {.name = "contact",
     .type = PM_KEY_ENUM,
     .offset = C(contact),
     .def = "frictionless",
     .names = contact_names,
     .doc = "plate, sphere: frictionless (normal force only), sticking "
            "(a point that touches is held where it touched, let go when "
            "it comes off) or glued (held in every direction, pulled as "
            "well as pushed: a face tied to it, a grip; method mpm: the "
            "face it starts on; method fpm: the points on it at t = 0 and "
            "those that touch later)"},
    {.name = "penalty",
     .type = PM_KEY_NUMBER,
     .offset = C(contact_penalty),
     .def = "100",
     .range = PM_RANGE_GT,
     .doc = "plate, sphere: contact stiffness factor kappa, the stiffness "
            "of a point kappa E A / h (A its boundary facet area, "
            "h discretization.mesh_size; FPM only: the MPM's grid contact "
            "has no penalty)"},
    {.name = "name",
     .type = PM_KEY_STRING,
     .offset = C(name),
     .doc = "plate, sphere: the label of its reaction columns (default "
            "plate.<index>, sphere.<index>)"},
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
    {.name = "max_load_step",
     .type = PM_KEY_NUMBER,
     .offset = S(time.qs_max_step),
     .def = "0",
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 0,
     .hi = 1,
     .unit = "",
     .doc = "method static (FPM): the largest load step, a fraction of the "
            "load: after a step Newton finished in at most 3 iterations "
            "the next grows by half, up to this (1: the largest step that "
            "converges); 0: steps of 1/load_steps, grown back to it after "
            "cuts (fewer Newton iterations with growth, but more CPU: the "
            "kept factorisation goes stale sooner)"},
    {.name = "relax_after",
     .type = PM_KEY_INTEGER,
     .offset = S(time.qs_relax_after),
     .def = "2",
     .range = PM_RANGE_GE,
     .lo = 0,
     .unit = "",
     .doc = "method static (FPM, one process): after this many halvings of "
            "a load step in a row, and at the smallest step, dynamic "
            "relaxation within the step, then Newton again; 0: never"},
    {.name = "pseudo_transient",
     .type = PM_KEY_INTEGER,
     .offset = S(time.qs_ptc),
     .def = "60",
     .range = PM_RANGE_GE,
     .lo = 0,
     .unit = "",
     .doc = "method static (FPM, one process): where relax_after would "
            "relax a load step, first pseudo-transient continuation "
            "within it: Newton on the tangent plus the relaxation's "
            "masses over a pseudo time step that grows as the residual "
            "falls, at most this many iterations (one linear solve "
            "each), relaxation only if it fails; it passes where the "
            "tangent turns singular or indefinite (a fold); before it, "
            "the tangent's lowest mode at the last converged state: "
            "its eigenvalue negative (past a bifurcation), the "
            "continuation starts off the state along the mode; not "
            "negative (a limit point), arc length follows the path "
            "round the fold first; 0: relaxation alone (the solver "
            "before)"},
    {.name = "line_search",
     .type = PM_KEY_ENUM,
     .offset = S(time.qs_line_search),
     .def = "auto",
     .names = line_search_names,
     .doc = "method static: the line search along each Newton step: "
            "whole-then-secant, Newton's whole step where it lowers the "
            "residual's norm as backtracking's first trial asks, else the "
            "secant; secant, a secant step on the residual's norm from its "
            "values at the half and the whole step (PETSc's l2: its step "
            "seldom exactly the whole one, Newton's last iterations lose "
            "some quadratic order); backtracking, the whole step unless the "
            "residual does not fall enough, then cubic backtracking "
            "(PETSc's bt); auto: whole-then-secant for FPM (F3 200% at 1851 "
            "points in 65 Newton iterations where backtracking takes 131), "
            "backtracking for the implicit MPM"},
    {.name = "relax_first",
     .type = PM_KEY_BOOL,
     .offset = S(time.qs_relax_first),
     .def = "true",
     .doc = "method static (FPM, one process): true: after a load step "
            "that relaxation carried (the continuation before it failed "
            "or is off, or past a snap), the next steps are relaxed first, "
            "then Newton from there, skipping the Newton attempts and the "
            "continuation that failed on the step before (a step whose "
            "start inverts a point before relaxation's first iteration "
            "is cut and relaxed first again); the first step "
            "relaxation does not carry goes the ordinary way, and so do "
            "those after it until relaxation carries one again; and "
            "once relaxation has carried a step, a step that falls back "
            "tries relaxation ahead of the lowest mode, arc length and "
            "the continuation (F4 40% at 1851 points in 13 load steps and "
            "half the time, F4 60% completed); false: every step the "
            "ordinary way (the solver before)"},
    {.name = "follow_fold",
     .type = PM_KEY_BOOL,
     .offset = S(time.qs_follow_fold),
     .def = "false",
     .doc = "method static (FPM, one process): where arc length finds a "
            "limit point (the load turning back along the path: a snap), "
            "false: the step is carried by relaxation at its load from "
            "the last converged state to the stable branch the structure "
            "jumps to (what relaxation in time finds); true: the arc "
            "follows the path round the fold and on to the step's load, "
            "which may end on another branch"},
    {.name = "fallback_seconds",
     .type = PM_KEY_NUMBER,
     .offset = S(time.qs_fallback_cpu),
     .def = "600",
     .range = PM_RANGE_GE,
     .unit = "s",
     .doc = "method static (FPM): the CPU seconds (all threads) each "
            "fallback of a load step (arc length, a continuation, a "
            "relaxation) may take before it stops and the next is "
            "tried; 0: no bound"},
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
            "gmres-ilu, cg-jacobi or cg-gamg (symmetric problems); "
            "mpm-implicit without it: direct up to 30000 unknowns in 3-D "
            "and 100000 in 2-D, gmres-gamg beyond; FPM static without "
            "it: direct up to 8000 free dofs, gmres-gamg beyond; FPM "
            "static with gamg: inexact and reuse_iterations 40 unless "
            "set"},
    {.name = "reuse_iterations",
     .type = PM_KEY_INTEGER,
     .offset = S(time.qs_reuse),
     .def = "10",
     .range = PM_RANGE_GE,
     .lo = 0,
     .unit = "",
     .doc = "method static (FPM): keep the factorisation or preconditioner "
            "over Newton iterations and load steps while the linear solves "
            "it preconditions (GMRES) take at most this many iterations, a "
            "new one after a solve that took more; 0: a new one at every "
            "Newton iteration"},
    {.name = "inexact",
     .type = PM_KEY_BOOL,
     .offset = S(time.qs_inexact),
     .def = "true",
     .doc = "method static (FPM): inexact Newton where the linear solve is "
            "iterative (GMRES with a kept factorisation or with multigrid, "
            "or a matrix-free tangent): each linear solve to the "
            "Eisenstat-Walker tolerance, at most 1e-2, tightening as Newton "
            "converges (the state is Newton's to its tolerance; runs on "
            "different rank counts agree to that, not to round-off); "
            "false: every linear solve to 1e-10 (1e-6 with multigrid), "
            "ranks agree to round-off"},
    {.name = "averaged_coupling",
     .type = PM_KEY_BOOL,
     .offset = S(time.qs_coupled),
     .def = "true",
     .doc = "method static (FPM, fpm.volumetric averaged, direct solver, "
            "one process): factorise the tangent with the averages' "
            "coupling, one unknown more per point (the exact tangent's LU: "
            "GMRES takes an iteration or two; 1.8 times the LU's memory, "
            "so by default only up to 15000 free dofs); false: the LU of "
            "the tangent without it, which preconditions GMRES on the exact "
            "tangent"},
    {.name = "multigrid_operator",
     .type = PM_KEY_ENUM,
     .offset = S(time.qs_amg),
     .def = "tangent",
     .names = amg_operator_names,
     .doc = "method static (FPM, gmres-gamg or cg-gamg, one process): what "
            "multigrid is built on: tangent, the whole assembled tangent "
            "(3 rings with the quadratic jump); support, the tangent's "
            "blocks of each point's own support (its neighbours; a tenth "
            "of the entries and less memory, but at 4036 points 5.6 times "
            "the GMRES iterations and 1.8 times the CPU); support2, those "
            "of its supports' supports; with support and support2 the "
            "exact tangent is the Krylov operator (matrix-free), "
            "preconditioned on the right"},
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
    {.name = "ranks",
     .type = PM_KEY_ENUM,
     .offset = S(output.ranks),
     .def = "auto",
     .names = pm_output_ranks_names,
     .doc = "a run across MPI ranks: auto (pieces where the method writes "
            "them: MPM, explicit or implicit, without membranes or dynamic "
            "relaxation; else gather), gather (each frame and checkpoint "
            "gathered into rank 0 and written whole) or pieces (MPM without "
            "membranes, FPM but its static solve: each rank writes its own "
            "particles or points, over no cells, "
            "results/frame_NNNNNN.piece_RRRR.h5, joined by rank 0's frame "
            "file, which readers put in one-process order; MPM "
            "writes its share of each checkpoint too, checkpoint.pieces/, "
            "joined by rank 0's checkpoint.h5 and resumed on any count of "
            "ranks; no rank holds the whole model, but where checkpoints "
            "are gathered: MPM's dynamic relaxation and FPM with "
            "output.checkpoint; FPM in pieces without output.checkpoint "
            "writes no checkpoint on a signal)"},
    {.name = "checkpoint",
     .type = PM_KEY_MAPPING,
     .keys = checkpoint_keys,
     .doc = "{every, minutes}: the whole state, written atomically (SIGINT "
            "and SIGTERM write one too; across ranks with frames in pieces "
            "each rank writes its share, checkpoint.pieces/, joined by "
            "checkpoint.h5)"},
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
     .read = pm_scene_read_dimension,
     .what = "2 or 3",
     .doc = "3, or 2 for plane strain"},
    {.name = "domain",
     .type = PM_KEY_MAPPING,
     .keys = domain_keys,
     .doc = "{box: {min, max}}; FPM may leave it out where one gmsh volume "
            "(or one box body) is the geometry: its bounds are the box "
            "(faces xmin ... zmax); MPM needs it (the grid, with room for "
            "the bodies' motion)"},
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
     .doc = "[{on | region | plate | sphere, displacement | traction | "
            "...}]"},
    {.name = "gravity",
     .type = PM_KEY_POINT,
     .offset = S(gravity),
     .unit = "m/s^2",
     .doc = "body force per mass (FPM, MPM); not ramped: times body_curve "
            "(FPM)"},
    {.name = "body_force",
     .type = PM_KEY_COMPONENTS,
     .offset = S(body_force),
     .count_offset = S(body_force_mask),
     .unit = "N/kg",
     .doc = "body force per mass f(x, y, z, t) per component, added to "
            "gravity (FPM); not ramped: times body_curve"},
    {.name = "body_curve",
     .type = PM_KEY_CUSTOM,
     .offset = S(body_curve),
     .read = pm_scene_read_curve,
     .release = pm_scene_release_curve,
     .what = "an expression of t or a .csv table",
     .doc = "load curve of gravity and body_force (FPM): an expression of "
            "t, or FILE.csv of rows t, factor; default 1"},
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
