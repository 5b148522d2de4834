/* fpm_region: the part of the cells around a rank's own points, its model,
 * and the share made from it. */
#include "fpm_region.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_contact.h"
#include "fpm_share.h"

/* Each point's ring of support around rank r's own points (0: its own),
 * up to `most`; most + 1 for the points beyond (a search by rings). */
static pm_err find_rings(const gm_dual *d, const int *owner, int r, int most,
                         int *ring) {
  const long n = d->n_points;
  long *queue = NULL, head = 0, tail = 0;
  PM_CALL(PM_ALLOC(queue, n + 1, "rings of points"));
  for (long i = 0; i < n; i++) {
    ring[i] = owner[i] == r ? 0 : most + 1;
    if (!ring[i]) queue[tail++] = i;
  }
  while (head < tail) {
    const long i = queue[head++];
    if (ring[i] >= most) continue;
    for (long e = d->nbr_ptr[i]; e < d->nbr_ptr[i + 1]; e++) {
      const long k = d->nbr[e];
      if (ring[k] > ring[i] + 1) {
        ring[k] = ring[i] + 1;
        queue[tail++] = k;
      }
    }
  }
  free(queue);
  return PM_SUCCESS;
}

/* Copy `width` values per item of the listed items (idx[0..count)). */
static void copy_items(double *to, const double *from, const long *idx,
                       long count, int width) {
  for (long k = 0; k < count; k++)
    memcpy(to + width * k, from + width * idx[k], sizeof(double) * width);
}

/* The interfaces of the part's rows, numbered as they first appear, with
 * their points as the part's. */
static pm_err part_interfaces(const gm_dual *d, const long *lof,
                              const long *whole_iface, gm_dual *p) {
  pm_err ret = PM_SUCCESS;
  const long nnz = p->nbr_ptr[p->n_points];
  long *map = NULL, *idx = NULL;
  PM_TRY(PM_ALLOC(map, d->n_ifaces + 1, "part's interfaces"));
  PM_TRY(PM_ALLOC(idx, nnz + 1, "part's interfaces"));
  PM_TRY(PM_ALLOC(p->nbr_iface, nnz + 1, "part's interfaces"));
  for (long f = 0; f < d->n_ifaces; f++) map[f] = -1;
  long nf = 0;
  for (long e = 0; e < nnz; e++) {
    const long f = whole_iface[e];
    if (map[f] < 0) {
      map[f] = nf;
      idx[nf++] = f;
    }
    p->nbr_iface[e] = map[f];
  }
  p->n_ifaces = nf;
  PM_TRY(PM_ALLOC(p->if_pair, 2 * nf + 1, "part's interfaces"));
  PM_TRY(PM_ALLOC(p->if_area_vec, 3 * nf + 1, "part's interfaces"));
  PM_TRY(PM_ALLOC(p->if_moment, 9 * nf + 1, "part's interfaces"));
  PM_TRY(PM_ALLOC(p->if_centroid, 3 * nf + 1, "part's interfaces"));
  PM_TRY(PM_ALLOC(p->if_area, nf + 1, "part's interfaces"));
  for (long k = 0; k < nf; k++) {
    p->if_pair[2 * k] = lof[d->if_pair[2 * idx[k]]];
    p->if_pair[2 * k + 1] = lof[d->if_pair[2 * idx[k] + 1]];
  }
  copy_items(p->if_area_vec, d->if_area_vec, idx, nf, 3);
  copy_items(p->if_moment, d->if_moment, idx, nf, 9);
  copy_items(p->if_centroid, d->if_centroid, idx, nf, 3);
  copy_items(p->if_area, d->if_area, idx, nf, 1);
done:
  free(map);
  free(idx);
  return ret;
}

/* The boundary facets of the part's points, in the whole's order (*fgid:
 * each one's index in the whole). */
static pm_err part_facets(const gm_dual *d, const long *lof, gm_dual *p,
                          long **fgid) {
  long nf = 0;
  for (long f = 0; f < d->n_facets; f++) nf += lof[d->facet_point[f]] >= 0;
  PM_CALL(PM_ALLOC(*fgid, nf + 1, "part's facets"));
  PM_CALL(gm_dual_alloc_facets(p, nf));
  long *idx = *fgid;
  nf = 0;
  for (long f = 0; f < d->n_facets; f++)
    if (lof[d->facet_point[f]] >= 0) idx[nf++] = f;
  for (long k = 0; k < nf; k++) {
    p->facet_point[k] = lof[d->facet_point[idx[k]]];
    p->facet_surface[k] = d->facet_surface[idx[k]];
  }
  copy_items(p->facet_area_vec, d->facet_area_vec, idx, nf, 3);
  copy_items(p->facet_moment, d->facet_moment, idx, nf, 9);
  copy_items(p->facet_centroid, d->facet_centroid, idx, nf, 3);
  copy_items(p->facet_area, d->facet_area, idx, nf, 1);
  return PM_SUCCESS;
}

/* The cells of the points gid[0..np) (ascending): rows where ring <= rows
 * (their neighbours all among the points), none beyond. */
static pm_err part_dual(const gm_dual *d, const int *ring, int rows, long np,
                        const long *gid, const long *lof, gm_dual **out,
                        long **fgid) {
  pm_err ret = PM_SUCCESS;
  gm_dual *p = NULL;
  long *wif = NULL; /* the whole's interface of each entry */
  PM_TRY(PM_ALLOC(p, 1, "part's cells"));
  p->dim = d->dim;
  p->n_points = np;
  PM_TRY(PM_ALLOC(p->x, 3 * np + 1, "part's points"));
  PM_TRY(PM_ALLOC(p->volume, np + 1, "part's points"));
  PM_TRY(PM_ALLOC(p->nbr_ptr, np + 1, "part's supports"));
  copy_items(p->x, d->x, gid, np, 3);
  copy_items(p->volume, d->volume, gid, np, 1);
  for (long li = 0; li < np; li++) {
    const long i = gid[li];
    p->nbr_ptr[li + 1] =
        p->nbr_ptr[li] +
        (ring[i] <= rows ? d->nbr_ptr[i + 1] - d->nbr_ptr[i] : 0);
  }
  const long nnz = p->nbr_ptr[np];
  PM_TRY(PM_ALLOC(p->nbr, nnz + 1, "part's supports"));
  PM_TRY(PM_ALLOC(wif, nnz + 1, "part's supports"));
  for (long li = 0; li < np; li++) {
    const long i = gid[li], f0 = p->nbr_ptr[li];
    if (p->nbr_ptr[li + 1] == f0) continue;
    for (long e = d->nbr_ptr[i]; e < d->nbr_ptr[i + 1]; e++) {
      p->nbr[f0 + e - d->nbr_ptr[i]] = lof[d->nbr[e]];
      wif[f0 + e - d->nbr_ptr[i]] = d->nbr_iface[e];
    }
  }
  PM_TRY(part_interfaces(d, lof, wif, p));
  PM_TRY(part_facets(d, lof, p, fgid));
  p->n_dropped_faces = d->n_dropped_faces;
  p->n_slivers = d->n_slivers;
  p->min_quality = d->min_quality;
  p->min_quality_point = d->min_quality_point;
  *out = p;
  p = NULL;
done:
  gm_dual_destroy(p);
  free(wif);
  return ret;
}

/* Each traction facet of the part's model by its index among the whole
 * model's (the conditions in order, each one's facets in the whole's
 * order: w lists the whole's, fgid maps the part's facets to the whole's). */
static pm_err traction_ids(const pm_scene *s, fpm_model *pm, const long *wptr,
                           const long *wf, const long *fgid) {
  PM_CALL(PM_ALLOC(pm->tf_gid, pm->n_tfacets + 1, "part's traction facets"));
  long nt = 0, base = 0;
  for (int b = 0; b < s->n_bcs; b++) {
    if (!s->bcs[b].traction_mask) continue;
    long w = wptr[b];
    for (long e = pm->bcf_ptr[b]; e < pm->bcf_ptr[b + 1]; e++) {
      const long f = fgid[pm->bcf_facet[e]];
      while (w < wptr[b + 1] && wf[w] < f) w++;
      pm->tf_gid[nt++] = base + w - wptr[b];
    }
    base += wptr[b + 1] - wptr[b];
  }
  return PM_SUCCESS;
}

pm_err fpm_share_build(const pm_scene *s, const fpm_options *o,
                       const gm_mesh *mesh, gm_dual **whole, bool release,
                       const int *owner, int r, fpm_model **out) {
  pm_err ret = PM_SUCCESS;
  const gm_dual *d = *whole;
  const long n = d->n_points;
  const int held = o->jump == FPM_JUMP_QUADRATIC ? 5 : 3;
  int *ring = NULL, *part_owner = NULL;
  long *gid = NULL, *lof = NULL, *fgid = NULL, *wptr = NULL, *wf = NULL;
  gm_dual *pd = NULL;
  fpm_model *pm = NULL;
  *out = NULL;
  /* The conditions' facets on the whole: its errors, and the traction
   * facets' indices. */
  PM_TRY(fpm_select_facets(d, s, mesh, true, &wptr, &wf));
  PM_TRY(PM_ALLOC(ring, n + 1, "rings of points"));
  PM_TRY(find_rings(d, owner, r, held + 2, ring));
  PM_TRY(PM_ALLOC(lof, n + 1, "part's points"));
  long np = 0;
  for (long i = 0; i < n; i++) lof[i] = ring[i] <= held + 2 ? np++ : -1;
  PM_TRY(PM_ALLOC(gid, np + 1, "part's points"));
  for (long i = 0; i < n; i++)
    if (lof[i] >= 0) gid[lof[i]] = i;
  PM_TRY(part_dual(d, ring, held + 1, np, gid, lof, &pd, &fgid));
  PM_TRY(PM_ALLOC(part_owner, np + 1, "part's partition"));
  for (long li = 0; li < np; li++) part_owner[li] = owner[gid[li]];
  free(ring);
  free(lof);
  ring = NULL;
  lof = NULL;
  if (release) { /* the part's cells are all the model reads */
    gm_dual_destroy(*whole);
    *whole = NULL;
  }
  PM_TRY(fpm_model_create_part(s, o, mesh, pd, gid, &pm));
  if (pm->contact) PM_TRY(fpm_contact_refuse_ranks(s));
  PM_TRY(traction_ids(s, pm, wptr, wf, fgid));
  PM_TRY(fpm_share_create(pm, part_owner, r, out));
done:
  fpm_model_destroy(pm);
  gm_dual_destroy(pd);
  free(ring);
  free(part_owner);
  free(gid);
  free(lof);
  free(fgid);
  free(wptr);
  free(wf);
  return ret;
}
