/* pm_rigid: the geometry and motion of a rigid plate or sphere (a
 * boundary: entry with plate: or sphere:), shared by the backends'
 * contact. */
#ifndef PM_RIGID_H
#define PM_RIGID_H

#include "pm_scene.h"

/* Signed distance of x (3) from rigid body bc displaced by d (3), > 0 on
 * the deformable body's side, < 0 inside the rigid body, and the unit
 * normal there into n (3; out of the rigid body).  bc must be a plate or
 * a sphere (PM_BC_RIGID). */
double pm_rigid_gap(const pm_scene_bc *bc, const double d[3], const double x[3],
                    double n[3]);

/* The rigid body's displacement at time t: ramp(t) displacement(t) into
 * d (3; components not given are 0). */
void pm_rigid_displacement(const pm_scene_bc *bc, double t, double d[3]);

/* Fail (PM_ERR_SCENE) at the key of rigid body i of s
 * (boundary.<i>.plate or .sphere, file:line:col) with "contact needs
 * <needs>, got a rigid plate|sphere with <got>". */
pm_err pm_rigid_refuse(const pm_scene *s, int i, const char *needs,
                       const char *got);

#endif
