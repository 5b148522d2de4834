/* gm_surface: named boundary surfaces of a gm_mesh: the faces of its box,
 * or the physical groups of the file it was meshed from, matched to the
 * mesh's boundary faces by their node sets; lookup by name. */
#include "gm_surface.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_face.h"

void gm_surface_drop(gm_mesh *m) {
  if (m->surface_name)
    for (int s = 0; s < m->n_surfaces; s++) free(m->surface_name[s]);
  free(m->surface_name);
  free(m->face_surface);
  m->surface_name = NULL;
  m->face_surface = NULL;
  m->n_surfaces = 0;
}

/* Room for n names and a tag per cell face, every face on no surface. */
static pm_err alloc_surfaces(gm_mesh *m, int n) {
  gm_surface_drop(m);
  const size_t slots = (size_t)m->nodes_per_cell * (size_t)m->n_cells;
  PM_CALL(PM_ALLOC(m->surface_name, n, "surface names"));
  m->n_surfaces = n;
  PM_CALL(PM_ALLOC(m->face_surface, slots, "face surfaces"));
  for (size_t k = 0; k < slots; k++) m->face_surface[k] = -1;
  return PM_SUCCESS;
}

pm_err gm_surface_name_box(gm_mesh *m) {
  const int dim = m->dim, npc = m->nodes_per_cell;
  PM_CALL(alloc_surfaces(m, 2 * dim));
  for (int f = 0; f < 2 * dim; f++) {
    m->surface_name[f] = strdup(pm_face_name(f));
    PM_CHECK(m->surface_name[f], PM_ERR_MEMORY, "no memory for a name");
  }
  double size = 0.0;
  for (int k = 0; k < dim; k++)
    size = fmax(size, m->box_max[k] - m->box_min[k]);
  const double tol = 1e-9 * size;
  for (long c = 0; c < m->n_cells; c++) {
    const long *cell = m->cells + (size_t)npc * c;
    for (int o = 0; o < npc; o++)
      for (int f = 0; f < 2 * dim; f++) {
        const int axis = pm_face_axis(f);
        const double plane = pm_face_plane(f, m->box_min, m->box_max);
        int on = 1;
        for (int a = 0; a < npc && on; a++)
          if (a != o) on = fabs(m->x[3 * cell[a] + axis] - plane) <= tol;
        if (on) {
          m->face_surface[(size_t)npc * c + o] = f;
          break;
        }
      }
  }
  return PM_SUCCESS;
}

/* A face by its sorted nodes, and where it sits (cell slot or -1). */
typedef struct {
  long node[3];
  long slot;
} face_key;

static int cmp_nodes(const face_key *x, const face_key *y) {
  for (int a = 0; a < 3; a++)
    if (x->node[a] != y->node[a]) return x->node[a] < y->node[a] ? -1 : 1;
  return 0;
}

static int cmp_face(const void *a, const void *b) {
  const face_key *x = a, *y = b;
  int c = cmp_nodes(x, y);
  if (c) return c;
  return (x->slot > y->slot) - (x->slot < y->slot);
}

/* Sorts the n (<= 3) nodes of a key; unused places stay 0. */
static void sort_key(face_key *k, int n) {
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && k->node[j - 1] > k->node[j]; j--) {
      long t = k->node[j];
      k->node[j] = k->node[j - 1];
      k->node[j - 1] = t;
    }
}

/* Slot of the boundary face with k's nodes in the sorted keys, or -1 when
 * no face has them or two cells do (an interior face). */
static long find_boundary(const face_key *keys, long n, const face_key *k) {
  long lo = 0, hi = n;
  while (lo < hi) {
    long mid = lo + (hi - lo) / 2;
    if (cmp_nodes(&keys[mid], k) < 0)
      lo = mid + 1;
    else
      hi = mid;
  }
  if (lo == n || cmp_nodes(&keys[lo], k) != 0) return -1;
  if (lo + 1 < n && cmp_nodes(&keys[lo + 1], k) == 0) return -1;
  return keys[lo].slot;
}

pm_err gm_surface_from_groups(gm_mesh *m, const gm_gmsh_mesh *raw) {
  pm_err ret = PM_SUCCESS;
  const int dim = m->dim, npc = m->nodes_per_cell;
  const long n_keys = (long)npc * m->n_cells;
  face_key *keys = NULL;
  PM_TRY(alloc_surfaces(m, raw->n_groups));
  for (int g = 0; g < raw->n_groups; g++) {
    m->surface_name[g] = strdup(raw->group_name[g]);
    PM_ENSURE(m->surface_name[g], PM_ERR_MEMORY, "no memory for a name");
  }
  /* Every cell face by its node set: a set met once is a boundary face. */
  PM_TRY(PM_ALLOC(keys, n_keys, "face keys"));
  for (long c = 0; c < m->n_cells; c++) {
    const long *cell = m->cells + (size_t)npc * c;
    for (int o = 0; o < npc; o++) {
      face_key *k = &keys[(long)npc * c + o];
      int n = 0;
      for (int a = 0; a < npc; a++)
        if (a != o) k->node[n++] = cell[a];
      sort_key(k, n);
      k->slot = (long)npc * c + o;
    }
  }
  qsort(keys, (size_t)n_keys, sizeof *keys, cmp_face);
  for (int g = 0; g < raw->n_groups; g++)
    for (long f = raw->group_ptr[g]; f < raw->group_ptr[g + 1]; f++) {
      face_key k = {{0, 0, 0}, -1};
      int missing = 0;
      for (int a = 0; a < dim; a++) {
        k.node[a] = raw->group_face[(size_t)dim * f + a];
        missing |= k.node[a] < 0;
      }
      if (missing) continue; /* a node of no cell: not a face of the mesh */
      sort_key(&k, dim);
      long slot = find_boundary(keys, n_keys, &k);
      if (slot >= 0) m->face_surface[slot] = g;
    }
done:
  free(keys);
  return ret;
}

int gm_mesh_surface_find(const gm_mesh *m, const char *name) {
  if (!m || !name) return -1;
  for (int s = 0; s < m->n_surfaces; s++)
    if (m->surface_name[s] && strcmp(m->surface_name[s], name) == 0) return s;
  return -1;
}

const char *gm_mesh_surface_name(const gm_mesh *m, int s) {
  if (!m || s < 0 || s >= m->n_surfaces) return NULL;
  return m->surface_name[s];
}

char *gm_mesh_surface_list(const gm_mesh *m, char *buf, size_t size) {
  if (!buf || size == 0) return buf;
  buf[0] = '\0';
  const int n = m ? m->n_surfaces : 0;
  size_t used = 0;
  if (n == 0) {
    snprintf(buf, size, "(none)");
    return buf;
  }
  for (int s = 0; s < n; s++) {
    int w = snprintf(buf + used, size - used, "%s%s", s ? ", " : "",
                     m->surface_name[s]);
    if (w < 0 || (size_t)w >= size - used) {
      /* Does not fit: end with "..." where there is room for it. */
      if (size > 4) snprintf(buf + size - 4, 4, "...");
      return buf;
    }
    used += (size_t)w;
  }
  return buf;
}
