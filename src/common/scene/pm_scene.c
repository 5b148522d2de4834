/* pm_scene: the scene schema (libcyaml), loading with overrides, range
 * checks with file positions, and conversion to pm_scene. */
#include "pm_scene.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_scene_doc.h"

/* ---- raw document, as libcyaml fills it ------------------------------- */

typedef struct {
  char *x, *y, *z; /* expression texts; NULL when absent */
} raw_vec;

typedef struct {
  int type;
  double gamma, p_inf;
} raw_eos;

typedef struct {
  double c0, c1;
} raw_av;

typedef struct {
  char *name;
  int model;
  double density, youngs_modulus, poisson_ratio;
  double viscosity, bulk_viscosity;
  raw_eos eos;
  raw_av artificial_viscosity;
} raw_material;

typedef struct {
  double *min, *max;
  unsigned min_count, max_count;
} raw_box;

typedef struct {
  double *center;
  unsigned center_count;
  double radius;
} raw_sphere;

typedef struct {
  double *base, *axis;
  unsigned base_count, axis_count;
  double radius;
} raw_cylinder;

typedef struct {
  char *material, *region, *mesh;
  raw_box box;
  raw_sphere sphere;
  raw_cylinder cylinder;
  double *velocity;
  unsigned velocity_count;
  double density, pressure;
} raw_body;

typedef struct {
  int on, ramp;
  raw_vec displacement, traction, velocity;
  bool absorbing;
  double ramp_time;
} raw_bc;

typedef struct {
  raw_box box;
} raw_domain;

typedef struct {
  double mesh_size;
} raw_discretization;

typedef struct {
  double penalty;
  int flux;
} raw_fpm;

typedef struct {
  int energy_update;
  double tolerance;
  long max_iterations;
} raw_mpm_fluid;

typedef struct {
  int shape, update;
  double flip;
  long *ppc;
  unsigned ppc_count;
  unsigned null_velocity;
  raw_mpm_fluid fluid;
} raw_mpm;

typedef struct {
  int method;
  double tolerance, damping;
} raw_quasi_static;

typedef struct {
  double end, dt, dt_safety, ramp;
  int dt_rule;
  long max_steps;
  raw_quasi_static quasi_static;
} raw_time;

typedef struct {
  long every;
  unsigned fields;
} raw_output;

typedef struct {
  double min_jacobian, max_energy_error;
} raw_stability;

typedef struct {
  raw_vec displacement;
} raw_reference;

typedef struct {
  char *name;
  int method;
  long dimension;
  raw_domain domain;
  raw_discretization discretization;
  raw_material *materials;
  unsigned materials_count;
  raw_body *bodies;
  unsigned bodies_count;
  raw_bc *boundary;
  unsigned boundary_count;
  raw_fpm fpm;
  raw_mpm mpm;
  double *gravity;
  unsigned gravity_count;
  raw_time time;
  raw_output output;
  raw_stability stability;
  raw_reference reference;
} raw_scene;

/* ---- schema ----------------------------------------------------------- */

#define OPT CYAML_FLAG_OPTIONAL
#define ENUM_FLAGS CYAML_FLAG_STRICT

static const cyaml_strval_t method_names[] = {
    {"fpm", PM_METHOD_FPM},
    {"mpm", PM_METHOD_MPM},
    {"mpm-implicit", PM_METHOD_MPM_IMPLICIT},
};
enum { MODEL_NEO_HOOKEAN, MODEL_LINEAR_ELASTIC, MODEL_FLUID };
static const cyaml_strval_t model_names[] = {
    {"neo-hookean", MODEL_NEO_HOOKEAN},
    {"linear-elastic", MODEL_LINEAR_ELASTIC},
    {"fluid", MODEL_FLUID},
};
static const cyaml_strval_t eos_names[] = {
    {"ideal-gas", PM_EOS_IDEAL_GAS},
    {"stiffened-gas", PM_EOS_STIFFENED_GAS},
};
static const cyaml_strval_t shape_names[] = {
    {"linear", PM_SHAPE_LINEAR},
    {"quadratic", PM_SHAPE_QUADRATIC},
};
static const cyaml_strval_t update_names[] = {
    {"usf", PM_UPDATE_USF},
    {"usl", PM_UPDATE_USL},
    {"musl", PM_UPDATE_MUSL},
};
static const cyaml_strval_t energy_update_names[] = {
    {"iterative", PM_ENERGY_ITERATIVE},
    {"non-iterative", PM_ENERGY_NON_ITERATIVE},
};
static const cyaml_strval_t axis_names[] = {
    {"x", 1u << 0},
    {"y", 1u << 1},
    {"z", 1u << 2},
};
static const cyaml_strval_t face_names[] = {
    {"xmin", PM_FACE_XMIN}, {"xmax", PM_FACE_XMAX}, {"ymin", PM_FACE_YMIN},
    {"ymax", PM_FACE_YMAX}, {"zmin", PM_FACE_ZMIN}, {"zmax", PM_FACE_ZMAX},
};
static const cyaml_strval_t ramp_names[] = {
    {"smooth", PM_RAMP_SMOOTH},
    {"linear", PM_RAMP_LINEAR},
    {"none", PM_RAMP_NONE},
};
static const cyaml_strval_t qs_names[] = {
    {"none", PM_QS_NONE},
    {"dynamic-relaxation", PM_QS_DYNAMIC_RELAXATION},
    {"damping", PM_QS_DAMPING},
};
static const cyaml_strval_t dt_rule_names[] = {
    {"paper", PM_DT_PAPER},
    {"spectral", PM_DT_SPECTRAL},
};
static const cyaml_strval_t field_names[] = {
    {"displacement", PM_FIELD_DISPLACEMENT},
    {"velocity", PM_FIELD_VELOCITY},
    {"stress", PM_FIELD_STRESS},
    {"strain_energy_density", PM_FIELD_STRAIN_ENERGY_DENSITY},
    {"jacobian", PM_FIELD_JACOBIAN},
    {"force", PM_FIELD_FORCE},
};

static const cyaml_schema_value_t number_entry = {
    CYAML_VALUE_FLOAT(CYAML_FLAG_DEFAULT, double),
};

/* Components are strings so that 0, -0.04 and "100*t" all compile alike. */
static const cyaml_schema_field_t vec_fields[] = {
    CYAML_FIELD_STRING_PTR("x", OPT, raw_vec, x, 1, CYAML_UNLIMITED),
    CYAML_FIELD_STRING_PTR("y", OPT, raw_vec, y, 1, CYAML_UNLIMITED),
    CYAML_FIELD_STRING_PTR("z", OPT, raw_vec, z, 1, CYAML_UNLIMITED),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t box_fields[] = {
    CYAML_FIELD_SEQUENCE("min", CYAML_FLAG_POINTER, raw_box, min, &number_entry,
                         2, 3),
    CYAML_FIELD_SEQUENCE("max", CYAML_FLAG_POINTER, raw_box, max, &number_entry,
                         2, 3),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t domain_fields[] = {
    CYAML_FIELD_MAPPING("box", CYAML_FLAG_DEFAULT, raw_domain, box, box_fields),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t discretization_fields[] = {
    CYAML_FIELD_FLOAT("mesh_size", CYAML_FLAG_DEFAULT, raw_discretization,
                      mesh_size),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t eos_fields[] = {
    CYAML_FIELD_ENUM("type", ENUM_FLAGS, raw_eos, type, eos_names,
                     CYAML_ARRAY_LEN(eos_names)),
    CYAML_FIELD_FLOAT("gamma", CYAML_FLAG_DEFAULT, raw_eos, gamma),
    CYAML_FIELD_FLOAT("p_inf", OPT, raw_eos, p_inf),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t av_fields[] = {
    CYAML_FIELD_FLOAT("c0", OPT, raw_av, c0),
    CYAML_FIELD_FLOAT("c1", OPT, raw_av, c1),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t material_fields[] = {
    CYAML_FIELD_STRING_PTR("name", CYAML_FLAG_DEFAULT, raw_material, name, 1,
                           CYAML_UNLIMITED),
    CYAML_FIELD_ENUM("model", ENUM_FLAGS, raw_material, model, model_names,
                     CYAML_ARRAY_LEN(model_names)),
    CYAML_FIELD_FLOAT("density", CYAML_FLAG_DEFAULT, raw_material, density),
    CYAML_FIELD_FLOAT("youngs_modulus", OPT, raw_material, youngs_modulus),
    CYAML_FIELD_FLOAT("poisson_ratio", OPT, raw_material, poisson_ratio),
    CYAML_FIELD_FLOAT("viscosity", OPT, raw_material, viscosity),
    CYAML_FIELD_FLOAT("bulk_viscosity", OPT, raw_material, bulk_viscosity),
    CYAML_FIELD_MAPPING("eos", OPT, raw_material, eos, eos_fields),
    CYAML_FIELD_MAPPING("artificial_viscosity", OPT, raw_material,
                        artificial_viscosity, av_fields),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t material_entry = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, raw_material, material_fields),
};

static const cyaml_schema_field_t sphere_fields[] = {
    CYAML_FIELD_SEQUENCE("center", CYAML_FLAG_POINTER, raw_sphere, center,
                         &number_entry, 2, 3),
    CYAML_FIELD_FLOAT("radius", CYAML_FLAG_DEFAULT, raw_sphere, radius),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t cylinder_fields[] = {
    CYAML_FIELD_SEQUENCE("base", CYAML_FLAG_POINTER, raw_cylinder, base,
                         &number_entry, 3, 3),
    CYAML_FIELD_SEQUENCE("axis", CYAML_FLAG_POINTER, raw_cylinder, axis,
                         &number_entry, 3, 3),
    CYAML_FIELD_FLOAT("radius", CYAML_FLAG_DEFAULT, raw_cylinder, radius),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t body_fields[] = {
    CYAML_FIELD_STRING_PTR("material", CYAML_FLAG_DEFAULT, raw_body, material,
                           1, CYAML_UNLIMITED),
    CYAML_FIELD_STRING_PTR("region", OPT, raw_body, region, 1, CYAML_UNLIMITED),
    CYAML_FIELD_MAPPING("box", OPT, raw_body, box, box_fields),
    CYAML_FIELD_MAPPING("sphere", OPT, raw_body, sphere, sphere_fields),
    CYAML_FIELD_MAPPING("cylinder", OPT, raw_body, cylinder, cylinder_fields),
    CYAML_FIELD_STRING_PTR("mesh", OPT, raw_body, mesh, 1, CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE("velocity", CYAML_FLAG_POINTER | OPT, raw_body,
                         velocity, &number_entry, 2, 3),
    CYAML_FIELD_FLOAT("density", OPT, raw_body, density),
    CYAML_FIELD_FLOAT("pressure", OPT, raw_body, pressure),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t body_entry = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, raw_body, body_fields),
};

static const cyaml_schema_field_t bc_fields[] = {
    CYAML_FIELD_ENUM("on", ENUM_FLAGS, raw_bc, on, face_names,
                     CYAML_ARRAY_LEN(face_names)),
    CYAML_FIELD_MAPPING("displacement", OPT, raw_bc, displacement, vec_fields),
    CYAML_FIELD_MAPPING("traction", OPT, raw_bc, traction, vec_fields),
    CYAML_FIELD_MAPPING("velocity", OPT, raw_bc, velocity, vec_fields),
    CYAML_FIELD_BOOL("absorbing", OPT, raw_bc, absorbing),
    CYAML_FIELD_ENUM("ramp", OPT | ENUM_FLAGS, raw_bc, ramp, ramp_names,
                     CYAML_ARRAY_LEN(ramp_names)),
    CYAML_FIELD_FLOAT("ramp_time", OPT, raw_bc, ramp_time),
    CYAML_FIELD_END,
};
static const cyaml_schema_value_t bc_entry = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, raw_bc, bc_fields),
};

static const cyaml_strval_t flux_names[] = {
    {"iipg", PM_FLUX_IIPG},
    {"sipg", PM_FLUX_SIPG},
};

static const cyaml_schema_field_t fpm_fields[] = {
    CYAML_FIELD_FLOAT("penalty", OPT, raw_fpm, penalty),
    CYAML_FIELD_ENUM("flux", OPT | ENUM_FLAGS, raw_fpm, flux, flux_names,
                     CYAML_ARRAY_LEN(flux_names)),
    CYAML_FIELD_END,
};

static const cyaml_schema_value_t integer_entry = {
    CYAML_VALUE_INT(CYAML_FLAG_DEFAULT, long),
};

static const cyaml_schema_field_t mpm_fluid_fields[] = {
    CYAML_FIELD_ENUM("energy_update", OPT | ENUM_FLAGS, raw_mpm_fluid,
                     energy_update, energy_update_names,
                     CYAML_ARRAY_LEN(energy_update_names)),
    CYAML_FIELD_FLOAT("tolerance", OPT, raw_mpm_fluid, tolerance),
    CYAML_FIELD_INT("max_iterations", OPT, raw_mpm_fluid, max_iterations),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t mpm_fields[] = {
    CYAML_FIELD_ENUM("shape", OPT | ENUM_FLAGS, raw_mpm, shape, shape_names,
                     CYAML_ARRAY_LEN(shape_names)),
    CYAML_FIELD_ENUM("update", OPT | ENUM_FLAGS, raw_mpm, update, update_names,
                     CYAML_ARRAY_LEN(update_names)),
    CYAML_FIELD_FLOAT("flip", OPT, raw_mpm, flip),
    CYAML_FIELD_SEQUENCE("particles_per_cell", CYAML_FLAG_POINTER | OPT,
                         raw_mpm, ppc, &integer_entry, 1, 3),
    CYAML_FIELD_FLAGS("null_velocity", OPT | ENUM_FLAGS, raw_mpm, null_velocity,
                      axis_names, CYAML_ARRAY_LEN(axis_names)),
    CYAML_FIELD_MAPPING("fluid", OPT, raw_mpm, fluid, mpm_fluid_fields),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t quasi_static_fields[] = {
    CYAML_FIELD_ENUM("method", OPT | ENUM_FLAGS, raw_quasi_static, method,
                     qs_names, CYAML_ARRAY_LEN(qs_names)),
    CYAML_FIELD_FLOAT("tolerance", OPT, raw_quasi_static, tolerance),
    CYAML_FIELD_FLOAT("damping", OPT, raw_quasi_static, damping),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t time_fields[] = {
    CYAML_FIELD_FLOAT("end", CYAML_FLAG_DEFAULT, raw_time, end),
    CYAML_FIELD_FLOAT("dt", OPT, raw_time, dt),
    CYAML_FIELD_FLOAT("dt_safety", OPT, raw_time, dt_safety),
    CYAML_FIELD_ENUM("dt_rule", OPT | ENUM_FLAGS, raw_time, dt_rule,
                     dt_rule_names, CYAML_ARRAY_LEN(dt_rule_names)),
    CYAML_FIELD_FLOAT("ramp", OPT, raw_time, ramp),
    CYAML_FIELD_INT("max_steps", OPT, raw_time, max_steps),
    CYAML_FIELD_MAPPING("quasi_static", OPT, raw_time, quasi_static,
                        quasi_static_fields),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t output_fields[] = {
    CYAML_FIELD_INT("every", OPT, raw_output, every),
    CYAML_FIELD_FLAGS("fields", OPT | ENUM_FLAGS, raw_output, fields,
                      field_names, CYAML_ARRAY_LEN(field_names)),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t stability_fields[] = {
    CYAML_FIELD_FLOAT("min_jacobian", OPT, raw_stability, min_jacobian),
    CYAML_FIELD_FLOAT("max_energy_error", OPT, raw_stability, max_energy_error),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t reference_fields[] = {
    CYAML_FIELD_MAPPING("displacement", OPT, raw_reference, displacement,
                        vec_fields),
    CYAML_FIELD_END,
};

static const cyaml_schema_field_t scene_fields[] = {
    CYAML_FIELD_STRING_PTR("name", CYAML_FLAG_DEFAULT, raw_scene, name, 1,
                           CYAML_UNLIMITED),
    CYAML_FIELD_ENUM("method", ENUM_FLAGS, raw_scene, method, method_names,
                     CYAML_ARRAY_LEN(method_names)),
    CYAML_FIELD_INT("dimension", CYAML_FLAG_DEFAULT, raw_scene, dimension),
    CYAML_FIELD_MAPPING("domain", CYAML_FLAG_DEFAULT, raw_scene, domain,
                        domain_fields),
    CYAML_FIELD_MAPPING("discretization", CYAML_FLAG_DEFAULT, raw_scene,
                        discretization, discretization_fields),
    CYAML_FIELD_SEQUENCE("materials", CYAML_FLAG_POINTER, raw_scene, materials,
                         &material_entry, 1, CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE("bodies", CYAML_FLAG_POINTER | OPT, raw_scene, bodies,
                         &body_entry, 1, CYAML_UNLIMITED),
    CYAML_FIELD_SEQUENCE("boundary", CYAML_FLAG_POINTER | OPT, raw_scene,
                         boundary, &bc_entry, 0, CYAML_UNLIMITED),
    CYAML_FIELD_MAPPING("fpm", OPT, raw_scene, fpm, fpm_fields),
    CYAML_FIELD_MAPPING("mpm", OPT, raw_scene, mpm, mpm_fields),
    CYAML_FIELD_SEQUENCE("gravity", CYAML_FLAG_POINTER | OPT, raw_scene,
                         gravity, &number_entry, 2, 3),
    CYAML_FIELD_MAPPING("time", CYAML_FLAG_DEFAULT, raw_scene, time,
                        time_fields),
    CYAML_FIELD_MAPPING("output", OPT, raw_scene, output, output_fields),
    CYAML_FIELD_MAPPING("stability", OPT, raw_scene, stability,
                        stability_fields),
    CYAML_FIELD_MAPPING("reference", OPT, raw_scene, reference,
                        reference_fields),
    CYAML_FIELD_END,
};

static const cyaml_schema_value_t scene_schema = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, raw_scene, scene_fields),
};

/* ---- libcyaml plumbing ------------------------------------------------ */

/* libcyaml's error log, kept for the (unexpected) case where it rejects a
 * tree the schema walk accepted. */
typedef struct {
  char text[1024];
  size_t len;
} cyaml_log_buf;

static void cyaml_log_capture(cyaml_log_t level, void *ctx, const char *fmt,
                              va_list args) {
  cyaml_log_buf *log = ctx;
  (void)level;
  if (log->len + 1 >= sizeof log->text) return;
  int n =
      vsnprintf(log->text + log->len, sizeof log->text - log->len, fmt, args);
  if (n > 0) log->len += (size_t)n;
  if (log->len >= sizeof log->text) log->len = sizeof log->text - 1;
}

static void cyaml_config_init(cyaml_config_t *cfg, cyaml_log_buf *log) {
  memset(cfg, 0, sizeof *cfg);
  cfg->log_fn = cyaml_log_capture;
  cfg->log_ctx = log;
  cfg->mem_fn = cyaml_mem;
  cfg->log_level = CYAML_LOG_ERROR;
  cfg->flags = CYAML_CFG_DEFAULT;
}

/* ---- helpers ---------------------------------------------------------- */

static const char *path_fmt(char buf[static PM_SDOC_PATH], const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static const char *path_fmt(char buf[static PM_SDOC_PATH], const char *fmt,
                            ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, PM_SDOC_PATH, fmt, ap);
  va_end(ap);
  return buf;
}

static bool has(const pm_sdoc *d, const char *path) {
  return pm_sdoc_find(d, path, false) != 0;
}

/* Compile one expression, turning its PM_ERR_EXPR into a located
 * PM_ERR_SCENE.  vars lists the variables it may use. */
static pm_err compile_at(const pm_sdoc *d, const char *path, const char *text,
                         const char *vars, pm_expr **out) {
  char msg[PM_SDOC_WHERE];
  if (pm_expr_create(text, out) != PM_SUCCESS) {
    /* Copy first: the new message is formatted into the same buffer. */
    snprintf(msg, sizeof msg, "%s", pm_error_message());
    return pm_sdoc_fail(d, path, false, "%s", msg);
  }
  for (const char *v = "xyzt"; *v; v++) {
    if (strchr(vars, *v) || !pm_expr_uses(*out, *v)) continue;
    char allowed[16];
    size_t n = 0;
    for (const char *a = vars; *a && n + 4 < sizeof allowed; a++) {
      if (n) {
        allowed[n++] = ',';
        allowed[n++] = ' ';
      }
      allowed[n++] = *a;
    }
    allowed[n] = '\0';
    pm_expr_destroy(*out);
    *out = NULL;
    return pm_sdoc_fail(d, path, false,
                        "invalid expression \"%s\": variable %c is not "
                        "allowed here (allowed: %s)",
                        text, *v, allowed);
  }
  return PM_SUCCESS;
}

/* Compile the components of a vector {x, y, z} at path into out[3] and
 * mask; a z component is refused in 2D. */
static pm_err compile_vec(const pm_sdoc *d, const char *path, const raw_vec *v,
                          int dim, const char *vars, pm_expr *out[3],
                          unsigned *mask) {
  const char *texts[3] = {v->x, v->y, v->z};
  char sub[PM_SDOC_PATH];
  for (int c = 0; c < 3; c++) {
    if (!texts[c]) continue;
    path_fmt(sub, "%s.%c", path, "xyz"[c]);
    if (c >= dim)
      return pm_sdoc_fail(d, sub, true,
                          "expected components x, y (dimension 2), got z");
    PM_CALL(compile_at(d, sub, texts[c], vars, &out[c]));
    *mask |= 1u << c;
  }
  return PM_SUCCESS;
}

/* Each check_* fails with "WHERE: expected ..., got VALUE" when the key at
 * path is present and out of range. */
static pm_err check_positive(const pm_sdoc *d, const char *path, double v) {
  if (has(d, path) && !(v > 0))
    return pm_sdoc_expected(d, path, "a number > 0");
  return PM_SUCCESS;
}

static pm_err check_nonneg(const pm_sdoc *d, const char *path, double v) {
  if (has(d, path) && !(v >= 0))
    return pm_sdoc_expected(d, path, "a number >= 0");
  return PM_SUCCESS;
}

/* ---- conversion ------------------------------------------------------- */

static pm_err build_domain(pm_scene *s, const pm_sdoc *d, const raw_scene *r) {
  char p[PM_SDOC_PATH], what[128];
  if (r->dimension != 2 && r->dimension != 3)
    return pm_sdoc_expected(d, "dimension", "2 or 3");
  s->dimension = (int)r->dimension;
  if (r->domain.box.min_count != (unsigned)s->dimension)
    return pm_sdoc_fail(d, "domain.box.min", false,
                        "expected %d numbers (dimension %d), got %u",
                        s->dimension, s->dimension, r->domain.box.min_count);
  if (r->domain.box.max_count != (unsigned)s->dimension)
    return pm_sdoc_fail(d, "domain.box.max", false,
                        "expected %d numbers (dimension %d), got %u",
                        s->dimension, s->dimension, r->domain.box.max_count);
  for (int c = 0; c < s->dimension; c++) {
    s->box_min[c] = r->domain.box.min[c];
    s->box_max[c] = r->domain.box.max[c];
    if (!(s->box_max[c] > s->box_min[c])) {
      snprintf(what, sizeof what, "a number > domain.box.min.%d (%g)", c,
               s->box_min[c]);
      return pm_sdoc_expected(d, path_fmt(p, "domain.box.max.%d", c), what);
    }
  }
  s->mesh_size = r->discretization.mesh_size;
  PM_CALL(check_positive(d, "discretization.mesh_size", s->mesh_size));
  if (s->method != PM_METHOD_FPM)
    for (int c = 0; c < s->dimension; c++) {
      /* MPM: the box faces are grid planes, where conditions act. */
      double cells = (s->box_max[c] - s->box_min[c]) / s->mesh_size;
      if (fabs(cells - round(cells)) > 1e-6 * cells) {
        snprintf(what, sizeof what,
                 "a cell size that divides domain.box (%g m along %c: %.4g "
                 "cells)",
                 s->box_max[c] - s->box_min[c], "xyz"[c], cells);
        return pm_sdoc_expected(d, "discretization.mesh_size", what);
      }
    }
  return PM_SUCCESS;
}

/* A material of model fluid: an equation of state and viscosities. */
static pm_err build_fluid(const pm_scene *s, const pm_sdoc *d, int i,
                          const raw_material *m, pm_scene_material *out) {
  char p[PM_SDOC_PATH];
  if (s->method == PM_METHOD_FPM)
    return pm_sdoc_expected(d, path_fmt(p, "materials.%d.model", i),
                            "a solid model (neo-hookean, linear-elastic) for "
                            "method fpm");
  static const char *const solid_keys[] = {"youngs_modulus", "poisson_ratio"};
  for (int k = 0; k < 2; k++)
    if (has(d, path_fmt(p, "materials.%d.%s", i, solid_keys[k])))
      return pm_sdoc_fail(d, p, true,
                          "expected a key of model fluid (density, viscosity, "
                          "bulk_viscosity, eos, artificial_viscosity), got %s",
                          solid_keys[k]);
  if (!has(d, path_fmt(p, "materials.%d.eos", i)))
    return pm_sdoc_fail(d, path_fmt(p, "materials.%d", i), false,
                        "missing required key eos (model fluid needs an "
                        "equation of state: {type: ideal-gas | "
                        "stiffened-gas, gamma: > 1, p_inf: Pa})");
  out->fluid = true;
  pm_fluid *f = &out->fluid_props;
  f->eos = (pm_eos)m->eos.type;
  f->gamma = m->eos.gamma;
  f->p_inf = m->eos.p_inf;
  f->density = m->density;
  f->viscosity = m->viscosity;
  f->bulk_viscosity = m->bulk_viscosity;
  if (!(f->gamma > 1))
    return pm_sdoc_expected(d, path_fmt(p, "materials.%d.eos.gamma", i),
                            "a number > 1");
  path_fmt(p, "materials.%d.eos.p_inf", i);
  if (f->eos == PM_EOS_IDEAL_GAS && has(d, p))
    return pm_sdoc_fail(d, p, true,
                        "expected no p_inf for type ideal-gas (use "
                        "stiffened-gas), got p_inf");
  PM_CALL(check_nonneg(d, p, f->p_inf));
  PM_CALL(
      check_nonneg(d, path_fmt(p, "materials.%d.viscosity", i), f->viscosity));
  /* lambda >= -2 mu / 3: a non-negative bulk viscosity lambda + 2 mu / 3
   * (Stokes' condition is lambda = -2 mu / 3). */
  if (!(f->bulk_viscosity >= -2.0 / 3.0 * f->viscosity * (1 + 1e-12)))
    return pm_sdoc_expected(d, path_fmt(p, "materials.%d.bulk_viscosity", i),
                            "a number >= -2/3 viscosity (Stokes: -2/3 "
                            "viscosity)");
  PM_CALL(pm_material_begin(&out->mat, "fluid", m->density));
  out->mat.fluid = *f;
  if (!has(d, path_fmt(p, "materials.%d.eos.p_inf", i)))
    out->mat.fluid.p_inf = NAN;
  const char *key;
  return out->mat.model->init(&out->mat, &key);
}

static pm_err build_materials(pm_scene *s, const pm_sdoc *d,
                              const raw_scene *r) {
  char p[PM_SDOC_PATH];
  PM_CALL(PM_ALLOC(s->materials, r->materials_count, "scene materials"));
  s->n_materials = (int)r->materials_count;
  for (int i = 0; i < s->n_materials; i++) {
    const raw_material *m = &r->materials[i];
    pm_scene_material *out = &s->materials[i];
    for (int j = 0; j < i; j++)
      if (strcmp(s->materials[j].name, m->name) == 0)
        return pm_sdoc_expected(d, path_fmt(p, "materials.%d.name", i),
                                "a name not used by an earlier material");
    out->name = strdup(m->name);
    PM_CHECK(out->name, PM_ERR_MEMORY, "cannot copy material name");
    out->mark =
        pm_sdoc_mark(d, pm_sdoc_find(d, path_fmt(p, "materials.%d", i), false));
    PM_CALL(
        check_positive(d, path_fmt(p, "materials.%d.density", i), m->density));
    PM_CALL(check_nonneg(d,
                         path_fmt(p, "materials.%d.artificial_viscosity.c0", i),
                         m->artificial_viscosity.c0));
    PM_CALL(check_nonneg(d,
                         path_fmt(p, "materials.%d.artificial_viscosity.c1", i),
                         m->artificial_viscosity.c1));
    out->av_c0 = m->artificial_viscosity.c0;
    out->av_c1 = m->artificial_viscosity.c1;
    if (m->model == MODEL_FLUID) {
      PM_CALL(build_fluid(s, d, i, m, out));
      continue;
    }
    static const char *const fluid_keys[] = {"viscosity", "bulk_viscosity",
                                             "eos"};
    for (int k = 0; k < 3; k++)
      if (has(d, path_fmt(p, "materials.%d.%s", i, fluid_keys[k])))
        return pm_sdoc_fail(d, p, true,
                            "expected a key of a solid model (%s), got %s "
                            "(a key of model fluid)",
                            model_names[m->model].str, fluid_keys[k]);
    static const char *const solid_keys[] = {"youngs_modulus", "poisson_ratio"};
    for (int k = 0; k < 2; k++)
      if (!has(d, path_fmt(p, "materials.%d.%s", i, solid_keys[k])))
        return pm_sdoc_fail(d, path_fmt(p, "materials.%d", i), false,
                            "missing required key %s (model %s)", solid_keys[k],
                            model_names[m->model].str);
    PM_CALL(check_positive(d, path_fmt(p, "materials.%d.youngs_modulus", i),
                           m->youngs_modulus));
    if (!(m->poisson_ratio > -1 && m->poisson_ratio < 0.5))
      return pm_sdoc_expected(d, path_fmt(p, "materials.%d.poisson_ratio", i),
                              "a number in (-1, 0.5)");
    if (pm_material_elastic(&out->mat, model_names[m->model].str, m->density,
                            m->youngs_modulus,
                            m->poisson_ratio) != PM_SUCCESS) {
      char msg[PM_SDOC_WHERE];
      snprintf(msg, sizeof msg, "%s", pm_error_message());
      return pm_sdoc_fail(d, path_fmt(p, "materials.%d", i), false, "%s", msg);
    }
  }
  return PM_SUCCESS;
}

/* Read a coordinate list of the scene's dimension at path. */
static pm_err read_point(const pm_sdoc *d, const char *path, int dim,
                         const double *v, unsigned count, double out[3]) {
  if (count != (unsigned)dim)
    return pm_sdoc_fail(d, path, false,
                        "expected %d numbers (dimension %d), got %u", dim, dim,
                        count);
  for (int c = 0; c < dim; c++) out[c] = v[c];
  return PM_SUCCESS;
}

/* The body's shape: exactly one of region, box, sphere, cylinder, mesh
 * (none: the whole domain). */
static pm_err build_body_shape(pm_scene *s, const pm_sdoc *d, int i,
                               const raw_body *b, pm_scene_body *body) {
  char p[PM_SDOC_PATH];
  static const char *const keys[] = {"region", "box", "sphere", "cylinder",
                                     "mesh"};
  int given = -1;
  for (int k = 0; k < 5; k++) {
    if (!has(d, path_fmt(p, "bodies.%d.%s", i, keys[k]))) continue;
    if (given >= 0)
      return pm_sdoc_fail(d, p, true,
                          "expected one shape (region, box, sphere, cylinder "
                          "or mesh), got %s and %s",
                          keys[given], keys[k]);
    given = k;
  }
  body->shape = PM_BODY_DOMAIN;
  if (given < 0) return PM_SUCCESS;
  if (given > 0 && s->method == PM_METHOD_FPM)
    return pm_sdoc_fail(d, path_fmt(p, "bodies.%d.%s", i, keys[given]), true,
                        "expected region (method fpm meshes the domain box), "
                        "got %s",
                        keys[given]);
  switch (given) {
  case 0:
    if (strcmp(b->region, "domain") == 0) return PM_SUCCESS;
    body->shape = PM_BODY_REGION;
    return compile_at(d, path_fmt(p, "bodies.%d.region", i), b->region, "xyz",
                      &body->region);
  case 1:
    body->shape = PM_BODY_BOX;
    PM_CALL(read_point(d, path_fmt(p, "bodies.%d.box.min", i), s->dimension,
                       b->box.min, b->box.min_count, body->a));
    PM_CALL(read_point(d, path_fmt(p, "bodies.%d.box.max", i), s->dimension,
                       b->box.max, b->box.max_count, body->b));
    for (int c = 0; c < s->dimension; c++)
      if (!(body->b[c] > body->a[c]))
        return pm_sdoc_expected(d, path_fmt(p, "bodies.%d.box.max.%d", i, c),
                                "a number > the box's min");
    return PM_SUCCESS;
  case 2:
    body->shape = PM_BODY_SPHERE;
    PM_CALL(read_point(d, path_fmt(p, "bodies.%d.sphere.center", i),
                       s->dimension, b->sphere.center, b->sphere.center_count,
                       body->a));
    body->radius = b->sphere.radius;
    return check_positive(d, path_fmt(p, "bodies.%d.sphere.radius", i),
                          b->sphere.radius);
  case 3:
    body->shape = PM_BODY_CYLINDER;
    if (s->dimension != 3)
      return pm_sdoc_fail(d, path_fmt(p, "bodies.%d.cylinder", i), true,
                          "expected box, sphere, region or mesh (dimension "
                          "2), got cylinder");
    for (int c = 0; c < 3; c++) {
      body->a[c] = b->cylinder.base[c];
      body->b[c] = b->cylinder.axis[c];
    }
    if (!(pm_v_norm(body->b) > 0))
      return pm_sdoc_expected(d, path_fmt(p, "bodies.%d.cylinder.axis", i),
                              "a non-zero vector (base to top face)");
    body->radius = b->cylinder.radius;
    return check_positive(d, path_fmt(p, "bodies.%d.cylinder.radius", i),
                          b->cylinder.radius);
  default: {
    body->shape = PM_BODY_MESH;
    /* Relative to the scene's folder. */
    const char *slash = strrchr(s->path, '/');
    size_t dir = (b->mesh[0] != '/' && slash) ? (size_t)(slash - s->path) : 0;
    size_t len = dir + 1 + strlen(b->mesh) + 1;
    body->mesh = malloc(len);
    PM_CHECK(body->mesh, PM_ERR_MEMORY, "cannot copy a mesh path");
    if (dir)
      snprintf(body->mesh, len, "%.*s/%s", (int)dir, s->path, b->mesh);
    else
      snprintf(body->mesh, len, "%s", b->mesh);
    return PM_SUCCESS;
  }
  }
}

static pm_err build_bodies(pm_scene *s, const pm_sdoc *d, const raw_scene *r) {
  char p[PM_SDOC_PATH], what[PM_SDOC_WHERE];
  int n = r->bodies_count > 0 ? (int)r->bodies_count : 1;
  PM_CALL(PM_ALLOC(s->bodies, n, "scene bodies"));
  s->n_bodies = n;
  if (r->bodies_count == 0) {
    /* materials[0] over the whole domain. */
    const pm_scene_material *mat = &s->materials[0];
    if (mat->fluid)
      return pm_sdoc_fail(d, "materials.0", false,
                          "expected bodies: a fluid needs a body with its "
                          "initial pressure (bodies: [{material: %s, "
                          "pressure: ...}])",
                          mat->name);
    s->bodies[0].density =
        mat->fluid ? mat->fluid_props.density : mat->mat.density;
    return PM_SUCCESS;
  }
  for (int i = 0; i < n; i++) {
    const raw_body *b = &r->bodies[i];
    int m = 0;
    while (m < s->n_materials && strcmp(s->materials[m].name, b->material)) m++;
    if (m == s->n_materials) {
      size_t used = (size_t)snprintf(what, sizeof what, "a material name (");
      for (int j = 0; j < s->n_materials && used < sizeof what; j++)
        used += (size_t)snprintf(what + used, sizeof what - used, "%s%s",
                                 j ? ", " : "", s->materials[j].name);
      if (used < sizeof what) snprintf(what + used, sizeof what - used, ")");
      return pm_sdoc_expected(d, path_fmt(p, "bodies.%d.material", i), what);
    }
    pm_scene_body *body = &s->bodies[i];
    body->material = m;
    body->mark =
        pm_sdoc_mark(d, pm_sdoc_find(d, path_fmt(p, "bodies.%d", i), false));
    PM_CALL(build_body_shape(s, d, i, b, body));
    const pm_scene_material *mat = &s->materials[m];
    body->density = mat->fluid ? mat->fluid_props.density : mat->mat.density;
    if (has(d, path_fmt(p, "bodies.%d.density", i))) {
      if (s->method == PM_METHOD_FPM)
        return pm_sdoc_fail(d, p, true,
                            "expected no body density for method fpm (set "
                            "the material's), got density");
      PM_CALL(check_positive(d, p, b->density));
      body->density = b->density;
    }
    if (has(d, path_fmt(p, "bodies.%d.pressure", i))) {
      if (!mat->fluid)
        return pm_sdoc_fail(d, p, true,
                            "expected a key of a solid body (material, shape, "
                            "velocity, density), got pressure (material %s "
                            "is not a fluid)",
                            mat->name);
      body->pressure = b->pressure;
      if (!(b->pressure + mat->fluid_props.p_inf > 0))
        return pm_sdoc_expected(d, p, "a pressure > -p_inf of the material");
    } else if (mat->fluid)
      return pm_sdoc_fail(d, path_fmt(p, "bodies.%d", i), false,
                          "missing required key pressure (a body of fluid "
                          "%s needs its initial pressure, Pa)",
                          mat->name);
    if (b->velocity) {
      path_fmt(p, "bodies.%d.velocity", i);
      if (s->method == PM_METHOD_FPM)
        return pm_sdoc_fail(d, p, true,
                            "expected no initial velocity for "
                            "method fpm, got velocity");
      if (b->velocity_count != (unsigned)s->dimension)
        return pm_sdoc_fail(d, p, false,
                            "expected %d numbers (dimension %d), got %u",
                            s->dimension, s->dimension, b->velocity_count);
      for (unsigned c = 0; c < b->velocity_count; c++)
        body->velocity[c] = b->velocity[c];
    }
  }
  return PM_SUCCESS;
}

static pm_err build_bcs(pm_scene *s, const pm_sdoc *d, const raw_scene *r) {
  char p[PM_SDOC_PATH], q[PM_SDOC_PATH];
  PM_CALL(PM_ALLOC(s->bcs, r->boundary_count, "scene boundary conditions"));
  s->n_bcs = (int)r->boundary_count;
  for (int i = 0; i < s->n_bcs; i++) {
    const raw_bc *b = &r->boundary[i];
    pm_scene_bc *bc = &s->bcs[i];
    bc->face = (pm_face)b->on;
    bc->mark =
        pm_sdoc_mark(d, pm_sdoc_find(d, path_fmt(p, "boundary.%d", i), false));
    if (s->dimension == 2 && bc->face >= PM_FACE_ZMIN)
      return pm_sdoc_expected(d, path_fmt(p, "boundary.%d.on", i),
                              "one of xmin, xmax, ymin, ymax (dimension 2)");
    PM_CALL(compile_vec(d, path_fmt(p, "boundary.%d.displacement", i),
                        &b->displacement, s->dimension, "xyzt", bc->disp,
                        &bc->disp_mask));
    PM_CALL(compile_vec(d, path_fmt(p, "boundary.%d.traction", i), &b->traction,
                        s->dimension, "xyzt", bc->traction,
                        &bc->traction_mask));
    PM_CALL(compile_vec(d, path_fmt(p, "boundary.%d.velocity", i), &b->velocity,
                        s->dimension, "xyzt", bc->velocity,
                        &bc->velocity_mask));
    bc->absorbing = b->absorbing;
    const char *grid_only = bc->velocity_mask ? "velocity"
                            : bc->absorbing   ? "absorbing"
                                              : NULL;
    if (grid_only && s->method == PM_METHOD_FPM)
      return pm_sdoc_fail(d, path_fmt(p, "boundary.%d.%s", i, grid_only), true,
                          "expected displacement or traction (method fpm), "
                          "got %s",
                          grid_only);
    if (bc->traction_mask && s->method == PM_METHOD_MPM)
      return pm_sdoc_fail(d, path_fmt(p, "boundary.%d.traction", i), true,
                          "expected displacement, velocity or absorbing "
                          "(method mpm), got traction");
    if (!bc->disp_mask && !bc->traction_mask && !bc->velocity_mask &&
        !bc->absorbing)
      return pm_sdoc_fail(d, path_fmt(p, "boundary.%d", i), false,
                          "expected a displacement, traction or velocity "
                          "component, or absorbing: true, got none");
    unsigned dv = bc->disp_mask & bc->velocity_mask;
    for (int c = 0; c < 3; c++)
      if (dv & (1u << c))
        return pm_sdoc_fail(
            d, path_fmt(q, "boundary.%d.velocity.%c", i, "xyz"[c]), true,
            "expected a component not prescribed as displacement, got %c "
            "(also in boundary.%d.displacement)",
            "xyz"[c], i);
    unsigned both = bc->disp_mask & bc->traction_mask;
    for (int c = 0; c < 3; c++)
      if (both & (1u << c))
        return pm_sdoc_fail(
            d, path_fmt(q, "boundary.%d.traction.%c", i, "xyz"[c]), true,
            "expected a component not prescribed as displacement, got %c "
            "(also in boundary.%d.displacement)",
            "xyz"[c], i);
    bc->ramp = has(d, path_fmt(p, "boundary.%d.ramp", i)) ? (pm_ramp)b->ramp
                                                          : PM_RAMP_SMOOTH;
    path_fmt(p, "boundary.%d.ramp_time", i);
    PM_CALL(check_positive(d, p, b->ramp_time));
    bc->ramp_time = has(d, p) ? b->ramp_time : s->time.ramp;
  }
  return PM_SUCCESS;
}

static pm_err build_mpm(pm_scene *s, const pm_sdoc *d, const raw_scene *r) {
  char p[PM_SDOC_PATH];
  const raw_mpm *m = &r->mpm;
  /* Both sections may be present: one scene runs with either method, and
   * each method reads its own. */
  s->mpm.shape = has(d, "mpm.shape") ? (pm_shape)m->shape : PM_SHAPE_QUADRATIC;
  s->mpm.update = has(d, "mpm.update") ? (pm_update)m->update : PM_UPDATE_MUSL;
  s->mpm.flip = has(d, "mpm.flip") ? m->flip : 1.0;
  if (!(s->mpm.flip >= 0 && s->mpm.flip <= 1))
    return pm_sdoc_expected(d, "mpm.flip", "a number in [0, 1]");
  for (int c = 0; c < 3; c++) s->mpm.ppc[c] = c < s->dimension ? 2 : 1;
  if (m->ppc) {
    if (m->ppc_count != 1 && m->ppc_count != (unsigned)s->dimension)
      return pm_sdoc_fail(d, "mpm.particles_per_cell", false,
                          "expected 1 or %d integers (dimension %d), got %u",
                          s->dimension, s->dimension, m->ppc_count);
    for (int c = 0; c < s->dimension; c++) {
      long n = m->ppc[m->ppc_count == 1 ? 0 : c];
      if (n < 1 || n > 64)
        return pm_sdoc_expected(
            d,
            path_fmt(p, "mpm.particles_per_cell.%d", m->ppc_count == 1 ? 0 : c),
            "an integer in [1, 64]");
      s->mpm.ppc[c] = (int)n;
    }
  }
  s->mpm.null_velocity = m->null_velocity;
  if (s->dimension == 2 && (m->null_velocity & 4u))
    return pm_sdoc_fail(d, "mpm.null_velocity", false,
                        "expected a list of x, y (dimension 2), got z");
  s->mpm.energy_update = has(d, "mpm.fluid.energy_update")
                             ? (pm_energy_update)m->fluid.energy_update
                             : PM_ENERGY_ITERATIVE;
  s->mpm.energy_tolerance =
      has(d, "mpm.fluid.tolerance") ? m->fluid.tolerance : 1e-10;
  PM_CALL(check_positive(d, "mpm.fluid.tolerance", m->fluid.tolerance));
  s->mpm.max_iterations =
      has(d, "mpm.fluid.max_iterations") ? (int)m->fluid.max_iterations : 50;
  if (!(s->mpm.max_iterations >= 1 && s->mpm.max_iterations <= 10000))
    return pm_sdoc_expected(d, "mpm.fluid.max_iterations",
                            "an integer in [1, 10000]");
  if (r->gravity) {
    if (s->method == PM_METHOD_FPM)
      return pm_sdoc_fail(d, "gravity", true,
                          "expected no gravity for method fpm, got gravity");
    PM_CALL(read_point(d, "gravity", s->dimension, r->gravity, r->gravity_count,
                       s->gravity));
    s->has_gravity = pm_v_norm(s->gravity) > 0;
  }
  return PM_SUCCESS;
}

static pm_err build_time(pm_scene *s, const pm_sdoc *d, const raw_scene *r) {
  const raw_time *t = &r->time;
  const raw_quasi_static *qs = &t->quasi_static;
  s->fpm.penalty = has(d, "fpm.penalty") ? r->fpm.penalty : 20.0;
  PM_CALL(check_nonneg(d, "fpm.penalty", s->fpm.penalty));
  s->fpm.flux = has(d, "fpm.flux") ? (pm_flux)r->fpm.flux : PM_FLUX_IIPG;
  PM_CALL(build_mpm(s, d, r));

  s->time.end = t->end;
  PM_CALL(check_positive(d, "time.end", t->end));
  s->time.dt = t->dt;
  PM_CALL(check_nonneg(d, "time.dt", t->dt));
  s->time.dt_safety = has(d, "time.dt_safety")     ? t->dt_safety
                      : s->method == PM_METHOD_FPM ? 0.9
                                                   : 0.5;
  if (!(s->time.dt_safety > 0 && s->time.dt_safety <= 1))
    return pm_sdoc_expected(d, "time.dt_safety", "a number in (0, 1]");
  s->time.dt_rule =
      has(d, "time.dt_rule") ? (pm_dt_rule)t->dt_rule : PM_DT_PAPER;
  s->time.ramp = has(d, "time.ramp") ? t->ramp : t->end / 2;
  PM_CALL(check_positive(d, "time.ramp", t->ramp));
  s->time.max_steps = t->max_steps;
  if (t->max_steps < 0)
    return pm_sdoc_expected(d, "time.max_steps", "an integer >= 0");

  s->time.qs = has(d, "time.quasi_static.method") ? (pm_qs_method)qs->method
                                                  : PM_QS_NONE;
  s->time.qs_tolerance =
      has(d, "time.quasi_static.tolerance") ? qs->tolerance : 1e-8;
  PM_CALL(check_positive(d, "time.quasi_static.tolerance", qs->tolerance));
  s->time.qs_damping = qs->damping;
  PM_CALL(check_nonneg(d, "time.quasi_static.damping", qs->damping));
  const raw_stability *st = &r->stability;
  s->stability.min_jacobian =
      has(d, "stability.min_jacobian") ? st->min_jacobian : 0.0;
  if (!(s->stability.min_jacobian >= 0 && s->stability.min_jacobian < 1))
    return pm_sdoc_expected(d, "stability.min_jacobian", "a number in [0, 1)");
  if (s->method != PM_METHOD_FPM && has(d, "stability.max_energy_error"))
    return pm_sdoc_fail(d, "stability.max_energy_error", true,
                        "expected min_jacobian only for method %s (its "
                        "transfers dissipate energy by design: the balance "
                        "is reported, not bounded), got max_energy_error",
                        pm_method_name(s->method));
  s->stability.max_energy_error =
      has(d, "stability.max_energy_error") ? st->max_energy_error : 0.1;
  PM_CALL(
      check_positive(d, "stability.max_energy_error", st->max_energy_error));
  if (s->time.qs == PM_QS_DAMPING && !(qs->damping > 0)) {
    if (has(d, "time.quasi_static.damping"))
      return pm_sdoc_expected(d, "time.quasi_static.damping",
                              "a number > 0 (method damping)");
    return pm_sdoc_fail(d, "time.quasi_static.damping", false,
                        "missing required key (method damping needs a "
                        "damping rate > 0, 1/s)");
  }
  return PM_SUCCESS;
}

static pm_err build_output(pm_scene *s, const pm_sdoc *d, const raw_scene *r) {
  s->output.every = has(d, "output.every") ? r->output.every : 100;
  if (!(s->output.every > 0))
    return pm_sdoc_expected(d, "output.every", "an integer > 0");
  s->output.fields =
      PM_FIELD_DISPLACEMENT | PM_FIELD_STRESS | PM_FIELD_STRAIN_ENERGY_DENSITY;
  if (has(d, "output.fields")) {
    if (!r->output.fields)
      return pm_sdoc_expected(d, "output.fields",
                              "a list of at least one field");
    s->output.fields = r->output.fields;
  }
  PM_CALL(compile_vec(d, "reference.displacement", &r->reference.displacement,
                      s->dimension, "xyzt", s->reference, &s->reference_mask));
  return PM_SUCCESS;
}

static pm_err build_scene(pm_scene *s, const pm_sdoc *d, const raw_scene *r) {
  s->name = strdup(r->name);
  PM_CHECK(s->name, PM_ERR_MEMORY, "cannot copy scene name");
  s->method = (pm_method)r->method;
  PM_CALL(build_domain(s, d, r));
  PM_CALL(build_materials(s, d, r));
  PM_CALL(build_bodies(s, d, r));
  /* Boundary ramps default to time.ramp, so time goes first. */
  PM_CALL(build_time(s, d, r));
  PM_CALL(build_bcs(s, d, r));
  PM_CALL(build_output(s, d, r));
  return PM_SUCCESS;
}

/* ---- public ----------------------------------------------------------- */

static pm_err read_text(const char *path, char **text, size_t *len) {
  pm_err ret = PM_SUCCESS;
  FILE *f = fopen(path, "rb");
  char *buf = NULL;
  size_t cap = 0, n = 0;
  *text = NULL;
  *len = 0;
  PM_ENSURE(f, PM_ERR_IO, "cannot open scene %s: %s", path, strerror(errno));
  for (;;) {
    if (n + 4096 + 1 > cap) {
      cap = 2 * (n + 4096 + 1);
      char *grown = realloc(buf, cap);
      PM_ENSURE(grown, PM_ERR_MEMORY, "cannot read scene %s: out of memory",
                path);
      buf = grown;
    }
    size_t got = fread(buf + n, 1, cap - n - 1, f);
    n += got;
    if (got == 0) break;
  }
  PM_ENSURE(!ferror(f), PM_ERR_IO, "cannot read scene %s: %s", path,
            strerror(errno));
  buf[n] = '\0';
  *text = buf;
  *len = n;
  buf = NULL;
done:
  free(buf);
  if (f) fclose(f);
  return ret;
}

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

pm_err pm_scene_load(const char *path, int n_overrides,
                     const char *const *overrides, pm_scene **out) {
  pm_err ret = PM_SUCCESS;
  pm_scene *s = NULL;
  pm_sdoc doc;
  raw_scene *raw = NULL;
  char *emitted = NULL;
  size_t len = 0;
  cyaml_config_t cfg;
  cyaml_log_buf log = {.len = 0};
  memset(&doc, 0, sizeof doc);
  cyaml_config_init(&cfg, &log);
  PM_ENSURE(out, PM_ERR_ARG, "pm_scene_load: out is NULL");
  *out = NULL;
  PM_ENSURE(path, PM_ERR_ARG, "pm_scene_load: no scene path");
  PM_ENSURE(n_overrides == 0 || overrides, PM_ERR_ARG,
            "pm_scene_load: %d overrides but no array", n_overrides);
  PM_TRY(PM_ALLOC(s, 1, "scene"));
  s->path = strdup(path);
  PM_ENSURE(s->path, PM_ERR_MEMORY, "cannot copy scene path");
  PM_TRY(read_text(path, &s->text, &len));
  PM_TRY(pm_sdoc_parse(&doc, s->path, s->text, len));
  PM_TRY(pm_sdoc_apply_overrides(&doc, &scene_schema, n_overrides, overrides));
  PM_TRY(pm_sdoc_validate(&doc, &scene_schema));
  PM_TRY(pm_sdoc_emit(&doc, &emitted, &len));
  cyaml_err_t cerr =
      cyaml_load_data((const uint8_t *)emitted, len, &cfg, &scene_schema,
                      (cyaml_data_t **)&raw, NULL);
  PM_ENSURE(cerr == CYAML_OK, PM_ERR_SCENE, "%s: %s: %s", path,
            cyaml_strerror(cerr), log.text);
  PM_TRY(build_scene(s, &doc, raw));
  PM_TRY(keep_overrides(s, n_overrides, overrides));
  *out = s;
  s = NULL;
done:
  if (raw) cyaml_free(&cfg, &scene_schema, raw, 0);
  free(emitted);
  pm_sdoc_free(&doc);
  pm_scene_destroy(s);
  return ret;
}

void pm_scene_destroy(pm_scene *s) {
  if (!s) return;
  for (int i = 0; i < s->n_materials; i++) free(s->materials[i].name);
  for (int i = 0; i < s->n_bodies; i++) {
    pm_expr_destroy(s->bodies[i].region);
    free(s->bodies[i].mesh);
  }
  for (int i = 0; i < s->n_bcs; i++)
    for (int c = 0; c < 3; c++) {
      pm_expr_destroy(s->bcs[i].disp[c]);
      pm_expr_destroy(s->bcs[i].traction[c]);
      pm_expr_destroy(s->bcs[i].velocity[c]);
    }
  for (int c = 0; c < 3; c++) pm_expr_destroy(s->reference[c]);
  free(s->materials);
  free(s->bodies);
  free(s->bcs);
  for (int k = 0; k < s->n_overrides; k++) free(s->overrides[k]);
  free(s->overrides);
  free(s->name);
  free(s->text);
  free(s->path);
  free(s);
}

const char *pm_method_name(pm_method m) {
  switch (m) {
  case PM_METHOD_FPM: return "fpm";
  case PM_METHOD_MPM: return "mpm";
  case PM_METHOD_MPM_IMPLICIT: return "mpm-implicit";
  }
  return "unknown";
}

bool pm_body_contains(const pm_scene_body *b, int dim, const double x[3]) {
  switch (b->shape) {
  case PM_BODY_DOMAIN: return true;
  case PM_BODY_REGION:
    return pm_expr_eval(b->region, x[0], x[1], dim == 3 ? x[2] : 0, 0) > 0;
  case PM_BODY_BOX:
    for (int c = 0; c < dim; c++)
      if (x[c] < b->a[c] || x[c] > b->b[c]) return false;
    return true;
  case PM_BODY_SPHERE: {
    double r2 = 0;
    for (int c = 0; c < dim; c++) r2 += (x[c] - b->a[c]) * (x[c] - b->a[c]);
    return r2 <= b->radius * b->radius;
  }
  case PM_BODY_CYLINDER: {
    double d[3] = {x[0] - b->a[0], x[1] - b->a[1], x[2] - b->a[2]};
    double len2 = pm_v_dot(b->b, b->b), s = pm_v_dot(d, b->b) / len2;
    if (s < 0 || s > 1) return false;
    double r2 = pm_v_dot(d, d) - s * s * len2;
    return r2 <= b->radius * b->radius;
  }
  case PM_BODY_MESH: return false;
  }
  return false;
}

double pm_ramp_factor(pm_ramp kind, double T, double t) {
  if (kind == PM_RAMP_NONE) return 1.0;
  if (t <= 0) return 0.0;
  if (!(T > 0) || t >= T) return 1.0;
  double x = t / T;
  if (kind == PM_RAMP_LINEAR) return x;
  return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}
