/* mpm_implicit_force: the implicit MPM's nodal forces (with F-bar over a
 * cell's particles) and the Newton callbacks of the residual and the
 * tangent's product. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_exchange.h"
#include "mpm_implicit_impl.h"
#include "pm_interrupt.h"
#include "mpm_kind.h"
#include "mpm_traction.h"
#include "pm_omp.h"
#include "pm_progress.h"
#include "pm_tensor.h"

/* T_q of particle p (with dT when du: then dS and dJbar are the bucket's
 * sums' derivatives), from the bucket's Jbar, S and sum V0.  Also s_q (and
 * ds_q) for the sums' pass.  False when the stress or tangent fails. */
bool mpm_implicit_fbar_particle(const mpm_implicit *im, long p,
                                const fbar_point *fp, double Jbar, double S,
                                double V, double dJbar, double dS, bool with_d,
                                double T[9], double dT[9], double *s_out,
                                double *ds_out) {
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
      ok = mpm_implicit_fbar_particle(im, p, &fp, Jbar, 0, V, dJbar, 0,
                                      du != NULL, NULL, NULL, &s,
                                      du ? &ds : NULL);
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
      mpm_implicit_fbar_particle(im, p, &fp, Jbar, S, V, dJbar, dS, du != NULL,
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
bool mpm_implicit_nodal_force(mpm_implicit *im, const double *u, double *f) {
  const mpm_model *m = im->m;
  const double lam = im->lam0 + im->lam_local * (im->lam1 - im->lam0);
  if (im->fbar) {
    const bool ok = fbar_force(im, u, NULL, f);
    mpm_tractions_nodal(m, &im->g, im->xb, u, lam, f);
    return ok;
  }
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
  mpm_tractions_nodal(m, &im->g, im->xb, u, lam, f);
  return im->fail_p < 0;
}

/* u from the unknowns x and the prescribed values at the local load. */
void mpm_implicit_fill_u(mpm_implicit *im, const double *x) {
  memset(im->u, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  for (long k = 0; k < im->nheld; k++) im->u[im->unk_dof[k]] = x[k];
  for (long k = 0; k < im->npre; k++) {
    const long an = im->pre_anchor[k];
    im->u[im->pre_dof[k]] = im->lam_local * im->pre_val[k] +
                            (an >= 0 ? im->pre_t[k] * im->u[an] : 0.0);
  }
}

void mpm_implicit_fill_du(mpm_implicit *im, const double *dx) {
  memset(im->du, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  for (long k = 0; k < im->nheld; k++) im->du[im->unk_dof[k]] = dx[k];
  for (long k = 0; k < im->npre; k++)
    if (im->pre_anchor[k] >= 0)
      im->du[im->pre_dof[k]] = im->pre_t[k] * im->du[im->pre_anchor[k]];
}

void mpm_implicit_fold(const mpm_implicit *im, const double *f, double *r) {
  for (long k = 0; k < im->nheld; k++) r[k] = f[im->unk_dof[k]];
  for (long k = 0; k < im->npre; k++)
    if (im->pre_anchor[k] >= 0)
      r[im->dof[im->pre_anchor[k]]] += im->pre_t[k] * f[im->pre_dof[k]];
}

/* ---- the problem's callbacks --------------------------------------------- */

pm_err mpm_implicit_cb_residual(void *ctx, const double *x, double *r) {
  mpm_implicit *im = ctx;
  /* a signal stops the solve here too (Newton's tests poll it between) */
  PM_CALL(pm_interrupt_check("in a residual evaluation"));
  mpm_implicit_fill_u(im, x);
  if (!mpm_implicit_nodal_force(im, im->u, im->f))
    return PM_ERROR(PM_ERR_UNSTABLE, "%s", im->fail_msg);
  mpm_implicit_fold(im, im->f, r);
  return PM_SUCCESS;
}

pm_err mpm_implicit_cb_set_load(void *ctx, double lambda) {
  ((mpm_implicit *)ctx)->lam_local = lambda;
  return PM_SUCCESS;
}

/* df += the pressures' load stiffness times du (the matrix-free product:
 * every entry, none left out). */
typedef struct {
  const double *du;
  double *df;
} pressure_product;

static void pressure_entry(void *ctx, long row, long col, double v) {
  pressure_product *pp = ctx;
  pp->df[row] += v * pp->du[col];
}

static void pressure_apply(const mpm_implicit *im, const double *du,
                           double *df) {
  const double lam = im->lam0 + im->lam_local * (im->lam1 - im->lam0);
  pressure_product pp = {du, df};
  mpm_pressures_tangent(im->m, &im->g, im->xb, im->u, lam, pressure_entry, &pp);
}

/* dr = K dx: the directional derivative of the nodal force. */
pm_err mpm_implicit_cb_apply(void *ctx, const double *x, const double *dx,
                             double *dr) {
  mpm_implicit *im = ctx;
  const mpm_model *m = im->m;
  mpm_implicit_fill_u(im, x);
  mpm_implicit_fill_du(im, dx);
  if (im->fbar) {
    if (!fbar_force(im, im->u, im->du, im->df))
      return PM_ERROR(PM_ERR_INTERNAL, "%s", im->fail_msg);
    pressure_apply(im, im->du, im->df);
    mpm_implicit_fold(im, im->df, dr);
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
  pressure_apply(im, du, df);
  mpm_implicit_fold(im, df, dr);
  return PM_SUCCESS;
}
