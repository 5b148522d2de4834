/* gm_construct: a seeded random network of branching tubes rasterized into a
 * voxel image, grown until it fills a target volume fraction (see
 * gm_construct.h). */
#include "gm_construct.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "pm_random.h"

/* Largest turn of a step: the direction plus TURN times a point of the unit
 * disk in x-y (up to asin 0.6 = 37 degrees) and Z_TURN times one of [-1, 1]
 * in z. */
#define TURN 0.6
#define Z_TURN 0.15
/* Largest |u_z| of a vessel's direction (17 degrees out of the plane). */
#define Z_MAX 0.3
/* A branch leaves at atan(k) to its parent, k in [K_LO, K_HI] (40-70
 * degrees); a sprout at 90 degrees plus up to atan(SPROUT_LEAN). */
#define K_LO 0.84
#define K_HI 2.75
#define SPROUT_LEAN 0.5
/* Bisection steps on the length of the last segment. */
#define BISECTIONS 60

static const double PI = 3.14159265358979323846;

typedef struct {
  double p[3], u[3], r; /* tip, direction (unit), radius */
  long age;             /* segments grown from where the vessel started */
} tip;

typedef struct {
  double a[3], b[3], r;
} segment;

/* The state of a growth: the image, the box, the draws and the lists. */
typedef struct {
  const gm_construct_opts *o;
  gm_image *im;
  double s[3];   /* voxel size / the x voxel size */
  double box[3]; /* the box's extent, x voxels */
  pm_random rng;
  long count; /* vessel voxels */
  tip *tips;  /* live tips, a queue from head to ntips */
  size_t head, ntips, tips_cap;
  segment *segs;
  size_t nsegs, segs_cap;
  long *added; /* voxels set by the last capsule (to undo it) */
  size_t nadded, added_cap;
} growth;

/* Room for need items of size bytes in *p (capacity *cap). */
static pm_err reserve(void **p, size_t *cap, size_t need, size_t size,
                      const char *what) {
  if (need <= *cap) return PM_SUCCESS;
  size_t c = *cap ? *cap : 64;
  while (c < need) c *= 2;
  void *q = realloc(*p, c * size);
  PM_CHECK(q, PM_ERR_MEMORY, "out of memory for %zu %s", c, what);
  *p = q;
  *cap = c;
  return PM_SUCCESS;
}

static double uniform(growth *g) { return pm_random_uniform(&g->rng); }

static double dot(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize(double u[3]) {
  const double l = sqrt(dot(u, u));
  if (l > 0)
    for (int c = 0; c < 3; c++) u[c] /= l;
  else
    u[0] = 1, u[1] = u[2] = 0;
}

/* A point of the unit disk, uniform (by rejection). */
static void disk(growth *g, double w[2]) {
  do {
    w[0] = 2 * uniform(g) - 1;
    w[1] = 2 * uniform(g) - 1;
  } while (w[0] * w[0] + w[1] * w[1] > 1);
}

/* u made unit, pulled towards +-y by align, and |u_z| held to Z_MAX. */
static void settle(const growth *g, double u[3]) {
  normalize(u);
  if (g->o->align > 0) {
    u[1] += u[1] >= 0 ? g->o->align : -g->o->align;
    normalize(u);
  }
  if (fabs(u[2]) > Z_MAX) {
    const double xy = u[0] * u[0] + u[1] * u[1];
    u[2] = u[2] > 0 ? Z_MAX : -Z_MAX;
    if (xy > 0) {
      const double f = sqrt((1 - Z_MAX * Z_MAX) / xy);
      u[0] *= f, u[1] *= f;
    } else {
      u[0] = sqrt(1 - Z_MAX * Z_MAX), u[1] = 0;
    }
  }
}

/* The unit vector in the x-y plane at 90 degrees to u (counter-clockwise). */
static void across(const double u[3], double q[3]) {
  q[0] = -u[1], q[1] = u[0], q[2] = 0;
  normalize(q);
}

/* The range of z the axis of a vessel of radius r keeps to: its tube inside
 * the stack, or the stack's middle when the stack is thinner than 2 r. */
static void z_range(const growth *g, double r, double *lo, double *hi) {
  const double h = g->box[2];
  *lo = r < h / 2 ? r : h / 2;
  *hi = r < h / 2 ? h - r : h / 2;
}

static pm_err push(growth *g, const double p[3], const double u[3], double r,
                   long age) {
  PM_CALL(reserve((void **)&g->tips, &g->tips_cap, g->ntips + 1,
                  sizeof *g->tips, "vessel tips"));
  tip *t = &g->tips[g->ntips++];
  memcpy(t->p, p, sizeof t->p);
  memcpy(t->u, u, sizeof t->u);
  t->r = r;
  t->age = age;
  return PM_SUCCESS;
}

/* A parent vessel: a random point of the box, growing both ways. */
static pm_err root(growth *g) {
  const gm_construct_opts *o = g->o;
  const double r = o->r_min + uniform(g) * (o->r_max - o->r_min);
  double lo, hi, p[3], u[3], w[2];
  z_range(g, r, &lo, &hi);
  p[0] = uniform(g) * g->box[0];
  p[1] = uniform(g) * g->box[1];
  p[2] = lo + uniform(g) * (hi - lo);
  disk(g, w);
  u[0] = w[0], u[1] = w[1], u[2] = Z_TURN * (2 * uniform(g) - 1);
  settle(g, u);
  PM_CALL(push(g, p, u, r, 0));
  for (int c = 0; c < 3; c++) u[c] = -u[c];
  return push(g, p, u, r, 0);
}

/* A vessel sprouting from the side of a segment drawn at random: from a
 * point of its axis (so inside it), across it, no thicker than it. */
static pm_err sprout(growth *g) {
  const segment *s = &g->segs[(size_t)(uniform(g) * (double)g->nsegs)];
  const double t = uniform(g);
  double p[3], e[3], q[3], u[3];
  for (int c = 0; c < 3; c++) {
    e[c] = s->b[c] - s->a[c];
    p[c] = s->a[c] + t * e[c];
  }
  normalize(e);
  across(e, q);
  const double side = uniform(g) < 0.5 ? -1 : 1;
  const double lean = SPROUT_LEAN * (2 * uniform(g) - 1);
  for (int c = 0; c < 3; c++) u[c] = side * q[c] + lean * e[c];
  settle(g, u);
  const double r = g->o->r_min + uniform(g) * (s->r - g->o->r_min);
  return push(g, p, u, r, 0);
}

/* Set the voxels whose centres lie within r of the segment a-b (clipped to
 * the image) that are not set yet; they are listed in g->added. */
static pm_err capsule(growth *g, const double a[3], const double b[3],
                      double r) {
  const long *n = g->im->n;
  long lo[3], hi[3];
  for (int c = 0; c < 3; c++) {
    const double mn = fmin(a[c], b[c]) - r, mx = fmax(a[c], b[c]) + r;
    lo[c] = (long)fmax(0, ceil(mn / g->s[c] - 0.5));
    hi[c] = (long)fmin((double)(n[c] - 1), floor(mx / g->s[c] - 0.5));
    if (hi[c] < lo[c]) return PM_SUCCESS;
  }
  const size_t box = (size_t)(hi[0] - lo[0] + 1) * (size_t)(hi[1] - lo[1] + 1) *
                     (size_t)(hi[2] - lo[2] + 1);
  PM_CALL(reserve((void **)&g->added, &g->added_cap, g->nadded + box,
                  sizeof *g->added, "voxel indices"));
  const double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double ee = dot(e, e), r2 = r * r;
  uint16_t *v = g->im->v;
  for (long k = lo[2]; k <= hi[2]; k++)
    for (long j = lo[1]; j <= hi[1]; j++)
      for (long i = lo[0]; i <= hi[0]; i++) {
        const long q = i + n[0] * (j + n[1] * k);
        if (v[q]) continue;
        const double w[3] = {(i + 0.5) * g->s[0] - a[0],
                             (j + 0.5) * g->s[1] - a[1],
                             (k + 0.5) * g->s[2] - a[2]};
        double t = ee > 0 ? dot(w, e) / ee : 0;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        const double f[3] = {w[0] - t * e[0], w[1] - t * e[1], w[2] - t * e[2]};
        if (dot(f, f) > r2) continue;
        v[q] = 255;
        g->added[g->nadded++] = q;
      }
  g->count += (long)g->nadded;
  return PM_SUCCESS;
}

/* Whether the voxel holding point x (x voxel units) is vessel; false
 * outside the image. */
static bool vessel_at(const growth *g, const double x[3]) {
  long idx[3];
  for (int c = 0; c < 3; c++) {
    const double f = floor(x[c] / g->s[c]);
    if (f < 0 || f >= (double)g->im->n[c]) return false;
    idx[c] = (long)f;
  }
  return gm_image_at(g->im, idx[0], idx[1], idx[2]) != 0;
}

/* Unset the voxels of the last capsule. */
static void undo(growth *g) {
  for (size_t m = 0; m < g->nadded; m++) g->im->v[g->added[m]] = 0;
  g->count -= (long)g->nadded;
  g->nadded = 0;
}

/* The segment p-b of radius r overshot `target` voxels: shorten it to the
 * length whose count comes closest (bisection on the length; the count
 * grows with it, since a shorter capsule lies inside a longer one). */
static pm_err shorten(growth *g, const double p[3], const double b[3], double r,
                      long target) {
  double lo = 0, hi = 1, best = 1, end[3];
  long best_miss = g->count - target;
  for (int it = 0; it < BISECTIONS && best_miss != 0; it++) {
    const double mid = 0.5 * (lo + hi);
    undo(g);
    for (int c = 0; c < 3; c++) end[c] = p[c] + mid * (b[c] - p[c]);
    PM_CALL(capsule(g, p, end, r));
    const long miss = labs(g->count - target);
    if (miss < best_miss) best = mid, best_miss = miss;
    if (g->count < target)
      lo = mid;
    else
      hi = mid;
  }
  undo(g);
  for (int c = 0; c < 3; c++) end[c] = p[c] + best * (b[c] - p[c]);
  return capsule(g, p, end, r);
}

/* Grow the tip at the head of the queue by one segment (and shorten it if
 * it passes target); the tip goes on, branches, or ends at the box's side. */
static pm_err step(growth *g, long target, gm_construct_report *rep) {
  const gm_construct_opts *o = g->o;
  tip t = g->tips[g->head++];
  double w[2], u[3], b[3], lo, hi;
  disk(g, w);
  u[0] = t.u[0] + TURN * w[0];
  u[1] = t.u[1] + TURN * w[1];
  u[2] = t.u[2] + Z_TURN * (2 * uniform(g) - 1);
  settle(g, u);
  const double len = t.r * (2 + 2 * uniform(g));
  for (int c = 0; c < 3; c++) b[c] = t.p[c] + len * u[c];
  /* The axis reflects off the top and bottom of the stack. */
  z_range(g, t.r, &lo, &hi);
  if (b[2] > hi) b[2] = 2 * hi - b[2], u[2] = -fabs(u[2]);
  if (b[2] < lo) b[2] = 2 * lo - b[2], u[2] = fabs(u[2]);
  b[2] = fmin(hi, fmax(lo, b[2]));

  /* A vessel two segments or more from where it started that runs into
   * another joins it there (anastomosis) and ends; nearer its start, the
   * vessel it left would stop it at once. */
  const bool joins = t.age >= 2 && vessel_at(g, b);
  g->nadded = 0;
  PM_CALL(capsule(g, t.p, b, t.r));
  if (g->count > target) PM_CALL(shorten(g, t.p, b, t.r, target));
  PM_CALL(reserve((void **)&g->segs, &g->segs_cap, g->nsegs + 1,
                  sizeof *g->segs, "vessel segments"));
  segment *s = &g->segs[g->nsegs++];
  memcpy(s->a, t.p, sizeof s->a);
  memcpy(s->b, b, sizeof s->b);
  s->r = t.r;
  rep->segments++;
  if (g->count >= target) return PM_SUCCESS;

  if (joins) {
    rep->joins++;
    return PM_SUCCESS;
  }
  const bool inside =
      b[0] >= 0 && b[0] <= g->box[0] && b[1] >= 0 && b[1] <= g->box[1];
  if (!inside) return PM_SUCCESS;
  PM_CALL(push(g, b, u, t.r, t.age + 1));
  if (uniform(g) < o->branch) {
    double q[3], v[3];
    across(u, q);
    const double side = uniform(g) < 0.5 ? -1 : 1;
    const double k = K_LO + uniform(g) * (K_HI - K_LO);
    for (int c = 0; c < 3; c++) v[c] = u[c] + side * k * q[c];
    settle(g, v);
    PM_CALL(push(g, b, v, o->r_min + uniform(g) * (t.r - o->r_min), 0));
    rep->branches++;
  }
  /* Drop the tips already grown once they make half the queue. */
  if (g->head >= 1024 && 2 * g->head >= g->ntips) {
    memmove(g->tips, g->tips + g->head, (g->ntips - g->head) * sizeof *g->tips);
    g->ntips -= g->head;
    g->head = 0;
  }
  return PM_SUCCESS;
}

void gm_construct_defaults(gm_construct_opts *o) {
  memset(o, 0, sizeof *o);
  o->n[0] = 512, o->n[1] = 512, o->n[2] = 52;
  o->d[0] = 1.05e-6, o->d[1] = 1.05e-6, o->d[2] = 1.0e-6;
  o->fraction = 0.104;
  o->seed = 1;
  o->r_min = 3, o->r_max = 6;
  o->branch = 0.1;
  o->align = 0;
  o->roots = 2;
}

pm_err gm_construct_check(const gm_construct_opts *o) {
  PM_CHECK(o, PM_ERR_ARG, "construct: no options");
  for (int c = 0; c < 3; c++) {
    PM_CHECK(o->n[c] >= 1 && o->n[c] <= 65535, PM_ERR_ARG,
             "construct: size: expected 1 to 65535 voxels along %c, got %ld",
             "xyz"[c], o -> n[c]);
    PM_CHECK(o->d[c] > 0 && isfinite(o->d[c]), PM_ERR_ARG,
             "construct: voxel: expected a positive voxel size along %c (m), "
             "got %g",
             "xyz"[c], o -> d[c]);
  }
  PM_CHECK(o->fraction > 0 && o->fraction <= 0.6, PM_ERR_ARG,
           "construct: fraction: expected a value in (0, 0.6], got %g",
           o->fraction);
  /* A vessel's voxels connect when the voxel of every point of its axis is
   * in it: when the radius reaches half a voxel's diagonal. */
  const double s1 = o->d[1] / o->d[0], s2 = o->d[2] / o->d[0];
  const double half = 0.5 * sqrt(1 + s1 * s1 + s2 * s2);
  PM_CHECK(o->r_min >= half && isfinite(o->r_max) && o->r_min <= o->r_max,
           PM_ERR_ARG,
           "construct: radius: expected %.3g <= min <= max (x voxels; half a "
           "voxel's diagonal at least), got min = %g, max = %g",
           half, o->r_min, o->r_max);
  PM_CHECK(o->branch >= 0 && o->branch <= 1, PM_ERR_ARG,
           "construct: branch: expected a probability in [0, 1], got %g",
           o->branch);
  PM_CHECK(o->align >= 0 && o->align <= 1, PM_ERR_ARG,
           "construct: align: expected a value in [0, 1], got %g", o->align);
  PM_CHECK(o->roots >= 1 && o->roots <= 10000, PM_ERR_ARG,
           "construct: roots: expected 1 to 10000 parent vessels, got %d",
           o->roots);
  return PM_SUCCESS;
}

pm_err gm_construct_vessels(const gm_construct_opts *o, gm_image *out,
                            gm_construct_report *rep) {
  PM_CHECK(out, PM_ERR_ARG, "gm_construct_vessels: no image");
  memset(out, 0, sizeof *out);
  PM_CALL(gm_construct_check(o));
  gm_construct_report own;
  if (!rep) rep = &own;
  memset(rep, 0, sizeof *rep);
  const double nv = (double)o->n[0] * (double)o->n[1] * (double)o->n[2];
  const long target = (long)(o->fraction * nv + 0.5);
  PM_CHECK(fabs((double)target / nv - o->fraction) <= GM_CONSTRUCT_TOLERANCE,
           PM_ERR_ARG,
           "construct: size: %ld x %ld x %ld voxels cannot hold a fraction of "
           "%g within %g (the nearest is %g)",
           o->n[0], o->n[1], o->n[2], o->fraction, GM_CONSTRUCT_TOLERANCE,
           (double)target / nv);

  growth g = {.o = o, .im = out, .rng = pm_random_seed(o->seed)};
  pm_err ret = PM_SUCCESS;
  const double o0[3] = {0, 0, 0};
  PM_TRY(gm_image_alloc(out, o->n, o->d, o0));
  out->bits = 8;
  for (int c = 0; c < 3; c++) {
    g.s[c] = o->d[c] / o->d[0];
    g.box[c] = (double)o->n[c] * g.s[c];
  }
  /* Fifty times the segments the fraction would take if none overlapped
   * (each at least 2 r_min long): past that, the network has saturated. */
  const double rm = o->r_min;
  const double most = 1000 + 50 * (double)target / (2 * PI * rm * rm * rm);
  for (int k = 0; k < o->roots; k++) PM_TRY(root(&g));
  rep->roots = o->roots;
  while (g.count < target) {
    PM_ENSURE((double)rep->segments < most, PM_ERR_NOT_CONVERGED,
              "construct: the network saturated at a fraction of %.4f after "
              "%ld segments, short of %g: use a smaller fraction or radius",
              (double)g.count / nv, rep->segments, o->fraction);
    if (g.head == g.ntips) {
      g.head = g.ntips = 0;
      PM_TRY(sprout(&g));
      rep->sprouts++;
    }
    PM_TRY(step(&g, target, rep));
  }
  rep->vessel_voxels = g.count;
  rep->fraction = (double)g.count / nv;
  PM_ENSURE(fabs(rep->fraction - o->fraction) <= GM_CONSTRUCT_TOLERANCE,
            PM_ERR_NOT_CONVERGED,
            "construct: the last segment's voxel steps are too coarse for the "
            "box: fraction %.5f, expected %g +- %g; use a smaller radius or a "
            "larger box",
            rep->fraction, o->fraction, GM_CONSTRUCT_TOLERANCE);
  PM_TRY(gm_image_components(out, &rep->components, &rep->largest));
  rep->largest_share = g.count > 0 ? (double)rep->largest / (double)g.count : 0;
done:
  free(g.tips);
  free(g.segs);
  free(g.added);
  if (ret) gm_image_free(out);
  return ret;
}
