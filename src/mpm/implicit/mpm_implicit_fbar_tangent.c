/* mpm_implicit_fbar_tangent: the assembled tangent of F-bar (mpm.fbar:
 * cell) bucket by bucket: each particle's own block plus two products of
 * vectors through the bucket's sums Jbar and S. */
#include <math.h>
#include <string.h>

#include "mpm_implicit_impl.h"
#include "pm_omp.h"
#include "pm_tensor.h"

/* v += the nodal form of the 9-tensor X of particle p over its stencil:
 * v[3a + i] = sum_J (X F_b^T)_iJ grad S_a,J (the force of a stress X; the
 * linear form X : dF on the nodal directions). */
static void add_nodal(const mpm_implicit *im, long p, const mpm_stencil *st,
                      const double X[9], double *v) {
  double Q[9];
  to_base(base_F(im, p), X, Q);
  for (int a = 0; a < st->n; a++) {
    const double *g = st->grad[a];
    for (int i = 0; i < 3; i++)
      v[3 * a + i] +=
          Q[3 * i] * g[0] + Q[3 * i + 1] * g[1] + Q[3 * i + 2] * g[2];
  }
}

/* The derivative of particle p's T_q is linear in its dF, the bucket's
 * dJbar and dS:  dT_q = L_q dF_q + m_q dJbar + n_q dS,  and ds_q = l_q .
 * dF_q + mu_q dJbar; with dJbar = sum_p j_p . dF_p (j_p = w_p J_p G_p)
 * and dS = sum_p l_p . dF_p + M dJbar (M = sum mu_p), the bucket's block
 * is
 *   sum_q B_q^T L_q B_q + (A_m + M A_n) A_j^T + A_n A_l^T,
 * A_x = sum_q B_q^T x_q, B_q: nodal directions to dF_q.  L_q, m_q, n_q,
 * l_q and mu_q come from mpm_implicit_fbar_particle along the unit
 * directions (eleven calls), which keeps one formula for the residual, its
 * product and this assembly.  False on a failed particle. */
static bool bucket_block(const mpm_implicit *im, long q0, long q1, double Jbar,
                         double S, double V, double *K, mpm_stencil *st) {
  double Am[3 * MPM_STENCIL_MAX] = {0}, An[3 * MPM_STENCIL_MAX] = {0},
                Aj[3 * MPM_STENCIL_MAX] = {0}, Al[3 * MPM_STENCIL_MAX] = {0};
  double M = 0;
  int n3 = 0;
  for (long q = q0; q < q1; q++) {
    const long p = im->order[q];
    mpm_stencil_at(&im->g, im->xb + 3 * p, MPM_STENCIL_GRAD, st);
    n3 = 3 * st->n;
    fbar_point fp;
    fbar_point_at(im, p, st, im->u, NULL, &fp);
    double L[81], mq[9], nq[9], lq[9], mu, col[9], Lb[81];
    for (int kl = 0; kl < 9; kl++) {
      memset(fp.dF, 0, sizeof fp.dF);
      fp.dF[kl] = 1;
      fp.dJ = fp.J * fp.G[kl];
      if (!mpm_implicit_fbar_particle(im, p, &fp, Jbar, S, V, 0, 0, true, NULL,
                                      col, NULL, &lq[kl]))
        return false;
      for (int iK = 0; iK < 9; iK++) L[9 * iK + kl] = col[iK];
    }
    memset(fp.dF, 0, sizeof fp.dF);
    fp.dJ = 0;
    if (!mpm_implicit_fbar_particle(im, p, &fp, Jbar, S, V, 1, 0, true, NULL,
                                    mq, NULL, &mu) ||
        !mpm_implicit_fbar_particle(im, p, &fp, Jbar, S, V, 0, 1, true, NULL,
                                    nq, NULL, NULL))
      return false;
    M += mu;
    double jq[9];
    const double w = im->m->vol0[p] / V;
    for (int k = 0; k < 9; k++) jq[k] = w * fp.J * fp.G[k];
    add_nodal(im, p, st, mq, Am);
    add_nodal(im, p, st, nq, An);
    add_nodal(im, p, st, jq, Aj);
    add_nodal(im, p, st, lq, Al);
    /* the particle's own block: grad_a . Lb . grad_b */
    mpm_implicit_tangent_to_base(im, p, L, Lb);
    for (int a = 0; a < st->n; a++)
      for (int i = 0; i < 3; i++) {
        double r[9]; /* r[kM] = sum_J g_a,J Lb[iJkM] */
        for (int kM = 0; kM < 9; kM++)
          r[kM] = st->grad[a][0] * Lb[9 * (3 * i) + kM] +
                  st->grad[a][1] * Lb[9 * (3 * i + 1) + kM] +
                  st->grad[a][2] * Lb[9 * (3 * i + 2) + kM];
        double *Ka = K + (long)(3 * a + i) * n3;
        for (int b = 0; b < st->n; b++) {
          const double *g = st->grad[b];
          for (int k = 0; k < 3; k++)
            Ka[3 * b + k] +=
                r[3 * k] * g[0] + r[3 * k + 1] * g[1] + r[3 * k + 2] * g[2];
        }
      }
  }
  for (int r = 0; r < n3; r++) {
    const double u = Am[r] + M * An[r];
    for (int c = 0; c < n3; c++) K[r * n3 + c] += u * Aj[c] + An[r] * Al[c];
  }
  return true;
}

pm_err mpm_implicit_fbar_values(mpm_implicit *im, double *val) {
  im->fail_p = -1;
  bool outside = false;
  FOR_BUCKETS(im, {
    double Jbar, V, S = 0;
    fbar_bucket_J(im, q0, q1, im->u, NULL, &Jbar, &V, NULL);
    bool ok = Jbar > 0;
    for (long q = q0; q < q1 && ok; q++) {
      const long p = im->order[q];
      mpm_stencil st;
      mpm_stencil_at(&im->g, im->xb + 3 * p, MPM_STENCIL_GRAD, &st);
      fbar_point fp;
      fbar_point_at(im, p, &st, im->u, NULL, &fp);
      double s;
      ok = mpm_implicit_fbar_particle(im, p, &fp, Jbar, 0, V, 0, 0, false, NULL,
                                      NULL, &s, NULL);
      S += s;
    }
    double K[9 * MPM_STENCIL_MAX * MPM_STENCIL_MAX];
    mpm_stencil st;
    if (ok) {
      memset(K, 0, sizeof K);
      ok = bucket_block(im, q0, q1, Jbar, S, V, K, &st);
    }
    if (!ok) {
      note_failure(im, im->order[q0], "F-bar: no tangent (J or Jbar <= 0)",
                   Jbar);
      continue;
    }
    mpm_implicit_scatter_block(im, &st, K, val, &outside);
  })
  return mpm_implicit_values_status(im, outside);
}
