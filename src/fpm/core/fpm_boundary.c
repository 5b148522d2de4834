/* fpm_boundary: the boundary conditions of an FPM model: the facets each
 * condition acts on (a face of the box, a named surface of the mesh, or
 * the boundary inside a region), the prescribed dofs, the consistency flux
 * of facets with displacement conditions, and the traction facets. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_loads.h"
#include "fpm_model.h"
#include "pm_omp.h"
#include "pm_scene_mirror.h"

pm_err fpm_select_facets(const gm_dual *d, const pm_scene *s,
                         const gm_mesh *mesh, bool whole, long **ptr,
                         long **facet) {
  char path[64], names[512];
  *facet = NULL;
  PM_CALL(PM_ALLOC(*ptr, s->n_bcs + 1, "boundary facet lists"));
  long *bcf_ptr = *ptr;
  for (int pass = 0; pass < 2; pass++) {
    long n = 0;
    for (int b = 0; b < s->n_bcs; b++) {
      const pm_scene_bc *bc = &s->bcs[b];
      int surf = -1;
      bcf_ptr[b] = n;
      /* in contact: fpm_contact; at a point: fpm_loads */
      if (PM_BC_RIGID(bc) || bc->on == PM_ON_POINT) continue;
      if (bc->on != PM_ON_REGION) {
        surf = gm_mesh_surface_find(mesh, bc->surface);
        if (surf < 0) {
          gm_mesh_surface_list(mesh, names, sizeof names);
          snprintf(path, sizeof path, "boundary.%d.on", b);
          return pm_scene_fail(s, path, false,
                               "expected a surface of the mesh (%s), got %s",
                               names, bc->surface);
        }
      }
      bcf_ptr[b] = n;
      for (long f = 0; f < d->n_facets; f++) {
        const double *c = d->facet_centroid + 3 * f;
        bool in = bc->on == PM_ON_REGION
                      ? pm_expr_eval(bc->region, c[0], c[1], c[2], 0) > 0
                      : d->facet_surface[f] == surf;
        if (!in) continue;
        if (pass) (*facet)[n] = f;
        n++;
      }
      if (whole && n == bcf_ptr[b]) {
        snprintf(path, sizeof path, "boundary.%d.%s", b,
                 bc->on == PM_ON_REGION ? "region" : "on");
        return pm_scene_fail(
            s, path, false, "no boundary facet lies %s %s",
            bc->on == PM_ON_REGION ? "in region" : "on surface",
            bc->on == PM_ON_REGION ? pm_expr_text(bc->region) : bc->surface);
      }
    }
    bcf_ptr[s->n_bcs] = n;
    if (!pass) PM_CALL(PM_ALLOC(*facet, n, "boundary facet lists"));
  }
  return PM_SUCCESS;
}

/* Boundary conditions: prescribed dofs from facets on faces with
 * displacement conditions, the consistency flux of those facets, and the
 * traction facets. */
pm_err fpm_build_boundary(fpm_model *m, const pm_scene *s,
                          const gm_mesh *mesh) {
  pm_err ret = PM_SUCCESS;
  const gm_dual *d = m->dual;
  int *bc_of = NULL;   /* 3 n: condition prescribing each dof, or -1 */
  long *dpt_of = NULL; /* n: index into the dpt arrays, or -1 */
  PM_TRY(PM_ALLOC(bc_of, 3 * m->n, "boundary dof map"));
  PM_TRY(PM_ALLOC(dpt_of, m->n, "boundary point map"));
  for (long k = 0; k < 3 * m->n; k++) bc_of[k] = -1;
  for (long i = 0; i < m->n; i++) dpt_of[i] = -1;
  m->n_dpts = 0;
  m->n_tfacets = 0;
  /* A part of the whole (m->gid) may hold no facet of a condition. */
  PM_TRY(fpm_select_facets(d, s, mesh, !m->gid, &m->bcf_ptr, &m->bcf_facet));
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *bc = &s->bcs[b];
    for (long e = m->bcf_ptr[b]; e < m->bcf_ptr[b + 1]; e++) {
      long i = d->facet_point[m->bcf_facet[e]];
      for (int c = 0; c < 3; c++)
        if (bc->disp_mask & (1u << c)) bc_of[3 * i + c] = b;
      if (bc->disp_mask && dpt_of[i] < 0) dpt_of[i] = m->n_dpts++;
      if (bc->traction_mask || bc->pressure) m->n_tfacets++;
    }
  }
  /* In 2D (plane strain) the out-of-plane component is fixed at zero. */
  if (m->dim == 2)
    for (long i = 0; i < m->n; i++) m->fixed[3 * i + 2] = 1;
  m->n_cdofs = 0;
  for (long k = 0; k < 3 * m->n; k++)
    if (bc_of[k] >= 0) m->n_cdofs++;
  PM_TRY(PM_ALLOC(m->cd_point, m->n_cdofs, "constrained dofs"));
  PM_TRY(PM_ALLOC(m->cd_comp, m->n_cdofs, "constrained dofs"));
  PM_TRY(PM_ALLOC(m->cd_bc, m->n_cdofs, "constrained dofs"));
  PM_TRY(PM_ALLOC(m->cd_base, m->n_cdofs, "constrained dofs"));
  long nc = 0;
  for (long k = 0; k < 3 * m->n; k++) {
    if (bc_of[k] < 0) continue;
    long i = k / 3;
    int c = (int)(k % 3);
    const pm_scene_bc *bc = &s->bcs[bc_of[k]];
    const double *xi = m->x + 3 * i;
    m->cd_point[nc] = i;
    m->cd_comp[nc] = c;
    m->cd_bc[nc] = bc_of[k];
    m->cd_base[nc] = pm_expr_eval(bc->disp[c], xi[0], xi[1], xi[2], 0);
    if (pm_expr_uses(bc->disp[c], 't')) m->cd_time_dependent = true;
    m->fixed[k] = 1;
    nc++;
  }
  PM_TRY(PM_ALLOC(m->dpt_point, m->n_dpts, "boundary flux points"));
  PM_TRY(PM_ALLOC(m->dpt_area, 9 * m->n_dpts, "boundary flux areas"));
  PM_TRY(PM_ALLOC(m->dpt_mrel, 27 * m->n_dpts, "boundary flux moments"));
  PM_TRY(PM_ALLOC(m->tf_point, m->n_tfacets, "traction facets"));
  PM_TRY(PM_ALLOC(m->tf_bc, m->n_tfacets, "traction facets"));
  PM_TRY(PM_ALLOC(m->tf_area, m->n_tfacets, "traction facets"));
  PM_TRY(PM_ALLOC(m->tf_rel, 3 * m->n_tfacets, "traction facets"));
  PM_TRY(PM_ALLOC(m->tf_centroid, 3 * m->n_tfacets, "traction facets"));
  PM_TRY(PM_ALLOC(m->tf_base, 3 * m->n_tfacets, "traction facets"));
  PM_TRY(PM_ALLOC(m->tf_normal, 3 * m->n_tfacets, "traction facets"));
  long nt = 0;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *bc = &s->bcs[b];
    for (long e = m->bcf_ptr[b]; e < m->bcf_ptr[b + 1]; e++) {
      long f = m->bcf_facet[e], i = d->facet_point[f];
      const double *xi = m->x + 3 * i, *af = d->facet_area_vec + 3 * f;
      const double *Mf = d->facet_moment + 9 * f,
                   *cf = d->facet_centroid + 3 * f;
      if (bc->disp_mask) {
        long p = dpt_of[i];
        m->dpt_point[p] = i;
        for (int c = 0; c < 3; c++) {
          if (!(bc->disp_mask & (1u << c))) continue;
          for (int a = 0; a < 3; a++) {
            m->dpt_area[9 * p + 3 * c + a] += af[a];
            for (int q = 0; q < 3; q++)
              m->dpt_mrel[27 * p + 9 * c + 3 * a + q] +=
                  Mf[3 * a + q] - af[a] * xi[q];
          }
        }
      }
      if (bc->traction_mask || bc->pressure) {
        m->tf_point[nt] = i;
        m->tf_bc[nt] = b;
        m->tf_area[nt] = d->facet_area[f];
        for (int a = 0; a < 3; a++) {
          m->tf_rel[3 * nt + a] = d->facet_area[f] * (cf[a] - xi[a]);
          m->tf_centroid[3 * nt + a] = cf[a];
          m->tf_normal[3 * nt + a] = af[a] / d->facet_area[f];
        }
        if (bc->pressure && pm_expr_uses(bc->pressure, 't'))
          m->tf_time_dependent = true;
        for (int c = 0; c < 3; c++) {
          if (!(bc->traction_mask & (1u << c))) continue;
          m->tf_base[3 * nt + c] =
              pm_expr_eval(bc->traction[c], cf[0], cf[1], cf[2], 0);
          if (pm_expr_uses(bc->traction[c], 't')) m->tf_time_dependent = true;
        }
        nt++;
      }
    }
  }
  PM_TRY(fpm_build_loads(m, s));
done:
  free(bc_of);
  free(dpt_of);
  return ret;
}

double fpm_prescribed(const fpm_model *m, long k, double t) {
  const pm_scene_bc *bc = &m->scene->bcs[m->cd_bc[k]];
  double r = pm_bc_factor(bc, t);
  if (!m->cd_time_dependent) return r * m->cd_base[k];
  const double *xi = m->x + 3 * m->cd_point[k];
  return r * pm_expr_eval(bc->disp[m->cd_comp[k]], xi[0], xi[1], xi[2], t);
}

long fpm_update_tractions(const fpm_model *m, fpm_state *st, double t) {
  double norm2 = 0;
  const long n_own = m->n_own;
  long bad = -1;
  for (long k = 0; k < m->n_tfacets; k++) {
    const pm_scene_bc *bc = &m->scene->bcs[m->tf_bc[k]];
    double r = pm_bc_factor(bc, t);
    const double *c = m->tf_centroid + 3 * k;
    /* the pressure's traction follows the face: the force sets it */
    double p =
        bc->pressure ? r * pm_expr_eval(bc->pressure, c[0], c[1], c[2], t) : 0;
    if (!isfinite(p) && bad < 0) bad = 3 * k;
    st->tf_p[k] = p;
    if (m->tf_point[k] < n_own) norm2 += p * p * m->tf_area[k] * m->tf_area[k];
    for (int a = 0; a < 3; a++) {
      double v = 0;
      if (!(bc->traction_mask & (1u << a)))
        v = 0;
      else if (m->tf_time_dependent)
        v = r * pm_expr_eval(bc->traction[a], c[0], c[1], c[2], t);
      else
        v = r * m->tf_base[3 * k + a];
      if (!isfinite(v) && bad < 0) bad = 3 * k + a;
      st->tf_value[3 * k + a] = v;
      if (m->tf_point[k] < n_own)
        norm2 += v * v * m->tf_area[k] * m->tf_area[k];
    }
  }
  st->fext_sq = norm2;
  st->fext_norm = sqrt(norm2);
  return bad;
}

pm_err fpm_condition_failure(const fpm_model *m, bool traction, long k,
                             long step, double t) {
  if (traction) {
    const pm_scene_bc *bc = &m->scene->bcs[m->tf_bc[k / 3]];
    const pm_expr *e = bc->traction[k % 3];
    if (!e || (bc->pressure && k % 3 == 0 &&
               !isfinite(pm_expr_eval(bc->pressure, m->tf_centroid[k],
                                      m->tf_centroid[k + 1],
                                      m->tf_centroid[k + 2], t))))
      e = bc->pressure;
    const double *c = m->tf_centroid + 3 * (k / 3);
    return pm_expr_fail_value(e, pm_expr_eval(e, c[0], c[1], c[2], t), step, t,
                              "facet of point",
                              fpm_point_id(m, m->tf_point[k / 3]), c);
  }
  const pm_scene_bc *bc = &m->scene->bcs[m->cd_bc[k]];
  const pm_expr *e = bc->disp[m->cd_comp[k]];
  const double *x = m->x + 3 * m->cd_point[k];
  return pm_expr_fail_value(e, pm_expr_eval(e, x[0], x[1], x[2], t), step, t,
                            "point", fpm_point_id(m, m->cd_point[k]), x);
}

/* Past a plane by more than this fraction of the box along its axis
 * (points on the plane hold their normal displacement at exactly 0). */
#define FPM_SYMMETRY_SLACK 1e-9

long fpm_symmetry_crossed(const fpm_model *m, const fpm_state *st, int *axis) {
  const pm_scene *s = m->scene;
  *axis = -1;
  if (!s || !s->mirror_mask) return -1;
  long first = m->n_own;
  for (int a = 0; a < 3; a++) {
    if (!(s->mirror_mask >> a & 1u)) continue;
    const double at = s->mirror_at[a];
    const double side = pm_scene_mirror_above(s, a) ? 1.0 : -1.0;
    const double slack = FPM_SYMMETRY_SLACK * (s->box_max[a] - s->box_min[a]);
    long bad = m->n_own;
    PM_OMP(parallel for schedule(static) reduction(min : bad))
    for (long i = 0; i < m->n_own; i++)
      if (side * (m->x[3 * i + a] + st->u[3 * i + a] - at) < -slack && i < bad)
        bad = i;
    if (bad < first) {
      first = bad;
      *axis = a;
    }
  }
  return first < m->n_own ? first : -1;
}

pm_err fpm_symmetry_failure(const fpm_model *m, const fpm_state *st, long p,
                            int axis, const char *prefix) {
  const double *x = m->x + 3 * p, *u = st->u + 3 * p;
  const char name = (char)('x' + axis);
  return PM_ERROR(PM_ERR_UNSTABLE,
                  "%spoint %ld at (%g, %g, %g) passed the symmetry plane %c = "
                  "%g (now at %c = %.6g): the part's surface folded through "
                  "the plane, into the mirrored part (nothing holds the two "
                  "apart: no self-contact)",
                  prefix, fpm_point_id(m, p), x[0], x[1], x[2], name,
                  m->scene->mirror_at[axis], name, x[axis] + u[axis]);
}

/* Samples of the ramps' span (the factors are smooth or piecewise linear
 * between a table's rows: the largest difference quotient over this many
 * steps is the peak rate to a fraction of a percent); conditions whose
 * expressions use t take an evaluation a dof and a sample, so they are
 * sampled more coarsely: at most SPEED_SAMPLES_EXPR times, and at most
 * SPEED_EVALUATIONS evaluations in all (at least 8 samples). */
#define SPEED_SAMPLES 512
#define SPEED_SAMPLES_EXPR 64
#define SPEED_EVALUATIONS 1000000L

double fpm_support_speed(const fpm_model *m) {
  const pm_scene *s = m->scene;
  const double end = pm_scene_load_end(s);
  double vmax = 0;
  if (end > 0 && m->n_cdofs > 0) {
    if (!m->cd_time_dependent) {
      /* r(t) cd_base[k]: each condition's peak rate, then its dofs' */
      const double dt = end / SPEED_SAMPLES;
      for (int b = 0; b < s->n_bcs; b++) {
        double rate = 0, r0 = pm_bc_factor(&s->bcs[b], 0);
        for (int i = 1; i <= SPEED_SAMPLES; i++) {
          const double r1 = pm_bc_factor(&s->bcs[b], i * dt);
          rate = fmax(rate, fabs(r1 - r0) / dt);
          r0 = r1;
        }
        for (long k = 0; k < m->n_cdofs; k++)
          if (m->cd_bc[k] == b) vmax = fmax(vmax, rate * fabs(m->cd_base[k]));
      }
    } else {
      long ns = SPEED_EVALUATIONS / m->n_cdofs;
      ns = ns > SPEED_SAMPLES_EXPR ? SPEED_SAMPLES_EXPR : ns < 8 ? 8 : ns;
      const double dt = end / (double)ns;
      for (long k = 0; k < m->n_cdofs; k++) {
        double u0 = fpm_prescribed(m, k, 0);
        for (long i = 1; i <= ns; i++) {
          const double u1 = fpm_prescribed(m, k, i * dt);
          if (isfinite(u1) && isfinite(u0))
            vmax = fmax(vmax, fabs(u1 - u0) / dt);
          u0 = u1;
        }
      }
    }
  }
  return vmax;
}
