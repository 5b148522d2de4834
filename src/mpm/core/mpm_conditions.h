/* mpm_conditions: boundary conditions on the grid.  A face condition sets
 * the nodes at and beyond its (moving) wall from an anchor inside it, moves
 * their forces onto the anchors, and counts its reaction and work; null
 * directions zero components everywhere (in the grid update).  A condition
 * on a region holds particles instead (a grip: mpm_grip.h); a traction
 * acts through the particles at a face (mpm_traction.h); a rigid plate or
 * sphere acts in the grid's contact (mpm_contact.h). */
#ifndef MPM_CONDITIONS_H
#define MPM_CONDITIONS_H

#include <stdbool.h>

#include "mpm_grid.h"
#include "mpm_stage.h"
#include "pm_scene.h"

/* A condition on a face, as grid columns normal to it: fixed after setup.
 * The expressions are the scene's (borrowed). */
typedef struct {
  pm_face face;
  int axis;
  double outward; /* -1 on a min face, +1 on a max face */
  double plane;   /* face coordinate */
  long n_cols;
  long *col; /* node index of each column on the face plane (owned) */
  unsigned disp_mask, vel_mask;
  const pm_expr *disp[3], *velocity[3]; /* NULL where not prescribed */
  pm_ramp ramp;
  double ramp_time;
  const pm_curve *curve; /* the scene's load curve (borrowed), NULL: 1 */
  bool absorbing;
  bool constant[3]; /* expression uses none of x, y, z */
  /* A grip (a condition on a region): the particles it holds (indices,
   * owned; found by mpm_grips_create), and no columns. */
  bool grip;
  const pm_expr *region;
  long n_held;
  long *held;
  /* A traction (nominal, Pa, at full load; NULL where not given), on a
   * face or on a named surface of a gmsh body: the particles that carry
   * it are held[0..n_held) (a particle may carry several points), each
   * point with its area and its reference offset from its particle (3 per
   * point; owned; found by mpm_tractions_create). */
  unsigned traction_mask;
  const pm_expr *traction[3];
  double *area, *offset;
  /* A follower pressure (Pa at full load; NULL if none) on the same
   * points: -p cof(F) N per unit reference area, N each point's outward
   * reference normal (3 per point; owned). */
  const pm_expr *pressure;
  double *normal;
  /* On a named surface, the pressure acts on each facet as it deforms:
   * the particle nearest each corner of a point's facet (3 per point; -1
   * for a facet that carries nothing), and the corner's reference offset
   * from it (9 per point), corners ordered so that their area vector
   * points out (owned; NULL on a face, where cof(F) N of the carrier
   * acts). */
  long *corner;
  double *coff;
  /* A rigid plate or sphere in the grid's contact (mpm_contact.h): the
   * scene's condition (borrowed; NULL for other conditions), and no
   * columns. */
  const pm_scene_bc *rigid;
} mpm_bc;

/* The factor of bc's values at time t: its load curve times its ramp (as
 * pm_bc_factor for the scene's condition). */
static inline double mpm_bc_factor(const mpm_bc *bc, double t) {
  return pm_curve_at(bc->curve, t) * pm_ramp_factor(bc->ramp, bc->ramp_time, t);
}

/* Whether condition bc loads its surface (a traction or a pressure). */
#define MPM_BC_LOADS(bc) ((bc)->traction_mask || (bc)->pressure)

/* What the conditions keep during a step: workspace. */
typedef struct {
  short *owner;      /* 3 per node: the condition that set the dof this step,
                        -(b + 1) prescribed, b + 1 reflected, 0 free */
  double *fold;      /* 3 per node: forces of the conditions' dependent dofs
                        moved onto the dofs they follow (their anchors) */
  double *fold_out;  /* 3 per node: the force a dependent dof moved out */
  double *reaction;  /* 3 per condition: its force on the body, N */
  double *grip_mass; /* per node: a grip's mass there (grips only) */
  double *grip_mom;  /* 3 per node: its prescribed momentum (grips only) */
  unsigned char *touched; /* per node: a rigid body's particles reach it
                             there (rigid bodies only) */
  /* The first prescribed value that was not finite: its expression (NULL
   * while none), the node of its column, the face position and the time
   * it was evaluated at. */
  const pm_expr *bad_expr;
  long bad_node;
  double bad_x[3], bad_t;
} mpm_cond_work;

/* Build the conditions of scene s on grid g into *bcs (n_bcs of them).
 * PM_ERR_MEMORY on failure; the caller releases with
 * mpm_conditions_destroy. */
pm_err mpm_conditions_create(const pm_scene *s, const mpm_grid *g, mpm_bc **bcs,
                             int *n_bcs);
/* Release conditions made by mpm_conditions_create (NULL accepted). */
void mpm_conditions_destroy(mpm_bc *bcs, int n_bcs);

/* Allocate the conditions' workspace for conditions bcs[0..n_bcs) on grid
 * g (none when n_bcs is 0; with grips their nodal sums too). */
pm_err mpm_cond_work_create(mpm_cond_work *cw, const mpm_grid *g,
                            const mpm_bc *bcs, int n_bcs);
/* Release the conditions' workspace (and zero it). */
void mpm_cond_work_destroy(mpm_cond_work *cw);
/* Bytes the conditions' workspace takes. */
size_t mpm_cond_work_bytes(const mpm_cond_work *cw, const mpm_grid *g);

/* Velocity condition bc prescribes on component c at reference position x
 * over the step from t to t + dt (the mean over the step of a prescribed
 * displacement's rate). */
double mpm_bc_velocity(const mpm_bc *bc, int c, const double x[3], double t,
                       double dt);

/* Move the forces of the dependent dofs onto their anchors (into the
 * work's fold), from the nodal forces of this step. */
void mpm_conditions_fold(const mpm_ctx *ctx);

/* Apply the conditions to the nodal velocities vel (3 per node) for the
 * step from the state's t to t + dt.  With reactions: record which
 * condition set each dof, the reactions (in the work), and return the
 * conditions' work over the step (J); else return 0. */
double mpm_conditions_apply(const mpm_ctx *ctx, double *vel, bool reactions);

/* PM_SUCCESS, or PM_ERR_UNSTABLE when a condition's expression gave a
 * value that is not finite in this step: "step N, t = T s: node I at (x):
 * KEY: "TEXT" = nan, not a finite value" (pm_expr_fail_value). */
pm_err mpm_conditions_status(const mpm_ctx *ctx);

/* Whether conditions bcs[0..n_bcs) hold still: no velocities, no rigid
 * bodies, and every prescribed displacement 0 at the corners and the
 * centre of the box [lo, hi] at t = 0 and t_end (fixed supports, which do
 * no work). */
bool mpm_supports_still(const mpm_bc *bcs, int n_bcs, const double lo[3],
                        const double hi[3], double t_end);

#endif
