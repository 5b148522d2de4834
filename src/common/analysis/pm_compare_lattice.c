/* pm_compare_lattice: the lattice a comparison's fields are compared on
 * (regular over the bodies' box, or the FE referee's points), and a cloud's
 * field fitted at its points (moving least squares), flagged off the body. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pm_compare_impl.h"
#include "pm_mls.h"
#include "pm_probe.h"
#include "pm_scene_mirror.h"

/* How far a lattice point's fit may reach, in mean point spacings, and
 * how far its nearest point may be, in mean nearest-neighbour distances: a
 * point farther than that (off the method's body) is flagged rather than
 * extrapolated to.  A corner of a body whose points are inset by half their
 * spacing (MPM particles) is 0.87 of it from its nearest point; a point on
 * a face of a mesh, at most 0.58 of an edge. */
#define CMP_REACH 5.0
#define CMP_GAP 1.5
/* Regular lattice: points along a long axis at most this many times the
 * shortest axis's intervals. */
#define CMP_ASPECT_MAX 8

static void grow(double lo[3], double hi[3], const double *p, double r) {
  for (int k = 0; k < 3; k++) {
    lo[k] = fmin(lo[k], p[k] - r);
    hi[k] = fmax(hi[k], p[k] + r);
  }
}

/* The reference box of the scene's bodies: their shapes' bounds, the
 * domain box for shapes given by a region, a mesh, an image or a
 * membrane (where the lattice points off the body are then flagged). */
static void bodies_box(const pm_scene *s, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; k++) lo[k] = INFINITY, hi[k] = -INFINITY;
  for (int b = 0; b < s->n_bodies; b++) {
    const pm_scene_body *B = &s->bodies[b];
    double top[3];
    switch (B->shape) {
    case PM_BODY_BOX:
      grow(lo, hi, B->a, 0);
      grow(lo, hi, B->b, 0);
      break;
    case PM_BODY_SPHERE: grow(lo, hi, B->a, B->radius); break;
    case PM_BODY_CYLINDER:
      for (int k = 0; k < 3; k++) top[k] = B->a[k] + B->b[k];
      grow(lo, hi, B->a, B->radius);
      grow(lo, hi, top, B->radius);
      break;
    default:
      grow(lo, hi, s->box_min, 0);
      grow(lo, hi, s->box_max, 0);
      break;
    }
  }
  for (int k = 0; k < 3; k++) {
    if (!(lo[k] <= hi[k])) lo[k] = s->box_min[k], hi[k] = s->box_max[k];
    /* Within the domain: a shape cannot reach past it. */
    lo[k] = fmax(lo[k], s->box_min[k]);
    hi[k] = fmin(hi[k], s->box_max[k]);
  }
  if (s->dimension == 2) lo[2] = hi[2] = 0;
}

/* n points along the shortest axis of the bodies' box, the other axes at
 * about the same spacing, x outermost and z innermost. */
pm_err cmp_regular_lattice(cmp_study *c, long n) {
  pm_err ret = PM_SUCCESS;
  double lo[3], hi[3], shortest = INFINITY;
  bodies_box(c->base, lo, hi);
  for (int k = 0; k < c->dim; k++) {
    PM_CHECK(hi[k] > lo[k], PM_ERR_SCENE,
             "%s: the bodies' box is flat along %c ([%g, %g] m): no lattice",
             c->base->path, "xyz"[k], lo[k], hi[k]);
    shortest = fmin(shortest, hi[k] - lo[k]);
  }
  const double spacing = shortest / (double)(n - 1);
  c->m = 1;
  for (int k = 0; k < 3; k++) {
    c->side[k] = 1;
    if (k < c->dim) {
      double cells = ceil((hi[k] - lo[k]) / spacing - 1e-9);
      c->side[k] = 1 + (long)fmin(cells, CMP_ASPECT_MAX * (double)(n - 1));
    }
    c->m *= c->side[k];
    c->centre[k] = 0.5 * (lo[k] + hi[k]);
  }
  PM_TRY(PM_ALLOC(c->x, 3 * c->m, "lattice"));
  long i = 0;
  for (long a = 0; a < c->side[0]; a++)
    for (long b = 0; b < c->side[1]; b++)
      for (long d = 0; d < c->side[2]; d++, i++) {
        const long idx[3] = {a, b, d};
        for (int k = 0; k < 3; k++)
          c->x[3 * i + k] = c->side[k] > 1
                                ? lo[k] + (hi[k] - lo[k]) * (double)idx[k] /
                                              (double)(c->side[k] - 1)
                                : lo[k];
      }
  int len = snprintf(c->lattice_label, sizeof c->lattice_label,
                     "a regular lattice of %ld", c->side[0]);
  for (int k = 1; k < c->dim; k++)
    len += snprintf(c->lattice_label + len, sizeof c->lattice_label - len,
                    " x %ld", c->side[k]);
  len += snprintf(c->lattice_label + len, sizeof c->lattice_label - len,
                  " points over the bodies' box [%g, %g]", lo[0], hi[0]);
  for (int k = 1; k < c->dim; k++)
    len += snprintf(c->lattice_label + len, sizeof c->lattice_label - len,
                    " x [%g, %g]", lo[k], hi[k]);
  snprintf(c->lattice_label + len, sizeof c->lattice_label - len, " m");
done:
  return ret;
}

/* The FE referee's lattice points, and its centre. */
pm_err cmp_fe_lattice(cmp_study *c) {
  pm_err ret = PM_SUCCESS;
  const pm_fe_reference *fe = c->fe;
  c->m = fe->n;
  c->dim = fe->dim == 2 ? 2 : 3;
  PM_TRY(PM_ALLOC(c->x, 3 * c->m, "lattice"));
  memcpy(c->x, fe->x, sizeof *c->x * 3 * (size_t)c->m);
  memcpy(c->centre, fe->centre, sizeof c->centre);
  snprintf(c->lattice_label, sizeof c->lattice_label,
           "the FE referee's lattice (%s/lattice.csv, %ld points)", fe->dir,
           fe->n);
done:
  return ret;
}

/* The field f (ncomp components) at q into v when q lies on the cloud
 * and a regular fit reaches it; false (v NaN) when q is flagged. */
bool cmp_fit_on_cloud(pm_mls *mls, const double *q, int ncomp, const double *f,
                      double *v) {
  if (pm_mls_nearest(mls, q) <= CMP_GAP * pm_mls_gap(mls) &&
      pm_mls_fit(mls, q, ncomp, f, CMP_REACH, v) > 0)
    return true;
  for (int k = 0; k < ncomp; k++) v[k] = NAN;
  return false;
}

long cmp_map_lattice(const cmp_study *c, const pm_scene *part, pm_mls *mls,
                     const double *u, double *out) {
  long flagged = 0;
  /* A scene of a part mirrored about its symmetry planes: a lattice point
   * of the whole body takes its image's value in the part. */
  for (long i = 0; i < c->m; i++) {
    double y[3];
    const unsigned flips = pm_scene_mirror_fold(part, c->x + 3 * i, y);
    flagged += !cmp_fit_on_cloud(mls, y, 3, u, out + 3 * i);
    pm_scene_mirror_unfold(flips, out + 3 * i);
  }
  return flagged;
}

/* The last frame of the reference run, on the lattice. */
pm_err cmp_map_run(cmp_study *c) {
  pm_err ret = PM_SUCCESS;
  long n = 0;
  double *x = NULL, *u = NULL;
  pm_mls *mls = NULL;
  char what[PM_PATH_MAX + 64];
  PM_TRY(pm_results_read(c->run_dir, -1, &n, &x, &u));
  snprintf(what, sizeof what, "the reference run %s", c->run_dir);
  PM_TRY(pm_mls_create(n, x, what, &mls));
  PM_TRY(PM_ALLOC(c->run_u, 3 * c->m, "reference at the lattice"));
  /* (a reference run of the base scene: its planes) */
  cmp_map_lattice(c, c->base, mls, u, c->run_u);
done:
  pm_mls_free(mls);
  free(x);
  free(u);
  return ret;
}

void cmp_analytic(const cmp_study *c, double t, double *ref) {
  const pm_scene *s = c->base;
  for (long i = 0; i < c->m; i++) {
    const double *X = c->x + 3 * i;
    for (int k = 0; k < 3; k++)
      ref[3 * i + k] = s->reference_mask >> k & 1u
                           ? pm_expr_eval(s->reference[k], X[0], X[1], X[2], t)
                           : 0.0;
  }
}
