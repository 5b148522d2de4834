/* pm_load_branch: the tangent's lowest mode at a converged state of load
 * stepping (inverse iteration on a fresh factorisation), and the branch
 * switch along it where Newton cannot pass a critical point. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pm_interrupt.h"
#include "pm_newton_impl.h"
#include "pm_newton_solver_impl.h"
#include "pm_omp.h"
#include "pm_petsc.h"

/* Inverse iterations at most, and the relative change of the eigenvalue's
 * estimate that ends them. */
#define MODE_ITERS 12
#define MODE_RTOL 1e-4

/* The M-products v.M v, v.M u and u.M u (M diagonal, m), in one pass. */
static void mass_dots(long n, const double *m, const double *v, const double *u,
                      double *vmv, double *vmu, double *umu) {
  double a = 0, b = 0, c = 0;
  PM_OMP(parallel for schedule(static) reduction(+ : a, b, c))
  for (long i = 0; i < n; i++) {
    a += m[i] * v[i] * v[i];
    b += m[i] * v[i] * u[i];
    c += m[i] * u[i] * u[i];
  }
  *vmv = a;
  *vmu = b;
  *umu = c;
}

pm_err pm_load_lowest_mode(pm_newton *s, const double *x, const double *m,
                           double *v, double *u, double *b, pm_load_report *rep,
                           double *eig, int *iters) {
  const long n = s->p.n;
  pm_err e = PM_SUCCESS;
  double est = NAN;
  int it = 0;
  PM_CHECK(!s->dist, PM_ERR_UNSUPPORTED, "lowest mode: one process only");
  /* a start with a part in every mode, the same on every run */
  for (long i = 0; i < n; i++)
    v[i] = 1.0 + 0.5 * sin(0.7 * (double)i) + 0.25 * cos(1.3 * (double)i);
  /* the factorisation made at x (the kept one is of another state) */
  s->pc_built = false;
  for (it = 1; it <= MODE_ITERS; it++) {
    PM_CALL(pm_interrupt_check("in the tangent's lowest mode"));
    for (long i = 0; i < n; i++) b[i] = m[i] * v[i];
    pm_newton_report tr;
    memset(&tr, 0, sizeof tr);
    e = pm_newton_tangent_solve(s, x, b, u, &tr);
    pm_load_add_costs(rep, &tr);
    if (e != PM_SUCCESS) break;
    /* K u = M v: for an eigenvector v of eigenvalue q, u = v / q */
    double vmv, vmu, umu;
    mass_dots(n, m, v, u, &vmv, &vmu, &umu);
    const double next = vmv / vmu;
    PM_CHECK(umu > 0 && isfinite(umu) && isfinite(next), PM_ERR_UNSTABLE,
             "lowest mode: the inverse iterate is not finite");
    const double sc = 1.0 / sqrt(umu);
    for (long i = 0; i < n; i++) v[i] = sc * u[i];
    const bool done =
        isfinite(est) && fabs(next - est) <= MODE_RTOL * fabs(next);
    est = next;
    if (done) break;
  }
  if (it > MODE_ITERS) it = MODE_ITERS;
  /* the next Newton solve factorises again at its own state */
  s->pc_built = false;
  *eig = est;
  *iters = it;
  return e;
}

pm_err pm_load_mode_at(pm_newton *s, double lambda, double target,
                       const double *x, pm_relax_work *w, pm_load_report *rep,
                       double *eig, char *msg, long cap) {
  const pm_newton_problem *p = &s->p;
  double q = NAN;
  int its = 0;
  msg[0] = '\0';
  *eig = NAN;
  pm_newton_note_load(s, lambda);
  pm_err e = p->set_load(p->ctx, lambda);
  if (e == PM_SUCCESS) e = pm_relax_masses(s, x, w->mass);
  if (e == PM_SUCCESS)
    e = pm_load_lowest_mode(s, x, w->mass, w->mode, w->v, w->r, rep, &q, &its);
  pm_newton_note_load(s, target);
  pm_err e2 = p->set_load(p->ctx, target);
  if (e == PM_SUCCESS) e = e2;
  if (e != PM_SUCCESS) return e;
  rep->mode_runs++;
  if (rep->mode_runs == 1 || q < rep->mode_eigenvalue) rep->mode_eigenvalue = q;
  char where[320] = "";
  if (p->describe_mode &&
      p->describe_mode(p->ctx, w->mode, where, sizeof where) != PM_SUCCESS) {
    where[0] = '\0';
    pm_error_clear();
  }
  snprintf(msg, (size_t)cap,
           "lowest mode at lambda %.6g: eigenvalue %.3e of the masses' "
           "scale (%d inverse iterations)%s%s",
           lambda, q, its, where[0] ? "; " : "", where);
  *eig = q;
  return PM_SUCCESS;
}

pm_err pm_load_ptc_noted(pm_newton *s, double *x, double goal, double shift0,
                         pm_relax_work *w, pm_load_report *rep,
                         const char *label, char *msg, size_t cap) {
  double r0 = 0, q = 0;
  const size_t used = pm_msg_appendf(msg, cap, "%s", label);
  pm_err e = pm_load_ptc(s, x, goal, shift0, w, rep, &r0, &q, msg + used,
                         (long)(cap - used));
  if (rep->ptc_runs == 1 || q < rep->ptc_curvature) rep->ptc_curvature = q;
  return e;
}

/* The branch switch's perturbation: its largest entry this fraction of
 * the state's largest. */
#define BRANCH_AMPLITUDE 1e-2

pm_err pm_load_branch_switch(pm_newton *s, double *x, const double *xc,
                             double goal, double shift0, pm_relax_work *w,
                             pm_load_report *rep, char *msg, size_t cap) {
  const long n = pm_newton_problem_of(s)->n;
  double xmax = 0, vmax = 0;
  for (long i = 0; i < n; i++) {
    xmax = fmax(xmax, fabs(xc[i]));
    vmax = fmax(vmax, fabs(w->mode[i]));
  }
  pm_err e = PM_ERR_NOT_CONVERGED;
  if (!(xmax > 0 && vmax > 0)) return e;
  for (int sign = 1; sign >= -1; sign -= 2) {
    const double a = sign * BRANCH_AMPLITUDE * xmax / vmax;
    for (long i = 0; i < n; i++) x[i] = xc[i] + a * w->mode[i];
    char label[64];
    snprintf(label, sizeof label,
             "%sfrom the state %s %.2e x the mode: ", msg[0] ? "; " : "",
             sign > 0 ? "+" : "-", fabs(a));
    e = pm_load_ptc_noted(s, x, goal, shift0, w, rep, label, msg, cap);
    if (e == PM_SUCCESS) {
      rep->branch_switches++;
      return e;
    }
    if (e != PM_ERR_NOT_CONVERGED && e != PM_ERR_UNSTABLE) return e;
    pm_error_clear();
  }
  return e;
}
