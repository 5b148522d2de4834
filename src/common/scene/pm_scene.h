/* pm_scene: a simulation scene loaded from YAML, with command-line
 * overrides.  The shared vocabulary (domain, materials, bodies, boundary,
 * gravity, time, output, reference, stability) is read here; each method's
 * own section ("fpm:", "mpm:") is declared and checked by its backend
 * (pm_backend.h) and kept here as an options struct. */
#ifndef PM_SCENE_H
#define PM_SCENE_H

#include <stdbool.h>
#include <stdio.h>

#include "pm_curve.h"
#include "pm_error.h"
#include "pm_expr.h"
#include "pm_face.h"
#include "pm_keys.h"
#include "pm_material.h"
#include "pm_scene_doc.h"

struct pm_backend;

/* Sections a scene can hold: one per registered backend. */
#define PM_SCENE_SECTIONS 8

typedef enum { PM_RAMP_SMOOTH = 0, PM_RAMP_LINEAR, PM_RAMP_NONE } pm_ramp;
typedef enum {
  PM_QS_NONE = 0,           /* plain dynamics */
  PM_QS_DYNAMIC_RELAXATION, /* adaptive (Rayleigh-quotient) damping */
  PM_QS_DAMPING,            /* fixed mass-proportional damping */
  PM_QS_STATIC              /* Newton's method in load steps (no time) */
} pm_qs_method;

/* The linear solver of a static solve (time.quasi_static.linear_solver). */
typedef enum {
  PM_LINEAR_DIRECT = 0, /* LU (MUMPS) */
  PM_LINEAR_GMRES_GAMG, /* GMRES + algebraic multigrid */
  PM_LINEAR_CG_JACOBI,  /* CG + Jacobi (symmetric problems) */
  PM_LINEAR_GMRES_ILU,  /* GMRES + ILU(0) */
  PM_LINEAR_CG_GAMG     /* CG + algebraic multigrid (symmetric problems) */
} pm_linear_solver;

/* What algebraic multigrid is built on in an FPM static solve
 * (time.quasi_static.multigrid_operator). */
typedef enum {
  PM_AMG_TANGENT = 0, /* the assembled tangent (3 rings) */
  PM_AMG_SUPPORT,     /* the tangent on each point's own support */
  PM_AMG_SUPPORT2     /* the tangent on its supports' supports */
} pm_amg_operator;

/* The line search of a static solve's Newton iterations
 * (time.quasi_static.line_search). */
typedef enum {
  PM_QS_LS_AUTO = 0,     /* the method's own: FPM whole-then-secant, the
                            implicit MPM backtracking */
  PM_QS_LS_BACKTRACKING, /* cubic backtracking from the full step */
  PM_QS_LS_SECANT,       /* a secant step on the residual's norm */
  PM_QS_LS_FULL_SECANT   /* the whole step where it lowers the residual,
                            else the secant */
} pm_qs_line_search;

/* How the stable time step is found. */
typedef enum {
  PM_DT_PAPER = 0, /* the method's bound (FPM: eqs. 24-26 of its paper) */
  PM_DT_SPECTRAL   /* the measured largest eigenvalue of M^-1 K (FPM) */
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

/* Elastodamage of a membrane (eqs. 38-41 of the fluid-membrane paper):
 * damage surface f = eps_max - S_L (1 + omega), secant stiffness
 * E^e (1 + 2 c0 (exp(-c1 omega) - 1)), failure at eps_max >= failure. */
typedef struct {
  bool given;
  double c0, c1;
  double elastic_limit; /* S_L: eps_max at the elastic limit */
  double failure;       /* eps_max at which a point fails */
} pm_scene_damage;

typedef struct {
  char *name;
  pm_material mat;        /* the model of the table and its constants */
  double av_c0, av_c1;    /* artificial viscosity (eq. 32); 0: none */
  pm_scene_damage damage; /* membranes: elastodamage */
  pm_scene_mark mark;
} pm_scene_material;

/* Shape of a body. */
typedef enum {
  PM_BODY_DOMAIN = 0, /* the whole domain box */
  PM_BODY_REGION,     /* region expression > 0 */
  PM_BODY_BOX,        /* box: {min, max} */
  PM_BODY_SPHERE,     /* sphere: {center, radius} (a disk in 2D) */
  PM_BODY_CYLINDER,   /* cylinder: {base, axis, radius}; axis from the base
                          to the top face */
  PM_BODY_MESH,       /* mesh: a gmsh-readable volume (surface in 2D) */
  PM_BODY_MEMBRANE,   /* membrane: one layer of points of a thickness
                         (MPM): a triangulated surface's vertices (3D), a
                         curve's points (2D) or a point cloud */
  PM_BODY_INSIDE,     /* inside: the inside of a closed membrane body */
  PM_BODY_OUTSIDE,    /* outside: the domain outside a closed membrane */
  PM_BODY_IMAGE       /* image: the voxels of a labelled volumetric image
                         whose intensity is in a range (MPM) */
} pm_body_shape;

/* Where an image body's voxels come from (image.file, .raw, .points). */
typedef enum {
  PM_IMAGE_TIFF = 0, /* a multi-page TIFF, or a folder of TIFF files */
  PM_IMAGE_RAW,      /* raw: {file, size, bits}, x fastest */
  PM_IMAGE_POINTS    /* points: {file, size, unit}: voxel centres */
} pm_image_source;

/* The surface of a membrane body. */
typedef enum {
  PM_SURFACE_SPHERE = 0, /* membrane.sphere: {center, radius, refinement} */
  PM_SURFACE_RECTANGLE,  /* membrane.rectangle: {origin, edge_u, edge_v,
                            points} */
  PM_SURFACE_FILE,       /* membrane.file: a gmsh-readable surface */
  PM_SURFACE_CURVE,      /* membrane.curve: {x, y, from, to, points,
                            closed}, a line of points (2D) */
  PM_SURFACE_POINTS      /* membrane.points: a point cloud file, no
                            connectivity */
} pm_surface_kind;

/* How a membrane's normals are found each step. */
typedef enum {
  PM_NORMALS_CONNECTIVITY = 0, /* from the triangles (3D) or the neighbours
                                  in the list (2D) */
  PM_NORMALS_ISO_LINEAR,       /* isosurface least squares, linear B-splines
                                  (papers/mpm-membrane-normals-...) */
  PM_NORMALS_ISO_QUADRATIC,    /* ..., quadratic B-splines */
  PM_NORMALS_HYBRID,           /* quadratic, linear or merged cells by the
                                  points in each cell (section 8) */
  PM_NORMALS_HYBRID_QUADRATIC  /* quadratic on the smallest block of cells
                                  (1, 2, 4, 8 a side) with enough points */
} pm_normals_method;

/* The scene's words for them (membrane.normals). */
extern const pm_name pm_normals_names[];

/* discretization.mesh_sizes: how a gmsh file's own element sizes meet
 * mesh_size where gmsh meshes it (gm_sizes' order). */
enum {
  PM_MESH_SIZES_SCALE = 0, /* the file's sizes times one factor: the longest
                              edge of its curves' mesh becomes mesh_size */
  PM_MESH_SIZES_REPLACE,   /* mesh_size everywhere (the file's sizes ignored) */
  PM_MESH_SIZES_FILE,      /* the file's sizes as written */
};
extern const pm_name pm_mesh_sizes_names[];

/* output.ranks: how a run across MPI ranks writes its frames. */
enum {
  PM_OUTPUT_GATHER = 0, /* gathered into rank 0, which writes each whole */
  PM_OUTPUT_PIECES,     /* each rank its own points, joined by rank 0 */
  PM_OUTPUT_AUTO        /* pieces where the method writes them, else gather
                           (resolved when the scene is read) */
};
extern const pm_name pm_output_ranks_names[];

/* discretization.refine.to: what the grading's distance is measured to. */
enum { PM_REFINE_FACES = 0, PM_REFINE_EDGES = 1 };
extern const pm_name pm_refine_to_names[];

typedef struct {
  int material;        /* index into materials */
  char *material_name; /* as the scene gives it */
  char *name;          /* bodies.N.name (NULL when not given) */
  pm_body_shape shape;
  pm_expr *region;   /* PM_BODY_REGION: inside where expr > 0 */
  double a[3], b[3]; /* box: min, max; sphere: center; cylinder: base, axis */
  double radius;
  int n_cylinder;     /* numbers read for the cylinder's vectors */
  char *mesh;         /* PM_BODY_MESH: file path, relative paths resolved
                         against the scene's folder */
  double velocity[3]; /* initial velocity, m/s */
  double density;     /* initial density, kg/m^3 (default: the material's) */
  double pressure;    /* fluids: initial pressure, Pa */
  pm_material_point point; /* what its material's points take from it
                              (fibre directions, unit) */
  /* PM_BODY_MEMBRANE: the surface (sphere: a = center, radius; rectangle:
   * a = origin, b = edge_u, edge_v; file) and the thickness. */
  struct {
    pm_surface_kind surface;
    double thickness; /* m */
    long refinement;  /* sphere: icosahedron subdivisions */
    double edge_v[3]; /* rectangle */
    double points[2]; /* rectangle: points along edge_u and edge_v */
    int n_points;
    char *file; /* file, points: relative paths resolved against the
                   scene's folder */
    pm_normals_method normals;
    pm_expr *curve[2];     /* curve: x(t), y(t) */
    double curve_range[2]; /* curve: t from, to */
    long curve_points;
    bool closed;
    double area; /* points: total area (3D) or length (2D) shared equally
                    when the file gives none per point; 0: not given */
  } membrane;
  /* PM_BODY_IMAGE: n^d particles in each voxel of the crop whose
   * intensity is in [label[0], label[1]]. */
  struct {
    pm_image_source source;
    /* The TIFF file or folder, raw file or point file: relative paths
     * resolved against the scene's folder. */
    char *file;
    double size[3]; /* raw, points: voxels per axis (n_size of them) */
    int n_size;
    int bits;        /* raw: 8 or 16 */
    double unit;     /* points: metres per unit of the file */
    double voxel[3]; /* voxel size, m (n_voxel of them; in 2D z only
                        places a point file's centres) */
    int n_voxel;
    double origin[3]; /* corner of voxel (0, 0, 0), m (likewise) */
    int n_origin;
    double crop_min[3], crop_max[3]; /* voxel indices, half-open; n_crop 0:
                                        the whole image */
    int n_crop_min, n_crop_max;
    double label[2]; /* inclusive intensity range */
    int n_label;
    long per_voxel; /* n: particles per voxel and direction */
  } image;
  char *inside, *outside; /* PM_BODY_INSIDE / OUTSIDE: the membrane body's
                             name */
  int surface_body;       /* ... and its index */
  /* MPM: particles per cell of this body (n_ppc 0: mpm.particles_per_cell) */
  double ppc[3];
  int n_ppc;
  /* Prescribed motion (MPM): the body moves rigidly with the velocity
   * motion[c](t) (components in motion_mask) and imposes it on the grid
   * nodes its particles touch. */
  bool moving; /* motion given */
  unsigned motion_mask;
  pm_expr *motion[3];
  pm_scene_mark mark;
} pm_scene_body;

/* Where a boundary condition acts. */
typedef enum {
  PM_ON_FACE = 0, /* a face of domain.box (on: xmin ... zmax) */
  PM_ON_SURFACE,  /* a named surface of the domain's mesh (on: NAME, a gmsh
                     physical group) */
  PM_ON_REGION,   /* the boundary where region(x, y, z) > 0 */
  PM_ON_PLATE,    /* a rigid plane pushing where it touches (contact) */
  PM_ON_SPHERE,   /* a rigid sphere pushing where it touches (contact) */
  PM_ON_POINT     /* the point nearest a position (at: [x, y, z]) */
} pm_on;

/* How a rigid body holds what touches it. */
typedef enum {
  PM_CONTACT_FRICTIONLESS = 0, /* normal force only */
  PM_CONTACT_STICKING,         /* held tangentially where it touched */
  PM_CONTACT_GLUED /* held in every direction, pulling too (explicit MPM's
                      grip on a face) */
} pm_contact;

/* Whether a condition is a rigid body in contact (plate or sphere). */
#define PM_BC_RIGID(bc) ((bc)->on == PM_ON_PLATE || (bc)->on == PM_ON_SPHERE)

/* A boundary condition.  Displacement components are prescribed values at
 * full load (expressions in x, y, z and t, in m); traction components are
 * nominal tractions at full load (Pa); pressure a follower pressure on the
 * deformed face (Pa); force components a concentrated force on the points
 * selected (N, shared equally among them); velocity components (m/s).  The
 * value applied at time t is curve(t) * ramp(t) * value(x, y, z, t). */
typedef struct {
  pm_on on;
  pm_face face;       /* PM_ON_FACE */
  char *surface;      /* PM_ON_SURFACE: the name; PM_ON_FACE: the face name */
  pm_expr *region;    /* PM_ON_REGION */
  unsigned disp_mask; /* bit c: component c prescribed */
  pm_expr *disp[3];   /* NULL where not prescribed */
  unsigned traction_mask;
  pm_expr *traction[3];
  pm_expr *pressure; /* follower pressure, or NULL */
  unsigned force_mask;
  pm_expr *force[3];
  double at[3]; /* PM_ON_POINT: the position whose nearest point is loaded */
  unsigned velocity_mask;
  pm_expr *velocity[3];
  struct pm_curve *curve; /* curve: the load curve, or NULL (factor 1) */
  bool absorbing;         /* viscous (absorbing) boundary */
  bool symmetry; /* a symmetry plane (on a face): the normal component held
                    at 0, and the scene's figures are the mirrored body's */
  pm_ramp ramp;
  double ramp_time; /* s; time.ramp when not given */
  /* A rigid body (PM_ON_PLATE, PM_ON_SPHERE): its reference geometry,
   * moved rigidly by ramp(t) * displacement(t) (every component prescribed:
   * those not given are 0); surface holds its name (default plate.<i> or
   * sphere.<i>), the label of its reactions. */
  double rigid_point[3];  /* plate: a point of the plane; sphere: centre */
  double rigid_normal[3]; /* plate: unit normal, toward the body */
  double rigid_radius;    /* sphere: m */
  pm_contact contact;     /* frictionless (default) or sticking */
  double contact_penalty; /* kappa: FPM contact stiffness kappa E A / h */
  char *name;             /* name: as given, or NULL */
  pm_scene_mark mark;
} pm_scene_bc;

typedef struct pm_scene {
  char *path;       /* scene file as given */
  char *text;       /* full source text (stored with the results), then the
                       overrides as comment lines */
  char **overrides; /* the "key=value" overrides applied */
  int n_overrides;
  char *name;
  char *method;                     /* "fpm", "mpm", ... */
  const struct pm_backend *backend; /* the registered backend of method */
  int dimension;                    /* 2 (plane strain) or 3 */
  double box_min[3], box_max[3];    /* domain.box; z 0 in 2D */
  bool domain_from_body;            /* domain not given: box_min, box_max
                                       bound the scene's body (FPM) */
  double mesh_size;                 /* discretization.mesh_size, m, > 0 */
  int mesh_sizes;                   /* discretization.mesh_sizes:
                                       PM_MESH_SIZES_SCALE ... */
  struct {
    unsigned near;     /* discretization.refine.near: bit f for face f
                          (pm_face); 0: a uniform mesh */
    double size;       /* discretization.refine.size, m, in (0, mesh_size];
                          0 when size_ratio is given */
    double size_ratio; /* discretization.refine.size_ratio: the size on the
                          faces over the size far from them, in (0, 1]; 0
                          when size is given.  Then mesh_size is the point
                          budget: FPM meshes far from the faces at the size
                          giving about the uniform cloud's points */
    double distance;   /* discretization.refine.distance, m, > 0 */
    int to;            /* discretization.refine.to: PM_REFINE_FACES (the
                          distance to the faces) or PM_REFINE_EDGES (to the
                          edges bounding them) */
  } refine;
  pm_scene_material *materials;
  int n_materials;
  pm_scene_body *bodies;
  int n_bodies;
  pm_scene_bc *bcs;
  int n_bcs;
  double gravity[3]; /* gravity: m/s^2 */
  bool has_gravity;
  /* The symmetry planes (boundary conditions with symmetry: true): bit a
   * for the plane normal to axis a, at mirror_at[a].  The scene models the
   * part of a body mirrored about them: figures compared with the whole
   * body's (the loaded face's reaction, a referee's lattice) mirror it
   * (pm_scene_mirror.h). */
  unsigned mirror_mask;
  double mirror_at[3];
  /* body_force: a force per unit mass f(x, y, z, t) per component (N/kg),
   * added to gravity; both times body_curve(t) (NULL: 1) */
  unsigned body_force_mask;
  pm_expr *body_force[3];
  struct pm_curve *body_curve;
  struct {
    double end;             /* time.end, s, > 0 */
    double dt;              /* time.dt, s; 0: the stable step */
    double dt_safety;       /* time.dt_safety in (0, 1]; the backend's default
                               when not given */
    pm_dt_rule dt_rule;     /* time.dt_rule: paper (default) | spectral */
    double ramp;            /* time.ramp, s: default ramp duration */
    pm_qs_method qs;        /* time.quasi_static.method */
    double qs_tolerance;    /* time.quasi_static.tolerance: relative residual */
    double qs_damping;      /* time.quasi_static.damping: 1/s for damping */
    long qs_load_steps;     /* time.quasi_static.load_steps (static) */
    double qs_max_step;     /* ...max_load_step (FPM static), in [0, 1] */
    long qs_max_iterations; /* ...max_iterations per load step */
    long qs_relax_after;    /* ...relax_after: cuts before relaxation */
    long qs_ptc;            /* ...pseudo_transient: continuation iterations */
    bool qs_follow_fold;    /* ...follow_fold: arc length past a limit point */
    bool qs_relax_first;    /* ...relax_first: after a relaxed step, relax */
    pm_qs_line_search qs_line_search; /* ...line_search */
    double qs_fallback_cpu;     /* ...fallback_seconds: CPU s per fallback */
    pm_linear_solver qs_linear; /* ...linear_solver */
    long qs_reuse;              /* ...reuse_iterations (FPM static) */
    bool qs_inexact;            /* ...inexact: Eisenstat-Walker (FPM) */
    bool qs_coupled;            /* ...averaged_coupling (FPM) */
    pm_amg_operator qs_amg;     /* ...multigrid_operator (FPM) */
    char *qs_solver_options;    /* ...solver_options: PETSc options */
    long max_steps;             /* time.max_steps; 0: no limit */
  } time;
  struct {
    double min_jacobian;     /* stop when some J falls to or below it */
    double max_energy_error; /* stop when the energy-balance error exceeds
                                this fraction (methods that bound it) */
  } stability;
  struct {
    long every;      /* output.every: frame every N steps (> 0) */
    unsigned fields; /* PM_FIELD_* mask */
    int ranks;       /* output.ranks: PM_OUTPUT_GATHER or PM_OUTPUT_PIECES */
    struct {
      long every;     /* output.checkpoint.every: steps (0: never) */
      double minutes; /* output.checkpoint.minutes: wall time (0: never) */
    } checkpoint;
  } output;
  unsigned reference_mask; /* reference.displacement components given */
  pm_expr *reference[3];   /* analytic u_c(x, y, z, t) or NULL */
  char *reference_fe;      /* reference.fe: a folder of FE reference data
                              (cases/fe/CASE), relative to the scene's
                              folder when given relative; NULL if none */
  /* private: the options of every registered section, and the document
   * (kept for located messages after loading) */
  void *section_opts[PM_SCENE_SECTIONS];
  pm_sdoc doc;
} pm_scene;

/* The bounds [lo, hi] of the geometry in a gmsh-readable file (dimension
 * dim), for a scene that gives no domain; its error names the file. */
typedef pm_err (*pm_scene_file_bounds_fn)(const char *path, int dim,
                                          double lo[3], double hi[3]);
/* The reader of such bounds (the program sets the geometry layer's,
 * gm_file_bounds, at start); without one a scene whose domain would come
 * from a file fails. */
void pm_scene_set_file_bounds(pm_scene_file_bounds_fn fn);

/* Load a scene file, apply overrides ("key.path=value", e.g.
 * "discretization.mesh_size=8.02e-3", "boundary.3.displacement.z=-0.06"),
 * read it against the shared keys and every registered backend's section,
 * and have the scene's backend check that it can honour it.  Errors
 * (PM_ERR_IO for a missing file, PM_ERR_SCENE otherwise) carry
 * "FILE:LINE:COL: KEY: expected ..., got ..." or, for an override,
 * "--set KEY=VALUE: ...".  Backends must be registered first
 * (pm_backend_register).  *out is NULL on failure. */
pm_err pm_scene_load(const char *path, int n_overrides,
                     const char *const *overrides, pm_scene **out);
/* The same for a scene given as text (len bytes, which need not end in a
 * NUL), named name in messages and resolving relative paths against
 * name's folder, as if read from a file called name. */
pm_err pm_scene_load_text(const char *text, size_t len, const char *name,
                          int n_overrides, const char *const *overrides,
                          pm_scene **out);
void pm_scene_destroy(pm_scene *s);

/* The options of the registered section called name (the struct its
 * backend declared), or NULL when no backend declares it. */
const void *pm_scene_section(const pm_scene *s, const char *name);

/* Whether the scene gives the key at a dotted path (file or override). */
bool pm_scene_has(const pm_scene *s, const char *path);

/* Format a key path into the char array buf and give buf:
 * PM_PATH(p, "boundary.%d.on", i). */
#define PM_PATH(buf, ...) (snprintf((buf), sizeof(buf), __VA_ARGS__), (buf))

/* Located failures about the key at path (PM_ERR_SCENE): "WHERE: " + the
 * formatted text (at the key's name with key set), and "WHERE: expected
 * WHAT, got VALUE". */
pm_err pm_scene_fail(const pm_scene *s, const char *path, bool key,
                     const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
pm_err pm_scene_expected(const pm_scene *s, const char *path, const char *what);

/* The whole vocabulary, from the key tables: shared keys, every model's
 * and every registered backend's section. */
void pm_scene_print_keys(FILE *out);

/* Ramp factor in [0, 1] at time t for ramp kind and duration T:
 * smooth is C2 (10 s^3 - 15 s^4 + 6 s^5), linear is s, none is 1. */
double pm_ramp_factor(pm_ramp kind, double T, double t);

/* The factor of condition bc's values at time t: its curve times its
 * ramp. */
double pm_bc_factor(const pm_scene_bc *bc, double t);

/* Time at which every ramped condition of the scene (with a displacement
 * or velocity) has reached its full value. */
double pm_scene_load_end(const pm_scene *s);

/* The slowest shear wave speed sqrt(mu_0 / rho_0) of the scene's solid
 * materials, m/s (0 where none has both). */
double pm_scene_shear_wave_speed(const pm_scene *s);

#endif
