/* fpm_linear: the storage of FPM's linearised force: create, free, its
 * size for the memory estimate, and read access for the static tangent. */
#include <stdbool.h>
#include <stdlib.h>

#include "fpm_linear_impl.h"
#include "pm_error.h"

pm_err fpm_linear_create(const fpm_model *m, fpm_linear **out) {
  pm_err ret = PM_SUCCESS;
  fpm_linear *l = NULL;
  const long n = m->n;
  *out = NULL;
  PM_TRY(PM_ALLOC(l, 1, "FPM linearisation"));
  PM_TRY(PM_ALLOC(l->D, 81 * n, "tangent moduli"));
  PM_TRY(PM_ALLOC(l->dH, 9 * n, "gradient increments"));
  PM_TRY(PM_ALLOC(l->dP, 9 * n, "stress increments"));
  PM_TRY(PM_ALLOC(l->T, 9 * n, "flux tensor increments"));
  PM_TRY(PM_ALLOC(l->r, 3 * n, "interface force increments"));
  PM_TRY(PM_ALLOC(l->bu, 3 * n, "linearisation point"));
  PM_TRY(PM_ALLOC(l->bH, 9 * n, "linearisation point"));
  if (m->q) {
    PM_TRY(PM_ALLOC(l->theta, 27 * n, "fit increments"));
    PM_TRY(PM_ALLOC(l->zq, 3 * n, "penalty force increments"));
    PM_TRY(PM_ALLOC(l->Zq, 27 * n, "penalty fit force increments"));
    if (m->stiffen_quadratic && m->stiffening > 0)
      PM_TRY(PM_ALLOC(l->btheta, 27 * n, "linearisation point's fits"));
  }
  if (m->volume_penalty > 0) {
    PM_TRY(PM_ALLOC(l->vphi, n, "volume penalty"));
    PM_TRY(PM_ALLOC(l->vdphi, n, "volume penalty increments"));
  }
  if (m->vavg) PM_TRY(fpm_volumetric_lin_create(m, &l->vol));
  for (int b = 0; b < m->scene->n_bcs; b++)
    if (m->scene->bcs[b].pressure && !l->tf_p)
      PM_TRY(PM_ALLOC(l->tf_p, m->n_tfacets + 1, "pressures"));
  *out = l;
  l = NULL;
done:
  fpm_linear_destroy(l);
  return ret;
}

void fpm_linear_destroy(fpm_linear *l) {
  if (!l) return;
  free(l->D);
  free(l->dH);
  free(l->dP);
  free(l->theta);
  free(l->T);
  free(l->r);
  free(l->zq);
  free(l->Zq);
  free(l->bu);
  free(l->bH);
  fpm_volumetric_lin_free(&l->vol);
  free(l->btheta);
  free(l->vphi);
  free(l->vdphi);
  free(l->tf_p);
  free(l);
}

size_t fpm_linear_bytes(const fpm_model *m) {
  const bool bth = m->q && m->stiffen_quadratic && m->stiffening > 0;
  return (size_t)m->n *
             (81 + 9 + 9 + 9 + 3 + 12 + (m->q ? 57 : 0) + (bth ? 27 : 0) +
              (m->volume_penalty > 0 ? 2 : 0)) *
             sizeof(double) +
         (size_t)m->n_tfacets * sizeof(double) + fpm_volumetric_lin_bytes(m);
}

const double *fpm_linear_tangent(const fpm_linear *l) { return l->D; }

void fpm_linear_base(const fpm_linear *l, const double **u,
                     const double **theta) {
  *u = l->bu;
  *theta = l->btheta;
}

const fpm_volumetric_lin *fpm_linear_volumetric(const fpm_linear *l) {
  return &l->vol;
}
