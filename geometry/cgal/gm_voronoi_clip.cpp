/* gm_voronoi_clip: each point's Voronoi cell on its own, written here: the
 * box cut by the bisector planes (lines in 2D) of its neighbours, each face
 * remembering the neighbour or box face that made it, its vertices made
 * the same to the bit in every cell that has them, and its faces'
 * integrals. */
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

extern "C" {
#include "pm_face.h"
}

#include "gm_voronoi_impl.h"

namespace gm_voronoi_impl {

namespace {

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

} // namespace

pm_err clip_cells(int dim, long n, const double *x, const double lo[3],
                  const double hi[3], double vtol, const std::vector<long> &ptr,
                  const std::vector<long> &nbr, Cells &cells) {
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
  return PM_SUCCESS;
}

} // namespace gm_voronoi_impl
