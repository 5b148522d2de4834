/* gm_trisurf_load: a triangulated surface from a file gmsh reads: its 2-D
 * elements as triangles by their corners, with the points an STL repeats
 * merged through a hash of cells the size of the merging tolerance. */
#include "gm_trisurf.h"

#include "gm_gmsh_api.h" /* gmshc.h, through the table */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "gm_gmsh.h"
#include "pm_tensor.h"

/* Points closer than this fraction of the bounding box's diagonal are one
 * point. */
#define GM_TRISURF_MERGE_TOL 1e-10
/* A triangle with less area than this fraction of its longest edge squared
 * is degenerate (as flat simplices in gm_volume). */
#define GM_TRISURF_FLAT_TOL 1e-12

/* ---- the elements ------------------------------------------------------- */

/* Frees an array of n arrays gmsh allocated. */
static void free_nested(size_t **a, size_t n) {
  if (!a) return;
  for (size_t i = 0; i < n; i++)
    if (a[i]) gmshFree(a[i]);
  gmshFree(a);
}

/* Nodes per element of gmsh type `type`, after checking that it is a
 * triangle or a quadrangle (of any order): *corners 3 or 4. */
static pm_err surface_type(const char *path, int type, int *corners,
                           size_t *all) {
  pm_err ret = PM_SUCCESS;
  char *tname = NULL;
  double *local = NULL;
  size_t n_local = 0;
  int edim = 0, order = 0, nodes = 0, ierr = 0;
  gmshModelMeshGetElementProperties(type, &tname, &edim, &order, &nodes, &local,
                                    &n_local, corners, &ierr);
  GM_GMSH_CHECK("reading element properties in", path);
  PM_ENSURE(*corners == 3 || *corners == 4, PM_ERR_MESH,
            "'%s' has 2-D elements '%s' (gmsh type %d, %d corners): only "
            "triangles and quadrangles make a surface",
            path, tname ? tname : "?", type, *corners);
  PM_ENSURE(nodes >= *corners, PM_ERR_MESH,
            "gmsh gives %d nodes to its element type %d of %d corners", nodes,
            type, *corners);
  *all = (size_t)nodes;
done:
  if (tname) gmshFree(tname);
  if (local) gmshFree(local);
  return ret;
}

/* Appends the corner node tags of every 2-D element of the open model to
 * *tags as triangles, 3 tags each (*tags grows with realloc; *n counts the
 * triangles): a quadrangle (a, b, c, d) gives (a, b, c) and (a, c, d).
 * gmsh's getElements, not getElementsByType: on a surface that mixes
 * orders of one element (3- and 6-node triangles), gmsh 4.8's
 * getElementsByType writes past its own array, while getElements lists
 * the order of the surface's first element alone. */
static pm_err read_triangles(const char *path, size_t **tags, long *n) {
  pm_err ret = PM_SUCCESS;
  int ierr = 0, *types = NULL;
  size_t n_types = 0, **etags = NULL, *n_etags = NULL, nn_etags = 0;
  size_t **enodes = NULL, *n_enodes = NULL, nn_enodes = 0;
  gmshModelMeshGetElements(&types, &n_types, &etags, &n_etags, &nn_etags,
                           &enodes, &n_enodes, &nn_enodes, 2, -1, &ierr);
  GM_GMSH_CHECK("reading the surface elements of", path);
  PM_ENSURE(nn_etags == n_types && nn_enodes == n_types, PM_ERR_MESH,
            "gmsh returned %zu element types but %zu and %zu lists for '%s'",
            n_types, nn_etags, nn_enodes, path);
  for (size_t t = 0; t < n_types; t++) {
    int corners = 0;
    size_t all = 0;
    PM_TRY(surface_type(path, types[t], &corners, &all));
    const size_t ne = n_etags[t];
    PM_ENSURE(n_enodes[t] == all * ne, PM_ERR_MESH,
              "gmsh returned %zu nodes for %zu elements of '%s'", n_enodes[t],
              ne, path);
    const size_t split = (size_t)corners - 2; /* triangles per element */
    if (ne > 0) {
      size_t *grown =
          realloc(*tags, sizeof **tags * 3 * ((size_t)*n + split * ne));
      PM_ENSURE(grown, PM_ERR_MEMORY, "no memory for %zu elements of '%s'",
                (size_t)*n + split * ne, path);
      *tags = grown;
    }
    /* gmsh lists an element's corner nodes first, in order around it. */
    for (size_t e = 0; e < ne; e++) {
      const size_t *c = enodes[t] + all * e;
      for (size_t k = 0; k < split; k++, (*n)++) {
        size_t *d = *tags + 3 * (size_t)*n;
        d[0] = c[0];
        d[1] = c[k + 1];
        d[2] = c[k + 2];
      }
    }
  }
done:
  if (types) gmshFree(types);
  free_nested(etags, nn_etags);
  free_nested(enodes, nn_enodes);
  if (n_etags) gmshFree(n_etags);
  if (n_enodes) gmshFree(n_enodes);
  return ret;
}

/* ---- merging coincident points ------------------------------------------ */

/* Cells of side tol over the points' box, hashed: each lists the merged
 * points (representatives) that fell in it.  Points within tol of one
 * another lie in the same or adjacent cells. */
typedef struct {
  int64_t (*cell)[3];
  long *head; /* first representative of the slot's cell, -1: empty */
  long *next; /* the next representative of the same cell */
  size_t mask;
  double lo[3], h;
} cell_hash;

static size_t cell_slot(const cell_hash *c, const int64_t k[3]) {
  uint64_t u = (uint64_t)k[0] * 0x9E3779B97F4A7C15ull;
  u ^= (uint64_t)k[1] * 0xC2B2AE3D27D4EB4Full;
  u ^= (uint64_t)k[2] * 0x165667B19E3779F9ull;
  return (size_t)(u ^ (u >> 29)) & c->mask;
}

/* The slot of cell k: its own, or the empty one where it would go. */
static size_t cell_find(const cell_hash *c, const int64_t k[3]) {
  size_t s = cell_slot(c, k);
  while (c->head[s] >= 0 && memcmp(c->cell[s], k, sizeof c->cell[s]) != 0)
    s = (s + 1) & c->mask;
  return s;
}

/* Merges the n points x (3 per point) within tol of an earlier kept point
 * into it: the kept points are compacted to the front of x (*n_kept of
 * them, in their order), rep[i] is point i's kept number. */
static pm_err merge_points(double *x, long n, double tol, long *rep,
                           long *n_kept) {
  pm_err ret = PM_SUCCESS;
  cell_hash c = {.cell = NULL, .head = NULL, .next = NULL};
  size_t size = 16;
  while (size < 2 * (size_t)n) size <<= 1;
  c.mask = size - 1;
  c.h = tol > 0 ? tol : 1.0;
  for (int k = 0; k < 3; k++) c.lo[k] = INFINITY;
  for (long i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) c.lo[k] = fmin(c.lo[k], x[3 * i + k]);
  PM_TRY(PM_ALLOC(c.cell, size, "point merging cells"));
  PM_TRY(PM_ALLOC(c.head, size, "point merging cells"));
  PM_TRY(PM_ALLOC(c.next, (size_t)n, "point merging cells"));
  for (size_t s = 0; s < size; s++) c.head[s] = -1;
  long kept = 0;
  for (long i = 0; i < n; i++) {
    const double *p = x + 3 * i;
    int64_t k[3];
    for (int d = 0; d < 3; d++) k[d] = (int64_t)floor((p[d] - c.lo[d]) / c.h);
    rep[i] = -1;
    for (int nb = 0; nb < 27 && rep[i] < 0; nb++) {
      const int64_t q[3] = {k[0] + nb % 3 - 1, k[1] + nb / 3 % 3 - 1,
                            k[2] + nb / 9 - 1};
      for (long r = c.head[cell_find(&c, q)]; r >= 0; r = c.next[r]) {
        const double *y = x + 3 * r;
        double d[3] = {p[0] - y[0], p[1] - y[1], p[2] - y[2]};
        if (pm_v_dot(d, d) <= tol * tol) {
          rep[i] = r;
          break;
        }
      }
    }
    if (rep[i] >= 0) continue;
    /* A new kept point: moved to the front (kept <= i) and listed first
     * in its cell. */
    rep[i] = kept;
    memmove(x + 3 * kept, p, 3 * sizeof *x);
    const size_t s = cell_find(&c, k);
    if (c.head[s] < 0) memcpy(c.cell[s], k, sizeof c.cell[s]);
    c.next[kept] = c.head[s];
    c.head[s] = kept;
    kept++;
  }
  *n_kept = kept;
done:
  free(c.cell);
  free(c.head);
  free(c.next);
  return ret;
}

/* ---- the surface -------------------------------------------------------- */

static bool degenerate(const double *x, const long *v) {
  if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) return true;
  double e[3][3], n[3], l2 = 0.0;
  for (int c = 0; c < 3; c++) {
    const double *a = x + 3 * v[c], *b = x + 3 * v[(c + 1) % 3];
    for (int k = 0; k < 3; k++) e[c][k] = b[k] - a[k];
    l2 = fmax(l2, pm_v_dot(e[c], e[c]));
  }
  pm_v_cross(e[0], e[1], n);
  return !(0.5 * pm_v_norm(n) >= GM_TRISURF_FLAT_TOL * l2);
}

/* out from n triangles of corners corner (3 n, into the np points x):
 * coincident points merged, degenerate triangles and unused points
 * dropped.  x and corner are reused as scratch. */
static pm_err build_surface(const char *path, double *x, long np, long *corner,
                            long n, gm_trisurf *out) {
  pm_err ret = PM_SUCCESS;
  long *rep = NULL, *number = NULL, kept = 0, nt = 0;
  PM_TRY(PM_ALLOC(rep, (size_t)np + 1, "point merging"));
  double lo[3] = {INFINITY, INFINITY, INFINITY};
  double hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (long i = 0; i < np; i++)
    for (int k = 0; k < 3; k++) {
      PM_ENSURE(isfinite(x[3 * i + k]), PM_ERR_MESH,
                "'%s' has a point at (%g, %g, %g): expected finite "
                "coordinates",
                path, x[3 * i], x[3 * i + 1], x[3 * i + 2]);
      lo[k] = fmin(lo[k], x[3 * i + k]);
      hi[k] = fmax(hi[k], x[3 * i + k]);
    }
  const double diag[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  PM_TRY(
      merge_points(x, np, GM_TRISURF_MERGE_TOL * pm_v_norm(diag), rep, &kept));
  for (long t = 0; t < n; t++) {
    long v[3];
    for (int c = 0; c < 3; c++) v[c] = rep[corner[3 * t + c]];
    if (degenerate(x, v)) continue;
    memcpy(corner + 3 * nt++, v, sizeof v);
  }
  PM_ENSURE(nt > 0, PM_ERR_MESH,
            "all %ld surface triangles of '%s' are degenerate", n, path);
  /* Kept points no triangle uses are dropped; the rest keep their order. */
  PM_TRY(PM_ALLOC(number, (size_t)kept + 1, "point numbers"));
  for (long k = 0; k < 3 * nt; k++) number[corner[k]] = 1;
  long used = 0;
  for (long p = 0; p < kept; p++) number[p] = number[p] ? used++ : -1;
  PM_TRY(PM_ALLOC(out->x, 3 * (size_t)used, "surface points"));
  PM_TRY(PM_ALLOC(out->tri, 3 * (size_t)nt, "surface triangles"));
  for (long p = 0; p < kept; p++)
    if (number[p] >= 0)
      memcpy(out->x + 3 * number[p], x + 3 * p, 3 * sizeof *x);
  for (long k = 0; k < 3 * nt; k++) out->tri[k] = number[corner[k]];
  out->n_points = used;
  out->n_tris = nt;
done:
  free(rep);
  free(number);
  return ret;
}

pm_err gm_trisurf_load_here(const char *path, gm_trisurf *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_trisurf_load: out is NULL");
  memset(out, 0, sizeof *out);
  PM_CHECK(path && path[0], PM_ERR_ARG, "no surface file name");
  PM_CALL(gm_gmsh_check_file(path, "surface file"));
  pm_err ret = PM_SUCCESS;
  int ierr = 0;
  size_t *ctag = NULL;
  long n = 0, np = 0, *corner = NULL;
  double *x = NULL;
  gm_gmsh_nodes nodes = {0};
  gm_gmsh_session session = {.threads = 0, .open = false};
  PM_TRY(gm_gmsh_begin(&session, path));
  gmshOpen(path, &ierr);
  GM_GMSH_CHECK("reading", path);
  PM_TRY(read_triangles(path, &ctag, &n));
  if (n == 0) {
    const int dim = gmshModelGetDimension(&ierr);
    PM_FAIL(PM_ERR_MESH,
            "'%s' holds no surface element (triangle or quadrangle; the "
            "model's dimension is %d): a surface mesh is needed",
            path, ierr ? -1 : dim);
  }
  PM_TRY(PM_ALLOC(corner, 3 * (size_t)n, "surface triangles"));
  PM_TRY(gm_gmsh_corners(path, ctag, 3 * (size_t)n, corner, &x, &np, &nodes));
  PM_TRY(build_surface(path, x, np, corner, n, out));
done:
  gm_gmsh_end(&session);
  gm_gmsh_nodes_free(&nodes);
  if (ret) gm_trisurf_free(out);
  free(ctag);
  free(corner);
  free(x);
  return ret;
}
