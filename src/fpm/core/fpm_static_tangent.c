/* fpm_static_tangent: the tangent of FPM's static solve assembled
 * directly: its constant parts (the interface and boundary geometry E
 * gathered by the GFD weights, the penalty's matrix S) built once, and its
 * values in the Jacobian's pattern at each Newton iteration. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_gfd.h"
#include "fpm_penalty_terms.h"
#include "fpm_static_impl.h"
#include "pm_omp.h"

void fpm_static_tangent_free(fpm_static_tangent *t) {
  free(t->R_ptr);
  free(t->R_list);
  free(t->E_ptr);
  free(t->E_j);
  free(t->E);
  free(t->S_ptr);
  free(t->S_m);
  free(t->S);
  free(t->Dg);
  free(t->Dg_ptr);
  free(t->work);
  free(t->mark);
  free(t->Sq_off);
  free(t->Sq_w);
  free(t->Sx_e);
  free(t->Sx_mark);
  free(t->Sx_list);
  free(t->Sx_acc);
}

/* Adds the 3 x 3 geometry C^c_ij (rows s, columns q) of T_i = sum_j P_j C_ij
 * for component row c: member r of i's closed support. */
static void flux_geometry(const fpm_model *m, const long *dpt_of, long i,
                          long r, int c, double C[9], double cv[3]) {
  if (r == 0) {
    const double *Bm = m->p_mrel + 9 * i, *A = m->p_area + 3 * i;
    for (int a = 0; a < 9; a++) C[a] = -0.5 * Bm[a];
    for (int a = 0; a < 3; a++) {
      C[4 * a] += m->dual->volume[i];
      cv[a] = -0.5 * A[a];
    }
    long p = dpt_of[i];
    if (p >= 0) {
      const double *Ac = m->dpt_area + 9 * p + 3 * c,
                   *Bc = m->dpt_mrel + 27 * p + 9 * c;
      for (int a = 0; a < 9; a++) C[a] -= Bc[a];
      for (int a = 0; a < 3; a++) cv[a] -= Ac[a];
    }
    return;
  }
  const double *rec = m->erec + FPM_EREC * (m->nbr_ptr[i] + r - 1);
  const double *a = rec, *Mc = rec + 3, *di = rec + 12;
  for (int s = 0; s < 3; s++) {
    cv[s] = -0.5 * a[s];
    for (int q = 0; q < 3; q++)
      C[3 * s + q] = -0.5 * (Mc[3 * s + q] + a[s] * di[q]);
  }
}

/* E: per point k, the points j whose stress reaches f_k, with
 * E^c_kj[s] = sum_i C^c_ij[s] . gamma_ik + c^c_kj[s]. */
static pm_err build_E(const fpm_model *m, fpm_static_tangent *t) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, rows = m->n_own; /* (rows: the own points') */
  long *mark = NULL, *list = NULL, *dpt_of = NULL;
  PM_TRY(PM_ALLOC(mark, n, "tangent marks"));
  PM_TRY(PM_ALLOC(list, n, "tangent lists"));
  PM_TRY(PM_ALLOC(dpt_of, n, "prescribed-face points"));
  PM_TRY(PM_ALLOC(t->E_ptr, n + 1, "tangent geometry"));
  for (long i = 0; i < n; i++) mark[i] = dpt_of[i] = -1;
  for (long p = 0; p < m->n_dpts; p++) dpt_of[m->dpt_point[p]] = p;
  for (int pass = 0; pass < 2; pass++) {
    for (long k = 0; k < rows; k++) {
      long cnt = 0;
      /* i over k's closed support: gamma_ik is the weight of u_k in H_i */
      for (long ri = 0; ri < closed_size(m, k); ri++) {
        const double *dummy;
        long i = closed_member(m, k, ri, &dummy);
        for (long rj = 0; rj < closed_size(m, i); rj++) {
          long j = closed_member(m, i, rj, &dummy);
          if (mark[j] < 0) {
            mark[j] = cnt;
            list[cnt++] = j;
          }
        }
      }
      if (pass == 1) {
        double *E = t->E + 9 * t->E_ptr[k];
        for (long a = 0; a < cnt; a++) t->E_j[t->E_ptr[k] + a] = list[a];
        for (long ri = 0; ri < closed_size(m, k); ri++) {
          const double *w;
          long i = closed_member(m, k, ri, &w);
          double gik[3];
          if (ri == 0)
            for (int a = 0; a < 3; a++) gik[a] = -w[a];
          else {
            const double *g = m->g + 3 * m->mirror[m->nbr_ptr[k] + ri - 1];
            for (int a = 0; a < 3; a++) gik[a] = g[a];
          }
          for (long rj = 0; rj < closed_size(m, i); rj++) {
            const double *dummy;
            long j = closed_member(m, i, rj, &dummy);
            double *Ekj = E + 9 * mark[j];
            for (int c = 0; c < 3; c++) {
              double C[9], cv[3];
              flux_geometry(m, dpt_of, i, rj, c, C, cv);
              for (int s2 = 0; s2 < 3; s2++)
                Ekj[3 * c + s2] += C[3 * s2] * gik[0] + C[3 * s2 + 1] * gik[1] +
                                   C[3 * s2 + 2] * gik[2];
            }
          }
        }
        /* r_k = sum_j P_j c_kj over k's closed support */
        for (long rj = 0; rj < closed_size(m, k); rj++) {
          const double *dummy;
          long j = closed_member(m, k, rj, &dummy);
          for (int c = 0; c < 3; c++) {
            double C[9], cv[3];
            flux_geometry(m, dpt_of, k, rj, c, C, cv);
            for (int s2 = 0; s2 < 3; s2++)
              E[9 * mark[j] + 3 * c + s2] += cv[s2];
          }
        }
      } else {
        t->E_ptr[k + 1] = cnt;
      }
      for (long a = 0; a < cnt; a++) mark[list[a]] = -1;
    }
    if (pass == 0) {
      for (long k = 0; k < rows; k++) t->E_ptr[k + 1] += t->E_ptr[k];
      PM_TRY(PM_ALLOC(t->E_j, t->E_ptr[rows] + 1, "tangent geometry"));
      PM_TRY(PM_ALLOC(t->E, 9 * t->E_ptr[rows] + 1, "tangent geometry"));
    }
  }
done:
  free(mark);
  free(list);
  free(dpt_of);
  return ret;
}

/* The point of the r-th member of i's reconstruction support (r = 0: i). */
static long recon_id(const fpm_model *m, bool quad, long i, long r) {
  if (!quad) {
    const double *g;
    return closed_member(m, i, r, &g);
  }
  return r == 0 ? i : m->qs_nbr[m->qs_ptr[i] + r - 1];
}

/* The penalty's reconstruction weight of u_x in point i's field at offset
 * d (linear: H_i d; quadratic: theta_i phi with phi = fpm_gfd_phi(d), which
 * the caller evaluates once for all members), for the r-th member of
 * i's reconstruction support; returns the member's point. */
static long recon_member(const fpm_model *m, bool quad, long i, long r,
                         const double d[3], const double *phi, double *w) {
  if (quad) {
    const double *q;
    long x;
    if (r == 0) {
      q = m->qsum + FPM_QFIT * i;
      x = i;
    } else {
      q = m->q + FPM_QFIT * (m->qs_ptr[i] + r - 1);
      x = m->qs_nbr[m->qs_ptr[i] + r - 1];
    }
    double v = 0;
    for (int a = 0; a < FPM_QFIT; a++) v += q[a] * phi[a];
    *w = r == 0 ? -v : v;
    return x;
  }
  const double *g;
  long x = closed_member(m, i, r, &g);
  double v = g[0] * d[0] + g[1] * d[1] + g[2] * d[2];
  *w = r == 0 ? -v : v;
  return x;
}

static long recon_size(const fpm_model *m, bool quad, long i) {
  return quad ? m->qs_ptr[i + 1] - m->qs_ptr[i] + 1 : closed_size(m, i);
}

/* The reconstruction weights of one kind of jump (quad: the fits'; else
 * the linear fields'), for every interface e of beta_e != 0 in that kind's
 * slot of erec: at w + off[e], the weights (recon_member) of the members
 * of its point i's reconstruction at d_i, then those of its neighbour's at
 * d_k.  Made once for the rows of S, which each read them many times. */
typedef struct {
  long *off;
  double *w;
} sweights;

static int s_slot(const fpm_model *m, bool quad) {
  return quad || !m->q ? 18 : 19;
}

static void sweights_free(sweights *sw) {
  free(sw->off);
  free(sw->w);
}

static pm_err sweights_build(const fpm_model *m, bool quad, sweights *sw) {
  const long n = m->n, ne = m->nbr_ptr[n];
  const int slot = s_slot(m, quad);
  PM_CALL(PM_ALLOC(sw->off, ne + 1, "penalty weights"));
  for (long i = 0; i < n; i++)
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++)
      sw->off[e + 1] =
          m->erec[FPM_EREC * e + slot] == 0
              ? 0
              : recon_size(m, quad, i) + recon_size(m, quad, m->nbr[e]);
  for (long e = 0; e < ne; e++) sw->off[e + 1] += sw->off[e];
  PM_CALL(PM_ALLOC(sw->w, sw->off[ne] + 1, "penalty weights"));
  const long *off = sw->off;
  double *w = sw->w;
  PM_OMP(parallel for schedule(dynamic, 16) default(none)
         shared(m, quad, slot, n, off, w))
  for (long i = 0; i < n; i++)
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
      const double *rec = m->erec + FPM_EREC * e;
      if (rec[slot] == 0) continue;
      const long kk = m->nbr[e], ri = recon_size(m, quad, i);
      double phi[FPM_QFIT], *out = w + off[e];
      if (quad) fpm_gfd_phi(rec + 12, phi);
      for (long r = 0; r < ri; r++)
        recon_member(m, quad, i, r, rec + 12, quad ? phi : NULL, out + r);
      if (quad) fpm_gfd_phi(rec + 15, phi);
      for (long r = 0; r < recon_size(m, quad, kk); r++)
        recon_member(m, quad, kk, r, rec + 15, quad ? phi : NULL, out + ri + r);
    }
  return PM_SUCCESS;
}

/* The row scratch of build_S (a thread's): mark[x] is x's slot in
 * list/acc, or -1. */
typedef struct {
  long *mark, *list, cnt;
  double *acc; /* 1 per slot, or 9 (a 3 x 3 block) with add_S_row's blocks */
} srow;

/* Adds to row k of S the penalty of one reconstruction (quad: the fits'
 * jump with beta = rec[18]; else the linear fields' jump with beta =
 * rec[18], or rec[19] beside the quadratic jump), from its weights sw;
 * with blocks not NULL, the 3 x 3 block blocks[9 e] in place of beta on
 * the entries that have one, into 9 values a slot of w->acc. */
static void add_S_row(const fpm_model *m, bool quad, const sweights *sw, long k,
                      const double *blocks, srow *w) {
  const int slot = s_slot(m, quad);
  /* the points i whose own field at their interfaces moves with u_k:
   * k itself and those whose reconstruction holds k */
  long ni = quad ? 1 + m->qt_ptr[k + 1] - m->qt_ptr[k] : closed_size(m, k);
  for (long ii = 0; ii < ni; ii++) {
    long i;
    if (ii == 0)
      i = k;
    else if (quad)
      i = m->qs_own[m->qt_entry[m->qt_ptr[k] + ii - 1]];
    else
      i = m->nbr[m->nbr_ptr[k] + ii - 1];
    const long ri = recon_size(m, quad, i);
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
      const double be = m->erec[FPM_EREC * e + slot];
      const double *blk = blocks ? blocks + 9 * e : NULL;
      const long kk = m->nbr[e];
      if (be == 0 || (blk && blk[0] == 0 && blk[4] == 0 && blk[8] == 0))
        continue;
      const double *wi = sw->w + sw->off[e];
      /* t_ek: k's weight in u_i + recon_i(d_i) */
      double tk = 0;
      for (long r = 0; r < ri; r++)
        if (recon_id(m, quad, i, r) == k) tk += wi[r];
      if (k == i) tk += 1;
      if (tk == 0) continue;
      /* J_em over both sides */
      for (int side = 0; side < 2; side++) {
        const long p = side ? kk : i;
        const double sign = side ? -1 : 1, *ws = side ? wi + ri : wi;
        for (long r = 0; r < recon_size(m, quad, p); r++) {
          double wt = ws[r];
          const long x = recon_id(m, quad, p, r);
          if (r == 0) wt += 1;
          const long width = blk ? 9 : 1;
          if (w->mark[x] < 0) {
            w->mark[x] = w->cnt;
            w->list[w->cnt++] = x;
            for (long q = 0; q < width; q++) w->acc[width * w->mark[x] + q] = 0;
          }
          if (blk)
            for (int q = 0; q < 9; q++)
              w->acc[9 * w->mark[x] + q] += tk * sign * wt * blk[q];
          else
            w->acc[w->mark[x]] += be * tk * sign * wt;
        }
      }
    }
  }
}

/* S: the penalty's scalar matrix, S_km = sum_i sum_(e of i) beta_e
 * t_ek J_em with [[u]]_e = sum_m J_em u_m and t_ek = d[[u]]_e / d u_k
 * through point i's side only (the force of the side's own field); with
 * the quadratic jump, plus the boundary interfaces' linear-jump term.
 * fpm.stiffening's quartic term and fpm.volume_penalty are not in S (their
 * tangents depend on the state): with them this tangent is approximate and
 * preconditions fpm_force_linear's exact linearisation (fpm_static.c); the
 * stiffening of the quadratic jump adds its 3 x 3 blocks at each assembly
 * (tangent_values, Sx_e), the weights of the fits kept for it.
 * Rows on every thread, each with its own scratch: a row's sum is one
 * thread's, in the order one thread takes, so the bits do not depend on
 * the threads. */
static pm_err build_S(const fpm_model *m, fpm_static_tangent *t) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, rows = m->n_own;
  const int threads = pm_omp_threads();
  long *mark = NULL, *list = NULL;
  double *acc = NULL;
  sweights sq = {0}, sl = {0};
  bool lin_too = false;
  if (m->q)
    for (long e = 0; e < m->nnz && !lin_too; e++)
      lin_too = m->erec[FPM_EREC * e + 19] != 0;
  PM_TRY(sweights_build(m, m->q != NULL, &sq));
  if (lin_too) PM_TRY(sweights_build(m, false, &sl));
  PM_TRY(PM_ALLOC(mark, (size_t)threads * n, "penalty marks"));
  PM_TRY(PM_ALLOC(list, (size_t)threads * n, "penalty lists"));
  PM_TRY(PM_ALLOC(acc, (size_t)threads * n, "penalty row"));
  PM_TRY(PM_ALLOC(t->S_ptr, n + 1, "penalty matrix"));
  for (long i = 0; i < (long)threads * n; i++) mark[i] = -1;
  for (int pass = 0; pass < 2; pass++) {
    PM_OMP(parallel default(none)
               shared(m, t, mark, list, acc, n, rows, lin_too, pass, sq, sl)) {
      const long off = (long)pm_omp_thread() * n;
      srow w = {.mark = mark + off, .list = list + off, .acc = acc + off};
      PM_OMP(for schedule(dynamic, 16))
      for (long k = 0; k < rows; k++) {
        w.cnt = 0;
        add_S_row(m, m->q != NULL, &sq, k, NULL, &w);
        if (lin_too) add_S_row(m, false, &sl, k, NULL, &w);
        if (pass == 0)
          t->S_ptr[k + 1] = w.cnt;
        else
          for (long a = 0; a < w.cnt; a++) {
            t->S_m[t->S_ptr[k] + a] = w.list[a];
            t->S[t->S_ptr[k] + a] = w.acc[a];
          }
        for (long a = 0; a < w.cnt; a++) w.mark[w.list[a]] = -1;
      }
    }
    if (pass == 0) {
      for (long k = 0; k < rows; k++) t->S_ptr[k + 1] += t->S_ptr[k];
      PM_TRY(PM_ALLOC(t->S_m, t->S_ptr[rows] > 0 ? t->S_ptr[rows] : 1,
                      "penalty matrix"));
      PM_TRY(PM_ALLOC(t->S, t->S_ptr[rows] > 0 ? t->S_ptr[rows] : 1,
                      "penalty matrix"));
    }
  }
  if (m->q && m->stiffening > 0 && m->stiffen_quadratic) {
    /* the stiffening's blocks, gathered at each assembly */
    const long ne = m->nbr_ptr[n];
    t->Sq_off = sq.off;
    t->Sq_w = sq.w;
    sq.off = NULL;
    sq.w = NULL;
    PM_TRY(PM_ALLOC(t->Sx_e, 9 * (ne > 0 ? ne : 1), "stiffening blocks"));
    PM_TRY(PM_ALLOC(t->Sx_mark, (size_t)threads * n, "stiffening marks"));
    PM_TRY(PM_ALLOC(t->Sx_list, (size_t)threads * n, "stiffening lists"));
    PM_TRY(PM_ALLOC(t->Sx_acc, (size_t)threads * 9 * n, "stiffening row"));
    for (long i = 0; i < (long)threads * n; i++) t->Sx_mark[i] = -1;
  }
done:
  sweights_free(&sq);
  sweights_free(&sl);
  free(mark);
  free(list);
  free(acc);
  return ret;
}

/* Rows are the own points' (a share's; all on one process), the products
 * D gamma those of the points whose stress they read. */
pm_err fpm_static_tangent_build(const fpm_model *m, fpm_static_tangent *t) {
  const long n = m->n, ns = m->n_stress;
  PM_CALL(build_E(m, t));
  PM_CALL(build_S(m, t));
  PM_CALL(PM_ALLOC(t->Dg_ptr, ns + 1, "tangent products"));
  for (long j = 0; j < ns; j++)
    t->Dg_ptr[j + 1] = t->Dg_ptr[j] + closed_size(m, j);
  PM_CALL(PM_ALLOC(t->Dg, 27 * t->Dg_ptr[ns], "tangent products"));
  t->max_reach = 0;
  for (long k = 0; k < m->n_own; k++)
    if (t->R_ptr[k + 1] - t->R_ptr[k] > t->max_reach)
      t->max_reach = t->R_ptr[k + 1] - t->R_ptr[k];
  t->threads = pm_omp_threads();
  PM_CALL(PM_ALLOC(t->mark, (size_t)t->threads * n, "tangent marks"));
  for (long a = 0; a < (long)t->threads * n; a++) t->mark[a] = -1;
  PM_CALL(PM_ALLOC(t->work, (size_t)t->threads * 9 * t->max_reach,
                   "tangent blocks"));
  return PM_SUCCESS;
}

/* The stiffening's block of every entry (fpm_stiffen_block, 9 an entry)
 * at the linearisation point's displacements u and fits theta: on the
 * quadratic jump, with its onset at the points' deformed distance
 * (fpm.stiffening_spacing: current) or the record's. */
static void stiffen_blocks(const fpm_model *m, const double *u,
                           const double *theta, double *we) {
  const long n = m->n;
  const double tau2 = m->stiffening_onset * m->stiffening_onset;
  PM_OMP(parallel for schedule(dynamic, 64) default(none)
         shared(m, u, theta, we, n, tau2))
  for (long i = 0; i < n; i++)
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
      const double *rec = m->erec + FPM_EREC * e;
      const long k = m->nbr[e];
      double *A = we + 9 * e;
      for (int q = 0; q < 9; q++) A[q] = 0;
      if (rec[20] == 0 || rec[18] == 0) continue;
      double phi_i[FPM_QFIT], phi_k[FPM_QFIT], j[3], t2 = rec[22];
      fpm_gfd_phi(rec + 12, phi_i);
      fpm_gfd_phi(rec + 15, phi_k);
      fpm_quad_jump(u + 3 * i, u + 3 * k, theta + 27 * i, theta + 27 * k, phi_i,
                    phi_k, j);
      if (m->stiffen_current) {
        double dc[3];
        for (int a = 0; a < 3; a++)
          dc[a] = rec[12 + a] - rec[15 + a] + u[3 * k + a] - u[3 * i + a];
        t2 = tau2 * pm_v_dot(dc, dc);
      }
      fpm_stiffen_block(rec[20], t2, j, A);
    }
}

/* The tangent's values into val: in the Jacobian's pattern, or (sp) in
 * the support operator's. */
static void tangent_values(fpm_static_ctx *c, const fpm_static_support *sp,
                           double *val) {
  const fpm_model *m = c->m;
  fpm_static_tangent *t = &c->tg;
  const long n = m->n, ns = m->n_stress, rows = m->n_own;
  const double *D = t->Dpc ? t->Dpc : fpm_linear_tangent(c->lin);
  /* D_j gamma_jm for every j (whose stress the rows read) and member m of
   * its closed support */
  PM_OMP(parallel for schedule(static) default(none) shared(ns, m, t, D))
  for (long j = 0; j < ns; j++) {
    const double *Dj = D + 81 * j;
    for (long r = 0; r < closed_size(m, j); r++) {
      const double *w;
      closed_member(m, j, r, &w);
      double g[3] = {w[0], w[1], w[2]};
      if (r == 0) g[0] = -g[0], g[1] = -g[1], g[2] = -g[2];
      double *out = t->Dg + 27 * (t->Dg_ptr[j] + r);
      for (int row = 0; row < 9; row++)
        for (int a = 0; a < 3; a++)
          out[3 * row + a] = Dj[9 * row + 3 * a] * g[0] +
                             Dj[9 * row + 3 * a + 1] * g[1] +
                             Dj[9 * row + 3 * a + 2] * g[2];
    }
  }
  if (t->Sx_e) {
    const double *bu, *bth;
    fpm_linear_base(c->lin, &bu, &bth);
    stiffen_blocks(m, bu, bth, t->Sx_e);
  }
  const sweights sx = {.off = t->Sq_off, .w = t->Sq_w};
  const long *free_of = c->free_of, *pat = c->pat_ptr;
  const double *K = c->contact_K;
  PM_OMP(parallel default(none)
             shared(n, rows, m, t, free_of, pat, val, K, sp, sx)) {
    const int th = pm_omp_thread();
    long *mark = t->mark + (size_t)th * n;
    double *blk = t->work + (size_t)th * 9 * t->max_reach;
    srow xw = {0};
    if (t->Sx_e)
      xw = (srow){.mark = t->Sx_mark + (size_t)th * n,
                  .list = t->Sx_list + (size_t)th * n,
                  .acc = t->Sx_acc + (size_t)th * 9 * n};
    PM_OMP(for schedule(dynamic, 16))
    for (long k = 0; k < rows; k++) {
      const long r0 = t->R_ptr[k], nr = t->R_ptr[k + 1] - r0;
      for (long a = 0; a < nr; a++) mark[t->R_list[r0 + a]] = a;
      for (long a = 0; a < 9 * nr; a++) blk[a] = 0;
      for (long q = t->E_ptr[k]; q < t->E_ptr[k + 1]; q++) {
        const long j = t->E_j[q];
        const double *E = t->E + 9 * q;
        for (long r = 0; r < closed_size(m, j); r++) {
          const double *w;
          long mm = closed_member(m, j, r, &w);
          const double *Dg = t->Dg + 27 * (t->Dg_ptr[j] + r);
          double *b = blk + 9 * mark[mm];
          for (int cc = 0; cc < 3; cc++)
            for (int a = 0; a < 3; a++)
              b[3 * cc + a] += E[3 * cc] * Dg[3 * (3 * cc) + a] +
                               E[3 * cc + 1] * Dg[3 * (3 * cc + 1) + a] +
                               E[3 * cc + 2] * Dg[3 * (3 * cc + 2) + a];
        }
      }
      for (long q = t->S_ptr[k]; q < t->S_ptr[k + 1]; q++) {
        double *b = blk + 9 * mark[t->S_m[q]];
        for (int cc = 0; cc < 3; cc++) b[4 * cc] += t->S[q];
      }
      if (t->Sx_e) { /* the stiffening's, in S's pattern */
        xw.cnt = 0;
        add_S_row(m, true, &sx, k, t->Sx_e, &xw);
        for (long a = 0; a < xw.cnt; a++) {
          double *b = blk + 9 * mark[xw.list[a]];
          for (int q = 0; q < 9; q++) b[q] += xw.acc[9 * a + q];
          xw.mark[xw.list[a]] = -1;
        }
      }
      if (K) /* the contact's block on the diagonal */
        for (int a = 0; a < 9; a++) blk[9 * mark[k] + a] += K[9 * k + a];
      if (sp) fpm_static_support_row(k, free_of, mark, blk, sp, val);
      for (int cc = 0; cc < 3 && !sp; cc++) {
        long row = free_of[3 * k + cc];
        if (row < 0) continue;
        long w = pat[row];
        for (long a = 0; a < nr; a++)
          for (int b = 0; b < 3; b++)
            if (free_of[3 * t->R_list[r0 + a] + b] >= 0)
              val[w++] = blk[9 * a + 3 * cc + b];
      }
      for (long a = 0; a < nr; a++) mark[t->R_list[r0 + a]] = -1;
    }
  }
}

pm_err fpm_static_tangent_values(void *ctx, const double *x, double *val) {
  (void)x;
  tangent_values(ctx, NULL, val);
  return PM_SUCCESS;
}

pm_err fpm_static_support_values(void *ctx, const double *x, double *val) {
  fpm_static_ctx *c = ctx;
  (void)x;
  tangent_values(c, &c->sp, val);
  return PM_SUCCESS;
}
