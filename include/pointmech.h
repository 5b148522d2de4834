/* pointmech.h: pointmech as a library.  A scene (a file or a string, with
 * overrides as `pointmech run --set` takes them) is loaded into an opaque
 * handle, run through the same driver as the program (the same results,
 * history and summary when given an output folder, none without one),
 * with a callback after every step, and its fields and figures read back
 * by name into the caller's arrays.
 *
 * Every function that can fail returns a pointmech_code (POINTMECH_OK, 0,
 * on success); pointmech_error_message() then says what failed and where
 * (a scene's errors as FILE:LINE:COL: KEY: expected ..., got ...).  The
 * library keeps the last message per process: call it from one thread.
 *
 * One process needs nothing more.  Across MPI ranks, the caller starts MPI
 * and hands its communicator to pointmech_attach_mpi on every rank before
 * loading; every rank then makes the same calls in the same order (load,
 * run, destroy), each steps its share, rank 0 writes the files and calls
 * the observer, and fields are read on rank 0.
 *
 * C and C++ (extern "C"); no other header of pointmech's is needed. */
#ifndef POINTMECH_H
#define POINTMECH_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The version of this interface (the functions and types here); the
 * library's own is pointmech_version(). */
#define POINTMECH_API_VERSION_MAJOR 1
#define POINTMECH_API_VERSION_MINOR 0

typedef enum {
  POINTMECH_OK = 0,
  POINTMECH_ERR_MEMORY,        /* out of memory */
  POINTMECH_ERR_IO,            /* a file could not be read or written */
  POINTMECH_ERR_ARG,           /* a bad argument to a function here */
  POINTMECH_ERR_SCENE,         /* a bad scene or override */
  POINTMECH_ERR_EXPR,          /* a bad expression in the scene */
  POINTMECH_ERR_MESH,          /* meshing failed */
  POINTMECH_ERR_GEOMETRY,      /* degenerate geometry */
  POINTMECH_ERR_LINALG,        /* a linear solve failed */
  POINTMECH_ERR_HDF5,          /* an HDF5 failure */
  POINTMECH_ERR_UNSTABLE,      /* the run stopped on a numerical failure */
  POINTMECH_ERR_NOT_CONVERGED, /* a quasi-static run missed its tolerance */
  POINTMECH_ERR_UNSUPPORTED,   /* not supported by this method or build */
  POINTMECH_ERR_INTERRUPTED,   /* SIGINT, SIGTERM or the observer stopped it */
  POINTMECH_ERR_INTERNAL       /* a bug: please report it */
} pointmech_code;

/* A scene, its simulation and the state the last run left. */
typedef struct pointmech pointmech;

/* The library's version ("0.1.0"), the program's. */
const char *pointmech_version(void);

/* What the last failure said (empty when none), and a code's name
 * ("POINTMECH_ERR_SCENE"). */
const char *pointmech_error_message(void);
const char *pointmech_code_name(int code);

/* Run across the ranks of the caller's communicator: comm points to an
 * MPI_Comm (Open MPI, the library's own), valid while the library is
 * used; MPI started by the caller.  Call on every rank before loading.
 * Without it, or where MPI is not started, every process is one run. */
pointmech_code pointmech_attach_mpi(const void *comm);

/* Let go of what the library started for its solvers (PETSc): across
 * MPI ranks, call on every rank before MPI_Finalize; on one process it
 * happens at exit by itself.  No run can start after it. */
void pointmech_finalize(void);

/* A new handle, empty (*out NULL on failure). */
pointmech_code pointmech_create(pointmech **out);
/* Release p and everything it holds (NULL: nothing). */
void pointmech_destroy(pointmech *p);

/* Override a scene value by its dotted key, "KEY=VALUE" as `--set` takes
 * it ("discretization.mesh_size=2.5e-2", "boundary.3.displacement.z=-0.06").
 * Applies to the next load; refused after one (create another handle). */
pointmech_code pointmech_set(pointmech *p, const char *key_value);

/* Load a scene from a YAML file, or from text named name (messages, and
 * relative paths in the scene, as if read from a file of that name; NULL:
 * "scene.yaml" in the working folder), with the overrides set so far. */
pointmech_code pointmech_load_file(pointmech *p, const char *path);
pointmech_code pointmech_load_string(pointmech *p, const char *text,
                                     const char *name);

/* The scene's name and method ("fpm", "mpm", "mpm-implicit"). */
const char *pointmech_scene_name(const pointmech *p);
const char *pointmech_method(const pointmech *p);

/* One step of a run, as the observer sees it. */
typedef struct {
  long step;       /* 0 is the initial state */
  double time;     /* simulated time, s */
  double residual; /* quasi-static residual (0 in dynamics) */
  double progress; /* fraction of the run done, in [0, 1] */
  int frame;       /* a frame step (output.every, the first and the last):
                      fields are read here across ranks too */
  int last;        /* the run's last step */
} pointmech_step;

/* Called after every step with the handle, whose fields and figures
 * (pointmech_field_read, pointmech_figure) are the step's.  Return 0 to go
 * on; anything else ends the run after this step (with its frame and
 * checkpoint when there is an output folder), and pointmech_run returns
 * POINTMECH_ERR_INTERRUPTED. */
typedef int (*pointmech_observer)(pointmech *p, const pointmech_step *step,
                                  void *ctx);

/* How a run goes (a bit mask). */
enum {
  POINTMECH_RUN_PROGRESS = 1u << 0, /* progress line and stage times on
                                       stderr, as the program shows */
  POINTMECH_RUN_OVERWRITE = 1u << 1 /* replace another run's files in
                                       out_dir */
};

/* Set up the loaded scene's simulation and run it to the end, calling
 * observer (may be NULL) with ctx after every step.  out_dir: the folder
 * the program's `run --out` would write (results.h5, history.csv,
 * summary.json; created if missing), or NULL to write nothing.  A run
 * that ends on a numerical failure, short of a quasi-static tolerance or
 * stopped still leaves its last state to read.  A handle runs once. */
pointmech_code pointmech_run(pointmech *p, const char *out_dir, unsigned flags,
                             pointmech_observer observer, void *ctx);

/* How the run ended: "completed", "converged", "not-converged",
 * "unstable", "failed", "interrupted", "not-run". */
const char *pointmech_status(const pointmech *p);

/* ---- fields of the current state (during and after a run) ---- */

/* The number of points (FPM points, MPM particles), 0 before a run. */
long pointmech_point_count(const pointmech *p);
/* Their reference coordinates, x y z per point (z 0 in 2-D), into
 * xyz[0 .. 3 * points); capacity: the doubles xyz holds. */
pointmech_code pointmech_points(pointmech *p, double *xyz, size_t capacity);

/* The fields of the state: how many, and the name of field k in
 * [0, count) ("displacement", "velocity", "stress", ...; the method may add
 * its own), valid until the next call here. */
int pointmech_field_count(pointmech *p);
const char *pointmech_field_name(pointmech *p, int k);
/* Field name's components per point: 1 (scalar), 3 (vector), 9 (tensor,
 * row-major 3x3).  POINTMECH_ERR_ARG (message listing the fields) for a
 * name the state has not. */
pointmech_code pointmech_field_components(pointmech *p, const char *name,
                                          int *components);
/* Copy field name, components per point point-major
 * (dst[i * components + c]), into dst[0 .. points * components); capacity:
 * the doubles dst holds (POINTMECH_ERR_ARG if fewer). */
pointmech_code pointmech_field_read(pointmech *p, const char *name, double *dst,
                                    size_t capacity);

/* A figure of the state, by its name in summary.json: "time", "steps",
 * "points", "h", "dt", "residual", "kinetic_energy", "strain_energy",
 * "internal_energy", "external_work", "dissipated",
 * "energy_balance_error", "min_jacobian", and after a run
 * "mean_strain_energy_density", "max_von_mises".  POINTMECH_ERR_ARG for
 * another name. */
pointmech_code pointmech_figure(pointmech *p, const char *name, double *value);
/* The force the supports of a boundary condition apply on the body, N
 * (per unit thickness in 2-D), by its label in summary.json's reactions:
 * its surface ("zmax") or "boundary.B" for a region. */
pointmech_code pointmech_reaction(pointmech *p, const char *label,
                                  double force[3]);

#ifdef __cplusplus
}
#endif

#endif
