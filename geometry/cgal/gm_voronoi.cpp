/* gm_voronoi: Voronoi cells clipped to a box behind the C interface of
 * gm_voronoi.h.  CGAL's Delaunay triangulation gives each point its Voronoi
 * neighbours; the clipped cell, convex, is the box cut by the bisector
 * planes of those neighbours (the clip is written here), each face
 * remembering the neighbour or box face that made it.  No exception leaves
 * this file. */
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <new>
#include <utility>
#include <vector>

extern "C" {
#include "gm_voronoi.h"
#include "pm_face.h"
}

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb3 = CGAL::Triangulation_vertex_base_with_info_3<long, Kernel>;
using Tds3 = CGAL::Triangulation_data_structure_3<Vb3>;
using Delaunay3 = CGAL::Delaunay_triangulation_3<Kernel, Tds3>;
using Vb2 = CGAL::Triangulation_vertex_base_with_info_2<long, Kernel>;
using Tds2 = CGAL::Triangulation_data_structure_2<Vb2>;
using Delaunay2 = CGAL::Delaunay_triangulation_2<Kernel, Tds2>;

using Vec = std::array<double, 3>;

Vec sub(const Vec &a, const Vec &b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const Vec &a, const Vec &b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec cross(const Vec &a, const Vec &b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
          a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec &a) { return std::sqrt(dot(a, a)); }

/* The Delaunay edges (i < j) of the points: the pairs of Voronoi
 * neighbours before clipping.  Exact duplicates were refused before, so
 * every point is a vertex. */
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

/* A face of a cell: its label (a neighbour j >= 0, or -1 - f for box face
 * f) and its integrals: area vector a (outward), moment M = sum_t a_t (x)
 * c_t over the fan triangles (segments in 2D), centroid and area. */
struct Face {
  long label;
  double a[3], M[9], c[3], area;
};

/* Adds the piece with area vector a and centroid c to face f (the centroid
 * accumulates |a| c, divided by the area at the end). */
void add_piece(Face &f, const Vec &a, const Vec &c) {
  double len = norm(a);
  for (int p = 0; p < 3; p++) {
    f.a[p] += a[p];
    f.c[p] += len * c[p];
    for (int q = 0; q < 3; q++) f.M[3 * p + q] += a[p] * c[q];
  }
  f.area += len;
}

Face empty_face(long label) {
  Face f;
  std::memset(&f, 0, sizeof f);
  f.label = label;
  return f;
}

void finish_face(Face &f) {
  if (f.area > 0)
    for (double &c : f.c) c /= f.area;
}

/* What a plane does to a convex cell: leaves it whole, leaves nothing, or
 * cuts it. */
enum Side { KEEP, EMPTY, CUT };

/* The signed distances d[k] = n . (v[k] - m) of the vertices, and what the
 * plane does to the cell they span (the part n . (y - m) <= 0 is kept). */
Side sides(const std::vector<Vec> &v, const Vec &n, const Vec &m,
           std::vector<double> &d) {
  d.resize(v.size());
  bool any_out = false, any_in = false;
  for (std::size_t k = 0; k < v.size(); k++) {
    d[k] = dot(n, sub(v[k], m));
    any_out |= d[k] > 0;
    any_in |= d[k] < 0;
  }
  return !any_out ? KEEP : !any_in ? EMPTY : CUT;
}

/* Replaces vertex p of the cell of point i by the point where the planes
 * labelled lab[0 .. dim) meet: equidistant from i and the neighbours
 * among the labels, on the box planes among them.  Computed from the set
 * of points and planes alone (sorted, relative to the lowest point), so
 * every cell that has the vertex gets the same coordinates to the bit and
 * the faces of neighbouring cells close exactly.  Keeps p (the clip's own
 * coordinates) and returns false when the planes do not meet in one
 * point, or meet farther than tol from p: more than three planes through
 * a vertex, some of them nearly parallel (four nearly cocircular points
 * in a plane), make the point of these three ill-conditioned. */
bool canonical_vertex(int dim, const double *x, long i, const long *lab,
                      const double lo[3], const double hi[3], double tol,
                      Vec &p) {
  long g[4] = {i, 0, 0, 0};
  int b[3] = {0, 0, 0}, ng = 1, nb = 0;
  for (int k = 0; k < dim; k++)
    if (lab[k] >= 0)
      g[ng++] = lab[k];
    else
      b[nb++] = static_cast<int>(-1 - lab[k]);
  std::sort(g, g + ng);
  std::sort(b, b + nb);
  const double *base = x + 3 * g[0];
  double A[3][4];
  for (int r = 0; r + 1 < ng; r++) {
    const double *xg = x + 3 * g[r + 1];
    double rhs = 0;
    for (int c = 0; c < dim; c++) {
      A[r][c] = xg[c] - base[c];
      rhs += A[r][c] * A[r][c];
    }
    A[r][dim] = 0.5 * rhs;
  }
  for (int r = 0; r < nb; r++) {
    int axis = b[r] / 2;
    double *row = A[ng - 1 + r];
    for (int c = 0; c < dim; c++) row[c] = c == axis;
    row[dim] = pm_face_plane(b[r], lo, hi) - base[axis];
  }
  /* Gaussian elimination with partial pivoting. */
  for (int c = 0; c < dim; c++) {
    int piv = c;
    for (int r = c + 1; r < dim; r++)
      if (std::fabs(A[r][c]) > std::fabs(A[piv][c])) piv = r;
    if (!(std::fabs(A[piv][c]) > 0)) return false;
    for (int k = 0; k <= dim; k++) std::swap(A[c][k], A[piv][k]);
    for (int r = c + 1; r < dim; r++) {
      double f = A[r][c] / A[c][c];
      for (int k = c; k <= dim; k++) A[r][k] -= f * A[c][k];
    }
  }
  double y[3] = {0, 0, 0};
  for (int c = dim - 1; c >= 0; c--) {
    double s = A[c][dim];
    for (int k = c + 1; k < dim; k++) s -= A[c][k] * y[k];
    y[c] = s / A[c][c];
  }
  Vec q = {0, 0, 0};
  for (int c = 0; c < dim; c++) q[c] = base[c] + y[c];
  for (int r = 0; r < nb; r++) q[b[r] / 2] = pm_face_plane(b[r], lo, hi);
  if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
    return false;
  if (!(norm(sub(p, q)) <= tol)) return false;
  p = q;
  return true;
}

/* A convex polyhedron: vertices, each with the labels of three faces
 * through it, and faces (vertex cycles counter-clockwise seen from
 * outside), each labelled.  Scratch arrays live here so that cutting the
 * cells one after the other reuses their memory. */
using Labels = std::array<long, 3>;
class Polyhedron {
public:
  std::vector<Vec> v;
  std::vector<Labels> vlab;
  std::vector<std::vector<int>> face;
  std::vector<long> label;

  void box(const double lo[3], const double hi[3]) {
    v.clear();
    vlab.clear();
    for (int k = 0; k < 8; k++) {
      v.push_back({k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1],
                   k & 4 ? hi[2] : lo[2]});
      vlab.push_back({-1 - (k & 1 ? PM_FACE_XMAX : PM_FACE_XMIN),
                      -1 - (k & 2 ? PM_FACE_YMAX : PM_FACE_YMIN),
                      -1 - (k & 4 ? PM_FACE_ZMAX : PM_FACE_ZMIN)});
    }
    /* Corners k = x + 2 y + 4 z; faces in pm_face order, outward. */
    static const int quad[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                   {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    face.assign(6, std::vector<int>(4));
    label.resize(6);
    for (int f = 0; f < 6; f++) {
      for (int k = 0; k < 4; k++) face[f][k] = quad[f][k];
      label[f] = -1 - f;
    }
  }

  /* Keeps the part where n . (y - m) <= 0; the cut face is labelled lab.
   * Returns false when nothing is left. */
  bool cut(const Vec &n, const Vec &m, long lab) {
    const std::size_t nv = v.size();
    const int side = sides(v, n, m, d);
    if (side != CUT) return side == KEEP;
    /* Kept vertices, then the new ones, each edge's made once. */
    nv2.clear();
    nlab2.clear();
    on.clear();
    idx.assign(nv, -1);
    for (std::size_t k = 0; k < nv; k++)
      if (d[k] <= 0) {
        idx[k] = static_cast<int>(nv2.size());
        nv2.push_back(v[k]);
        nlab2.push_back(vlab[k]);
        on.push_back(d[k] == 0);
      }
    made.clear();
    nface.clear();
    nlabel.clear();
    for (std::size_t f = 0; f < face.size(); f++) {
      const std::vector<int> &fv = face[f];
      out.clear();
      bool all_on = true;
      for (std::size_t k = 0; k < fv.size(); k++) {
        int a = fv[k], b = fv[(k + 1) % fv.size()];
        if (d[a] <= 0) {
          out.push_back(idx[a]);
          all_on &= d[a] == 0;
        }
        if ((d[a] < 0 && d[b] > 0) || (d[a] > 0 && d[b] < 0))
          out.push_back(edge_vertex(a, b, label[f], lab));
      }
      /* A face lying in the plane is replaced by the cut face. */
      if (out.size() < 3 || all_on) continue;
      nface.push_back(out);
      nlabel.push_back(label[f]);
    }
    cap(n, lab);
    v.swap(nv2);
    vlab.swap(nlab2);
    face.swap(nface);
    label.swap(nlabel);
    return true;
  }

private:
  std::vector<double> d, ang;
  std::vector<Vec> nv2;
  std::vector<Labels> nlab2;
  std::vector<char> on;
  std::vector<int> idx, out, order;
  std::vector<std::array<int, 3>> made;
  std::vector<std::vector<int>> nface;
  std::vector<long> nlabel;

  /* The label of the face other than the one labelled fl that holds the
   * edge a -> b (it runs b -> a there). */
  long other_face(int a, int b, long fl) const {
    for (std::size_t g = 0; g < face.size(); g++) {
      const std::vector<int> &fv = face[g];
      for (std::size_t k = 0; k < fv.size(); k++)
        if (fv[k] == b && fv[(k + 1) % fv.size()] == a && label[g] != fl)
          return label[g];
    }
    return fl;
  }

  /* The vertex where edge a - b of the face labelled fl meets the cut
   * labelled lab. */
  int edge_vertex(int a, int b, long fl, long lab) {
    int lo = std::min(a, b), hi = std::max(a, b);
    for (const auto &e : made)
      if (e[0] == lo && e[1] == hi) return e[2];
    /* From the kept end, so both faces of the edge compute the same point. */
    int in = d[a] < 0 ? a : b, ex = in == a ? b : a;
    double t = d[in] / (d[in] - d[ex]);
    Vec p;
    for (int k = 0; k < 3; k++) p[k] = v[in][k] + t * (v[ex][k] - v[in][k]);
    int id = static_cast<int>(nv2.size());
    nv2.push_back(p);
    nlab2.push_back({fl, other_face(a, b, fl), lab});
    on.push_back(1);
    made.push_back({lo, hi, id});
    return id;
  }

  /* The cut face: the vertices in the plane, in angular order about their
   * mean, counter-clockwise about n (the cell is convex, so they are its
   * corners). */
  void cap(const Vec &n, long lab) {
    order.clear();
    Vec g = {0, 0, 0};
    for (std::size_t k = 0; k < nv2.size(); k++)
      if (on[k]) {
        order.push_back(static_cast<int>(k));
        for (int q = 0; q < 3; q++) g[q] += nv2[k][q];
      }
    if (order.size() < 3) return;
    for (double &q : g) q /= static_cast<double>(order.size());
    int ax = std::fabs(n[0]) < std::fabs(n[1])
                 ? (std::fabs(n[0]) < std::fabs(n[2]) ? 0 : 2)
                 : (std::fabs(n[1]) < std::fabs(n[2]) ? 1 : 2);
    Vec e = {0, 0, 0};
    e[ax] = 1;
    /* (e1, e2, n) is right-handed: angles count counter-clockwise about n */
    Vec e1 = cross(n, e), e2 = cross(n, e1);
    ang.assign(nv2.size(), 0);
    for (int k : order) {
      Vec r = sub(nv2[k], g);
      ang[k] = std::atan2(dot(r, e2) / norm(e2), dot(r, e1) / norm(e1));
    }
    std::sort(order.begin(), order.end(),
              [this](int p, int q) { return ang[p] < ang[q]; });
    nface.push_back(order);
    nlabel.push_back(lab);
  }
};

/* A convex polygon in the z = 0 plane: vertices counter-clockwise, edge k
 * from vertex k to k + 1 labelled elabel[k]. */
class Polygon {
public:
  std::vector<Vec> v;
  std::vector<long> label;

  void box(const double lo[3], const double hi[3]) {
    v = {{lo[0], lo[1], 0},
         {hi[0], lo[1], 0},
         {hi[0], hi[1], 0},
         {lo[0], hi[1], 0}};
    label = {-1 - PM_FACE_YMIN, -1 - PM_FACE_XMAX, -1 - PM_FACE_YMAX,
             -1 - PM_FACE_XMIN};
  }

  /* Keeps the part where n . (y - m) <= 0, the cut edge labelled lab;
   * false when nothing is left. */
  bool cut(const Vec &n, const Vec &m, long lab) {
    const std::size_t nv = v.size();
    const int side = sides(v, n, m, d);
    if (side != CUT) return side == KEEP;
    nv2.clear();
    nl.clear();
    for (std::size_t k = 0; k < nv; k++) {
      std::size_t k1 = (k + 1) % nv;
      double da = d[k], db = d[k1];
      if (da <= 0) {
        nv2.push_back(v[k]);
        nl.push_back(db > 0 && da == 0 ? lab : label[k]);
        if (da < 0 && db > 0) {
          nv2.push_back(point(k, k1));
          nl.push_back(lab);
        }
      } else if (db < 0) {
        nv2.push_back(point(k1, k));
        nl.push_back(label[k]);
      }
    }
    v.swap(nv2);
    label.swap(nl);
    return v.size() >= 3;
  }

private:
  std::vector<double> d;
  std::vector<Vec> nv2;
  std::vector<long> nl;

  /* Where the edge from kept vertex a to cut vertex b meets the line. */
  Vec point(std::size_t a, std::size_t b) const {
    double t = d[a] / (d[a] - d[b]);
    Vec p;
    for (int k = 0; k < 3; k++) p[k] = v[a][k] + t * (v[b][k] - v[a][k]);
    return p;
  }
};

/* The faces of the cell of point i: the box cut by the bisector of each
 * neighbour in nbr; its own enclosed volume (divergence theorem about the
 * point) in *vol.  False when the cell is empty. */
bool cell_faces_3d(Polyhedron &P, const double lo[3], const double hi[3],
                   double tol, const double *x, long i, const long *nbr,
                   long nn, std::vector<Face> &faces, double *vol) {
  const Vec xi = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
  P.box(lo, hi);
  for (long k = 0; k < nn; k++) {
    const long j = nbr[k];
    const Vec xj = {x[3 * j], x[3 * j + 1], x[3 * j + 2]};
    const Vec n = sub(xj, xi);
    const Vec m = {0.5 * (xi[0] + xj[0]), 0.5 * (xi[1] + xj[1]),
                   0.5 * (xi[2] + xj[2])};
    if (!P.cut(n, m, j)) return false;
  }
  for (std::size_t k = 0; k < P.v.size(); k++)
    canonical_vertex(3, x, i, P.vlab[k].data(), lo, hi, tol, P.v[k]);
  faces.clear();
  *vol = 0;
  for (std::size_t f = 0; f < P.face.size(); f++) {
    const std::vector<int> &fv = P.face[f];
    Face F = empty_face(P.label[f]);
    Vec g = {0, 0, 0};
    for (int k : fv)
      for (int q = 0; q < 3; q++) g[q] += P.v[k][q] / fv.size();
    for (std::size_t k = 0; k < fv.size(); k++) {
      const Vec &p = P.v[fv[k]], &q = P.v[fv[(k + 1) % fv.size()]];
      Vec a = cross(sub(p, g), sub(q, g));
      Vec c;
      for (int r = 0; r < 3; r++) {
        a[r] *= 0.5;
        c[r] = (g[r] + p[r] + q[r]) / 3.0;
      }
      add_piece(F, a, c);
      *vol += dot(a, sub(c, xi)) / 3.0;
    }
    finish_face(F);
    faces.push_back(F);
  }
  return true;
}

/* The same in 2D: the rectangle cut by the bisector lines; each edge's
 * area vector is its outward normal times its length. */
bool cell_faces_2d(Polygon &P, const double lo[3], const double hi[3],
                   double tol, const double *x, long i, const long *nbr,
                   long nn, std::vector<Face> &faces, double *vol) {
  const Vec xi = {x[3 * i], x[3 * i + 1], 0};
  P.box(lo, hi);
  for (long k = 0; k < nn; k++) {
    const long j = nbr[k];
    const Vec xj = {x[3 * j], x[3 * j + 1], 0};
    const Vec n = sub(xj, xi);
    const Vec m = {0.5 * (xi[0] + xj[0]), 0.5 * (xi[1] + xj[1]), 0};
    if (!P.cut(n, m, j)) return false;
  }
  const std::size_t nv = P.v.size();
  for (std::size_t k = 0; k < nv; k++) {
    const long lab[2] = {P.label[(k + nv - 1) % nv], P.label[k]};
    canonical_vertex(2, x, i, lab, lo, hi, tol, P.v[k]);
  }
  faces.clear();
  *vol = 0;
  for (std::size_t k = 0; k < nv; k++) {
    const Vec &p = P.v[k], &q = P.v[(k + 1) % nv];
    Face F = empty_face(P.label[k]);
    Vec a = {q[1] - p[1], -(q[0] - p[0]), 0};
    Vec c = {0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0};
    add_piece(F, a, c);
    *vol += dot(a, sub(c, xi)) / 2.0;
    finish_face(F);
    faces.push_back(F);
  }
  return true;
}

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

/* All faces of all cells, and each cell's own volume. */
struct Cells {
  std::vector<std::vector<Face>> faces;
  std::vector<double> volume;
};

/* Index of the face labelled lab in list, or -1. */
long find_face(const std::vector<Face> &list, long lab) {
  for (std::size_t k = 0; k < list.size(); k++)
    if (list[k].label == lab) return static_cast<long>(k);
  return -1;
}

/* One interface: the pair and the face data oriented from i to j. */
struct Iface {
  long i, j;
  const Face *f;
  double sign;
};

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
  cells.faces.resize(static_cast<std::size_t>(n));
  cells.volume.resize(static_cast<std::size_t>(n));
  Polyhedron P3;
  Polygon P2;
  for (long i = 0; i < n; i++) {
    const long *ni = nbr.data() + ptr[i];
    const long nn = ptr[i + 1] - ptr[i];
    bool ok = dim == 3 ? cell_faces_3d(P3, lo, hi, vtol, x, i, ni, nn,
                                       cells.faces[i], &cells.volume[i])
                       : cell_faces_2d(P2, lo, hi, vtol, x, i, ni, nn,
                                       cells.faces[i], &cells.volume[i]);
    PM_CHECK(ok && cells.volume[i] > 0, PM_ERR_GEOMETRY,
             "the Voronoi cell of point %ld at (%g, %g, %g) is empty", i,
             x[3 * i], x[3 * i + 1], x[3 * i + 2]);
  }

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
