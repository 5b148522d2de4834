/* gm_dual: median-dual cells of a simplex mesh: volumes, interfaces between
 * edge neighbours (CSR adjacency) and boundary facets tagged with the
 * mesh's surfaces. */
#include "gm_dual.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Tetrahedron edges (a, b) completed by (c, d) so that (a, b, c, d) is an
 * even permutation of (0, 1, 2, 3): det[b-a, c-a, d-a] keeps the cell's
 * positive sign, which fixes the orientation of the dual triangles. */
static const int tet_edge[6][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2},
                                   {1, 2, 0, 3}, {1, 3, 2, 0}, {2, 3, 0, 1}};
/* Faces of a positively oriented tetrahedron, indexed by the opposite
 * vertex, ordered so that (q - p) x (r - p) points outward. */
static const int tet_face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
/* Triangle edges (a, b) with the third vertex c, counter-clockwise. */
static const int tri_edge[3][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}};
/* Edges of a counter-clockwise triangle, indexed by the opposite vertex and
 * ordered so that the outward normal is the edge turned clockwise. */
static const int tri_face[3][2] = {{1, 2}, {2, 0}, {0, 1}};

/* Frees the dual and all its arrays; NULL is a no-op. */
void gm_dual_destroy(gm_dual *d) {
  if (!d) return;
  free(d->x);
  free(d->volume);
  free(d->nbr_ptr);
  free(d->nbr);
  free(d->nbr_iface);
  free(d->if_pair);
  free(d->if_area_vec);
  free(d->if_moment);
  free(d->if_centroid);
  free(d->if_area);
  free(d->facet_point);
  free(d->facet_surface);
  free(d->facet_area_vec);
  free(d->facet_moment);
  free(d->facet_centroid);
  free(d->facet_area);
  free(d);
}

void gm_dual_drop(gm_dual *d, bool interfaces, bool facets) {
  void **const at[] = {(void **)&d->nbr_iface,      (void **)&d->if_pair,
                       (void **)&d->if_area_vec,    (void **)&d->if_moment,
                       (void **)&d->if_centroid,    (void **)&d->if_area,
                       (void **)&d->facet_point,    (void **)&d->facet_surface,
                       (void **)&d->facet_area_vec, (void **)&d->facet_moment,
                       (void **)&d->facet_centroid, (void **)&d->facet_area};
  for (size_t k = 0; k < sizeof at / sizeof *at; k++)
    if (k < 6 ? interfaces : facets) { /* the interfaces' six first */
      free(*at[k]);
      *at[k] = NULL;
    }
  if (interfaces) d->n_ifaces = 0;
  if (facets) d->n_facets = 0;
}

static void cross(const double u[3], const double v[3], double w[3]) {
  w[0] = u[1] * v[2] - u[2] * v[1];
  w[1] = u[2] * v[0] - u[0] * v[2];
  w[2] = u[0] * v[1] - u[1] * v[0];
}

static double norm3(const double v[3]) {
  return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* Signed volume (3D) or area (2D) of cell nodes p[]. */
static double simplex_measure(int dim, const double *const p[4]) {
  double e[3][3];
  for (int a = 0; a < dim; a++)
    for (int k = 0; k < 3; k++) e[a][k] = p[a + 1][k] - p[0][k];
  if (dim == 2) return 0.5 * (e[0][0] * e[1][1] - e[0][1] * e[1][0]);
  double w[3];
  cross(e[1], e[2], w);
  return (e[0][0] * w[0] + e[0][1] * w[1] + e[0][2] * w[2]) / 6.0;
}

/* Adds a flat piece with area vector a (times sign s) and centroid c to the
 * running sums of an interface or facet; the centroid slot accumulates
 * |a| c and is divided by the area at the end. */
static void add_piece(double s, const double a[3], const double c[3],
                      double *av, double *mom, double *cen, double *area) {
  double sa[3] = {s * a[0], s * a[1], s * a[2]};
  double len = norm3(a);
  for (int p = 0; p < 3; p++) {
    av[p] += sa[p];
    cen[p] += len * c[p];
    for (int q = 0; q < 3; q++) mom[3 * p + q] += sa[p] * c[q];
  }
  *area += len;
}

/* Triangle (p, q, r): area vector (1/2)(q - p) x (r - p) and centroid. */
static void tri_piece(const double p[3], const double q[3], const double r[3],
                      double a[3], double c[3]) {
  double u[3], v[3];
  for (int k = 0; k < 3; k++) {
    u[k] = q[k] - p[k];
    v[k] = r[k] - p[k];
    c[k] = (p[k] + q[k] + r[k]) / 3.0;
  }
  cross(u, v, a);
  for (int k = 0; k < 3; k++) a[k] *= 0.5;
}

/* Segment p -> q in the z = 0 plane: normal turned clockwise from q - p,
 * times the length, and midpoint. */
static void seg_piece(const double p[3], const double q[3], double a[3],
                      double c[3]) {
  a[0] = q[1] - p[1];
  a[1] = -(q[0] - p[0]);
  a[2] = 0.0;
  for (int k = 0; k < 3; k++) c[k] = 0.5 * (p[k] + q[k]);
}

static int cmp_long(const void *a, const void *b) {
  long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* Neighbour lists are short (about 14 in 3D), so insertion sort beats qsort
 * there; qsort guards against pathological fans. */
static void sort_longs(long *v, long n) {
  if (n > 32) {
    qsort(v, (size_t)n, sizeof *v, cmp_long);
    return;
  }
  for (long i = 1; i < n; i++) {
    long t = v[i], j = i;
    while (j > 0 && v[j - 1] > t) {
      v[j] = v[j - 1];
      j--;
    }
    v[j] = t;
  }
}

/* Interface of edge (i, j), i < j, by binary search in i's sorted list. */
static long find_iface(const gm_dual *d, long i, long j) {
  long lo = d->nbr_ptr[i], hi = d->nbr_ptr[i + 1];
  while (lo < hi) {
    long mid = lo + (hi - lo) / 2;
    if (d->nbr[mid] < j)
      lo = mid + 1;
    else
      hi = mid;
  }
  PM_ASSERT(lo < d->nbr_ptr[i + 1] && d->nbr[lo] == j);
  return d->nbr_iface[lo];
}

/* Node -> incident cells, CSR. */
static pm_err build_incidence(const gm_mesh *m, long **ptr_out,
                              long **list_out) {
  pm_err ret = PM_SUCCESS;
  const int npc = m->nodes_per_cell;
  long *ptr = NULL, *list = NULL, *fill = NULL;
  PM_TRY(PM_ALLOC(ptr, m->n_nodes + 1, "node incidence"));
  PM_TRY(PM_ALLOC(list, (size_t)npc * m->n_cells, "node incidence"));
  PM_TRY(PM_ALLOC(fill, m->n_nodes, "node incidence"));
  for (long i = 0; i < (long)npc * m->n_cells; i++) ptr[m->cells[i] + 1]++;
  for (long i = 0; i < m->n_nodes; i++) {
    PM_ENSURE(ptr[i + 1] > 0, PM_ERR_GEOMETRY,
              "mesh node %ld belongs to no cell", i);
    ptr[i + 1] += ptr[i];
  }
  for (long c = 0; c < m->n_cells; c++)
    for (int a = 0; a < npc; a++) {
      long i = m->cells[(size_t)npc * c + a];
      list[ptr[i] + fill[i]++] = c;
    }
  *ptr_out = ptr;
  *list_out = list;
  ptr = list = NULL;
done:
  free(ptr);
  free(list);
  free(fill);
  return ret;
}

/* Edge adjacency (CSR, sorted) and interface numbering: interface k is the
 * k-th pair (i, j), i < j, in lexicographic order. */
static pm_err build_adjacency(const gm_mesh *m, const long *inc_ptr,
                              const long *inc, gm_dual *d) {
  pm_err ret = PM_SUCCESS;
  const int npc = m->nodes_per_cell;
  const long n = m->n_nodes;
  long *mark = NULL;
  PM_TRY(PM_ALLOC(mark, n, "adjacency marks"));
  PM_TRY(PM_ALLOC(d->nbr_ptr, n + 1, "adjacency"));
  /* Two passes (count, fill) keep memory at the final size. */
  for (int pass = 0; pass < 2; pass++) {
    for (long i = 0; i < n; i++) mark[i] = -1;
    for (long i = 0; i < n; i++) {
      long cnt = 0, base = d->nbr_ptr[i];
      for (long k = inc_ptr[i]; k < inc_ptr[i + 1]; k++) {
        const long *cell = m->cells + (size_t)npc * inc[k];
        for (int a = 0; a < npc; a++) {
          long j = cell[a];
          if (j == i || mark[j] == i) continue;
          mark[j] = i;
          if (pass == 1) d->nbr[base + cnt] = j;
          cnt++;
        }
      }
      if (pass == 0)
        d->nbr_ptr[i + 1] = base + cnt;
      else
        sort_longs(d->nbr + base, cnt);
    }
    if (pass == 0) {
      PM_TRY(PM_ALLOC(d->nbr, d->nbr_ptr[n], "adjacency"));
      PM_TRY(PM_ALLOC(d->nbr_iface, d->nbr_ptr[n], "adjacency"));
    }
  }
  d->n_ifaces = d->nbr_ptr[n] / 2;
  PM_TRY(PM_ALLOC(d->if_pair, 2 * d->n_ifaces, "interface pairs"));
  long next = 0;
  for (long i = 0; i < n; i++)
    for (long k = d->nbr_ptr[i]; k < d->nbr_ptr[i + 1]; k++) {
      long j = d->nbr[k];
      if (j > i) {
        d->if_pair[2 * next] = i;
        d->if_pair[2 * next + 1] = j;
        d->nbr_iface[k] = next++;
      } else {
        /* j < i was numbered already, from j's own list. */
        d->nbr_iface[k] = find_iface(d, j, i);
      }
    }
  PM_ASSERT(next == d->n_ifaces);
done:
  free(mark);
  return ret;
}

/* Volumes and interfaces, cell by cell. */
static pm_err build_interfaces(const gm_mesh *m, gm_dual *d) {
  pm_err ret = PM_SUCCESS;
  const int dim = m->dim, npc = m->nodes_per_cell;
  const long ni = d->n_ifaces;
  PM_TRY(PM_ALLOC(d->volume, m->n_nodes, "dual volumes"));
  PM_TRY(PM_ALLOC(d->if_area_vec, 3 * ni, "interface area vectors"));
  PM_TRY(PM_ALLOC(d->if_moment, 9 * ni, "interface moments"));
  PM_TRY(PM_ALLOC(d->if_centroid, 3 * ni, "interface centroids"));
  PM_TRY(PM_ALLOC(d->if_area, ni, "interface areas"));
  for (long c = 0; c < m->n_cells; c++) {
    const long *cell = m->cells + (size_t)npc * c;
    const double *p[4] = {NULL, NULL, NULL, NULL};
    double g[3] = {0, 0, 0};
    for (int a = 0; a < npc; a++) {
      p[a] = m->x + 3 * cell[a];
      for (int k = 0; k < 3; k++) g[k] += p[a][k] / npc;
    }
    double vol = simplex_measure(dim, p);
    PM_ENSURE(vol > 0.0, PM_ERR_GEOMETRY,
              "cell %ld is not positively oriented (measure %g)", c, vol);
    for (int a = 0; a < npc; a++) d->volume[cell[a]] += vol / npc;

    const int n_edges = dim == 3 ? 6 : 3;
    for (int e = 0; e < n_edges; e++) {
      const int *le = dim == 3 ? tet_edge[e] : tri_edge[e];
      long i = cell[le[0]], j = cell[le[1]];
      /* Pieces point from le[0] to le[1]; interfaces from i < j. */
      double s = i < j ? 1.0 : -1.0;
      long f = i < j ? find_iface(d, i, j) : find_iface(d, j, i);
      double *av = d->if_area_vec + 3 * f, *mom = d->if_moment + 9 * f;
      double *cen = d->if_centroid + 3 * f, *area = d->if_area + f;
      const double *xa = p[le[0]], *xb = p[le[1]], *xc = p[le[2]];
      double mid[3], a[3], ct[3];
      for (int k = 0; k < 3; k++) mid[k] = 0.5 * (xa[k] + xb[k]);
      if (dim == 2) {
        seg_piece(mid, g, a, ct);
        add_piece(s, a, ct, av, mom, cen, area);
        continue;
      }
      const double *xd = p[le[3]];
      double fc[3], fd[3];
      for (int k = 0; k < 3; k++) {
        fc[k] = (xa[k] + xb[k] + xc[k]) / 3.0;
        fd[k] = (xa[k] + xb[k] + xd[k]) / 3.0;
      }
      tri_piece(mid, fc, g, a, ct);
      add_piece(s, a, ct, av, mom, cen, area);
      tri_piece(mid, g, fd, a, ct);
      add_piece(s, a, ct, av, mom, cen, area);
    }
  }
  for (long f = 0; f < ni; f++) {
    PM_ENSURE(d->if_area[f] > 0.0, PM_ERR_GEOMETRY,
              "interface %ld (%ld, %ld) has zero area", f, d->if_pair[2 * f],
              d->if_pair[2 * f + 1]);
    for (int k = 0; k < 3; k++) d->if_centroid[3 * f + k] /= d->if_area[f];
  }
done:
  return ret;
}

/* Whether a cell other than c holds all nf nodes of face fn: scans the
 * incidence list of the face node with the fewest cells. */
static int face_shared(long c, const long *fn, int nf, const gm_mesh *m,
                       const long *inc_ptr, const long *inc) {
  const int npc = m->nodes_per_cell;
  long best = fn[0];
  for (int a = 1; a < nf; a++)
    if (inc_ptr[fn[a] + 1] - inc_ptr[fn[a]] < inc_ptr[best + 1] - inc_ptr[best])
      best = fn[a];
  for (long k = inc_ptr[best]; k < inc_ptr[best + 1]; k++) {
    long o = inc[k];
    if (o == c) continue;
    const long *cell = m->cells + (size_t)npc * o;
    int found = 0;
    for (int a = 0; a < nf; a++)
      for (int b = 0; b < npc; b++)
        if (cell[b] == fn[a]) {
          found++;
          break;
        }
    if (found == nf) return 1;
  }
  return 0;
}

pm_err gm_dual_alloc_facets(gm_dual *d, long nf) {
  d->n_facets = nf;
  PM_CALL(PM_ALLOC(d->facet_point, nf, "facet points"));
  PM_CALL(PM_ALLOC(d->facet_surface, nf, "facet surfaces"));
  PM_CALL(PM_ALLOC(d->facet_area_vec, 3 * nf, "facet area vectors"));
  PM_CALL(PM_ALLOC(d->facet_moment, 9 * nf, "facet moments"));
  PM_CALL(PM_ALLOC(d->facet_centroid, 3 * nf, "facet centroids"));
  PM_CALL(PM_ALLOC(d->facet_area, nf, "facet areas"));
  return PM_SUCCESS;
}

/* Boundary facets: faces of one cell only, split among their nodes. */
static pm_err build_facets(const gm_mesh *m, const long *inc_ptr,
                           const long *inc, gm_dual *d) {
  pm_err ret = PM_SUCCESS;
  const int dim = m->dim, npc = m->nodes_per_cell;
  unsigned char *bnd = NULL;
  PM_TRY(PM_ALLOC(bnd, (size_t)npc * m->n_cells, "boundary face flags"));
  long n_bnd = 0;
  for (long c = 0; c < m->n_cells; c++) {
    const long *cell = m->cells + (size_t)npc * c;
    for (int o = 0; o < npc; o++) {
      long fn[3] = {0, 0, 0};
      for (int a = 0; a < dim; a++)
        fn[a] = cell[dim == 3 ? tet_face[o][a] : tri_face[o][a]];
      if (!face_shared(c, fn, dim, m, inc_ptr, inc)) {
        bnd[(size_t)npc * c + o] = 1;
        n_bnd++;
      }
    }
  }
  const long nf = n_bnd * dim;
  PM_TRY(gm_dual_alloc_facets(d, nf));

  long f = 0;
  for (long c = 0; c < m->n_cells; c++) {
    const long *cell = m->cells + (size_t)npc * c;
    for (int o = 0; o < npc; o++) {
      if (!bnd[(size_t)npc * c + o]) continue;
      long fn[3] = {0, 0, 0};
      const double *q[3];
      for (int a = 0; a < dim; a++) {
        fn[a] = cell[dim == 3 ? tet_face[o][a] : tri_face[o][a]];
        q[a] = m->x + 3 * fn[a];
      }
      const int tag =
          m->face_surface ? m->face_surface[(size_t)npc * c + o] : -1;
      double fc[3] = {0, 0, 0};
      for (int a = 0; a < dim; a++)
        for (int k = 0; k < 3; k++) fc[k] += q[a][k] / dim;
      for (int a = 0; a < dim; a++, f++) {
        d->facet_point[f] = fn[a];
        d->facet_surface[f] = tag;
        double *av = d->facet_area_vec + 3 * f, *mom = d->facet_moment + 9 * f;
        double *cen = d->facet_centroid + 3 * f, *area = d->facet_area + f;
        double pa[3], ct[3];
        if (dim == 2) {
          /* Half edge on the node's side, keeping the outward direction. */
          if (a == 0)
            seg_piece(q[0], fc, pa, ct);
          else
            seg_piece(fc, q[1], pa, ct);
          add_piece(1.0, pa, ct, av, mom, cen, area);
        } else {
          /* Node, midpoint to next, face centroid, midpoint to previous:
           * both triangles keep the face's outward orientation. */
          const double *xp = q[a], *xn = q[(a + 1) % 3], *xr = q[(a + 2) % 3];
          double mn[3], mr[3];
          for (int k = 0; k < 3; k++) {
            mn[k] = 0.5 * (xp[k] + xn[k]);
            mr[k] = 0.5 * (xp[k] + xr[k]);
          }
          tri_piece(xp, mn, fc, pa, ct);
          add_piece(1.0, pa, ct, av, mom, cen, area);
          tri_piece(xp, fc, mr, pa, ct);
          add_piece(1.0, pa, ct, av, mom, cen, area);
        }
        PM_ENSURE(*area > 0.0, PM_ERR_GEOMETRY,
                  "boundary facet of node %ld has zero area", fn[a]);
        for (int k = 0; k < 3; k++) cen[k] /= *area;
      }
    }
  }
  PM_ASSERT(f == nf);
done:
  free(bnd);
  return ret;
}

/* Checks the mesh, then builds adjacency, interfaces and facets. */
pm_err gm_dual_build(const gm_mesh *m, gm_dual **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_dual_build: out is NULL");
  *out = NULL;
  PM_CHECK(m, PM_ERR_ARG, "gm_dual_build: mesh is NULL");
  PM_CHECK((m->dim == 2 || m->dim == 3) && m->nodes_per_cell == m->dim + 1,
           PM_ERR_ARG, "mesh of dimension %d with %d nodes per cell", m->dim,
           m->nodes_per_cell);
  PM_CHECK(m->n_nodes > 0 && m->n_cells > 0 && m->x && m->cells, PM_ERR_ARG,
           "empty mesh (%ld nodes, %ld cells)", m->n_nodes, m->n_cells);
  for (long i = 0; i < (long)m->nodes_per_cell * m->n_cells; i++)
    PM_CHECK(m->cells[i] >= 0 && m->cells[i] < m->n_nodes, PM_ERR_ARG,
             "cell %ld refers to node %ld of %ld", i / m->nodes_per_cell,
             m->cells[i], m->n_nodes);

  pm_err ret = PM_SUCCESS;
  gm_dual *d = NULL;
  long *inc_ptr = NULL, *inc = NULL;
  PM_TRY(PM_ALLOC(d, 1, "dual"));
  d->min_quality_point = -1;
  d->dim = m->dim;
  d->n_points = m->n_nodes;
  PM_TRY(PM_ALLOC(d->x, 3 * m->n_nodes, "dual points"));
  memcpy(d->x, m->x, sizeof(double) * 3 * (size_t)m->n_nodes);
  PM_TRY(build_incidence(m, &inc_ptr, &inc));
  PM_TRY(build_adjacency(m, inc_ptr, inc, d));
  PM_TRY(build_interfaces(m, d));
  PM_TRY(build_facets(m, inc_ptr, inc, d));
  *out = d;
  d = NULL;
done:
  free(inc_ptr);
  free(inc);
  gm_dual_destroy(d);
  return ret;
}
