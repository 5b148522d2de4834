/* fpm_share: the partition of the points (MatPartitioning) and a rank's
 * share of an FPM model, its own points and ghosts in pass order. */
#include "fpm_share.h"

#include <petscmat.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_gfd.h"
#include "pm_petsc.h"

/* ---- partition ------------------------------------------------------------
 */

pm_err fpm_partition(const fpm_model *m, int parts, int *owner) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, nnz = m->nbr_ptr[m->n];
  Mat adj = NULL;
  MatPartitioning part = NULL;
  IS is = NULL;
  PetscInt *ia = NULL, *ja = NULL, *w = NULL;
  memset(owner, 0, sizeof(int) * (size_t)n);
  if (parts <= 1) return PM_SUCCESS;
  PM_CALL(pm_petsc_init());
  /* PT-Scotch's threads take turns in an order that varies from run to
   * run, and so did its partitions (3 different ones in 6 runs of the
   * same graph); on one thread it gives the same partition every time. */
  setenv("SCOTCH_PTHREAD_NUMBER", "1", 1);
  PM_PETSC(PetscMalloc1(n + 1, &ia));
  PM_PETSC(PetscMalloc1(nnz + 1, &ja));
  PM_PETSC(PetscMalloc1(n + 1, &w));
  for (long i = 0; i <= n; i++) ia[i] = (PetscInt)m->nbr_ptr[i];
  for (long e = 0; e < nnz; e++) ja[e] = (PetscInt)m->nbr[e];
  for (long i = 0; i < n; i++)
    w[i] = (PetscInt)(1 + m->nbr_ptr[i + 1] - m->nbr_ptr[i] +
                      (m->qs_ptr ? m->qs_ptr[i + 1] - m->qs_ptr[i] : 0));
  /* The adjacency and the weights are PETSc's from here. */
  PetscInt *a = ia, *b = ja;
  ia = ja = NULL;
  PM_PETSC(MatCreateMPIAdj(PETSC_COMM_SELF, (PetscInt)n, (PetscInt)n, a, b,
                           NULL, &adj));
  PM_PETSC(MatPartitioningCreate(PETSC_COMM_SELF, &part));
  PM_PETSC(MatPartitioningSetAdjacency(part, adj));
  PM_PETSC(MatPartitioningSetType(part, MATPARTITIONINGPTSCOTCH));
  PM_PETSC(MatPartitioningSetNParts(part, (PetscInt)parts));
  PetscInt *weights = w;
  w = NULL;
  PM_PETSC(MatPartitioningSetVertexWeights(part, weights));
  PM_PETSC(MatPartitioningSetFromOptions(part));
  PM_PETSC(MatPartitioningApply(part, &is));
  const PetscInt *to;
  PM_PETSC(ISGetIndices(is, &to));
  for (long i = 0; i < n; i++) owner[i] = (int)to[i];
  PM_PETSC(ISRestoreIndices(is, &to));
done:
  ISDestroy(&is);
  MatPartitioningDestroy(&part);
  MatDestroy(&adj);
  PetscFree(ia);
  PetscFree(ja);
  PetscFree(w);
  return ret;
}

long fpm_partition_edge_cut(const fpm_model *m, const int *owner) {
  long cut = 0;
  for (long i = 0; i < m->n; i++)
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++)
      cut += m->nbr[e] > i && owner[m->nbr[e]] != owner[i];
  return cut;
}

/* ---- a rank's share ---------------------------------------------------------
 */

/* Levels of the points a share holds: its own, and the ghosts whose flux,
 * stress or displacement it reads; NONE for the others. */
enum { OWN = 0, FLUX = 1, STRESS = 2, DISPLACEMENT = 3, NONE = 4 };

/* Mark `to` on the points not yet held that the points of level `from` or
 * lower read: their supports, and for displacement ghosts also the points
 * of their fits. */
static void mark_support(const fpm_model *m, signed char *level, int from,
                         int to) {
  for (long i = 0; i < m->n; i++) {
    if (level[i] > from) continue;
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++)
      if (level[m->nbr[e]] == NONE) level[m->nbr[e]] = (signed char)to;
    if (to != DISPLACEMENT || !m->qs_ptr) continue;
    for (long e = m->qs_ptr[i]; e < m->qs_ptr[i + 1]; e++)
      if (level[m->qs_nbr[e]] == NONE) level[m->qs_nbr[e]] = DISPLACEMENT;
  }
}

/* Each point's level in rank r's share. */
static void share_levels(const fpm_model *m, const int *owner, int r,
                         signed char *level) {
  for (long i = 0; i < m->n; i++) level[i] = owner[i] == r ? OWN : NONE;
  /* The gather of an own point reads its support's flux, and with the
   * quadratic jump that of every fit holding it. */
  mark_support(m, level, OWN, FLUX);
  if (m->qs_ptr)
    for (long k = 0; k < m->n; k++) {
      if (level[k] != OWN) continue;
      for (long t = m->qt_ptr[k]; t < m->qt_ptr[k + 1]; t++) {
        const long i = m->qs_own[m->qt_entry[t]];
        if (level[i] == NONE) level[i] = FLUX;
      }
    }
  mark_support(m, level, FLUX, STRESS);
  mark_support(m, level, STRESS, DISPLACEMENT);
}

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

/* The points' own arrays: positions, volumes, rows of the support, GFD
 * weights, interface records, sums, materials, masses and the mask. */
static pm_err share_points(const fpm_model *m, fpm_model *s, const int *lof) {
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
  PM_CALL(PM_ALLOC(s->g, 3 * nnz + 1, "share's GFD weights"));
  PM_CALL(PM_ALLOC(s->erec, FPM_EREC * nnz + 1, "share's interfaces"));
  PM_CALL(PM_ALLOC(s->mirror, nnz + 1, "share's mirror entries"));
  for (long li = 0; li < ns; li++) {
    const long gi = s->gid[li], e0 = m->nbr_ptr[gi], f0 = s->nbr_ptr[li];
    const long cnt = m->nbr_ptr[gi + 1] - e0;
    memcpy(s->g + 3 * f0, m->g + 3 * e0, sizeof(double) * 3 * cnt);
    memcpy(s->erec + FPM_EREC * f0, m->erec + FPM_EREC * e0,
           sizeof(double) * FPM_EREC * cnt);
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
  return PM_SUCCESS;
}

/* The quadratic fits of the points whose stress the share computes, and
 * for its own points the fits that hold them, in one process's order
 * (the order of their entries). */
static pm_err share_fits(const fpm_model *m, fpm_model *s, const int *lof) {
  const long n = s->n, ns = s->n_stress, no = s->n_own;
  PM_CALL(PM_ALLOC(s->qs_ptr, n + 1, "share's fits"));
  PM_CALL(
      copy_rows(m->qs_ptr, m->qs_nbr, ns, s->gid, lof, s->qs_ptr, &s->qs_nbr));
  for (long li = ns; li < n; li++) s->qs_ptr[li + 1] = s->qs_ptr[ns];
  const long nq = s->qs_ptr[n];
  PM_CALL(PM_ALLOC(s->qs_own, nq + 1, "share's fit owners"));
  PM_CALL(PM_ALLOC(s->q, FPM_QFIT * nq + 1, "share's fit weights"));
  PM_CALL(PM_ALLOC(s->qsum, FPM_QFIT * n, "share's fit sums"));
  copy_items(s->qsum, m->qsum, s->gid, n, FPM_QFIT);
  for (long li = 0; li < ns; li++) {
    const long e0 = m->qs_ptr[s->gid[li]], f0 = s->qs_ptr[li];
    memcpy(s->q + FPM_QFIT * f0, m->q + FPM_QFIT * e0,
           sizeof(double) * FPM_QFIT * (s->qs_ptr[li + 1] - f0));
    for (long f = f0; f < s->qs_ptr[li + 1]; f++) s->qs_own[f] = (int)li;
  }
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
  return PM_SUCCESS;
}

/* The boundary: the consistency flux and the tractions of the points whose
 * flux the share computes (in one process's order: facets that share a
 * point add up in it), the prescribed dofs of its own points. */
static pm_err share_boundary(const fpm_model *m, fpm_model *s, const int *lof) {
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
  s->tf_time_dependent = m->tf_time_dependent;
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

pm_err fpm_share_create(const fpm_model *m, const int *owner, int r,
                        fpm_model **out) {
  pm_err ret = PM_SUCCESS;
  fpm_model *s = NULL;
  signed char *level = NULL;
  int *lof = NULL; /* each point's index in the share, or -1 */
  *out = NULL;
  PM_TRY(PM_ALLOC(level, m->n + 1, "share's points"));
  PM_TRY(PM_ALLOC(lof, m->n + 1, "share's points"));
  share_levels(m, owner, r, level);
  PM_TRY(PM_ALLOC(s, 1, "FPM model (a rank's share)"));
  PM_TRY(PM_ALLOC(s->own_dual, 1, "share's points"));
  long count[NONE + 1] = {0};
  for (long i = 0; i < m->n; i++) count[level[i]]++;
  s->n_own = count[OWN];
  s->n_flux = s->n_own + count[FLUX];
  s->n_stress = s->n_flux + count[STRESS];
  s->n = s->n_stress + count[DISPLACEMENT];
  PM_TRY(PM_ALLOC(s->gid, s->n + 1, "share's point indices"));
  long at = 0;
  for (int lv = OWN; lv < NONE; lv++)
    for (long i = 0; i < m->n; i++)
      if (level[i] == lv) s->gid[at++] = i;
  for (long i = 0; i < m->n; i++) lof[i] = -1;
  for (long li = 0; li < s->n; li++) lof[s->gid[li]] = (int)li;
  s->dim = m->dim;
  s->own_dual->dim = m->dim;
  s->own_dual->n_points = s->n;
  s->dual = s->own_dual;
  s->scene = m->scene;
  s->penalty = m->penalty;
  s->flux = m->flux;
  s->jump = m->jump;
  s->n_mats = m->n_mats;
  memcpy(s->mats, m->mats, sizeof s->mats);
  PM_TRY(share_points(m, s, lof));
  if (m->qs_ptr) PM_TRY(share_fits(m, s, lof));
  PM_TRY(share_boundary(m, s, lof));
  *out = s;
  s = NULL;
done:
  fpm_model_destroy(s);
  free(level);
  free(lof);
  return ret;
}

void fpm_share_count(const fpm_model *s, fpm_share_counts *c) {
  c->own = s->n_own;
  c->flux_ghosts = s->n_flux - s->n_own;
  c->stress_ghosts = s->n_stress - s->n_flux;
  c->u_ghosts = s->n - s->n_stress;
  c->bytes = (double)(fpm_model_bytes(s) + fpm_state_bytes(s));
}

/* ---- plan ------------------------------------------------------------------
 */

void fpm_share_print(const fpm_model *m, const int *owner, int parts,
                     const fpm_share_counts *c, FILE *out) {
  long most = 0, ghosts = 0, most_ghosts = 0;
  for (int r = 0; r < parts; r++) {
    const long g = c[r].flux_ghosts + c[r].stress_ghosts + c[r].u_ghosts;
    most = c[r].own > most ? c[r].own : most;
    most_ghosts = g > most_ghosts ? g : most_ghosts;
    ghosts += g;
  }
  fprintf(out,
          "ranks        %d: points by PT-Scotch on the support graph "
          "(MatPartitioning), %s\n"
          "             %ld support pairs cut of %ld; points per rank %ld at "
          "most (imbalance %.3f: the most over the mean)\n",
          parts,
          m->qs_ptr ? "ghosts to 3 rings of support, 5 where the quadratic "
                      "fits take two"
                    : "ghosts to 3 rings of support",
          fpm_partition_edge_cut(m, owner), m->nbr_ptr[m->n] / 2, most,
          m->n > 0 ? most * (double)parts / m->n : 0.0);
  if (parts <= 16) {
    fprintf(out, "             rank  points  ghosts (flux + stress + "
                 "displacement)  memory\n");
    for (int r = 0; r < parts; r++)
      fprintf(out, "             %4d  %6ld  %6ld (%ld + %ld + %ld)  %.1f MiB\n",
              r, c[r].own,
              c[r].flux_ghosts + c[r].stress_ghosts + c[r].u_ghosts,
              c[r].flux_ghosts, c[r].stress_ghosts, c[r].u_ghosts,
              c[r].bytes / 1048576.0);
  }
  fprintf(out,
          "             ghost points per rank %.0f on average, %ld at most: a "
          "rank receives their displacements, %.0f bytes per step on "
          "average, %.0f at most\n",
          (double)ghosts / parts, most_ghosts,
          3.0 * sizeof(double) * ghosts / parts,
          3.0 * sizeof(double) * most_ghosts);
}

pm_err fpm_share_predict(const fpm_model *m, int parts, FILE *out) {
  pm_err ret = PM_SUCCESS;
  int *owner = NULL;
  fpm_share_counts *c = NULL;
  fpm_model *s = NULL;
  PM_TRY(PM_ALLOC(owner, m->n + 1, "partition"));
  PM_TRY(PM_ALLOC(c, parts, "shares"));
  PM_TRY(fpm_partition(m, parts, owner));
  for (int r = 0; r < parts; r++) {
    PM_TRY(fpm_share_create(m, owner, r, &s));
    fpm_share_count(s, &c[r]);
    fpm_model_destroy(s);
    s = NULL;
  }
  fpm_share_print(m, owner, parts, c, out);
done:
  fpm_model_destroy(s);
  free(owner);
  free(c);
  return ret;
}
