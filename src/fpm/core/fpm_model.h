/* fpm_model: the Fragile Points Method discretization of a scene: points,
 * supports, GFD operators, interface and boundary geometry, masses, boundary
 * conditions, all computed once before the time loop; and the state. */
#ifndef FPM_MODEL_H
#define FPM_MODEL_H

#include <stdbool.h>

#include "gm_dual.h"
#include "fpm_exchange.h"
#include "fpm_scene.h"
#include "pm_error.h"
#include "pm_material.h"
#include "pm_scene.h"

#define FPM_MAX_MATERIALS 16

struct fpm_contact;
#define FPM_EREC 23 /* doubles per support-entry record */
#define FPM_LANES 4 /* entries a block of the plain flux stream */

/* Everything that does not change during a run.  Arrays are per point
 * (n), per support entry (nnz, in the CSR order of the dual's adjacency) or
 * per boundary item.  Vectors are 3 per item, tensors 9 (row-major). */
typedef struct {
  int dim;
  long n;              /* points */
  const gm_dual *dual; /* borrowed: positions, volumes, adjacency */
  const double *x;     /* dual->x */
  const long *nbr_ptr; /* dual->nbr_ptr: support of i is entries
                          nbr_ptr[i] .. nbr_ptr[i+1] */
  long nnz;            /* support entries */
  int *nbr;            /* nnz: neighbour of each entry (32-bit copy) */
  double *g;           /* 3 nnz: GFD weight g_ik of entry (i, k) */
  double *gsum;        /* 3 n: sum_k g_ik */
  int *mirror;         /* nnz: entry (k, i) of entry (i, k) */
  double *cond;        /* n: support condition numbers */
  /* Interface geometry, one record of FPM_EREC doubles per support entry,
   * oriented outward from the entry's point i (neighbour k): area vector a
   * (3), first moment about the interface centroid Mc = M - a (x) x_e (9),
   * d_i = x_e - X_i (3), d_k = x_e - X_k (3), beta |e| = p E / h_e |e| (1),
   * and with the quadratic jump the linear jump's beta_b |e| = p_b E / h_e
   * |e| on the interfaces of boundary points, else 0 (1), and the
   * stiffening penalty's c_e |e| = p_s E / h_e^3 |e| (1, 0 without it),
   * the volume penalty's p_v E / h_e |e| (1, 0 without it), and the
   * stiffening's onset (tau h_e)^2 (1).
   * Entries stream in order in the flux pass; moments about the centroid
   * keep M - a (x) X_i = Mc + a (x) d_i free of cancellation. */
  double *erec;   /* FPM_EREC nnz */
  double *p_area; /* 3 n: sum of a_e (outward from i) */
  double *p_mrel; /* 9 n: sum of M_e - a_e (x) X_i (outward) */
  /* The entries streamed (fpm_stream.h): point i's entries in blocks
   * fs_ptr[i] .. fs_ptr[i+1] of FPM_LANES entries, padded; per block
   * FPM_LANES neighbours, their g_ik, the mirror entries' g_ki and with the
   * plain formulation the records' first 19 fields (else fs_rec NULL), each
   * field's lanes contiguous. */
  long *fs_ptr;   /* n_stress + 1 */
  int *fs_nbr;    /* FPM_LANES blocks */
  double *fs_g;   /* 3 FPM_LANES blocks */
  double *fs_gm;  /* 3 FPM_LANES blocks */
  double *fs_rec; /* 19 FPM_LANES blocks, or NULL */
  /* Materials. */
  int n_mats;
  pm_material mats[FPM_MAX_MATERIALS];
  int *mat;       /* n: material of each point */
  double *mstate; /* mstate_stride n: per-point state of the models that
                     have one (fibre directions), or NULL when none has */
  int mstate_stride;
  double *mass;            /* n: lumped mass rho V */
  double penalty;          /* p */
  double boundary_penalty; /* p_b (quadratic jump only) */
  double stiffening;       /* p_s: the quartic penalty on the jump */
  bool stiffen_quadratic;  /* it measures the quadratic jump (else linear) */
  double stiffening_onset; /* tau: it acts beyond |[[u]]| = tau h */
  bool stiffen_current;    /* h of the onset: the points' current distance */
  double volume_penalty;   /* p_v: linear-jump penalty scaled by (ln J)^2 */
  fpm_flux flux;           /* IIPG or SIPG */
  /* fpm.volumetric: averaged (fpm_volumetric.h): the weights a_ik of each
   * support entry and a_ii of each point (both NULL with standard). */
  double *vavg;  /* nnz */
  double *vself; /* n */
  /* The quadratic reconstruction of fpm.jump: quadratic (all NULL with the
   * linear jump).  Point i's fit uses the points qs_nbr[qs_ptr[i] ..
   * qs_ptr[i+1]) (its support, or its two rings where the support cannot
   * determine a quadratic); theta_i = sum (u_m - u_i) (x) q (3 x FPM_QFIT).
   * qt_ptr/qt_entry list, per point m, the fit entries whose neighbour is
   * m (the transpose, for the force gather); qs_own is each entry's point. */
  fpm_jump jump;
  long *qs_ptr, *qt_ptr;
  int *qs_nbr, *qs_own, *qt_entry;
  double *q;      /* FPM_QFIT per fit entry */
  double *qsum;   /* FPM_QFIT n: sum of q over each fit */
  long n_qwide;   /* points fitted over two rings */
  long n_qlinear; /* points with no usable quadratic fit: linear there */
  /* Consistency flux on faces with displacement conditions, per point that
   * has such facets: row c of the projected flux uses area A^c and moment
   * B^c summed over the facets that prescribe component c. */
  long n_dpts;
  long *dpt_point;  /* n_dpts */
  double *dpt_area; /* 9 n_dpts: A^c for c = 0..2, 3 each */
  double *dpt_mrel; /* 27 n_dpts: B^c for c = 0..2, 9 each */
  /* Traction facets (one row per facet and traction condition). */
  long n_tfacets;
  long *tf_point;         /* n_tfacets */
  int *tf_bc;             /* n_tfacets: scene boundary condition */
  double *tf_area;        /* n_tfacets: |f| */
  double *tf_rel;         /* 3 n_tfacets: |f| (c_f - X_i) */
  double *tf_centroid;    /* 3 n_tfacets */
  double *tf_base;        /* 3 n_tfacets: traction at full load (t = 0) */
  bool tf_time_dependent; /* some traction expression uses t */
  double *tf_normal;      /* 3 n_tfacets: unit outward normal N (pressure) */
  /* Body forces and concentrated forces (fpm_loads.h). */
  double *bf_base;        /* 3 n: m_i (g + b(X_i, 0)), or NULL when none */
  bool bf_time_dependent; /* body_force uses t */
  long n_pforces;         /* concentrated forces: one row per point */
  long *pf_point;         /* n_pforces */
  int *pf_bc;             /* n_pforces: the condition */
  double *pf_share;       /* n_pforces: 1 / its condition's points */
  /* Prescribed displacement components. */
  long n_cdofs;
  long *cd_point;
  int *cd_comp;
  int *cd_bc;                  /* scene boundary condition */
  double *cd_base;             /* value at full load (t-independent part) */
  bool cd_time_dependent;      /* some displacement expression uses t */
  unsigned char *fixed;        /* 3 n: 1 where the component is prescribed */
  long *bcf_ptr;               /* n_bcs + 1: the facets of condition b are */
  long *bcf_facet;             /* bcf_facet[bcf_ptr[b] .. bcf_ptr[b + 1]) */
  const pm_scene *scene;       /* borrowed: boundary expressions and ramps */
  struct fpm_contact *contact; /* rigid bodies in contact (fpm_contact.h),
                                  or NULL when the scene has none */
  /* Across ranks (src/fpm/ranks) a rank's model is its share: its own
   * points first, in one-process order, then the ghost points their force
   * reads, and each pass runs over the points that need it: the force is
   * gathered on [0, n_own), the flux of [0, n_flux), the stress (and the
   * quadratic fit) of [0, n_stress), and u is held on all n.  Only its own
   * points count in sums, and its conditions' dofs are its own points'.
   * On one process all are n, gid and xc NULL. */
  long n_own, n_flux, n_stress;
  long *gid;         /* n: each point's index on one process, or NULL */
  long *tf_gid;      /* n_tfacets: each traction facet's, or NULL */
  gm_dual *own_dual; /* a share's points, volumes and rows (dual is it) */
  fpm_exchange *xc;  /* a share's exchanges with the other ranks (released
                        with the model), or NULL */
} fpm_model;

/* The deformation gradient F = I + H of a point's displacement gradient H
 * (9, row-major). */
static inline void fpm_deformation(const double *H, double F[9]) {
  for (int a = 0; a < 9; a++) F[a] = H[a];
  F[0] += 1;
  F[4] += 1;
  F[8] += 1;
}

/* Point i's index on one process (for messages). */
static inline long fpm_point_id(const fpm_model *m, long i) {
  return m->gid ? m->gid[i] : i;
}

/* Fields that change every step.  All allocated by fpm_state_create. */
typedef struct {
  double *u, *v;            /* 3 n displacement, velocity (half step) */
  double *f;                /* 3 n net force f_int - f_ext */
  double *H;                /* 9 n: F - I per point */
  double *P;                /* 9 n: first Piola-Kirchhoff stress */
  double *T;                /* 9 n: V P - Q, the gathered flux tensor */
  double *r;                /* 3 n: interface and boundary force terms */
  double *W;                /* n: strain energy density */
  double *J;                /* n: det F */
  double *tf_value;         /* 3 n_tfacets: traction at the current time */
  double *tf_p;             /* n_tfacets: pressure at the current time */
  double *tf_load;          /* 3 n_tfacets: the nominal traction applied,
                               tf_value - p cof(F_i) N (set by the force) */
  double *fload;            /* 3 n: body and concentrated forces now */
  double *fload_prev;       /* 3 n: at the last step (their work) */
  double fext_norm;         /* |f_ext| of the current tractions */
  double bflux_norm;        /* |consistency flux on prescribed faces| */
  double fext_sq, bflux_sq; /* their squares over the model's own points
                               (a share's part of the whole run's) */
  double penalty_energy;    /* interface energy, J: 1/2 sum_e beta |e| [[u]]^2,
                               and with SIPG also - sum_e {P} : K_e */
  double *theta;            /* 27 n: the quadratic fit (fpm.jump: quadratic) */
  double *zq;               /* 3 n: sum_e b_e, the penalty force through u_i */
  double *Zq;               /* 27 n: sum_e b_e (x) phi(d_i), through theta_i */
  double *Jbar, *dUbar;     /* n each: averaged J and U'(Jbar) (fpm.volumetric:
                               averaged; else NULL) */
  double *vphi;             /* n: (ln J)^2 (fpm.volume_penalty), else NULL */
  double *bflux;        /* 3 n_dpts: that flux per point: the supports' force on
                           the body, with f on the prescribed dofs */
  double *support_prev; /* n_cdofs + 3 n_dpts: those forces at the previous
                           step (trapezoidal work of the supports); then
                           3 n_tfacets tractions and 3 n_tfacets of the
                           displacements they work on (fpm_support_work) */
  double *contact;      /* the rigid bodies' contact state
                           (fpm_contact_state_size), or NULL */
  /* What the time loop carries from step to step (fpm_run continues from
   * it: step 0 is the initial state). */
  long step;
  double t;
  double damping;       /* current damping coefficient, 1/s */
  double external_work; /* of the supports and tractions so far, J */
  double dissipated;    /* by damping so far, J */
} fpm_state;

/* Build the model of scene s with the fpm options o on the cells d of
 * mesh (s, mesh and d borrowed and kept alive by the caller until
 * fpm_model_destroy).  Computes the GFD weights (failing with
 * the point id and position of an ill-conditioned support), interface
 * geometry, masses and boundary conditions. */
pm_err fpm_model_create(const pm_scene *s, const fpm_options *o,
                        const gm_mesh *mesh, const gm_dual *d, fpm_model **out);

/* The same on the cells d of a part of the whole mesh (a rank's share and
 * the rings around it, fpm_region.h): d's point i is the whole's gid[i]
 * (ascending), its rows are those of the whole where held, and empty
 * where not (the part's edge); every per-point and per-entry figure of a
 * point whose rows, and whose neighbours' rows, are held is the whole
 * model's, bit for bit.  Conditions may select none of its facets.  It
 * has no entry stream (it is never stepped: its shares are, with theirs).
 * gid is copied (m->gid).  d's interfaces are let go once the interface
 * records are built (NULL, n_ifaces 0; d keeps its points, rows and
 * facets). */
pm_err fpm_model_create_part(const pm_scene *s, const fpm_options *o,
                             const gm_mesh *mesh, gm_dual *d, const long *gid,
                             fpm_model **out);

/* The points a model holds of a whole model's (a rank's share): its own
 * points [0, n_own), then the ghosts whose flux [n_own, n_flux), stress
 * [n_flux, n_stress) and displacement [n_stress, n) its passes read (see
 * fpm_model.n_own), each group in one-process order. */
typedef struct {
  long n_own, n_flux, n_stress, n;
  const long *gid; /* n: each point's index in the whole model */
} fpm_points;

/* The model of the points pts of model m (m held whole; pts borrowed): a
 * model whose point i is m's pts->gid[i], with their operators,
 * interfaces, masses, materials, boundary facets (of the points whose flux
 * it computes) and prescribed dofs (of its own points), in one process's
 * order; rows, fits and mirror entries of the points whose stress it
 * computes.  Reactions are not computed on it (no facet lists).  *out owns
 * its arrays (fpm_model_destroy); m is left as it is.  PM_ERR_MEMORY. */
pm_err fpm_model_subset(const fpm_model *m, const fpm_points *pts,
                        fpm_model **out);
/* The same subset, m taken: the records of each support and fit entry (GFD
 * and averaging weights, interface records, fits' weights) are moved in
 * place into the subset's order and handed to it, and m's other arrays of
 * points and entries are let go once copied, so that m and its subset are
 * never held whole together (a part's model, fpm_region.h).  m keeps its
 * boundary and gid, and is destroyed by the caller whatever the
 * outcome. */
pm_err fpm_model_subset_take(fpm_model *m, const fpm_points *pts,
                             fpm_model **out);

/* The body FPM meshes as its domain: the scene's only body when it is a
 * gmsh volume (bodies: [{mesh: FILE}]), whose physical surfaces then name
 * boundary conditions; -1 when FPM meshes domain.box. */
int fpm_domain_body(const pm_scene *s);

/* The boundary conditions of s on the model (called by fpm_model_create):
 * the facets each condition selects on mesh's surfaces or in its region
 * (none is an error at the condition's key), prescribed dofs, the
 * consistency flux on prescribed facets and the traction facets. */
pm_err fpm_build_boundary(fpm_model *m, const pm_scene *s, const gm_mesh *mesh);
/* The facets of d each condition of s acts on, as CSR lists *ptr (n_bcs +
 * 1) and *facet, each in d's order: on a named surface of the mesh (the
 * box's faces are its surfaces xmin ... zmax), or where the region
 * expression is positive at the facet's centroid.  A condition that
 * selects nothing is an error at its key where d is whole.  The caller
 * frees both. */
pm_err fpm_select_facets(const gm_dual *d, const pm_scene *s,
                         const gm_mesh *mesh, bool whole, long **ptr,
                         long **facet);
void fpm_model_destroy(fpm_model *m);
/* With the plain formulation (its stream holds the flux records, m->fs_rec),
 * frees the interface records erec and the weights g, which only static
 * solves, the general flux pass, fpm_stable_dt and the shares built from
 * the model read: for an explicit run, before its time loop.  Otherwise
 * nothing. */
void fpm_model_drop_static(fpm_model *m);
/* Bytes held by the model (not counting the dual). */
size_t fpm_model_bytes(const fpm_model *m);

pm_err fpm_state_create(const fpm_model *m, fpm_state **out);
void fpm_state_destroy(fpm_state *st);
size_t fpm_state_bytes(const fpm_model *m);

/* Prescribed value of constrained dof k at time t. */
double fpm_prescribed(const fpm_model *m, long k, double t);
/* The fastest a prescribed dof moves while the scene's ramps and curves
 * run (pm_scene_load_end), m/s: the largest difference quotient over
 * samples of that span, over this model's (a share's: its own) dofs; 0
 * where nothing prescribed moves.  Setup only: expressions of t cost up to
 * 1e6 evaluations. */
double fpm_support_speed(const fpm_model *m);
/* Evaluate the traction of every traction facet at time t into
 * st->tf_value (serial: expressions are not thread-safe).  Returns -1, or
 * the first entry 3 k + a of tf_value that is not finite. */
long fpm_update_tractions(const fpm_model *m, fpm_state *st, double t);
/* PM_ERR_UNSTABLE for a condition whose expression gave a value that is
 * not finite at time t (step < 0: none): constrained dof k (traction
 * false) or entry k = 3 f + a of the traction facets (traction true),
 * naming the point, the scene key and the expression. */
pm_err fpm_condition_failure(const fpm_model *m, bool traction, long k,
                             long step, double t);
/* The first of the model's own points whose current position lies past
 * a symmetry plane of the scene (on the side the mirrored part fills:
 * the surface has folded through the plane), or -1 (at once where the
 * scene has no plane); *axis receives its plane's axis. */
long fpm_symmetry_crossed(const fpm_model *m, const fpm_state *st, int *axis);
/* PM_ERR_UNSTABLE naming point p past the plane normal to axis (prefix:
 * the step and time where that applies, or ""). */
pm_err fpm_symmetry_failure(const fpm_model *m, const fpm_state *st, long p,
                            int axis, const char *prefix);

/* The net nodal force f = f_int(u) - f_ext(t) into st->f (also F, P, W, J,
 * T, r).  Returns -1, or the smallest point id whose deformation gradient
 * is inadmissible (J <= 0 or not finite).  On a share with
 * fpm.volumetric: averaged it is collective (the averaged pressure of the
 * ghosts comes from their owners, fpm_volumetric.h): a rank that does not
 * evaluate the force when the others do calls fpm_force_skipped. */
long fpm_force(const fpm_model *m, fpm_state *st);
void fpm_force_skipped(const fpm_model *m, fpm_state *st);
/* fpm_force, then, when it succeeds, tail(ctx) by every thread of the
 * force's parallel region (tail NULL: nothing), each thread right after
 * its share of the gather: a loop over the model's own points with
 * schedule(static) and nowait reads the f of its own points without a
 * barrier.  The region's end is the tail's barrier. */
long fpm_force_then(const fpm_model *m, fpm_state *st, void (*tail)(void *),
                    void *ctx);

/* The linearisation of fpm_force about a state: df = K du with K the
 * consistent tangent (exact but for the SIPG adjoint term's derivative of
 * the material tangent, taken by central differences).  Work space made
 * once; nothing allocates per application. */
typedef struct fpm_linear fpm_linear;
pm_err fpm_linear_create(const fpm_model *m, fpm_linear **out);
void fpm_linear_destroy(fpm_linear *l);
size_t fpm_linear_bytes(const fpm_model *m);
/* Linearise about st, whose force fpm_force has just computed (its u and H
 * are copied: st may change before the applications). */
void fpm_linear_prepare(const fpm_model *m, const fpm_state *st, fpm_linear *l);
/* The tangent moduli dP/dF of the last prepare: 81 per point, row-major
 * (row a = 3 i + j of P, column b of F). */
const double *fpm_linear_tangent(const fpm_linear *l);
/* The last prepare's displacements (3 per point) and, with fpm.stiffening
 * on the quadratic jump, its fits' coefficients (27 per point; else
 * NULL). */
void fpm_linear_base(const fpm_linear *l, const double **u,
                     const double **theta);
/* df (3 n) = K du (3 n), every dof (prescribed ones included); collective
 * on a share with fpm.volumetric: averaged. */
void fpm_force_linear(const fpm_model *m, fpm_linear *l, const double *du,
                      double *df);

/* Stable time step of eqs. 24-26 of the FPM paper: for each point j,
 * lambda_j <= m_j c_j^2 |C_j|_F^2 (m_j support size, c_j the dilatational
 * wave speed, C_j the GFD derivative matrix including the centre column),
 * dt = 2 / sqrt(max lambda_j) / sqrt(max(p, 1)).  Also returns the point
 * that sets it. */
double fpm_stable_dt(const fpm_model *m, long *critical_point);
/* Its parts: the largest lambda_j over the model's own points, and the
 * point that has it first (by its index on one process); the step of a
 * largest lambda (the penalties' and rigid bodies' bounds with it).  Across
 * ranks, the largest over the shares gives one process's step. */
double fpm_stable_lambda(const fpm_model *m, long *critical_point);
double fpm_stable_dt_of(const fpm_model *m, double lam_max);

#endif
