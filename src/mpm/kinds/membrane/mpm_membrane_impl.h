/* mpm_membrane_impl: what the files of the membrane kind share (not a
 * public interface): its state slots and constants, the membrane law, the
 * link points, and the functions the kind's table entry gathers. */
#ifndef MPM_MEMBRANE_IMPL_H
#define MPM_MEMBRANE_IMPL_H

#include <math.h>
#include <stdint.h>

#include "mpm_kind.h"
#include "mpm_state.h"

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
   * of another rank, at mpm_xc_ghost_x.  The rooms are the arrays'
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

/* ---- links and the stress's frame -------------------------------------- */

/* The position of link point c: the group's point c (positions xo, np of
 * them) or ghost c - np (positions xg). */
static inline const double *link_x(const double *xo, const double *xg, long np,
                                   long c) {
  return c < np ? xo + 3 * c : xg + 3 * (c - np);
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

/* sigma = sum_ab s_ab e_a (x) e_b over the frame's tangent vectors. */
static inline void to_global(const double f[9], const double s[3],
                             double sig[9]) {
  const double *e1 = f, *e2 = f + 3;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      sig[3 * i + j] = s[0] * e1[i] * e1[j] + s[1] * e2[i] * e2[j] +
                       s[2] * (e1[i] * e2[j] + e2[i] * e1[j]);
}

/* ---- normals ------------------------------------------------------------ */

/* A body's fits (mpm_membrane_fit.c), one per run's workspace. */
typedef struct iso_work iso_work;

/* Where a body's fits are made: the whole grid's nodes per axis (the
 * cells' keys, which seed the fits' draws, count on the whole grid) and
 * the cells whose points' normals are wanted, [lo, hi) per axis (a rank's
 * own; the points in the cells around them serve the merged blocks). */
typedef struct {
  long nn[3], lo[3], hi[3];
} iso_cells;

/* The fits' figures of a step, added to mpm_state.iso's. */
typedef struct {
  long cells[4], points, degenerate, draws;
  double max_condition;
} iso_stats;

/* Create the fits' workspace of group g into *out (NULL when no body of it
 * fits its normals), *bytes its size; released by mpm_membrane_fits_free.
 * PM_ERR_MEMORY. */
pm_err mpm_membrane_fits_create(const mpm_model *m, const mpm_group *g,
                                void **out, size_t *bytes);
void mpm_membrane_fits_free(void *p);

/* Normals nn (3 per point of the body, holding its previous normals on
 * entry) of the body's n points at x (3 each), by method, at step `step`,
 * for the points in the cells [cells->lo, cells->hi); the fits' figures
 * added to *st.  PM_ERR_* of a fit. */
pm_err mpm_membrane_fit(const mpm_grid *g, const iso_cells *cells, iso_work *w,
                        int body, int method, long n, const double *x,
                        long step, double *nn, iso_stats *st);

/* As mpm_membrane_fit, across ranks, for body b's points of the rank (group
 * points [b0, b1), positions x from the group's start), fitted with the
 * nearby points of other ranks in one-process order. */
pm_err mpm_membrane_fit_ranks(const mpm_model *m, const mpm_group *gr,
                              const struct membrane_body *b,
                              const iso_cells *cells, iso_work *w, long b0,
                              long b1, const double *x, long step, double *nn,
                              iso_stats *st);

/* Unit normals of the links' triangles into tn (3 each) from the
 * positions of the group's np points xo and of the ghosts xg; zero for a
 * degenerate triangle. */
void mpm_membrane_triangle_normals(const membrane_params *mp, const double *xo,
                                   const double *xg, long np, double *tn);

/* Each point's new unit normal into nn (3 per point of the group, holding
 * the previous normals on entry; a point without one keeps them), by its
 * body's method; tn: 3 per triangle of the links; iw: the fits'
 * workspace.  PM_ERR_* of a fit. */
pm_err mpm_membrane_group_normals(const mpm_model *m, const mpm_group *gr,
                                  const double *x, long step, iso_work *iw,
                                  double *tn, double *nn, iso_stats *st);

/* e1, e2 in the plane of unit n, into the frame f = (e1, e2, n). */
void mpm_membrane_frame_from_normal(const double n[3], double f[9]);

/* The kind's table entry's (mpm_kind.h says what each does). */
pm_err mpm_membrane_finish(const mpm_model *m, mpm_group *g, mpm_state *s);
pm_err mpm_membrane_ranks_share(const mpm_group *whole, mpm_group *g);
pm_err mpm_membrane_ranks_link(const mpm_model *m, mpm_group *g, long **want,
                               long *room, long *n_want);
int mpm_membrane_ranks_reach(const mpm_group *g);
pm_err mpm_membrane_normals(mpm_ctx *ctx, const mpm_stage *self);
void mpm_membrane_describe_normals(const mpm_model *m, const mpm_group *g,
                                   char *buf, size_t size);
pm_err mpm_membrane_stress(mpm_ctx *ctx, const mpm_stage *self);

#endif
