/* gm_inside: CGAL's side-of-triangle-mesh test (a ray cast through an AABB
 * tree, exact predicates) behind the C interface of gm_inside.h.  No
 * exception leaves this file. */
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

/* The C headers (and the C headers they include) declare C functions. */
extern "C" {
#include "gm_inside.h"
}

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Side = CGAL::Side_of_triangle_mesh<Mesh, Kernel>;
using Tree = Side::AABB_tree;

namespace PMP = CGAL::Polygon_mesh_processing;

/* Whether the triangles around each point form a single fan, for a closed,
 * consistently oriented surface: the links b -> c of the point's triangles
 * (p, b, c) make one cycle.  Two cones tip to tip make two. */
bool one_fan_per_point(const gm_trisurf *s) {
  const std::size_t np = static_cast<std::size_t>(s->n_points);
  const std::size_t nc = 3 * static_cast<std::size_t>(s->n_tris);
  std::vector<std::size_t> start(np + 1, 0);
  for (std::size_t k = 0; k < nc; k++) start[s->tri[k] + 1]++;
  for (std::size_t p = 0; p < np; p++) start[p + 1] += start[p];
  std::vector<std::size_t> fill(start.begin(), start.end() - 1);
  std::vector<std::array<long, 2>> link(nc);
  for (std::size_t k = 0; k < nc; k++) {
    const long *t = s->tri + 3 * (k / 3);
    link[fill[t[k % 3]]++] = {t[(k + 1) % 3], t[(k + 2) % 3]};
  }
  for (std::size_t p = 0; p < np; p++) {
    const std::size_t b = start[p], e = start[p + 1];
    if (b == e) continue;
    /* The cycle through the point's first link must take in all of them. */
    long at = link[b][1];
    std::size_t steps = 1;
    while (at != link[b][0]) {
      std::size_t j = b;
      while (j < e && link[j][0] != at) j++;
      if (j == e || ++steps > e - b) return false;
      at = link[j][1];
    }
    if (steps != e - b) return false;
  }
  return true;
}

/* The surface's triangles as a CGAL mesh.  A closed, consistently oriented
 * surface can still touch itself at a point (two cones tip to tip): a
 * halfedge mesh needs such a point split in two, which orient_polygon_soup
 * does without moving anything.  Otherwise the triangles go in as they
 * are: CGAL's check of a soup took 160 of 260 ms at 81920 triangles. */
Mesh make_mesh(const gm_trisurf *s) {
  Mesh mesh;
  if (one_fan_per_point(s)) {
    std::vector<Mesh::Vertex_index> v;
    v.reserve(static_cast<std::size_t>(s->n_points));
    for (long p = 0; p < s->n_points; p++)
      v.push_back(mesh.add_vertex(
          Point(s->x[3 * p], s->x[3 * p + 1], s->x[3 * p + 2])));
    for (long t = 0; t < s->n_tris; t++) {
      const long *c = s->tri + 3 * t;
      if (mesh.add_face(v[c[0]], v[c[1]], v[c[2]]) == Mesh::null_face())
        throw std::runtime_error("CGAL's surface mesh refused triangle " +
                                 std::to_string(t));
    }
    return mesh;
  }
  std::vector<Point> points;
  std::vector<std::array<std::size_t, 3>> tris;
  points.reserve(static_cast<std::size_t>(s->n_points));
  tris.reserve(static_cast<std::size_t>(s->n_tris));
  for (long p = 0; p < s->n_points; p++)
    points.emplace_back(s->x[3 * p], s->x[3 * p + 1], s->x[3 * p + 2]);
  for (long t = 0; t < s->n_tris; t++)
    tris.push_back({static_cast<std::size_t>(s->tri[3 * t]),
                    static_cast<std::size_t>(s->tri[3 * t + 1]),
                    static_cast<std::size_t>(s->tri[3 * t + 2])});
  PMP::orient_polygon_soup(points, tris);
  PMP::polygon_soup_to_polygon_mesh(points, tris, mesh);
  return mesh;
}

const Tree &built(Tree &tree) {
  tree.build();
  return tree;
}

} // namespace

/* Members in the order they are built: the tree refers to the mesh, the
 * test to the tree.  The test is given the tree already built, so a query
 * never builds anything (Side_of_triangle_mesh builds its own tree on the
 * first query otherwise), and the tree is built with build(): its internal
 * lazy build (root_node) is done before any thread queries it.  Distance
 * queries, whose search tree AABB_tree also builds lazily, are not used. */
struct gm_inside {
  Mesh mesh;
  Tree tree;
  Side side;
  double lo[3], hi[3];

  explicit gm_inside(Mesh &&m)
      : mesh(std::move(m)),
        tree(faces(mesh).first, faces(mesh).second, std::as_const(mesh)),
        side(built(tree)) {
    const CGAL::Bbox_3 box = tree.bbox();
    lo[0] = box.xmin();
    lo[1] = box.ymin();
    lo[2] = box.zmin();
    hi[0] = box.xmax();
    hi[1] = box.ymax();
    hi[2] = box.zmax();
  }
};

extern "C" pm_err gm_inside_create(const gm_trisurf *s, gm_inside **out) {
  PM_CHECK(out, PM_ERR_ARG, "gm_inside_create: out is NULL");
  *out = nullptr;
  PM_CHECK(s, PM_ERR_ARG, "gm_inside_create: no surface");
  char why[256];
  PM_CHECK(gm_trisurf_closed(s, why, sizeof why), PM_ERR_ARG,
           "an inside/outside test needs a closed, consistently oriented "
           "surface: %s",
           why);
  try {
    *out = new gm_inside(make_mesh(s));
  } catch (const std::bad_alloc &) {
    return PM_ERROR(PM_ERR_MEMORY,
                    "no memory for the inside test of a surface of %ld "
                    "triangles",
                    s->n_tris);
  } catch (const std::exception &e) {
    return PM_ERROR(PM_ERR_ARG,
                    "CGAL refused the surface of %ld points and %ld "
                    "triangles: %s",
                    s->n_points, s->n_tris, e.what());
  } catch (...) {
    return PM_ERROR(PM_ERR_ARG,
                    "CGAL refused the surface of %ld points and %ld "
                    "triangles (unknown exception)",
                    s->n_points, s->n_tris);
  }
  return PM_SUCCESS;
}

extern "C" bool gm_inside_contains(const gm_inside *in, const double x[3]) {
  if (!in || !x) return false;
  if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
    return false;
  try {
    return in->side(Point(x[0], x[1], x[2])) != CGAL::ON_UNBOUNDED_SIDE;
  } catch (...) {
    /* Not expected of a built tree: counted outside rather than let an
     * exception unwind through C. */
    return false;
  }
}

extern "C" void gm_inside_bounds(const gm_inside *in, double lo[3],
                                 double hi[3]) {
  for (int k = 0; k < 3; k++) {
    lo[k] = in ? in->lo[k] : 0.0;
    hi[k] = in ? in->hi[k] : 0.0;
  }
}

extern "C" void gm_inside_destroy(gm_inside *in) { delete in; }
