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
 * E t eps / (1 - nu^2) along the tangent, per unit depth. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gm_curve.h"
#include "gm_trisurf.h"
#include "mpm_isonormal.h"
#include "mpm_kind.h"
#include "mpm_exchange.h"
#include "mpm_state.h"
#include "pm_omp.h"

/* State array slots. */
enum { MEM_FRAME = 0, MEM_STRAIN = 1, MEM_OMEGA = 2, MEM_FAILED = 3 };

typedef struct {
  double E, nu;
  double C;       /* plane-stress modulus E / (1 - nu^2) */
  double G;       /* E / (2 (1 + nu)) */
  bool damage;    /* eqs. 38-41 */
  double c0, c1;  /* eq. 39 */
  double limit;   /* S_L, eq. 40 */
  double failure; /* eps_max at failure */
  /* The links the normal stage reads among the group's points (counted
   * from the group's start): triangles of 3 corners, each point's
   * triangles (gm_trisurf's incidence, in triangle order) and, along a
   * curve, each point's neighbours (2 per point: before and after it, as
   * gm_curve_neighbours gives them).  Across ranks a corner or neighbour
   * np + j (np the rank's points of the group) is the j-th ghost: a point
   * of another rank, at mpm_par_ghost_x.  The rooms are the arrays'
   * (across ranks they grow: tri 3 per triangle, inc_start and link 1 and
   * 2 per point). */
  long n_tris, *tri, *inc_start, *inc_tri, *link;
  long tri_room, inc_room, point_room;
  /* Across ranks: the whole group's links on one process (its points
   * counted from `first`, the group's start there), from which a rank's
   * are made whenever points move between ranks; each of the rank's
   * triangles' index among the whole's (increasing). */
  struct {
    long first, n_points, n_tris, *tri, *inc_start, *inc_tri;
  } whole;
  long *tri_whole;
  /* the group's bodies: points [begin, end) counted within the group on
   * one process (the whole group's, across ranks), their links
   * (MPM_LINKS_*) and normal method (pm_normals_method) */
  int n_bodies;
  struct membrane_body {
    int body;
    long begin, end;
    int links, method;
  } * bodies;
  bool iso;      /* some body's normals by isosurface least squares */
  long max_body; /* most points in one body */
} membrane_params;

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

/* ---- the membrane law ----------------------------------------------------
 * In the frame: strain e = (e11, e22, e12) (tensor shear), secant factor
 * d in [0, 1], stress s = d C(e).  Energy W = 1/2 s : e per reference
 * volume. */

static inline double eps_max(const double e[3]) {
  double a = 0.5 * (e[0] + e[1]), b = 0.5 * (e[0] - e[1]);
  return a + sqrt(b * b + e[2] * e[2]);
}

static inline void plane_stress(const membrane_params *mp, const double e[3],
                                double d, double s[3]) {
  s[0] = d * mp->C * (e[0] + mp->nu * e[1]);
  s[1] = d * mp->C * (e[1] + mp->nu * e[0]);
  s[2] = d * 2 * mp->G * e[2];
}

static inline double plane_energy(const membrane_params *mp, const double e[3],
                                  double d) {
  double s[3];
  plane_stress(mp, e, d, s);
  return 0.5 * (s[0] * e[0] + s[1] * e[1] + 2 * s[2] * e[2]);
}

/* The secant factor of eq. 39: 1 + 2 c0 (exp(-c1 omega) - 1), at least 0
 * (a secant stiffness does not turn negative). */
static inline double secant(const membrane_params *mp, double omega) {
  return fmax(0.0, 1.0 + 2.0 * mp->c0 * (exp(-mp->c1 * omega) - 1.0));
}

/* The point's factor d from its damage state (1 without damage). */
static inline double factor_of(const membrane_params *mp, const double *om,
                               const double *failed, long k) {
  if (!mp->damage) return 1.0;
  return failed[k] > 0 ? 0.0 : secant(mp, om[k]);
}

/* Eqs. 38-40 at the largest principal strain e_max: failure at the
 * failure strain, omega on the damage surface f = 0 when e_max passes it;
 * returns the secant factor. */
static inline double damage_step(const membrane_params *mp, double e_max,
                                 double *omega, double *failed) {
  if (*failed <= 0 && e_max >= mp->failure) *failed = 1;
  if (*failed <= 0 && e_max > mp->limit * (1 + *omega))
    *omega = e_max / mp->limit - 1;
  return *failed > 0 ? 0.0 : secant(mp, *omega);
}

double mpm_membrane_damage(const pm_scene_damage *dm, double e_max,
                           double *omega, double *failed) {
  membrane_params mp = {.c0 = dm->c0,
                        .c1 = dm->c1,
                        .limit = dm->elastic_limit,
                        .failure = dm->failure,
                        .damage = true};
  return damage_step(&mp, e_max, omega, failed);
}

double mpm_membrane_max_strain(const double e[3]) { return eps_max(e); }

/* ---- normals and frames ------------------------------------------------- */

/* The position of link point c: the group's point c (positions xo, np of
 * them) or ghost c - np (positions xg). */
static inline const double *link_x(const double *xo, const double *xg, long np,
                                   long c) {
  return c < np ? xo + 3 * c : xg + 3 * (c - np);
}

/* Unit normals of the links' triangles into tn (3 each) from the
 * positions of the group's np points xo and of the ghosts xg; zero for a
 * degenerate triangle. */
static void triangle_normals(const membrane_params *mp, const double *xo,
                             const double *xg, long np, double *tn) {
  const long *tri = mp->tri, nt = mp->n_tris;
  PM_OMP(parallel for schedule(static) default(none)
         shared(tri, nt, xo, xg, np, tn))
  for (long t = 0; t < nt; t++) {
    const double *a = link_x(xo, xg, np, tri[3 * t]),
                 *b = link_x(xo, xg, np, tri[3 * t + 1]),
                 *c = link_x(xo, xg, np, tri[3 * t + 2]);
    double u[3], v[3], n[3];
    for (int i = 0; i < 3; i++) u[i] = b[i] - a[i], v[i] = c[i] - a[i];
    pm_v_cross(u, v, n);
    double len = pm_v_norm(n);
    for (int i = 0; i < 3; i++) tn[3 * t + i] = len > 0 ? n[i] / len : 0;
  }
}

/* The mean of point k's triangles' unit normals, normalised (eq. 8); false
 * when it vanishes. */
static inline bool point_normal(const membrane_params *mp, long k,
                                const double *tn, double n[3]) {
  n[0] = n[1] = n[2] = 0;
  for (long j = mp->inc_start[k]; j < mp->inc_start[k + 1]; j++) {
    const double *a = tn + 3 * mp->inc_tri[j];
    for (int i = 0; i < 3; i++) n[i] += a[i];
  }
  double len = pm_v_norm(n);
  if (!(len > 1e-12)) return false;
  for (int i = 0; i < 3; i++) n[i] /= len;
  return true;
}

/* e1, e2 in the plane of n: e1 from the axis least aligned with n. */
static void frame_from_normal(const double n[3], double f[9]) {
  int a = 0;
  for (int i = 1; i < 3; i++)
    if (fabs(n[i]) < fabs(n[a])) a = i;
  double e1[3] = {0, 0, 0};
  e1[a] = 1;
  double dot = pm_v_dot(e1, n);
  for (int i = 0; i < 3; i++) e1[i] -= dot * n[i];
  double len = pm_v_norm(e1);
  for (int i = 0; i < 3; i++) e1[i] /= len;
  double e2[3];
  pm_v_cross(n, e1, e2);
  memcpy(f, e1, sizeof e1);
  memcpy(f + 3, e2, sizeof e2);
  memcpy(f + 6, n, 3 * sizeof(double));
}

/* v <- S v, the rotation of eq. 22 taking unit n0 to unit n1 and keeping
 * w = n0 x n1: S v = w^ (w^.v) + c (v - w^ (w^.v)) + n1 (n0.v) - n0 (n1.v),
 * c = n0.n1 (S = I when w vanishes). */
static inline void rotate_s(const double n0[3], const double n1[3],
                            double v[3]) {
  double w[3];
  pm_v_cross(n0, n1, w);
  double s = pm_v_norm(w);
  if (!(s > 0)) return;
  for (int i = 0; i < 3; i++) w[i] /= s;
  double c = pm_v_dot(n0, n1), wv = pm_v_dot(w, v), a = pm_v_dot(n0, v),
         b = pm_v_dot(n1, v), r[3];
  for (int i = 0; i < 3; i++)
    r[i] = w[i] * wv + c * (v[i] - w[i] * wv) + n1[i] * a - n0[i] * b;
  memcpy(v, r, sizeof r);
}

/* Carry frame f (e1, e2, n) over the step: turn e1, e2 about n by the
 * in-plane spin angle phi, then apply S from n to n1, and make the frame
 * orthonormal again (e1 projected, e2 = n1 x e1). */
void mpm_membrane_carry_frame(double f[9], double phi, const double n1[3]) {
  double *e1 = f, *e2 = f + 3, *n0 = f + 6;
  double c = cos(phi), s = sin(phi), a[3], b[3];
  for (int i = 0; i < 3; i++) {
    a[i] = c * e1[i] + s * e2[i];
    b[i] = -s * e1[i] + c * e2[i];
  }
  rotate_s(n0, n1, a);
  double dot = pm_v_dot(a, n1);
  for (int i = 0; i < 3; i++) a[i] -= dot * n1[i];
  double len = pm_v_norm(a);
  if (!(len > 0)) {
    frame_from_normal(n1, f);
    return;
  }
  for (int i = 0; i < 3; i++) e1[i] = a[i] / len;
  pm_v_cross(n1, e1, b);
  memcpy(e2, b, sizeof b);
  memcpy(n0, n1, 3 * sizeof(double));
}

/* sigma = sum_ab s_ab e_a (x) e_b over the frame's tangent vectors. */
static inline void to_global(const double f[9], const double s[3],
                             double sig[9]) {
  const double *e1 = f, *e2 = f + 3;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      sig[3 * i + j] = s[0] * e1[i] * e1[j] + s[1] * e2[i] * e2[j] +
                       s[2] * (e1[i] * e2[j] + e2[i] * e1[j]);
}

/* ---- normals by isosurface least squares ---------------------------------
 * Per body, each step: the points sorted by grid cell; each cell fitted on
 * its own (quadratic or linear by the method, or by the hybrid rule), or,
 * with too few points for the hybrid rule, with the points of the block of
 * 2, then 4 cells a side around it taken as one larger element (the block
 * placed so that the cell's points are nearest its middle).  The fits of
 * different cells are independent: one thread each. */

enum { ISO_MERGE_LEVELS = 3 }; /* blocks of 2, 4 and 8 cells a side */

typedef struct {
  long key, k; /* cell key, point (within the body) */
} cell_point;

/* One thread's fits. */
typedef struct {
  mpm_iso_work *fit[2]; /* linear, quadratic */
  long *gather;         /* points of a merged block */
  double *normal;       /* 3 per point of a body: a merged block's normals */
} iso_thread;

typedef struct {
  int threads;
  iso_thread *t;
  cell_point *cp; /* per point of a body */
  long *order;    /* the points in cell order */
  long *run;      /* start of each cell's points in order, and the end */
  /* across ranks: a body's points with the nearby points of other ranks,
   * in one-process order (3 each), their normals, and where each of the
   * rank's points is among them */
  double *xe, *ne;
  long *at;
} iso_work;

/* Where a body's fits are made: the whole grid's nodes per axis (the
 * cells' keys, which seed the fits' draws, count on the whole grid) and
 * the cells whose points' normals are wanted, [lo, hi) per axis (a rank's
 * own; the points in the cells around them serve the merged blocks). */
typedef struct {
  long nn[3], lo[3], hi[3];
} iso_cells;

static void iso_work_free(void *p) {
  iso_work *w = p;
  if (!w) return;
  for (int t = 0; w->t && t < w->threads; t++) {
    mpm_iso_work_destroy(w->t[t].fit[0]);
    mpm_iso_work_destroy(w->t[t].fit[1]);
    free(w->t[t].gather);
    free(w->t[t].normal);
  }
  free(w->t);
  free(w->cp);
  free(w->order);
  free(w->run);
  free(w->xe);
  free(w->ne);
  free(w->at);
  free(w);
}

static pm_err iso_work_create(const mpm_model *m, const mpm_group *g,
                              void **out, size_t *bytes) {
  const membrane_params *mp = g->params;
  *out = NULL;
  *bytes = 0;
  if (!mp->iso) return PM_SUCCESS;
  pm_err ret = PM_SUCCESS;
  iso_work *w = NULL;
  const long n = mp->max_body;
  PM_TRY(PM_ALLOC(w, 1, "membrane normal fits"));
  w->threads = pm_omp_threads();
  PM_TRY(PM_ALLOC(w->t, w->threads, "membrane normal fits"));
  PM_TRY(PM_ALLOC(w->cp, n, "membrane points by cell"));
  PM_TRY(PM_ALLOC(w->order, n, "membrane points by cell"));
  PM_TRY(PM_ALLOC(w->run, n + 1, "membrane cells"));
  *bytes = sizeof *w + (size_t)n * (sizeof(cell_point) + 2 * sizeof(long));
  if (m->xc) {
    PM_TRY(PM_ALLOC(w->xe, 3 * n, "membrane points with nearby ones"));
    PM_TRY(PM_ALLOC(w->ne, 3 * n, "membrane points with nearby ones"));
    PM_TRY(PM_ALLOC(w->at, n, "membrane points with nearby ones"));
    *bytes += (size_t)n * (6 * sizeof(double) + sizeof(long));
  }
  for (int t = 0; t < w->threads; t++) {
    for (int o = 0; o < 2; o++) {
      mpm_iso_config c = mpm_iso_config_default(m->dim, o + 1);
      PM_TRY(mpm_iso_work_create(&c, &w->t[t].fit[o]));
      *bytes += mpm_iso_work_bytes(w->t[t].fit[o]);
    }
    PM_TRY(PM_ALLOC(w->t[t].gather, n, "membrane merged cells"));
    PM_TRY(PM_ALLOC(w->t[t].normal, 3 * n, "membrane merged cells"));
    *bytes += (size_t)n * (sizeof(long) + 3 * sizeof(double));
  }
  *out = w;
  w = NULL;
done:
  iso_work_free(w);
  return ret;
}

static int cell_point_cmp(const void *a, const void *b) {
  const cell_point *p = a, *q = b;
  if (p->key != q->key) return p->key < q->key ? -1 : 1;
  return (p->k > q->k) - (p->k < q->k);
}

/* The cell of x (indices of its lower node), its key on the whole grid
 * of nn nodes per axis. */
static inline long cell_of(const mpm_grid *g, const long nn[3],
                           const double x[3], long c[3]) {
  c[2] = 0;
  for (int d = 0; d < g->dim; d++)
    c[d] = (long)floor((x[d] - g->origin[d]) * g->inv_h);
  return c[0] + nn[0] * (c[1] + nn[1] * c[2]);
}

/* The points of the cell at key in cell order [*lo, *hi), found by
 * bisection of the sorted cells; false when it has none. */
static bool cell_range(const iso_work *w, long n_cells, long key, long *lo,
                       long *hi) {
  long a = 0, b = n_cells;
  while (a < b) {
    long mid = (a + b) / 2;
    long km = w->cp[w->run[mid]].key;
    if (km < key)
      a = mid + 1;
    else
      b = mid;
  }
  if (a >= n_cells || w->cp[w->run[a]].key != key) return false;
  *lo = w->run[a];
  *hi = w->run[a + 1];
  return true;
}

/* Whether the n points x + 3 idx[k] spread over a surface in 3D, not
 * along a line: the second principal variance of their covariance at least
 * ISO_SPREAD of the largest (m2 / tr^2, m2 the sum of its principal 2 x 2
 * minors, is that ratio when the third vanishes).  Points along a line do
 * not fix the plane through them: a fit takes some plane, and a flat sheet
 * turned rigidly got normals 9 degrees off.  Always true in 2D (a curve). */
#define ISO_SPREAD 0.01
static bool spread(int dim, const double *x, const long *idx, long n) {
  if (dim == 2) return true;
  double c[3] = {0, 0, 0}, C[3][3] = {{0}};
  for (long k = 0; k < n; k++)
    for (int d = 0; d < 3; d++) c[d] += x[3 * idx[k] + d] / (double)n;
  for (long k = 0; k < n; k++) {
    double u[3];
    for (int d = 0; d < 3; d++) u[d] = x[3 * idx[k] + d] - c[d];
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) C[a][b] += u[a] * u[b];
  }
  const double tr = C[0][0] + C[1][1] + C[2][2];
  const double m2 = C[0][0] * C[1][1] - C[0][1] * C[0][1] + C[0][0] * C[2][2] -
                    C[0][2] * C[0][2] + C[1][1] * C[2][2] - C[1][2] * C[1][2];
  return m2 > ISO_SPREAD * tr * tr;
}

/* A fit's seed: the step, the body, the cell and the block level mixed
 * (splitmix64's finaliser), so that a run repeats bit for bit whatever
 * thread fits which cell. */
static inline uint64_t fit_seed(long step, int body, long key, int level) {
  return mpm_iso_mix((uint64_t)step * 0x9E3779B97F4A7C15ull ^
                     ((uint64_t)body << 56) ^ ((uint64_t)level << 48) ^
                     (uint64_t)key * 0xBF58476D1CE4E5B9ull);
}

typedef struct {
  long cells[4], points, degenerate, draws;
  double max_condition;
} iso_stats;

static void stats_merge(iso_stats *a, const iso_stats *b) {
  for (int i = 0; i < 4; i++) a->cells[i] += b->cells[i];
  a->points += b->points;
  a->degenerate += b->degenerate;
  a->draws += b->draws;
  if (b->max_condition > a->max_condition) a->max_condition = b->max_condition;
}

static void stats_add(iso_stats *a, const mpm_iso_report *r, long points) {
  a->points += points;
  a->degenerate += r->degenerate;
  a->draws += r->draws;
  if (r->condition > a->max_condition) a->max_condition = r->condition;
}

/* Normals nn (3 per point of the body, holding its previous normals on
 * entry) of the body's n points at x (3 each), by method, at step `step`,
 * for the points in the cells [cells->lo, cells->hi). */
static pm_err iso_normals(const mpm_grid *g, const iso_cells *cells,
                          iso_work *w, int body, int method, long n,
                          const double *x, long step, double *nn,
                          iso_stats *st) {
  const int dim = g->dim;
  const long *gn = cells->nn;
  for (long k = 0; k < n; k++) {
    long c[3];
    w->cp[k].key = cell_of(g, gn, x + 3 * k, c);
    w->cp[k].k = k;
  }
  qsort(w->cp, (size_t)n, sizeof *w->cp, cell_point_cmp);
  long n_cells = 0;
  for (long k = 0; k < n; k++) {
    w->order[k] = w->cp[k].k;
    if (k == 0 || w->cp[k].key != w->cp[k - 1].key) w->run[n_cells++] = k;
  }
  w->run[n_cells] = n;
  pm_err err = PM_SUCCESS;
  iso_stats sum = {0};
  PM_OMP(parallel default(none) shared(g, cells, gn, w, body, method, n, x,
                                       step, nn, n_cells, dim, err, sum)) {
    iso_stats my = {0};
    iso_thread *th = &w->t[pm_omp_thread()];
    PM_OMP(for schedule(dynamic, 8))
    for (long ci = 0; ci < n_cells; ci++) {
      const long r0 = w->run[ci], r1 = w->run[ci + 1], cnt = r1 - r0;
      const long key = w->cp[r0].key;
      long cell[3];
      cell_of(g, gn, x + 3 * w->order[r0], cell);
      bool wanted = true;
      for (int d = 0; d < dim; d++)
        wanted = wanted && cell[d] >= cells->lo[d] && cell[d] < cells->hi[d];
      if (!wanted) continue; /* another rank's */
      int order = method == PM_NORMALS_ISO_LINEAR ? 1
                  : method == PM_NORMALS_ISO_QUADRATIC
                      ? 2
                      : mpm_iso_hybrid_order(dim, cnt);
      /* hybrid-quadratic: quadratic or merged; linear only on the largest
       * block. */
      const bool hybrid =
          method == PM_NORMALS_HYBRID || method == PM_NORMALS_HYBRID_QUADRATIC;
      const int block_order = method == PM_NORMALS_HYBRID_QUADRATIC ? 2 : 1;
      if (hybrid && order > 0 &&
          (order < block_order || !spread(dim, x, w->order + r0, cnt)))
        order = 0;
      mpm_iso_report rep;
      double lo[3] = {0, 0, 0};
      if (order > 0) {
        for (int d = 0; d < dim; d++) lo[d] = g->origin[d] + cell[d] * g->h;
        for (long r = r0; r < r1; r++)
          for (int d = 0; d < 3; d++)
            th->normal[3 * w->order[r] + d] = nn[3 * w->order[r] + d];
        pm_err e =
            mpm_iso_fit(th->fit[order - 1], lo, g->h, cnt, x, w->order + r0,
                        fit_seed(step, body, key, 0), nn, &rep);
        if (e) {
          PM_OMP(critical(membrane_iso)) err = e;
          continue;
        }
        /* Hybrid: points in a special position (on a line or a conic of
         * the surface) leave S rank deficient, and the minimum-norm phi is
         * not constant along the surface (7 points of a flat sheet gave a
         * normal 2.7 degrees off): the cell is merged as a sparse one. */
        if (!hybrid || rep.rank == mpm_iso_unknowns(dim, order)) {
          my.cells[order == 2 ? 0 : 1]++;
          stats_add(&my, &rep, cnt);
          continue;
        }
        for (long r = r0; r < r1; r++)
          for (int d = 0; d < 3; d++)
            nn[3 * w->order[r] + d] = th->normal[3 * w->order[r] + d];
      }
      /* Too few points (or, by the hybrid rule, points that do not fix the
       * surface): the block of B cells a side around the cell, B = 2, 4, 8,
       * until it has enough for a full-rank linear fit. */
      double mid[3] = {0, 0, 0};
      for (long r = r0; r < r1; r++)
        for (int d = 0; d < dim; d++)
          mid[d] += (x[3 * w->order[r] + d] - g->origin[d]) * g->inv_h / cnt;
      bool done_cell = false;
      for (int level = 1; level <= ISO_MERGE_LEVELS && !done_cell; level++) {
        const long B = 1L << level;
        long first[3] = {0, 0, 0}, span[3] = {1, 1, 1};
        for (int d = 0; d < dim; d++) {
          long f = lround(mid[d] - 0.5 * (double)B);
          if (f > cell[d]) f = cell[d];
          if (f < cell[d] - B + 1) f = cell[d] - B + 1;
          first[d] = f;
          span[d] = B;
        }
        long m = 0;
        for (long c2 = 0; c2 < span[2]; c2++)
          for (long c1 = 0; c1 < span[1]; c1++)
            for (long c0 = 0; c0 < span[0]; c0++) {
              long q[3] = {first[0] + c0, first[1] + c1, first[2] + c2}, a, z;
              bool in = true;
              for (int d = 0; d < dim; d++)
                if (q[d] < 0 || q[d] >= gn[d] - 1) in = false;
              if (!in ||
                  !cell_range(w, n_cells, q[0] + gn[0] * (q[1] + gn[1] * q[2]),
                              &a, &z))
                continue;
              for (long r = a; r < z; r++) th->gather[m++] = w->order[r];
            }
        /* The larger element's fit: linear as the paper does (hybrid), or
         * quadratic when the block has enough points (hybrid-quadratic);
         * else the next block, and the largest block's fit whatever it
         * has (linear). */
        order = mpm_iso_hybrid_order(dim, m) >= block_order ? block_order : 0;
        if ((order == 0 || !spread(dim, x, th->gather, m)) &&
            level < ISO_MERGE_LEVELS)
          continue;
        if (order == 0) order = 1;
        for (int d = 0; d < dim; d++) lo[d] = g->origin[d] + first[d] * g->h;
        for (long r = r0; r < r1; r++)
          for (int d = 0; d < 3; d++)
            th->normal[3 * w->order[r] + d] = nn[3 * w->order[r] + d];
        pm_err e = mpm_iso_fit(th->fit[order - 1], lo, (double)B * g->h, m, x,
                               th->gather, fit_seed(step, body, key, level),
                               th->normal, &rep);
        if (e) {
          PM_OMP(critical(membrane_iso)) err = e;
          break;
        }
        if (rep.rank < mpm_iso_unknowns(dim, order) && level < ISO_MERGE_LEVELS)
          continue;
        for (long r = r0; r < r1; r++)
          for (int d = 0; d < 3; d++)
            nn[3 * w->order[r] + d] = th->normal[3 * w->order[r] + d];
        my.cells[rep.rank == mpm_iso_unknowns(dim, order) ? 2 : 3]++;
        stats_add(&my, &rep, cnt);
        done_cell = true;
      }
    }
    PM_OMP(critical(membrane_iso_stats)) stats_merge(&sum, &my);
  }
  stats_merge(st, &sum);
  return err;
}

/* ---- normals of every body of the group ---------------------------------- */

/* The first of the n increasing a[] that is at least v. */
static long lower_bound(const long *a, long n, long v) {
  long lo = 0, hi = n;
  while (lo < hi) {
    const long mid = lo + (hi - lo) / 2;
    if (a[mid] < v)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* Across ranks, the fitted normals nn of body b's points of the rank
 * (group points [b0, b1), positions x from the group's start): fitted with
 * the nearby points of other ranks (those within the merged blocks' reach
 * of the rank's cells), all in one-process order, so that each cell of
 * the rank is fitted to the points, in the order, one process fits it
 * to. */
static pm_err iso_normals_ranks(const mpm_model *m, const mpm_group *gr,
                                const struct membrane_body *b,
                                const iso_cells *cells, iso_work *w, long b0,
                                long b1, const double *x, long step, double *nn,
                                iso_stats *st) {
  const membrane_params *mp = gr->params;
  const long *own = m->gid + gr->begin, *ids;
  long n_near;
  const double *xn = mpm_xc_nearby(m, gr->index, &n_near, &ids);
  const long j0 = lower_bound(ids, n_near, mp->whole.first + b->begin),
             j1 = lower_bound(ids, n_near, mp->whole.first + b->end);
  long e = 0;
  for (long k = b0, j = j0; k < b1 || j < j1; e++) {
    const bool mine = j >= j1 || (k < b1 && own[k] < ids[j]);
    if (mine) {
      memcpy(w->xe + 3 * e, x + 3 * k, 3 * sizeof(double));
      memcpy(w->ne + 3 * e, nn + 3 * k, 3 * sizeof(double));
      w->at[k++ - b0] = e;
    } else {
      memcpy(w->xe + 3 * e, xn + 3 * j++, 3 * sizeof(double));
      memset(w->ne + 3 * e, 0, 3 * sizeof(double)); /* not read */
    }
  }
  PM_CALL(iso_normals(&m->grid, cells, w, b->body, b->method, e, w->xe, step,
                      w->ne, st));
  for (long k = b0; k < b1; k++)
    memcpy(nn + 3 * k, w->ne + 3 * w->at[k - b0], 3 * sizeof(double));
  return PM_SUCCESS;
}

/* Each point's new unit normal into nn (3 per point of the group, holding
 * the previous normals n0 on entry; a point without one keeps n0), by its
 * body's method.  tn: 3 per triangle of the links.  The bodies' points are
 * the model's (across ranks, the rank's), their neighbours on other ranks
 * the ghosts. */
static pm_err group_normals(const mpm_model *m, const mpm_group *gr,
                            const double *x, long step, iso_work *iw,
                            double *tn, double *nn, iso_stats *st) {
  const membrane_params *mp = gr->params;
  const long np = gr->end - gr->begin;
  const double *xo = x + 3 * gr->begin, *xg = mpm_xc_ghost_x(m, gr->index);
  if (mp->n_tris > 0) triangle_normals(mp, xo, xg, np, tn);
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    const long b0 = m->body_begin[b->body] - gr->begin,
               b1 = m->body_end[b->body] - gr->begin;
    if (b->method != PM_NORMALS_CONNECTIVITY) {
      iso_cells cells;
      mpm_xc_cells(m, cells.nn, cells.lo, cells.hi);
      if (m->xc)
        PM_CALL(
            iso_normals_ranks(m, gr, b, &cells, iw, b0, b1, xo, step, nn, st));
      else
        PM_CALL(iso_normals(&m->grid, &cells, iw, b->body, b->method, b1 - b0,
                            xo + 3 * b0, step, nn + 3 * b0, st));
      continue;
    }
    if (b->links == MPM_LINKS_TRIANGLES) {
      for (long k = b0; k < b1; k++) {
        double n1[3];
        if (point_normal(mp, k, tn, n1)) memcpy(nn + 3 * k, n1, sizeof n1);
      }
      continue;
    }
    /* A curve: perpendicular to the chord of the neighbours (a point whose
     * chord vanishes gets 0, and the stress stage keeps its normal). */
    const long *link = mp->link;
    for (long k = b0; k < b1; k++)
      gm_curve_normal(link_x(xo, xg, np, link[2 * k]),
                      link_x(xo, xg, np, link[2 * k + 1]), nn + 3 * k);
  }
  return PM_SUCCESS;
}

static const char *const method_words[] = {
    "connectivity", "isosurface least squares, linear B-splines",
    "isosurface least squares, quadratic B-splines",
    "isosurface least squares, hybrid (quadratic, linear, or merged cells)",
    "isosurface least squares, hybrid-quadratic (quadratic on the smallest "
    "block of cells with enough points)"};

static void membrane_describe_normals(const mpm_model *m, const mpm_group *g,
                                      char *buf, size_t size) {
  (void)m;
  const membrane_params *mp = g->params;
  size_t used = 0;
  for (int bi = 0; bi < mp->n_bodies && used < size; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    const char *how = method_words[b->method];
    if (b->method == PM_NORMALS_CONNECTIVITY)
      how = b->links == MPM_LINKS_TRIANGLES
                ? "mean of the triangles' (eq. 8)"
                : "perpendicular to the neighbours' "
                  "chord";
    int len = snprintf(buf + used, size - used, "%sbodies.%d: %s",
                       bi ? "; " : "", b->body, how);
    if (len < 0) break;
    used += (size_t)len;
  }
}

/* The centre of body b (the mean of its points, x counted within the
 * group). */
static void body_centre(const double *x, const struct membrane_body *b,
                        double c[3]) {
  c[0] = c[1] = c[2] = 0;
  for (long j = b->begin; j < b->end; j++)
    for (int d = 0; d < 3; d++)
      c[d] += x[3 * j + d] / (double)(b->end - b->begin);
}

/* The unit vector from c to point k, or 0. */
static void away_from(const double *x, const double c[3], long k, double v[3]) {
  for (int d = 0; d < 3; d++) v[d] = x[3 * k + d] - c[d];
  double len = pm_v_norm(v);
  for (int d = 0; d < 3; d++) v[d] = len > 0 ? v[d] / len : 0;
}

/* The group's bodies, its incidence, and each point's first normal and
 * frame (setup).  Without connectivity, the first normals are turned to
 * point away from the body's centre. */
static pm_err membrane_finish(const mpm_model *m, mpm_group *g, mpm_state *s) {
  membrane_params *mp = g->params;
  const long t0 = m->tri_begin[g->index], t1 = m->tri_end[g->index];
  const long np = g->end - g->begin;
  double *tn = NULL, *nn = NULL, *ref = NULL;
  void *iw = NULL;
  size_t iw_bytes;
  pm_err ret = PM_SUCCESS;
  PM_TRY(PM_ALLOC(mp->bodies, m->n_bodies, "membrane bodies"));
  for (int b = 0; b < m->n_bodies; b++) {
    if (m->body_end[b] <= m->body_begin[b] || m->body_begin[b] < g->begin ||
        m->body_end[b] > g->end)
      continue;
    struct membrane_body *mb = &mp->bodies[mp->n_bodies++];
    mb->body = b;
    mb->begin = m->body_begin[b] - g->begin;
    mb->end = m->body_end[b] - g->begin;
    mb->links = m->body_links[b];
    mb->method = m->body_normals[b];
    if (mb->method != PM_NORMALS_CONNECTIVITY) mp->iso = true;
    if (mb->end - mb->begin > mp->max_body) mp->max_body = mb->end - mb->begin;
  }
  /* The links: the group's triangles, each point's (the surface's
   * incidence), and along curves each point's neighbours. */
  PM_TRY(mpm_triangles_local(m, t0, t1, g->begin, &mp->tri));
  mp->n_tris = mp->tri_room = t1 - t0;
  mp->point_room = np;
  gm_trisurf sf = {.n_points = np,
                   .x = s->x + 3 * g->begin,
                   .n_tris = t1 - t0,
                   .tri = mp->tri};
  PM_TRY(gm_trisurf_incidence(&sf, &mp->inc_start, &mp->inc_tri));
  mp->inc_room = mp->inc_start[np];
  PM_TRY(PM_ALLOC(mp->link, 2 * np + 1, "membrane curves"));
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    if (b->links != MPM_LINKS_CHAIN && b->links != MPM_LINKS_LOOP) continue;
    for (long k = b->begin; k < b->end; k++) {
      long prev, next;
      gm_curve_neighbours(k - b->begin, b->end - b->begin,
                          b->links == MPM_LINKS_LOOP, &prev, &next);
      mp->link[2 * k] = b->begin + prev;
      mp->link[2 * k + 1] = b->begin + next;
    }
  }
  PM_TRY(PM_ALLOC(tn, 3 * (t1 - t0) + 3, "triangle normals"));
  PM_TRY(PM_ALLOC(nn, 3 * np, "membrane normals"));
  PM_TRY(iso_work_create(m, g, &iw, &iw_bytes));
  /* The reference of the first normals' sides: the connectivity's
   * normals where the body has connectivity, else away from its centre;
   * they are also the fit's previous normals. */
  PM_TRY(PM_ALLOC(ref, 3 * np, "membrane normals"));
  const double *xo = s->x + 3 * g->begin;
  if (t1 > t0) triangle_normals(mp, xo, NULL, np, tn);
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    if (b->links == MPM_LINKS_CHAIN || b->links == MPM_LINKS_LOOP)
      gm_curve_normals(b->end - b->begin, xo + 3 * b->begin,
                       b->links == MPM_LINKS_LOOP, ref + 3 * b->begin);
    double c[3];
    body_centre(xo, b, c);
    for (long k = b->begin; k < b->end; k++) {
      if (b->links == MPM_LINKS_TRIANGLES) point_normal(mp, k, tn, ref + 3 * k);
      if (!(pm_v_norm(ref + 3 * k) > 0.5)) away_from(xo, c, k, ref + 3 * k);
    }
  }
  memcpy(nn, ref, sizeof(double) * 3 * (size_t)np);
  iso_stats st = {0};
  PM_TRY(group_normals(m, g, s->x, -1, iw, tn, nn, &st));
  double *frame = s->group[g->index].array[MEM_FRAME].data;
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    for (long k = b->begin; k < b->end; k++) {
      double *n = nn + 3 * k, *xp = s->x + 3 * (g->begin + k);
      /* A fitted normal's sign is arbitrary: the reference's side. */
      if (pm_v_dot(n, ref + 3 * k) < 0)
        for (int d = 0; d < 3; d++) n[d] = -n[d];
      bool has = pm_v_norm(n) > 0.5;
      if (has && b->method == PM_NORMALS_CONNECTIVITY &&
          b->links == MPM_LINKS_TRIANGLES) {
        double n1[3];
        has = point_normal(mp, k, tn, n1);
      }
      PM_ENSURE(has, PM_ERR_SCENE,
                "membrane %s: point %ld at (%g, %g, %g) has no normal (it "
                "belongs to no triangle, or its triangles' normals cancel)",
                g->name, g->begin + k, xp[0], xp[1], xp[2]);
      frame_from_normal(n, frame + 9 * k);
    }
  }
done:
  iso_work_free(iw);
  free(tn);
  free(nn);
  free(ref);
  return ret;
}

/* Doubles of step workspace: each point's new normal, each triangle's
 * (across ranks, room for as many as the arrays have). */
static long membrane_scratch(const mpm_model *m, const mpm_group *g) {
  (void)m;
  const membrane_params *mp = g->params;
  const long np = g->end - g->begin;
  return 3 * (g->cap > np ? g->cap : np) + 3 * mp->tri_room;
}

/* ---- across ranks ---------------------------------------------------------
 * A rank's points of the group read their neighbours' positions: the
 * points of its triangles, and along a curve the points before and after
 * them.  Those on other ranks are ghosts (mpm_par.h sends their positions
 * after every step's migration); the links are made anew from the whole
 * group's whenever points move between ranks. */

/* Room for n longs in *a (room *room), kept when it suffices. */
static pm_err room_for_longs(long **a, long *room, long n, const char *what) {
  if (n <= *room && *a) return PM_SUCCESS;
  const long r = n + n / 4 + 16;
  PM_CALL(PM_REALLOC(*a, r, what));
  *room = r;
  return PM_SUCCESS;
}

static int long_cmp(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

/* Sort n longs and drop repeats; returns how many are left. */
static long sort_unique(long *a, long n) {
  if (n == 0) return 0;
  qsort(a, (size_t)n, sizeof *a, long_cmp);
  long k = 1;
  for (long i = 1; i < n; i++)
    if (a[i] != a[k - 1]) a[k++] = a[i];
  return k;
}

/* The place of v in the sorted a[0, n), or -1. */
static long find_long(const long *a, long n, long v) {
  const long *f = bsearch(&v, a, (size_t)n, sizeof *a, long_cmp);
  return f ? f - a : -1;
}

static pm_err membrane_ranks_share(const mpm_group *whole, mpm_group *g) {
  const membrane_params *wp = whole->params;
  membrane_params *mp = g->params;
  const long np = whole->end - whole->begin;
  PM_CALL(PM_ALLOC(mp->bodies, wp->n_bodies + 1, "membrane bodies"));
  memcpy(mp->bodies, wp->bodies, sizeof *wp->bodies * (size_t)wp->n_bodies);
  mp->n_bodies = wp->n_bodies;
  mp->iso = wp->iso;
  mp->max_body = wp->max_body;
  mp->whole.first = whole->begin;
  mp->whole.n_points = np;
  mp->whole.n_tris = wp->n_tris;
  PM_CALL(PM_ALLOC(mp->whole.tri, 3 * wp->n_tris + 1, "membrane triangles"));
  PM_CALL(PM_ALLOC(mp->whole.inc_start, np + 1, "membrane incidence"));
  PM_CALL(
      PM_ALLOC(mp->whole.inc_tri, wp->inc_start[np] + 1, "membrane incidence"));
  memcpy(mp->whole.tri, wp->tri, sizeof(long) * 3 * (size_t)wp->n_tris);
  memcpy(mp->whole.inc_start, wp->inc_start, sizeof(long) * (size_t)(np + 1));
  memcpy(mp->whole.inc_tri, wp->inc_tri,
         sizeof(long) * (size_t)wp->inc_start[np]);
  return PM_SUCCESS;
}

/* The link point of the whole group's point q: the rank's point (from the
 * group's start; its points' one-process indices own[0, np), increasing)
 * or np + its place among the ghosts want[0, nw). */
static long link_of(const long *own, long np, const long *want, long nw,
                    long q) {
  long k = find_long(own, np, q);
  return k >= 0 ? k : np + find_long(want, nw, q);
}

static pm_err membrane_ranks_link(const mpm_model *m, mpm_group *g, long **want,
                                  long *room, long *n_want) {
  membrane_params *mp = g->params;
  const long np = g->end - g->begin, first = mp->whole.first;
  const long *own = m->gid + g->begin, *ws = mp->whole.inc_start,
             *wi = mp->whole.inc_tri, *wt = mp->whole.tri;
  /* The triangles of the rank's points, by their index in the whole. */
  long nt = 0;
  for (long k = 0; k < np; k++)
    nt += ws[own[k] - first + 1] - ws[own[k] - first];
  const long ni = nt; /* the incidence's entries */
  const long tri_room = mp->tri_room;
  PM_CALL(
      room_for_longs(&mp->tri_whole, &mp->tri_room, nt, "membrane triangles"));
  if (mp->tri_room != tri_room || !mp->tri)
    PM_CALL(PM_REALLOC(mp->tri, 3 * mp->tri_room, "membrane triangles"));
  if (np > mp->point_room || !mp->link) {
    const long r = np + np / 4 + 16;
    PM_CALL(PM_REALLOC(mp->link, 2 * r, "membrane curves"));
    PM_CALL(PM_REALLOC(mp->inc_start, r + 1, "membrane incidence"));
    mp->point_room = r;
  }
  PM_CALL(
      room_for_longs(&mp->inc_tri, &mp->inc_room, ni, "membrane incidence"));
  nt = 0;
  for (long k = 0; k < np; k++)
    for (long j = ws[own[k] - first]; j < ws[own[k] - first + 1]; j++)
      mp->tri_whole[nt++] = wi[j];
  nt = sort_unique(mp->tri_whole, nt);
  /* The ghosts: their corners and the curves' neighbours that are not the
   * rank's, by one-process index. */
  PM_CALL(room_for_longs(want, room, 3 * nt + 2 * np, "membrane ghosts"));
  long nw = 0;
  for (long t = 0; t < nt; t++)
    for (int c = 0; c < 3; c++) {
      const long q = first + wt[3 * mp->tri_whole[t] + c];
      if (find_long(own, np, q) < 0) (*want)[nw++] = q;
    }
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    if (b->links != MPM_LINKS_CHAIN && b->links != MPM_LINKS_LOOP) continue;
    const long b0 = m->body_begin[b->body] - g->begin,
               b1 = m->body_end[b->body] - g->begin;
    for (long k = b0; k < b1; k++) {
      long prev, next;
      gm_curve_neighbours(own[k] - first - b->begin, b->end - b->begin,
                          b->links == MPM_LINKS_LOOP, &prev, &next);
      mp->link[2 * k] = first + b->begin + prev; /* one-process, for now */
      mp->link[2 * k + 1] = first + b->begin + next;
      for (int e = 0; e < 2; e++)
        if (find_long(own, np, mp->link[2 * k + e]) < 0)
          (*want)[nw++] = mp->link[2 * k + e];
    }
  }
  nw = sort_unique(*want, nw);
  *n_want = nw;
  /* The triangles' corners, the incidence and the curves' neighbours as
   * link points. */
  for (long t = 0; t < nt; t++)
    for (int c = 0; c < 3; c++)
      mp->tri[3 * t + c] =
          link_of(own, np, *want, nw, first + wt[3 * mp->tri_whole[t] + c]);
  mp->n_tris = nt;
  long at = 0;
  for (long k = 0; k < np; k++) {
    mp->inc_start[k] = at;
    for (long j = ws[own[k] - first]; j < ws[own[k] - first + 1]; j++)
      mp->inc_tri[at++] = find_long(mp->tri_whole, nt, wi[j]);
  }
  mp->inc_start[np] = at;
  for (int bi = 0; bi < mp->n_bodies; bi++) {
    const struct membrane_body *b = &mp->bodies[bi];
    if (b->links != MPM_LINKS_CHAIN && b->links != MPM_LINKS_LOOP) continue;
    for (long k = m->body_begin[b->body] - g->begin;
         k < m->body_end[b->body] - g->begin; k++)
      for (int e = 0; e < 2; e++)
        mp->link[2 * k + e] = link_of(own, np, *want, nw, mp->link[2 * k + e]);
  }
  return PM_SUCCESS;
}

/* The normal stage: each point's new normal into the group's workspace. */
static pm_err membrane_normals(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  const int gi = self->group;
  const mpm_group *gr = &m->group[gi];
  const long np = gr->end - gr->begin;
  double *nn = w->scratch[gi], *tn = nn + 3 * np;
  const double *frame = s->group[gi].array[MEM_FRAME].data;
  for (long k = 0; k < np; k++)
    for (int d = 0; d < 3; d++) nn[3 * k + d] = frame[9 * k + 6 + d];
  iso_stats st = {0};
  pm_err e = group_normals(m, gr, s->x, s->step, w->kind_work[gi], tn, nn, &st);
  /* Across ranks each cell is fitted by one rank: the fits' figures are
   * the ranks' summed (every rank then keeps the run's, as one process). */
  double v[8] = {(double)st.cells[0], (double)st.cells[1],
                 (double)st.cells[2], (double)st.cells[3],
                 (double)st.points,   (double)st.degenerate,
                 (double)st.draws,    st.max_condition};
  if (m->xc && ((const membrane_params *)gr->params)->iso) {
    mpm_xc_sum(m, v, 7);
    mpm_xc_max(m, v + 7, 1);
  }
  if (e) return e;
  for (int i = 0; i < 4; i++) s->iso.cells[i] += v[i];
  s->iso.points += v[4];
  s->iso.degenerate += v[5];
  s->iso.draws += v[6];
  s->iso.max_condition = v[7];
  return PM_SUCCESS;
}

/* Across ranks, the cells around a rank's whose points its fits read: a
 * merged block of up to 2^ISO_MERGE_LEVELS cells a side reaches that many
 * less one beyond the cell it fits. */
static int membrane_ranks_reach(const mpm_group *g) {
  const membrane_params *mp = g->params;
  return mp->iso ? (1 << ISO_MERGE_LEVELS) - 1 : 0;
}

/* ---- the stage ---------------------------------------------------------- */

static pm_err membrane_stress(mpm_ctx *ctx, const mpm_stage *self) {
  const mpm_model *m = ctx->model;
  mpm_state *s = ctx->state;
  mpm_work *w = ctx->work;
  const int gi = self->group;
  const mpm_group *gr = &m->group[gi];
  const mpm_grid *g = &m->grid;
  const membrane_params *mp = gr->params;
  const long begin = gr->begin, end = gr->end;
  const double dt = s->dt, jmin = m->opt.min_jacobian;
  const double ez_of = -mp->nu / (1 - mp->nu); /* eq. 1 */
  const double *nn = w->scratch[gi];           /* the normal stage's */
  /* The strain follows the velocity that moves the points (MUSL's remapped
   * velocity differs from it by the particles' noise, and a membrane whose
   * strain and positions part creeps without stretching). */
  const double *vel =
      m->opt.update == MPM_MUSL ? w->nodes.vel_new : w->nodes.vel_stress;
  const double *x = s->x, *vol0 = m->vol0;
  mpm_group_state *gs = &s->group[gi];
  double *frame = gs->array[MEM_FRAME].data, *eps = gs->array[MEM_STRAIN].data;
  double *om = mp->damage ? gs->array[MEM_OMEGA].data : NULL;
  double *failed = mp->damage ? gs->array[MEM_FAILED].data : NULL;
  double *vol = s->vol, *sigma = s->sigma;
  double lost = 0, Jlow = INFINITY;
  PM_OMP(parallel for schedule(static) default(none)
         shared(g, mp, w, begin, end, dt, jmin, ez_of, nn, vel, x, vol0,
                frame, eps, om, failed, vol, sigma)
         reduction(+ : lost) reduction(min : Jlow))
  for (long p = begin; p < end; p++) {
    const long k = p - begin;
    double L[9], D[9], W[9], n1[3];
    double *f = frame + 9 * k, *e = eps + 3 * k, *sig = sigma + 9 * p;
    mpm_velocity_gradient(g, vel, x + 3 * p, L);
    mpm_sym_skew(L, D, W);
    /* The spin about the normal: the axial vector of W along n. */
    const double *n0 = f + 6;
    double spin = W[7] * n0[0] + W[2] * n0[1] + W[3] * n0[2];
    /* The new normal, on the side of the old one (a fitted normal's sign
     * is arbitrary; S must not see a flip). */
    memcpy(n1, nn + 3 * k, sizeof n1);
    if (!(pm_v_norm(n1) > 0.5)) memcpy(n1, n0, sizeof n1);
    if (pm_v_dot(n1, n0) < 0)
      for (int d = 0; d < 3; d++) n1[d] = -n1[d];
    mpm_membrane_carry_frame(f, spin * dt, n1);
    /* The strain increment in the frame. */
    const double *e1 = f, *e2 = f + 3;
    double De1[3], De2[3];
    for (int i = 0; i < 3; i++) {
      De1[i] = D[3 * i] * e1[0] + D[3 * i + 1] * e1[1] + D[3 * i + 2] * e1[2];
      De2[i] = D[3 * i] * e2[0] + D[3 * i + 1] * e2[1] + D[3 * i + 2] * e2[2];
    }
    e[0] += dt * pm_v_dot(e1, De1);
    e[1] += dt * pm_v_dot(e2, De2);
    e[2] += dt * pm_v_dot(e1, De2);
    double J = 1 + (1 + ez_of) * (e[0] + e[1]);
    if (!(J > jmin) || !isfinite(J)) {
      mpm_fail(w, p,
               "membrane area-thickness ratio J = %g <= %g (the membrane is "
               "compressed through itself)",
               J, jmin);
      continue;
    }
    vol[p] = vol0[p] * J;
    Jlow = fmin(Jlow, J);
    double d = 1.0;
    if (mp->damage) {
      double d_old = factor_of(mp, om, failed, k);
      double w_old = plane_energy(mp, e, d_old);
      d = damage_step(mp, eps_max(e), &om[k], &failed[k]);
      lost += vol0[p] * (w_old - plane_energy(mp, e, d));
    }
    double sl[3];
    plane_stress(mp, e, d, sl);
    to_global(f, sl, sig);
  }
  if (Jlow < w->min_jacobian) w->min_jacobian = Jlow;
  if (mp->damage) mpm_book_dissipated(ctx, self, lost);
  return mpm_stage_status(ctx, self);
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

const mpm_kind mpm_kind_membrane = {
    .name = "membrane",
    .stage_name = "stress: membrane",
    .flags = MPM_KIND_STRAIN_ENERGY | MPM_KIND_MEMBRANE,
    .setup = membrane_setup,
    .release = membrane_release,
    .seed = membrane_seed,
    .finish = membrane_finish,
    .scratch = membrane_scratch,
    .ranks_share = membrane_ranks_share,
    .ranks_link = membrane_ranks_link,
    .ranks_reach = membrane_ranks_reach,
    .work_create = iso_work_create,
    .work_free = iso_work_free,
    .pre_stress = membrane_normals,
    .pre_stage_name = "normals: membrane",
    .describe_pre = membrane_describe_normals,
    .stress = membrane_stress,
    .describe = membrane_describe,
    .wave_speeds = membrane_wave_speeds,
    .energies = membrane_energies,
    .fields = membrane_fields,
    .surface_fields = membrane_surface_fields,
};
