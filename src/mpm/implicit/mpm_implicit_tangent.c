/* mpm_implicit_tangent: the implicit MPM's tangent: its assembled values,
 * the diagonal preconditioner, and the check against differences. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_exchange.h"
#include "mpm_implicit_impl.h"
#include "pm_interrupt.h"
#include "mpm_kind.h"
#include "mpm_traction.h"
#include "pm_omp.h"
#include "pm_progress.h"
#include "pm_tensor.h"

/* A_n[iJkM] = sum_KL A[iKkL] Fb[JK] Fb[ML] (A when F_b = I), with
 * A[iKkL] = dP_iK / dF_kL from nine tangent calls. */
static bool particle_tangent(const mpm_implicit *im, long p, const double F[9],
                             double An[81]) {
  const mpm_solid_view *v = &im->view[im->grp[p]];
  const double *ms = model_state(im, p);
  double A[81];
  for (int kl = 0; kl < 9; kl++) {
    double dF[9] = {0}, dP[9];
    dF[kl] = 1;
    if (!pm_material_tangent(v->mat, F, ms, dF, dP)) return false;
    for (int iK = 0; iK < 9; iK++) A[9 * iK + kl] = dP[iK];
  }
  mpm_implicit_tangent_to_base(im, p, A, An);
  return true;
}

void mpm_implicit_tangent_to_base(const mpm_implicit *im, long p,
                                  const double A[81], double An[81]) {
  const double *Fb = base_F(im, p);
  if (!Fb) {
    memcpy(An, A, 81 * sizeof(double));
    return;
  }
  double T[81]; /* T[iJkL] = sum_K A[iKkL] Fb[JK] */
  for (int i = 0; i < 3; i++)
    for (int J = 0; J < 3; J++)
      for (int kl = 0; kl < 9; kl++) {
        double s = 0;
        for (int K = 0; K < 3; K++)
          s += A[9 * (3 * i + K) + kl] * Fb[3 * J + K];
        T[9 * (3 * i + J) + kl] = s;
      }
  for (int iJ = 0; iJ < 9; iJ++)
    for (int k = 0; k < 3; k++)
      for (int M = 0; M < 3; M++) {
        double s = 0;
        for (int L = 0; L < 3; L++) s += T[9 * iJ + 3 * k + L] * Fb[3 * M + L];
        An[9 * iJ + 3 * k + M] = s;
      }
}

/* Unknown components of node b before component c. */
static inline int rank_of(const long *dof, long b, int c) {
  int r = 0;
  for (int j = 0; j < c; j++) r += dof[3 * b + j] >= 0;
  return r;
}

bool mpm_implicit_add_entry(const mpm_implicit *im, long row, long rn, long cd,
                            double v, double *val) {
  const mpm_grid *g = &im->g;
  const long cn = cd / 3;
  int s = 0;
  for (int c = im->dim - 1; c >= 0; c--) {
    const long dc =
        (cn / g->stride[c]) % g->nn[c] - (rn / g->stride[c]) % g->nn[c];
    if (dc < 1 - im->w || dc > im->w - 1) return false;
    s = s * im->nb + (int)dc + im->w - 1;
  }
  const int off = im->nb_off[rn * im->nnb + s];
  if (off < 0) return false;
  /* Rows an extension folds onto lie in the particle's own stencil (the
   * mirror of a node beyond a face is in every stencil that reaches it),
   * so the colours keep threads apart; atomic all the same. */
  double *e =
      val + im->pat_ptr[row] + off + rank_of(im->dof, cn, (int)(cd % 3));
  PM_OMP(atomic)
  *e += v;
  return true;
}

pm_err mpm_implicit_values_status(const mpm_implicit *im, bool outside) {
  if (im->fail_p >= 0) return PM_ERROR(PM_ERR_INTERNAL, "%s", im->fail_msg);
  PM_CHECK(!outside, PM_ERR_INTERNAL,
           "a condition's extension couples unknowns outside the tangent's "
           "pattern");
  return PM_SUCCESS;
}

/* Add v to the entry (row unknown of node rn, column grid dof cd) through
 * the unknown cd follows (none: nothing). */
static inline void add_followed(const mpm_implicit *im, long row, long rn,
                                long cd, double v, double *val, bool *outside) {
  long cu;
  double ct;
  if (!follows(im, cd, &cu, &ct)) return;
  if (!mpm_implicit_add_entry(im, row, rn, im->unk_dof[cu], ct * v, val))
    *outside = true;
}

void mpm_implicit_scatter_block(const mpm_implicit *im, const mpm_stencil *st,
                                const double *K, double *val, bool *outside) {
  const long *dof = im->dof;
  const int n3 = 3 * st->n;
  for (int a = 0; a < st->n; a++) {
    const long na = st->node[a];
    for (int i = 0; i < 3; i++) {
      const double *Ka = K + (long)(3 * a + i) * n3;
      const long row = dof[3 * na + i];
      if (row >= 0) { /* an unknown: its stencil's unknowns in order */
        for (int b = 0; b < st->n; b++) {
          const long nbn = st->node[b];
          const int off = im->nb_off[na * im->nnb + im->soff[a][b]];
          long pos = off < 0 ? -1 : im->pat_ptr[row] + off;
          for (int k = 0; k < 3; k++)
            if (dof[3 * nbn + k] >= 0)
              val[pos++] += Ka[3 * b + k];
            else if (dof[3 * nbn + k] <= -2)
              add_followed(im, row, na, 3 * nbn + k, Ka[3 * b + k], val,
                           outside);
        }
        continue;
      }
      long ru; /* a prescribed dof that follows an unknown */
      double rt;
      if (!follows(im, 3 * na + i, &ru, &rt)) continue;
      const long rn = im->unk_dof[ru] / 3;
      for (int b = 0; b < st->n; b++)
        for (int k = 0; k < 3; k++)
          add_followed(im, ru, rn, 3 * st->node[b] + k, rt * Ka[3 * b + k], val,
                       outside);
    }
  }
}

/* The pressures' load stiffness into the tangent's values: an entry
 * through the unknowns its row and column follow; one outside the
 * pattern (a facet's corners in cells apart) is left out and counted. */
typedef struct {
  const mpm_implicit *im;
  double *val;
  long left_out;
} pressure_fill;

static void pressure_entry(void *ctx, long row, long col, double v) {
  pressure_fill *pf = ctx;
  const mpm_implicit *im = pf->im;
  long ru, cu;
  double rt, ct;
  if (v == 0 || !follows(im, row, &ru, &rt) || !follows(im, col, &cu, &ct))
    return;
  if (!mpm_implicit_add_entry(im, ru, im->unk_dof[ru] / 3, im->unk_dof[cu],
                              rt * ct * v, pf->val))
    pf->left_out++;
}

static pm_err pressure_values(mpm_implicit *im, double *val) {
  const double lam = im->lam0 + im->lam_local * (im->lam1 - im->lam0);
  pressure_fill pf = {im, val, 0};
  mpm_pressures_tangent(im->m, &im->g, im->xb, im->u, lam, pressure_entry, &pf);
  im->pressure_left_out = pf.left_out;
  return PM_SUCCESS;
}

/* The assembled tangent in the pattern's order. */
pm_err mpm_implicit_cb_values(void *ctx, const double *x, double *val) {
  mpm_implicit *im = ctx;
  const mpm_model *m = im->m;
  mpm_implicit_fill_u(im, x);
  memset(val, 0, sizeof(double) * (size_t)im->pat_ptr[im->nheld]);
  if (im->fbar) {
    PM_CALL(mpm_implicit_fbar_values(im, val));
    return pressure_values(im, val);
  }
  im->fail_p = -1;
  bool outside = false;
  FOR_PARTICLES(im, {
    double F[9], An[81], G[MPM_STENCIL_MAX][27];
    double K[9 * MPM_STENCIL_MAX * MPM_STENCIL_MAX];
    particle_F(im, p, &st, im->u, F);
    if (!particle_tangent(im, p, F, An)) {
      note_failure(im, p, "no tangent: J <= 0", pm_t_det(F));
      continue;
    }
    const double V0 = m->vol0[p];
    /* G_b[iJk] = V0 sum_M An[iJkM] g_b[M] */
    for (int b = 0; b < st.n; b++)
      for (int iJk = 0; iJk < 27; iJk++)
        G[b][iJk] = V0 * (An[3 * iJk] * st.grad[b][0] +
                          An[3 * iJk + 1] * st.grad[b][1] +
                          An[3 * iJk + 2] * st.grad[b][2]);
    const int n3 = 3 * st.n;
    for (int a = 0; a < st.n; a++)
      for (int i = 0; i < 3; i++)
        for (int b = 0; b < st.n; b++)
          for (int k = 0; k < 3; k++) {
            double s = 0;
            for (int J = 0; J < 3; J++)
              s += st.grad[a][J] * G[b][9 * i + 3 * J + k];
            K[(3 * a + i) * n3 + 3 * b + k] = s;
          }
    mpm_implicit_scatter_block(im, &st, K, val, &outside);
  })
  PM_CALL(mpm_implicit_values_status(im, outside));
  return pressure_values(im, val);
}

/* The tangent's diagonal, for the matrix-free operator's Jacobi
 * preconditioner: P dx = diag(K) dx (assembled by colouring from the
 * diagonal pattern: one product with dx = 1). */
pm_err mpm_implicit_cb_prepare(void *ctx, const double *x) {
  mpm_implicit *im = ctx;
  PM_CALL(pm_interrupt_check("before the tangent's assembly"));
  if (!im->matrix_free) return PM_SUCCESS;
  const mpm_model *m = im->m;
  mpm_implicit_fill_u(im, x);
  double *dg = im->df;
  memset(dg, 0, 3 * sizeof(double) * (size_t)im->g.n_nodes);
  im->fail_p = -1;
  FOR_PARTICLES(im, {
    double F[9], An[81];
    particle_F(im, p, &st, im->u, F);
    if (!particle_tangent(im, p, F, An)) {
      note_failure(im, p, "no tangent: J <= 0", pm_t_det(F));
      continue;
    }
    for (int a = 0; a < st.n; a++) {
      const double *ga = st.grad[a];
      double *d = dg + 3 * st.node[a];
      for (int i = 0; i < 3; i++) {
        double s = 0;
        for (int J = 0; J < 3; J++)
          for (int M = 0; M < 3; M++)
            s += ga[J] * An[9 * (3 * i + J) + 3 * i + M] * ga[M];
        d[i] += m->vol0[p] * s;
      }
    }
  })
  if (im->fail_p >= 0) return PM_ERROR(PM_ERR_INTERNAL, "%s", im->fail_msg);
  for (long k = 0; k < im->nunk; k++) im->diag[k] = dg[im->unk_dof[k]];
  return PM_SUCCESS;
}

pm_err mpm_implicit_cb_precond(void *ctx, const double *x, const double *dx,
                               double *dr) {
  (void)x;
  mpm_implicit *im = ctx;
  for (long k = 0; k < im->nunk; k++) dr[k] = im->diag[k] * dx[k];
  return PM_SUCCESS;
}

/* A smooth field over the unknowns, for the tangent check. */
static void smooth_field(const mpm_implicit *im, double amp, double *x) {
  for (long k = 0; k < im->nunk; k++) {
    double y[3];
    long d = im->unk_dof[k];
    mpm_grid_node_position(&im->g, d / 3, y);
    double h = im->g.h * 10;
    x[k] = amp * sin(y[0] / h + 0.3 * (double)(d % 3)) * cos(y[1] / h) *
           (1 + 0.2 * sin(y[2] / h));
  }
}

pm_err mpm_implicit_check_tangent(mpm_implicit *im, double lambda, double amp,
                                  double *assembled_error,
                                  double *matrix_free_error) {
  pm_err ret = PM_SUCCESS;
  if (im->mode == MPM_GRID_RESET) PM_CALL(mpm_implicit_rebuild(im));
  const long n = im->nunk;
  const long nz = im->pat_ptr[n];
  double *x = NULL, *val = NULL, *xp = NULL, *r1 = NULL, *r2 = NULL, *e = NULL,
         *ke = NULL;
  PM_TRY(PM_ALLOC(x, n, "check"));
  PM_TRY(PM_ALLOC(xp, n, "check"));
  PM_TRY(PM_ALLOC(r1, n, "check"));
  PM_TRY(PM_ALLOC(r2, n, "check"));
  PM_TRY(PM_ALLOC(e, n, "check"));
  PM_TRY(PM_ALLOC(ke, n, "check"));
  PM_TRY(PM_ALLOC(val, nz, "check"));
  im->lam_local = lambda;
  smooth_field(im, amp, x);
  /* the values the solver assembles (directly, or coloured from the
   * product with F-bar) */
  PM_TRY(pm_newton_jacobian_values(im->solver, x, val));
  /* central differences, column by column */
  double dmax = 0, err_a = 0, err_m = 0;
  for (long j = 0; j < n; j++) {
    const double h = 1e-6 * (fabs(x[j]) + amp + 1e-30);
    memcpy(xp, x, sizeof(double) * (size_t)n);
    xp[j] = x[j] + h;
    PM_TRY(mpm_implicit_cb_residual(im, xp, r1));
    xp[j] = x[j] - h;
    PM_TRY(mpm_implicit_cb_residual(im, xp, r2));
    memset(e, 0, sizeof(double) * (size_t)n);
    e[j] = 1;
    PM_TRY(mpm_implicit_cb_apply(im, x, e, ke));
    for (long i = 0; i < n; i++) {
      double d = (r1[i] - r2[i]) / (2 * h);
      dmax = fmax(dmax, fabs(d));
      err_m = fmax(err_m, fabs(ke[i] - d));
      /* the assembled value of (i, j), 0 outside the pattern */
      double a = 0;
      for (long q = im->pat_ptr[i]; q < im->pat_ptr[i + 1]; q++)
        if (im->pat_idx[q] == j) a += val[q];
      err_a = fmax(err_a, fabs(a - d));
    }
  }
  *assembled_error = dmax > 0 ? err_a / dmax : err_a;
  *matrix_free_error = dmax > 0 ? err_m / dmax : err_m;
done:
  free(x);
  free(xp);
  free(r1);
  free(r2);
  free(e);
  free(ke);
  free(val);
  return ret;
}
