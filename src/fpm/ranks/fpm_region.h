/* fpm_region: a rank's share of an FPM model made without the whole model.
 * Every rank holds the whole mesh and its cells (the cheap geometry: the
 * points, their supports and the interfaces' and facets' shapes); the
 * operators (GFD weights, interface records, quadratic fits, averaging
 * weights, boundary flux) are computed on the rank's own points and the
 * rings around them only: a part of the cells, its points in one-process
 * order, whose model (fpm_model_create_part) is the whole model's on every
 * point the share holds, and whose share (fpm_share_create) is then the
 * share cut from the whole model, bit for bit.
 *
 * The share holds its own points and 3 rings of support around them, 5
 * with the quadratic jump (fpm_share.h); the part holds one ring more with
 * its rows (the fits over two rings and the averaging weights of the
 * share's outer ring read them) and one more without (the neighbours of
 * those rows). */
#ifndef FPM_REGION_H
#define FPM_REGION_H

#include "fpm_model.h"
#include "gm_mesh.h"

/* Rank r's share of the model of scene s (fpm options o) on the whole
 * mesh's cells *whole, under partition owner (n_points ranks), without the
 * whole model: the model fpm_share_create makes of the whole model, bit
 * for bit.  Errors of the scene's conditions are the whole model's (a
 * condition that selects no facet of the whole).  With release, *whole is
 * destroyed (and NULL) once the part's cells are taken from it, before
 * the part's model is built, so that the two are never held together.
 * *out owns its arrays. */
pm_err fpm_share_build(const pm_scene *s, const fpm_options *o,
                       const gm_mesh *mesh, gm_dual **whole, bool release,
                       const int *owner, int r, fpm_model **out);

#endif
