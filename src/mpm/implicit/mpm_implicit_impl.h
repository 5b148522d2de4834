/* mpm_implicit_impl: what the pieces of the implicit MPM share: the
 * solver's struct, the per-particle helpers, the colour loops and F-bar's
 * per-particle sums.  Internal to implicit/. */
#ifndef MPM_IMPLICIT_IMPL_H
#define MPM_IMPLICIT_IMPL_H

#include <stdio.h>
#include <string.h>

#include "mpm_implicit.h"
#include "mpm_kind.h"
#include "pm_omp.h"
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
  /* A prescribed dof may follow an unknown (its anchor, a grid dof,
   * -1 none): u = lam_local pre_val + pre_t u[anchor], the odd or even
   * extension of the field beyond a condition's face (grid kept). */
  long *pre_anchor;
  double *pre_t;
  int *nb_off; /* nnb per node: offset of a neighbour's columns in a row */
  long *pat_ptr, *pat_idx, pat_cap;
  long *pc_ptr, *pc_idx; /* diagonal pattern (matrix-free Jacobi) */
  double *near_null;     /* rigid motions for algebraic multigrid */
  /* face particles of each condition (reset) */
  long *face_ptr, *face;
  /* 2 per node: the mass of the particles, and of a grip's, that reach
   * it (grid kept, a motion on a named surface only) */
  double *grip_mass;
  /* the pressures' tangent entries outside the pattern at the last
   * assembly (left out: the tangent is then inexact there) */
  long pressure_left_out;
  /* nodal work, 3 per node */
  double *u, *du, *f, *df, *diag;
  double *trac_at; /* the tractions' points where the last step left them
                      (3 per point; mpm_tractions_work) */
  double *x_unk;   /* unknowns */
  double *x_held;  /* across ranks: the owned unknowns and the ghosts' */
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
  /* why the linear solver and F-bar are what they are (for plan) */
  char why_linear[192], why_fbar[256];
  int threads;
  double *tmin;         /* per thread: smallest J of a force evaluation */
  double *wbar;         /* F-bar: V0 W(Fbar) a particle at the last
                           converged state (NULL without F-bar) */
  double strain_energy; /* F-bar: their sum over every rank's particles */
  double min_jacobian;  /* of the last force evaluation */
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

/* Note particle p's failure in im->fail_msg: the lowest index wins, as on
 * one process. */
static inline void note_failure(mpm_implicit *im, long p, const char *what,
                                double J) {
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

/* The unknown dof d follows and its factor: dof d itself (factor 1), or
 * a prescribed dof's anchor; false when d follows none. */
static inline bool follows(const mpm_implicit *im, long d, long *unk,
                           double *t) {
  const long k = im->dof[d];
  if (k >= 0) {
    *unk = k;
    *t = 1;
    return true;
  }
  if (k > -2 || im->pre_anchor[-2 - k] < 0) return false;
  *unk = im->dof[im->pre_anchor[-2 - k]];
  *t = im->pre_t[-2 - k];
  return true;
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

/* T_q of particle p at fp (the bucket's Jbar, S and sum V0 given), and
 * with with_d its derivative dT along fp's dF, dJ and the bucket's dJbar,
 * dS; s_q and ds_q for the bucket's sums (each output may be NULL).
 * False when the stress or tangent fails (mpm_implicit_force.c). */
bool mpm_implicit_fbar_particle(const mpm_implicit *im, long p,
                                const fbar_point *fp, double Jbar, double S,
                                double V, double dJbar, double dS, bool with_d,
                                double T[9], double dT[9], double *s_out,
                                double *ds_out);

/* ---- between the pieces -------------------------------------------------- */

/* Forces (mpm_implicit_force.c): the nodal forces f at displacements u,
 * false with im->fail_msg set when a particle fails; u from the unknowns x
 * and the prescribed values; the Newton callbacks of the residual, the
 * load and the tangent's product. */
bool mpm_implicit_nodal_force(mpm_implicit *im, const double *u, double *f);
void mpm_implicit_fill_u(mpm_implicit *im, const double *x);
/* du from the directions dx of the unknowns (the prescribed dofs follow
 * their anchors); the nodal forces f folded onto the unknowns into r (a
 * dof that follows an anchor adds its force times its factor there). */
void mpm_implicit_fill_du(mpm_implicit *im, const double *dx);
void mpm_implicit_fold(const mpm_implicit *im, const double *f, double *r);
pm_err mpm_implicit_cb_residual(void *ctx, const double *x, double *r);
pm_err mpm_implicit_cb_set_load(void *ctx, double lambda);
pm_err mpm_implicit_cb_apply(void *ctx, const double *x, const double *dx,
                             double *y);
/* Tangent (mpm_implicit_tangent.c): the assembled values, the
 * preparation of a product and the diagonal preconditioner. */
pm_err mpm_implicit_cb_values(void *ctx, const double *x, double *val);
pm_err mpm_implicit_cb_prepare(void *ctx, const double *x);
pm_err mpm_implicit_cb_precond(void *ctx, const double *x, const double *dx,
                               double *y);
/* Structure (mpm_implicit_dofs.c): buckets, dofs, the Jacobian's pattern,
 * the solver; rebuilt for the grid of a load step (reset). */
void mpm_implicit_make_buckets(mpm_implicit *im);
pm_err mpm_implicit_make_dofs(mpm_implicit *im);
pm_err mpm_implicit_make_solver(mpm_implicit *im);
pm_err mpm_implicit_rebuild(mpm_implicit *im);
/* Add v to the tangent's entry (row unknown of node rn, column dof cd) in
 * the pattern's order (val); false when the entry is outside the
 * pattern. */
bool mpm_implicit_add_entry(const mpm_implicit *im, long row, long rn, long cd,
                            double v, double *val);
/* The particle's (or bucket's) tangent block K (3 st->n square, rows and
 * columns node by node, component by component) added to the assembled
 * values val, folded through the conditions' extensions; *outside set
 * when an entry falls outside the pattern. */
void mpm_implicit_scatter_block(const mpm_implicit *im, const mpm_stencil *st,
                                const double *K, double *val, bool *outside);
/* After an assembly: PM_ERR_INTERNAL with the failed particle
 * (im->fail_msg) or when an entry fell outside the pattern, else
 * PM_SUCCESS. */
pm_err mpm_implicit_values_status(const mpm_implicit *im, bool outside);
/* An[iJkM] = sum_KL A[iKkL] Fb[JK] Fb[ML] for particle p (A when F_b =
 * I), A[9 iK + kL] = dP_iK / dF_kL. */
void mpm_implicit_tangent_to_base(const mpm_implicit *im, long p,
                                  const double A[81], double An[81]);
/* F-bar's assembled tangent (mpm_implicit_fbar_tangent.c). */
pm_err mpm_implicit_fbar_values(mpm_implicit *im, double *val);
/* Converged steps (mpm_implicit_steps.c): Newton's step callback. */
pm_err mpm_implicit_on_step(void *ctx, int step, double lambda, const double *x,
                            const pm_newton_report *report);

#endif
