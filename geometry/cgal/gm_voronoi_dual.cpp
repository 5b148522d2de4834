/* gm_voronoi_dual: the clipped cells as a gm_dual: interfaces between
 * neighbours and facets on the box, with their area vectors, moments and
 * centroids, then each cell's volume, closure and quality from them. */
#include <cmath>
#include <cstring>
#include <vector>

#include "gm_voronoi_impl.h"

namespace gm_voronoi_impl {

/* Index of the face labelled lab in list, or -1. */
long find_face(const std::vector<Face> &list, long lab) {
  for (std::size_t k = 0; k < list.size(); k++)
    if (list[k].label == lab) return static_cast<long>(k);
  return -1;
}

pm_err fill_dual(int dim, long n, const double *x, const Cells &cells,
                 const std::vector<Iface> &ifs, double tiny,
                 const int *face_surface, long n_dropped_facets,
                 long n_dropped_ifaces, gm_dual **out) {
  pm_err ret = PM_SUCCESS;
  gm_dual *d = nullptr;
  long nf = 0, ni = static_cast<long>(ifs.size()), f = 0;
  std::vector<long> fill;
  PM_TRY(PM_ALLOC(d, 1, "Voronoi cells"));
  d->dim = dim;
  d->n_points = n;
  PM_TRY(PM_ALLOC(d->x, 3 * n, "Voronoi points"));
  std::memcpy(d->x, x, sizeof(double) * 3 * static_cast<std::size_t>(n));
  PM_TRY(PM_ALLOC(d->volume, n, "Voronoi volumes"));
  PM_TRY(PM_ALLOC(d->nbr_ptr, n + 1, "Voronoi adjacency"));
  PM_TRY(PM_ALLOC(d->nbr, 2 * ni, "Voronoi adjacency"));
  PM_TRY(PM_ALLOC(d->nbr_iface, 2 * ni, "Voronoi adjacency"));
  d->n_ifaces = ni;
  PM_TRY(PM_ALLOC(d->if_pair, 2 * ni, "interface pairs"));
  PM_TRY(PM_ALLOC(d->if_area_vec, 3 * ni, "interface area vectors"));
  PM_TRY(PM_ALLOC(d->if_moment, 9 * ni, "interface moments"));
  PM_TRY(PM_ALLOC(d->if_centroid, 3 * ni, "interface centroids"));
  PM_TRY(PM_ALLOC(d->if_area, ni, "interface areas"));
  /* Adjacency: interfaces are in lexicographic order, so each point's list
   * (smaller neighbours first, from earlier pairs) comes out sorted. */
  for (const Iface &e : ifs) {
    d->nbr_ptr[e.i + 1]++;
    d->nbr_ptr[e.j + 1]++;
  }
  for (long i = 0; i < n; i++) d->nbr_ptr[i + 1] += d->nbr_ptr[i];
  fill.assign(d->nbr_ptr, d->nbr_ptr + n);
  for (long k = 0; k < ni; k++) {
    const Iface &e = ifs[k];
    d->if_pair[2 * k] = e.i;
    d->if_pair[2 * k + 1] = e.j;
    d->nbr[fill[e.i]] = e.j;
    d->nbr_iface[fill[e.i]++] = k;
    d->nbr[fill[e.j]] = e.i;
    d->nbr_iface[fill[e.j]++] = k;
    for (int p = 0; p < 3; p++) {
      d->if_area_vec[3 * k + p] = e.sign * e.f->a[p];
      d->if_centroid[3 * k + p] = e.f->c[p];
      for (int q = 0; q < 3; q++)
        d->if_moment[9 * k + 3 * p + q] = e.sign * e.f->M[3 * p + q];
    }
    d->if_area[k] = e.f->area;
  }
  for (long i = 0; i < n; i++)
    for (const Face &F : cells.faces[i])
      if (F.label < 0 && F.area >= tiny) nf++;
  PM_TRY(gm_dual_alloc_facets(d, nf));
  for (long i = 0; i < n; i++)
    for (const Face &F : cells.faces[i]) {
      if (F.label >= 0 || F.area < tiny) continue;
      int box_face = static_cast<int>(-1 - F.label);
      d->facet_point[f] = i;
      d->facet_surface[f] = face_surface ? face_surface[box_face] : box_face;
      std::memcpy(d->facet_area_vec + 3 * f, F.a, sizeof F.a);
      std::memcpy(d->facet_moment + 9 * f, F.M, sizeof F.M);
      std::memcpy(d->facet_centroid + 3 * f, F.c, sizeof F.c);
      d->facet_area[f] = F.area;
      f++;
    }
  d->n_dropped_faces = n_dropped_facets + n_dropped_ifaces;
  *out = d;
  d = nullptr;
done:
  gm_dual_destroy(d);
  return ret;
}

/* Volumes from the faces kept (the trace of sum of moments about the
 * point, over dim), their closure, and the cells' quality. */
pm_err finish_cells(gm_dual *d, const Cells &cells) {
  const int dim = d->dim;
  double qmin = HUGE_VAL;
  long worst = -1, slivers = 0, f = 0;
  for (long i = 0; i < d->n_points; i++) {
    const double *xi = d->x + 3 * i;
    double tr = 0, S = 0, sum[3] = {0, 0, 0};
    auto add = [&](double s, const double *a, const double *M, double area) {
      for (int p = 0; p < 3; p++) {
        sum[p] += s * a[p];
        tr += s * (M[4 * p] - a[p] * xi[p]);
      }
      S += area;
    };
    for (long k = d->nbr_ptr[i]; k < d->nbr_ptr[i + 1]; k++) {
      long e = d->nbr_iface[k];
      add(d->if_pair[2 * e] == i ? 1.0 : -1.0, d->if_area_vec + 3 * e,
          d->if_moment + 9 * e, d->if_area[e]);
    }
    /* facets come in the order of their points */
    for (; f < d->n_facets && d->facet_point[f] == i; f++)
      add(1.0, d->facet_area_vec + 3 * f, d->facet_moment + 9 * f,
          d->facet_area[f]);
    double V = tr / dim;
    double closure =
        std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    PM_CHECK(V > 0 && std::fabs(V - cells.volume[i]) <= 1e-9 * V,
             PM_ERR_GEOMETRY,
             "the faces of the Voronoi cell of point %ld at (%g, %g, %g) "
             "enclose %g, its polyhedron %g",
             i, xi[0], xi[1], xi[2], V, cells.volume[i]);
    PM_CHECK(closure <= 1e-9 * S, PM_ERR_GEOMETRY,
             "the faces of the Voronoi cell of point %ld at (%g, %g, %g) do "
             "not close: |sum of area vectors| = %g of %g",
             i, xi[0], xi[1], xi[2], closure, S);
    d->volume[i] = V;
    double q = dim == 3 ? 216 * V * V / (S * S * S) : 16 * V / (S * S);
    if (q < GM_VORONOI_SLIVER) slivers++;
    if (q < qmin) {
      qmin = q;
      worst = i;
    }
  }
  d->n_slivers = slivers;
  d->min_quality = qmin;
  d->min_quality_point = worst;
  return PM_SUCCESS;
}

} // namespace gm_voronoi_impl
