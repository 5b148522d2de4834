/* fpm_part: a rank's part of the whole cells as the bytes rank 0 sends it
 * (fpm_region.h), and the names of the whole mesh's surfaces. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_region.h"

/* The counts that size a part's arrays, first in its bytes. */
enum {
  H_DIM,
  H_POINTS,
  H_ENTRIES,
  H_IFACES,
  H_FACETS,
  H_TRACTIONS,
  H_BCS,
  H_WHOLE,
  H_DROPPED,
  H_SLIVERS,
  H_QUALITY_POINT,
  H_COUNT
};

/* One array of a part: where its pointer is, its items' size and count. */
typedef struct {
  void **at;
  size_t size;
  long count;
} part_array;

#define PART_ARRAYS 21

/* The arrays of part p (whose cells exist) sized by the counts h. */
static void part_arrays(fpm_part *p, const long *h, part_array *a) {
  gm_dual *c = p->cells;
  const long n = h[H_POINTS], e = h[H_ENTRIES], f = h[H_IFACES],
             b = h[H_FACETS];
  const size_t D = sizeof(double), L = sizeof(long), I = sizeof(int);
  const part_array all[PART_ARRAYS] = {
      {(void **)&c->x, D, 3 * n},
      {(void **)&c->volume, D, n},
      {(void **)&c->nbr_ptr, L, n + 1},
      {(void **)&c->nbr, L, e},
      {(void **)&c->nbr_iface, L, e},
      {(void **)&c->if_pair, L, 2 * f},
      {(void **)&c->if_area_vec, D, 3 * f},
      {(void **)&c->if_moment, D, 9 * f},
      {(void **)&c->if_centroid, D, 3 * f},
      {(void **)&c->if_area, D, f},
      {(void **)&c->facet_point, L, b},
      {(void **)&c->facet_surface, I, b},
      {(void **)&c->facet_area_vec, D, 3 * b},
      {(void **)&c->facet_moment, D, 9 * b},
      {(void **)&c->facet_centroid, D, 3 * b},
      {(void **)&c->facet_area, D, b},
      {(void **)&p->gid, L, n},
      {(void **)&p->owner, I, n},
      {(void **)&p->index, L, n},
      {(void **)&p->tf_ptr, L, h[H_BCS] + 1},
      {(void **)&p->tf_id, L, h[H_TRACTIONS]},
  };
  memcpy(a, all, sizeof all);
}

pm_err fpm_part_pack(const fpm_part *p, char **buf, size_t *len) {
  const gm_dual *c = p->cells;
  long h[H_COUNT] = {
      [H_DIM] = c->dim,
      [H_POINTS] = c->n_points,
      [H_ENTRIES] = c->nbr_ptr[c->n_points],
      [H_IFACES] = c->n_ifaces,
      [H_FACETS] = c->n_facets,
      [H_TRACTIONS] = p->tf_ptr[p->n_bcs],
      [H_BCS] = p->n_bcs,
      [H_WHOLE] = p->n_whole,
      [H_DROPPED] = c->n_dropped_faces,
      [H_SLIVERS] = c->n_slivers,
      [H_QUALITY_POINT] = c->min_quality_point,
  };
  part_array a[PART_ARRAYS];
  part_arrays((fpm_part *)p, h, a); /* read only */
  size_t bytes = sizeof h + sizeof c->min_quality;
  for (int k = 0; k < PART_ARRAYS; k++) bytes += a[k].size * (size_t)a[k].count;
  PM_CALL(PM_ALLOC(*buf, bytes, "a part's bytes"));
  char *at = *buf;
  memcpy(at, h, sizeof h);
  at += sizeof h;
  memcpy(at, &c->min_quality, sizeof c->min_quality);
  at += sizeof c->min_quality;
  for (int k = 0; k < PART_ARRAYS; k++) {
    const size_t n = a[k].size * (size_t)a[k].count;
    if (n) memcpy(at, *a[k].at, n);
    at += n;
  }
  *len = bytes;
  return PM_SUCCESS;
}

pm_err fpm_part_unpack(const char *buf, size_t len, fpm_part *p) {
  pm_err ret = PM_SUCCESS;
  long h[H_COUNT];
  *p = (fpm_part){0};
  PM_ENSURE(len >= sizeof h + sizeof(double), PM_ERR_INTERNAL,
            "a part of %zu bytes has no counts", len);
  memcpy(h, buf, sizeof h);
  PM_TRY(PM_ALLOC(p->cells, 1, "part's cells"));
  gm_dual *c = p->cells;
  c->dim = (int)h[H_DIM];
  c->n_points = h[H_POINTS];
  c->n_ifaces = h[H_IFACES];
  c->n_facets = h[H_FACETS];
  c->n_dropped_faces = h[H_DROPPED];
  c->n_slivers = h[H_SLIVERS];
  c->min_quality_point = h[H_QUALITY_POINT];
  p->n_bcs = (int)h[H_BCS];
  p->n_whole = h[H_WHOLE];
  const char *at = buf + sizeof h;
  memcpy(&c->min_quality, at, sizeof c->min_quality);
  at += sizeof c->min_quality;
  part_array a[PART_ARRAYS];
  part_arrays(p, h, a);
  for (int k = 0; k < PART_ARRAYS; k++) {
    const size_t n = a[k].size * (size_t)a[k].count;
    PM_ENSURE(a[k].count >= 0 && (size_t)(at - buf) + n <= len, PM_ERR_INTERNAL,
              "a part of %zu bytes ends inside array %d", len, k);
    PM_TRY(pm_calloc(a[k].at, (size_t)a[k].count + 1, a[k].size,
                     "a part's arrays"));
    if (n) memcpy(*a[k].at, at, n);
    at += n;
  }
  PM_ENSURE((size_t)(at - buf) == len, PM_ERR_INTERNAL,
            "a part of %zu bytes read as %zu", len, (size_t)(at - buf));
done:
  if (ret) fpm_part_free(p);
  return ret;
}

pm_err fpm_mesh_names(const gm_mesh *m, gm_mesh **out) {
  pm_err ret = PM_SUCCESS;
  gm_mesh *s = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(s, 1, "the mesh's surface names"));
  s->dim = m->dim;
  s->nodes_per_cell = m->nodes_per_cell;
  memcpy(s->box_min, m->box_min, sizeof s->box_min);
  memcpy(s->box_max, m->box_max, sizeof s->box_max);
  s->meshed = m->meshed;
  s->size_factor = m->size_factor;
  PM_TRY(PM_ALLOC(s->surface_name, m->n_surfaces + 1, "surface names"));
  s->n_surfaces = m->n_surfaces;
  for (int k = 0; k < m->n_surfaces; k++)
    if (m->surface_name[k]) {
      const size_t n = strlen(m->surface_name[k]) + 1;
      PM_TRY(PM_ALLOC(s->surface_name[k], n, "surface names"));
      memcpy(s->surface_name[k], m->surface_name[k], n);
    }
  *out = s;
  s = NULL;
done:
  gm_mesh_destroy(s);
  return ret;
}
