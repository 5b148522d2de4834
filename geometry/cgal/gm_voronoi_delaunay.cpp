/* gm_voronoi_delaunay: the Voronoi neighbours of a set of points, the edges
 * of CGAL's Delaunay triangulation (2D or 3D, exact predicates).  The only
 * file of the Voronoi cells that includes CGAL. */
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <utility>
#include <vector>

#include "gm_voronoi_impl.h"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb3 = CGAL::Triangulation_vertex_base_with_info_3<long, Kernel>;
using Tds3 = CGAL::Triangulation_data_structure_3<Vb3>;
using Delaunay3 = CGAL::Delaunay_triangulation_3<Kernel, Tds3>;
using Vb2 = CGAL::Triangulation_vertex_base_with_info_2<long, Kernel>;
using Tds2 = CGAL::Triangulation_data_structure_2<Vb2>;
using Delaunay2 = CGAL::Delaunay_triangulation_2<Kernel, Tds2>;

} // namespace

namespace gm_voronoi_impl {

std::vector<std::pair<long, long>> delaunay_edges(int dim, long n,
                                                  const double *x) {
  std::vector<std::pair<long, long>> edges;
  if (dim == 3) {
    std::vector<std::pair<Delaunay3::Point, long>> pts;
    pts.reserve(static_cast<std::size_t>(n));
    for (long i = 0; i < n; i++)
      pts.emplace_back(Delaunay3::Point(x[3 * i], x[3 * i + 1], x[3 * i + 2]),
                       i);
    Delaunay3 dt(pts.begin(), pts.end());
    for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
      long a = e->first->vertex(e->second)->info();
      long b = e->first->vertex(e->third)->info();
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  } else {
    std::vector<std::pair<Delaunay2::Point, long>> pts;
    pts.reserve(static_cast<std::size_t>(n));
    for (long i = 0; i < n; i++)
      pts.emplace_back(Delaunay2::Point(x[3 * i], x[3 * i + 1]), i);
    Delaunay2 dt(pts.begin(), pts.end());
    for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
      long a = e->first->vertex(Delaunay2::cw(e->second))->info();
      long b = e->first->vertex(Delaunay2::ccw(e->second))->info();
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

} // namespace gm_voronoi_impl
