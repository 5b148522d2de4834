/* gm_gmsh_isolate: the readers of files through gmsh (gm_gmsh_load,
 * gm_file_bounds, gm_trisurf_load) run in a child process (pm_isolate.h):
 * gmsh 4.8 stops the process on some damaged files (a .msh whose elements
 * name a node it does not list: a segmentation fault inside gmshOpen), and
 * such a file is refused by name instead.  The child's gmsh model, with
 * the memory gmsh keeps after finalizing, ends with it; so gmsh meshes a
 * box there too (gm_mesh_box_raw). */
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "gm_gmsh.h"
#include "gm_mesh.h"
#include "gm_trisurf.h"
#include "pm_isolate.h"

/* One reading of path through gmsh in a child: work, then put and get
 * its result; what names what path should be where gmsh fails on it
 * (NULL: a mesh or geometry gmsh reads). */
static pm_err isolate(const char *path, const char *what,
                      pm_err (*work)(void *), pm_err (*put)(void *, int),
                      pm_err (*get)(void *, int), void *arg) {
  const pm_isolate_job job = {.path = path ? path : "",
                              .library = "gmsh",
                              .what =
                                  what ? what : "a mesh or geometry gmsh reads",
                              .code = PM_ERR_MESH,
                              .work = work,
                              .put = put,
                              .get = get,
                              .arg = arg};
  return pm_isolate_run(&job);
}

/* ---- gm_gmsh_load ------------------------------------------------------ */

typedef struct {
  const char *path;
  int dim;
  double h;
  gm_sizes rule;
  bool groups;
  gm_gmsh_mesh *out;
} load_arg;

/* The scalars of a gm_gmsh_mesh, passed first. */
typedef struct {
  int dim, n_groups;
  long n_nodes, n_elems;
  int meshed; /* a bool, passed as an int: any bytes read back are one */
  double size_factor;
} mesh_head;

static pm_err load_work(void *p) {
  load_arg *a = p;
  return gm_gmsh_load_here(a->path, a->dim, a->h, a->rule, a->groups, a->out);
}

/* m down fd, as mesh_get reads it. */
static pm_err mesh_put(int fd, const gm_gmsh_mesh *m) {
  const mesh_head head = {m->dim,     m->n_groups, m->n_nodes,
                          m->n_elems, m->meshed,   m->size_factor};
  PM_CALL(pm_isolate_put(fd, &head, sizeof head));
  PM_CALL(pm_isolate_put_array(fd, m->x, 3 * (size_t)m->n_nodes, sizeof *m->x));
  PM_CALL(pm_isolate_put_array(fd, m->elem, (size_t)(m->dim + 1) * m->n_elems,
                               sizeof *m->elem));
  if (m->n_groups == 0) return PM_SUCCESS;
  for (int g = 0; g < m->n_groups; g++)
    PM_CALL(pm_isolate_put_array(fd, m->group_name[g],
                                 strlen(m->group_name[g]) + 1, 1));
  PM_CALL(pm_isolate_put_array(fd, m->group_ptr, (size_t)m->n_groups + 1,
                               sizeof *m->group_ptr));
  return pm_isolate_put_array(fd, m->group_face,
                              (size_t)m->dim * m->group_ptr[m->n_groups],
                              sizeof *m->group_face);
}

static pm_err load_put(void *p, int fd) {
  return mesh_put(fd, ((load_arg *)p)->out);
}

/* Whether the n numbers of v are in [lo, hi). */
static bool in_range(const long *v, size_t n, long lo, long hi) {
  for (size_t k = 0; k < n; k++)
    if (v[k] < lo || v[k] >= hi) return false;
  return true;
}

/* The arrays of m from fd, checked as gm_gmsh_read leaves them (the
 * process indexes by them; a child that lies is refused): dim as asked,
 * the counts against the scalars, every corner a node, the groups' faces
 * in order and their corners nodes or -1. */
static pm_err mesh_get(int fd, int dim, gm_gmsh_mesh *m) {
  pm_err ret = PM_SUCCESS;
  mesh_head head;
  size_t n = 0;
  PM_CALL(pm_isolate_get(fd, &head, sizeof head));
  PM_CHECK(head.dim == dim && head.n_nodes > 0 && head.n_elems > 0 &&
               head.n_nodes <= (long)(SIZE_MAX / 24) &&
               head.n_elems <= (long)(SIZE_MAX / 32) && head.n_groups >= 0 &&
               head.n_groups < (1 << 30),
           PM_ERR_INTERNAL,
           "a mesh of dimension %d, %ld nodes, %ld elements and %d groups "
           "passed back for one of dimension %d",
           head.dim, head.n_nodes, head.n_elems, head.n_groups, dim);
  m->dim = head.dim;
  m->n_nodes = head.n_nodes;
  m->n_elems = head.n_elems;
  m->meshed = head.meshed != 0;
  m->size_factor = head.size_factor;
  const size_t corners = (size_t)(m->dim + 1) * (size_t)m->n_elems;
  PM_TRY(pm_isolate_get_array(fd, (void **)&m->x, &n, sizeof *m->x));
  PM_ENSURE(n == 3 * (size_t)m->n_nodes, PM_ERR_INTERNAL,
            "%zu coordinates passed back for %ld nodes", n, m->n_nodes);
  PM_TRY(gm_gmsh_check_nodes("the mesh passed back", m->x, m->n_nodes));
  PM_TRY(pm_isolate_get_array(fd, (void **)&m->elem, &n, sizeof *m->elem));
  PM_ENSURE(n == corners, PM_ERR_INTERNAL,
            "%zu corners passed back for %ld elements", n, m->n_elems);
  PM_ENSURE(in_range(m->elem, n, 0, m->n_nodes), PM_ERR_INTERNAL,
            "an element's corner passed back is no node");
  if (head.n_groups == 0) return PM_SUCCESS;
  /* The names' table grows as they arrive: a count no names follow
   * allocates nothing. */
  for (int g = 0, cap = 0; g < head.n_groups; g++) {
    if (g == cap) {
      cap = cap ? (cap < head.n_groups / 2 ? 2 * cap : head.n_groups)
                : (head.n_groups < 64 ? head.n_groups : 64);
      char **grown = realloc(m->group_name, (size_t)cap * sizeof *grown);
      PM_ENSURE(grown, PM_ERR_MEMORY, "cannot allocate %d group names", cap);
      m->group_name = grown;
    }
    m->group_name[g] = NULL;
    m->n_groups = g + 1;
    PM_TRY(pm_isolate_get_array(fd, (void **)&m->group_name[g], &n, 1));
    PM_ENSURE(n > 0 &&
                  memchr(m->group_name[g], '\0', n) == m->group_name[g] + n - 1,
              PM_ERR_INTERNAL, "group name passed back");
  }
  PM_TRY(pm_isolate_get_array(fd, (void **)&m->group_ptr, &n,
                              sizeof *m->group_ptr));
  PM_ENSURE(n == (size_t)m->n_groups + 1 && m->group_ptr[0] == 0,
            PM_ERR_INTERNAL, "groups passed back");
  for (int g = 0; g < m->n_groups; g++)
    PM_ENSURE(m->group_ptr[g + 1] >= m->group_ptr[g] &&
                  m->group_ptr[g + 1] <= (long)(SIZE_MAX / 24),
              PM_ERR_INTERNAL, "group %d's faces passed back out of order", g);
  PM_TRY(pm_isolate_get_array(fd, (void **)&m->group_face, &n,
                              sizeof *m->group_face));
  PM_ENSURE(n == (size_t)m->dim * (size_t)m->group_ptr[m->n_groups],
            PM_ERR_INTERNAL, "%zu group corners passed back for %ld faces", n,
            m->group_ptr[m->n_groups]);
  PM_ENSURE(in_range(m->group_face, n, -1, m->n_nodes), PM_ERR_INTERNAL,
            "a group face's corner passed back is no node");
done:
  if (ret) gm_gmsh_mesh_free(m);
  return ret;
}

static pm_err load_get(void *p, int fd) {
  const load_arg *a = p;
  return mesh_get(fd, a->dim, a->out);
}

pm_err gm_gmsh_load(const char *path, int dim, double h, gm_sizes rule,
                    bool groups, gm_gmsh_mesh *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_gmsh_load: out is NULL");
  memset(out, 0, sizeof *out);
  load_arg a = {path, dim, h, rule, groups, out};
  return isolate(path, NULL, load_work, load_put, load_get, &a);
}

/* ---- gm_mesh_box_raw --------------------------------------------------- */

typedef struct {
  int dim;
  const double *min, *max;
  double h;
  const gm_grade *g;
  gm_gmsh_mesh *out;
} box_arg;

static pm_err box_work(void *p) {
  box_arg *a = p;
  return gm_mesh_box_raw_here(a->dim, a->min, a->max, a->h, a->g, a->out);
}

static pm_err box_put(void *p, int fd) {
  return mesh_put(fd, ((box_arg *)p)->out);
}

static pm_err box_get(void *p, int fd) {
  const box_arg *a = p;
  return mesh_get(fd, a->dim, a->out);
}

/* Not for safety from a file: gmsh's libraries (about 50 MB resident once
 * loaded) and the model it keeps after finalizing stay in the child, so
 * the process that meshes (rank 0 across ranks) holds its mesh alone. */
pm_err gm_mesh_box_raw(int dim, const double min[3], const double max[3],
                       double h, const gm_grade *g, gm_gmsh_mesh *raw) {
  memset(raw, 0, sizeof *raw);
  box_arg a = {dim, min, max, h, g, raw};
  return isolate("domain.box", "a box gmsh meshes (a fault of gmsh's)",
                 box_work, box_put, box_get, &a);
}

/* ---- gm_file_bounds ---------------------------------------------------- */

typedef struct {
  const char *path;
  int dim;
  double box[6]; /* lo, hi */
} bounds_arg;

static pm_err bounds_work(void *p) {
  bounds_arg *a = p;
  return gm_file_bounds_here(a->path, a->dim, a->box, a->box + 3);
}

static pm_err bounds_put(void *p, int fd) {
  return pm_isolate_put(fd, ((bounds_arg *)p)->box, sizeof(double[6]));
}

static pm_err bounds_get(void *p, int fd) {
  bounds_arg *a = p;
  PM_CALL(pm_isolate_get(fd, a->box, sizeof(double[6])));
  /* What gm_file_bounds_here leaves: a box along each axis in use. */
  for (int c = 0; c < 3; c++)
    PM_CHECK(isfinite(a->box[c]) && isfinite(a->box[3 + c]) &&
                 (c < a->dim ? a->box[3 + c] > a->box[c]
                             : a->box[3 + c] >= a->box[c]),
             PM_ERR_INTERNAL, "bounds passed back: [%g, %g] along %c",
             a->box[c], a->box[3 + c], "xyz"[c]);
  return PM_SUCCESS;
}

pm_err gm_file_bounds(const char *path, int dim, double lo[3], double hi[3]) {
  bounds_arg a = {.path = path, .dim = dim};
  PM_CALL(isolate(path, NULL, bounds_work, bounds_put, bounds_get, &a));
  memcpy(lo, a.box, 3 * sizeof *lo);
  memcpy(hi, a.box + 3, 3 * sizeof *hi);
  return PM_SUCCESS;
}

/* ---- gm_trisurf_load --------------------------------------------------- */

typedef struct {
  const char *path;
  gm_trisurf *out;
} surface_arg;

static pm_err surface_work(void *p) {
  surface_arg *a = p;
  return gm_trisurf_load_here(a->path, a->out);
}

static pm_err surface_put(void *p, int fd) {
  const gm_trisurf *s = ((surface_arg *)p)->out;
  PM_CALL(
      pm_isolate_put_array(fd, s->x, 3 * (size_t)s->n_points, sizeof *s->x));
  return pm_isolate_put_array(fd, s->tri, 3 * (size_t)s->n_tris,
                              sizeof *s->tri);
}

static pm_err surface_get(void *p, int fd) {
  gm_trisurf *s = ((surface_arg *)p)->out;
  size_t nx = 0, nt = 0;
  pm_err ret = PM_SUCCESS;
  PM_TRY(pm_isolate_get_array(fd, (void **)&s->x, &nx, sizeof *s->x));
  PM_TRY(pm_isolate_get_array(fd, (void **)&s->tri, &nt, sizeof *s->tri));
  PM_ENSURE(nx % 3 == 0 && nt % 3 == 0 && nx / 3 <= LONG_MAX, PM_ERR_INTERNAL,
            "surface passed back");
  s->n_points = (long)(nx / 3);
  s->n_tris = (long)(nt / 3);
  PM_ENSURE(in_range(s->tri, nt, 0, s->n_points), PM_ERR_INTERNAL,
            "a triangle's corner passed back is no point");
  PM_TRY(gm_gmsh_check_nodes("the surface passed back", s->x, s->n_points));
done:
  if (ret) gm_trisurf_free(s);
  return ret;
}

pm_err gm_trisurf_load(const char *path, gm_trisurf *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_trisurf_load: out is NULL");
  memset(out, 0, sizeof *out);
  surface_arg a = {path, out};
  return isolate(path, NULL, surface_work, surface_put, surface_get, &a);
}
