/* fpm_share_testing: every array of an FPM share, by name, for the tests
 * that hold two shares equal bit for bit (test_fpm_region on one process,
 * ranks_fpm_setup across ranks). */
#ifndef FPM_SHARE_TESTING_H
#define FPM_SHARE_TESTING_H

#include <stddef.h>

#include "fpm_gfd.h"
#include "fpm_model.h"
#include "fpm_stream.h"

typedef struct {
  const char *name;
  const void *data; /* NULL: not held */
  size_t bytes;
} fpm_share_array;

#define FPM_SHARE_ARRAYS 42

/* The arrays of share m into a[FPM_SHARE_ARRAYS]; their count. */
static inline int fpm_share_arrays(const fpm_model *m, fpm_share_array *a) {
  const long n = m->n, nnz = m->nnz, blocks = m->fs_ptr[m->n_stress];
  const long nd = m->n_dpts, nt = m->n_tfacets, nc = m->n_cdofs;
  const long nq = m->qs_ptr ? m->qs_ptr[n] : 0,
             nqt = m->qt_ptr ? m->qt_ptr[n] : 0;
  int k = 0;
#define ARRAY(field, count)                                                    \
  a[k++] =                                                                     \
      (fpm_share_array){#field, m->field, (size_t)(count) * sizeof *m->field}
  ARRAY(gid, n);
  ARRAY(x, 3 * n);
  ARRAY(nbr_ptr, n + 1);
  ARRAY(nbr, nnz);
  ARRAY(g, 3 * nnz);
  ARRAY(gsum, 3 * n);
  ARRAY(mirror, nnz);
  ARRAY(cond, n);
  ARRAY(erec, FPM_EREC * nnz);
  ARRAY(p_area, 3 * n);
  ARRAY(p_mrel, 9 * n);
  ARRAY(fs_ptr, m->n_stress + 1);
  ARRAY(fs_nbr, FPM_LANES * blocks);
  ARRAY(fs_g, 3 * FPM_LANES * blocks);
  ARRAY(fs_gm, 3 * FPM_LANES * blocks);
  ARRAY(fs_rec, m->fs_rec ? 19 * FPM_LANES * blocks : 0);
  ARRAY(mat, n);
  ARRAY(mass, n);
  ARRAY(fixed, 3 * n);
  ARRAY(vavg, nnz);
  ARRAY(vself, n);
  ARRAY(qs_ptr, n + 1);
  ARRAY(qs_nbr, nq);
  ARRAY(qs_own, nq);
  ARRAY(q, FPM_QFIT * nq);
  ARRAY(qsum, FPM_QFIT * n);
  ARRAY(qt_ptr, n + 1);
  ARRAY(qt_entry, nqt);
  /* The boundary: the flux points, the traction facets and the prescribed
   * dofs. */
  ARRAY(dpt_point, nd);
  ARRAY(dpt_area, 9 * nd);
  ARRAY(dpt_mrel, 27 * nd);
  ARRAY(tf_point, nt);
  ARRAY(tf_gid, nt);
  ARRAY(tf_bc, nt);
  ARRAY(tf_area, nt);
  ARRAY(tf_rel, 3 * nt);
  ARRAY(tf_centroid, 3 * nt);
  ARRAY(tf_base, 3 * nt);
  ARRAY(cd_point, nc);
  ARRAY(cd_comp, nc);
  ARRAY(cd_bc, nc);
  ARRAY(cd_base, nc);
#undef ARRAY
  return k;
}

#endif
