/* pm_scene: a simulation scene loaded from YAML against a schema, with
 * command-line overrides.  One vocabulary for every method. */
#ifndef PM_SCENE_H
#define PM_SCENE_H

#include <stdbool.h>

#include "pm_error.h"
#include "pm_expr.h"
#include "pm_face.h"
#include "pm_fluid.h"
#include "pm_material.h"

typedef enum {
  PM_METHOD_FPM = 0,
  PM_METHOD_MPM,
  PM_METHOD_MPM_IMPLICIT
} pm_method;
typedef enum { PM_RAMP_SMOOTH = 0, PM_RAMP_LINEAR, PM_RAMP_NONE } pm_ramp;
typedef enum {
  PM_QS_NONE = 0,           /* plain dynamics */
  PM_QS_DYNAMIC_RELAXATION, /* adaptive (Rayleigh-quotient) damping */
  PM_QS_DAMPING             /* fixed mass-proportional damping */
} pm_qs_method;

/* Interior-penalty flux of FPM. */
typedef enum {
  PM_FLUX_IIPG = 0, /* incomplete (the FPM paper's eq. 16) */
  PM_FLUX_SIPG      /* symmetric: the force is the gradient of an energy */
} pm_flux;

/* How the stable time step is found. */
typedef enum {
  PM_DT_PAPER = 0, /* the bound of eqs. 24-26 of the FPM paper */
  PM_DT_SPECTRAL   /* the measured largest eigenvalue of M^-1 K */
} pm_dt_rule;

/* Output fields (bit mask). */
enum {
  PM_FIELD_DISPLACEMENT = 1u << 0,
  PM_FIELD_VELOCITY = 1u << 1,
  PM_FIELD_STRESS = 1u << 2, /* Cauchy stress */
  PM_FIELD_STRAIN_ENERGY_DENSITY = 1u << 3,
  PM_FIELD_JACOBIAN = 1u << 4,
  PM_FIELD_FORCE = 1u << 5 /* residual (out-of-balance) force */
};

/* A position in the scene file (1-based; 0 when not from the file). */
typedef struct {
  int line, col;
} pm_scene_mark;

/* MPM grid shape functions, update variants and fluid energy update. */
typedef enum { PM_SHAPE_LINEAR = 0, PM_SHAPE_QUADRATIC } pm_shape;
typedef enum { PM_UPDATE_USF = 0, PM_UPDATE_USL, PM_UPDATE_MUSL } pm_update;
typedef enum {
  PM_ENERGY_ITERATIVE = 0, /* steps (1)-(6) of the fluid paper, eqs. 27-31 */
  PM_ENERGY_NON_ITERATIVE  /* energy from the previous stress (eq. 27 only) */
} pm_energy_update;

typedef struct {
  char *name;
  bool fluid; /* model: fluid (then `fluid` holds it, `mat` is unused) */
  pm_material mat;
  pm_fluid fluid_props;
  double av_c0, av_c1; /* artificial viscosity (eq. 32); 0: none */
  pm_scene_mark mark;
} pm_scene_material;

/* Shape of a body (MPM seeding; FPM uses region only). */
typedef enum {
  PM_BODY_DOMAIN = 0, /* the whole domain box */
  PM_BODY_REGION,     /* region expression > 0 */
  PM_BODY_BOX,        /* box: {min, max} */
  PM_BODY_SPHERE,     /* sphere: {center, radius} (a disk in 2D) */
  PM_BODY_CYLINDER,   /* cylinder: {base, axis, radius}; axis from the base
                          to the top face */
  PM_BODY_MESH        /* mesh: a gmsh-readable volume (surface in 2D) */
} pm_body_shape;

typedef struct {
  int material; /* index into materials */
  pm_body_shape shape;
  pm_expr *region;   /* PM_BODY_REGION: inside where expr > 0 */
  double a[3], b[3]; /* box: min, max; sphere: center; cylinder: base, axis */
  double radius;
  char *mesh;         /* PM_BODY_MESH: file path, relative paths resolved
                         against the scene's folder */
  double velocity[3]; /* initial velocity, m/s */
  double density;     /* initial density, kg/m^3 (default: the material's) */
  double pressure;    /* fluids: initial pressure, Pa */
  pm_scene_mark mark;
} pm_scene_body;

/* A boundary condition on one named face.  Displacement components are
 * prescribed values at full load (expressions in x, y, z and t, in m);
 * traction components are nominal tractions at full load (Pa).  The value
 * applied at time t is ramp(t) * value(x, y, z, t). */
typedef struct {
  pm_face face;
  unsigned disp_mask; /* bit c: component c prescribed */
  pm_expr *disp[3];   /* NULL where not prescribed */
  unsigned traction_mask;
  pm_expr *traction[3];
  unsigned velocity_mask; /* MPM: prescribed velocity components, m/s */
  pm_expr *velocity[3];
  bool absorbing; /* MPM: viscous (absorbing) boundary on this face */
  pm_ramp ramp;
  double ramp_time; /* s; the loader puts time.ramp when not given */
  pm_scene_mark mark;
} pm_scene_bc;

typedef struct pm_scene {
  char *path;       /* scene file as given */
  char *text;       /* full source text (stored with the results),
                       then the overrides as comment lines */
  char **overrides; /* the "key=value" overrides applied */
  int n_overrides;
  char *name;
  pm_method method;
  int dimension;                 /* 2 (plane strain) or 3 */
  double box_min[3], box_max[3]; /* domain.box; z ignored in 2D */
  double mesh_size;              /* discretization.mesh_size, m, > 0 */
  pm_scene_material *materials;
  int n_materials;
  pm_scene_body *bodies;
  int n_bodies;
  pm_scene_bc *bcs;
  int n_bcs;
  struct {
    double penalty; /* fpm.penalty p >= 0 (beta = p E / h) */
    pm_flux flux;   /* fpm.flux: iipg (default) | sipg */
  } fpm;
  struct {
    pm_shape shape;   /* mpm.shape: quadratic (default) | linear */
    pm_update update; /* mpm.update: musl (default) | usl | usf */
    double flip;      /* mpm.flip: FLIP fraction of the particle velocity
                         update in [0, 1] (1 FLIP, 0 PIC; default 1) */
    int ppc[3];       /* mpm.particles_per_cell: per direction (default 2) */
    pm_energy_update energy_update; /* mpm.fluid.energy_update */
    double energy_tolerance;        /* mpm.fluid.tolerance (relative) */
    int max_iterations;             /* mpm.fluid.max_iterations */
    unsigned null_velocity;         /* mpm.null_velocity: grid velocity
                                       components held at zero (mask) */
  } mpm;
  double gravity[3]; /* gravity: m/s^2 */
  bool has_gravity;
  struct {
    double end;          /* time.end, s, > 0 */
    double dt;           /* time.dt, s; 0: stable dt from eqs. 24-26 */
    double dt_safety;    /* time.dt_safety in (0, 1] */
    pm_dt_rule dt_rule;  /* time.dt_rule: paper (default) | spectral */
    double ramp;         /* time.ramp, s: default ramp duration */
    pm_qs_method qs;     /* time.quasi_static.method */
    double qs_tolerance; /* time.quasi_static.tolerance: relative residual */
    double qs_damping;   /* time.quasi_static.damping: 1/s for PM_QS_DAMPING */
    long max_steps;      /* time.max_steps; 0: no limit */
  } time;
  struct {
    /* stability.min_jacobian: stop when some J falls to or below it
     * (default 0: an inverted subdomain) */
    double min_jacobian;
    /* stability.max_energy_error: stop when |kinetic + strain + dissipated
     * - external work| exceeds this fraction of the energy in play
     * (default 0.1) */
    double max_energy_error;
  } stability;
  struct {
    long every;      /* output.every: frame every N steps (> 0) */
    unsigned fields; /* PM_FIELD_* mask */
  } output;
  unsigned reference_mask; /* reference.displacement components given */
  pm_expr *reference[3];   /* analytic u_c(x, y, z, t) or NULL */
} pm_scene;

/* Load a scene file, apply overrides ("key.path=value", e.g.
 * "discretization.mesh_size=8.02e-3", "boundary.3.displacement.z=-0.06",
 * "time.quasi_static.tolerance=1e-9"), validate, and return a new scene.
 * Errors (PM_ERR_IO for a missing file, PM_ERR_SCENE otherwise) carry
 * "FILE:LINE:COL: KEY: expected ..., got ..." or, for an override,
 * "--set KEY=VALUE: ...".  *out is NULL on failure. */
pm_err pm_scene_load(const char *path, int n_overrides,
                     const char *const *overrides, pm_scene **out);
void pm_scene_destroy(pm_scene *s);

const char *pm_method_name(pm_method m);

/* True when x (3 components; z unused in 2D) lies in the body's shape:
 * domain, region (expr > 0), box, sphere or cylinder (boundary included).
 * A mesh shape needs the geometry layer: this returns false for it. */
bool pm_body_contains(const pm_scene_body *b, int dim, const double x[3]);

/* Ramp factor in [0, 1] at time t for ramp kind and duration T:
 * smooth is C2 (10 s^3 - 15 s^4 + 6 s^5), linear is s, none is 1. */
double pm_ramp_factor(pm_ramp kind, double T, double t);

#endif
