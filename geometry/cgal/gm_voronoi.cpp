/* gm_voronoi: Voronoi cells clipped to a box behind the C interface of
 * gm_voronoi.h.  CGAL's Delaunay triangulation gives each point its Voronoi
 * neighbours (gm_voronoi_delaunay.cpp); the clipped cell, convex, is the
 * box cut by the bisector planes of those neighbours (gm_voronoi_clip.cpp),
 * each face remembering the neighbour or box face that made it; the cells
 * become a gm_dual (gm_voronoi_dual.cpp).  This file checks the points,
 * runs those steps, and is the only way in: no exception leaves it. */
#include <algorithm>
#include <cmath>
#include <exception>
#include <new>
#include <utility>
#include <vector>

#include "gm_voronoi_impl.h"

using namespace gm_voronoi_impl;

namespace {

/* Refuses non-finite points, points outside the box (beyond tol) and exact
 * duplicates, naming them. */
pm_err check_points(int dim, long n, const double *x, const double lo[3],
                    const double hi[3], double tol) {
  for (long i = 0; i < n; i++) {
    const double *p = x + 3 * i;
    PM_CHECK(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]),
             PM_ERR_ARG, "point %ld has a non-finite coordinate (%g, %g, %g)",
             i, p[0], p[1], p[2]);
    for (int k = 0; k < dim; k++)
      PM_CHECK(p[k] >= lo[k] - tol && p[k] <= hi[k] + tol, PM_ERR_ARG,
               "point %ld at (%.17g, %.17g, %.17g) lies outside the domain "
               "box [%g, %g] x [%g, %g] x [%g, %g] (by more than %g along "
               "%c): Voronoi cells need every point in the domain",
               i, p[0], p[1], p[2], lo[0], hi[0], lo[1], hi[1],
               dim == 3 ? lo[2] : 0.0, dim == 3 ? hi[2] : 0.0, tol, "xyz"[k]);
  }
  std::vector<long> ord(static_cast<std::size_t>(n));
  for (long i = 0; i < n; i++) ord[i] = i;
  auto less = [x, dim](long a, long b) {
    for (int k = 0; k < dim; k++)
      if (x[3 * a + k] != x[3 * b + k]) return x[3 * a + k] < x[3 * b + k];
    return a < b;
  };
  std::sort(ord.begin(), ord.end(), less);
  for (long k = 1; k < n; k++) {
    long a = ord[k - 1], b = ord[k];
    bool same = true;
    for (int c = 0; c < dim; c++) same &= x[3 * a + c] == x[3 * b + c];
    PM_CHECK(!same, PM_ERR_ARG,
             "points %ld and %ld are duplicates, both at (%.17g, %.17g, "
             "%.17g): Voronoi cells need distinct points",
             a, b, x[3 * a], x[3 * a + 1], x[3 * a + 2]);
  }
  return PM_SUCCESS;
}

pm_err build(int dim, long n, const double *x, const double lo[3],
             const double hi[3], const int *face_surface, gm_dual **out) {
  double size = 0, vbox = 1;
  for (int k = 0; k < dim; k++) {
    size = std::max(size, hi[k] - lo[k]);
    vbox *= hi[k] - lo[k];
  }
  PM_CALL(check_points(dim, n, x, lo, hi, 1e-10 * size));
  const double spacing = std::pow(vbox / n, 1.0 / dim);
  const double tiny = GM_VORONOI_TINY_FACE * std::pow(spacing, dim - 1);
  /* A vertex computed twice differs by some epsilons of its coordinates
   * (of the box's size at most) when well-conditioned; by a fair part of
   * the spacing when not (canonical_vertex). */
  double xmax = 0;
  for (int k = 0; k < dim; k++)
    xmax = std::max(xmax, std::max(std::fabs(lo[k]), std::fabs(hi[k])));
  const double vtol = 1e-10 * spacing + 1e-13 * xmax;

  /* Voronoi neighbours, both ways (CSR), refusing near-duplicates. */
  std::vector<std::pair<long, long>> edges = delaunay_edges(dim, n, x);
  std::vector<long> ptr(static_cast<std::size_t>(n) + 1, 0), nbr;
  for (const auto &e : edges) {
    long a = e.first, b = e.second;
    double r2 = 0;
    for (int k = 0; k < dim; k++)
      r2 += (x[3 * a + k] - x[3 * b + k]) * (x[3 * a + k] - x[3 * b + k]);
    PM_CHECK(std::sqrt(r2) > 1e-10 * spacing, PM_ERR_ARG,
             "points %ld at (%.17g, %.17g, %.17g) and %ld at (%.17g, %.17g, "
             "%.17g) are %g apart, below 1e-10 of the mean spacing %g: "
             "duplicates",
             a, x[3 * a], x[3 * a + 1], x[3 * a + 2], b, x[3 * b], x[3 * b + 1],
             x[3 * b + 2], std::sqrt(r2), spacing);
    ptr[a + 1]++;
    ptr[b + 1]++;
  }
  for (long i = 0; i < n; i++) ptr[i + 1] += ptr[i];
  nbr.resize(static_cast<std::size_t>(ptr[n]));
  std::vector<long> fill(ptr.begin(), ptr.end() - 1);
  for (const auto &e : edges) {
    nbr[fill[e.first]++] = e.second;
    nbr[fill[e.second]++] = e.first;
  }
  /* Each cell on its own. */
  Cells cells;
  PM_CALL(clip_cells(dim, n, x, lo, hi, vtol, ptr, nbr, cells));

  /* Interfaces: a pair is kept when either side's face reaches the tiny
   * bound; its data come from the smaller point's side when it has the
   * face, else from the other side, reversed. */
  std::vector<Iface> ifs;
  long dropped_ifaces = 0, dropped_facets = 0;
  for (long i = 0; i < n; i++)
    for (const Face &F : cells.faces[i]) {
      if (F.label < 0) {
        dropped_facets += F.area < tiny;
        continue;
      }
      long j = F.label;
      long back = find_face(cells.faces[j], i);
      const Face *G = back >= 0 ? &cells.faces[j][back] : nullptr;
      if (j < i && G) continue; /* taken from j's side */
      if (std::max(F.area, G ? G->area : 0.0) < tiny) {
        dropped_ifaces++;
        continue;
      }
      if (i < j)
        ifs.push_back({i, j, F.area >= tiny || !G ? &F : G,
                       F.area >= tiny || !G ? 1.0 : -1.0});
      else
        ifs.push_back({j, i, &F, -1.0});
    }
  std::sort(ifs.begin(), ifs.end(), [](const Iface &a, const Iface &b) {
    return a.i != b.i ? a.i < b.i : a.j < b.j;
  });
  PM_CALL(fill_dual(dim, n, x, cells, ifs, tiny, face_surface, dropped_facets,
                    dropped_ifaces, out));
  pm_err err = finish_cells(*out, cells);
  if (err != PM_SUCCESS) {
    gm_dual_destroy(*out);
    *out = nullptr;
  }
  return err;
}

} // namespace

extern "C" pm_err gm_voronoi_build(int dim, long n, const double *x,
                                   const double lo[3], const double hi[3],
                                   const int *face_surface, gm_dual **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_voronoi_build: out is NULL");
  *out = nullptr;
  PM_CHECK(x && lo && hi, PM_ERR_ARG, "gm_voronoi_build: NULL points or box");
  PM_CHECK(dim == 2 || dim == 3, PM_ERR_ARG,
           "Voronoi cells in %d dimensions: expected 2 or 3", dim);
  PM_CHECK(n >= 1, PM_ERR_ARG, "Voronoi cells of %ld points", n);
  for (int k = 0; k < dim; k++)
    PM_CHECK(hi[k] > lo[k], PM_ERR_ARG,
             "the box for Voronoi cells is empty along axis %d ([%g, %g])", k,
             lo[k], hi[k]);
  try {
    return build(dim, n, x, lo, hi, face_surface, out);
  } catch (const std::bad_alloc &) {
    return PM_ERROR(PM_ERR_MEMORY,
                    "no memory for the Voronoi cells of %ld "
                    "points",
                    n);
  } catch (const std::exception &e) {
    return PM_ERROR(PM_ERR_GEOMETRY,
                    "CGAL failed on the Voronoi cells of %ld points: %s", n,
                    e.what());
  } catch (...) {
    return PM_ERROR(PM_ERR_GEOMETRY,
                    "CGAL failed on the Voronoi cells of %ld points (unknown "
                    "exception)",
                    n);
  }
}
