/* fpm_region: the part of the whole cells around a rank's own points, cut
 * on rank 0, its model on that rank, and the share made from it. */
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

/* The boundary facets of the part's points, in the whole's order. */
static pm_err part_facets(const gm_dual *d, const long *lof, gm_dual *p) {
  pm_err ret = PM_SUCCESS;
  long nf = 0, *idx = NULL; /* each one's index in the whole */
  for (long f = 0; f < d->n_facets; f++) nf += lof[d->facet_point[f]] >= 0;
  PM_TRY(PM_ALLOC(idx, nf + 1, "part's facets"));
  PM_TRY(gm_dual_alloc_facets(p, nf));
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
done:
  free(idx);
  return ret;
}

/* The cells of the points gid[0..np) (ascending): rows where ring <= rows
 * (their neighbours all among the points), none beyond. */
static pm_err part_dual(const gm_dual *d, const int *ring, int rows, long np,
                        const long *gid, const long *lof, gm_dual **out) {
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
  PM_TRY(part_facets(d, lof, p));
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

pm_err fpm_cutter_init(fpm_cutter *c, const pm_scene *s, const fpm_options *o,
                       const gm_mesh *mesh, const gm_dual *d, const int *owner,
                       int parts) {
  pm_err ret = PM_SUCCESS;
  long *seen = NULL;
  *c = (fpm_cutter){.d = d,
                    .owner = owner,
                    .held = o->jump == FPM_JUMP_QUADRATIC ? 5 : 3,
                    .n_bcs = s->n_bcs};
  PM_TRY(fpm_select_facets(d, s, mesh, true, &c->wptr, &c->wf));
  PM_TRY(PM_ALLOC(c->traction, s->n_bcs + 1, "traction conditions"));
  for (int b = 0; b < s->n_bcs; b++) /* a pressure's facets are traction's */
    c->traction[b] = s->bcs[b].traction_mask || s->bcs[b].pressure;
  PM_TRY(PM_ALLOC(c->index, d->n_points + 1, "owners' indices"));
  PM_TRY(PM_ALLOC(seen, parts + 1, "owners' indices"));
  for (long i = 0; i < d->n_points; i++) c->index[i] = seen[owner[i]]++;
done:
  free(seen);
  if (ret) fpm_cutter_free(c);
  return ret;
}

void fpm_cutter_free(fpm_cutter *c) {
  free(c->traction);
  free(c->index);
  free(c->wptr);
  free(c->wf);
  *c = (fpm_cutter){0};
}

void fpm_part_free(fpm_part *p) {
  gm_dual_destroy(p->cells);
  free(p->gid);
  free(p->owner);
  free(p->index);
  free(p->tf_ptr);
  free(p->tf_id);
  *p = (fpm_part){0};
}

/* The part's facets of each traction condition (those of its points, lof
 * >= 0), each by its index among the whole model's traction facets: the
 * conditions in order, each one's facets in the whole's order. */
static pm_err part_tractions(const fpm_cutter *c, const long *lof,
                             fpm_part *p) {
  const long *wptr = c->wptr, *wf = c->wf;
  const long *at = c->d->facet_point;
  PM_CALL(PM_ALLOC(p->tf_ptr, c->n_bcs + 1, "part's traction facets"));
  long nt = 0;
  for (int pass = 0; pass < 2; pass++) {
    long base = 0;
    nt = 0;
    for (int b = 0; b < c->n_bcs; b++) {
      p->tf_ptr[b] = nt;
      if (!c->traction[b]) continue;
      for (long w = wptr[b]; w < wptr[b + 1]; w++)
        if (lof[at[wf[w]]] >= 0) {
          if (pass) p->tf_id[nt] = base + w - wptr[b];
          nt++;
        }
      base += wptr[b + 1] - wptr[b];
    }
    p->tf_ptr[c->n_bcs] = nt;
    if (!pass) PM_CALL(PM_ALLOC(p->tf_id, nt + 1, "part's traction facets"));
  }
  return PM_SUCCESS;
}

pm_err fpm_part_cut(const fpm_cutter *c, int r, fpm_part *p) {
  pm_err ret = PM_SUCCESS;
  const gm_dual *d = c->d;
  const long n = d->n_points;
  const int reach = c->held + 2;
  int *ring = NULL;
  long *lof = NULL;
  *p = (fpm_part){.n_bcs = c->n_bcs, .n_whole = n};
  PM_TRY(PM_ALLOC(ring, n + 1, "rings of points"));
  PM_TRY(find_rings(d, c->owner, r, reach, ring));
  PM_TRY(PM_ALLOC(lof, n + 1, "part's points"));
  long np = 0;
  for (long i = 0; i < n; i++) lof[i] = ring[i] <= reach ? np++ : -1;
  PM_TRY(PM_ALLOC(p->gid, np + 1, "part's points"));
  PM_TRY(PM_ALLOC(p->owner, np + 1, "part's partition"));
  PM_TRY(PM_ALLOC(p->index, np + 1, "part's owners' indices"));
  for (long i = 0; i < n; i++)
    if (lof[i] >= 0) {
      p->gid[lof[i]] = i;
      p->owner[lof[i]] = c->owner[i];
      p->index[lof[i]] = c->index[i];
    }
  PM_TRY(part_dual(d, ring, c->held + 1, np, p->gid, lof, &p->cells));
  PM_TRY(part_tractions(c, lof, p));
done:
  free(ring);
  free(lof);
  if (ret) fpm_part_free(p);
  return ret;
}

/* Each traction facet of the part's model by its index among the whole
 * model's (the part's facets of each condition are the whole's facets of
 * its points, in the whole's order, as p lists them). */
static pm_err traction_ids(const fpm_part *p, fpm_model *pm) {
  PM_CALL(PM_ALLOC(pm->tf_gid, pm->n_tfacets + 1, "part's traction facets"));
  long nt = 0;
  for (int b = 0; b < p->n_bcs; b++) {
    if (p->tf_ptr[b + 1] == p->tf_ptr[b]) continue;
    PM_CHECK(
        pm->bcf_ptr[b + 1] - pm->bcf_ptr[b] == p->tf_ptr[b + 1] - p->tf_ptr[b],
        PM_ERR_INTERNAL,
        "condition %d selects %ld facets of the part, the whole %ld", b,
        pm->bcf_ptr[b + 1] - pm->bcf_ptr[b], p->tf_ptr[b + 1] - p->tf_ptr[b]);
    for (long k = p->tf_ptr[b]; k < p->tf_ptr[b + 1]; k++)
      pm->tf_gid[nt++] = p->tf_id[k];
  }
  PM_CHECK(nt == pm->n_tfacets, PM_ERR_INTERNAL,
           "%ld traction facets of the part, %ld named by the whole",
           pm->n_tfacets, nt);
  return PM_SUCCESS;
}

/* The facets of each condition among rank r's own points of a part
 * (owner: each part point's rank), from the part's model pm (whose facet
 * lists are the whole's over its points, in the whole's order): each list
 * entry a facet of the share's dual, its point numbered among the own
 * points (the share's own points are the part's of rank r, in the same
 * order), so that fpm_reaction on the share gives its own points' part of
 * each reaction, which a run without the whole model sums over the
 * ranks. */
typedef struct {
  long n, *ptr, *point; /* n facets; ptr[n_bcs + 1] */
  double *area_vec;     /* 3 n */
} own_facets;

static pm_err own_facets_make(const fpm_model *pm, const int *owner, int r,
                              own_facets *f) {
  pm_err ret = PM_SUCCESS;
  const int n_bcs = pm->scene->n_bcs;
  const gm_dual *pd = pm->dual;
  long *own = NULL; /* each part point's index among r's own, or -1 */
  PM_TRY(PM_ALLOC(own, pm->n + 1, "share's facets"));
  for (long i = 0, k = 0; i < pm->n; i++) own[i] = owner[i] == r ? k++ : -1;
  long nf = 0;
  for (long e = 0; e < pm->bcf_ptr[n_bcs]; e++)
    nf += own[pd->facet_point[pm->bcf_facet[e]]] >= 0;
  PM_TRY(PM_ALLOC(f->ptr, n_bcs + 1, "share's facet lists"));
  PM_TRY(PM_ALLOC(f->point, nf + 1, "share's facets"));
  PM_TRY(PM_ALLOC(f->area_vec, 3 * nf + 1, "share's facets"));
  nf = 0;
  for (int b = 0; b < n_bcs; b++) {
    f->ptr[b] = nf;
    for (long e = pm->bcf_ptr[b]; e < pm->bcf_ptr[b + 1]; e++) {
      const long k = pm->bcf_facet[e], i = own[pd->facet_point[k]];
      if (i < 0) continue;
      f->point[nf] = i;
      memcpy(f->area_vec + 3 * nf, pd->facet_area_vec + 3 * k,
             3 * sizeof(double));
      nf++;
    }
  }
  f->ptr[n_bcs] = nf;
  f->n = nf;
done:
  free(own);
  return ret;
}

/* The facets f into share s (taken over): its dual's facets, and each
 * condition's list of them. */
static pm_err own_facets_give(own_facets *f, fpm_model *s) {
  PM_CALL(PM_ALLOC(s->bcf_facet, f->n + 1, "share's facet lists"));
  for (long k = 0; k < f->n; k++) s->bcf_facet[k] = k;
  s->bcf_ptr = f->ptr;
  s->own_dual->facet_point = f->point;
  s->own_dual->facet_area_vec = f->area_vec;
  s->own_dual->n_facets = f->n;
  *f = (own_facets){0};
  return PM_SUCCESS;
}

pm_err fpm_part_share(const pm_scene *s, const fpm_options *o,
                      const gm_mesh *mesh, fpm_part *p, int r,
                      fpm_model **out) {
  pm_err ret = PM_SUCCESS;
  fpm_model *pm = NULL;
  own_facets f = {0};
  *out = NULL;
  PM_TRY(fpm_model_create_part(s, o, mesh, p->cells, p->gid, &pm));
  if (pm->contact) PM_TRY(fpm_contact_refuse_ranks(s));
  PM_TRY(traction_ids(p, pm));
  PM_TRY(own_facets_make(pm, p->owner, r, &f));
  /* What the share reads of the part's cells once the part's model is
   * built: the points' positions, volumes and rows.  Their facets go
   * first, so that they are not held with the share (the interfaces, as
   * much again as the rest at 14 neighbours a point, went as the model
   * built its interface records: fpm_model_create_part). */
  gm_dual_drop(p->cells, false, true);
  PM_TRY(fpm_share_take(pm, p->owner, r, out));
  PM_TRY(own_facets_give(&f, *out));
done:
  free(f.ptr);
  free(f.point);
  free(f.area_vec);
  if (ret) {
    fpm_model_destroy(*out);
    *out = NULL;
  }
  fpm_model_destroy(pm);
  return ret;
}

pm_err fpm_share_build(const pm_scene *s, const fpm_options *o,
                       const gm_mesh *mesh, gm_dual **whole, bool release,
                       const int *owner, int r, fpm_model **out) {
  pm_err ret = PM_SUCCESS;
  fpm_cutter c = {0};
  fpm_part cut = {0}, part = {0};
  char *buf = NULL;
  size_t len = 0;
  int parts = 0;
  *out = NULL;
  for (long i = 0; i < (*whole)->n_points; i++)
    parts = owner[i] >= parts ? owner[i] + 1 : parts;
  PM_TRY(fpm_cutter_init(&c, s, o, mesh, *whole, owner, parts));
  PM_TRY(fpm_part_cut(&c, r, &cut));
  fpm_cutter_free(&c);
  if (release) { /* the part's cells are all the model reads */
    gm_dual_destroy(*whole);
    *whole = NULL;
  }
  PM_TRY(fpm_part_pack(&cut, &buf, &len));
  fpm_part_free(&cut);
  PM_TRY(fpm_part_unpack(buf, len, &part));
  PM_TRY(fpm_part_share(s, o, mesh, &part, r, out));
done:
  fpm_cutter_free(&c);
  fpm_part_free(&cut);
  fpm_part_free(&part);
  free(buf);
  return ret;
}
