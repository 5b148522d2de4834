/* fpm_share: the partition of the points (Scotch) and the choice of a
 * rank's share of an FPM model, its own points and ghosts in pass order
 * (the model of them is fpm_model_subset's). */
#include "fpm_share.h"

#include <stdlib.h>
#include <string.h>

#include "fpm_scotch.h"

/* ---- partition ------------------------------------------------------------
 */

pm_err fpm_partition(const gm_dual *d, int parts, int *owner) {
  pm_err ret = PM_SUCCESS;
  const long n = d->n_points;
  long *w = NULL;
  memset(owner, 0, sizeof(int) * (size_t)n);
  if (parts <= 1) return PM_SUCCESS;
  /* A point's work in the passes: its support's entries. */
  PM_TRY(PM_ALLOC(w, n + 1, "partition weights"));
  for (long i = 0; i < n; i++) w[i] = 1 + d->nbr_ptr[i + 1] - d->nbr_ptr[i];
  PM_TRY(fpm_scotch_part(n, d->nbr_ptr, d->nbr, w, parts, owner));
done:
  free(w);
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

/* Rank r's share of m (t: m where the share takes it, else NULL). */
static pm_err share_make(const fpm_model *m, const int *owner, int r,
                         fpm_model *t, fpm_model **out) {
  pm_err ret = PM_SUCCESS;
  signed char *level = NULL;
  long *gid = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(level, m->n + 1, "share's points"));
  share_levels(m, owner, r, level);
  long count[NONE + 1] = {0};
  for (long i = 0; i < m->n; i++) count[level[i]]++;
  fpm_points pts = {.n_own = count[OWN]};
  pts.n_flux = pts.n_own + count[FLUX];
  pts.n_stress = pts.n_flux + count[STRESS];
  pts.n = pts.n_stress + count[DISPLACEMENT];
  PM_TRY(PM_ALLOC(gid, pts.n + 1, "share's point indices"));
  long at = 0;
  for (int lv = OWN; lv < NONE; lv++)
    for (long i = 0; i < m->n; i++)
      if (level[i] == lv) gid[at++] = i;
  pts.gid = gid;
  free(level);
  level = NULL;
  PM_TRY(t ? fpm_model_subset_take(t, &pts, out)
           : fpm_model_subset(m, &pts, out));
done:
  free(level);
  free(gid);
  return ret;
}

pm_err fpm_share_create(const fpm_model *m, const int *owner, int r,
                        fpm_model **out) {
  return share_make(m, owner, r, NULL, out);
}

pm_err fpm_share_take(fpm_model *m, const int *owner, int r, fpm_model **out) {
  return share_make(m, owner, r, m, out);
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
          "ranks        %d: points by Scotch on the support graph, %s\n"
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
  int largest = 0;
  for (int r = 1; r < parts; r++)
    if (c[r].bytes > c[largest].bytes) largest = r;
  fprintf(out,
          "             memory per rank: %.1f MiB at most (rank %d's share, "
          "operators and state); a rank that keeps the whole model (rank 0 "
          "where the frames are gathered) holds its %.1f MiB besides\n",
          c[largest].bytes / 1048576.0, largest,
          (double)(fpm_model_bytes(m) + fpm_state_bytes(m)) / 1048576.0);
  /* with the averaged volume also their pressures U'(Jbar) */
  const double per = (m->vavg ? 4.0 : 3.0) * sizeof(double);
  fprintf(out,
          "             ghost points per rank %.0f on average, %ld at most: a "
          "rank receives their displacements%s, %.0f bytes per step on "
          "average, %.0f at most\n",
          (double)ghosts / parts, most_ghosts,
          m->vavg ? " and averaged pressures" : "", per * ghosts / parts,
          per * most_ghosts);
}

pm_err fpm_share_predict(const fpm_model *m, int parts, FILE *out) {
  pm_err ret = PM_SUCCESS;
  int *owner = NULL;
  fpm_share_counts *c = NULL;
  fpm_model *s = NULL;
  PM_TRY(PM_ALLOC(owner, m->n + 1, "partition"));
  PM_TRY(PM_ALLOC(c, parts, "shares"));
  PM_TRY(fpm_partition(m->dual, parts, owner));
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
