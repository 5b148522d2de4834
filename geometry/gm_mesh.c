/* gm_mesh: simplex meshes of a box or rectangle made with the gmsh C API,
 * of a gmsh-readable file, or built from caller arrays; node ordering,
 * orientation and mean edge length. */
#include "gm_mesh.h"

#include "gm_gmsh_api.h" /* gmshc.h, through the table */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gm_gmsh.h"
#include "gm_surface.h"

/* Relative size below which a simplex counts as flat. */
#define GM_FLAT_TOL 1e-12

/* Signed measure of cell c: volume (3D) or area (2D), and the largest edge
 * length, so flatness is judged relative to the cell's own size. */
static double cell_measure(int dim, const double *x, const long *cell,
                           double *max_edge) {
  const int npc = dim + 1;
  double l2 = 0.0;
  for (int a = 0; a < npc; a++)
    for (int b = a + 1; b < npc; b++) {
      double s = 0.0;
      for (int k = 0; k < 3; k++) {
        double d = x[3 * cell[b] + k] - x[3 * cell[a] + k];
        s += d * d;
      }
      if (s > l2) l2 = s;
    }
  *max_edge = sqrt(l2);
  const double *p0 = x + 3 * cell[0];
  double e[3][3];
  for (int a = 1; a < npc; a++)
    for (int k = 0; k < 3; k++) e[a - 1][k] = x[3 * cell[a] + k] - p0[k];
  if (dim == 2) return 0.5 * (e[0][0] * e[1][1] - e[0][1] * e[1][0]);
  return (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
          e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
          e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
         6.0;
}

static pm_err morton_order(gm_mesh *m);

/* Flip negatively oriented cells (swap their last two nodes) and reject
 * flat ones (path, may be NULL, names the file in the message): the dual
 * construction relies on positive orientation.  A face's surface tag
 * follows the node it is opposite to. */
static pm_err orient_cells(gm_mesh *m, const char *path) {
  const int npc = m->nodes_per_cell;
  for (long c = 0; c < m->n_cells; c++) {
    long *cell = m->cells + (size_t)npc * c;
    double h;
    double v = cell_measure(m->dim, m->x, cell, &h);
    double scale = m->dim == 3 ? h * h * h : h * h;
    PM_CHECK(fabs(v) > GM_FLAT_TOL * scale, PM_ERR_GEOMETRY,
             "cell %ld%s%s%s has zero %s (%g)", c, path ? " of '" : "",
             path ? path : "", path ? "'" : "", m->dim == 3 ? "volume" : "area",
             v);
    if (v < 0.0) {
      long t = cell[npc - 1];
      cell[npc - 1] = cell[npc - 2];
      cell[npc - 2] = t;
      if (m->face_surface) {
        int *fs = m->face_surface + (size_t)npc * c;
        int u = fs[npc - 1];
        fs[npc - 1] = fs[npc - 2];
        fs[npc - 2] = u;
      }
    }
  }
  return PM_SUCCESS;
}

/* Frees the mesh and its arrays; NULL is a no-op. */
void gm_mesh_destroy(gm_mesh *m) {
  if (!m) return;
  free(m->x);
  free(m->cells);
  gm_surface_drop(m);
  free(m);
}

/* Copies the caller's arrays after checking them, orients the cells and
 * names the box faces. */
pm_err gm_mesh_from_arrays(int dim, long n_nodes, const double *x, long n_cells,
                           const long *cells, const double box_min[3],
                           const double box_max[3], gm_mesh **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_mesh_from_arrays: out is NULL");
  *out = NULL;
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG, "mesh dimension %d is not 2 or 3",
           dim);
  PM_CHECK(n_nodes > 0 && n_cells > 0, PM_ERR_ARG,
           "mesh needs nodes and cells (got %ld nodes, %ld cells)", n_nodes,
           n_cells);
  PM_CHECK(x && cells, PM_ERR_ARG, "mesh arrays are NULL");
  PM_CHECK(box_min && box_max, PM_ERR_ARG, "mesh box is NULL");
  for (int k = 0; k < dim; k++)
    PM_CHECK(box_max[k] > box_min[k], PM_ERR_ARG,
             "empty box along axis %d: [%g, %g]", k, box_min[k], box_max[k]);
  const int npc = dim + 1;
  for (long i = 0; i < (long)npc * n_cells; i++)
    PM_CHECK(cells[i] >= 0 && cells[i] < n_nodes, PM_ERR_ARG,
             "cell %ld refers to node %ld of %ld", i / npc, cells[i], n_nodes);
  for (long i = 0; i < 3 * n_nodes; i++)
    PM_CHECK(isfinite(x[i]), PM_ERR_ARG, "node %ld has a non-finite coordinate",
             i / 3);

  pm_err ret = PM_SUCCESS;
  gm_mesh *m = NULL;
  PM_TRY(PM_ALLOC(m, 1, "mesh"));
  PM_TRY(PM_ALLOC(m->x, 3 * n_nodes, "mesh coordinates"));
  PM_TRY(PM_ALLOC(m->cells, (size_t)npc * n_cells, "mesh cells"));
  m->dim = dim;
  m->n_nodes = n_nodes;
  m->n_cells = n_cells;
  m->nodes_per_cell = npc;
  memcpy(m->x, x, sizeof(double) * 3 * (size_t)n_nodes);
  memcpy(m->cells, cells, sizeof(long) * (size_t)npc * n_cells);
  for (int k = 0; k < 3; k++) {
    m->box_min[k] = box_min[k];
    m->box_max[k] = box_max[k];
  }
  /* 2D meshes live in the z = 0 plane whatever the caller passed. */
  if (dim == 2) {
    for (long i = 0; i < n_nodes; i++) m->x[3 * i + 2] = 0.0;
    m->box_min[2] = m->box_max[2] = 0.0;
  }
  PM_TRY(orient_cells(m, NULL));
  PM_TRY(gm_surface_name_box(m));
  *out = m;
  m = NULL;
done:
  gm_mesh_destroy(m);
  return ret;
}

/* A new mesh taking over raw's nodes and elements (raw keeps its groups). */
static pm_err mesh_from_raw(gm_gmsh_mesh *raw, gm_mesh **out) {
  gm_mesh *m = NULL;
  PM_CALL(PM_ALLOC(m, 1, "mesh"));
  m->dim = raw->dim;
  m->nodes_per_cell = raw->dim + 1;
  m->n_nodes = raw->n_nodes;
  m->x = raw->x;
  m->n_cells = raw->n_elems;
  m->cells = raw->elem;
  raw->x = NULL;
  raw->elem = NULL;
  *out = m;
  return PM_SUCCESS;
}

/* Not thread-safe: gmsh keeps global state, initialized and finalized here. */
pm_err gm_mesh_box(int dim, const double min[3], const double max[3], double h,
                   gm_mesh **out) {
  return gm_mesh_box_graded(dim, min, max, h, NULL, out);
}

/* The distance from x to the nearest graded face, or to the nearest edge
 * bounding a graded face: in 3D the line where the face meets a face across
 * axis b, in 2D that line's trace, the corner (the same expression). */
static double grade_distance(const gm_grade *g, int dim, const double min[3],
                             const double max[3], const double x[3]) {
  double d = INFINITY;
  for (int f = 0; f < 2 * dim; f++) {
    if (!(g->faces & (1u << f))) continue;
    const int a = f / 2;
    const double da = x[a] - ((f % 2) ? max[a] : min[a]);
    if (!g->edges) {
      d = fmin(d, fabs(da));
      continue;
    }
    for (int b = 0; b < dim; b++)
      if (b != a)
        d = fmin(d, fmin(hypot(da, x[b] - min[b]), hypot(da, x[b] - max[b])));
  }
  return d;
}

double gm_grade_size(const gm_grade *g, int dim, const double min[3],
                     const double max[3], double h, const double x[3]) {
  if (!g || !g->faces) return h;
  const double d = grade_distance(g, dim, min, max, x);
  if (d >= g->distance) return h;
  return g->size + (h - g->size) * d / g->distance;
}

/* The gmsh tags of the graded faces (surfaces in 3D, curves in 2D), or of
 * the edges bounding them (curves in 3D, points in 2D), each once, into
 * tags[*n] (at most 12). */
static pm_err grade_entities(int dim, const double min[3], const double max[3],
                             const gm_grade *g, double tags[12], size_t *n) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  *n = 0;
  /* Wide enough for OpenCASCADE's enlarged bounding boxes, far from the
   * opposite face. */
  double eps = INFINITY;
  for (int k = 0; k < dim; k++) eps = fmin(eps, 1e-3 * (max[k] - min[k]));
  const int edim = g->edges ? dim - 2 : dim - 1;
  for (int f = 0; f < 2 * dim; f++) {
    if (!(g->faces & (1u << f))) continue;
    double lo[3] = {min[0] - eps, min[1] - eps, dim == 3 ? min[2] - eps : -eps};
    double hi[3] = {max[0] + eps, max[1] + eps, dim == 3 ? max[2] + eps : eps};
    const double plane = (f % 2) ? max[f / 2] : min[f / 2];
    lo[f / 2] = plane - eps;
    hi[f / 2] = plane + eps;
    int *dt = NULL;
    size_t ndt = 0;
    gmshModelGetEntitiesInBoundingBox(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
                                      &dt, &ndt, edim, &ierr);
    GM_GMSH_CHECK("finding a graded face", NULL);
    for (size_t i = 0; i + 1 < ndt && *n < 12; i += 2) {
      size_t j = 0;
      while (j < *n && tags[j] != dt[i + 1]) j++;
      if (j == *n) tags[(*n)++] = dt[i + 1];
    }
    gmshFree(dt);
  }
done:
  return ret;
}

/* The Distance field on the graded faces or edges and the Threshold field
 * from it, as the background mesh. */
static pm_err grade_fields(int dim, const double min[3], const double max[3],
                           double h, const gm_grade *g) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  double tags[12];
  size_t n = 0;
  PM_TRY(grade_entities(dim, min, max, g, tags, &n));
  const int dist = gmshModelMeshFieldAdd("Distance", -1, &ierr);
  GM_GMSH_CHECK("adding the Distance field", NULL);
  const int edim = g->edges ? dim - 2 : dim - 1;
  const char *list[] = {"NodesList", "EdgesList", "FacesList"};
  gmshModelMeshFieldSetNumbers(dist, list[edim], tags, n, &ierr);
  GM_GMSH_CHECK("setting the graded faces", NULL);
  if (g->edges && edim == 1) {
    /* Samples along each curve a quarter of the graded size apart (gmsh's
     * default 20 a curve would put steps in the distance). */
    double len = 0.0;
    for (int k = 0; k < dim; k++) len = fmax(len, max[k] - min[k]);
    gmshModelMeshFieldSetNumber(dist, "NNodesByEdge",
                                fmax(20.0, ceil(4.0 * len / g->size)), &ierr);
    GM_GMSH_CHECK("NNodesByEdge", NULL);
  }
  const int thr = gmshModelMeshFieldAdd("Threshold", -1, &ierr);
  GM_GMSH_CHECK("adding the Threshold field", NULL);
  const struct {
    const char *name;
    double value;
  } opt[] = {{"IField", dist},
             {"LcMin", g->size},
             {"LcMax", h},
             {"DistMin", 0.0},
             {"DistMax", g->distance}};
  for (size_t i = 0; i < sizeof opt / sizeof opt[0]; i++) {
    gmshModelMeshFieldSetNumber(thr, opt[i].name, opt[i].value, &ierr);
    GM_GMSH_CHECK(opt[i].name, NULL);
  }
  gmshModelMeshFieldSetAsBackgroundMesh(thr, &ierr);
  GM_GMSH_CHECK("setting the background mesh", NULL);
  gmshOptionSetNumber("Mesh.MeshSizeMin", g->size, &ierr);
  GM_GMSH_CHECK("Mesh.MeshSizeMin", NULL);
  gmshOptionSetNumber("Mesh.MeshSizeExtendFromBoundary", 0, &ierr);
  GM_GMSH_CHECK("Mesh.MeshSizeExtendFromBoundary", NULL);
done:
  return ret;
}

/* Not thread-safe: gmsh keeps global state, initialized and finalized here. */
pm_err gm_mesh_box_raw_here(int dim, const double min[3], const double max[3],
                            double h, const gm_grade *g, gm_gmsh_mesh *raw) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  gm_gmsh_session session = {.threads = 0, .open = false};
  PM_TRY(gm_gmsh_begin(&session, NULL));
  PM_TRY(gm_gmsh_size(h, NULL));
  gmshModelAdd("pointmech_box", &ierr);
  GM_GMSH_CHECK("model add", NULL);
  if (dim == 3)
    gmshModelOccAddBox(min[0], min[1], min[2], max[0] - min[0], max[1] - min[1],
                       max[2] - min[2], -1, &ierr);
  else
    gmshModelOccAddRectangle(min[0], min[1], 0.0, max[0] - min[0],
                             max[1] - min[1], -1, 0.0, &ierr);
  GM_GMSH_CHECK("adding the box", NULL);
  gmshModelOccSynchronize(&ierr);
  GM_GMSH_CHECK("synchronize", NULL);
  if (g && g->faces) PM_TRY(grade_fields(dim, min, max, h, g));
  gmshModelMeshGenerate(dim, &ierr);
  GM_GMSH_CHECK("mesh generation", NULL);
  PM_TRY(gm_gmsh_read(NULL, dim, false, raw));
done:
  gm_gmsh_end(&session);
  return ret;
}

/* gmsh meshes the box in a child process (gm_mesh_box_raw): its libraries
 * and the model it keeps after finalizing are never the process's. */
pm_err gm_mesh_box_graded(int dim, const double min[3], const double max[3],
                          double h, const gm_grade *g, gm_mesh **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_mesh_box: out is NULL");
  *out = NULL;
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG, "mesh dimension %d is not 2 or 3",
           dim);
  PM_CHECK(min && max, PM_ERR_ARG, "gm_mesh_box: box is NULL");
  PM_CHECK(isfinite(h) && h > 0.0, PM_ERR_ARG,
           "mesh size h must be positive (got %g)", h);
  for (int k = 0; k < dim; k++)
    PM_CHECK(isfinite(min[k]) && isfinite(max[k]) && max[k] > min[k],
             PM_ERR_ARG, "empty box along axis %d: [%g, %g]", k, min[k],
             max[k]);
  if (g && g->faces) {
    PM_CHECK(isfinite(g->size) && g->size > 0.0 && g->size <= h, PM_ERR_ARG,
             "graded size must be in (0, %g] (got %g)", h, g->size);
    PM_CHECK(isfinite(g->distance) && g->distance > 0.0, PM_ERR_ARG,
             "grading distance must be positive (got %g)", g->distance);
    PM_CHECK(g->faces < (1u << (2 * dim)), PM_ERR_ARG,
             "graded faces 0x%x: a face the dimension %d has not", g->faces,
             dim);
  }

  pm_err ret = PM_SUCCESS;
  gm_mesh *m = NULL;
  gm_gmsh_mesh raw = {.dim = 0};
  PM_TRY(gm_mesh_box_raw(dim, min, max, h, g, &raw));
  PM_TRY(mesh_from_raw(&raw, &m));
  for (int k = 0; k < 3; k++) {
    m->box_min[k] = k < dim ? min[k] : 0.0;
    m->box_max[k] = k < dim ? max[k] : 0.0;
  }
  PM_TRY(morton_order(m));
  PM_TRY(orient_cells(m, NULL));
  PM_TRY(gm_surface_name_box(m));
  *out = m;
  m = NULL;
done:
  gm_gmsh_mesh_free(&raw);
  gm_mesh_destroy(m);
  return ret;
}

/* Not thread-safe: gm_gmsh_load runs a gmsh session of its own. */
pm_err gm_mesh_file(const char *path, int dim, double h, gm_sizes rule,
                    gm_mesh **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_mesh_file: out is NULL");
  *out = NULL;
  pm_err ret = PM_SUCCESS;
  gm_mesh *m = NULL;
  gm_gmsh_mesh raw = {.dim = 0};
  PM_TRY(gm_gmsh_load(path, dim, h, rule, true, &raw));
  PM_TRY(mesh_from_raw(&raw, &m));
  m->meshed = raw.meshed;
  m->size_factor = raw.size_factor;
  for (int k = 0; k < 3; k++) {
    m->box_min[k] = m->box_max[k] = m->x[k];
    for (long i = 1; i < m->n_nodes; i++) {
      m->box_min[k] = fmin(m->box_min[k], m->x[3 * i + k]);
      m->box_max[k] = fmax(m->box_max[k], m->x[3 * i + k]);
    }
  }
  /* Tags first, in gmsh's numbering: they follow the cells' own nodes
   * through the renumbering and the reorientation. */
  PM_TRY(gm_surface_from_groups(m, &raw));
  PM_TRY(morton_order(m));
  PM_TRY(orient_cells(m, path));
  *out = m;
  m = NULL;
done:
  gm_gmsh_mesh_free(&raw);
  gm_mesh_destroy(m);
  return ret;
}

/* Spread the low 21 bits of v so that two zero bits follow each. */
static unsigned long long spread3(unsigned long long v) {
  v &= 0x1fffffull;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

typedef struct {
  unsigned long long key;
  long node;
} morton_entry;

static int cmp_morton(const void *a, const void *b) {
  const morton_entry *x = a, *y = b;
  if (x->key != y->key) return (x->key > y->key) - (x->key < y->key);
  return (x->node > y->node) - (x->node < y->node);
}

/* Renumber nodes along a Morton (Z-order) curve of the box so that mesh
 * neighbours sit close in memory: the solvers gather neighbour data every
 * step, and gmsh's own numbering scatters it. */
static pm_err morton_order(gm_mesh *m) {
  pm_err ret = PM_SUCCESS;
  morton_entry *e = NULL;
  long *new_of = NULL;
  double *x = NULL;
  const long n = m->n_nodes;
  PM_TRY(PM_ALLOC(e, n, "node ordering"));
  PM_TRY(PM_ALLOC(new_of, n, "node ordering"));
  PM_TRY(PM_ALLOC(x, 3 * n, "node ordering"));
  for (long i = 0; i < n; i++) {
    unsigned long long key = 0;
    for (int a = 0; a < m->dim; a++) {
      double span = m->box_max[a] - m->box_min[a];
      double s = span > 0 ? (m->x[3 * i + a] - m->box_min[a]) / span : 0;
      s = s < 0 ? 0 : (s > 1 ? 1 : s);
      key |= spread3((unsigned long long)(s * 2097151.0)) << a;
    }
    e[i].key = key;
    e[i].node = i;
  }
  qsort(e, n, sizeof *e, cmp_morton);
  for (long k = 0; k < n; k++) {
    new_of[e[k].node] = k;
    for (int a = 0; a < 3; a++) x[3 * k + a] = m->x[3 * e[k].node + a];
  }
  for (long c = 0; c < m->n_cells * m->nodes_per_cell; c++)
    m->cells[c] = new_of[m->cells[c]];
  free(m->x);
  m->x = x;
  x = NULL;
done:
  free(e);
  free(new_of);
  free(x);
  return ret;
}

static int cmp_u64(const void *a, const void *b) {
  unsigned long long x = *(const unsigned long long *)a;
  unsigned long long y = *(const unsigned long long *)b;
  return (x > y) - (x < y);
}

/* Each edge counted once however many cells share it; NAN when memory for
 * the edge list cannot be had (a reporting figure, not worth an error). */
double gm_mesh_volume(const gm_mesh *m) {
  if (!m || !m->x || !m->cells) return 0.0;
  double vol = 0.0, h;
  for (long c = 0; c < m->n_cells; c++)
    vol += fabs(cell_measure(m->dim, m->x,
                             m->cells + (size_t)m->nodes_per_cell * c, &h));
  return vol;
}

double gm_mesh_mean_edge(const gm_mesh *m) {
  if (!m || m->n_cells <= 0) return NAN;
  const int npc = m->nodes_per_cell;
  const size_t per = (size_t)npc * (npc - 1) / 2;
  size_t n = per * (size_t)m->n_cells;
  unsigned long long *key = malloc(n * sizeof *key);
  if (!key) return NAN;
  size_t k = 0;
  for (long c = 0; c < m->n_cells; c++) {
    const long *cell = m->cells + (size_t)npc * c;
    for (int a = 0; a < npc; a++)
      for (int b = a + 1; b < npc; b++) {
        unsigned long long i = (unsigned long long)cell[a];
        unsigned long long j = (unsigned long long)cell[b];
        if (i > j) {
          unsigned long long t = i;
          i = j;
          j = t;
        }
        key[k++] = i * (unsigned long long)m->n_nodes + j;
      }
  }
  qsort(key, n, sizeof *key, cmp_u64);
  double sum = 0.0;
  size_t n_edges = 0;
  for (size_t e = 0; e < n; e++) {
    if (e > 0 && key[e] == key[e - 1]) continue;
    long i = (long)(key[e] / (unsigned long long)m->n_nodes);
    long j = (long)(key[e] % (unsigned long long)m->n_nodes);
    double s = 0.0;
    for (int d = 0; d < 3; d++) {
      double dx = m->x[3 * j + d] - m->x[3 * i + d];
      s += dx * dx;
    }
    sum += sqrt(s);
    n_edges++;
  }
  free(key);
  return sum / (double)n_edges;
}
