/* mpm_implicit: quasi-static implicit MPM by Newton's method on the grid
 * (see mpm_implicit.h for the formulation). */
#include "mpm_implicit.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_exchange.h"
#include "pm_omp.h"
#include "pm_progress.h"
#include "pm_tensor.h"

#define MAX_NB 125 /* neighbours of a node within a stencil's reach: 5^3 */

struct mpm_implicit {
  const pm_scene *s;
  const mpm_model *m;
  mpm_state *st;
  mpm_grid_mode mode;
  mpm_grid g; /* the solver's grid: the model's (kept), or one with room */
  int dim, w, nb, nnb; /* stencil width, neighbour span 2w - 1, nb^dim */
  int sn;              /* nodes of a stencil: w^dim */
  int soff[MPM_STENCIL_MAX][MPM_STENCIL_MAX]; /* neighbour slot of b from a */
  long n;
  unsigned char *grp;                  /* per particle: its group */
  mpm_solid_view view[MPM_MAX_GROUPS]; /* per group */
  long group_begin[MPM_MAX_GROUPS];
  const double *xb; /* base positions: X (kept) or the state's x (reset) */
  bool base_f;      /* F_b is the state's F (reset); identity (kept) */
  /* particles by the first node of their stencil, buckets by colour */
  long *order, *bucket, *cbuck;
  long cptr[MPM_STENCIL_MAX + 1];
  int ncol;
  /* dofs: 3 per node: unknown index (>= 0), -1 none, -2 - k prescribed k */
  unsigned char *active;
  long *dof, *unk_dof;
  long nunk, npre, pre_cap;
  /* Across ranks (the model a rank's share: m->xc): the unknowns are the
   * owned nodes' (nunk), then the ghost nodes' that other ranks own
   * (nghost, global numbers ghost); nheld = nunk + nghost (nunk on one
   * process).  Sums over nodes add the ranks' parts first. */
  bool ranks;
  long nghost, nheld;
  long *ghost, *gnum; /* gnum: 3 per node, a dof's global number or -1 */
  long nunk_all, entries_all; /* over all ranks */
  double *whole;   /* load stepping's two states on the whole grid (for
                      checkpoints: rank 0's across ranks) */
  long active_all; /* active nodes over all ranks */
  long *pre_dof;
  double *pre_val; /* increment at local load 1 */
  int *pre_bc;
  int *nb_off; /* nnb per node: offset of a neighbour's columns in a row */
  long *pat_ptr, *pat_idx, pat_cap;
  long *pc_ptr, *pc_idx; /* diagonal pattern (matrix-free Jacobi) */
  double *near_null;     /* rigid motions for algebraic multigrid */
  /* face particles of each condition (reset) */
  long *face_ptr, *face;
  /* nodal work, 3 per node */
  double *u, *du, *f, *df, *diag;
  double *x_unk;  /* unknowns */
  double *x_held; /* across ranks: the owned unknowns and the ghosts' */
  /* load: the base's global load, the step's end, the local load */
  double lam0, lam1, lam_local;
  pm_newton_options opt;
  pm_newton *solver;
  pm_load_state ls;
  pm_load_report rep; /* totals over the run */
  double lambda;      /* global load reached */
  int step;           /* converged load steps reported */
  double *reaction;   /* 3 per condition */
  double residual;
  double jmin; /* stability.min_jacobian */
  bool matrix_free;
  bool fbar; /* mpm.fbar: cell (the stress from the bucket's Jbar) */
  int threads;
  double *tmin;        /* per thread: smallest J of a force evaluation */
  double min_jacobian; /* of the last force evaluation */
  long fail_p;
  char fail_msg[256];
  bool has_gravity;
  double gravity[3];
  int opt_steps; /* nominal load steps */
  int built_for; /* reset: the load step the structure was built for */
  mpm_implicit_observer obs;
  void *octx;
  double t_step;
};

static pm_err on_step(void *ctx, int step, double lambda, const double *x,
                      const pm_newton_report *report);

/* ---- per particle ------------------------------------------------------- */

static inline const double *base_F(const mpm_implicit *im, long p) {
  if (!im->base_f) return NULL;
  int gi = im->grp[p];
  return im->view[gi].F + 9 * (p - im->group_begin[gi]);
}

/* D + sum_I u_I (x) grad S_I over the stencil st, times F_b of particle
 * p (F_b = I when the base is the reference): F from D = I, its change
 * along a nodal direction from D = 0. */
static inline void gradient_times_base(const mpm_implicit *im, long p,
                                       const mpm_stencil *st, const double *u,
                                       double D[9], double out[9]) {
  for (int k = 0; k < st->n; k++) {
    const double *uk = u + 3 * st->node[k];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) D[3 * i + j] += uk[i] * st->grad[k][j];
  }
  const double *Fb = base_F(im, p);
  if (Fb)
    pm_t_mul(D, Fb, out);
  else
    memcpy(out, D, 9 * sizeof(double));
}

/* F = (I + sum_I u_I (x) grad S_I) F_b at particle p from the nodal values
 * u, with the stencil st at its base position. */
static inline void particle_F(const mpm_implicit *im, long p,
                              const mpm_stencil *st, const double *u,
                              double F[9]) {
  double D[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  gradient_times_base(im, p, st, u, D, F);
}

/* The model's state of particle p (NULL when its model has none). */
static inline const double *model_state(const mpm_implicit *im, long p) {
  const mpm_solid_view *v = &im->view[im->grp[p]];
  return v->mstate ? v->mstate + v->mstride * (p - im->group_begin[im->grp[p]])
                   : NULL;
}

/* Q = P F_b^T (P when F_b = I). */
static inline void to_base(const double *Fb, const double P[9], double Q[9]) {
  if (!Fb) {
    memcpy(Q, P, 9 * sizeof(double));
    return;
  }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      Q[3 * i + j] = P[3 * i] * Fb[3 * j] + P[3 * i + 1] * Fb[3 * j + 1] +
                     P[3 * i + 2] * Fb[3 * j + 2];
}

static void note_failure(mpm_implicit *im, long p, const char *what, double J) {
  PM_OMP(critical(mpm_implicit_fail)) {
    if (im->fail_p < 0 || p < im->fail_p) {
      im->fail_p = p;
      const double *x = im->xb + 3 * p;
      snprintf(im->fail_msg, sizeof im->fail_msg,
               "particle %ld at (%.6g, %.6g, %.6g): %s (J = %.4g)",
               im->m->gid ? im->m->gid[p] : p, x[0], x[1], x[2], what, J);
    }
  }
}

/* ---- the colour loop ---------------------------------------------------- */

/* Visit every particle, colour by colour, buckets of a colour in parallel:
 * BODY sees p and its stencil st (weights and gradients at the base). */
#define FOR_PARTICLES(im, ...)                                                 \
  for (int col_ = 0; col_ < (im)->ncol; col_++) {                              \
    const long c0_ = (im)->cptr[col_], c1_ = (im)->cptr[col_ + 1];             \
    PM_OMP(parallel for schedule(dynamic, 64))                                 \
    for (long b_ = c0_; b_ < c1_; b_++) {                                      \
      const long bk_ = (im)->cbuck[b_];                                        \
      for (long q_ = (im)->bucket[bk_]; q_ < (im)->bucket[bk_ + 1]; q_++) {    \
        const long p = (im)->order[q_];                                        \
        mpm_stencil st;                                                        \
        mpm_stencil_at(&(im)->g, (im)->xb + 3 * p,                             \
                       MPM_STENCIL_W | MPM_STENCIL_GRAD, &st);                 \
        __VA_ARGS__                                                            \
      }                                                                        \
    }                                                                          \
  }

/* Visit the buckets (the particles sharing a cell: linear B-splines; a
 * stencil: quadratic), colour by colour: BODY sees q0, q1, the bucket's
 * range in im->order. */
#define FOR_BUCKETS(im, ...)                                                   \
  for (int col_ = 0; col_ < (im)->ncol; col_++) {                              \
    const long c0_ = (im)->cptr[col_], c1_ = (im)->cptr[col_ + 1];             \
    PM_OMP(parallel for schedule(dynamic, 16))                                 \
    for (long b_ = c0_; b_ < c1_; b_++) {                                      \
      const long bk_ = (im)->cbuck[b_];                                        \
      const long q0 = (im)->bucket[bk_], q1 = (im)->bucket[bk_ + 1];           \
      __VA_ARGS__                                                              \
    }                                                                          \
  }

/* ---- F-bar (mpm.fbar: cell) ----------------------------------------------
 * The stress of particle q comes from Fbar = a F, a = (Jbar / J)^(1/d) on
 * the first d rows and columns (plane strain keeps the out-of-plane
 * stretch), Jbar = sum_c w_p J_p over the particles of q's bucket, w_p =
 * V0_p / sum_c V0.  The residual is the derivative of sum V0 W(Fbar):
 *   T_q = V0 a P(Fbar) - s_q G_q + (S / Jbar) w_q J_q G_q,
 *   s_q = V0 a (P(Fbar) : F_d) / d,  S = sum_c s_p,  G = F^-T,
 * F_d: F's first d rows and columns; f_I = sum_q T_q F_b^T grad S_I.  Its
 * directional derivative (below) is the exact tangent; it couples the
 * particles of a bucket only, which share their stencil, so the Jacobian's
 * pattern is unchanged. */

/* What F-bar needs of one particle at u (and, with du, its derivative). */
typedef struct {
  double F[9], G[9], Fd[9], J;
  double dF[9], dJ;
} fbar_point;

static inline void fbar_point_at(const mpm_implicit *im, long p,
                                 const mpm_stencil *st, const double *u,
                                 const double *du, fbar_point *fp) {
  particle_F(im, p, st, u, fp->F);
  fp->J = pm_t_det(fp->F);
  double Finv[9];
  pm_t_inverse(fp->F, Finv);
  pm_t_transpose(Finv, fp->G);
  memcpy(fp->Fd, fp->F, sizeof fp->Fd);
  if (im->dim == 2) fp->Fd[8] = 0;
  if (!du) return;
  double dD[9] = {0};
  gradient_times_base(im, p, st, du, dD, fp->dF);
  fp->dJ = fp->J * pm_t_ddot(fp->G, fp->dF);
}

/* Fbar = a F on the first d rows and columns. */
static inline void fbar_scale(int dim, double a, const double F[9],
                              double Fbar[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      Fbar[3 * i + j] = (i < dim && j < dim ? a : 1.0) * F[3 * i + j];
}

/* The bucket [q0, q1)'s sums: Jbar, sum V0, and with du dJbar. */
static inline void fbar_bucket_J(const mpm_implicit *im, long q0, long q1,
                                 const double *u, const double *du,
                                 double *Jbar, double *V, double *dJbar) {
  double sv = 0, sj = 0, sd = 0;
  for (long q = q0; q < q1; q++) {
    const long p = im->order[q];
    mpm_stencil st;
    mpm_stencil_at(&im->g, im->xb + 3 * p, MPM_STENCIL_GRAD, &st);
    fbar_point fp;
    fbar_point_at(im, p, &st, u, du, &fp);
    const double V0 = im->m->vol0[p];
    sv += V0;
    sj += V0 * fp.J;
    if (du) sd += V0 * fp.dJ;
  }
  *V = sv;
  *Jbar = sj / sv;
  if (dJbar) *dJbar = sd / sv;
}

/* T_q of particle p (with dT when du: then dS and dJbar are the bucket's
 * sums' derivatives), from the bucket's Jbar, S and sum V0.  Also s_q (and
 * ds_q) for the sums' pass.  False when the stress or tangent fails. */
static bool fbar_particle(const mpm_implicit *im, long p, const fbar_point *fp,
                          double Jbar, double S, double V, double dJbar,
                          double dS, bool with_d, double T[9], double dT[9],
                          double *s_out, double *ds_out) {
  const int d = im->dim;
  const mpm_solid_view *v = &im->view[im->grp[p]];
  const double *ms = model_state(im, p);
  const double V0 = im->m->vol0[p], w = V0 / V;
  if (!(fp->J > 0) || !(Jbar > 0)) return false;
  const double a = pow(Jbar / fp->J, 1.0 / d);
  double Fbar[9], P[9];
  fbar_scale(d, a, fp->F, Fbar);
  if (!pm_material_stress(v->mat, Fbar, ms, P, NULL, NULL)) return false;
  const double PF = pm_t_ddot(P, fp->Fd);
  const double s = V0 * a * PF / d;
  if (s_out) *s_out = s;
  if (T)
    for (int k = 0; k < 9; k++)
      T[k] = V0 * a * P[k] - s * fp->G[k] + (S / Jbar) * w * fp->J * fp->G[k];
  if (!with_d) return true;
  const double da = (a / d) * (dJbar / Jbar - fp->dJ / fp->J);
  double dFbar[9], dP[9];
  fbar_scale(d, a, fp->dF, dFbar);
  for (int k = 0; k < 9; k++) dFbar[k] += da * fp->Fd[k];
  if (!pm_material_tangent(v->mat, Fbar, ms, dFbar, dP)) return false;
  double dFd[9];
  memcpy(dFd, fp->dF, sizeof dFd);
  if (d == 2) dFd[8] = 0;
  const double ds =
      V0 / d * (da * PF + a * (pm_t_ddot(dP, fp->Fd) + pm_t_ddot(P, dFd)));
  if (ds_out) *ds_out = ds;
  if (!dT) return true;
  /* dG = -G dF^T G */
  double dFT[9], t1[9], dG[9];
  pm_t_transpose(fp->dF, dFT);
  pm_t_mul(fp->G, dFT, t1);
  pm_t_mul(t1, fp->G, dG);
  for (int k = 0; k < 9; k++) dG[k] = -dG[k];
  const double r = S / Jbar, dr = dS / Jbar - S * dJbar / (Jbar * Jbar);
  for (int k = 0; k < 9; k++)
    dT[k] = V0 * (da * P[k] + a * dP[k]) - ds * fp->G[k] - s * dG[k] +
            dr * w * fp->J * fp->G[k] +
            r * w * (fp->dJ * fp->G[k] + fp->J * dG[k]);
  return true;
}

/* Nodal force (du NULL) or its derivative along du (into f) with F-bar.
 * False on a failed particle (im->fail_msg). */
static bool fbar_force(mpm_implicit *im, const double *u, const double *du,
                       double *f) {
  const mpm_model *m = im->m;
  const double lam = im->lam0 + im->lam_local * (im->lam1 - im->lam0);
  memset(f, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  im->fail_p = -1;
  for (int t = 0; t < im->threads; t++) im->tmin[t] = INFINITY;
  FOR_BUCKETS(im, {
    double Jbar, V, dJbar = 0, S = 0, dS = 0;
    fbar_bucket_J(im, q0, q1, u, du, &Jbar, &V, du ? &dJbar : NULL);
    bool ok = Jbar > im->jmin;
    for (long q = q0; q < q1 && ok; q++) {
      const long p = im->order[q];
      mpm_stencil st;
      mpm_stencil_at(&im->g, im->xb + 3 * p, MPM_STENCIL_GRAD, &st);
      fbar_point fp;
      fbar_point_at(im, p, &st, u, du, &fp);
      double s, ds = 0;
      ok = fbar_particle(im, p, &fp, Jbar, 0, V, dJbar, 0, du != NULL, NULL,
                         NULL, &s, du ? &ds : NULL);
      S += s;
      dS += ds;
    }
    if (!ok) {
      note_failure(im, im->order[q0], "F-bar: J or the cell's Jbar failed",
                   Jbar);
      continue;
    }
    double *tl = im->tmin + pm_omp_thread();
    if (Jbar < *tl) *tl = Jbar;
    for (long q = q0; q < q1; q++) {
      const long p = im->order[q];
      mpm_stencil st;
      mpm_stencil_at(&im->g, im->xb + 3 * p, MPM_STENCIL_W | MPM_STENCIL_GRAD,
                     &st);
      fbar_point fp;
      fbar_point_at(im, p, &st, u, du, &fp);
      double T[9], dT[9], Q[9];
      fbar_particle(im, p, &fp, Jbar, S, V, dJbar, dS, du != NULL,
                    du ? NULL : T, du ? dT : NULL, NULL, NULL);
      to_base(base_F(im, p), du ? dT : T, Q);
      const double mg = lam * m->mass[p];
      for (int k = 0; k < st.n; k++) {
        double *fk = f + 3 * st.node[k];
        const double *gk = st.grad[k];
        for (int i = 0; i < 3; i++)
          fk[i] +=
              Q[3 * i] * gk[0] + Q[3 * i + 1] * gk[1] + Q[3 * i + 2] * gk[2];
        if (im->has_gravity && !du)
          for (int i = 0; i < 3; i++) fk[i] -= mg * st.w[k] * im->gravity[i];
      }
    }
  })
  im->min_jacobian = INFINITY;
  for (int t = 0; t < im->threads; t++)
    im->min_jacobian = fmin(im->min_jacobian, im->tmin[t]);
  return im->fail_p < 0;
}

/* Nodal force f = f_int - lambda f_gravity from the nodal values u.
 * Returns false when a particle's stress fails (im->fail_msg). */
static bool nodal_force(mpm_implicit *im, const double *u, double *f) {
  if (im->fbar) return fbar_force(im, u, NULL, f);
  const mpm_model *m = im->m;
  const double lam = im->lam0 + im->lam_local * (im->lam1 - im->lam0);
  memset(f, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  im->fail_p = -1;
  for (int t = 0; t < im->threads; t++) im->tmin[t] = INFINITY;
  FOR_PARTICLES(im, {
    double F[9], P[9], Q[9], J;
    particle_F(im, p, &st, u, F);
    const mpm_solid_view *v = &im->view[im->grp[p]];
    if (!pm_material_stress(v->mat, F, model_state(im, p), P, NULL, &J)) {
      note_failure(im, p, "no stress: J <= 0 or not finite", pm_t_det(F));
      continue;
    }
    if (!(J > im->jmin)) {
      note_failure(im, p, "J at or below stability.min_jacobian", J);
      continue;
    }
    double *tl = im->tmin + pm_omp_thread();
    if (J < *tl) *tl = J;
    to_base(base_F(im, p), P, Q);
    const double V0 = m->vol0[p], mg = lam * m->mass[p];
    for (int k = 0; k < st.n; k++) {
      double *fk = f + 3 * st.node[k];
      const double *gk = st.grad[k];
      for (int i = 0; i < 3; i++)
        fk[i] += V0 * (Q[3 * i] * gk[0] + Q[3 * i + 1] * gk[1] +
                       Q[3 * i + 2] * gk[2]);
      if (im->has_gravity)
        for (int i = 0; i < 3; i++) fk[i] -= mg * st.w[k] * im->gravity[i];
    }
  })
  im->min_jacobian = INFINITY;
  for (int t = 0; t < im->threads; t++)
    im->min_jacobian = fmin(im->min_jacobian, im->tmin[t]);
  return im->fail_p < 0;
}

/* u from the unknowns x and the prescribed values at the local load. */
static void fill_u(mpm_implicit *im, const double *x) {
  memset(im->u, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  for (long k = 0; k < im->nheld; k++) im->u[im->unk_dof[k]] = x[k];
  for (long k = 0; k < im->npre; k++)
    im->u[im->pre_dof[k]] = im->lam_local * im->pre_val[k];
}

/* ---- the problem's callbacks --------------------------------------------- */

static pm_err cb_residual(void *ctx, const double *x, double *r) {
  mpm_implicit *im = ctx;
  fill_u(im, x);
  if (!nodal_force(im, im->u, im->f))
    return PM_ERROR(PM_ERR_UNSTABLE, "%s", im->fail_msg);
  for (long k = 0; k < im->nheld; k++) r[k] = im->f[im->unk_dof[k]];
  return PM_SUCCESS;
}

static pm_err cb_set_load(void *ctx, double lambda) {
  ((mpm_implicit *)ctx)->lam_local = lambda;
  return PM_SUCCESS;
}

/* dr = K dx: the directional derivative of the nodal force. */
static pm_err cb_apply(void *ctx, const double *x, const double *dx,
                       double *dr) {
  mpm_implicit *im = ctx;
  const mpm_model *m = im->m;
  fill_u(im, x);
  memset(im->du, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  for (long k = 0; k < im->nheld; k++) im->du[im->unk_dof[k]] = dx[k];
  if (im->fbar) {
    if (!fbar_force(im, im->u, im->du, im->df))
      return PM_ERROR(PM_ERR_INTERNAL, "%s", im->fail_msg);
    for (long k = 0; k < im->nheld; k++) dr[k] = im->df[im->unk_dof[k]];
    return PM_SUCCESS;
  }
  memset(im->df, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  const double *du = im->du;
  double *df = im->df;
  im->fail_p = -1;
  FOR_PARTICLES(im, {
    double F[9], dD[9] = {0}, dF[9], dP[9], dQ[9];
    particle_F(im, p, &st, im->u, F);
    gradient_times_base(im, p, &st, du, dD, dF);
    const double *Fb = base_F(im, p);
    const mpm_solid_view *v = &im->view[im->grp[p]];
    if (!pm_material_tangent(v->mat, F, model_state(im, p), dF, dP)) {
      note_failure(im, p, "no tangent: J <= 0", pm_t_det(F));
      continue;
    }
    to_base(Fb, dP, dQ);
    const double V0 = m->vol0[p];
    for (int k = 0; k < st.n; k++) {
      double *fk = df + 3 * st.node[k];
      const double *gk = st.grad[k];
      for (int i = 0; i < 3; i++)
        fk[i] += V0 * (dQ[3 * i] * gk[0] + dQ[3 * i + 1] * gk[1] +
                       dQ[3 * i + 2] * gk[2]);
    }
  })
  if (im->fail_p >= 0) return PM_ERROR(PM_ERR_INTERNAL, "%s", im->fail_msg);
  for (long k = 0; k < im->nheld; k++) dr[k] = df[im->unk_dof[k]];
  return PM_SUCCESS;
}

/* A_n[iJkM] = sum_KL A[iKkL] Fb[JK] Fb[ML] (A when F_b = I), with
 * A[iKkL] = dP_iK / dF_kL from nine tangent calls. */
static bool particle_tangent(const mpm_implicit *im, long p, const double F[9],
                             double An[81]) {
  const mpm_solid_view *v = &im->view[im->grp[p]];
  const double *ms = model_state(im, p);
  double A[81];
  for (int kl = 0; kl < 9; kl++) {
    double dF[9] = {0}, dP[9];
    dF[kl] = 1;
    if (!pm_material_tangent(v->mat, F, ms, dF, dP)) return false;
    for (int iK = 0; iK < 9; iK++) A[9 * iK + kl] = dP[iK];
  }
  const double *Fb = base_F(im, p);
  if (!Fb) {
    memcpy(An, A, sizeof A);
    return true;
  }
  double T[81]; /* T[iJkL] = sum_K A[iKkL] Fb[JK] */
  for (int i = 0; i < 3; i++)
    for (int J = 0; J < 3; J++)
      for (int kl = 0; kl < 9; kl++) {
        double s = 0;
        for (int K = 0; K < 3; K++)
          s += A[9 * (3 * i + K) + kl] * Fb[3 * J + K];
        T[9 * (3 * i + J) + kl] = s;
      }
  for (int iJ = 0; iJ < 9; iJ++)
    for (int k = 0; k < 3; k++)
      for (int M = 0; M < 3; M++) {
        double s = 0;
        for (int L = 0; L < 3; L++) s += T[9 * iJ + 3 * k + L] * Fb[3 * M + L];
        An[9 * iJ + 3 * k + M] = s;
      }
  return true;
}

/* Unknown components of node b before component c. */
static inline int rank_of(const long *dof, long b, int c) {
  int r = 0;
  for (int j = 0; j < c; j++) r += dof[3 * b + j] >= 0;
  return r;
}

/* The assembled tangent in the pattern's order. */
static pm_err cb_values(void *ctx, const double *x, double *val) {
  mpm_implicit *im = ctx;
  const mpm_model *m = im->m;
  fill_u(im, x);
  memset(val, 0, sizeof(double) * (size_t)im->pat_ptr[im->nheld]);
  im->fail_p = -1;
  const long *dof = im->dof;
  FOR_PARTICLES(im, {
    double F[9], An[81], G[MPM_STENCIL_MAX][27];
    particle_F(im, p, &st, im->u, F);
    if (!particle_tangent(im, p, F, An)) {
      note_failure(im, p, "no tangent: J <= 0", pm_t_det(F));
      continue;
    }
    const double V0 = m->vol0[p];
    /* G_b[iJk] = V0 sum_M An[iJkM] g_b[M] */
    for (int b = 0; b < st.n; b++)
      for (int iJk = 0; iJk < 27; iJk++)
        G[b][iJk] = V0 * (An[3 * iJk] * st.grad[b][0] +
                          An[3 * iJk + 1] * st.grad[b][1] +
                          An[3 * iJk + 2] * st.grad[b][2]);
    for (int a = 0; a < st.n; a++) {
      const long na = st.node[a];
      for (int i = 0; i < 3; i++) {
        const long row = dof[3 * na + i];
        if (row < 0) continue;
        for (int b = 0; b < st.n; b++) {
          const long nbn = st.node[b];
          const int off = im->nb_off[na * im->nnb + im->soff[a][b]];
          if (off < 0) continue;
          long pos = im->pat_ptr[row] + off;
          for (int k = 0; k < 3; k++) {
            if (dof[3 * nbn + k] < 0) continue;
            double s = 0;
            for (int J = 0; J < 3; J++)
              s += st.grad[a][J] * G[b][9 * i + 3 * J + k];
            val[pos++] += s;
          }
        }
      }
    }
  })
  if (im->fail_p >= 0) return PM_ERROR(PM_ERR_INTERNAL, "%s", im->fail_msg);
  return PM_SUCCESS;
}

/* The tangent's diagonal, for the matrix-free operator's Jacobi
 * preconditioner: P dx = diag(K) dx (assembled by colouring from the
 * diagonal pattern: one product with dx = 1). */
static pm_err cb_prepare(void *ctx, const double *x) {
  mpm_implicit *im = ctx;
  if (!im->matrix_free) return PM_SUCCESS;
  const mpm_model *m = im->m;
  fill_u(im, x);
  double *dg = im->df;
  memset(dg, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  im->fail_p = -1;
  FOR_PARTICLES(im, {
    double F[9], An[81];
    particle_F(im, p, &st, im->u, F);
    if (!particle_tangent(im, p, F, An)) {
      note_failure(im, p, "no tangent: J <= 0", pm_t_det(F));
      continue;
    }
    for (int a = 0; a < st.n; a++) {
      const double *ga = st.grad[a];
      double *d = dg + 3 * st.node[a];
      for (int i = 0; i < 3; i++) {
        double s = 0;
        for (int J = 0; J < 3; J++)
          for (int M = 0; M < 3; M++)
            s += ga[J] * An[9 * (3 * i + J) + 3 * i + M] * ga[M];
        d[i] += m->vol0[p] * s;
      }
    }
  })
  if (im->fail_p >= 0) return PM_ERROR(PM_ERR_INTERNAL, "%s", im->fail_msg);
  for (long k = 0; k < im->nunk; k++) im->diag[k] = dg[im->unk_dof[k]];
  return PM_SUCCESS;
}

static pm_err cb_precond(void *ctx, const double *x, const double *dx,
                         double *dr) {
  (void)x;
  mpm_implicit *im = ctx;
  for (long k = 0; k < im->nunk; k++) dr[k] = im->diag[k] * dx[k];
  return PM_SUCCESS;
}

/* ---- structure: buckets, dofs, pattern ---------------------------------- */

/* The first node of particle p's stencil (its cell's for linear shapes). */
static long stencil_base(const mpm_grid *g, const double x[3], long ijk[3]) {
  long base = 0;
  for (int c = 0; c < 3; c++) {
    ijk[c] = 0;
    if (c >= g->dim) continue;
    double w[3], dw[3];
    mpm_shape_1d(g->shape, (x[c] - g->origin[c]) * g->inv_h, g->inv_h, &ijk[c],
                 w, dw);
    ijk[c] -= g->offset[c]; /* in the rank's block (0 on one process) */
    base += ijk[c] * g->stride[c];
  }
  return base;
}

/* Particles sorted into buckets by their stencil's first node, and the
 * non-empty buckets listed by colour (sum_c (ijk_c mod w) w^c). */
static void make_buckets(mpm_implicit *im) {
  const mpm_grid *g = &im->g;
  const long nn = g->n_nodes;
  long *cnt = im->bucket; /* nn + 1 */
  memset(cnt, 0, sizeof(long) * (size_t)(nn + 1));
  for (long p = 0; p < im->n; p++) {
    long ijk[3];
    cnt[stencil_base(g, im->xb + 3 * p, ijk) + 1]++;
  }
  for (long k = 0; k < nn; k++) cnt[k + 1] += cnt[k];
  /* fill: order by bucket (cnt[k] moves to the bucket's end, then back) */
  for (long p = 0; p < im->n; p++) {
    long ijk[3];
    long b = stencil_base(g, im->xb + 3 * p, ijk);
    im->order[cnt[b]++] = p;
  }
  for (long k = nn; k > 0; k--) cnt[k] = cnt[k - 1];
  cnt[0] = 0;
  /* colours */
  long ccount[MPM_STENCIL_MAX + 1] = {0};
  for (long k = 0; k < nn; k++) {
    if (cnt[k + 1] == cnt[k]) continue;
    long i = k % g->nn[0], j = (k / g->nn[0]) % g->nn[1], l = k / g->stride[2];
    int col = (int)(i % im->w) +
              im->w * ((int)(j % im->w) + im->w * (int)(l % im->w));
    ccount[col + 1]++;
  }
  im->ncol = im->sn;
  for (int c = 0; c < im->ncol; c++) ccount[c + 1] += ccount[c];
  memcpy(im->cptr, ccount, sizeof(long) * (size_t)(im->ncol + 1));
  for (long k = 0; k < nn; k++) {
    if (cnt[k + 1] == cnt[k]) continue;
    long i = k % g->nn[0], j = (k / g->nn[0]) % g->nn[1], l = k / g->stride[2];
    int col = (int)(i % im->w) +
              im->w * ((int)(j % im->w) + im->w * (int)(l % im->w));
    im->cbuck[ccount[col]++] = k;
  }
}

/* The full-load value of condition b's component c at x (face plane on its
 * axis). */
static double bc_value(const mpm_implicit *im, int b, int c,
                       const double x[3]) {
  const mpm_bc *bc = &im->m->bcs[b];
  double y[3] = {x[0], x[1], x[2]};
  y[bc->axis] = bc->plane;
  double T = im->m->opt.t_load;
  return pm_ramp_factor(bc->ramp, bc->ramp_time, T) *
         pm_expr_eval(bc->disp[c], y[0], y[1], y[2], T);
}

/* Prescribe component c of node k by condition b with increment v at
 * local load 1 (a later condition overrides an earlier one). */
static pm_err prescribe(mpm_implicit *im, long node, int c, int b, double v) {
  long d = 3 * node + c;
  if (im->dof[d] <= -2) {
    long k = -2 - im->dof[d];
    im->pre_val[k] = v;
    im->pre_bc[k] = b;
    return PM_SUCCESS;
  }
  if (im->npre == im->pre_cap) {
    long cap = im->pre_cap ? 2 * im->pre_cap : 1024;
    PM_CALL(PM_REALLOC(im->pre_dof, cap, "prescribed dofs"));
    PM_CALL(PM_REALLOC(im->pre_val, cap, "prescribed values"));
    PM_CALL(PM_REALLOC(im->pre_bc, cap, "prescribed dofs"));
    im->pre_cap = cap;
  }
  im->pre_dof[im->npre] = d;
  im->pre_val[im->npre] = v;
  im->pre_bc[im->npre] = b;
  im->dof[d] = -2 - im->npre++;
  return PM_SUCCESS;
}

/* Node k's position on the solver's grid. */
static void node_position(const mpm_grid *g, long k, double x[3]) {
  long ijk[3] = {k % g->nn[0], (k / g->nn[0]) % g->nn[1], k / g->stride[2]};
  for (int c = 0; c < 3; c++)
    x[c] =
        c < g->dim ? g->origin[c] + (double)(ijk[c] + g->offset[c]) * g->h : 0;
}

/* Prescribed dofs of the conditions for the step from lam0 to lam1. */
static pm_err make_prescribed(mpm_implicit *im) {
  const mpm_model *m = im->m;
  const mpm_grid *g = &im->g;
  const double scale = im->lam1 - im->lam0;
  im->npre = 0;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (!bc->disp_mask) continue;
    const int a = bc->axis;
    if (im->mode == MPM_GRID_KEPT) {
      long ia = (long)llround((bc->plane - g->origin[a]) * g->inv_h);
      for (long k = 0; k < g->n_nodes; k++) {
        if (!im->active[k]) continue;
        long idx = (k / g->stride[a]) % g->nn[a] + g->offset[a];
        if (bc->outward > 0 ? idx < ia : idx > ia) continue;
        double x[3];
        node_position(g, k, x);
        for (int c = 0; c < im->dim; c++)
          if (bc->disp_mask & (1u << c))
            PM_CALL(prescribe(im, k, c, b, scale * bc_value(im, b, c, x)));
      }
    } else {
      for (long q = im->face_ptr[b]; q < im->face_ptr[b + 1]; q++) {
        long p = im->face[q];
        mpm_stencil st;
        mpm_stencil_at(g, im->xb + 3 * p, MPM_STENCIL_W, &st);
        for (int k = 0; k < st.n; k++)
          for (int c = 0; c < im->dim; c++)
            if (bc->disp_mask & (1u << c))
              PM_CALL(prescribe(im, st.node[k], c, b,
                                scale * bc_value(im, b, c, m->x0 + 3 * p)));
      }
    }
  }
  return PM_SUCCESS;
}

/* Active nodes, prescribed and unknown dofs, and the Jacobian's pattern:
 * every row of a node lists the unknowns of the nodes within a stencil's
 * reach in neighbour order, each neighbour's components in order.  Across
 * ranks a node is active where any rank's particles reach it, a rank
 * numbers its own nodes' unknowns, and the rows of ghost nodes hold what
 * its particles add to them. */
static pm_err make_dofs(mpm_implicit *im) {
  const mpm_grid *g = &im->g;
  const long nn = g->n_nodes;
  memset(im->active, 0, (size_t)nn);
  for (long p = 0; p < im->n; p++) {
    mpm_stencil st;
    mpm_stencil_at(g, im->xb + 3 * p, MPM_STENCIL_W, &st);
    for (int k = 0; k < st.n; k++) im->active[st.node[k]] = 1;
  }
  const unsigned char *own = im->ranks ? mpm_xc_owned(im->m) : NULL;
  if (im->ranks)
    PM_CALL(mpm_xc_nodes_reduce(im->m, im->active, MPM_XC_BYTE, MPM_XC_MAX));
  for (long d = 0; d < 3 * nn; d++) im->dof[d] = -1;
  PM_CALL(make_prescribed(im));
  im->nunk = 0;
  im->active_all = 0;
  for (long k = 0; k < nn; k++) {
    if (!im->active[k] || (own && !own[k])) continue;
    im->active_all++;
    for (int c = 0; c < im->dim; c++)
      if (im->dof[3 * k + c] == -1) im->dof[3 * k + c] = im->nunk++;
  }
  im->nheld = im->nunk;
  /* Across ranks: the global numbers of the unknowns, the owners' numbers
   * at the ghost nodes, and the ghost nodes' unknowns after the owned. */
  if (im->ranks) {
    PM_CALL(mpm_xc_number_unknowns(im->m, im->nunk, im->dof, im->gnum,
                                   &im->ghost, &im->nghost));
    im->nheld = im->nunk + im->nghost;
  }
  long counts[2] = {im->nunk, im->active_all};
  mpm_xc_sum_long(im->m, counts, 2);
  im->nunk_all = counts[0];
  im->active_all = counts[1];
  PM_CHECK(im->nunk_all > 0, PM_ERR_SCENE,
           "%s: every grid displacement is prescribed: nothing to solve",
           im->s->path);
  const long nh = im->nheld;
  PM_CALL(PM_REALLOC(im->unk_dof, nh + 1, "unknowns"));
  PM_CALL(PM_REALLOC(im->x_unk, im->nunk + 1, "unknowns"));
  if (im->ranks) PM_CALL(PM_REALLOC(im->x_held, nh + 1, "held unknowns"));
  PM_CALL(PM_REALLOC(im->diag, nh + 1, "tangent diagonal"));
  PM_CALL(PM_REALLOC(im->pat_ptr, nh + 1, "Jacobian pattern"));
  PM_CALL(PM_REALLOC(im->pc_ptr, nh + 1, "diagonal pattern"));
  PM_CALL(PM_REALLOC(im->pc_idx, nh + 1, "diagonal pattern"));
  memset(im->x_unk, 0, sizeof(double) * (size_t)im->nunk);
  for (long d = 0; d < 3 * nn; d++)
    if (im->dof[d] >= 0) im->unk_dof[im->dof[d]] = d;
  for (long k = 0; k <= nh; k++) im->pc_ptr[k] = k;
  for (long k = 0; k < nh; k++) im->pc_idx[k] = k;
  /* neighbour offsets and the row lengths */
  const int span = im->w - 1;
  long total = 0;
  im->pat_ptr[0] = 0;
  for (long k = 0; k < nn; k++) {
    int *off = im->nb_off + k * im->nnb;
    int cnt = 0, own = 0;
    for (int c = 0; c < 3; c++) own += im->dof[3 * k + c] >= 0;
    long ijk[3] = {k % g->nn[0], (k / g->nn[0]) % g->nn[1], k / g->stride[2]};
    for (int s = 0; s < im->nnb; s++) {
      off[s] = -1;
      if (!own) continue;
      int d[3] = {0, 0, 0};
      for (int c = 0, q = s; c < im->dim; c++, q /= im->nb)
        d[c] = q % im->nb - span;
      long nb = 0;
      bool in = true;
      for (int c = 0; c < 3; c++) {
        if (c >= im->dim) {
          if (d[c] != 0) in = false;
          continue;
        }
        long i = ijk[c] + d[c];
        if (i < 0 || i >= g->nn[c]) in = false;
        nb += i * g->stride[c];
      }
      if (!in) continue;
      int r = 0;
      for (int c = 0; c < 3; c++) r += im->dof[3 * nb + c] >= 0;
      if (!r) continue;
      off[s] = cnt;
      cnt += r;
    }
    for (int c = 0; c < 3; c++) {
      long row = im->dof[3 * k + c];
      if (row < 0) continue;
      total += cnt;
      im->pat_ptr[row + 1] = cnt; /* lengths first */
    }
  }
  for (long r = 0; r < nh; r++) im->pat_ptr[r + 1] += im->pat_ptr[r];
  im->entries_all = total;
  mpm_xc_sum_long(im->m, &im->entries_all, 1);
  if (total > im->pat_cap) {
    PM_CALL(PM_REALLOC(im->pat_idx, total, "Jacobian pattern"));
    im->pat_cap = total;
  }
  for (long k = 0; k < nn; k++) {
    const int *off = im->nb_off + k * im->nnb;
    long ijk[3] = {k % g->nn[0], (k / g->nn[0]) % g->nn[1], k / g->stride[2]};
    for (int c = 0; c < 3; c++) {
      long row = im->dof[3 * k + c];
      if (row < 0) continue;
      long pos = im->pat_ptr[row];
      for (int s = 0; s < im->nnb; s++) {
        if (off[s] < 0) continue;
        long nb = 0;
        for (int e = 0; e < im->dim; e++) {
          int d = (e == 0   ? s % im->nb
                   : e == 1 ? (s / im->nb) % im->nb
                            : s / (im->nb * im->nb)) -
                  span;
          nb += (ijk[e] + d) * g->stride[e];
        }
        for (int e = 0; e < 3; e++)
          if (im->dof[3 * nb + e] >= 0)
            im->pat_idx[pos++] = im->dof[3 * nb + e];
      }
    }
  }
  return PM_SUCCESS;
}

/* Rigid motions over the unknowns, at the nodes' base positions (the
 * grid's for reset; the reference for kept), for algebraic multigrid. */
static pm_err make_near_null(mpm_implicit *im, int *count) {
  const int nr = im->dim == 3 ? 6 : 3;
  PM_CALL(PM_REALLOC(im->near_null, (long)nr * im->nunk, "rigid motions"));
  double *z = im->near_null;
  for (long k = 0; k < im->nunk; k++) {
    long d = im->unk_dof[k], node = d / 3;
    int c = (int)(d % 3);
    double x[3];
    node_position(&im->g, node, x);
    for (int r = 0; r < nr; r++) z[(long)r * im->nunk + k] = 0;
    z[(long)c * im->nunk + k] = 1; /* translations */
    if (im->dim == 2) {
      /* rotation about z: (-y, x) */
      z[2L * im->nunk + k] = c == 0 ? -x[1] : x[0];
    } else {
      /* rotations about x, y, z: e_r x x */
      const double rx[3][3] = {
          {0, -x[2], x[1]}, {x[2], 0, -x[0]}, {-x[1], x[0], 0}};
      for (int r = 0; r < 3; r++) z[(long)(3 + r) * im->nunk + k] = rx[r][c];
    }
  }
  *count = nr;
  return PM_SUCCESS;
}

/* The solver for the current structure. */
static pm_err make_solver(mpm_implicit *im) {
  pm_newton_destroy(&im->solver);
  int nnull = 0;
  const bool amg = im->opt.linear == PM_NEWTON_GMRES_GAMG ||
                   im->opt.linear == PM_NEWTON_CG_GAMG;
  if (amg) PM_CALL(make_near_null(im, &nnull));
  pm_newton_problem pb = {
      .n = im->nunk,
      .ctx = im,
      .residual = cb_residual,
      .jacobian_apply = cb_apply,
      .jacobian_prepare = cb_prepare,
      .jacobian_values = im->matrix_free || im->fbar ? NULL : cb_values,
      .pat_ptr = im->pat_ptr,
      .pat_idx = im->pat_idx,
      .precond_apply = im->matrix_free ? cb_precond : NULL,
      .pc_pat_ptr = im->matrix_free ? im->pc_ptr : NULL,
      .pc_pat_idx = im->matrix_free ? im->pc_idx : NULL,
      .near_null_count = nnull,
      .near_null = amg ? im->near_null : NULL,
      .shared = im->ranks,
      .n_ghost = im->nghost,
      .ghost = im->ghost,
      .set_load = cb_set_load,
  };
  pb.on_step = on_step;
  return pm_newton_create(&pb, &im->opt, &im->solver);
}

/* Build buckets, dofs and the solver for the base as it is. */
static pm_err rebuild(mpm_implicit *im) {
  make_buckets(im);
  PM_CALL(make_dofs(im));
  return make_solver(im);
}

/* ---- converged steps ---------------------------------------------------- */

/* The particles at the converged unknowns x: position, F, stress and
 * volume; the reactions and the residual. */
static pm_err commit(mpm_implicit *im, const double *x) {
  const mpm_model *m = im->m;
  mpm_state *st = im->st;
  if (im->ranks) { /* the ghost nodes' unknowns too */
    PM_CALL(pm_newton_held_values(im->solver, x, im->x_held));
    x = im->x_held;
  }
  fill_u(im, x);
  if (!nodal_force(im, im->u, im->f))
    return PM_ERROR(PM_ERR_UNSTABLE, "%s", im->fail_msg);
  /* Across ranks: whole nodal sums, counted at the nodes a rank owns. */
  const unsigned char *own = im->ranks ? mpm_xc_owned(m) : NULL;
  if (im->ranks)
    PM_CALL(mpm_xc_nodes_reduce(m, im->f, MPM_XC_DOUBLE3, MPM_XC_SUM));
  for (int b = 0; b < 3 * m->n_bcs; b++) im->reaction[b] = 0;
  double sums[2] = {0, 0}; /* |r|^2, |reactions|^2 */
  for (long k = 0; k < im->npre; k++) {
    if (own && !own[im->pre_dof[k] / 3]) continue;
    const double fk = im->f[im->pre_dof[k]];
    im->reaction[3 * im->pre_bc[k] + im->pre_dof[k] % 3] += fk;
    sums[1] += fk * fk;
  }
  for (long k = 0; k < im->nunk; k++)
    sums[0] += im->f[im->unk_dof[k]] * im->f[im->unk_dof[k]];
  if (im->ranks) {
    mpm_xc_sum(m, im->reaction, 3 * m->n_bcs);
    mpm_xc_sum(m, sums, 2);
    mpm_xc_min(m, &im->min_jacobian, 1);
  }
  const double rr = sums[0], rf = sums[1];
  im->residual = rf > 0 ? sqrt(rr / rf) : sqrt(rr);
  if (im->fbar) /* the stress from Fbar, before F_b changes */
    FOR_BUCKETS(im, {
      double Jbar, V;
      fbar_bucket_J(im, q0, q1, im->u, NULL, &Jbar, &V, NULL);
      for (long q = q0; q < q1; q++) {
        const long p = im->order[q];
        mpm_stencil stn;
        mpm_stencil_at(&im->g, im->xb + 3 * p, MPM_STENCIL_GRAD, &stn);
        double F[9], Fbar[9], P[9];
        particle_F(im, p, &stn, im->u, F);
        fbar_scale(im->dim, pow(Jbar / pm_t_det(F), 1.0 / im->dim), F, Fbar);
        const mpm_solid_view *v = &im->view[im->grp[p]];
        if (!pm_material_stress(v->mat, Fbar, model_state(im, p), P, NULL,
                                NULL))
          continue; /* nodal_force succeeded on the same state */
        double *sig = st->sigma + 9 * p;
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < 3; j++)
            sig[3 * i + j] =
                (P[3 * i] * Fbar[3 * j] + P[3 * i + 1] * Fbar[3 * j + 1] +
                 P[3 * i + 2] * Fbar[3 * j + 2]) /
                Jbar;
      }
    })
  const long n = im->n;
  const double *u = im->u;
  long bad = -1;
  PM_OMP(parallel for schedule(static) reduction(max : bad))
  for (long p = 0; p < n; p++) {
    mpm_stencil stn;
    const double *xb = im->xb + 3 * p;
    mpm_stencil_at(&im->g, xb, MPM_STENCIL_W | MPM_STENCIL_GRAD, &stn);
    double F[9], P[9], J, xn[3] = {xb[0], xb[1], xb[2]};
    particle_F(im, p, &stn, u, F);
    for (int k = 0; k < stn.n; k++)
      for (int c = 0; c < 3; c++) xn[c] += stn.w[k] * u[3 * stn.node[k] + c];
    const int gi = im->grp[p];
    const mpm_solid_view *v = &im->view[gi];
    if (!pm_material_stress(v->mat, F, model_state(im, p), P, NULL, &J)) {
      bad = p > bad ? p : bad;
      continue;
    }
    double *sig = st->sigma + 9 * p;
    if (!im->fbar)
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          sig[3 * i + j] = (P[3 * i] * F[3 * j] + P[3 * i + 1] * F[3 * j + 1] +
                            P[3 * i + 2] * F[3 * j + 2]) /
                           J;
    memcpy(v->F + 9 * (p - im->group_begin[gi]), F, sizeof F);
    st->vol[p] = m->vol0[p] * J;
    for (int c = 0; c < 3; c++) {
      st->x[3 * p + c] = xn[c];
      st->v[3 * p + c] = 0;
    }
  }
  PM_CHECK(bad < 0, PM_ERR_UNSTABLE,
           "particle %ld: no stress at the converged state",
           m->gid ? m->gid[bad] : bad);
  return PM_SUCCESS;
}

/* The observer's view of a converged step. */
static pm_err report_step(mpm_implicit *im, const pm_newton_report *r) {
  im->step++;
  double now = pm_wtime();
  mpm_implicit_step info = {.step = im->step,
                            .lambda = im->lambda,
                            .newton = r ? r->iterations : 0,
                            .linear = r ? r->linear_iterations : 0,
                            .cuts = im->rep.cuts,
                            .residual = im->residual,
                            .min_jacobian = im->min_jacobian,
                            .seconds = now - im->t_step,
                            .report = r};
  im->t_step = now;
  return im->obs ? im->obs(im->octx, &info) : PM_SUCCESS;
}

static pm_err on_step(void *ctx, int step, double lambda, const double *x,
                      const pm_newton_report *report) {
  (void)step;
  mpm_implicit *im = ctx;
  if (im->mode == MPM_GRID_RESET && lambda < 1) return PM_SUCCESS;
  pm_err e = commit(im, x);
  PM_CALL(im->ranks ? mpm_xc_agree(im->m, e) : e);
  im->lambda = im->lam0 + lambda * (im->lam1 - im->lam0);
  return report_step(im, report);
}

/* Add one load stepping's counters to the run's. */
static void add_report(pm_load_report *t, const pm_load_report *r) {
  t->steps += r->steps;
  t->cuts += r->cuts;
  t->newton_iterations += r->newton_iterations;
  t->linear_iterations += r->linear_iterations;
  t->time_residual += r->time_residual;
  t->time_assembly += r->time_assembly;
  t->time_linear += r->time_linear;
  t->time_total += r->time_total;
  if (r->steps > 0 && (t->dlambda_min == 0 || r->dlambda_min < t->dlambda_min))
    t->dlambda_min = r->dlambda_min;
  t->last = r->last;
}

pm_err mpm_implicit_run(mpm_implicit *im, mpm_implicit_observer obs,
                        void *ctx) {
  pm_err e = PM_SUCCESS;
  im->obs = obs;
  im->octx = ctx;
  im->t_step = pm_wtime();
  if (im->mode == MPM_GRID_KEPT) {
    im->lam0 = 0;
    im->lam1 = 1;
    e = pm_load_steps_from(im->solver, im->x_unk, &im->ls, &im->rep);
  } else {
    const int N = im->opt_steps;
    for (int k = (int)llround(im->lambda * N); k < N && !e; k++) {
      im->lam0 = (double)k / N;
      im->lam1 = (double)(k + 1) / N;
      im->lam_local = 0;
      if (im->built_for != k) e = rebuild(im); /* create built the first */
      im->built_for = -1;
      if (e) break;
      memset(im->x_unk, 0, sizeof(double) * (size_t)im->nunk);
      pm_load_report r = {0};
      e = pm_load_steps(im->solver, im->x_unk, &r);
      add_report(&im->rep, &r);
      if (e == PM_ERR_NOT_CONVERGED || e == PM_ERR_UNSTABLE) {
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", pm_error_message());
        e = PM_ERROR(e,
                     "load step %d of %d (lambda %.6g -> %.6g, grid reset, "
                     "increments from the step's start): %s",
                     k + 1, N, im->lam0, im->lam1, msg);
      }
    }
    im->rep.lambda = im->lambda;
  }
  im->obs = NULL;
  return e;
}

/* ---- setup -------------------------------------------------------------- */

/* The outermost layer of particles at each condition's face (reset). */
static pm_err make_faces(mpm_implicit *im) {
  const mpm_model *m = im->m;
  PM_CALL(PM_ALLOC(im->face_ptr, m->n_bcs + 1, "face particles"));
  long total = 0;
  double *dmin = NULL;
  PM_CALL(PM_ALLOC(dmin, m->n_bcs + 1, "face distances"));
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    dmin[b] = INFINITY;
    for (long p = 0; p < im->n; p++)
      dmin[b] = fmin(dmin[b], fabs(m->x0[3 * p + bc->axis] - bc->plane));
    for (long p = 0; p < im->n; p++)
      total +=
          fabs(m->x0[3 * p + bc->axis] - bc->plane) <= dmin[b] + 1e-6 * im->g.h;
  }
  pm_err e = PM_ALLOC(im->face, total + 1, "face particles");
  if (e) {
    free(dmin);
    return e;
  }
  long k = 0;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    im->face_ptr[b] = k;
    for (long p = 0; p < im->n; p++)
      if (fabs(m->x0[3 * p + bc->axis] - bc->plane) <= dmin[b] + 1e-6 * im->g.h)
        im->face[k++] = p;
  }
  im->face_ptr[m->n_bcs] = k;
  free(dmin);
  return PM_SUCCESS;
}

/* The grid of the reset algorithm: the model's box with room on every side
 * for the largest prescribed displacement, plus a cell. */
static pm_err reset_grid(mpm_implicit *im, const pm_scene *s) {
  const mpm_model *m = im->m;
  double umax = 0;
  for (int b = 0; b < m->n_bcs; b++)
    for (int c = 0; c < im->dim; c++)
      umax = fmax(umax, mpm_bc_largest_displacement(s, b, c, 0));
  const double h = m->grid.h;
  const double room = (ceil(umax / h) + 1) * h;
  double lo[3], hi[3];
  for (int c = 0; c < 3; c++) {
    lo[c] = m->box_min[c] - (c < im->dim ? room : 0);
    hi[c] = m->box_max[c] + (c < im->dim ? room : 0);
  }
  return mpm_grid_init(&im->g, im->dim, m->grid.shape, h, lo, hi, s->path);
}

pm_err mpm_implicit_create(const pm_scene *s, const mpm_model *m, mpm_state *st,
                           mpm_implicit **out) {
  pm_err ret = PM_SUCCESS;
  mpm_implicit *im = NULL;
  *out = NULL;
  const mpm_settings *ms = mpm_scene_settings(s);
  PM_TRY(PM_ALLOC(im, 1, "implicit MPM"));
  im->s = s;
  im->m = m;
  im->st = st;
  im->n = m->n;
  im->ranks = mpm_xc_shared(m);
  im->dim = m->dim;
  im->mode = (mpm_grid_mode)ms->implicit.grid;
  im->matrix_free = ms->implicit.op == MPM_OP_MATRIX_FREE;
  im->fbar = ms->fbar == MPM_FBAR_CELL;
  im->jmin = s->stability.min_jacobian;
  im->has_gravity = m->opt.has_gravity;
  for (int c = 0; c < 3; c++) im->gravity[c] = m->opt.gravity[c];
  im->lam1 = 1;
  im->built_for = -1;
  PM_TRY(PM_ALLOC(im->grp, im->n, "particle groups"));
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    if (!mpm_solid_access(g, st, &im->view[gi])) {
      char p[64];
      ret =
          pm_scene_fail(s, PM_PATH(p, "materials.%d.model", g->material), false,
                        "expected a solid for method mpm-implicit, got %s "
                        "particles of material %s",
                        g->kind->name, g->name);
      goto done;
    }
    im->group_begin[gi] = g->begin;
    for (long p = g->begin; p < g->end; p++) im->grp[p] = (unsigned char)gi;
  }
  im->threads = pm_omp_threads();
  PM_TRY(PM_ALLOC(im->tmin, im->threads, "thread minima"));
  if (im->mode == MPM_GRID_KEPT) {
    im->g = m->grid;
    im->xb = m->x0;
  } else {
    PM_TRY(reset_grid(im, s));
    im->xb = st->x;
    im->base_f = true;
    PM_TRY(make_faces(im));
  }
  im->w = im->g.width;
  im->nb = 2 * im->w - 1;
  im->nnb = im->dim == 3 ? im->nb * im->nb * im->nb : im->nb * im->nb;
  im->sn = im->dim == 3 ? im->w * im->w * im->w : im->w * im->w;
  for (int a = 0; a < im->sn; a++)
    for (int b = 0; b < im->sn; b++) {
      int sa[3] = {a % im->w, (a / im->w) % im->w, a / (im->w * im->w)};
      int sb[3] = {b % im->w, (b / im->w) % im->w, b / (im->w * im->w)};
      int k = 0, mul = 1;
      for (int c = 0; c < im->dim; c++, mul *= im->nb)
        k += (sb[c] - sa[c] + im->w - 1) * mul;
      im->soff[a][b] = k;
    }
  const long nn = im->g.n_nodes;
  PM_TRY(PM_ALLOC(im->order, im->n, "particle order"));
  PM_TRY(PM_ALLOC(im->bucket, nn + 1, "particle buckets"));
  PM_TRY(PM_ALLOC(im->cbuck, nn, "bucket colours"));
  PM_TRY(PM_ALLOC(im->active, nn, "active nodes"));
  PM_TRY(PM_ALLOC(im->dof, 3 * nn, "grid dofs"));
  if (im->ranks) PM_TRY(PM_ALLOC(im->gnum, 3 * nn, "global dofs"));
  PM_TRY(PM_ALLOC(im->nb_off, nn * im->nnb, "neighbour offsets"));
  PM_TRY(PM_ALLOC(im->u, 3 * nn, "nodal displacements"));
  PM_TRY(PM_ALLOC(im->du, 3 * nn, "nodal directions"));
  PM_TRY(PM_ALLOC(im->f, 3 * nn, "nodal forces"));
  PM_TRY(PM_ALLOC(im->df, 3 * nn, "nodal force changes"));
  PM_TRY(PM_ALLOC(im->reaction, 3 * m->n_bcs + 1, "reactions"));
  /* Newton's settings */
  pm_newton_options *o = &im->opt;
  *o = pm_newton_options_default();
  o->max_iter = (int)s->time.qs_max_iterations;
  im->opt_steps = (int)s->time.qs_load_steps;
  o->load_steps = im->mode == MPM_GRID_KEPT ? im->opt_steps : 1;
  if (ms->implicit.convergence == MPM_CONV_PAPER) {
    o->rtol = 0;
    o->dtol = ms->implicit.dtol;
    o->etol = ms->implicit.etol;
    o->all_criteria = true;
  } else {
    o->rtol = s->time.qs_tolerance;
  }
  o->linear = pm_scene_has(s, "time.quasi_static.linear_solver")
                  ? pm_newton_linear_of(s->time.qs_linear)
                  : PM_NEWTON_GMRES_GAMG; /* measured fastest from
                                             I2 at 128^2 cells up */
  if (im->matrix_free) {
    if (pm_scene_has(s, "time.quasi_static.linear_solver") &&
        o->linear != PM_NEWTON_CG_JACOBI) {
      ret = pm_scene_fail(s, "time.quasi_static.linear_solver", false,
                          "expected cg-jacobi with mpm.implicit.operator "
                          "matrix-free (its preconditioner is the tangent's "
                          "diagonal)");
      goto done;
    }
    o->linear = PM_NEWTON_CG_JACOBI;
    o->op = PM_NEWTON_MATRIX_FREE_CHEAP_PC;
  }
  /* Each step starts from the last two states extrapolated (the first
   * from the tangent predictor): a step's first state is then near
   * equilibrium, where the tangent is positive definite, rather than with
   * the prescribed nodes moved alone, where near-incompressible
   * particles by the face make it indefinite and CG breaks down. */
  o->predictor = true;
  o->linear_rtol = 1e-10;
  o->linear_max_iter = 20000;
  o->petsc_options = s->time.qs_solver_options;
  if (im->mode == MPM_GRID_RESET) im->lam1 = 1.0 / im->opt_steps;
  make_buckets(im);
  PM_TRY(make_dofs(im));
  /* An absolute floor on the residual: a hundred times its roundoff, eps
   * times the stiffest material's P-wave modulus times a node's share of
   * a face (h^(d-1)), over the unknowns.  Below it the relative test
   * cannot be met (the volumetric term of a nearly incompressible solid
   * alone carries K (J - 1) with J - 1 from det F). */
  double M = 0;
  for (int gi = 0; gi < m->n_groups; gi++)
    M = fmax(M, im->view[gi].mat->wave_modulus);
  o->atol = 100 * DBL_EPSILON * M * pow(m->grid.h, im->dim - 1) *
            sqrt((double)im->nunk_all);
  PM_TRY(make_solver(im));
  im->built_for = 0;
  if (im->mode == MPM_GRID_KEPT) PM_TRY(pm_load_state_init(&im->ls, im->nunk));
  /* the initial state's reactions (zero load) */
  for (int b = 0; b < 3 * m->n_bcs; b++) im->reaction[b] = 0;
  *out = im;
  im = NULL;
done:
  mpm_implicit_destroy(im);
  return ret;
}

void mpm_implicit_destroy(mpm_implicit *im) {
  if (!im) return;
  pm_newton_destroy(&im->solver);
  pm_load_state_free(&im->ls);
  free(im->grp);
  free(im->tmin);
  free(im->order);
  free(im->bucket);
  free(im->cbuck);
  free(im->active);
  free(im->dof);
  free(im->gnum);
  free(im->ghost);
  free(im->unk_dof);
  free(im->pre_dof);
  free(im->pre_val);
  free(im->pre_bc);
  free(im->nb_off);
  free(im->pat_ptr);
  free(im->pat_idx);
  free(im->pc_ptr);
  free(im->pc_idx);
  free(im->near_null);
  free(im->face_ptr);
  free(im->face);
  free(im->u);
  free(im->du);
  free(im->f);
  free(im->df);
  free(im->diag);
  free(im->x_unk);
  free(im->x_held);
  free(im->whole);
  free(im->reaction);
  free(im);
}

const double *mpm_implicit_reactions(const mpm_implicit *im) {
  return im->reaction;
}
double mpm_implicit_residual(const mpm_implicit *im) { return im->residual; }
double mpm_implicit_lambda(const mpm_implicit *im) { return im->lambda; }
const pm_load_report *mpm_implicit_report(const mpm_implicit *im) {
  return &im->rep;
}
void mpm_implicit_size(const mpm_implicit *im, long *unknowns, long *entries) {
  *unknowns = im->nunk_all;
  *entries = im->entries_all;
}

void mpm_implicit_held(const mpm_implicit *im, long *own, long *ghost) {
  *own = im->nunk;
  *ghost = im->ranks ? im->nghost : 0;
}

static const char *linear_name(pm_newton_linear l) {
  switch (l) {
  case PM_NEWTON_DIRECT: return "direct (LU)";
  case PM_NEWTON_GMRES_GAMG: return "GMRES + GAMG";
  case PM_NEWTON_CG_JACOBI: return "CG + Jacobi";
  case PM_NEWTON_GMRES_ILU: return "GMRES + ILU(0)";
  case PM_NEWTON_CG_GAMG: return "CG + GAMG";
  }
  return "?";
}

void mpm_implicit_plan(const mpm_implicit *im, FILE *out) {
  const mpm_grid *g = &im->g;
  const long active = im->active_all;
  fprintf(out, "algorithm    %s\n",
          im->mode == MPM_GRID_KEPT
              ? "grid kept with the particles (the modified algorithm: "
                "total Lagrangian on the grid)"
              : "grid reset after each load step (the standard algorithm)");
  fprintf(out,
          "solver grid  %ld x %ld x %ld nodes%s (%ld active), cell %g m, "
          "%d colours of cells\n",
          g->nn[0], g->nn[1], g->nn[2], im->ranks ? " on rank 0" : "", active,
          g->h, im->sn);
  fprintf(out,
          "unknowns     %ld (%ld prescribed), Jacobian %ld entries "
          "(%.1f MiB)%s\n",
          im->nunk_all, im->npre, im->entries_all,
          im->entries_all * 12.0 / 1048576.0,
          im->mode == MPM_GRID_RESET ? ", first load step" : "");
  fprintf(out, "newton       %d load steps, at most %d iterations each, ",
          im->opt_steps, im->opt.max_iter);
  if (im->opt.rtol > 0)
    fprintf(out, "residual below %g of the first\n", im->opt.rtol);
  else
    fprintf(out,
            "eq. 9: displacement below %g and energy below %g of the first\n",
            im->opt.dtol, im->opt.etol);
  fprintf(out, "linear       %s, %s\n", linear_name(im->opt.linear),
          im->matrix_free ? "matrix-free (diagonal preconditioner)"
                          : "assembled tangent");
}

/* Node i of the solver's grid g as a node of the whole grid fg. */
static long whole_node(const mpm_grid *g, const mpm_grid *fg, long i) {
  const long ijk[3] = {i % g->nn[0], (i / g->nn[0]) % g->nn[1],
                       i / g->stride[2]};
  long q = 0;
  for (int a = 0; a < 3; a++) q += (ijk[a] + g->offset[a]) * fg->stride[a];
  return q;
}

/* The owned unknowns x (nunk) as nodal displacements u of the solver's
 * grid (0 at the other dofs), and back. */
static void unknowns_to_nodes(const mpm_implicit *im, const double *x,
                              double *u) {
  memset(u, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  for (long k = 0; k < im->nunk; k++) u[im->unk_dof[k]] = x[k];
}

pm_err mpm_implicit_gather(mpm_implicit *im, const mpm_model *full) {
  if (im->mode != MPM_GRID_KEPT) return PM_SUCCESS;
  pm_err e = PM_SUCCESS;
  if (full && !im->whole)
    e = PM_ALLOC(im->whole, 6 * full->grid.n_nodes, "nodal gather");
  PM_CALL(mpm_xc_agree(im->m, e));
  const long nf = full ? 3 * full->grid.n_nodes : 0;
  for (int s = 0; s < 2; s++) {
    unknowns_to_nodes(im, s ? im->ls.xprev : im->ls.xc, im->du);
    PM_CALL(mpm_xc_gather_nodes(im->m, full, im->du,
                                full ? im->whole + s * nf : NULL));
  }
  return PM_SUCCESS;
}

/* With the grid kept: load stepping's two states as nodal displacements of
 * the whole grid (full's), written from the solver's unknowns (or, across
 * ranks, from what mpm_implicit_gather gathered) or read into them. */
static pm_err checkpoint_states(mpm_implicit *im, const mpm_model *full,
                                pm_ckpt *ck) {
  const mpm_grid *fg = &full->grid;
  const long nf = 3 * fg->n_nodes;
  const bool reading = pm_ckpt_reading(ck);
  if (!im->whole) PM_CALL(PM_ALLOC(im->whole, 2 * nf, "nodal states"));
  for (int s = 0; s < 2; s++) {
    double *x = s ? im->ls.xprev : im->ls.xc, *u = im->whole + s * nf;
    if (!reading && !im->ranks) unknowns_to_nodes(im, x, u);
    PM_CALL(pm_ckpt_doubles(ck, s ? "implicit.load.u_prev" : "implicit.load.u",
                            nf, u));
    if (!reading) continue;
    for (long k = 0; k < im->nunk; k++) {
      const long d = im->unk_dof[k];
      x[k] = u[3 * whole_node(&im->g, fg, d / 3) + d % 3];
    }
  }
  return PM_SUCCESS;
}

pm_err mpm_implicit_checkpoint(mpm_implicit *im, const mpm_model *full,
                               pm_ckpt *ck) {
  long step = im->step;
  PM_CALL(pm_ckpt_double(ck, "implicit.lambda", &im->lambda));
  PM_CALL(pm_ckpt_long(ck, "implicit.step", &step));
  im->step = (int)step;
  PM_CALL(
      pm_ckpt_doubles(ck, "implicit.reaction", 3 * im->m->n_bcs, im->reaction));
  PM_CALL(pm_ckpt_double(ck, "implicit.residual", &im->residual));
  if (im->mode == MPM_GRID_KEPT) {
    PM_CALL(pm_load_checkpoint(ck, "implicit.load", 0, &im->ls, &im->rep));
    PM_CALL(checkpoint_states(im, full, ck));
  } else {
    PM_CALL(pm_load_checkpoint(ck, "implicit.load", 0, NULL, &im->rep));
  }
  if (pm_ckpt_reading(ck) && im->mode == MPM_GRID_RESET) im->built_for = -1;
  return PM_SUCCESS;
}

/* A smooth field over the unknowns, for the tangent check. */
static void smooth_field(const mpm_implicit *im, double amp, double *x) {
  for (long k = 0; k < im->nunk; k++) {
    double y[3];
    long d = im->unk_dof[k];
    node_position(&im->g, d / 3, y);
    double h = im->g.h * 10;
    x[k] = amp * sin(y[0] / h + 0.3 * (double)(d % 3)) * cos(y[1] / h) *
           (1 + 0.2 * sin(y[2] / h));
  }
}

pm_err mpm_implicit_check_tangent(mpm_implicit *im, double lambda, double amp,
                                  double *assembled_error,
                                  double *matrix_free_error) {
  pm_err ret = PM_SUCCESS;
  if (im->mode == MPM_GRID_RESET) PM_CALL(rebuild(im));
  const long n = im->nunk;
  const long nz = im->pat_ptr[n];
  double *x = NULL, *val = NULL, *xp = NULL, *r1 = NULL, *r2 = NULL, *e = NULL,
         *ke = NULL;
  PM_TRY(PM_ALLOC(x, n, "check"));
  PM_TRY(PM_ALLOC(xp, n, "check"));
  PM_TRY(PM_ALLOC(r1, n, "check"));
  PM_TRY(PM_ALLOC(r2, n, "check"));
  PM_TRY(PM_ALLOC(e, n, "check"));
  PM_TRY(PM_ALLOC(ke, n, "check"));
  PM_TRY(PM_ALLOC(val, nz, "check"));
  im->lam_local = lambda;
  smooth_field(im, amp, x);
  /* the values the solver assembles (directly, or coloured from the
   * product with F-bar) */
  PM_TRY(pm_newton_jacobian_values(im->solver, x, val));
  /* central differences, column by column */
  double dmax = 0, err_a = 0, err_m = 0;
  for (long j = 0; j < n; j++) {
    const double h = 1e-6 * (fabs(x[j]) + amp + 1e-30);
    memcpy(xp, x, sizeof(double) * (size_t)n);
    xp[j] = x[j] + h;
    PM_TRY(cb_residual(im, xp, r1));
    xp[j] = x[j] - h;
    PM_TRY(cb_residual(im, xp, r2));
    memset(e, 0, sizeof(double) * (size_t)n);
    e[j] = 1;
    PM_TRY(cb_apply(im, x, e, ke));
    for (long i = 0; i < n; i++) {
      double d = (r1[i] - r2[i]) / (2 * h);
      dmax = fmax(dmax, fabs(d));
      err_m = fmax(err_m, fabs(ke[i] - d));
      /* the assembled value of (i, j), 0 outside the pattern */
      double a = 0;
      for (long q = im->pat_ptr[i]; q < im->pat_ptr[i + 1]; q++)
        if (im->pat_idx[q] == j) a += val[q];
      err_a = fmax(err_a, fabs(a - d));
    }
  }
  *assembled_error = dmax > 0 ? err_a / dmax : err_a;
  *matrix_free_error = dmax > 0 ? err_m / dmax : err_m;
done:
  free(x);
  free(xp);
  free(r1);
  free(r2);
  free(e);
  free(ke);
  free(val);
  return ret;
}
