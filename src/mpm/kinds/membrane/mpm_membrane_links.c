/* mpm_membrane_links: the membrane's links (its triangles, each point's
 * incidence, a curve's neighbours) and first normals and frames, on one
 * process and, whenever points move, on each rank with its ghosts. */
#include <stdlib.h>
#include <string.h>

#include "gm_curve.h"
#include "gm_trisurf.h"
#include "mpm_membrane_impl.h"

/* The centre of body b (the mean of its points, x counted within the
 * group). */
static void body_centre(const double *x, const struct membrane_body *b,
                        double c[3]) {
  c[0] = c[1] = c[2] = 0;
  for (long j = b->begin; j < b->end; j++)
    for (int d = 0; d < 3; d++)
      c[d] += x[3 * j + d] / (double)(b->end - b->begin);
}

/* The unit vector from c to point k, or 0. */
static void away_from(const double *x, const double c[3], long k, double v[3]) {
  for (int d = 0; d < 3; d++) v[d] = x[3 * k + d] - c[d];
  double len = pm_v_norm(v);
  for (int d = 0; d < 3; d++) v[d] = len > 0 ? v[d] / len : 0;
}

/* The group's bodies, its incidence, and each point's first normal and
 * frame (setup).  Without connectivity, the first normals are turned to
 * point away from the body's centre. */
pm_err mpm_membrane_finish(const mpm_model *m, mpm_group *g, mpm_state *s) {
  membrane_params *mp = g->params;
  const long t0 = m->tri_begin[g->index], t1 = m->tri_end[g->index];
  const long np = g->end - g->begin;
  double *tn = NULL, *nn = NULL, *ref = NULL;
  void *iw = NULL;
  size_t iw_bytes;
  pm_err ret = PM_SUCCESS;
  PM_TRY(PM_ALLOC(mp->bodies, m->n_bodies, "membrane bodies"));
  for (int b = 0; b < m->n_bodies; b++) {
    if (m->body_end[b] <= m->body_begin[b] || m->body_begin[b] < g->begin ||
        m->body_end[b] > g->end)
      continue;
    struct membrane_body *mb = &mp->bodies[mp->n_bodies++];
    mb->body = b;
    mb->begin = m->body_begin[b] - g->begin;
    mb->end = m->body_end[b] - g->begin;
    mb->links = m->body_links[b];
    mb->method = m->body_normals[b];
    if (mb->method != PM_NORMALS_CONNECTIVITY) mp->iso = true;
    if (mb->end - mb->begin > mp->max_body) mp->max_body = mb->end - mb->begin;
  }
  /* The links: the group's triangles, each point's (the surface's
   * incidence), and along curves each point's neighbours. */
  PM_TRY(mpm_triangles_local(m, t0, t1, g->begin, &mp->tri));
  mp->n_tris = mp->tri_room = t1 - t0;
  mp->point_room = np;
  gm_trisurf sf = {.n_points = np,
                   .x = s->x + 3 * g->begin,
                   .n_tris = t1 - t0,
                   .tri = mp->tri};
  PM_TRY(gm_trisurf_incidence(&sf, &mp->inc_start, &mp->inc_tri));
  mp->inc_room = mp->inc_start[np];
  PM_TRY(PM_ALLOC(mp->link, 2 * np + 1, "membrane curves"));
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    if (b->links != MPM_LINKS_CHAIN && b->links != MPM_LINKS_LOOP) continue;
    for (long k = b->begin; k < b->end; k++) {
      long prev, next;
      gm_curve_neighbours(k - b->begin, b->end - b->begin,
                          b->links == MPM_LINKS_LOOP, &prev, &next);
      mp->link[2 * k] = b->begin + prev;
      mp->link[2 * k + 1] = b->begin + next;
    }
  }
  PM_TRY(PM_ALLOC(tn, 3 * (t1 - t0) + 3, "triangle normals"));
  PM_TRY(PM_ALLOC(nn, 3 * np, "membrane normals"));
  PM_TRY(mpm_membrane_fits_create(m, g, &iw, &iw_bytes));
  /* The reference of the first normals' sides: the connectivity's
   * normals where the body has connectivity, else away from its centre;
   * they are also the fit's previous normals. */
  PM_TRY(PM_ALLOC(ref, 3 * np, "membrane normals"));
  const double *xo = s->x + 3 * g->begin;
  if (t1 > t0) mpm_membrane_triangle_normals(mp, xo, NULL, np, tn);
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    if (b->links == MPM_LINKS_CHAIN || b->links == MPM_LINKS_LOOP)
      gm_curve_normals(b->end - b->begin, xo + 3 * b->begin,
                       b->links == MPM_LINKS_LOOP, ref + 3 * b->begin);
    double c[3];
    body_centre(xo, b, c);
    for (long k = b->begin; k < b->end; k++) {
      if (b->links == MPM_LINKS_TRIANGLES) point_normal(mp, k, tn, ref + 3 * k);
      if (!(pm_v_norm(ref + 3 * k) > 0.5)) away_from(xo, c, k, ref + 3 * k);
    }
  }
  memcpy(nn, ref, sizeof(double) * 3 * (size_t)np);
  iso_stats st = {0};
  PM_TRY(mpm_membrane_group_normals(m, g, s->x, -1, iw, tn, nn, &st));
  double *frame = s->group[g->index].array[MEM_FRAME].data;
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    for (long k = b->begin; k < b->end; k++) {
      double *n = nn + 3 * k, *xp = s->x + 3 * (g->begin + k);
      /* A fitted normal's sign is arbitrary: the reference's side. */
      if (pm_v_dot(n, ref + 3 * k) < 0)
        for (int d = 0; d < 3; d++) n[d] = -n[d];
      bool has = pm_v_norm(n) > 0.5;
      if (has && b->method == PM_NORMALS_CONNECTIVITY &&
          b->links == MPM_LINKS_TRIANGLES) {
        double n1[3];
        has = point_normal(mp, k, tn, n1);
      }
      PM_ENSURE(has, PM_ERR_SCENE,
                "membrane %s: point %ld at (%g, %g, %g) has no normal (it "
                "belongs to no triangle, or its triangles' normals cancel)",
                g->name, g->begin + k, xp[0], xp[1], xp[2]);
      mpm_membrane_frame_from_normal(n, frame + 9 * k);
    }
  }
done:
  mpm_membrane_fits_free(iw);
  free(tn);
  free(nn);
  free(ref);
  return ret;
}

/* ---- across ranks ---------------------------------------------------------
 * A rank's points of the group read their neighbours' positions: the
 * points of its triangles, and along a curve the points before and after
 * them.  Those on other ranks are ghosts (mpm_par.h sends their positions
 * after every step's migration); the links are made anew from the whole
 * group's whenever points move between ranks. */

/* Room for n longs in *a (room *room), kept when it suffices. */
static pm_err room_for_longs(long **a, long *room, long n, const char *what) {
  if (n <= *room && *a) return PM_SUCCESS;
  const long r = n + n / 4 + 16;
  PM_CALL(PM_REALLOC(*a, r, what));
  *room = r;
  return PM_SUCCESS;
}

static int long_cmp(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* Sort n longs and drop repeats; returns how many are left. */
static long sort_unique(long *a, long n) {
  if (n == 0) return 0;
  qsort(a, (size_t)n, sizeof *a, long_cmp);
  long k = 1;
  for (long i = 1; i < n; i++)
    if (a[i] != a[k - 1]) a[k++] = a[i];
  return k;
}

/* The place of v in the sorted a[0, n), or -1. */
static long find_long(const long *a, long n, long v) {
  const long *f = bsearch(&v, a, (size_t)n, sizeof *a, long_cmp);
  return f ? f - a : -1;
}

pm_err mpm_membrane_ranks_share(const mpm_group *whole, mpm_group *g) {
  const membrane_params *wp = whole->params;
  membrane_params *mp = g->params;
  const long np = whole->end - whole->begin;
  PM_CALL(PM_ALLOC(mp->bodies, wp->n_bodies + 1, "membrane bodies"));
  memcpy(mp->bodies, wp->bodies, sizeof *wp->bodies * (size_t)wp->n_bodies);
  mp->n_bodies = wp->n_bodies;
  mp->iso = wp->iso;
  mp->max_body = wp->max_body;
  mp->whole.first = whole->begin;
  mp->whole.n_points = np;
  mp->whole.n_tris = wp->n_tris;
  PM_CALL(PM_ALLOC(mp->whole.tri, 3 * wp->n_tris + 1, "membrane triangles"));
  PM_CALL(PM_ALLOC(mp->whole.inc_start, np + 1, "membrane incidence"));
  PM_CALL(
      PM_ALLOC(mp->whole.inc_tri, wp->inc_start[np] + 1, "membrane incidence"));
  memcpy(mp->whole.tri, wp->tri, sizeof(long) * 3 * (size_t)wp->n_tris);
  memcpy(mp->whole.inc_start, wp->inc_start, sizeof(long) * (size_t)(np + 1));
  memcpy(mp->whole.inc_tri, wp->inc_tri,
         sizeof(long) * (size_t)wp->inc_start[np]);
  return PM_SUCCESS;
}

/* The link point of the whole group's point q: the rank's point (from the
 * group's start; its points' one-process indices own[0, np), increasing)
 * or np + its place among the ghosts want[0, nw). */
static long link_of(const long *own, long np, const long *want, long nw,
                    long q) {
  long k = find_long(own, np, q);
  return k >= 0 ? k : np + find_long(want, nw, q);
}

pm_err mpm_membrane_ranks_link(const mpm_model *m, mpm_group *g, long **want,
                               long *room, long *n_want) {
  membrane_params *mp = g->params;
  const long np = g->end - g->begin, first = mp->whole.first;
  const long *own = m->gid + g->begin, *ws = mp->whole.inc_start,
             *wi = mp->whole.inc_tri, *wt = mp->whole.tri;
  /* The triangles of the rank's points, by their index in the whole. */
  long nt = 0;
  for (long k = 0; k < np; k++)
    nt += ws[own[k] - first + 1] - ws[own[k] - first];
  const long ni = nt; /* the incidence's entries */
  const long tri_room = mp->tri_room;
  PM_CALL(
      room_for_longs(&mp->tri_whole, &mp->tri_room, nt, "membrane triangles"));
  if (mp->tri_room != tri_room || !mp->tri)
    PM_CALL(PM_REALLOC(mp->tri, 3 * mp->tri_room, "membrane triangles"));
  if (np > mp->point_room || !mp->link) {
    const long r = np + np / 4 + 16;
    PM_CALL(PM_REALLOC(mp->link, 2 * r, "membrane curves"));
    PM_CALL(PM_REALLOC(mp->inc_start, r + 1, "membrane incidence"));
    mp->point_room = r;
  }
  PM_CALL(
      room_for_longs(&mp->inc_tri, &mp->inc_room, ni, "membrane incidence"));
  nt = 0;
  for (long k = 0; k < np; k++)
    for (long j = ws[own[k] - first]; j < ws[own[k] - first + 1]; j++)
      mp->tri_whole[nt++] = wi[j];
  nt = sort_unique(mp->tri_whole, nt);
  /* The ghosts: their corners and the curves' neighbours that are not the
   * rank's, by one-process index. */
  PM_CALL(room_for_longs(want, room, 3 * nt + 2 * np, "membrane ghosts"));
  long nw = 0;
  for (long t = 0; t < nt; t++)
    for (int c = 0; c < 3; c++) {
      const long q = first + wt[3 * mp->tri_whole[t] + c];
      if (find_long(own, np, q) < 0) (*want)[nw++] = q;
    }
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    if (b->links != MPM_LINKS_CHAIN && b->links != MPM_LINKS_LOOP) continue;
    const long b0 = m->body_begin[b->body] - g->begin,
               b1 = m->body_end[b->body] - g->begin;
    for (long k = b0; k < b1; k++) {
      long prev, next;
      gm_curve_neighbours(own[k] - first - b->begin, b->end - b->begin,
                          b->links == MPM_LINKS_LOOP, &prev, &next);
      mp->link[2 * k] = first + b->begin + prev; /* one-process, for now */
      mp->link[2 * k + 1] = first + b->begin + next;
      for (int e = 0; e < 2; e++)
        if (find_long(own, np, mp->link[2 * k + e]) < 0)
          (*want)[nw++] = mp->link[2 * k + e];
    }
  }
  nw = sort_unique(*want, nw);
  *n_want = nw;
  /* The triangles' corners, the incidence and the curves' neighbours as
   * link points. */
  for (long t = 0; t < nt; t++)
    for (int c = 0; c < 3; c++)
      mp->tri[3 * t + c] =
          link_of(own, np, *want, nw, first + wt[3 * mp->tri_whole[t] + c]);
  mp->n_tris = nt;
  long at = 0;
  for (long k = 0; k < np; k++) {
    mp->inc_start[k] = at;
    for (long j = ws[own[k] - first]; j < ws[own[k] - first + 1]; j++)
      mp->inc_tri[at++] = find_long(mp->tri_whole, nt, wi[j]);
  }
  mp->inc_start[np] = at;
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    if (b->links != MPM_LINKS_CHAIN && b->links != MPM_LINKS_LOOP) continue;
    for (long k = m->body_begin[b->body] - g->begin;
         k < m->body_end[b->body] - g->begin; k++)
      for (int e = 0; e < 2; e++)
        mp->link[2 * k + e] = link_of(own, np, *want, nw, mp->link[2 * k + e]);
  }
  return PM_SUCCESS;
}
