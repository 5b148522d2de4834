/* gm_gmsh: the gmsh session of the geometry modules (gm_mesh, gm_volume):
 * quiet, single-threaded and repeatable, leaving the process's OpenMP
 * thread count as it found it, and gmsh's errors as PM_ERR_MESH; and the
 * one reader of gmsh models and files they share. */
#ifndef GM_GMSH_H
#define GM_GMSH_H

#include <stdbool.h>

#include "pm_error.h"

typedef struct {
  int threads; /* OpenMP threads before gmsh set its own */
  bool open;
} gm_gmsh_session;

/* Initialize gmsh and make it quiet, single-threaded and repeatable.  path
 * (may be NULL) names the file in a failure message.  Call gm_gmsh_end
 * whatever this returns. */
pm_err gm_gmsh_begin(gm_gmsh_session *s, const char *path);
/* Finalize gmsh (if it was initialized) and restore the thread count.  In
 * a child of pm_isolate_run gmsh is left as it is: the child's memory, and
 * gmsh's state with it, ends with the child, and finalizing costs as much
 * as initializing. */
void gm_gmsh_end(gm_gmsh_session *s);
/* Initialize gmsh once ahead, in a process that then reads gmsh files in
 * children (pm_isolate.h): the next session begun (in each child, which
 * inherits it unused) takes it instead of initializing gmsh again.  A
 * process that reads many files (a fuzzer) saves gmsh's start-up on each;
 * the parent itself must begin no session of its own meanwhile. */
pm_err gm_gmsh_warm(void);
/* Map libgmsh in this process now, without starting gmsh.  Every mesh and
 * gmsh file is made or read in a child (gm_gmsh_load and the others below;
 * pm_isolate.h), which maps and relocates libgmsh and the hundred libraries
 * it brings unless its parent has: about 0.2 s a child, 0.3 s under the
 * sanitizers.  A process that meshes many times (a test's fixtures) maps
 * it once here; a run that meshes once leaves it to its child, so that its
 * own memory never holds gmsh.  need says what needs gmsh, for the message
 * when it cannot be loaded (PM_ERR_UNSUPPORTED). */
pm_err gm_gmsh_preload(const char *need);
/* Element size h everywhere (overrides sizes a file sets). */
pm_err gm_gmsh_size(double h, const char *path);

/* How the element sizes a file sets itself (point sizes, size fields, its
 * Mesh options) meet a size h where gmsh meshes the file. */
typedef enum {
  GM_SIZES_SCALE = 0, /* the file's sizes times one factor, so that the
                         longest edge of the mesh of its curves at its own
                         sizes becomes h, and at most h: the file's grading
                         at h's level */
  GM_SIZES_REPLACE,   /* h everywhere (gm_gmsh_size) */
  GM_SIZES_FILE,      /* the file's sizes as written (h unused) */
} gm_sizes;

/* Apply rule to the open session's model before it is meshed.  *factor
 * (may be NULL): what multiplies the file's sizes (1 for file, 0 for
 * replace).  Scale meshes the curves once to measure them; a model without
 * curves is meshed at h (replace, *factor 0). */
pm_err gm_gmsh_sizes(gm_sizes rule, double h, const char *path, double *factor);
/* The last gmsh error as PM_ERR_MESH: "gmsh: WHAT['PATH'] failed: MSG". */
pm_err gm_gmsh_fail(const char *what, const char *path);

/* After a gmsh call, in a function with `int ierr`, `pm_err ret` and a
 * `done` label: on failure record gmsh's message and leave. */
#define GM_GMSH_CHECK(what, path)                                              \
  do {                                                                         \
    if (ierr) {                                                                \
      ret = gm_gmsh_fail(what, path);                                          \
      goto done;                                                               \
    }                                                                          \
  } while (0)

/* The linear simplices of dimension dim of a gmsh model, and optionally its
 * physical groups of dimension dim - 1 (boundary surfaces in 3D, curves in
 * 2D).  Arrays are malloc'd and owned by the struct (gm_gmsh_mesh_free). */
typedef struct {
  int dim;
  long n_nodes;
  double *x; /* 3 * n_nodes: the nodes elements use as corners, in gmsh's
                node order; z = 0 in 2D */
  long n_elems;
  long *elem; /* (dim + 1) * n_elems: corner nodes, 0-based, as gmsh lists
                 them (not reoriented) */
  int n_groups;
  char **group_name;  /* n_groups: the physical name, or "surface-TAG" for a
                         group without one */
  long *group_ptr;    /* n_groups + 1: faces of group g are
                         group_face[dim * group_ptr[g] .. dim * group_ptr[g+1]) */
  long *group_face;   /* dim corner nodes per face (0-based like elem); -1 for
                         a node that is no element's corner */
  bool meshed;        /* gmsh meshed the file (it held no mesh) */
  double size_factor; /* then: what multiplied the file's sizes (0: h
                         replaced them; gm_gmsh_sizes) */
} gm_gmsh_mesh;

/* Read the open session's model into out (zeroed first): every element of
 * dimension dim counts through its corner nodes (higher-order nodes are
 * ignored), and with groups true the physical groups of dimension dim - 1
 * and their elements.  name labels the model in messages (the file path;
 * NULL for a model built in memory).  Fails with PM_ERR_UNSUPPORTED for
 * elements that are not simplices (hexahedra, prisms, quadrangles, in the
 * volume or in a group), PM_ERR_MESH for no element of dimension dim (the
 * message gives the model's dimension), 2D nodes off the z = 0 plane or
 * inconsistent gmsh data, PM_ERR_MEMORY.  On failure out holds nothing. */
pm_err gm_gmsh_read(const char *name, int dim, bool groups, gm_gmsh_mesh *out);

/* PM_ERR_MESH naming name (a file, or NULL for a model in memory) and the
 * node when one of the n nodes x[3 n] has a coordinate that is not finite
 * (gmsh reads "nan" and "inf" in a .msh; the mesh's ordering and volumes
 * need numbers). */
pm_err gm_gmsh_check_nodes(const char *name, const double *x, long n);

/* The model's nodes by tag, sorted: each with its number among the
 * elements' corners (-1 for a node no element uses). */
typedef struct {
  size_t n;
  size_t *tag;
  long *number;
} gm_gmsh_nodes;

/* Number the nodes the elements use as corners (ctag[0..nc), gmsh node
 * tags) in gmsh's node order: corner[k] the number of ctag[k]'s node, *x
 * (3 per node, the caller frees it) their coordinates, *nn their count,
 * and *nodes (gm_gmsh_nodes_free) every node's number by tag.  Tags are
 * looked up in a sorted list, so the memory follows the node count
 * whatever the tags a file gives (one may tag a node 4e9).  PM_ERR_MESH
 * naming name for a corner without coordinates, PM_ERR_MEMORY. */
pm_err gm_gmsh_corners(const char *name, const size_t *ctag, size_t nc,
                       long *corner, double **x, long *nn,
                       gm_gmsh_nodes *nodes);
/* The number of the node tagged tag, -1 for none or one no element uses. */
long gm_gmsh_node_number(const gm_gmsh_nodes *nodes, size_t tag);
void gm_gmsh_nodes_free(gm_gmsh_nodes *nodes);

/* Checks, before gmsh sees it (gmsh reports a missing file without
 * failing), that path is a regular file this process can read: PM_ERR_IO
 * otherwise, with "cannot open WHAT 'PATH': REASON" (what: "volume file",
 * "surface file"); and a .geo by gm_geo_check. */
pm_err gm_gmsh_check_file(const char *path, const char *what);

/* A gmsh script (a path ending .geo; anything else passes) read as text
 * before gmsh runs it: PM_ERR_MESH with its file and line when it calls a
 * command that starts a program (SystemCall, NonBlockingSystemCall,
 * OnelabRun, a solver's Executable option), or includes or merges a file
 * not named by a plain string; the .geo files it includes or merges are
 * checked the same way (gm_geo_check.c). */
pm_err gm_geo_check(const char *path);

/* The node count a .msh file (ASCII 2.x or 4.x, binary 2.x) states in its
 * $Nodes header, read without gmsh; -1 when the file cannot be read or
 * states none this reads. */
long gm_msh_node_count(const char *path);

/* The bounding box [lo, hi] of the geometry (or mesh) in a gmsh-readable
 * file, checked as gm_gmsh_load checks it; z = 0 in 2D.  PM_ERR_IO,
 * PM_ERR_MESH (gmsh fails, or the box is empty along an axis of dim). */
pm_err gm_file_bounds(const char *path, int dim, double lo[3], double hi[3]);

/* Read a gmsh-readable file (.msh, .geo, .step/.stp, .brep) into out: checks
 * the file is a readable regular file (PM_ERR_IO naming it: gmsh reports a
 * missing file without failing), opens it in a session of its own, meshes
 * it by rule at size h (gm_gmsh_sizes; h <= 0: the file's own sizes
 * whatever the rule) when it holds no element of dimension dim (a mesh in
 * the file is used as it is), reads it as gm_gmsh_read does and closes
 * gmsh whatever happens.  Not thread-safe (gmsh keeps global state); must
 * not run inside another session. */
pm_err gm_gmsh_load(const char *path, int dim, double h, gm_sizes rule,
                    bool groups, gm_gmsh_mesh *out);

/* gm_gmsh_load, gm_file_bounds and gm_trisurf_load (gm_trisurf.h) read the
 * file in a child process (pm_isolate.h; gm_gmsh_isolate.c), so that gmsh
 * stopping on a damaged file (a segmentation fault, an abort) refuses it,
 * PM_ERR_MESH naming the file, instead of ending the process.  These are
 * the same readers in the process itself, which the child runs. */
pm_err gm_gmsh_load_here(const char *path, int dim, double h, gm_sizes rule,
                         bool groups, gm_gmsh_mesh *out);
pm_err gm_file_bounds_here(const char *path, int dim, double lo[3],
                           double hi[3]);

/* Frees the arrays of m and zeroes it; NULL is a no-op. */
void gm_gmsh_mesh_free(gm_gmsh_mesh *m);

#endif
