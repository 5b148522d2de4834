/* mpm_implicit: quasi-static implicit MPM (papers/implicit-mpm-multicellular-
 * constructs.txt): Newton's method on the grid in load steps, through the
 * shared PETSc layer (pm_newton), with the consistent tangent of the
 * material table's models.
 *
 * The unknowns are the grid's nodal displacements over a base
 * configuration: the particles' positions x_b and deformation gradients
 * F_b where the load step starts.  At a particle,
 *   F = (I + sum_I du_I (x) grad S_I(x_b)) F_b,
 *   f_I = sum_p V0_p P(F) F_b^T grad S_I(x_b) - lambda m_p S_I(x_b) g,
 * the internal force (eq. 3) less gravity; P F_b^T grad S is the first
 * Piola stress carried to the base configuration.  Its derivative, with
 * A = dP/dF of the model, gives the tangent of eqs. 4-6 exactly.
 *
 * Two algorithms (mpm.implicit.grid):
 *   kept   the paper's modified algorithm: the grid moves with the
 *          particles, so every particle keeps its cell and its weights.
 *          The base is the reference configuration throughout (x_b = X,
 *          F_b = I): total Lagrangian, one unknown set for the whole run,
 *          and load stepping with step cutting by pm_load_steps.
 *   reset  the standard algorithm: after each load step the particles
 *          take their new positions and F, and the grid returns to its
 *          rectilinear place; the next step's base is the particles'
 *          state, their stencils change as they cross cells, and the
 *          active nodes, the prescribed nodes and the pattern are built
 *          anew.  The grid reaches past domain.box by the room the
 *          prescribed displacements need.
 *
 * Conditions: a face condition of the scene prescribes its displacement
 * components (lambda times their value at the end of the ramps).  Kept:
 * on the grid nodes at and beyond the face plane.  Reset: on the nodes of
 * the stencils of the body's outermost layer of particles at that face
 * (the paper's "displacement prescribed to material points along the
 * top"), which move with them.  Reactions are the internal force on the
 * prescribed dofs: the force the supports apply on the body.
 *
 * Particles are visited by cells in width^dim colours (no two cells of a
 * colour share a node), so nodal sums need no per-thread copies and come
 * out the same on any thread count. */
#ifndef MPM_IMPLICIT_H
#define MPM_IMPLICIT_H

#include <stdbool.h>
#include <stdio.h>

#include "mpm_model.h"
#include "mpm_state.h"
#include "pm_checkpoint.h"
#include "pm_newton.h"

typedef struct mpm_implicit mpm_implicit;

/* mpm_estimate_bytes of scene s and, on top, the grid solve's tangent
 * with its factors or multigrid hierarchy, by the linear solver the setup
 * would choose: the estimate that refuses a scene too large for the
 * machine before anything is allocated. */
size_t mpm_implicit_estimate_bytes(const pm_scene *s, long *points);

/* What one converged load step reports. */
typedef struct {
  int step;            /* load step, from 1 */
  double lambda;       /* the load reached */
  int newton;          /* Newton iterations of its last solve */
  int linear;          /* linear iterations of its last solve */
  int cuts;            /* cuts over the run so far */
  double residual;     /* |r| over the reactions' size at convergence */
  double min_jacobian; /* smallest J of the particles */
  double seconds;      /* wall time of the step */
  const pm_newton_report *report; /* its last Newton solve (per-iteration
                                     norms), valid during the call */
} mpm_implicit_step;

/* Called after each converged load step (particles updated: x, F, stress,
 * volume, reactions).  A failure stops the run with it. */
typedef pm_err (*mpm_implicit_observer)(void *ctx,
                                        const mpm_implicit_step *step);

/* Set up the implicit solver of model m (created from scene s, whose
 * state st it updates) with the scene's settings: mpm.implicit (grid,
 * operator, convergence) and time.quasi_static (tolerance, load_steps,
 * max_iterations, linear_solver, solver_options).  Fails with PM_ERR_SCENE
 * naming the key for what it cannot do (a group that is not solid).
 * *out is NULL on failure. */
pm_err mpm_implicit_create(const pm_scene *s, const mpm_model *m, mpm_state *st,
                           mpm_implicit **out);
void mpm_implicit_destroy(mpm_implicit *im);

/* Load from where the solver is (lambda 0, or a checkpoint's) to 1,
 * calling obs after each converged load step.  On failure returns
 * PM_ERR_NOT_CONVERGED or PM_ERR_UNSTABLE with a message naming the load
 * step, the load factor and the cause; the state holds the last converged
 * step. */
pm_err mpm_implicit_run(mpm_implicit *im, mpm_implicit_observer obs, void *ctx);

/* The reactions of the scene's conditions at the last converged state
 * (3 per condition, N; per unit depth in 2D). */
const double *mpm_implicit_reactions(const mpm_implicit *im);
/* The residual over the reactions at the last converged state. */
double mpm_implicit_residual(const mpm_implicit *im);
/* With F-bar: true and *e the strain energy sum V0 W(Fbar) at the last
 * converged state (every rank's), the energy the residual derives from
 * (the particles' own F give another); without: false. */
bool mpm_implicit_strain_energy(const mpm_implicit *im, double *e);
/* The load factor reached. */
double mpm_implicit_lambda(const mpm_implicit *im);
/* The run's totals: load steps, cuts, Newton and linear iterations, and
 * the time in residuals, assembly and linear solves, s. */
const pm_load_report *mpm_implicit_report(const mpm_implicit *im);
/* Unknowns and stored Jacobian entries of the current (last) problem. */
void mpm_implicit_size(const mpm_implicit *im, long *unknowns, long *entries);
/* Across ranks: this rank's own unknowns and its ghost nodes' unknowns
 * (the values a product with the tangent or a residual's assembly
 * exchanges); on one process all unknowns and 0. */
void mpm_implicit_held(const mpm_implicit *im, long *own, long *ghost);

/* Print the plan's lines: algorithm, grid, unknowns, solver. */
void mpm_implicit_plan(const mpm_implicit *im, FILE *out);

/* The solver's part of a checkpoint (load stepping, counters), between
 * load steps; the particles' state is the model state's.  With the grid
 * kept, load stepping's last two converged states are written as the
 * nodal displacements of the whole grid (full: the whole model, whose grid
 * is the solver's on one process), so that a run resumes on any number of
 * ranks.  Across ranks rank 0 writes what mpm_implicit_gather gathered,
 * and every rank reads. */
pm_err mpm_implicit_checkpoint(mpm_implicit *im, const mpm_model *full,
                               pm_ckpt *ck);

/* A checkpoint in pieces (a run across ranks without the whole model):
 * the solver's scalars (load stepping's figures, counters, reactions),
 * which rank 0 writes into the index and every rank reads. */
pm_err mpm_implicit_checkpoint_scalars(mpm_implicit *im, pm_ckpt *ck);
/* This rank's part of a piece: load stepping's last two converged states
 * at its own unknowns, each named by its dof on the whole grid (so that
 * a run on any count of ranks finds its own), and into box the whole
 * grid's node indices their nodes span (lower corner, upper corner,
 * inclusive; zeros without any). */
pm_err mpm_implicit_checkpoint_piece(mpm_implicit *im, pm_ckpt *ck,
                                     double box[6]);
/* The box of the nodes of this rank's unknowns, as
 * mpm_implicit_checkpoint_piece records it. */
void mpm_implicit_nodes_box(const mpm_implicit *im, double box[6]);
/* Reading a piece's part: the values of this rank's unknowns it holds
 * into load stepping's states, *placed counting them; seen (one a
 * unknown, mpm_implicit_unknowns, the caller's) marks those placed over
 * the pieces, and one in two pieces is refused (PM_ERR_IO). */
pm_err mpm_implicit_read_piece(mpm_implicit *im, pm_ckpt *ck, bool *seen,
                               long *placed);
/* The unknowns a checkpoint's pieces must hold for this rank (0 where
 * the grid is reset: no nodal state is kept between load steps). */
long mpm_implicit_unknowns(const mpm_implicit *im);

/* Across ranks: load stepping's last two converged states, as nodal
 * displacements of the whole grid, to rank 0 for its checkpoint (full:
 * the whole model there, NULL on the other ranks; collective). */
pm_err mpm_implicit_gather(mpm_implicit *im, const mpm_model *full);

/* Tests: the largest |J - J_fd| over the largest |J_fd| of the Jacobian
 * against central differences of the residual at a smooth field of size
 * amp over the unknowns (prescribed dofs at local load lambda; the grid
 * reset rebuilt on the state as it is), with the assembled values, and
 * with the matrix-free product.  2 n residuals: small models. */
pm_err mpm_implicit_check_tangent(mpm_implicit *im, double lambda, double amp,
                                  double *assembled_error,
                                  double *matrix_free_error);

#endif
