/* fpm_linear_impl.h: the storage of FPM's linearised force (fpm_linear),
 * shared by its lifecycle (fpm_linear.c) and its passes (fpm_force.c). */
#ifndef FPM_LINEAR_IMPL_H
#define FPM_LINEAR_IMPL_H

#include "fpm_model.h"
#include "fpm_volumetric.h"

struct fpm_linear {
  double *D;               /* 81 n: dP/dF at each point, row-major (9 x 9) */
  double *dH, *dP, *theta; /* 9 n, 9 n, 27 n (NULL with the linear jump) */
  double *T, *r, *zq, *Zq; /* 9 n, 3 n, 3 n, 27 n */
  double *bu, *bH;         /* 3 n, 9 n: the state linearised about */
  fpm_volumetric_lin vol;  /* fpm.volumetric: averaged (else NULLs) */
  double *btheta;          /* 27 n: its fits (quadratic stiffening only) */
  double *vphi, *vdphi;    /* n, n: fpm.volume_penalty's phi there, dphi */
  double *tf_p; /* n_tfacets: the pressures there (NULL: no pressure) */
};

#endif
