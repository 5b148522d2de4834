/* mpm_step: the stages of an explicit MPM step and the pipeline built from
 * the scene.  Transfers follow section 7 of
 * papers/mpm-membrane-normals-without-connectivity.txt; the fluid update
 * follows section 2.2 of papers/mpm-fluid-membrane-zona-piezo-icsi.txt
 * (eqs. 23-33). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_model.h"
#include "pm_omp.h"
#include "pm_tensor.h"

enum { P2G_MASS = 1, P2G_MOM = 2, P2G_FORCE = 4 };

static inline int thread_id(void) {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

/* Record the first failure of a stage (thread-safe). */
static void fail_at(mpm_sim *sim, long p, const char *fmt, double a, double b) {
  PM_OMP(critical(mpm_fail)) {
    if (!sim->fail.failed) {
      sim->fail.failed = true;
      sim->fail.particle = p;
      snprintf(sim->fail.cause, sizeof sim->fail.cause, fmt, a, b);
    }
  }
}

/* Wave speeds of particle p of group g: dilatational and shear. */
static inline void wave_speeds(const mpm_sim *sim, const mpm_group *g, long p,
                               double *cp, double *cs) {
  long k = p - g->begin;
  if (g->fluid) {
    *cp = pm_eos_sound_speed(&g->fluid_props, g->rho[k], g->pressure[k]);
    *cs = 0;
  } else {
    /* The particle's own density (a body may set it), which follows its
     * volume. */
    double rho = sim->mass[p] / sim->vol[p];
    *cp = sqrt(g->solid.wave_modulus / rho);
    *cs = sqrt(g->solid.shear_modulus / rho);
  }
}

/* ---- particle to grid --------------------------------------------------- */

static void p2g_mode(mpm_sim *sim, int mode) {
  mpm_grid *g = &sim->grid;
  const int S = g->acc_stride;
  const bool imp = (mode & P2G_FORCE) && g->impedance;
  const long nn = g->n_nodes;
  /* The accumulators were sized for g->threads: run exactly that many. */
  PM_OMP(parallel num_threads(g->threads)) {
    double *acc = g->acc + (size_t)thread_id() * nn * S;
    memset(acc, 0, sizeof(double) * nn * S);
    for (int gi = 0; gi < sim->n_groups; gi++) {
      const mpm_group *gr = &sim->group[gi];
      PM_OMP(for schedule(static) nowait)
      for (long p = gr->begin; p < gr->end; p++) {
        mpm_stencil st;
        mpm_stencil_at(g, sim->x + 3 * p, &st);
        const double m = sim->mass[p];
        const double *vp = sim->v + 3 * p;
        double s[9] = {0};
        if (mode & P2G_FORCE)
          for (int k = 0; k < 9; k++)
            s[k] = -sim->vol[p] * sim->sigma[9 * p + k];
        double cp = 0, cs = 0;
        if (imp) {
          /* Impedances rho c of the particle. */
          wave_speeds(sim, gr, p, &cp, &cs);
          double rho = m / sim->vol[p];
          cp *= rho;
          cs *= rho;
        }
        for (int c = 0; c < st.n[2]; c++)
          for (int b = 0; b < st.n[1]; b++) {
            double wbc = st.w[1][b] * st.w[2][c];
            double gy = st.dw[1][b] * st.w[2][c];
            double gz = st.w[1][b] * st.dw[2][c];
            long row = st.base + b * g->stride[1] + c * g->stride[2];
            for (int a = 0; a < st.n[0]; a++) {
              double w = st.w[0][a] * wbc;
              double *r = acc + (row + a) * S;
              if (mode & P2G_MASS) r[MPM_ACC_M] += w * m;
              if (mode & P2G_MOM) {
                r[MPM_ACC_P + 0] += w * m * vp[0];
                r[MPM_ACC_P + 1] += w * m * vp[1];
                r[MPM_ACC_P + 2] += w * m * vp[2];
              }
              if (mode & P2G_FORCE) {
                double gr3[3] = {st.dw[0][a] * wbc, st.w[0][a] * gy,
                                 st.w[0][a] * gz};
                r[MPM_ACC_F + 0] +=
                    s[0] * gr3[0] + s[1] * gr3[1] + s[2] * gr3[2];
                r[MPM_ACC_F + 1] +=
                    s[3] * gr3[0] + s[4] * gr3[1] + s[5] * gr3[2];
                r[MPM_ACC_F + 2] +=
                    s[6] * gr3[0] + s[7] * gr3[1] + s[8] * gr3[2];
                if (imp) {
                  r[MPM_ACC_BASE + 0] += w * m * cp;
                  r[MPM_ACC_BASE + 1] += w * m * cs;
                }
              }
            }
          }
      }
    }
    PM_OMP(barrier)
#ifdef _OPENMP
    const int T = omp_get_num_threads();
#else
    const int T = 1;
#endif
    PM_OMP(for schedule(static))
    for (long i = 0; i < nn; i++) {
      double sum[MPM_ACC_BASE + 2] = {0};
      for (int t = 0; t < T; t++) {
        const double *r = g->acc + ((size_t)t * nn + i) * S;
        for (int k = 0; k < S; k++) sum[k] += r[k];
      }
      if (mode & P2G_MASS) g->mass[i] = sum[MPM_ACC_M];
      if (mode & P2G_MOM)
        for (int c = 0; c < 3; c++) g->mom[3 * i + c] = sum[MPM_ACC_P + c];
      if (mode & P2G_FORCE) {
        for (int c = 0; c < 3; c++) g->force[3 * i + c] = sum[MPM_ACC_F + c];
        if (imp) {
          g->impedance[2 * i] = sum[MPM_ACC_BASE];
          g->impedance[2 * i + 1] = sum[MPM_ACC_BASE + 1];
        }
      }
    }
  }
}

void mpm_p2g(mpm_sim *sim, int with_force) {
  p2g_mode(sim, P2G_MASS | P2G_MOM | (with_force ? P2G_FORCE : 0));
}

/* ---- boundary conditions on the grid ------------------------------------ */

/* Velocity the condition prescribes on component c at face position x. */
static double bc_velocity(const mpm_sim *sim, const pm_scene_bc *sb, int c,
                          const double x[3]) {
  double t = sim->t, dt = sim->dt, T = sb->ramp_time;
  if (sb->disp[c]) {
    double u1 = pm_ramp_factor(sb->ramp, T, t + dt) *
                pm_expr_eval(sb->disp[c], x[0], x[1], x[2], t + dt);
    double u0 = pm_ramp_factor(sb->ramp, T, t) *
                pm_expr_eval(sb->disp[c], x[0], x[1], x[2], t);
    return (u1 - u0) / dt;
  }
  return pm_ramp_factor(sb->ramp, T, t + dt) *
         pm_expr_eval(sb->velocity[c], x[0], x[1], x[2], t + dt);
}

/* Current wall coordinate of the face at x: the plane moved by the
 * prescribed normal displacement. */
static double bc_wall(const mpm_sim *sim, const mpm_bc *bc,
                      const pm_scene_bc *sb, const double x[3]) {
  int a = bc->axis;
  if (!sb->disp[a]) return bc->plane;
  return bc->plane + pm_ramp_factor(sb->ramp, sb->ramp_time, sim->t) *
                         pm_expr_eval(sb->disp[a], x[0], x[1], x[2], sim->t);
}

/* The dependent dofs of the conditions.  On each column of a face, a node
 * at or beyond the face's current wall is set from one free node of the
 * column (its anchor), v = T v_anchor + (1 - T) v_b:
 *  - prescribed components: the line through the anchor's velocity and the
 *    prescribed value at the wall, so a linear field stays linear through
 *    the wall wherever it is.  The anchor is the first inside node at least
 *    h/2 from the wall (nearer, the line's slope would amplify the anchor's
 *    noise); a node inside the wall but nearer than h/2 is then set too.
 *    On a wall at a node plane this is the odd reflection v = 2 v_b - v_in.
 *  - free components of a wall (normal prescribed): the first inside
 *    node's, as at a plane of symmetry (T = 1), beyond the wall.
 * With fold, instead of setting vel, the dependent dofs' forces are moved
 * onto their anchors (f_anchor += T f): the free dofs then carry the
 * shape functions of the constrained space, S_anchor + T S_ghost, and the
 * internal force is its Galerkin force (without it, a free node whose
 * support crosses the wall misses the ghost's share and feels the stress
 * at the wall as a spurious load).  With mark, record in g->owner which
 * condition set each dof (-(b + 1) prescribed, b + 1 reflected; a
 * prescription wins over a reflection). */
static void apply_bcs_once(mpm_sim *sim, double *vel, bool mark,
                           const double *force, double *fold) {
  const pm_scene *s = sim->scene;
  mpm_grid *g = &sim->grid;
  const double eps = 1e-9 * g->h;
  /* Folding visits the faces in reverse: a dof set by two faces follows
   * the last one's rule, as its velocity does. */
  for (int bb = 0; bb < sim->n_bcs; bb++) {
    int b = fold ? sim->n_bcs - 1 - bb : bb;
    mpm_bc *bc = &sim->bcs[b];
    const pm_scene_bc *sb = &s->bcs[bc->bc];
    unsigned mask = bc->disp_mask | bc->vel_mask;
    if (!mask) continue;
    int a = bc->axis;
    double vconst[3] = {0, 0, 0}, wall_const = bc->plane;
    double xc[3];
    for (int c = 0; c < 3; c++) xc[c] = 0.5 * (s->box_min[c] + s->box_max[c]);
    xc[a] = bc->plane;
    for (int c = 0; c < 3; c++)
      if ((mask >> c & 1u) && bc->constant[c])
        vconst[c] = bc_velocity(sim, sb, c, xc);
    if (bc->constant[a]) wall_const = bc_wall(sim, bc, sb, xc);
    long step_a = g->stride[a];
    for (long k = 0; k < bc->n_cols; k++) {
      long col = bc->col[k];
      /* Face position of the column. */
      double x[3] = {0, 0, 0};
      long rem = col;
      for (int c = 2; c >= 0; c--) {
        long i = rem / g->stride[c];
        rem -= i * g->stride[c];
        x[c] = g->origin[c] + i * g->h;
      }
      x[a] = bc->plane;
      double v[3] = {0, 0, 0};
      if (!fold)
        for (int c = 0; c < 3; c++)
          if (mask >> c & 1u)
            v[c] = bc->constant[c] ? vconst[c] : bc_velocity(sim, sb, c, x);
      double wall = bc->constant[a] ? wall_const : bc_wall(sim, bc, sb, x);
      /* The first node inside the wall, and the anchor of the prescribed
       * components. */
      long ia_face = (long)llround((bc->plane - g->origin[a]) * g->inv_h);
      long i_start = bc->outward > 0 ? g->nn[a] - 1 : 0;
      long di = bc->outward > 0 ? -1 : 1;
#define DIST(i) ((g->origin[a] + (i)*g->h - wall) * bc->outward)
#define INSIDE(i) ((i) >= 0 && (i) < g->nn[a])
#define NODE(i) (col + ((i)-ia_face) * step_a)
      long i_in = i_start;
      while (INSIDE(i_in) && DIST(i_in) >= -eps) i_in += di;
      long i_an = i_in;
      if (INSIDE(i_an) && DIST(i_an) > -0.5 * g->h) i_an += di;
      /* The inside nodes count only where material is (a node without
       * mass has no velocity to extend). */
      long n_in = NODE(i_in), n_an = NODE(i_an);
      bool has_in = INSIDE(i_in) && g->mass[n_in] > 0;
      bool has_an = INSIDE(i_an) && g->mass[n_an] > 0;
      double d_an = INSIDE(i_an) ? DIST(i_an) : -g->h;
      long i_end = INSIDE(i_an) ? i_an : i_in;
      for (long i = i_start; i != i_end; i += di) {
        long node = NODE(i);
        double d = DIST(i);
        double m = g->mass[node];
        for (int c = 0; c < 3; c++) {
          bool fixed = mask >> c & 1u;
          long anchor;
          double T;
          if (fixed) {
            /* v = v_an + (d - d_an) / -d_an (v_b - v_an) */
            anchor = has_an && fabs(d) > eps ? n_an : -1;
            T = anchor >= 0 ? 1.0 - (d - d_an) / -d_an : 0.0;
          } else {
            if (!(mask >> a & 1u) || !has_in || d <= eps) continue;
            anchor = n_in;
            T = 1.0;
          }
          if (fold) {
            short *o = &g->owner[3 * node + c];
            if (*o) continue; /* folded by a later face */
            *o = 1;
            if (anchor < 0 || m <= 0) continue;
            double f = T * (force[3 * node + c] + fold[3 * node + c]);
            fold[3 * anchor + c] += f;
            g->fold_out[3 * node + c] = f;
            continue;
          }
          double vset =
              anchor >= 0 ? T * vel[3 * anchor + c] + (1.0 - T) * v[c] : v[c];
          if (mark && m > 0) {
            short *o = &g->owner[3 * node + c];
            if (fixed)
              *o = (short)-(b + 1);
            else if (*o >= 0)
              *o = (short)(b + 1);
          }
          vel[3 * node + c] = vset;
        }
      }
#undef DIST
#undef INSIDE
#undef NODE
    }
  }
}

/* The forces of the dependent dofs moved onto their anchors (see
 * apply_bcs_once), into g->fold. */
static void fold_bcs(mpm_sim *sim) {
  mpm_grid *g = &sim->grid;
  size_t n3 = 3 * (size_t)g->n_nodes;
  memset(g->fold, 0, n3 * sizeof(double));
  memset(g->fold_out, 0, n3 * sizeof(double));
  if (sim->n_bcs == 0) return;
  memset(g->owner, 0, n3 * sizeof(short));
  apply_bcs_once(sim, NULL, false, g->force, g->fold);
}

/* The conditions, twice: where two faces meet, one face's mirror reads
 * nodes the other sets, so the second pass sees them set.  With
 * reactions, then one pass over the constrained dofs: the force each
 * condition applies, R = m (v - v0) / dt - f - f_in + f_out, with f_in the
 * force folded onto the dof and f_out the force it folded onto its anchor
 * (the anchors' share of the internal force, not a reaction), counted
 * once per dof (to the condition that prescribes it, else the one that
 * reflects it); and the work of the conditions, m (v - v0) / dt - f times
 * (v0 + v) / 2 dt, over the constrained dofs and the anchors. */
static void apply_bcs(mpm_sim *sim, double *vel, bool reactions) {
  mpm_grid *g = &sim->grid;
  if (sim->n_bcs == 0) return;
  if (reactions) memset(g->owner, 0, 3 * sizeof(short) * (size_t)g->n_nodes);
  apply_bcs_once(sim, vel, false, NULL, NULL);
  apply_bcs_once(sim, vel, reactions, NULL, NULL);
  if (!reactions) return;
  for (int b = 0; b < sim->n_bcs; b++)
    for (int c = 0; c < 3; c++) sim->bcs[b].reaction[c] = 0;
  double work = 0;
  const double dt = sim->dt;
  for (long i = 0; i < 3 * g->n_nodes; i++) {
    short o = g->owner[i];
    double fold = g->fold ? g->fold[i] : 0.0;
    if (!o && fold == 0) continue;
    long node = i / 3;
    if (!(g->mass[node] > 0)) continue;
    double R = g->mass[node] * (vel[i] - g->vel0[i]) / dt - g->force[i];
    if (o)
      sim->bcs[(o > 0 ? o : -o) - 1].reaction[i % 3] +=
          R - fold + (g->fold_out ? g->fold_out[i] : 0.0);
    work += R * 0.5 * (g->vel0[i] + vel[i]) * dt;
  }
  sim->external_work += work;
}

/* ---- grid stages -------------------------------------------------------- */

static void stage_gravity(mpm_sim *sim, int arg) {
  (void)arg;
  mpm_grid *g = &sim->grid;
  const double *gv = sim->scene->gravity;
  /* Its work is counted in the grid update, with the mean velocity. */
  PM_OMP(parallel for schedule(static))
  for (long i = 0; i < g->n_nodes; i++) {
    double m = g->mass[i];
    if (m <= 0) continue;
    for (int c = 0; c < 3; c++) g->force[3 * i + c] += m * gv[c];
  }
}

/* Viscous boundary: the traction t = -rho (c_p v_n n + c_s v_t) on the
 * face, with rho c the mass-weighted mean of the particles' impedances at
 * the node, spread as f_I = N_I(face) t A: the face node and (quadratic)
 * the node inside it; the light node beyond is left out. */
static void stage_absorbing(mpm_sim *sim, int arg) {
  (void)arg;
  mpm_grid *g = &sim->grid;
  double area = g->node_volume * g->inv_h, lost = 0;
  for (int b = 0; b < sim->n_bcs; b++) {
    const mpm_bc *bc = &sim->bcs[b];
    if (!bc->absorbing) continue;
    int a = bc->axis;
    const bool quad = g->shape == PM_SHAPE_QUADRATIC;
    const double share[2] = {quad ? 0.75 : 1.0, quad ? 0.125 : 0.0};
    PM_OMP(parallel for schedule(static) reduction(+ : lost))
    for (long k = 0; k < bc->n_cols; k++)
      for (int l = 0; l < 2; l++) {
        if (share[l] == 0) continue;
        long node = bc->col[k] - (long)bc->outward * l * g->stride[a];
        double m = g->mass[node];
        if (m <= 0) continue;
        double zp = share[l] * g->impedance[2 * node] / m;
        double zs = share[l] * g->impedance[2 * node + 1] / m;
        const double *p = g->mom + 3 * node;
        for (int c = 0; c < sim->dim; c++) {
          double v = p[c] / m, z = c == a ? zp : zs;
          /* Implicit in v so that a light node cannot overshoot. */
          double keep = 1.0 / (1.0 + sim->dt * z * area / m);
          double f = -(1.0 - keep) * (m * v / sim->dt + g->force[3 * node + c]);
          g->force[3 * node + c] += f;
          lost -= f * v * sim->dt;
        }
      }
  }
  sim->dissipated += lost;
}

/* Mass-proportional damping (quasi-static): f -= c m v. */
static void stage_damping(mpm_sim *sim, int arg) {
  (void)arg;
  mpm_grid *g = &sim->grid;
  if (g->force_prev) {
    /* Dynamic relaxation: c = 2 sqrt(v.K v / v.M v), with K v estimated by
     * the change of the internal force over the step. */
    /* Free dofs only (those the conditions set in the previous step are
     * left out: their forces change by what the conditions impose). */
    double num = 0, den = 0;
    PM_OMP(parallel for schedule(static) reduction(+ : num, den))
    for (long i = 0; i < g->n_nodes; i++) {
      double m = g->mass[i];
      if (m <= 0) continue;
      for (int c = 0; c < 3; c++) {
        double v = g->mom[3 * i + c] / m;
        if (!g->owner || !g->owner[3 * i + c]) {
          num += v * (g->force_prev[3 * i + c] - g->force[3 * i + c]);
          den += m * v * v;
        }
        g->force_prev[3 * i + c] = g->force[3 * i + c];
      }
    }
    if (den > 0 && sim->step > 0) {
      double lambda = num / (sim->dt * den);
      double c = lambda > 0 ? 2.0 * sqrt(lambda) : 0.0;
      /* Keep the rate well within what the step resolves. */
      double cmax = 0.2 / sim->dt;
      sim->damping = fmin(c, cmax);
    }
  }
  double c = sim->damping, lost = 0;
  PM_OMP(parallel for schedule(static) reduction(+ : lost))
  for (long i = 0; i < g->n_nodes; i++) {
    double m = g->mass[i];
    if (m <= 0) continue;
    for (int k = 0; k < 3; k++) {
      double v = g->mom[3 * i + k] / m;
      g->force[3 * i + k] -= c * m * v;
      lost += c * m * v * v * sim->dt;
    }
  }
  sim->dissipated += lost;
}

/* Nodal velocities before and after the Lagrangian update, null
 * directions, boundary conditions, reactions and the residual. */
static void stage_grid_update(mpm_sim *sim, int arg) {
  (void)arg;
  mpm_grid *g = &sim->grid;
  const unsigned nul = sim->scene->mpm.null_velocity;
  const double dt = sim->dt;
  const double *fold = g->fold;
  if (fold) fold_bcs(sim);
  PM_OMP(parallel for schedule(static))
  for (long i = 0; i < g->n_nodes; i++) {
    double m = g->mass[i];
    for (int k = 0; k < 3; k++) {
      double v0 = 0, v1 = 0;
      if (m > 0 && !(nul >> k & 1u)) {
        v0 = g->mom[3 * i + k] / m;
        double f = g->force[3 * i + k] + (fold ? fold[3 * i + k] : 0.0);
        v1 = v0 + dt * f / m;
      }
      g->vel0[3 * i + k] = v0;
      g->vel_new[3 * i + k] = v1;
    }
  }
  apply_bcs(sim, g->vel_new, true);
  if (sim->scene->has_gravity) {
    /* The work of gravity over the step, with the mean velocity. */
    const double *gv = sim->scene->gravity;
    double work = 0;
    PM_OMP(parallel for schedule(static) reduction(+ : work))
    for (long i = 0; i < g->n_nodes; i++) {
      double m = g->mass[i];
      if (m <= 0) continue;
      for (int k = 0; k < 3; k++)
        work += m * gv[k] * 0.5 * (g->vel0[3 * i + k] + g->vel_new[3 * i + k]);
    }
    sim->external_work += work * dt;
  }
  if (sim->scene->time.qs == PM_QS_NONE) return;
  /* Quasi-static residual: the out-of-balance force (without the damping)
   * on the free dofs, relative to the reactions (or, with none, to the
   * forces on all dofs). */
  const double c = sim->damping;
  double r2 = 0, f2 = 0;
  PM_OMP(parallel for schedule(static) reduction(+ : r2, f2))
  for (long i = 0; i < g->n_nodes; i++) {
    double m = g->mass[i];
    if (m <= 0) continue;
    for (int k = 0; k < 3; k++) {
      if (nul >> k & 1u) continue;
      double f = g->force[3 * i + k] + c * m * g->vel0[3 * i + k] +
                 (fold ? fold[3 * i + k] : 0.0);
      f2 += f * f;
      if (!g->owner || !g->owner[3 * i + k]) r2 += f * f;
    }
  }
  double scale = 0;
  for (int b = 0; b < sim->n_bcs; b++)
    for (int k = 0; k < 3; k++)
      scale += sim->bcs[b].reaction[k] * sim->bcs[b].reaction[k];
  if (!(scale > 0)) scale = f2;
  sim->residual = scale > 0 ? sqrt(r2 / scale) : 0.0;
}

/* USF: the velocity before the update, with its conditions, for the
 * stress. */
static void stage_grid_velocity(mpm_sim *sim, int arg) {
  (void)arg;
  mpm_grid *g = &sim->grid;
  const unsigned nul = sim->scene->mpm.null_velocity;
  PM_OMP(parallel for schedule(static))
  for (long i = 0; i < g->n_nodes; i++) {
    double m = g->mass[i];
    for (int k = 0; k < 3; k++)
      g->vel[3 * i + k] =
          (m > 0 && !(nul >> k & 1u)) ? g->mom[3 * i + k] / m : 0.0;
  }
  apply_bcs(sim, g->vel, false);
}

/* ---- grid to particle --------------------------------------------------- */

static void stage_g2p(mpm_sim *sim, int arg) {
  (void)arg;
  const mpm_grid *g = &sim->grid;
  const double flip = sim->scene->mpm.flip, dt = sim->dt;
  PM_OMP(parallel for schedule(static))
  for (long p = 0; p < sim->n; p++) {
    mpm_stencil st;
    mpm_stencil_at(g, sim->x + 3 * p, &st);
    double vn[3] = {0, 0, 0}, dv[3] = {0, 0, 0};
    for (int c = 0; c < st.n[2]; c++)
      for (int b = 0; b < st.n[1]; b++) {
        double wbc = st.w[1][b] * st.w[2][c];
        long row = st.base + b * g->stride[1] + c * g->stride[2];
        for (int a = 0; a < st.n[0]; a++) {
          double w = st.w[0][a] * wbc;
          const double *v1 = g->vel_new + 3 * (row + a);
          const double *v0 = g->vel0 + 3 * (row + a);
          for (int k = 0; k < 3; k++) {
            vn[k] += w * v1[k];
            dv[k] += w * (v1[k] - v0[k]);
          }
        }
      }
    double *v = sim->v + 3 * p;
    for (int k = 0; k < 3; k++) {
      v[k] = flip * (v[k] + dv[k]) + (1.0 - flip) * vn[k];
      sim->dx[3 * p + k] = dt * vn[k];
    }
    if (!isfinite(v[0] + v[1] + v[2]))
      fail_at(sim, p, "velocity is not finite (|v|^2 = %g, v_x = %g)",
              v[0] * v[0] + v[1] * v[1] + v[2] * v[2], v[0]);
  }
}

/* MUSL: momentum remapped from the updated particle velocities. */
static void stage_remap(mpm_sim *sim, int arg) {
  (void)arg;
  p2g_mode(sim, P2G_MOM);
  stage_grid_velocity(sim, 0);
}

/* Positions: x += dx, and a check that the particle stays on the grid. */
static void stage_move(mpm_sim *sim, int arg) {
  (void)arg;
  const mpm_grid *g = &sim->grid;
  PM_OMP(parallel for schedule(static))
  for (long p = 0; p < sim->n; p++) {
    double *x = sim->x + 3 * p;
    for (int k = 0; k < 3; k++) x[k] += sim->dx[3 * p + k];
    for (int k = 0; k < g->dim; k++)
      if (!(x[k] >= g->lo[k] && x[k] < g->hi[k]))
        fail_at(sim, p,
                "left the grid (%g is outside the grid's reach along this "
                "axis, which ends at %g): enlarge domain.box",
                x[k], x[k] < g->lo[k] ? g->lo[k] : g->hi[k]);
  }
}

/* ---- stress ------------------------------------------------------------- */

/* Velocity gradient L_ij = sum_I v_Ii dS_I/dx_j at particle p. */
static inline void velocity_gradient(const mpm_grid *g, const double *vel,
                                     const double x[3], double L[9]) {
  mpm_stencil st;
  mpm_stencil_at(g, x, &st);
  memset(L, 0, 9 * sizeof(double));
  for (int c = 0; c < st.n[2]; c++)
    for (int b = 0; b < st.n[1]; b++) {
      double wbc = st.w[1][b] * st.w[2][c];
      double gy = st.dw[1][b] * st.w[2][c];
      double gz = st.w[1][b] * st.dw[2][c];
      long row = st.base + b * g->stride[1] + c * g->stride[2];
      for (int a = 0; a < st.n[0]; a++) {
        double gr[3] = {st.dw[0][a] * wbc, st.w[0][a] * gy, st.w[0][a] * gz};
        const double *v = vel + 3 * (row + a);
        for (int i = 0; i < 3; i++)
          for (int j = 0; j < 3; j++) L[3 * i + j] += v[i] * gr[j];
      }
    }
}

static inline void sym_skew(const double L[9], double D[9], double W[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      D[3 * i + j] = 0.5 * (L[3 * i + j] + L[3 * j + i]);
      W[3 * i + j] = 0.5 * (L[3 * i + j] - L[3 * j + i]);
    }
}

/* Solids: F <- (I + dt L) F; neo-Hookean from F, or the objective
 * (Jaumann) rate form of linear elasticity. */
static void stage_stress_solid(mpm_sim *sim, int gi) {
  const mpm_group *gr = &sim->group[gi];
  const mpm_grid *g = &sim->grid;
  const double dt = sim->dt, h = g->h;
  const pm_material *mat = &gr->solid;
  const bool rate = mat->model->rate != NULL;
  const double jmin = sim->scene->stability.min_jacobian;
  const bool av = gr->q != NULL;
  double maxdiv = 0;
  PM_OMP(parallel for schedule(static) reduction(max : maxdiv))
  for (long p = gr->begin; p < gr->end; p++) {
    long k = p - gr->begin;
    double L[9], D[9], W[9], A[9], Fn[9];
    velocity_gradient(g, g->vel_stress, sim->x + 3 * p, L);
    double *F = gr->F + 9 * k, *sig = sim->sigma + 9 * p;
    for (int i = 0; i < 9; i++) A[i] = dt * L[i];
    A[0] += 1;
    A[4] += 1;
    A[8] += 1;
    pm_t_mul(A, F, Fn);
    memcpy(F, Fn, sizeof Fn);
    double J = pm_t_det(F);
    if (!(J > jmin) || !isfinite(J)) {
      fail_at(sim, p,
              J > 0 ? "volume ratio J = %g <= stability.min_jacobian = %g"
                    : "volume ratio J = %g <= 0: inverted (bound %g)",
              J, jmin);
      continue;
    }
    sim->vol[p] = sim->vol0[p] * J;
    sym_skew(L, D, W);
    double trD = D[0] + D[4] + D[8];
    maxdiv = fmax(maxdiv, fabs(trD));
    if (rate) {
      mat->model->rate(mat, D, W, dt, sig);
      if (av) sig[0] += gr->q[k], sig[4] += gr->q[k], sig[8] += gr->q[k];
    } else {
      double P[9];
      if (!pm_material_stress(mat, F, NULL, P, NULL, NULL)) {
        fail_at(sim, p, "stress is not finite (J = %g, |F| = %g)", J,
                pm_t_norm(F));
        continue;
      }
      /* sigma = P F^T / J */
      for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
          sig[3 * i + j] = (P[3 * i] * F[3 * j] + P[3 * i + 1] * F[3 * j + 1] +
                            P[3 * i + 2] * F[3 * j + 2]) /
                           J;
    }
    if (av) {
      double rho = sim->mass[p] / sim->vol[p];
      double q = pm_artificial_viscosity(gr->c0, gr->c1, rho, h,
                                         sqrt(mat->wave_modulus / rho), trD);
      gr->q[k] = q;
      sig[0] -= q;
      sig[4] -= q;
      sig[8] -= q;
    }
  }
  if (maxdiv > sim->max_div) sim->max_div = maxdiv;
}

/* Fluids (eqs. 23-33): density by eq. 25, then the internal energy and the
 * pressure, iteratively (steps 1-6) or from the previous stress. */
static void stage_stress_fluid(mpm_sim *sim, int gi) {
  const mpm_group *gr = &sim->group[gi];
  const mpm_grid *g = &sim->grid;
  const pm_fluid *fl = &gr->fluid_props;
  const double dt = sim->dt, h = g->h;
  const bool iterative = sim->scene->mpm.energy_update == PM_ENERGY_ITERATIVE;
  const double tol = sim->scene->mpm.energy_tolerance;
  const int cap = sim->scene->mpm.max_iterations;
  const bool av = gr->q != NULL;
  double maxdiv = 0;
  int itmax = 0;
  long capped = 0;
  PM_OMP(parallel for schedule(static) reduction(max : maxdiv, itmax) \
         reduction(+ : capped))
  for (long p = gr->begin; p < gr->end; p++) {
    long k = p - gr->begin;
    double L[9], D[9], W[9], tau[9];
    velocity_gradient(g, g->vel_stress, sim->x + 3 * p, L);
    sym_skew(L, D, W);
    double trD = D[0] + D[4] + D[8];
    maxdiv = fmax(maxdiv, fabs(trD));
    double den = 1.0 + dt * trD;
    if (!(den > 0)) {
      fail_at(sim, p,
              "density update failed: 1 + dt div v = %g <= 0 (div v = %g "
              "1/s)",
              den, trD);
      continue;
    }
    double rho = gr->rho[k] / den; /* eq. 25 */
    double *sig = sim->sigma + 9 * p;
    pm_fluid_viscous_stress(fl, D, tau);
    double a = pm_eos_sound_speed(fl, rho, gr->pressure[k]);
    double q =
        av ? pm_artificial_viscosity(gr->c0, gr->c1, rho, h, a, trD) : 0.0;
    /* sigma : D = tau : D - (P + q) tr D */
    double tauD = pm_t_ddot(tau, D);
    double e0 = gr->energy[k], c = dt / rho;
    double e = e0 + c * pm_t_ddot(sig, D); /* eq. 27 */
    double P = pm_eos_pressure(fl, rho, e);
    if (iterative) {
      double work_prev = 0, work = 0;
      int m = 1;
      for (;; m++) {
        P = pm_eos_pressure(fl, rho, e);       /* eq. 28 */
        work = tauD - (P + q) * trD;           /* eq. 29 */
        double e_next = m == 1 ? e0 + c * work /* eq. 30 */
                               : e0 + c * 0.5 * (work_prev + work);
        double change = fabs(e_next - e);
        work_prev = work;
        e = e_next;
        if (change <= tol * (fabs(e) + fabs(e0)) || change == 0) break;
        if (m >= cap) {
          capped++;
          break;
        }
      }
      /* Eq. 31: the stress of the last iteration. */
      if (m > itmax) itmax = m;
    } else {
      itmax = itmax > 1 ? itmax : 1;
    }
    if (!iterative) P = pm_eos_pressure(fl, rho, e);
    if (!(P + fl->p_inf > 0) || !isfinite(e)) {
      /* No real sound speed: the state has left the equation of state
       * (cavitation, or an energy driven negative). */
      fail_at(sim, p,
              "pressure %g Pa <= -p_inf: no sound speed (internal energy %g "
              "J/kg)",
              P, e);
      continue;
    }
    gr->rho[k] = rho;
    gr->energy[k] = e;
    gr->pressure[k] = P;
    if (av) gr->q[k] = q;
    sim->vol[p] = sim->mass[p] / rho;
    for (int i = 0; i < 9; i++) sig[i] = tau[i];
    sig[0] -= P + q;
    sig[4] -= P + q;
    sig[8] -= P + q;
  }
  if (maxdiv > sim->max_div) sim->max_div = maxdiv;
  if (itmax > sim->iter_max_step) sim->iter_max_step = itmax;
  sim->iter_capped_step += capped;
}

/* ---- stable step -------------------------------------------------------- */

double mpm_stable_dt(const mpm_sim *sim) {
  const mpm_grid *g = &sim->grid;
  const double h = g->h, div = sim->max_div_prev;
  double worst = 0; /* largest effective speed */
  for (int gi = 0; gi < sim->n_groups; gi++) {
    const mpm_group *gr = &sim->group[gi];
    /* Dynamic viscosity of the viscous term; over the particle's density. */
    double mu_v = gr->fluid ? 2 * gr->fluid_props.viscosity +
                                  fabs(gr->fluid_props.bulk_viscosity)
                            : 0.0;
    double w = 0;
    PM_OMP(parallel for schedule(static) reduction(max : w))
    for (long p = gr->begin; p < gr->end; p++) {
      double cp, cs;
      wave_speeds(sim, gr, p, &cp, &cs);
      const double *v = sim->v + 3 * p;
      double nu = mu_v * sim->vol[p] / sim->mass[p];
      double Q = gr->c1 * cp + gr->c0 * h * div + 2.0 * nu / h;
      double speed = Q + sqrt(Q * Q + cp * cp) +
                     sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      w = fmax(w, speed);
    }
    worst = fmax(worst, w);
  }
  return worst > 0 ? sim->scene->time.dt_safety * h / worst : INFINITY;
}

static void stage_time_step(mpm_sim *sim, int arg) {
  (void)arg;
  sim->dt_stable = mpm_stable_dt(sim);
  if (!isfinite(sim->dt_stable)) {
    fail_at(sim, 0,
            "no stable step: no particle has a wave speed or a velocity "
            "(%g; %g)",
            sim->dt_stable, sim->t);
    return;
  }
  sim->dt = sim->dt_stable;
  double left = sim->scene->time.end - sim->t;
  if (left > 0 && sim->dt > left) sim->dt = left;
}

/* ---- energies ----------------------------------------------------------- */

void mpm_energies(const mpm_sim *sim, double *kinetic, double *strain,
                  double *internal) {
  double ke = 0, se = 0, ie = 0;
  PM_OMP(parallel for schedule(static) reduction(+ : ke))
  for (long p = 0; p < sim->n; p++) {
    const double *v = sim->v + 3 * p;
    ke += 0.5 * sim->mass[p] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  for (int gi = 0; gi < sim->n_groups; gi++) {
    const mpm_group *gr = &sim->group[gi];
    if (gr->fluid) {
      PM_OMP(parallel for schedule(static) reduction(+ : ie))
      for (long p = gr->begin; p < gr->end; p++)
        ie += sim->mass[p] * gr->energy[p - gr->begin];
    } else {
      PM_OMP(parallel for schedule(static) reduction(+ : se))
      for (long p = gr->begin; p < gr->end; p++) {
        double W =
            pm_material_energy(&gr->solid, gr->F + 9 * (p - gr->begin), NULL);
        se += sim->vol0[p] * W;
      }
    }
  }
  *kinetic = ke;
  *strain = se;
  *internal = ie;
}

/* ---- pipeline ----------------------------------------------------------- */

static mpm_stage *add(mpm_sim *sim, const char *name, mpm_stage_fn fn,
                      int arg) {
  PM_ASSERT(sim->n_stages < MPM_MAX_STAGES);
  mpm_stage *st = &sim->stage[sim->n_stages++];
  st->fn = fn;
  st->arg = arg;
  st->name = name;
  st->timer = pm_timers_add(&sim->timers, name);
  st->detail[0] = '\0';
  return st;
}

static void add_stress(mpm_sim *sim) {
  const pm_scene *s = sim->scene;
  for (int gi = 0; gi < sim->n_groups; gi++) {
    const mpm_group *gr = &sim->group[gi];
    mpm_stage *st;
    if (gr->fluid) {
      st = add(sim, "stress: fluid", stage_stress_fluid, gi);
      snprintf(
          st->detail, sizeof st->detail,
          "%s: density (eq. 25), %s EOS, %s energy update%s%s", gr->name,
          pm_eos_name(gr->fluid_props.eos),
          s->mpm.energy_update == PM_ENERGY_ITERATIVE ? "iterative (steps 1-6)"
                                                      : "non-iterative",
          gr->fluid_props.viscosity > 0 || gr->fluid_props.bulk_viscosity > 0
              ? ", viscous stress (eq. 23)"
              : "",
          gr->q ? ", artificial viscosity (eq. 32)" : "");
    } else {
      st = add(sim, "stress: solid", stage_stress_solid, gi);
      snprintf(st->detail, sizeof st->detail, "%s: %s%s", gr->name,
               gr->solid.model->rate ? "linear elastic, Jaumann rate form"
                                     : "neo-Hookean from F",
               gr->q ? ", artificial viscosity (eq. 32)" : "");
    }
  }
}

static void add_grid_forces(mpm_sim *sim) {
  const pm_scene *s = sim->scene;
  if (s->has_gravity) {
    mpm_stage *st = add(sim, "gravity", stage_gravity, 0);
    snprintf(st->detail, sizeof st->detail,
             "m g on the nodes, g = (%g, %g, %g)", s->gravity[0], s->gravity[1],
             s->gravity[2]);
  }
  if (sim->has_absorbing) {
    mpm_stage *st = add(sim, "absorbing boundaries", stage_absorbing, 0);
    snprintf(st->detail, sizeof st->detail,
             "viscous tractions rho (c_p v_n, c_s v_t) on absorbing faces");
  }
  if (s->time.qs != PM_QS_NONE) {
    mpm_stage *st = add(sim, "damping", stage_damping, 0);
    snprintf(st->detail, sizeof st->detail, "%s",
             s->time.qs == PM_QS_DYNAMIC_RELAXATION
                 ? "dynamic relaxation: adaptive mass-proportional damping"
                 : "fixed mass-proportional damping");
  }
}

void mpm_build_pipeline(mpm_sim *sim) {
  const pm_scene *s = sim->scene;
  mpm_stage *st;
  sim->n_stages = 0;
  if (sim->dt_fixed <= 0) {
    st = add(sim, "time step", stage_time_step, 0);
    snprintf(st->detail, sizeof st->detail,
             "dt = %g h / max(wave speed + |v|, with viscous terms)",
             s->time.dt_safety);
  }
  if (s->mpm.update == PM_UPDATE_USF) {
    st = add(sim, "p2g", p2g_mode, P2G_MASS | P2G_MOM);
    snprintf(st->detail, sizeof st->detail, "mass and momentum to the grid");
    st = add(sim, "grid velocity", stage_grid_velocity, 0);
    snprintf(st->detail, sizeof st->detail,
             "USF: velocities with conditions for the stress");
    add_stress(sim);
    st = add(sim, "p2g force", p2g_mode, P2G_FORCE);
    snprintf(st->detail, sizeof st->detail, "internal forces to the grid%s",
             sim->has_absorbing ? ", impedances" : "");
  } else {
    st = add(sim, "p2g", p2g_mode, P2G_MASS | P2G_MOM | P2G_FORCE);
    snprintf(st->detail, sizeof st->detail,
             "mass, momentum and internal force to the grid%s",
             sim->has_absorbing ? ", impedances" : "");
  }
  add_grid_forces(sim);
  st = add(sim, "grid update", stage_grid_update, 0);
  snprintf(st->detail, sizeof st->detail,
           "v^L = v + dt f / m, %d boundary condition%s%s", sim->n_bcs,
           sim->n_bcs == 1 ? "" : "s",
           s->mpm.null_velocity ? ", null directions" : "");
  st = add(sim, "g2p", stage_g2p, 0);
  snprintf(st->detail, sizeof st->detail,
           "particle velocities (FLIP %g / PIC %g)", s->mpm.flip,
           1 - s->mpm.flip);
  if (s->mpm.update == PM_UPDATE_MUSL) {
    st = add(sim, "remap", stage_remap, 0);
    snprintf(st->detail, sizeof st->detail,
             "MUSL: momentum from the updated particles");
  }
  if (s->mpm.update != PM_UPDATE_USF) add_stress(sim);
  st = add(sim, "move", stage_move, 0);
  snprintf(st->detail, sizeof st->detail, "positions x += dt v^L");
}

pm_err mpm_step(mpm_sim *sim) {
  sim->iter_max_step = 0;
  sim->iter_capped_step = 0;
  sim->max_div = 0;
  for (int k = 0; k < sim->n_stages; k++) {
    mpm_stage *st = &sim->stage[k];
    pm_timers_start(&sim->timers, st->timer);
    st->fn(sim, st->arg);
    pm_timers_stop(&sim->timers, st->timer);
    if (sim->fail.failed) {
      long p = sim->fail.particle;
      const double *x = sim->x + 3 * p;
      return PM_ERROR(PM_ERR_UNSTABLE,
                      "step %ld, t = %.6g s, stage %s: particle %ld at (%g, "
                      "%g, %g), started at (%g, %g, %g): %s",
                      sim->step + 1, sim->t + sim->dt, st->name, p, x[0], x[1],
                      x[2], sim->x0[3 * p], sim->x0[3 * p + 1],
                      sim->x0[3 * p + 2], sim->fail.cause);
    }
  }
  sim->t += sim->dt;
  sim->step++;
  sim->max_div_prev = sim->max_div;
  sim->iter_capped_total += sim->iter_capped_step;
  if (sim->iter_max_step > sim->iter_max_total)
    sim->iter_max_total = sim->iter_max_step;
  return PM_SUCCESS;
}
