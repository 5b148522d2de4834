/* fpm_grade: the graded cloud a scene asks for (discretization.refine), with
 * the ratio form resolved against mesh_size as the point budget. */
#include "fpm_grade.h"

#include <math.h>

double fpm_grade_density(const pm_scene *s, const gm_grade *g, double h) {
  if (!g->faces) return 1.0;
  enum { N = 48 };
  const int dim = s->dimension;
  double sum = 0.0;
  long count = 0;
  for (int i = 0; i < N; i++)
    for (int j = 0; j < N; j++)
      for (int k = 0; k < (dim == 3 ? N : 1); k++) {
        const int ijk[3] = {i, j, k};
        double x[3] = {0, 0, 0};
        for (int c = 0; c < dim; c++)
          x[c] = s->box_min[c] +
                 (ijk[c] + 0.5) / N * (s->box_max[c] - s->box_min[c]);
        const double r =
            h / gm_grade_size(g, dim, s->box_min, s->box_max, h, x);
        sum += dim == 3 ? r * r * r : r * r;
        count++;
      }
  return sum / (double)count;
}

void fpm_grade_of(const pm_scene *s, gm_grade *g, double *far) {
  *g = (gm_grade){.faces = s->refine.near,
                  .size = s->refine.size,
                  .distance = s->refine.distance,
                  .edges = s->refine.to == PM_REFINE_EDGES};
  *far = s->mesh_size;
  const double r = s->refine.size_ratio;
  if (!g->faces || r <= 0.0) return;
  if (r >= 1.0) {
    g->faces = 0;
    return;
  }
  /* The density of the grading relative to its far size is the same at
   * every far size (the distance is in metres): solve for it at far = 1. */
  g->size = r;
  *far = s->mesh_size * pow(fpm_grade_density(s, g, 1.0), 1.0 / s->dimension);
  g->size = r * *far;
}
