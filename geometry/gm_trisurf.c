/* gm_trisurf: the built-in surfaces (a rectangle, an icosphere) and what is
 * measured on any triangulated surface (areas, incidence, closedness,
 * volume, orientation, bounds).  Files are read in gm_trisurf_load.c. */
#include "gm_trisurf.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_tensor.h"

/* Finest icosphere: 10 4^9 + 2 = 2.6 million points. */
#define GM_TRISURF_MAX_REFINEMENT 9
/* Edges of a rectangle closer to parallel than this (|u x v| against
 * |u| |v|) make no rectangle. */
#define GM_TRISURF_PARALLEL_TOL 1e-12

void gm_trisurf_free(gm_trisurf *s) {
  if (!s) return;
  free(s->x);
  free(s->tri);
  memset(s, 0, sizeof *s);
}

/* Arrays for np points and nt triangles (s zeroed first). */
static pm_err trisurf_alloc(gm_trisurf *s, long np, long nt) {
  memset(s, 0, sizeof *s);
  pm_err ret = PM_SUCCESS;
  PM_TRY(PM_ALLOC(s->x, 3 * (size_t)np, "surface points"));
  PM_TRY(PM_ALLOC(s->tri, 3 * (size_t)nt, "surface triangles"));
  s->n_points = np;
  s->n_tris = nt;
done:
  if (ret) gm_trisurf_free(s);
  return ret;
}

/* Twice the area vector of triangle t: (b - a) x (c - a). */
static void area_vector(const gm_trisurf *s, long t, double n[3]) {
  const long *v = s->tri + 3 * t;
  const double *a = s->x + 3 * v[0], *b = s->x + 3 * v[1], *c = s->x + 3 * v[2];
  double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  pm_v_cross(e1, e2, n);
}

static bool finite3(const double v[3]) {
  return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* ---- rectangle ---------------------------------------------------------- */

pm_err gm_trisurf_rectangle(const double origin[3], const double edge_u[3],
                            const double edge_v[3], long nu, long nv,
                            gm_trisurf *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_trisurf_rectangle: out is NULL");
  memset(out, 0, sizeof *out);
  PM_CHECK(origin && edge_u && edge_v, PM_ERR_ARG,
           "gm_trisurf_rectangle: NULL origin or edge");
  PM_CHECK(nu >= 2 && nv >= 2, PM_ERR_ARG,
           "rectangle: expected at least 2 points along each edge, got nu = "
           "%ld, nv = %ld",
           nu, nv);
  PM_CHECK(nu <= LONG_MAX / 6 / nv, PM_ERR_ARG,
           "rectangle: %ld x %ld points are too many", nu, nv);
  PM_CHECK(finite3(origin) && finite3(edge_u) && finite3(edge_v), PM_ERR_ARG,
           "rectangle: expected finite origin and edges");
  double n[3];
  pm_v_cross(edge_u, edge_v, n);
  const double lu = pm_v_norm(edge_u), lv = pm_v_norm(edge_v);
  PM_CHECK(pm_v_norm(n) > GM_TRISURF_PARALLEL_TOL * lu * lv && lu > 0 && lv > 0,
           PM_ERR_ARG,
           "rectangle: expected two non-zero, non-parallel edges, got u = "
           "(%g, %g, %g), v = (%g, %g, %g)",
           edge_u[0], edge_u[1], edge_u[2], edge_v[0], edge_v[1], edge_v[2]);
  PM_CALL(trisurf_alloc(out, nu * nv, 2 * (nu - 1) * (nv - 1)));
  for (long j = 0; j < nv; j++)
    for (long i = 0; i < nu; i++) {
      const double a = (double)i / (double)(nu - 1);
      const double b = (double)j / (double)(nv - 1);
      double *p = out->x + 3 * (i + nu * j);
      for (int k = 0; k < 3; k++)
        p[k] = origin[k] + a * edge_u[k] + b * edge_v[k];
    }
  /* Quad (i, j) -> (p, p + 1, p + nu + 1) and (p, p + nu + 1, p + nu): both
   * turn counter-clockwise about u x v. */
  long *t = out->tri;
  for (long j = 0; j + 1 < nv; j++)
    for (long i = 0; i + 1 < nu; i++) {
      const long p = i + nu * j;
      const long q[6] = {p, p + 1, p + nu + 1, p, p + nu + 1, p + nu};
      memcpy(t, q, sizeof q);
      t += 6;
    }
  return PM_SUCCESS;
}

/* ---- icosphere ---------------------------------------------------------- */

/* Edge -> midpoint map of one subdivision level: open addressing on the
 * edge's two point numbers (smaller first). */
typedef struct {
  uint64_t *key; /* UINT64_MAX: empty */
  long *mid;
  size_t mask;
} edge_map;

static uint64_t edge_key(long a, long b) {
  return a < b ? (uint64_t)a << 32 | (uint64_t)b
               : (uint64_t)b << 32 | (uint64_t)a;
}

/* The midpoint of edge (a, b), pushed out to the unit sphere and appended
 * to s the first time the edge is seen. */
static long midpoint(edge_map *m, gm_trisurf *s, long a, long b) {
  const uint64_t key = edge_key(a, b);
  size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 17) & m->mask;
  while (m->key[h] != UINT64_MAX) {
    if (m->key[h] == key) return m->mid[h];
    h = (h + 1) & m->mask;
  }
  const long p = s->n_points++;
  double *x = s->x + 3 * p;
  for (int k = 0; k < 3; k++) x[k] = s->x[3 * a + k] + s->x[3 * b + k];
  const double r = pm_v_norm(x);
  for (int k = 0; k < 3; k++) x[k] /= r;
  m->key[h] = key;
  m->mid[h] = p;
  return p;
}

/* The icosahedron on the unit sphere: its 12 points and 20 faces,
 * counter-clockwise seen from outside. */
static void icosahedron(gm_trisurf *s, long *tri) {
  const double g = (1.0 + sqrt(5.0)) / 2.0;
  const double p[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                           {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                           {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  static const long f[20][3] = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
      {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
      {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
      {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  const double r = sqrt(1.0 + g * g);
  for (int i = 0; i < 12; i++)
    for (int k = 0; k < 3; k++) s->x[3 * i + k] = p[i][k] / r;
  s->n_points = 12;
  memcpy(tri, f, sizeof f);
}

pm_err gm_trisurf_sphere(const double center[3], double radius, int refinement,
                         gm_trisurf *out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_trisurf_sphere: out is NULL");
  memset(out, 0, sizeof *out);
  PM_CHECK(center && finite3(center), PM_ERR_ARG,
           "sphere: expected a finite centre");
  PM_CHECK(isfinite(radius) && radius > 0, PM_ERR_ARG,
           "sphere: expected a radius > 0, got %g", radius);
  PM_CHECK(refinement >= 0 && refinement <= GM_TRISURF_MAX_REFINEMENT,
           PM_ERR_ARG, "sphere: expected a refinement in [0, %d], got %d",
           GM_TRISURF_MAX_REFINEMENT, refinement);
  const long n4 = 1L << (2 * refinement);
  pm_err ret = PM_SUCCESS;
  long *from = NULL, *to = NULL;
  edge_map m = {.key = NULL, .mid = NULL, .mask = 0};
  PM_TRY(trisurf_alloc(out, 10 * n4 + 2, 20 * n4));
  /* The last level splits n_tris / 4 triangles, 3 n_tris / 8 edges: the
   * table is at most half full. */
  size_t size = 16;
  while (size < 3 * (size_t)out->n_tris / 4) size <<= 1;
  m.mask = size - 1;
  PM_TRY(PM_ALLOC(m.key, size, "edge midpoint map"));
  PM_TRY(PM_ALLOC(m.mid, size, "edge midpoint map"));
  PM_TRY(PM_ALLOC(to, 3 * (size_t)out->n_tris, "sphere triangles"));
  from = out->tri;
  icosahedron(out, from);
  long nt = 20;
  for (int level = 0; level < refinement; level++) {
    memset(m.key, 0xff, sizeof *m.key * size);
    /* (a, b, c) -> its corners' triangles and the middle one, all turning
     * the same way. */
    for (long t = 0; t < nt; t++) {
      const long a = from[3 * t], b = from[3 * t + 1], c = from[3 * t + 2];
      const long ab = midpoint(&m, out, a, b), bc = midpoint(&m, out, b, c);
      const long ca = midpoint(&m, out, c, a);
      const long q[12] = {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca};
      memcpy(to + 12 * t, q, sizeof q);
    }
    long *swap = from;
    from = to;
    to = swap;
    nt *= 4;
  }
  PM_ASSERT(nt == out->n_tris && out->n_points == 10 * n4 + 2);
  /* The finest level may sit in the scratch array: out keeps that one. */
  if (from != out->tri) {
    to = out->tri;
    out->tri = from;
  }
  for (long p = 0; p < out->n_points; p++)
    for (int k = 0; k < 3; k++)
      out->x[3 * p + k] = center[k] + radius * out->x[3 * p + k];
done:
  free(to);
  free(m.key);
  free(m.mid);
  if (ret) gm_trisurf_free(out);
  return ret;
}

/* ---- measures ----------------------------------------------------------- */

void gm_trisurf_point_areas(const gm_trisurf *s, double *area) {
  for (long p = 0; p < s->n_points; p++) area[p] = 0.0;
  for (long t = 0; t < s->n_tris; t++) {
    double n[3];
    area_vector(s, t, n);
    const double a3 = pm_v_norm(n) / 6.0;
    for (int c = 0; c < 3; c++) area[s->tri[3 * t + c]] += a3;
  }
}

/* Whether corner c of the triangle v repeats an earlier corner (a
 * degenerate triangle lists its point once). */
static bool repeated_corner(const long *v, int c) {
  return (c > 0 && v[c] == v[0]) || (c > 1 && v[c] == v[1]);
}

pm_err gm_trisurf_incidence(const gm_trisurf *s, long **start, long **tris) {
  PM_CHECK(s && start && tris, PM_ERR_ARG,
           "gm_trisurf_incidence: NULL argument");
  *start = *tris = NULL;
  pm_err ret = PM_SUCCESS;
  long *st = NULL, *list = NULL;
  PM_TRY(PM_ALLOC(st, (size_t)s->n_points + 1, "point-triangle incidence"));
  for (long t = 0; t < s->n_tris; t++)
    for (int c = 0; c < 3; c++)
      if (!repeated_corner(s->tri + 3 * t, c)) st[s->tri[3 * t + c] + 1]++;
  for (long p = 0; p < s->n_points; p++) st[p + 1] += st[p];
  PM_TRY(
      PM_ALLOC(list, (size_t)st[s->n_points] + 1, "point-triangle incidence"));
  /* Filled in triangle order, so each row is sorted; st[p] serves as the
   * cursor of row p and is shifted back after. */
  for (long t = 0; t < s->n_tris; t++)
    for (int c = 0; c < 3; c++)
      if (!repeated_corner(s->tri + 3 * t, c))
        list[st[s->tri[3 * t + c]]++] = t;
  for (long p = s->n_points; p > 0; p--) st[p] = st[p - 1];
  st[0] = 0;
  *start = st;
  *tris = list;
  st = list = NULL;
done:
  free(st);
  free(list);
  return ret;
}

/* One side of an edge: the triangle and whether it runs lo -> hi. */
typedef struct {
  long lo, hi, tri;
  int forward;
} half_edge;

static int half_edge_cmp(const void *pa, const void *pb) {
  const half_edge *a = pa, *b = pb;
  if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
  if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
  return (a->tri > b->tri) - (a->tri < b->tri);
}

#define WHY(...)                                                               \
  do {                                                                         \
    if (why && size > 0) snprintf(why, size, __VA_ARGS__);                     \
  } while (0)

/* The first edge (in sorted order) not shared by exactly two triangles in
 * opposite directions, explained in why; true when there is none. */
static bool edges_paired(const half_edge *e, long n, char *why, size_t size) {
  for (long i = 0; i < n;) {
    long j = i + 1;
    while (j < n && e[j].lo == e[i].lo && e[j].hi == e[i].hi) j++;
    const long k = j - i;
    if (k == 1) {
      WHY("edge (%ld, %ld) belongs to 1 triangle (%ld): the surface has a "
          "hole",
          e[i].lo, e[i].hi, e[i].tri);
      return false;
    }
    if (k > 2) {
      WHY("edge (%ld, %ld) belongs to %ld triangles (%ld, %ld, %ld%s): the "
          "surface is not a manifold",
          e[i].lo, e[i].hi, k, e[i].tri, e[i + 1].tri, e[i + 2].tri,
          k > 3 ? ", ..." : "");
      return false;
    }
    if (e[i].forward == e[i + 1].forward) {
      WHY("triangles %ld and %ld run edge (%ld, %ld) the same way: "
          "inconsistent orientation",
          e[i].tri, e[i + 1].tri, e[i].lo, e[i].hi);
      return false;
    }
    i = j;
  }
  return true;
}

bool gm_trisurf_closed(const gm_trisurf *s, char *why, size_t size) {
  if (why && size > 0) why[0] = '\0';
  if (!s || s->n_tris <= 0) {
    WHY("the surface has no triangle");
    return false;
  }
  half_edge *e = malloc(sizeof *e * 3 * (size_t)s->n_tris);
  if (!e) {
    WHY("no memory to check the %ld triangles' edges", s->n_tris);
    return false;
  }
  bool closed = true;
  for (long t = 0; t < s->n_tris && closed; t++)
    for (int c = 0; c < 3; c++) {
      const long a = s->tri[3 * t + c], b = s->tri[3 * t + (c + 1) % 3];
      if (a < 0 || a >= s->n_points) {
        WHY("triangle %ld refers to point %ld, not in [0, %ld)", t, a,
            s->n_points);
        closed = false;
        break;
      }
      if (a == b) {
        WHY("triangle %ld lists point %ld twice: the surface is degenerate", t,
            a);
        closed = false;
        break;
      }
      e[3 * t + c] = (half_edge){a < b ? a : b, a < b ? b : a, t, a < b};
    }
  if (closed) {
    qsort(e, 3 * (size_t)s->n_tris, sizeof *e, half_edge_cmp);
    closed = edges_paired(e, 3 * s->n_tris, why, size);
  }
  free(e);
  return closed;
}

double gm_trisurf_volume(const gm_trisurf *s) {
  if (!s || s->n_points <= 0) return 0.0;
  /* The divergence theorem on cones from the first point: nearer than
   * the origin, so less cancellation for a surface far from it. */
  const double *o = s->x;
  double v = 0.0;
  for (long t = 0; t < s->n_tris; t++) {
    const long *c = s->tri + 3 * t;
    double a[3], b[3], d[3], n[3];
    for (int k = 0; k < 3; k++) {
      a[k] = s->x[3 * c[0] + k] - o[k];
      b[k] = s->x[3 * c[1] + k] - o[k];
      d[k] = s->x[3 * c[2] + k] - o[k];
    }
    pm_v_cross(b, d, n);
    v += pm_v_dot(a, n);
  }
  return v / 6.0;
}

void gm_trisurf_orient_outward(gm_trisurf *s) {
  if (!s || gm_trisurf_volume(s) >= 0.0) return;
  for (long t = 0; t < s->n_tris; t++) {
    long *c = s->tri + 3 * t;
    const long b = c[1];
    c[1] = c[2];
    c[2] = b;
  }
}

void gm_trisurf_bounds(const gm_trisurf *s, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; k++) lo[k] = hi[k] = 0.0;
  if (!s || s->n_points <= 0) return;
  for (int k = 0; k < 3; k++) lo[k] = hi[k] = s->x[k];
  for (long p = 1; p < s->n_points; p++)
    for (int k = 0; k < 3; k++) {
      lo[k] = fmin(lo[k], s->x[3 * p + k]);
      hi[k] = fmax(hi[k], s->x[3 * p + k]);
    }
}
