/* fpm_grade: the graded cloud a scene asks for (discretization.refine), with
 * the ratio form resolved against mesh_size as the point budget. */
#ifndef FPM_GRADE_H
#define FPM_GRADE_H

#include "gm_mesh.h"
#include "pm_scene.h"

/* The grading of s's box mesh into *g and the size far from the graded faces
 * into *far (m).  Ungraded (no refine, or size_ratio 1): g->faces 0 and *far
 * mesh_size.  refine.size given: *far is mesh_size, as the key says.
 * refine.size_ratio r given: *far = k mesh_size with k^dim the mean of
 * (far / size(x))^dim over the box, so that the graded cloud has about the
 * uniform cloud's points at mesh_size, and g->size = r *far.  No errors (the
 * scene loader checked the keys). */
void fpm_grade_of(const pm_scene *s, gm_grade *g, double *far);

/* The mean of (h / size(x))^dim over a 48^dim lattice of s's box, size(x)
 * from g and h (gm_grade_size): the points of the graded mesh over those of
 * the uniform one at h (1 for g->faces 0). */
double fpm_grade_density(const pm_scene *s, const gm_grade *g, double h);

#endif
