/* fpm_contact: rigid plates and spheres (boundary: plate / sphere) pushing
 * an FPM body by penalty contact on its boundary points, with the reaction
 * and the work of each rigid body. */
#ifndef FPM_CONTACT_H
#define FPM_CONTACT_H

#include "fpm_model.h"

/* The contact candidates of a model: for each rigid body, every point
 * that has boundary facets, with its penalty stiffness. */
typedef struct fpm_contact {
  int n_bodies;
  int *bc;          /* n_bodies: the scene's condition of each */
  long *pair_ptr;   /* n_bodies + 1: body b's pairs are pair_ptr[b] .. [b+1] */
  long *pair_point; /* the point of each pair */
  double *pair_k;   /* its penalty stiffness kappa E A / h, N/m */
  double max_k_over_m; /* the largest k / m of a pair, 1/s^2 */
  double *anchor0;     /* 3 per pair: the anchors at rest (glued: the points
                          on the body at t = 0; NaN elsewhere) */
} fpm_contact;

/* Doubles of state a contact holds (fpm_state.contact): per pair the
 * sticking anchor (3, NaN while apart), per body the reaction, the
 * previous reaction and the previous displacement (3 each), and the
 * contact energy (1). */
long fpm_contact_state_size(const fpm_contact *c);
/* Make that state (*out, the caller's to free): at rest, apart but for
 * the points on a glued body, anchored where they are. */
pm_err fpm_contact_state_init(const fpm_contact *c, double **out);

/* Penalty contact of one point at position x (3) against one rigid body
 * displaced by d (3), with gap g (the signed distance, < 0 inside): the
 * force on the point F (3) and its energy.  Frictionless: F = -k g n.
 * Sticking: F = -k (x - d - anchor), anchor (3, in the body's frame) the
 * surface point where it touched, set on touching and NaN while apart.
 * Glued: as sticking, but an anchored point is never let go (pulled off
 * as well as pushed: a face tied to the body).  Returns whether the point
 * touches (g < 0, or glued and anchored). */
bool fpm_contact_point(const pm_scene_bc *bc, double k, const double d[3],
                       const double x[3], double anchor[3], double F[3],
                       double *energy);

/* The tangent of fpm_contact_point at x (after the call that set the
 * anchor): dF = -K dx, K (9, row-major) symmetric; 0 while apart. */
void fpm_contact_tangent(const pm_scene_bc *bc, double k, const double d[3],
                         const double x[3], const double anchor[3],
                         double K[9]);

/* The contact of the scene's rigid bodies on model m (m's points,
 * boundary facets, masses and materials made): *out NULL when the scene
 * has none.  A body that starts inside the body (a point penetrating by
 * more than 1e-3 mesh_size at t = 0) fails at its key (PM_ERR_SCENE)
 * naming the point. */
pm_err fpm_contact_create(const fpm_model *m, const pm_scene *s,
                          fpm_contact **out);
void fpm_contact_destroy(fpm_contact *c);

/* PM_ERR_SCENE at the first rigid body of s: contact runs on one process
 * for now (a share's model holds no contact). */
pm_err fpm_contact_refuse_ranks(const pm_scene *s);

/* The rigid bodies' forces at time t added to st->f (f_int - f_ext),
 * their energy to st->penalty_energy, |F|^2 to st->fext_sq (and
 * fext_norm) and the reactions kept in st->contact.  Serial over bodies,
 * parallel over points; allocates nothing. */
void fpm_contact_force(const fpm_model *m, fpm_state *st, double t);

/* Start of the work: remember the reactions and displacements. */
void fpm_contact_start(const fpm_model *m, fpm_state *st, double t);

/* Work of the rigid bodies on the body since the last call (trapezoid rule:
 * mean reaction times the displacement increment), remembered next. */
double fpm_contact_work(const fpm_model *m, fpm_state *st, double t);

/* The same with every body's displacement d(t) times scale: a static
 * solve's proportional load path (t the end of the ramps, scale the load
 * factor). */
void fpm_contact_start_scaled(const fpm_model *m, fpm_state *st, double t,
                              double scale);
double fpm_contact_work_scaled(const fpm_model *m, fpm_state *st, double t,
                               double scale);

/* Static solves (fpm_static): the contact as a function of the
 * displacement alone, the anchors held as the last converged load step
 * left them (fpm_contact_commit).  A point with an anchor sticks to it
 * (tangent k I) through the load step, wherever it goes; one without
 * (frictionless bodies, and sticking points that touch anew within the
 * step) is pushed along the normal while its gap is < 0 (k n n, plus the
 * sphere's curvature term).
 *
 * fpm_contact_force_fixed: the forces at the bodies' displacements
 * scale d(t) subtracted from st->f, the reactions kept in st->contact and
 * the energy added to st->penalty_energy, as fpm_contact_force; returns
 * |F|^2 (st->fext_sq is left alone).  Allocates nothing. */
double fpm_contact_force_fixed(const fpm_model *m, fpm_state *st, double t,
                               double scale);
/* Its tangent at st->u: K (9 per own point, row-major, the caller's)
 * with dF_i = -K_i du_i summed over the bodies, 0 where apart. */
void fpm_contact_tangent_fixed(const fpm_model *m, const fpm_state *st,
                               double t, double scale, double *K);
/* After a converged load step (and at the start): every sticking point
 * touching (gap at most 1e-9 mesh_size: the faces that start on a plate
 * too) without an anchor is anchored where it is; an anchored point now
 * apart (gap above that: the contact pulled it) is let go for the next
 * step; a glued body's points are anchored likewise and never let go. */
void fpm_contact_commit(const fpm_model *m, fpm_state *st, double t,
                        double scale);

/* The sticking set of a static solve, updated between Newton iterations
 * (fpm_static): fpm_contact_touch_fixed anchors every sticking point that
 * penetrates its body (gap < 0) at st->u without an anchor, at the surface
 * point under it, so that its force there is unchanged (the normal push
 * becomes the sticking pull of the same value); returns how many.
 * fpm_contact_release_fixed lets go every anchored point that the state
 * st->u pulls off its body (gap above 1e-9 mesh_size), returning how
 * many, and marks it in let_go (one per pair, the caller's, cleared at
 * each attempt at a step).  A point marked already, anchored again since,
 * grazes the body (let go, it comes back): it is held (frozen) instead,
 * and counted in out.  Both allocate nothing. */
typedef struct {
  long first;        /* the point let go farthest off (-1: none) */
  double first_gap;  /* its gap, m */
  long frozen;       /* points held though pulled off (grazing) */
  long frozen_first; /* the farthest of those (-1: none) */
  double frozen_gap; /* its gap, m */
} fpm_contact_release;
long fpm_contact_touch_fixed(const fpm_model *m, fpm_state *st, double t,
                             double scale);
long fpm_contact_release_fixed(const fpm_model *m, fpm_state *st, double t,
                               double scale, unsigned char *let_go,
                               fpm_contact_release *out);

/* Add the reaction of condition b (the force of the rigid body on the body)
 * to R; nothing when b is no rigid body. */
void fpm_contact_reaction(const fpm_model *m, const fpm_state *st, int b,
                          double R[3]);

/* The stable step dt of the model, lowered for the contact stiffness:
 * 2 / sqrt((2 / dt)^2 + max k / m). */
double fpm_contact_stable_dt(const fpm_contact *c, double dt);

#endif
