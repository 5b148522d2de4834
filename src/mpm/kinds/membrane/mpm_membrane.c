/* mpm_membrane: the membrane particle kind (section 2.1 of
 * papers/mpm-fluid-membrane-zona-piezo-icsi.txt, eqs. 1-22, and the
 * elastodamage of eqs. 38-41).  One layer of points on the vertices of a
 * triangulated surface; each carries a local frame (e1, e2 in the tangent
 * plane, n the normal), its in-plane strain in that frame, and, with
 * damage, the damage variable omega and a failed flag.
 *
 * Each step, a normal stage and then the stress stage:
 *   1. each point's normal from the current positions, by the body's
 *      method: the mean of its triangles' unit normals (eq. 8); along a
 *      2-D curve, perpendicular to the chord of its neighbours; or, with
 *      no connectivity, the gradient of a function fitted per grid cell to
 *      be 1 on the points (papers/mpm-membrane-normals-without-
 *      connectivity.txt, mpm_isonormal.h), turned to agree with the point's
 *      previous normal (the fit does not tell inside from outside);
 *   3. the frame carried to it: first turned about the old normal by the
 *      grid's in-plane spin, then by the rotation S of eqs. 9-22 that takes
 *      the old normal to the new one and keeps what is perpendicular to
 *      both;
 *   4. the strain increment of the grid's rate of deformation, in the frame
 *      (eq. 5 applied to the increment), added to the frame's strain;
 *   5. plane stress (eqs. 1-2 with sigma_z' = 0 and no out-of-plane shear),
 *      scaled by the elastodamage secant stiffness, rotated back (eq. 7).
 *
 * The paper adds strain increments in the global axes and rotates the
 * total; a membrane that turns then sees its strain turn out of its plane.
 * Keeping the strain in the frame and the frame turning with the material
 * makes a rigid rotation leave the stress unchanged in the frame (the
 * frame-update test checks it).
 *
 * In 2-D (plane strain) a membrane is a line of points, each a strip of
 * unit depth: the frame is (z, the tangent, the in-plane normal), the
 * strain along z stays 0 and the law is the same, which makes the tension
 * E t eps / (1 - nu^2) along the tangent, per unit depth.
 *
 * Here: the kind's table entry, its constants and output fields.  Its
 * links and first frames: mpm_membrane_links.c; the normal stage:
 * mpm_membrane_normals.c (connectivity) and mpm_membrane_fit.c (fitted per
 * cell); frames: mpm_membrane_frames.c; the stress stage and the law:
 * mpm_membrane_stress.c and mpm_membrane_impl.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_membrane_impl.h"
#include "pm_omp.h"

static pm_err membrane_setup(mpm_group *g, const pm_scene_material *sm,
                             const mpm_options *opt) {
  (void)opt;
  membrane_params *mp = NULL;
  PM_CALL(PM_ALLOC(mp, 1, "membrane constants"));
  g->params = mp;
  mp->E = sm->mat.youngs_modulus;
  mp->nu = sm->mat.poisson_ratio;
  mp->C = mp->E / (1 - mp->nu * mp->nu);
  mp->G = mp->E / (2 * (1 + mp->nu));
  mp->damage = sm->damage.given;
  mp->c0 = sm->damage.c0;
  mp->c1 = sm->damage.c1;
  mp->limit = sm->damage.elastic_limit;
  mp->failure = sm->damage.failure;
  g->viscosity = 0;
  mpm_group_add_array(g, "frame", 9);
  mpm_group_add_array(g, "membrane_strain", 3);
  if (mp->damage) {
    mpm_group_add_array(g, "omega", 1);
    mpm_group_add_array(g, "failed", 1);
  }
  return PM_SUCCESS;
}

static void membrane_release(mpm_group *g) {
  membrane_params *mp = g->params;
  if (!mp) return;
  free(mp->tri);
  free(mp->inc_start);
  free(mp->inc_tri);
  free(mp->link);
  free(mp->whole.tri);
  free(mp->whole.inc_start);
  free(mp->whole.inc_tri);
  free(mp->tri_whole);
  free(mp->bodies);
}

static void membrane_seed(const mpm_group *g, mpm_group_state *gs, long k,
                          const pm_scene_body *b, double sigma[9]) {
  (void)g, (void)b, (void)sigma;
  /* The frame needs the surface: mpm_kind.finish sets it. */
  memset(gs->array[MEM_FRAME].data + 9 * k, 0, 9 * sizeof(double));
}

static void membrane_describe(const mpm_group *g, char *buf, size_t size) {
  const membrane_params *mp = g->params;
  if (mp->damage)
    snprintf(buf, size,
             "membrane: frame by S (eqs. 9-22), plane stress E = %g, nu = "
             "%g, elastodamage (eqs. 38-41, c0 = %g, c1 = %g, S_L = %g), "
             "fails at eps_max = %g",
             mp->E, mp->nu, mp->c0, mp->c1, mp->limit, mp->failure);
  else
    snprintf(buf, size,
             "membrane: frame by S (eqs. 9-22), plane stress E = %g, nu = %g",
             mp->E, mp->nu);
}

/* Doubles of step workspace: each point's new normal, each triangle's
 * (across ranks, room for as many as the arrays have). */
static long membrane_scratch(const mpm_model *m, const mpm_group *g) {
  (void)m;
  const membrane_params *mp = g->params;
  const long np = g->end - g->begin;
  return 3 * (g->cap > np ? g->cap : np) + 3 * mp->tri_room;
}

static void membrane_wave_speeds(const mpm_model *m, const mpm_state *s,
                                 const mpm_group *g, double *cp, double *cs) {
  const membrane_params *mp = g->params;
  const long begin = g->begin, end = g->end;
  const double *mass = m->mass, *vol = s->vol;
  PM_OMP(parallel for schedule(static) default(none)
         shared(mp, begin, end, mass, vol, cp, cs))
  for (long p = begin; p < end; p++) {
    double rho = mass[p] / vol[p];
    cp[p] = sqrt(mp->C / rho);
    if (cs) cs[p] = sqrt(mp->G / rho);
  }
}

static void membrane_energies(const mpm_model *m, const mpm_state *s,
                              const mpm_group *g, double *strain,
                              double *internal) {
  (void)internal;
  const membrane_params *mp = g->params;
  const mpm_group_state *gs = &s->group[g->index];
  const double *eps = gs->array[MEM_STRAIN].data, *vol0 = m->vol0;
  const double *om = mp->damage ? gs->array[MEM_OMEGA].data : NULL;
  const double *failed = mp->damage ? gs->array[MEM_FAILED].data : NULL;
  const long begin = g->begin, end = g->end;
  double se = 0; /* from zero, then added (as mpm_fluid.c) */
  PM_OMP(parallel for schedule(static) default(none)
         shared(mp, eps, vol0, om, failed, begin, end) reduction(+ : se))
  for (long p = begin; p < end; p++) {
    const long k = p - begin;
    se += vol0[p] * plane_energy(mp, eps + 3 * k, factor_of(mp, om, failed, k));
  }
  *strain += se;
}

static void membrane_fields(const mpm_model *m, const mpm_state *s,
                            const mpm_group *g, double *sed, double *pressure,
                            double *energy) {
  (void)m;
  const membrane_params *mp = g->params;
  const mpm_group_state *gs = &s->group[g->index];
  const double *eps = gs->array[MEM_STRAIN].data, *sigma = s->sigma;
  const double *om = mp->damage ? gs->array[MEM_OMEGA].data : NULL;
  const double *failed = mp->damage ? gs->array[MEM_FAILED].data : NULL;
  for (long p = g->begin; p < g->end; p++) {
    const long k = p - g->begin;
    const double *sg = sigma + 9 * p;
    sed[p] = plane_energy(mp, eps + 3 * k, factor_of(mp, om, failed, k));
    pressure[p] = -(sg[0] + sg[4] + sg[8]) / 3.0;
    energy[p] = 0;
  }
}

static void membrane_surface_fields(const mpm_model *m, const mpm_state *s,
                                    const mpm_group *g, double *normal,
                                    double *damage, double *failed_out) {
  (void)m;
  const membrane_params *mp = g->params;
  const mpm_group_state *gs = &s->group[g->index];
  const double *frame = gs->array[MEM_FRAME].data;
  const double *om = mp->damage ? gs->array[MEM_OMEGA].data : NULL;
  const double *failed = mp->damage ? gs->array[MEM_FAILED].data : NULL;
  for (long p = g->begin; p < g->end; p++) {
    const long k = p - g->begin;
    for (int c = 0; c < 3; c++) normal[3 * p + c] = frame[9 * k + 6 + c];
    damage[p] = 1.0 - factor_of(mp, om, failed, k);
    failed_out[p] = mp->damage && failed[k] > 0 ? 1.0 : 0.0;
  }
}

/* A membrane body (a surface's vertices), whatever its material. */
static bool membrane_takes(const pm_scene_material *sm, mpm_body_role role) {
  (void)sm;
  return role == MPM_BODY_MEMBRANE;
}

/* Its frame, strain, damage and failed, and its triangles (two per point)
 * with their incidence and normals. */
static double membrane_doubles(const pm_scene_material *sm, bool fbar) {
  (void)sm, (void)fbar;
  return 9 + 3 + 2 + 2 * (3 + 6);
}

const mpm_kind mpm_kind_membrane = {
    .name = "membrane",
    .stage_name = "stress: membrane",
    .flags = MPM_KIND_STRAIN_ENERGY | MPM_KIND_MEMBRANE,
    .takes = membrane_takes,
    .estimate_doubles = membrane_doubles,
    .setup = membrane_setup,
    .release = membrane_release,
    .seed = membrane_seed,
    .finish = mpm_membrane_finish,
    .scratch = membrane_scratch,
    .ranks_share = mpm_membrane_ranks_share,
    .ranks_link = mpm_membrane_ranks_link,
    .ranks_reach = mpm_membrane_ranks_reach,
    .work_create = mpm_membrane_fits_create,
    .work_free = mpm_membrane_fits_free,
    .pre_stress = mpm_membrane_normals,
    .pre_stage_name = "normals: membrane",
    .describe_pre = mpm_membrane_describe_normals,
    .stress = mpm_membrane_stress,
    .describe = membrane_describe,
    .wave_speeds = membrane_wave_speeds,
    .energies = membrane_energies,
    .fields = membrane_fields,
    .surface_fields = membrane_surface_fields,
};
