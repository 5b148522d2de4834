/* mpm_implicit: quasi-static implicit MPM by Newton's method on the grid
 * (see mpm_implicit.h for the formulation): setup, queries and plan. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_estimate.h"
#include "mpm_exchange.h"
#include "mpm_implicit_impl.h"
#include "mpm_grip.h"
#include "mpm_traction.h"
#include "mpm_kind.h"
#include "pm_interrupt.h"
#include "pm_omp.h"
#include "pm_progress.h"
#include "pm_tensor.h"

/* ---- setup -------------------------------------------------------------- */

/* The outermost layer of particles at each condition's face (reset). */
static pm_err make_faces(mpm_implicit *im) {
  const mpm_model *m = im->m;
  PM_CALL(PM_ALLOC(im->face_ptr, m->n_bcs + 1, "face particles"));
  long total = 0;
  double *dmin = NULL;
  PM_CALL(PM_ALLOC(dmin, m->n_bcs + 1, "face distances"));
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    if (bc->grip) { /* a named surface's: the particles at it */
      total += bc->n_held;
      continue;
    }
    dmin[b] = INFINITY;
    for (long p = 0; p < im->n; p++)
      dmin[b] = fmin(dmin[b], fabs(m->x0[3 * p + bc->axis] - bc->plane));
    for (long p = 0; p < im->n; p++)
      total +=
          fabs(m->x0[3 * p + bc->axis] - bc->plane) <= dmin[b] + 1e-6 * im->g.h;
  }
  pm_err e = PM_ALLOC(im->face, total + 1, "face particles");
  if (e) {
    free(dmin);
    return e;
  }
  long k = 0;
  for (int b = 0; b < m->n_bcs; b++) {
    const mpm_bc *bc = &m->bcs[b];
    im->face_ptr[b] = k;
    if (bc->grip) {
      for (long q = 0; q < bc->n_held; q++) im->face[k++] = bc->held[q];
      continue;
    }
    for (long p = 0; p < im->n; p++)
      if (fabs(m->x0[3 * p + bc->axis] - bc->plane) <= dmin[b] + 1e-6 * im->g.h)
        im->face[k++] = p;
  }
  im->face_ptr[m->n_bcs] = k;
  free(dmin);
  return PM_SUCCESS;
}

/* The grid of the reset algorithm: the model's box with room on every side
 * for the largest prescribed displacement, plus a cell. */
static pm_err reset_grid(mpm_implicit *im, const pm_scene *s) {
  const mpm_model *m = im->m;
  double umax = 0;
  for (int b = 0; b < m->n_bcs; b++)
    for (int c = 0; c < im->dim; c++)
      umax = fmax(umax, mpm_bc_largest_displacement(s, b, c, 0));
  const double h = m->grid.h;
  const double room = (ceil(umax / h) + 1) * h;
  double lo[3], hi[3];
  for (int c = 0; c < 3; c++) {
    lo[c] = m->box_min[c] - (c < im->dim ? room : 0);
    hi[c] = m->box_max[c] + (c < im->dim ? room : 0);
  }
  return mpm_grid_init(&im->g, im->dim, m->grid.shape, h, lo, hi, s->path);
}

/* Poisson's ratio from which a material is near-incompressible. */
#define MPM_IMPLICIT_NEAR_INCOMPRESSIBLE_NU 0.45

/* Unknowns up to which the default linear solver is direct (MUMPS LU),
 * by dimension: above, GMRES with algebraic multigrid (GAMG with the
 * rigid-body near-null space).  On this project's cases the Krylov solver
 * stalls where the factorisation is cheap (docs/validation.md,
 * "Implicit MPM that never hangs"). */
#define MPM_IMPLICIT_DIRECT_MAX_2D 100000L
#define MPM_IMPLICIT_DIRECT_MAX_3D 30000L

/* Bytes of the grid solve's tangent with its LU factors or multigrid
 * hierarchy: on the nodes the bodies touch, dimension x (3 or 5)^dimension
 * entries an unknown (linear or quadratic basis).  Per entry, measured as
 * whole runs' peak memory above that of the run at the smallest grid
 * (docs/validation.md, "Bad disks, memory for solves, and signals"): the
 * LU 177 bytes in 2-D (I2, 8190 -> 32766 unknowns) and 156 in 3-D (F2,
 * quadratic, 700 -> 4200), taken as 200 at 30 000 unknowns in 2-D and
 * 4 200 in 3-D and growing with the fill: in 2-D as log n (nested
 * dissection's n log n), in 3-D as n^0.25, as FPM's (fpm_static.c);
 * multigrid 120, flat (FPM's).  The matrix-free operator stores none.
 * On top, PETSc's and MPI's own: F2 at 700 unknowns peaked at 107 MiB
 * with 0.7 MiB of model and state. */
#define MPM_IMPLICIT_BASE_BYTES (100.0 * 1048576.0)
static double solve_bytes(const pm_scene *s, const mpm_settings *ms) {
  const int dim = s->dimension;
  const double n = dim * mpm_estimate_active_nodes(s),
               width = ms->shape == MPM_BASIS_QUADRATIC ? 5 : 3,
               nnz = n * dim * pow(width, dim);
  if (ms->implicit.op == MPM_OP_MATRIX_FREE) return MPM_IMPLICIT_BASE_BYTES;
  const long cap =
      dim == 3 ? MPM_IMPLICIT_DIRECT_MAX_3D : MPM_IMPLICIT_DIRECT_MAX_2D;
  const pm_newton_linear linear =
      pm_scene_has(s, "time.quasi_static.linear_solver")
          ? pm_newton_linear_of(s->time.qs_linear)
      : n <= (double)cap ? PM_NEWTON_DIRECT
                         : PM_NEWTON_GMRES_GAMG;
  if (linear != PM_NEWTON_DIRECT) return MPM_IMPLICIT_BASE_BYTES + 120.0 * nnz;
  const double fill =
      dim == 3 ? pow(n / 4200.0, 0.25) : log2(fmax(n, 2)) / log2(30000.0);
  return MPM_IMPLICIT_BASE_BYTES + 200.0 * fill * nnz;
}

size_t mpm_implicit_estimate_bytes(const pm_scene *s, long *points) {
  const double bytes = (double)mpm_estimate_bytes(s, points) +
                       solve_bytes(s, mpm_scene_settings(s));
  return bytes < (double)SIZE_MAX ? (size_t)bytes : SIZE_MAX;
}

/* The linear solver: the scene's, else direct below the size above and
 * GMRES + GAMG beyond; a multigrid solve is bounded (relative residual
 * 1e-6 of the preconditioned one, 1000 iterations: a failure then cuts the
 * load step with its reason instead of iterating for minutes; Jacobi and
 * ILU keep 1e-10 and 20 000, the paper's CG + Jacobi needing thousands). */
static void choose_linear(mpm_implicit *im, bool given) {
  pm_newton_options *o = &im->opt;
  const long cap =
      im->dim == 3 ? MPM_IMPLICIT_DIRECT_MAX_3D : MPM_IMPLICIT_DIRECT_MAX_2D;
  if (given) {
    snprintf(im->why_linear, sizeof im->why_linear,
             "time.quasi_static.linear_solver");
  } else {
    o->linear = im->nunk_all <= cap ? PM_NEWTON_DIRECT : PM_NEWTON_GMRES_GAMG;
    snprintf(im->why_linear, sizeof im->why_linear,
             "default: %ld unknowns %s %ld, where the factorisation %s",
             im->nunk_all, im->nunk_all <= cap ? "<=" : ">", cap,
             im->nunk_all <= cap ? "is faster and never stalls"
                                 : "costs too much memory and time");
  }
  if (o->linear == PM_NEWTON_GMRES_GAMG || o->linear == PM_NEWTON_CG_GAMG) {
    o->linear_rtol = 1e-6;
    o->linear_max_iter = 1000;
  }
}

/* F-bar by default: on for a near-incompressible material (the largest
 * Poisson ratio at or above the threshold), where the particles' own J
 * locks (the implicit MPM's locking beam: 52% too stiff without it, +2.9%
 * with it, docs/validation.md); mpm.fbar given decides.  Its tangent is
 * assembled (mpm_implicit_fbar_tangent.c), as cheap as the plain one.
 * Records why in why_fbar, for plan. */
static void choose_fbar(mpm_implicit *im, const pm_scene *s) {
  double nu = 0;
  for (int gi = 0; gi < im->m->n_groups; gi++)
    nu = fmax(nu, im->view[gi].mat->poisson_ratio);
  if (pm_scene_has(s, "mpm.fbar")) {
    im->fbar = mpm_scene_settings(s)->fbar == MPM_FBAR_CELL;
    snprintf(im->why_fbar, sizeof im->why_fbar, "mpm.fbar: %s",
             im->fbar ? "cell" : "none");
    return;
  }
  im->fbar = nu >= MPM_IMPLICIT_NEAR_INCOMPRESSIBLE_NU;
  if (im->fbar)
    snprintf(im->why_fbar, sizeof im->why_fbar,
             "cell (default): nu = %.4g is near-incompressible (>= %.2f), "
             "where the particles' own J locks; mpm.fbar: none turns it off",
             nu, MPM_IMPLICIT_NEAR_INCOMPRESSIBLE_NU);
  else
    snprintf(im->why_fbar, sizeof im->why_fbar,
             "off: nu = %.4g < %.2f, no volumetric locking to cure", nu,
             MPM_IMPLICIT_NEAR_INCOMPRESSIBLE_NU);
}

pm_err mpm_implicit_create(const pm_scene *s, const mpm_model *m, mpm_state *st,
                           mpm_implicit **out) {
  pm_err ret = PM_SUCCESS;
  mpm_implicit *im = NULL;
  *out = NULL;
  const mpm_settings *ms = mpm_scene_settings(s);
  PM_TRY(PM_ALLOC(im, 1, "implicit MPM"));
  im->s = s;
  im->m = m;
  im->st = st;
  im->n = m->n;
  im->ranks = mpm_xc_shared(m);
  im->dim = m->dim;
  im->mode = (mpm_grid_mode)ms->implicit.grid;
  im->matrix_free = ms->implicit.op == MPM_OP_MATRIX_FREE;
  im->jmin = s->stability.min_jacobian;
  im->has_gravity = m->opt.has_gravity;
  for (int c = 0; c < 3; c++) im->gravity[c] = m->opt.gravity[c];
  im->lam1 = 1;
  im->built_for = -1;
  PM_TRY(PM_ALLOC(im->grp, im->n, "particle groups"));
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    if (!mpm_solid_access(g, st, &im->view[gi])) {
      char p[64];
      ret =
          pm_scene_fail(s, PM_PATH(p, "materials.%d.model", g->material), false,
                        "expected a solid for method mpm-implicit, got %s "
                        "particles of material %s",
                        g->kind->name, g->name);
      goto done;
    }
    im->group_begin[gi] = g->begin;
    for (long p = g->begin; p < g->end; p++) im->grp[p] = (unsigned char)gi;
  }
  choose_fbar(im, s);
  im->threads = pm_omp_threads();
  PM_TRY(PM_ALLOC(im->tmin, im->threads, "thread minima"));
  if (im->fbar) PM_TRY(PM_ALLOC(im->wbar, im->n, "F-bar energies"));
  if (im->mode == MPM_GRID_KEPT) {
    im->g = m->grid;
    im->xb = m->x0;
  } else {
    PM_TRY(reset_grid(im, s));
    im->xb = st->x;
    im->base_f = true;
    PM_TRY(make_faces(im));
  }
  im->w = im->g.width;
  im->nb = 2 * im->w - 1;
  im->nnb = im->dim == 3 ? im->nb * im->nb * im->nb : im->nb * im->nb;
  im->sn = im->dim == 3 ? im->w * im->w * im->w : im->w * im->w;
  for (int a = 0; a < im->sn; a++)
    for (int b = 0; b < im->sn; b++) {
      int sa[3] = {a % im->w, (a / im->w) % im->w, a / (im->w * im->w)};
      int sb[3] = {b % im->w, (b / im->w) % im->w, b / (im->w * im->w)};
      int k = 0, mul = 1;
      for (int c = 0; c < im->dim; c++, mul *= im->nb)
        k += (sb[c] - sa[c] + im->w - 1) * mul;
      im->soff[a][b] = k;
    }
  const long nn = im->g.n_nodes;
  PM_TRY(PM_ALLOC(im->order, im->n, "particle order"));
  PM_TRY(PM_ALLOC(im->bucket, nn + 1, "particle buckets"));
  PM_TRY(PM_ALLOC(im->cbuck, nn, "bucket colours"));
  PM_TRY(PM_ALLOC(im->active, nn, "active nodes"));
  PM_TRY(PM_ALLOC(im->dof, 3 * nn, "grid dofs"));
  if (im->ranks) PM_TRY(PM_ALLOC(im->gnum, 3 * nn, "global dofs"));
  PM_TRY(PM_ALLOC(im->nb_off, nn * im->nnb, "neighbour offsets"));
  PM_TRY(PM_ALLOC(im->u, 3 * nn, "nodal displacements"));
  PM_TRY(PM_ALLOC(im->du, 3 * nn, "nodal directions"));
  PM_TRY(PM_ALLOC(im->f, 3 * nn, "nodal forces"));
  PM_TRY(PM_ALLOC(im->df, 3 * nn, "nodal force changes"));
  PM_TRY(PM_ALLOC(im->reaction, 3 * m->n_bcs + 1, "reactions"));
  if (im->mode == MPM_GRID_KEPT && mpm_grips_count(m->bcs, m->n_bcs) > 0)
    PM_TRY(PM_ALLOC(im->grip_mass, 2 * nn, "held node masses"));
  PM_TRY(PM_ALLOC(im->trac_at, 6 * mpm_tractions_points(m, st->x, NULL) + 1,
                  "traction points"));
  mpm_tractions_points(m, st->x, im->trac_at);
  /* Newton's settings */
  pm_newton_options *o = &im->opt;
  *o = pm_newton_options_default();
  o->max_iter = (int)s->time.qs_max_iterations;
  im->opt_steps = (int)s->time.qs_load_steps;
  o->load_steps = im->mode == MPM_GRID_KEPT ? im->opt_steps : 1;
  if (ms->implicit.convergence == MPM_CONV_PAPER) {
    o->rtol = 0;
    o->dtol = ms->implicit.dtol;
    o->etol = ms->implicit.etol;
    o->all_criteria = true;
  } else {
    o->rtol = s->time.qs_tolerance;
  }
  const bool linear_given = pm_scene_has(s, "time.quasi_static.linear_solver");
  o->linear = linear_given ? pm_newton_linear_of(s->time.qs_linear)
                           : PM_NEWTON_DIRECT; /* chosen by size below */
  if (im->matrix_free) {
    if (pm_scene_has(s, "time.quasi_static.linear_solver") &&
        o->linear != PM_NEWTON_CG_JACOBI) {
      ret = pm_scene_fail(s, "time.quasi_static.linear_solver", false,
                          "expected cg-jacobi with mpm.implicit.operator "
                          "matrix-free (its preconditioner is the tangent's "
                          "diagonal)");
      goto done;
    }
    o->linear = PM_NEWTON_CG_JACOBI;
    o->op = PM_NEWTON_MATRIX_FREE_CHEAP_PC;
  }
  /* Each step starts from the last two states extrapolated (the first
   * from the tangent predictor): a step's first state is then near
   * equilibrium, where the tangent is positive definite, rather than with
   * the prescribed nodes moved alone, where near-incompressible
   * particles by the face make it indefinite and CG breaks down. */
  o->predictor = true;
  o->linear_rtol = 1e-10;
  o->linear_max_iter = 20000;
  o->petsc_options = s->time.qs_solver_options;
  o->line_search =
      pm_newton_line_search_of(s->time.qs_line_search, PM_LINE_SEARCH_BT);
  if (im->mode == MPM_GRID_RESET) im->lam1 = 1.0 / im->opt_steps;
  mpm_implicit_make_buckets(im);
  PM_TRY(mpm_implicit_make_dofs(im));
  PM_TRY(pm_interrupt_check("while setting up the implicit MPM's grid"));
  if (!im->matrix_free) choose_linear(im, linear_given);
  /* An absolute floor on the residual: a hundred times its roundoff, eps
   * times the stiffest material's P-wave modulus times a node's share of
   * a face (h^(d-1)), over the unknowns.  Below it the relative test
   * cannot be met (the volumetric term of a nearly incompressible solid
   * alone carries K (J - 1) with J - 1 from det F). */
  double M = 0;
  for (int gi = 0; gi < m->n_groups; gi++)
    M = fmax(M, im->view[gi].mat->wave_modulus);
  o->atol = 100 * DBL_EPSILON * M * pow(m->grid.h, im->dim - 1) *
            sqrt((double)im->nunk_all);
  PM_TRY(mpm_implicit_make_solver(im));
  im->built_for = 0;
  if (im->mode == MPM_GRID_KEPT) PM_TRY(pm_load_state_init(&im->ls, im->nunk));
  /* the initial state's reactions (zero load) */
  for (int b = 0; b < 3 * m->n_bcs; b++) im->reaction[b] = 0;
  *out = im;
  im = NULL;
done:
  mpm_implicit_destroy(im);
  return ret;
}

void mpm_implicit_destroy(mpm_implicit *im) {
  if (!im) return;
  pm_newton_destroy(&im->solver);
  pm_load_state_free(&im->ls);
  free(im->grp);
  free(im->trac_at);
  free(im->tmin);
  free(im->wbar);
  free(im->order);
  free(im->bucket);
  free(im->cbuck);
  free(im->active);
  free(im->dof);
  free(im->gnum);
  free(im->ghost);
  free(im->unk_dof);
  free(im->pre_dof);
  free(im->pre_val);
  free(im->pre_bc);
  free(im->pre_anchor);
  free(im->pre_t);
  free(im->nb_off);
  free(im->pat_ptr);
  free(im->pat_idx);
  free(im->pc_ptr);
  free(im->pc_idx);
  free(im->near_null);
  free(im->face_ptr);
  free(im->face);
  free(im->u);
  free(im->du);
  free(im->f);
  free(im->df);
  free(im->diag);
  free(im->x_unk);
  free(im->x_held);
  free(im->whole);
  free(im->reaction);
  free(im->grip_mass);
  free(im);
}

const double *mpm_implicit_reactions(const mpm_implicit *im) {
  return im->reaction;
}
double mpm_implicit_residual(const mpm_implicit *im) { return im->residual; }
bool mpm_implicit_strain_energy(const mpm_implicit *im, double *e) {
  if (!im->fbar) return false;
  *e = im->strain_energy;
  return true;
}
double mpm_implicit_lambda(const mpm_implicit *im) { return im->lambda; }
const pm_load_report *mpm_implicit_report(const mpm_implicit *im) {
  return &im->rep;
}
void mpm_implicit_size(const mpm_implicit *im, long *unknowns, long *entries) {
  *unknowns = im->nunk_all;
  *entries = im->entries_all;
}

void mpm_implicit_held(const mpm_implicit *im, long *own, long *ghost) {
  *own = im->nunk;
  *ghost = im->ranks ? im->nghost : 0;
}

static const char *linear_name(pm_newton_linear l) {
  switch (l) {
  case PM_NEWTON_DIRECT: return "direct (LU)";
  case PM_NEWTON_GMRES_GAMG: return "GMRES + GAMG";
  case PM_NEWTON_CG_JACOBI: return "CG + Jacobi";
  case PM_NEWTON_GMRES_ILU: return "GMRES + ILU(0)";
  case PM_NEWTON_CG_GAMG: return "CG + GAMG";
  }
  return "?";
}

void mpm_implicit_plan(const mpm_implicit *im, FILE *out) {
  const mpm_grid *g = &im->g;
  const long active = im->active_all;
  fprintf(out, "algorithm    %s\n",
          im->mode == MPM_GRID_KEPT
              ? "grid kept with the particles (the modified algorithm: "
                "total Lagrangian on the grid)"
              : "grid reset after each load step (the standard algorithm)");
  fprintf(out,
          "solver grid  %ld x %ld x %ld nodes%s (%ld active), cell %g m, "
          "%d colours of cells\n",
          g->nn[0], g->nn[1], g->nn[2], im->ranks ? " on rank 0" : "", active,
          g->h, im->sn);
  fprintf(
      out,
      "unknowns     %ld (%ld prescribed or following), Jacobian %ld entries "
      "(%.1f MiB)%s\n",
      im->nunk_all, im->npre, im->entries_all,
      im->entries_all * 12.0 / 1048576.0,
      im->mode == MPM_GRID_RESET ? ", first load step" : "");
  fprintf(out, "newton       %d load steps, at most %d iterations each, ",
          im->opt_steps, im->opt.max_iter);
  if (im->opt.rtol > 0)
    fprintf(out, "residual below %g of the first\n", im->opt.rtol);
  else
    fprintf(out,
            "eq. 9: displacement below %g and energy below %g of the first\n",
            im->opt.dtol, im->opt.etol);
  fprintf(out, "linear       %s, %s (%s)\n", linear_name(im->opt.linear),
          im->matrix_free ? "matrix-free (diagonal preconditioner)"
                          : "assembled tangent",
          im->matrix_free ? "mpm.implicit.operator" : im->why_linear);
  fprintf(out, "F-bar        %s\n", im->why_fbar);
}
