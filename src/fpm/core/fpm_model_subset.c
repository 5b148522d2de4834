/* fpm_model_subset: the model of some of a whole model's points (a rank's
 * share): their rows, operators, interfaces, fits, masses, materials and
 * boundary, taken from the whole model in one process's order. */
#include <stdlib.h>
#include <string.h>

#include "fpm_stream.h"
#include "fpm_gfd.h"
#include "fpm_model.h"

/* Where the subset takes the model it is made of (t: that model, else
 * NULL), each of the model's smaller arrays is let go once its last
 * reader has copied it (the largest move into the subset's in place:
 * subset_entries), so that the model and its subset are never held whole
 * together. */
#define LET_GO(t, field)                                                       \
  do {                                                                         \
    if (t) {                                                                   \
      free((t)->field);                                                        \
      (t)->field = NULL;                                                       \
    }                                                                          \
  } while (0)

/* The rows (CSR) of the share's first n_rows points (those whose stress
 * it computes), entries in their order, neighbours as indices in the share
 * (the levels hold every one). */
static pm_err copy_rows(const long *ptr, const int *nbr, long n_rows,
                        const long *gid, const int *local_of, long *lptr,
                        int **lnbr) {
  long nnz = 0;
  lptr[0] = 0;
  for (long li = 0; li < n_rows; li++) {
    nnz += ptr[gid[li] + 1] - ptr[gid[li]];
    lptr[li + 1] = nnz;
  }
  PM_CALL(PM_ALLOC(*lnbr, nnz + 1, "share's rows"));
  for (long li = 0; li < n_rows; li++)
    for (long e = ptr[gid[li]], f = lptr[li]; e < ptr[gid[li] + 1]; e++, f++)
      (*lnbr)[f] = local_of[nbr[e]];
  return PM_SUCCESS;
}

/* Copy `width` values per item of the listed items (idx[0..count)). */
static void copy_items(double *to, const double *from, const long *idx,
                       long count, int width) {
  for (long k = 0; k < count; k++)
    memcpy(to + width * k, from + width * idx[k], sizeof(double) * width);
}

/* Rearrange the n_from records of `width` doubles of *a in place so that
 * the one at f is the one that was at src[f] (a permutation: the subset's
 * records first, n_to of them, then those not kept), by its cycles, each
 * record copied once, then shrink *a to the n_to records (and one zero
 * double, as PM_ALLOC's). */
static pm_err move_records(double **a, long n_from, const long *src, long n_to,
                           int width) {
  pm_err ret = PM_SUCCESS;
  unsigned char *done = NULL;
  double *held = NULL, *r = *a;
  PM_TRY(PM_ALLOC(done, n_from + 1, "records moved"));
  PM_TRY(PM_ALLOC(held, width, "records moved"));
  for (long f = 0; f < n_from; f++) {
    if (done[f] || src[f] == f) continue;
    for (int c = 0; c < width; c++) held[c] = r[width * f + c];
    long at = f;
    for (; src[at] != f; at = src[at]) {
      for (int c = 0; c < width; c++)
        r[width * at + c] = r[width * src[at] + c];
      done[at] = 1;
    }
    for (int c = 0; c < width; c++) r[width * at + c] = held[c];
    done[at] = 1;
  }
  if (pm_realloc((void **)a, (size_t)width * n_to + 1, sizeof(double),
                 "records moved") == PM_SUCCESS)
    (*a)[(size_t)width * n_to] = 0;
done:
  free(done);
  free(held);
  return ret;
}

/* The subset's records of `width` doubles per entry of the rows of its
 * first n_stress points (s_ptr, over its points) from the model's (m_ptr,
 * over the model's points; m_a, n_from records) into *to: copied, or where
 * the model is taken (take: the model's array) moved in place and taken
 * from it (*take NULL), so that the two arrays are never held together. */
static pm_err subset_entries(double **to, const double *m_a, double **take,
                             const long *m_ptr, long n_from, const long *s_ptr,
                             const fpm_model *s, int width, const char *what) {
  const long ns = s->n_stress, n_to = s_ptr[ns];
  if (!take) {
    PM_CALL(
        pm_calloc((void **)to, (size_t)width * n_to + 1, sizeof(double), what));
    for (long li = 0; li < ns; li++) {
      const long e0 = m_ptr[s->gid[li]], f0 = s_ptr[li];
      memcpy(*to + width * f0, m_a + width * e0,
             sizeof(double) * width * (size_t)(s_ptr[li + 1] - f0));
    }
    return PM_SUCCESS;
  }
  pm_err ret = PM_SUCCESS;
  long *src = NULL;
  unsigned char *kept = NULL;
  PM_TRY(PM_ALLOC(src, n_from + 1, what));
  PM_TRY(PM_ALLOC(kept, n_from + 1, what));
  for (long li = 0; li < ns; li++) {
    const long e0 = m_ptr[s->gid[li]], f0 = s_ptr[li];
    for (long f = f0; f < s_ptr[li + 1]; f++) {
      src[f] = e0 + f - f0;
      kept[e0 + f - f0] = 1;
    }
  }
  for (long e = 0, past = n_to; e < n_from; e++)
    if (!kept[e]) src[past++] = e;
  free(kept);
  kept = NULL;
  PM_TRY(move_records(take, n_from, src, n_to, width));
  *to = *take;
  *take = NULL;
done:
  free(src);
  free(kept);
  return ret;
}

/* The points' own arrays: positions, volumes, rows of the support, GFD
 * weights, interface records, sums, materials, masses and the mask. */
static pm_err subset_points(const fpm_model *m, fpm_model *s, const int *lof,
                            fpm_model *t) {
  const long n = s->n, ns = s->n_stress;
  gm_dual *d = s->own_dual;
  PM_CALL(PM_ALLOC(d->x, 3 * n, "share's positions"));
  PM_CALL(PM_ALLOC(d->volume, n, "share's volumes"));
  PM_CALL(PM_ALLOC(d->nbr_ptr, n + 1, "share's supports"));
  copy_items(d->x, m->x, s->gid, n, 3);
  for (long li = 0; li < n; li++) d->volume[li] = m->dual->volume[s->gid[li]];
  PM_CALL(copy_rows(m->nbr_ptr, m->nbr, ns, s->gid, lof, d->nbr_ptr, &s->nbr));
  for (long li = ns; li < n; li++) d->nbr_ptr[li + 1] = d->nbr_ptr[ns];
  s->x = d->x;
  s->nbr_ptr = d->nbr_ptr;
  s->nnz = d->nbr_ptr[n];
  const long nnz = s->nnz;
  PM_CALL(subset_entries(&s->g, m->g, t ? &t->g : NULL, m->nbr_ptr, m->nnz,
                         s->nbr_ptr, s, 3, "share's GFD weights"));
  PM_CALL(subset_entries(&s->erec, m->erec, t ? &t->erec : NULL, m->nbr_ptr,
                         m->nnz, s->nbr_ptr, s, FPM_EREC,
                         "share's interfaces"));
  PM_CALL(PM_ALLOC(s->mirror, nnz + 1, "share's mirror entries"));
  for (long li = 0; li < ns; li++) {
    const long gi = s->gid[li], e0 = m->nbr_ptr[gi], f0 = s->nbr_ptr[li];
    const long cnt = m->nbr_ptr[gi + 1] - e0;
    /* Entry (k, i) of entry (i, k), where k's row is held. */
    for (long f = f0; f < f0 + cnt; f++) {
      const long lk = s->nbr[f];
      const long gk = m->nbr[e0 + f - f0];
      s->mirror[f] =
          lk >= 0 && lk < ns
              ? (int)(s->nbr_ptr[lk] + m->mirror[e0 + f - f0] - m->nbr_ptr[gk])
              : -1;
    }
  }
  LET_GO(t, mirror);
  LET_GO(t, nbr);
  PM_CALL(PM_ALLOC(s->gsum, 3 * n, "share's GFD sums"));
  PM_CALL(PM_ALLOC(s->cond, n, "share's conditions"));
  PM_CALL(PM_ALLOC(s->p_area, 3 * n, "share's area sums"));
  PM_CALL(PM_ALLOC(s->p_mrel, 9 * n, "share's moment sums"));
  PM_CALL(PM_ALLOC(s->mat, n, "share's materials"));
  PM_CALL(PM_ALLOC(s->mass, n, "share's masses"));
  PM_CALL(PM_ALLOC(s->fixed, 3 * n, "share's constraint mask"));
  copy_items(s->gsum, m->gsum, s->gid, n, 3);
  copy_items(s->cond, m->cond, s->gid, n, 1);
  copy_items(s->p_area, m->p_area, s->gid, n, 3);
  copy_items(s->p_mrel, m->p_mrel, s->gid, n, 9);
  copy_items(s->mass, m->mass, s->gid, n, 1);
  for (long li = 0; li < n; li++) {
    s->mat[li] = m->mat[s->gid[li]];
    memcpy(s->fixed + 3 * li, m->fixed + 3 * s->gid[li], 3);
  }
  s->mstate_stride = m->mstate_stride;
  if (m->mstate) {
    PM_CALL(PM_ALLOC(s->mstate, (size_t)m->mstate_stride * n,
                     "share's material state"));
    copy_items(s->mstate, m->mstate, s->gid, n, m->mstate_stride);
  }
  LET_GO(t, gsum);
  LET_GO(t, cond);
  LET_GO(t, p_area);
  LET_GO(t, p_mrel);
  LET_GO(t, mass);
  LET_GO(t, mat);
  LET_GO(t, fixed);
  LET_GO(t, mstate);
  return PM_SUCCESS;
}

/* The averaging weights of fpm.volumetric: averaged, the whole model's
 * (they read the supports' volumes of two rings): a_ik of the rows the
 * share holds, a_ii of its points. */
static pm_err subset_averages(const fpm_model *m, fpm_model *s, fpm_model *t) {
  PM_CALL(subset_entries(&s->vavg, m->vavg, t ? &t->vavg : NULL, m->nbr_ptr,
                         m->nnz, s->nbr_ptr, s, 1,
                         "share's averaging weights"));
  PM_CALL(PM_ALLOC(s->vself, s->n, "share's averaging weights"));
  copy_items(s->vself, m->vself, s->gid, s->n, 1);
  LET_GO(t, vself);
  return PM_SUCCESS;
}

/* The quadratic fits of the points whose stress the share computes, and
 * for its own points the fits that hold them, in one process's order
 * (the order of their entries). */
static pm_err subset_fits(const fpm_model *m, fpm_model *s, const int *lof,
                          fpm_model *t) {
  const long n = s->n, ns = s->n_stress, no = s->n_own;
  PM_CALL(PM_ALLOC(s->qs_ptr, n + 1, "share's fits"));
  PM_CALL(
      copy_rows(m->qs_ptr, m->qs_nbr, ns, s->gid, lof, s->qs_ptr, &s->qs_nbr));
  LET_GO(t, qs_nbr);
  for (long li = ns; li < n; li++) s->qs_ptr[li + 1] = s->qs_ptr[ns];
  const long nq = s->qs_ptr[n];
  PM_CALL(subset_entries(&s->q, m->q, t ? &t->q : NULL, m->qs_ptr,
                         m->qs_ptr[m->n], s->qs_ptr, s, FPM_QFIT,
                         "share's fit weights"));
  PM_CALL(PM_ALLOC(s->qsum, FPM_QFIT * n, "share's fit sums"));
  copy_items(s->qsum, m->qsum, s->gid, n, FPM_QFIT);
  LET_GO(t, qsum);
  PM_CALL(PM_ALLOC(s->qs_own, nq + 1, "share's fit owners"));
  for (long li = 0; li < ns; li++)
    for (long f = s->qs_ptr[li]; f < s->qs_ptr[li + 1]; f++)
      s->qs_own[f] = (int)li;
  PM_CALL(PM_ALLOC(s->qt_ptr, n + 1, "share's fit transpose"));
  long nt = 0;
  for (long li = 0; li < no; li++) {
    const long gk = s->gid[li];
    nt += m->qt_ptr[gk + 1] - m->qt_ptr[gk];
  }
  PM_CALL(PM_ALLOC(s->qt_entry, nt + 1, "share's fit transpose"));
  nt = 0;
  for (long li = 0; li < n; li++) {
    s->qt_ptr[li] = nt;
    if (li >= no) continue;
    const long gk = s->gid[li];
    for (long t = m->qt_ptr[gk]; t < m->qt_ptr[gk + 1]; t++) {
      const long ge = m->qt_entry[t], gi = m->qs_own[ge], i = lof[gi];
      s->qt_entry[nt++] = (int)(s->qs_ptr[i] + ge - m->qs_ptr[gi]);
    }
  }
  s->qt_ptr[n] = nt;
  s->n_qwide = m->n_qwide;
  s->n_qlinear = m->n_qlinear;
  LET_GO(t, qt_entry);
  LET_GO(t, qt_ptr);
  LET_GO(t, qs_own);
  LET_GO(t, qs_ptr);
  return PM_SUCCESS;
}

/* The boundary: the consistency flux and the tractions of the points whose
 * flux the share computes (in one process's order: facets that share a
 * point add up in it), the prescribed dofs of its own points. */
static pm_err subset_boundary(const fpm_model *m, fpm_model *s,
                              const int *lof) {
  const long nf = s->n_flux, no = s->n_own;
  long *idx = NULL;
  pm_err ret = PM_SUCCESS;
  const long most = m->n_dpts > m->n_tfacets ? m->n_dpts : m->n_tfacets;
  PM_TRY(PM_ALLOC(idx, (most > m->n_cdofs ? most : m->n_cdofs) + 1,
                  "share's boundary"));
  long c = 0;
  for (long p = 0; p < m->n_dpts; p++)
    if (lof[m->dpt_point[p]] >= 0 && lof[m->dpt_point[p]] < nf) idx[c++] = p;
  s->n_dpts = c;
  PM_TRY(PM_ALLOC(s->dpt_point, c + 1, "share's flux points"));
  PM_TRY(PM_ALLOC(s->dpt_area, 9 * c + 1, "share's flux areas"));
  PM_TRY(PM_ALLOC(s->dpt_mrel, 27 * c + 1, "share's flux moments"));
  for (long k = 0; k < c; k++) s->dpt_point[k] = lof[m->dpt_point[idx[k]]];
  copy_items(s->dpt_area, m->dpt_area, idx, c, 9);
  copy_items(s->dpt_mrel, m->dpt_mrel, idx, c, 27);
  c = 0;
  for (long k = 0; k < m->n_tfacets; k++)
    if (lof[m->tf_point[k]] >= 0 && lof[m->tf_point[k]] < nf) idx[c++] = k;
  s->n_tfacets = c;
  PM_TRY(PM_ALLOC(s->tf_point, c + 1, "share's traction facets"));
  PM_TRY(PM_ALLOC(s->tf_gid, c + 1, "share's traction facets"));
  PM_TRY(PM_ALLOC(s->tf_bc, c + 1, "share's traction facets"));
  PM_TRY(PM_ALLOC(s->tf_area, c + 1, "share's traction facets"));
  PM_TRY(PM_ALLOC(s->tf_rel, 3 * c + 1, "share's traction facets"));
  PM_TRY(PM_ALLOC(s->tf_centroid, 3 * c + 1, "share's traction facets"));
  PM_TRY(PM_ALLOC(s->tf_base, 3 * c + 1, "share's traction facets"));
  for (long k = 0; k < c; k++) {
    s->tf_point[k] = lof[m->tf_point[idx[k]]];
    s->tf_gid[k] = idx[k];
    s->tf_bc[k] = m->tf_bc[idx[k]];
  }
  copy_items(s->tf_area, m->tf_area, idx, c, 1);
  copy_items(s->tf_rel, m->tf_rel, idx, c, 3);
  copy_items(s->tf_centroid, m->tf_centroid, idx, c, 3);
  copy_items(s->tf_base, m->tf_base, idx, c, 3);
  PM_TRY(PM_ALLOC(s->tf_normal, 3 * c + 1, "share's traction facets"));
  copy_items(s->tf_normal, m->tf_normal, idx, c, 3);
  s->tf_time_dependent = m->tf_time_dependent;
  /* body forces of its points, concentrated forces on its own */
  s->bf_time_dependent = m->bf_time_dependent;
  if (m->bf_base) {
    PM_TRY(PM_ALLOC(s->bf_base, 3 * s->n, "share's body forces"));
    copy_items(s->bf_base, m->bf_base, s->gid, s->n, 3);
  }
  c = 0;
  for (long k = 0; k < m->n_pforces; k++)
    if (lof[m->pf_point[k]] >= 0 && lof[m->pf_point[k]] < no) c++;
  s->n_pforces = c;
  PM_TRY(PM_ALLOC(s->pf_point, c + 1, "share's point forces"));
  PM_TRY(PM_ALLOC(s->pf_bc, c + 1, "share's point forces"));
  PM_TRY(PM_ALLOC(s->pf_share, c + 1, "share's point forces"));
  c = 0;
  for (long k = 0; k < m->n_pforces; k++)
    if (lof[m->pf_point[k]] >= 0 && lof[m->pf_point[k]] < no) {
      s->pf_point[c] = lof[m->pf_point[k]];
      s->pf_bc[c] = m->pf_bc[k];
      s->pf_share[c++] = m->pf_share[k];
    }
  c = 0;
  for (long k = 0; k < m->n_cdofs; k++)
    if (lof[m->cd_point[k]] >= 0 && lof[m->cd_point[k]] < no) idx[c++] = k;
  s->n_cdofs = c;
  PM_TRY(PM_ALLOC(s->cd_point, c + 1, "share's prescribed dofs"));
  PM_TRY(PM_ALLOC(s->cd_comp, c + 1, "share's prescribed dofs"));
  PM_TRY(PM_ALLOC(s->cd_bc, c + 1, "share's prescribed dofs"));
  PM_TRY(PM_ALLOC(s->cd_base, c + 1, "share's prescribed dofs"));
  for (long k = 0; k < c; k++) {
    s->cd_point[k] = lof[m->cd_point[idx[k]]];
    s->cd_comp[k] = m->cd_comp[idx[k]];
    s->cd_bc[k] = m->cd_bc[idx[k]];
  }
  copy_items(s->cd_base, m->cd_base, idx, c, 1);
  s->cd_time_dependent = m->cd_time_dependent;
done:
  free(idx);
  return ret;
}

/* The subset of m's points pts; t: m where the subset takes it, else
 * NULL. */
static pm_err subset(const fpm_model *m, const fpm_points *pts, fpm_model *t,
                     fpm_model **out) {
  pm_err ret = PM_SUCCESS;
  fpm_model *s = NULL;
  int *lof = NULL; /* each point's index in the subset, or -1 */
  *out = NULL;
  PM_TRY(PM_ALLOC(lof, m->n + 1, "share's points"));
  PM_TRY(PM_ALLOC(s, 1, "FPM model (a rank's share)"));
  PM_TRY(PM_ALLOC(s->own_dual, 1, "share's points"));
  s->n_own = pts->n_own;
  s->n_flux = pts->n_flux;
  s->n_stress = pts->n_stress;
  s->n = pts->n;
  PM_TRY(PM_ALLOC(s->gid, s->n + 1, "share's point indices"));
  memcpy(s->gid, pts->gid, sizeof(long) * (size_t)s->n);
  for (long i = 0; i < m->n; i++) lof[i] = -1;
  for (long li = 0; li < s->n; li++) lof[s->gid[li]] = (int)li;
  s->dim = m->dim;
  s->own_dual->dim = m->dim;
  s->own_dual->n_points = s->n;
  s->dual = s->own_dual;
  s->scene = m->scene;
  s->penalty = m->penalty;
  s->boundary_penalty = m->boundary_penalty;
  s->stiffening = m->stiffening;
  s->stiffen_quadratic = m->stiffen_quadratic;
  s->stiffen_current = m->stiffen_current;
  s->stiffening_onset = m->stiffening_onset;
  s->volume_penalty = m->volume_penalty;
  s->flux = m->flux;
  s->jump = m->jump;
  s->n_mats = m->n_mats;
  memcpy(s->mats, m->mats, sizeof s->mats);
  PM_TRY(subset_points(m, s, lof, t));
  if (m->vavg) PM_TRY(subset_averages(m, s, t));
  if (m->qs_ptr) PM_TRY(subset_fits(m, s, lof, t));
  PM_TRY(subset_boundary(m, s, lof));
  PM_TRY(fpm_stream_build(s));
  /* The points and traction facets of a part (m->gid) by their indices on
   * one process. */
  if (m->gid)
    for (long li = 0; li < s->n; li++) s->gid[li] = m->gid[s->gid[li]];
  if (m->tf_gid)
    for (long k = 0; k < s->n_tfacets; k++)
      s->tf_gid[k] = m->tf_gid[s->tf_gid[k]];
  *out = s;
  s = NULL;
done:
  fpm_model_destroy(s);
  free(lof);
  return ret;
}

pm_err fpm_model_subset(const fpm_model *m, const fpm_points *pts,
                        fpm_model **out) {
  return subset(m, pts, NULL, out);
}

pm_err fpm_model_subset_take(fpm_model *m, const fpm_points *pts,
                             fpm_model **out) {
  return subset(m, pts, m, out);
}
