/* fpm_volumetric: the averaged-volume treatment of J (fpm.volumetric:
 * averaged): the averaging weights, the stress's two extra gathers and
 * their linearisation.  No scatter, no atomics, no allocation per step. */
#include "fpm_volumetric.h"

#include <stdlib.h>
#include <string.h>

#include "pm_material.h"
#include "pm_omp.h"
#include "pm_tensor.h"

/* sum_k a_ik (x_k - shift) over i's closed support. */
static inline double average(const fpm_model *m, long i, const double *x,
                             double shift) {
  double s = m->vself[i] * (x[i] - shift);
  for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++)
    s += m->vavg[e] * (x[m->nbr[e]] - shift);
  return s;
}

pm_err fpm_volumetric_build(fpm_model *m) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n;
  const double *vol = m->dual->volume;
  double *vs = NULL;
  for (int k = 0; k < m->n_mats; k++)
    PM_ENSURE(pm_material_has_volumetric(&m->mats[k]), PM_ERR_ARG,
              "fpm.volumetric averaged needs a model split as W_iso + U(J), "
              "got %s",
              m->mats[k].model->name);
  PM_TRY(PM_ALLOC(vs, n, "support volumes"));
  PM_TRY(PM_ALLOC(m->vavg, m->nnz > 0 ? m->nnz : 1, "averaging weights"));
  PM_TRY(PM_ALLOC(m->vself, n, "averaging weights"));
  for (long i = 0; i < n; i++) {
    vs[i] = vol[i];
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++)
      vs[i] += vol[m->nbr[e]];
  }
  for (long i = 0; i < n; i++) {
    double off = 0;
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
      const long k = m->nbr[e];
      m->vavg[e] = vol[k] / (vs[i] > vs[k] ? vs[i] : vs[k]);
      off += m->vavg[e];
    }
    m->vself[i] = 1 - off;
  }
done:
  free(vs);
  return ret;
}

/* Across ranks (a share, fpm_model.n_own) Jbar_i = sum_k a_ik J_k of an
 * own point reads J over its support, which the share's stress holds;
 * pt_k of a point whose stress the share computes reads U'(Jbar) over its
 * support, up to the displacement ghosts: so Jbar and U'(Jbar) are the
 * own points', and the ghosts' U'(Jbar) come from their owners (the same
 * operations in the same order: one process's values). */
void fpm_volumetric_stress(const fpm_model *m, fpm_state *st) {
  const long n = m->n_stress, n_own = m->n_own;
  const double *restrict J = st->J, *restrict H = st->H;
  double *restrict Jb = st->Jbar, *restrict dUb = st->dUbar,
                   *restrict W = st->W, *restrict P = st->P;
  const int *restrict mat = m->mat;
  const pm_material *mats = m->mats;
  PM_OMP(parallel for schedule(static) default(none)
         shared(n_own, m, J, Jb, dUb, W, mat, mats))
  for (long i = 0; i < n_own; i++) {
    double ub[3], uj[3];
    const double jb = 1 + average(m, i, J, 1);
    pm_material_volumetric(&mats[mat[i]], jb, ub);
    pm_material_volumetric(&mats[mat[i]], J[i], uj);
    Jb[i] = jb;
    dUb[i] = ub[1];
    W[i] += ub[0] - uj[0];
  }
  fpm_exchange_ghost_scalars(m->xc, dUb);
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, m, J, H, dUb, P, mat, mats))
  for (long k = 0; k < n; k++) {
    double uj[3], F[9], cof[9];
    pm_material_volumetric(&mats[mat[k]], J[k], uj);
    const double q = average(m, k, dUb, 0) - uj[1];
    fpm_deformation(H + 9 * k, F);
    pm_t_cofactor(F, cof);
    for (int a = 0; a < 9; a++) P[9 * k + a] += q * cof[a];
  }
}

void fpm_volumetric_stress_skipped(const fpm_model *m, fpm_state *st) {
  fpm_exchange_ghost_scalars(m->xc, st->dUbar);
}

pm_err fpm_volumetric_lin_create(const fpm_model *m, fpm_volumetric_lin *v) {
  const long n = m->n;
  memset(v, 0, sizeof *v);
  PM_CALL(PM_ALLOC(v->cof, 9 * n, "cofactors"));
  PM_CALL(PM_ALLOC(v->d2, n, "volumetric moduli"));
  PM_CALL(PM_ALLOC(v->d2bar, n, "averaged volumetric moduli"));
  PM_CALL(PM_ALLOC(v->dJ, n, "volume increments"));
  PM_CALL(PM_ALLOC(v->dq, n, "pressure increments"));
  return PM_SUCCESS;
}

void fpm_volumetric_lin_free(fpm_volumetric_lin *v) {
  free(v->cof);
  free(v->d2);
  free(v->d2bar);
  free(v->dJ);
  free(v->dq);
  memset(v, 0, sizeof *v);
}

size_t fpm_volumetric_lin_bytes(const fpm_model *m) {
  return m->vavg ? (size_t)m->n * 13 * sizeof(double) : 0;
}

void fpm_volumetric_prepare(const fpm_model *m, const fpm_state *st,
                            fpm_volumetric_lin *v, double *D) {
  const long n = m->n_stress;
  const double *restrict J = st->J, *restrict H = st->H,
                         *restrict Jb = st->Jbar, *restrict dUb = st->dUbar;
  double *restrict cof = v->cof, *restrict d2 = v->d2, *restrict d2b = v->d2bar;
  const int *restrict mat = m->mat;
  const pm_material *mats = m->mats;
  const long n_own = m->n_own; /* (Jbar: the own points') */
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, n_own, m, J, H, Jb, dUb, cof, d2, d2b, D, mat, mats))
  for (long k = 0; k < n; k++) {
    double uj[3], ub[3], F[9];
    double *c = cof + 9 * k;
    pm_material_volumetric(&mats[mat[k]], J[k], uj);
    d2[k] = uj[2];
    if (k < n_own) {
      pm_material_volumetric(&mats[mat[k]], Jb[k], ub);
      d2b[k] = ub[2];
    }
    fpm_deformation(H + 9 * k, F);
    pm_t_cofactor(F, c);
    /* (pt - U'(J)) d cof[E_b] with d cof[dF] = (dJ cof - cof dF^T cof) / J,
     * dJ = cof : dF; E_b = e_r (x) e_s, b = 3 r + s */
    const double q = (average(m, k, dUb, 0) - uj[1]) / J[k];
    if (q == 0) continue;
    for (int a = 0; a < 9; a++) {
      const int i = a / 3, j = a % 3;
      for (int b = 0; b < 9; b++) {
        const int r = b / 3, s = b % 3;
        D[81 * k + 9 * a + b] +=
            q * (c[b] * c[a] - c[3 * i + s] * c[3 * r + j]);
      }
    }
  }
}

void fpm_volumetric_apply(const fpm_model *m, fpm_volumetric_lin *v,
                          const double *dH, double *dP) {
  const long n = m->n_stress;
  const double *restrict cof = v->cof, *restrict d2 = v->d2,
                         *restrict d2b = v->d2bar;
  double *restrict dJ = v->dJ, *restrict dq = v->dq;
  PM_OMP(parallel for schedule(static) default(none) shared(n, cof, dH, dJ))
  for (long k = 0; k < n; k++) {
    double s = 0;
    for (int a = 0; a < 9; a++) s += cof[9 * k + a] * dH[9 * k + a];
    dJ[k] = s;
  }
  /* (as the stress: the own points' dq, the ghosts' from their owners) */
  const long n_own = m->n_own;
  PM_OMP(parallel for schedule(static) default(none)
         shared(n_own, m, d2b, dJ, dq))
  for (long i = 0; i < n_own; i++) dq[i] = d2b[i] * average(m, i, dJ, 0);
  fpm_exchange_ghost_scalars(m->xc, dq);
  PM_OMP(parallel for schedule(static) default(none)
         shared(n, m, cof, d2, dJ, dq, dP))
  for (long k = 0; k < n; k++) {
    const double s = average(m, k, dq, 0) - d2[k] * dJ[k];
    for (int a = 0; a < 9; a++) dP[9 * k + a] += s * cof[9 * k + a];
  }
}
