/* pm_rigid: signed distance and motion of a rigid plate or sphere. */
#include "pm_rigid.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pm_expr.h"

double pm_rigid_gap(const pm_scene_bc *bc, const double d[3], const double x[3],
                    double n[3]) {
  double r[3];
  for (int a = 0; a < 3; a++) r[a] = x[a] - d[a] - bc->rigid_point[a];
  if (bc->on == PM_ON_PLATE) {
    memcpy(n, bc->rigid_normal, 3 * sizeof(double));
    return r[0] * n[0] + r[1] * n[1] + r[2] * n[2];
  }
  double len = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  for (int a = 0; a < 3; a++) n[a] = len > 0 ? r[a] / len : (a == 2);
  return len - bc->rigid_radius;
}

void pm_rigid_displacement(const pm_scene_bc *bc, double t, double d[3]) {
  const double r = pm_bc_factor(bc, t);
  for (int a = 0; a < 3; a++)
    d[a] = bc->disp[a] ? r * pm_expr_eval(bc->disp[a], 0, 0, 0, t) : 0;
}

pm_err pm_rigid_refuse(const pm_scene *s, int i, const char *needs,
                       const char *got) {
  const char *kind = s->bcs[i].on == PM_ON_PLATE ? "plate" : "sphere";
  char p[64];
  snprintf(p, sizeof p, "boundary.%d.%s", i, kind);
  return pm_scene_fail(s, p, true, "contact needs %s, got a rigid %s with %s",
                       needs, kind, got);
}
