/* pm_compare_errors: a comparison's errors on its lattice: every method
 * against the analytic field, the FE referee and a reference run, and the
 * methods' pairs against each other (NRMSE over the valid points). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_compare_impl.h"
#include "pm_metrics.h"

/* The rows of a ([m][3]) at the valid lattice points into b. */
static void compact(const cmp_study *c, const double *a, double *b) {
  long j = 0;
  for (long i = 0; i < c->m; i++)
    if (c->valid[i]) {
      memcpy(b + 3 * j, a + 3 * i, 3 * sizeof *a);
      j++;
    }
}

static double largest(long n, unsigned mask, const double *u) {
  double big = 0;
  for (long j = 0; j < n; j++) {
    double r2 = 0;
    for (int k = 0; k < 3; k++)
      if (mask >> k & 1u) r2 += u[3 * j + k] * u[3 * j + k];
    big = fmax(big, sqrt(r2));
  }
  return big;
}

/* Root mean square of |a - b| over n points, over scale. */
static double rms_over(long n, unsigned mask, const double *a, const double *b,
                       double scale) {
  double sum = 0;
  for (long j = 0; j < n; j++)
    for (int k = 0; k < 3; k++)
      if (mask >> k & 1u) {
        double d = a[3 * j + k] - b[3 * j + k];
        sum += d * d;
      }
  return n > 0 && scale > 0 ? sqrt(sum / (double)n) / scale : NAN;
}

/* The NRMSE against the analytic field as a run reports it (pm_run): a
 * single component's own (over its range), several as a vector. */
static double analytic_nrmse(long n, unsigned mask, const double *u,
                             const double *ref) {
  int count = 0, last = 0;
  for (int k = 0; k < 3; k++)
    if (mask >> k & 1u) count++, last = k;
  if (count == 1) return pm_nrmse(n, 3, u + last, ref + last);
  return pm_nrmse_vector(n, mask, u, ref);
}

/* The lattice points every mapped method and the reference run fit. */
static void find_valid(cmp_study *c) {
  c->n_valid = 0;
  for (long i = 0; i < c->m; i++) {
    bool ok = true;
    for (int k = 0; k < c->n && ok; k++)
      if (c->meth[k].mapped) ok = isfinite(c->meth[k].u[3 * i]);
    if (c->run_u) ok = ok && isfinite(c->run_u[3 * i]);
    c->valid[i] = ok;
    c->n_valid += ok;
  }
}

/* Every method against the references, the pairs against each other. */
pm_err cmp_compute_errors(cmp_study *c) {
  pm_err ret = PM_SUCCESS;
  double *full = NULL, *a = NULL, *b = NULL, *r = NULL, *xv = NULL, *fu = NULL;
  const unsigned mask = cmp_mask(c);
  PM_TRY(PM_ALLOC(c->valid, c->m, "lattice flags"));
  find_valid(c);
  const long nv = c->n_valid;
  PM_TRY(PM_ALLOC(full, 3 * c->m, "analytic field"));
  PM_TRY(PM_ALLOC(a, 3 * c->m + 3, "lattice values"));
  PM_TRY(PM_ALLOC(b, 3 * c->m + 3, "lattice values"));
  PM_TRY(PM_ALLOC(r, 3 * c->m + 3, "lattice values"));
  pm_fe_reference view = {.n = 0};
  if (c->fe) {
    PM_TRY(PM_ALLOC(xv, 3 * c->m + 3, "lattice points"));
    PM_TRY(PM_ALLOC(fu, 3 * c->m + 3, "FE values"));
    compact(c, c->fe->x, xv);
    compact(c, c->fe->u, fu);
    view = *c->fe;
    view.n = nv;
    view.x = xv;
    view.u = fu;
  }
  /* One scale for the pairs: the reference's largest |u|, else the
   * methods'. */
  c->scale = 0;
  if (c->fe) {
    c->scale = largest(nv, mask, fu);
    snprintf(c->scale_label, sizeof c->scale_label, "the FE referee's");
  } else if (c->run_u) {
    compact(c, c->run_u, r);
    c->scale = largest(nv, mask, r);
    snprintf(c->scale_label, sizeof c->scale_label, "the reference run's");
  } else {
    for (int k = 0; k < c->n; k++)
      if (c->meth[k].mapped) {
        compact(c, c->meth[k].u, a);
        c->scale = fmax(c->scale, largest(nv, mask, a));
      }
    snprintf(c->scale_label, sizeof c->scale_label, "the methods' own");
  }
  for (int k = 0; k < c->n; k++) {
    cmp_method *M = &c->meth[k];
    M->e_analytic = M->e_fe = M->e_fe_interior = NAN;
    M->reaction_fe = M->sed_fe = M->e_run = M->tip_fe = NAN;
    for (int l = 0; l < c->n; l++) c->pair[k][l] = NAN;
    if (!M->mapped || nv == 0) continue;
    compact(c, M->u, a);
    if (c->analytic) {
      cmp_analytic(c, M->out.fig.time, full);
      compact(c, full, r);
      M->e_analytic = analytic_nrmse(nv, c->base->reference_mask, a, r);
    }
    if (c->fe) {
      pm_fe_errors e;
      pm_fe_errors_of(&view, a, &M->out, &e);
      M->e_fe = e.nrmse;
      M->e_fe_interior = e.nrmse_interior;
      M->reaction_fe = e.reaction_error;
      M->sed_fe = e.sed_error;
      M->tip_fe = e.tip_error;
    }
    if (c->run_u) {
      compact(c, c->run_u, r);
      M->e_run = pm_nrmse_vector(nv, mask, a, r);
    }
    for (int l = 0; l < k; l++)
      if (c->meth[l].mapped) {
        compact(c, c->meth[l].u, b);
        c->pair[k][l] = c->pair[l][k] = rms_over(nv, mask, a, b, c->scale);
      }
  }
done:
  free(full);
  free(a);
  free(b);
  free(r);
  free(xv);
  free(fu);
  return ret;
}
