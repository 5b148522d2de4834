/* gm_cells: the table of cell builders for FPM. */
#include "gm_cells.h"

#include <math.h>
#include <string.h>

#include "gm_voronoi.h"

/* The mesh surface of each box face (pm_face order): the one its boundary
 * faces carry (for a box mesh, the face's own pm_face value; -1 for a mesh
 * without surfaces).  Faces of a box face carrying two surfaces are
 * refused: a Voronoi facet takes the surface of its box face. */
static pm_err box_face_surfaces(const gm_mesh *m, double tol, int surf[6]) {
  const int npc = m->nodes_per_cell;
  int seen[6] = {0, 0, 0, 0, 0, 0};
  for (int b = 0; b < 2 * m->dim; b++) surf[b] = -1;
  for (long c = 0; c < m->n_cells && m->face_surface; c++)
    for (int o = 0; o < npc; o++)
      for (int b = 0; b < 2 * m->dim; b++) {
        int axis = b / 2;
        double plane = b % 2 ? m->box_max[axis] : m->box_min[axis];
        int on = 1;
        for (int a = 0; a < npc; a++) {
          long v = m->cells[(size_t)npc * c + a];
          if (a != o) on &= fabs(m->x[3 * v + axis] - plane) <= tol;
        }
        if (!on) continue;
        int s = m->face_surface[(size_t)npc * c + o];
        if (seen[b] && s != surf[b]) {
          const char *n0 = gm_mesh_surface_name(m, surf[b]);
          const char *n1 = gm_mesh_surface_name(m, s);
          return PM_ERROR(PM_ERR_UNSUPPORTED,
                          "Voronoi cells: the box face %s of the mesh "
                          "carries two surfaces (%s and %s); expected one "
                          "surface per box face",
                          pm_face_name(b), n0 ? n0 : "none", n1 ? n1 : "none");
        }
        seen[b] = 1;
        surf[b] = s;
      }
  return PM_SUCCESS;
}

/* FPM prescribes a displacement at the points whose cells have facets on
 * the face: a node inside whose cell reaches the box (it lies closer to a
 * stretch of the face than the face's own nodes) would be held at the
 * face's value.  Refused, naming the node (a mesh generator's boundary
 * nodes keep the inner ones away: none of gmsh's box meshes from mesh size
 * 8.72e-3 to 2.15e-3 has one). */
static pm_err check_facet_points(const gm_mesh *m, const gm_dual *d,
                                 double tol) {
  for (long f = 0; f < d->n_facets; f++) {
    const double *a = d->facet_area_vec + 3 * f;
    int axis = 0;
    for (int k = 1; k < 3; k++)
      if (fabs(a[k]) > fabs(a[axis])) axis = k;
    int face = 2 * axis + (a[axis] > 0);
    long i = d->facet_point[f];
    const double *xi = d->x + 3 * i;
    double gap = fabs(xi[axis] - pm_face_plane(face, m->box_min, m->box_max));
    if (gap > tol)
      return PM_ERROR(PM_ERR_UNSUPPORTED,
                      "the Voronoi cell of node %ld at (%g, %g, %g) reaches "
                      "the box face %s, %g away from the node (a facet of "
                      "area %g): its displacement condition would be put "
                      "on a node inside; expected the face's own nodes "
                      "closer to it (a finer mesh on the boundary) or "
                      "fpm.cells = median-dual",
                      i, xi[0], xi[1], xi[2], pm_face_name(face), gap,
                      d->facet_area[f]);
  }
  return PM_SUCCESS;
}

/* Voronoi cells of the mesh nodes clipped to the mesh's box: only a mesh
 * that fills its bounding box (a box domain) has them. */
static pm_err voronoi_cells(const gm_mesh *m, gm_dual **out) {
  PM_CHECK(out, PM_ERR_ARG, "voronoi cells: out is NULL");
  *out = NULL;
  PM_CHECK(m && m->x && m->cells && (m->dim == 2 || m->dim == 3), PM_ERR_ARG,
           "voronoi cells: no mesh");
  double vbox = 1, size = 0, vol = gm_mesh_volume(m);
  for (int k = 0; k < m->dim; k++) {
    vbox *= m->box_max[k] - m->box_min[k];
    size = fmax(size, m->box_max[k] - m->box_min[k]);
  }
  PM_CHECK(fabs(vol - vbox) <= 1e-9 * vbox, PM_ERR_UNSUPPORTED,
           "fpm.cells = voronoi clips the cells to a box, but the domain is "
           "not one: its mesh fills %.6g of its bounding box [%g, %g] x "
           "[%g, %g] x [%g, %g] (%.6g); expected a box domain "
           "(domain.box) or fpm.cells = median-dual",
           vol, m->box_min[0], m->box_max[0], m->box_min[1], m->box_max[1],
           m->box_min[2], m->box_max[2], vbox);
  int surf[6];
  PM_CALL(box_face_surfaces(m, 1e-9 * size, surf));
  pm_err ret = PM_SUCCESS;
  gm_dual *d = NULL;
  PM_TRY(gm_voronoi_build(m->dim, m->n_nodes, m->x, m->box_min, m->box_max,
                          surf, &d));
  PM_TRY(check_facet_points(m, d, 1e-9 * size));
  *out = d;
  d = NULL;
done:
  gm_dual_destroy(d);
  return ret;
}

static const gm_cells_builder builders[] = {
    {"median-dual",
     "median-dual cells: node, edge midpoints, face and element centroids",
     gm_dual_build},
    {"voronoi",
     "Voronoi cells of the mesh nodes clipped to the domain box (CGAL)",
     voronoi_cells},
};

#define N_BUILDERS ((int)(sizeof builders / sizeof builders[0]))

const gm_cells_builder *gm_cells_find(const char *name) {
  if (!name) return NULL;
  for (int i = 0; i < N_BUILDERS; i++)
    if (strcmp(builders[i].name, name) == 0) return &builders[i];
  return NULL;
}

int gm_cells_count(void) { return N_BUILDERS; }

const gm_cells_builder *gm_cells_at(int i) {
  return i >= 0 && i < N_BUILDERS ? &builders[i] : NULL;
}
