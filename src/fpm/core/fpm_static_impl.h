/* fpm_static_impl: what the files of FPM's static solve share: the
 * directly assembled tangent's parts, the context pm_newton's callbacks
 * work on, and the solve's set-up. */
#ifndef FPM_STATIC_IMPL_H
#define FPM_STATIC_IMPL_H

#include "fpm_static.h"

/* The tangent assembled directly: K = E D Gamma + S, where
 *   H_j = sum_m u_m (x) gamma_jm        (gamma: GFD weights, self -gsum)
 *   f_k[c] = sum_j sum_s P_j[c][s] E^c_kj[s] + (penalty, linear in u)
 * E (constant: the interface and boundary geometry gathered by the GFD
 * weights) is built once per run, and so is the penalty's scalar matrix S
 * (the same for every component).  Per Newton iteration only the products
 * with the tangent moduli D are formed.  Exact for IIPG; with SIPG the
 * adjoint term's derivative is left out (the solve then multiplies by the
 * exact tangent matrix-free and preconditions with this one). */
typedef struct {
  long *R_ptr, *R_list; /* per point k: the points its force reaches */
  long *E_ptr, *E_j;    /* per point k: the points j whose stress reaches */
  double *E;            /* 9 per (k, j): E^c_kj[s] at 3 c + s */
  long *S_ptr, *S_m;    /* per point k: the penalty matrix's columns */
  double *S;
  double *Dg;   /* 27 per (j, m in S(j) and j): D_j gamma_jm */
  long *Dg_ptr; /* n + 1: point j's records start at Dg_ptr[j] */
  long max_reach;
  int threads;
  long *mark;        /* threads x n: a row's points */
  double *work;      /* threads x 9 max_reach: a row's blocks */
  const double *Dpc; /* the moduli to assemble with (NULL: the tangent's) */
  /* fpm.stiffening on the quadratic jump: its second derivative in the
   * jump at the linearisation point, a 3 x 3 block per entry (Sx_e, 9 an
   * entry, fpm_stiffen_block) gathered as S is, by the fits' weights
   * (Sq_off, Sq_w), at each assembly, with a row's scratch per thread
   * (Sx_mark, Sx_list: threads x n; Sx_acc: threads x 9 n); NULL without
   * it. */
  long *Sq_off;
  double *Sq_w, *Sx_e;
  long *Sx_mark, *Sx_list;
  double *Sx_acc;
} fpm_static_tangent;

/* The averaged volume's coupling in the preconditioner (fpm.volumetric
 * averaged, one process): the matrix [K0 G; C I] over the free dofs and
 * one value z per point, z = U''(Jbar) A dJ, with K0 the tangent without
 * the volumetric stiffness U''(J) cof F (x) cof F of each point, G z the
 * force of the stresses (A z)_j cof F_j and C u = -U''(Jbar) A dJ(u); its
 * Schur complement K0 - G C is the exact tangent (fpm_volumetric_apply).
 * Built by fpm_static_coupled_build (fpm_static_coupled.c). */
typedef struct {
  long *Z_ptr, *Z_i; /* per own point k: the z whose stresses reach f_k */
  long *U_ptr, *U_m; /* per point i: the points whose u reach z_i */
  long *ptr, *idx;   /* the matrix's pattern over nf + n */
  double *D;         /* 81 n: the moduli less the volumetric stiffness */
  double *jv;        /* K0's values in the tangent's pattern */
  long maxlen;       /* the longest Z or U list */
  int threads;
  long *mark;  /* threads x n */
  double *acc; /* threads x 3 maxlen */
} fpm_static_coupled;

/* The cheaper operator for multigrid (fpm_static_support.c): the
 * tangent's blocks of each own point k's rings of neighbours, the rest
 * left out: its support (1 ring: about a tenth of the tangent's entries
 * with the quadratic jump) or its supports' supports (2 rings). */
typedef struct {
  int rings;
  long *L_ptr, *L; /* per own point k: the points (k first) */
  long *ptr, *idx; /* the pattern over the free dofs (NULL: not used) */
} fpm_static_support;

typedef struct {
  const fpm_model *m;
  fpm_state *st;
  fpm_static_tangent tg;
  fpm_static_support sp; /* (zeroed when not used) */
  fpm_static_coupled cp; /* (zeroed when not used) */
  const long *pat_ptr;
  const long *free_of;
  fpm_linear *lin;
  /* The unknowns: the free dofs of the model's own points (nf; all its
   * points on one process), then across ranks those of its ghosts (nheld
   * in all), which the solver gives their owners' values. */
  long nf, nheld;
  long *dof;   /* nheld: their dof index */
  long *ghost; /* nheld - nf: the ghosts' unknowns' numbers over the ranks */
  pm_newton *solver;
  double *held;  /* nheld: the unknowns held, for a converged state */
  double *du;    /* 3 n work */
  double *df;    /* 3 n work */
  double *u_old; /* 3 n: the last converged displacement */
  double load_end, t, lambda;
  /* Rigid bodies in contact (m->contact): the contact tangent's blocks at
   * the linearisation point (9 per own point, fpm_contact_tangent_fixed)
   * and |F|^2 of the contact forces last evaluated. */
  double *contact_K;
  double contact_fsq;
  /* The axis of the symmetry plane the point fpm_static_evaluate last
   * returned has passed (fpm_symmetry_crossed), or -1: that point's J is
   * admissible. */
  int crossed_axis;
  /* The sticking anchors at the last converged load step (3 per pair):
   * each attempt at a step starts from them (fpm_static_set_load), as
   * the anchors set within it belong to that attempt. */
  double *contact_kept;
  /* Per pair: let go within the current attempt at a step
   * (fpm_contact_release_fixed); and over the run, the grazing points
   * held at a converged step and the largest gap one was held at (m). */
  unsigned char *contact_let_go;
  long contact_frozen;
  double contact_frozen_gap;
  fpm_observer observer;
  void *octx;
  fpm_step_info si;
  double *ext_work; /* fpm_static_state.external_work */
} fpm_static_ctx;

/* Everything a solve needs of the model: the free dofs, the Jacobian's
 * pattern, the directly assembled tangent's constant parts, the
 * linearisation's work space, and the problem for pm_newton.  Released by
 * fpm_static_solve_free (also after a failure in fpm_static_setup). */
typedef struct {
  fpm_static_ctx c; /* first: the problem's ctx is &c (coupled_prepare) */
  long *free_of, *ptr, *idx;
  double *x;
  double *rigid; /* the rigid motions on the free dofs (for multigrid) */
  pm_newton_problem prob;
} fpm_static_solve;

/* The weight of u_m in H_j for the r-th member of j's closed support
 * (r = 0: j itself, -gsum_j; else its (r-1)-th neighbour), and that point. */
static inline long closed_member(const fpm_model *m, long j, long r,
                                 const double **w) {
  if (r == 0) {
    *w = m->gsum + 3 * j;
    return j;
  }
  long e = m->nbr_ptr[j] + r - 1;
  *w = m->g + 3 * e;
  return m->nbr[e];
}

static inline long closed_size(const fpm_model *m, long j) {
  return m->nbr_ptr[j + 1] - m->nbr_ptr[j] + 1;
}

/* fpm_static_coupled.c: the averaged volume's coupled preconditioner
 * (fpm_static_coupled above) for solve v on one process: its lists and
 * pattern (into v->prob's aux_n, aux_ptr, aux_idx, aux_values), its
 * values (pm_newton_problem.aux_values; ctx is the fpm_static_ctx), and
 * their release.  PM_ERR_MEMORY. */
pm_err fpm_static_coupled_build(fpm_static_solve *v);
pm_err fpm_static_coupled_values(void *ctx, const double *x, double *val);
void fpm_static_coupled_free(fpm_static_coupled *cp);

/* fpm_static_problem.c: the problem pm_newton solves. */

/* The state at the free values x (NULL: the unknowns as they are; the
 * prescribed dofs as set by fpm_static_set_load): its force; returns -1 or
 * the first inadmissible point. */
long fpm_static_evaluate(fpm_static_ctx *c, const double *x);
/* fpm_static_evaluate at the owned unknowns x (n values), their ghosts'
 * from their owners across ranks (collective); *bad as it returns. */
pm_err fpm_static_evaluate_owned(fpm_static_ctx *c, const double *x, long *bad);
/* The state just evaluated (bad: its first inadmissible point, or -1),
 * admissible on every rank or on none (the failure one process meets
 * first): PM_ERR_UNSTABLE naming the point. */
pm_err fpm_static_admissible(const fpm_static_ctx *c, long bad);
/* The loads at load factor lambda (pm_newton_problem.set_load; ctx is the
 * fpm_static_ctx). */
pm_err fpm_static_set_load(void *ctx, double lambda);
/* The sticking anchors of c->st as a converged step left them, kept for
 * the next step's attempts (nothing without contact). */
void fpm_static_keep_anchors(fpm_static_ctx *c);
/* The figures of the state in c->st into c->si (collective). */
void fpm_static_figures(fpm_static_ctx *c, long step);
/* Everything a solve needs of model m with state st into *v (zeroed but
 * for the observer); release with fpm_static_solve_free, also after a
 * failure.  PM_ERR_MEMORY; PM_ERR_SCENE when every dof is prescribed. */
pm_err fpm_static_setup(const fpm_model *m, fpm_state *st, fpm_static_solve *v);
void fpm_static_solve_free(fpm_static_solve *v);

/* fpm_static_tangent.c: the tangent's constant parts for the rows of the
 * own points (after fpm_static_pattern, whose reach it reads), its values
 * in the pattern's order (pm_newton_problem.jacobian_values; ctx is the
 * fpm_static_ctx), and their release. */
pm_err fpm_static_tangent_build(const fpm_model *m, fpm_static_tangent *t);
pm_err fpm_static_tangent_values(void *ctx, const double *x, double *val);
void fpm_static_tangent_free(fpm_static_tangent *t);

/* fpm_static_support.c: the support operator of this many rings (1 or
 * 2) over the nf unknowns of one process (free_of: dof -> unknown) into
 * sp (PM_ERR_MEMORY); the row of own point k into val in its pattern's
 * order, from the tangent's blocks blk of the points of k's reach (mark:
 * a point's place among them); and its release. */
pm_err fpm_static_support_build(const fpm_model *m, const long *free_of,
                                long nf, int rings, fpm_static_support *sp);
void fpm_static_support_row(long k, const long *free_of, const long *mark,
                            const double *blk, const fpm_static_support *sp,
                            double *val);
void fpm_static_support_free(fpm_static_support *sp);
/* The support operator's values at the tangent's linearisation point
 * (pm_newton_problem.precond_values; ctx is the fpm_static_ctx), in
 * fpm_static_tangent.c. */
pm_err fpm_static_support_values(void *ctx, const double *x, double *val);

/* fpm_static_pattern.c: the Jacobian's pattern over the nf unknowns
 * (free_of: dof -> unknown, -1 for none) into *ptr_out, *idx_out (CSR,
 * the caller's), and each own point's reach into tg.  PM_ERR_MEMORY. */
pm_err fpm_static_pattern(const fpm_model *m, const long *free_of, long nf,
                          fpm_static_tangent *tg, long **ptr_out,
                          long **idx_out);

/* fpm_static_unknowns.c: across ranks (m->xc), the ghosts' unknowns
 * numbered after the own ones into free_of and c (dof, ghost, nheld); and
 * the rigid motions of the body on the nf free dofs dof into rigid
 * (count x nf; returns count). */
pm_err fpm_static_number_ghosts(const fpm_model *m, long *free_of,
                                fpm_static_ctx *c);
int fpm_static_rigid_modes(const fpm_model *m, const long *dof, long nf,
                           double *rigid);

/* The size of the blocks the free dofs dof (nf, by point, in order) come
 * in: the number of free components of every point that has any, when
 * all have as many (3 for a body clamped on whole faces); else 1. */
int fpm_static_block_size(const long *dof, long nf);

#endif
