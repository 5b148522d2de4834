/* fpm_loads: body forces, concentrated forces and the follower pressure of
 * an FPM model (fpm_loads.h). */
#include "fpm_loads.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The points of condition b's facets, each once (mark: n bytes, zero on
 * entry and on return), into pts (NULL: counted only). */
static long facet_points(const fpm_model *m, int b, unsigned char *mark,
                         long *pts) {
  long c = 0;
  for (long e = m->bcf_ptr[b]; e < m->bcf_ptr[b + 1]; e++) {
    const long i = m->dual->facet_point[m->bcf_facet[e]];
    if (mark[i]) continue;
    mark[i] = 1;
    if (pts) pts[c] = i;
    c++;
  }
  for (long e = m->bcf_ptr[b]; e < m->bcf_ptr[b + 1]; e++)
    mark[m->dual->facet_point[m->bcf_facet[e]]] = 0;
  return c;
}

/* The point nearest x (the first of equals). */
static long nearest_point(const fpm_model *m, const double *x) {
  long best = 0;
  double d2min = INFINITY;
  for (long i = 0; i < m->n; i++) {
    const double *xi = m->x + 3 * i;
    double d2 = 0;
    for (int a = 0; a < 3; a++) d2 += (xi[a] - x[a]) * (xi[a] - x[a]);
    if (d2 < d2min) d2min = d2, best = i;
  }
  return best;
}

static pm_err build_point_forces(fpm_model *m, const pm_scene *s) {
  pm_err ret = PM_SUCCESS;
  unsigned char *mark = NULL;
  PM_TRY(PM_ALLOC(mark, m->n + 1, "point force marks"));
  long n = 0;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *bc = &s->bcs[b];
    if (!bc->force_mask) continue;
    n += bc->on == PM_ON_POINT ? 1 : facet_points(m, b, mark, NULL);
  }
  m->n_pforces = n;
  PM_TRY(PM_ALLOC(m->pf_point, n + 1, "point forces"));
  PM_TRY(PM_ALLOC(m->pf_bc, n + 1, "point forces"));
  PM_TRY(PM_ALLOC(m->pf_share, n + 1, "point forces"));
  long k = 0;
  for (int b = 0; b < s->n_bcs; b++) {
    const pm_scene_bc *bc = &s->bcs[b];
    if (!bc->force_mask) continue;
    long c = 1;
    if (bc->on == PM_ON_POINT)
      m->pf_point[k] = nearest_point(m, bc->at);
    else
      c = facet_points(m, b, mark, m->pf_point + k);
    for (long j = k; j < k + c; j++) {
      m->pf_bc[j] = b;
      m->pf_share[j] = 1.0 / (double)c;
    }
    k += c;
  }
done:
  free(mark);
  return ret;
}

pm_err fpm_build_loads(fpm_model *m, const pm_scene *s) {
  PM_CALL(build_point_forces(m, s));
  if (!s->has_gravity && !s->body_force_mask) return PM_SUCCESS;
  PM_CALL(PM_ALLOC(m->bf_base, 3 * m->n, "body forces"));
  for (int a = 0; a < 3; a++)
    if (s->body_force[a] && pm_expr_uses(s->body_force[a], 't'))
      m->bf_time_dependent = true;
  for (long i = 0; i < m->n; i++) {
    const double *x = m->x + 3 * i;
    for (int a = 0; a < 3; a++) {
      double b = s->gravity[a];
      if (s->body_force[a])
        b += pm_expr_eval(s->body_force[a], x[0], x[1], x[2], 0);
      m->bf_base[3 * i + a] = m->mass[i] * b;
    }
  }
  return PM_SUCCESS;
}

long fpm_update_loads(const fpm_model *m, fpm_state *st, double t) {
  const pm_scene *s = m->scene;
  const long n_own = m->n_own;
  long bad = -1;
  double norm2 = 0;
  if (m->bf_base || m->n_pforces)
    memset(st->fload, 0, 3 * m->n * sizeof(double));
  if (m->bf_base) {
    const double r = pm_curve_at(s->body_curve, t);
    for (long i = 0; i < n_own; i++)
      for (int a = 0; a < 3; a++) {
        double v = m->bf_base[3 * i + a];
        if (m->bf_time_dependent && s->body_force[a]) {
          const double *x = m->x + 3 * i;
          v = m->mass[i] * (s->gravity[a] + pm_expr_eval(s->body_force[a], x[0],
                                                         x[1], x[2], t));
        }
        v *= r;
        if (!isfinite(v) && bad < 0) bad = 3 * i + a;
        st->fload[3 * i + a] = v;
      }
  }
  for (long k = 0; k < m->n_pforces; k++) {
    const long i = m->pf_point[k];
    const pm_scene_bc *bc = &s->bcs[m->pf_bc[k]];
    const double r = pm_bc_factor(bc, t) * m->pf_share[k];
    const double *x = m->x + 3 * i;
    for (int a = 0; a < 3; a++) {
      if (!(bc->force_mask & (1u << a))) continue;
      const double v = r * pm_expr_eval(bc->force[a], x[0], x[1], x[2], t);
      if (!isfinite(v) && bad < 0) bad = 3 * (m->n + k) + a;
      st->fload[3 * i + a] += v;
    }
  }
  if (m->bf_base || m->n_pforces)
    for (long d = 0; d < 3 * n_own; d++) norm2 += st->fload[d] * st->fload[d];
  st->fext_sq += norm2;
  st->fext_norm = sqrt(st->fext_sq);
  return bad;
}

pm_err fpm_load_failure(const fpm_model *m, long k, long step, double t) {
  const pm_scene *s = m->scene;
  const int a = (int)(k % 3);
  long i = k / 3;
  const pm_expr *e;
  if (i < m->n) {
    e = s->body_force[a];
  } else {
    const long row = i - m->n;
    e = s->bcs[m->pf_bc[row]].force[a];
    i = m->pf_point[row];
  }
  const double *x = m->x + 3 * i;
  if (!e) /* gravity times the curve: the curve's value */
    return PM_ERROR(PM_ERR_UNSTABLE,
                    "step %ld, t = %.6g s: point %ld: body_curve gave %g, "
                    "not a finite value",
                    step, t, fpm_point_id(m, i), pm_curve_at(s->body_curve, t));
  return pm_expr_fail_value(e, pm_expr_eval(e, x[0], x[1], x[2], t), step, t,
                            "point", fpm_point_id(m, i), x);
}

void fpm_loads_scale(const fpm_model *m, fpm_state *st, double lambda) {
  for (long k = 0; k < 3 * m->n_tfacets; k++) st->tf_value[k] *= lambda;
  for (long k = 0; k < m->n_tfacets; k++) st->tf_p[k] *= lambda;
  if (m->bf_base || m->n_pforces)
    for (long d = 0; d < 3 * m->n; d++) st->fload[d] *= lambda;
  st->fext_norm *= lambda;
}

/* C = cof2(A, B): C_ij = A_{i1 j1} B_{i2 j2} - A_{i1 j2} B_{i2 j1} (i1, i2
 * and j1, j2 the two indices after i and j, cyclic), so that cof(F) =
 * cof2(F, F) and its change along dF is cof2(dF, F) + cof2(F, dF). */
static void cof2(const double *A, const double *B, double C[9]) {
  for (int i = 0; i < 3; i++) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; j++) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      C[3 * i + j] =
          A[3 * i1 + j1] * B[3 * i2 + j2] - A[3 * i1 + j2] * B[3 * i2 + j1];
    }
  }
}

void fpm_pressure_traction(const double *H, double p, const double *N,
                           double t[3]) {
  double F[9], C[9];
  fpm_deformation(H, F);
  cof2(F, F, C);
  for (int a = 0; a < 3; a++)
    t[a] = -p * (C[3 * a] * N[0] + C[3 * a + 1] * N[1] + C[3 * a + 2] * N[2]);
}

void fpm_pressure_dtraction(const double *H, const double *dH, double p,
                            const double *N, double dt[3]) {
  double F[9], C1[9], C2[9];
  fpm_deformation(H, F);
  cof2(dH, F, C1);
  cof2(F, dH, C2);
  for (int a = 0; a < 3; a++) {
    double v = 0;
    for (int b = 0; b < 3; b++) v += (C1[3 * a + b] + C2[3 * a + b]) * N[b];
    dt[a] = -p * v;
  }
}

double fpm_loads_work(const fpm_model *m, fpm_state *st, const double *du,
                      double scale) {
  if (!m->bf_base && !m->n_pforces) return 0;
  double work = 0;
  for (long d = 0; d < 3 * m->n_own; d++) {
    work += 0.5 * (st->fload_prev[d] + st->fload[d]) * du[d] * scale;
    st->fload_prev[d] = st->fload[d];
  }
  return work;
}

void fpm_loads_start(const fpm_model *m, fpm_state *st) {
  if (m->bf_base || m->n_pforces)
    memcpy(st->fload_prev, st->fload, 3 * m->n * sizeof(double));
}
