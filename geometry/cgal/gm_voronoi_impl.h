/* gm_voronoi_impl: what the files of gm_voronoi_build share (C++17, inside
 * geometry/cgal only): small vector algebra, a cell's faces and the
 * functions of the steps from points to cells. */
#ifndef GM_VORONOI_IMPL_H
#define GM_VORONOI_IMPL_H

#include <array>
#include <cmath>
#include <utility>
#include <vector>

extern "C" {
#include "gm_voronoi.h"
}

namespace gm_voronoi_impl {

using Vec = std::array<double, 3>;

inline Vec sub(const Vec &a, const Vec &b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline double dot(const Vec &a, const Vec &b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec cross(const Vec &a, const Vec &b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
          a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec &a) { return std::sqrt(dot(a, a)); }

/* A face of a cell: its label (a neighbour j >= 0, or -1 - f for box face
 * f) and its integrals: area vector a (outward), moment M = sum_t a_t (x)
 * c_t over the fan triangles (segments in 2D), centroid and area. */
struct Face {
  long label;
  double a[3], M[9], c[3], area;
};

/* All faces of all cells, and each cell's own volume. */
struct Cells {
  std::vector<std::vector<Face>> faces;
  std::vector<double> volume;
};

/* One interface: the pair and the face data oriented from i to j. */
struct Iface {
  long i, j;
  const Face *f;
  double sign;
};

/* The Delaunay edges (i < j) of the n points x (gm_voronoi_delaunay.cpp):
 * the pairs of Voronoi neighbours before clipping.  Exact duplicates were
 * refused before, so every point is a vertex.  Throws CGAL's exceptions
 * and std::bad_alloc. */
std::vector<std::pair<long, long>> delaunay_edges(int dim, long n,
                                                  const double *x);

/* Each cell on its own (gm_voronoi_clip.cpp): the box [lo, hi] cut by the
 * bisectors of point i's neighbours nbr[ptr[i] .. ptr[i + 1]), its faces
 * and enclosed volume into cells (sized n here); vertices within vtol of
 * their canonical point are moved there.  PM_ERR_GEOMETRY for an empty
 * cell. */
pm_err clip_cells(int dim, long n, const double *x, const double lo[3],
                  const double hi[3], double vtol, const std::vector<long> &ptr,
                  const std::vector<long> &nbr, Cells &cells);

/* Index of the face labelled lab in list, or -1 (gm_voronoi_dual.cpp). */
long find_face(const std::vector<Face> &list, long lab);

/* *out: the dual of the cells with the interfaces ifs (sorted by pair) and
 * the box facets of at least tiny area (face_surface: each box face's
 * surface, or NULL for the face's index); the dropped counts recorded. */
pm_err fill_dual(int dim, long n, const double *x, const Cells &cells,
                 const std::vector<Iface> &ifs, double tiny,
                 const int *face_surface, long n_dropped_facets,
                 long n_dropped_ifaces, gm_dual **out);

/* Volumes from the faces kept (the trace of sum of moments about the
 * point, over dim), their closure (PM_ERR_GEOMETRY when they do not), and
 * the cells' quality. */
pm_err finish_cells(gm_dual *d, const Cells &cells);

} // namespace gm_voronoi_impl

#endif
