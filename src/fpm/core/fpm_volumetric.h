/* fpm_volumetric: fpm.volumetric: averaged, the averaged-volume (F-bar kind)
 * treatment of J: the energy sum_i V_i [W_iso(F_i) + U(Jbar_i)] with Jbar
 * averaged over each point's support, its stress and its linearisation. */
#ifndef FPM_VOLUMETRIC_H
#define FPM_VOLUMETRIC_H

#include "fpm_model.h"

/* The averaging weights of model m (m->vavg, m->vself): over the closed
 * support S(i) + i,
 *   a_ik = V_k / max(Vs_i, Vs_k)  (k in S(i)),  a_ii = 1 - sum_k a_ik,
 * with Vs_i the volume of i's closed support.  V_i a_ik = V_k a_ki, so
 * Jbar = A J and the adjoint average pt = A U'(Jbar) are both averages
 * (rows summing to 1, a_ii > V_i / Vs_i): a uniform J gives Jbar = J and
 * pt = U'(J) at every point.  Every material must have the volumetric
 * split (fpm_check_scene refuses the others at the key).  PM_ERR_MEMORY;
 * PM_ERR_ARG for a model without the split. */
pm_err fpm_volumetric_build(fpm_model *m);

/* After the stress pass (st->H, P, W, J of the points [0, m->n_stress),
 * the own ones admissible): Jbar_i = sum_k a_ik J_k and U'(Jbar_i) into
 * st->Jbar and st->dUbar and W_i += U(Jbar_i) - U(J_i) for the own points
 * [0, m->n_own), U'(Jbar) of the ghosts from their owners, then
 * P_k += (pt_k - U'(J_k)) cof F_k with pt = A U'(Jbar) on [0, n_stress).
 * Then sum_i V_i W_i is the energy above and V_k P_k its derivative with
 * respect to F_k along the GFD gradient.  Across ranks it is collective
 * (the ghosts' exchange): a rank whose own points are not admissible calls
 * fpm_volumetric_stress_skipped instead.  Allocates nothing. */
void fpm_volumetric_stress(const fpm_model *m, fpm_state *st);
void fpm_volumetric_stress_skipped(const fpm_model *m, fpm_state *st);

/* The linearisation's arrays (fpm_force_linear): cof F_k (9 n), U''(J_k)
 * and U''(Jbar_k) (n each), and work for dJ and U''(Jbar) dJbar (n each). */
typedef struct {
  double *cof, *d2, *d2bar, *dJ, *dq;
} fpm_volumetric_lin;

/* The arrays of the last fpm_linear_prepare (fpm.volumetric averaged;
 * else NULLs), owned by l. */
const fpm_volumetric_lin *fpm_linear_volumetric(const fpm_linear *l);

/* Make (zeroed, released by fpm_volumetric_lin_free) or release them.
 * PM_ERR_MEMORY. */
pm_err fpm_volumetric_lin_create(const fpm_model *m, fpm_volumetric_lin *v);
void fpm_volumetric_lin_free(fpm_volumetric_lin *v);
size_t fpm_volumetric_lin_bytes(const fpm_model *m);

/* About st (whose fpm_force was just computed): adds to the point
 * tangents D (81 per point, dP/dF row-major) the local part
 * (pt_k - U'(J_k)) d cof F_k / dF, and keeps what fpm_volumetric_apply
 * needs.  D alone is then the tangent without the averages' coupling
 * (the static solve's assembled preconditioner). */
void fpm_volumetric_prepare(const fpm_model *m, const fpm_state *st,
                            fpm_volumetric_lin *v, double *D);

/* The coupling: dP_k += (A (U''(Jbar) A dJ)_k - U''(J_k) dJ_k) cof F_k
 * with dJ_k = cof F_k : dH_k, for the points [0, m->n_stress); the inner
 * product U''(Jbar) A dJ of the own points, the ghosts' from their owners
 * (collective across ranks). */
void fpm_volumetric_apply(const fpm_model *m, fpm_volumetric_lin *v,
                          const double *dH, double *dP);

#endif
