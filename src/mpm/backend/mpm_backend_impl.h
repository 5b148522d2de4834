/* mpm_backend_impl: what the pieces of MPM's two backends share (internal
 * to backend/): the simulation's setup and reports, rank 0's view of a run
 * across ranks, and the backend table's entries both methods use. */
#ifndef MPM_BACKEND_IMPL_H
#define MPM_BACKEND_IMPL_H

#include <stdio.h>

#include "mpm_backend.h"
#include "mpm_implicit.h"
#include "mpm_kind.h"
#include "mpm_pipeline.h"

/* ---- the simulation (mpm_backend.c) ---- */

/* Doubles per particle of the output buffer (mpm_sim.scratch). */
long mpm_sim_scratch_per_particle(const mpm_model *m);
/* The simulation of s: explicit (its step's workspace) or implicit (its
 * solver; the workspace holds only the reactions and the timers).
 * Failures as mpm_model_create; *out NULL then. */
pm_err mpm_sim_setup(const pm_scene *s, bool implicit, mpm_sim **out);
/* A workspace that holds only the figures of a step (reactions, residual)
 * and the timers (*out, released with mpm_work_destroy).  PM_ERR_MEMORY. */
pm_err mpm_sim_figures_work(const mpm_model *m, mpm_work **out);
/* Bytes the simulation holds (across ranks rank 0's: share and view). */
size_t mpm_sim_bytes(const mpm_sim *r);
/* The report of the step the state is at, and that report to the run's
 * observer (with a frame when asked). */
pm_step_report mpm_sim_step_report(const mpm_sim *r, bool last);
pm_err mpm_sim_report(mpm_sim *r, bool frame, bool last);
/* What the run keeps of a step's figures over all its steps. */
void mpm_sim_note_step(mpm_sim *r, const mpm_state *s, const mpm_work *w,
                       const mpm_step_info *info);
/* The scene check of method mpm (with what a run across ranks cannot do). */
pm_err mpm_sim_check_scene(const pm_scene *s);
/* The backend table's destroy: mpm_sim_destroy. */
void mpm_sim_destroy_any(void *p);

/* ---- rank 0's view of a run across ranks (mpm_view.c) ---- */

/* This rank's share of the whole model and state, which every rank holds,
 * with the energy accounts of a checkpoint of as many ranks, if given
 * (collective; every rank returns the same error). */
pm_err mpm_view_share(mpm_sim *r, const double *accounts);
/* The share and rank 0's figures workspace (collective). */
pm_err mpm_view_setup(mpm_sim *r);
/* The run's view (pm_view): across ranks when r has a share, with the
 * explicit or the implicit gather. */
void mpm_view_init(mpm_sim *r, bool implicit);
/* Report the step the state is at to the run's observer (across ranks,
 * collective: rank 0 reports, the shares gathered into its view where the
 * observer reads them). */
pm_err mpm_view_report(mpm_sim *r, bool frame, bool last);
/* Let this rank's share (model, state, workspace) go, to make it anew. */
void mpm_view_drop_share(mpm_sim *r);
/* A run without the whole model resumed from a whole checkpoint, once its
 * shares are cut: the whole model read for them goes, and rank 0's state
 * of the run's scalars takes the checkpoint's values. */
void mpm_view_drop_whole(mpm_sim *r);
/* A resumed run across ranks: each rank's share anew from the whole state
 * read from the checkpoint (collective). */
pm_err mpm_view_reshare(mpm_sim *r);
/* What the exchanges cost over the run, summed over the ranks (the
 * busiest rank's seconds), into r->ranks_counts, and the particles each
 * rank held into r->ranks_held (collective). */
pm_err mpm_view_counts(mpm_sim *r);
/* A checkpoint's cut of the boxes across ranks (`ranks` of them): written
 * from this rank's share, read into r->ckpt_cut when this run has as
 * many ranks, so that the run goes on on the boxes it had (cut anew
 * while it went on, mpm.rebalance, they are not the start's). */
pm_err mpm_sim_cut_items(mpm_sim *r, pm_ckpt *ck, long ranks);
/* Across ranks without the whole model (mpm_sim.whole false), at setup:
 * rank 0's state of the run's scalars, its figures' workspace and the
 * whole run's reference positions (mesh_x0), every rank's room for the
 * bodies' sums (collective). */
pm_err mpm_view_sums_setup(mpm_sim *r);
/* The sums over the shares into rank 0's r->sums and the scalars of its
 * state (energies, accounts, the bodies' columns; with fields, the end's
 * field figures) (collective). */
pm_err mpm_view_sum(mpm_sim *r, bool fields);
/* pm_backend.errors: the NRMSE of the last sums (r->whole false). */
bool mpm_sim_errors(void *p, double nrmse[3], double *vector);
/* What rank 0's observer reads of a converged implicit load step: every
 * rank's particles and load stepping's states (collective). */
pm_err mpm_view_implicit_gather(void *ctx);
/* The same without the whole model: the sums over the shares
 * (mpm_view_sum) and the share's scalars (collective). */
pm_err mpm_view_implicit_sums(void *ctx);

/* ---- checkpoints in pieces (mpm_ckpt_pieces.c) ---- */

/* The driver's run items of a checkpoint after the state (both ways). */
pm_err mpm_sim_run_items(mpm_sim *r, pm_ckpt *ck);
/* pm_backend.ckpt_pieces: whether a run of s across ranks in pieces
 * checkpoints in pieces (not with dynamic relaxation's nodal arrays). */
bool mpm_sim_ckpt_pieces(const pm_scene *s);
/* pm_backend.pieces_apply: frames in pieces unless a body is a membrane
 * or the run relaxes dynamically. */
bool mpm_sim_pieces_apply(const pm_scene *s);
/* pm_view.ckpt_piece: this rank's share as piece of checkpoint id. */
pm_err mpm_sim_ckpt_piece(void *ctx, const char *dir, long id, long *count,
                          unsigned long long *sum, double *values);
/* Whether reader ck is the index of a checkpoint in pieces. */
bool mpm_sim_ckpt_is_pieces(const pm_ckpt *ck);
/* The backend's items of a checkpoint in pieces: a writer (rank 0) has
 * every rank write its piece (pm_view_checkpoint_pieces), then writes the
 * index; a reader reads the index and, on one process or where the run
 * keeps the whole model, every piece (mpm_sim_ckpt_load_whole), else
 * leaves the pieces to mpm_view_reload. */
pm_err mpm_sim_ckpt_index(mpm_sim *r, pm_ckpt *ck);
/* The whole model (made if missing) and its state from every piece. */
pm_err mpm_sim_ckpt_load_whole(mpm_sim *r);
/* Across ranks, once the run starts: each rank's share made anew from the
 * scene with the particles the pieces have in its cells, their state read
 * from the pieces that hold them (collective). */
pm_err mpm_view_reload(mpm_sim *r);
/* The same for an implicit run: its particles keep their ranks, so each
 * rank's share stays as seeded and takes its particles' state and the
 * solver's unknowns from the pieces that hold them (collective). */
pm_err mpm_view_implicit_reload(mpm_sim *r);

/* ---- what the run driver reads (mpm_fields.c, mpm_history.c) ---- */

void mpm_sim_points(void *p, pm_points *pts);
const double *mpm_sim_displacement(void *p);
int mpm_sim_fields(void *p, unsigned want, pm_field *f, int max);
/* Across ranks with frames in pieces: this rank's share of frame `frame`
 * written into the results folder dir (pm_view.piece), and rank 0's
 * record of the last frame's pieces (pm_backend.pieces). */
pm_err mpm_sim_piece(void *p, const char *dir, long frame,
                     const pm_step_report *rep, long *n, int *n_fields,
                     pm_field *fields);
const pm_view_pieces *mpm_sim_pieces(void *p);
/* Doubles a particle of m the fields `want` (PM_FIELD_*) take in an
 * output buffer (at most mpm_sim_scratch_per_particle). */
long mpm_sim_fields_per_particle(const mpm_model *m, unsigned want);
/* Room in the share's output buffer for its particles (grown with the
 * share; frame: for the message).  PM_ERR_MEMORY. */
pm_err mpm_sim_share_scratch(mpm_sim *r, long frame);
/* The end's field figures of m's particles at state s (their fields
 * computed into scratch, mpm_sim_scratch_per_particle doubles a particle)
 * into out's sed_volume, volume0, max_von_mises and min_jacobian with
 * where they are; at: the one-process indices of those two particles
 * (LONG_MAX: none), the first in one process's order among equals. */
void mpm_sim_field_sums(const mpm_model *m, const mpm_state *s, double *scratch,
                        mpm_sums *out, long at[2]);
/* Body b's sums over m's particles at state st into out (MPM_SUMS_BODY
 * doubles: mass times displacement, mass, and with pressure, its
 * pressure times volume and volume, its kind's fields computed into
 * scratch). */
void mpm_sim_body_sums(const mpm_model *m, const mpm_state *st, double *scratch,
                       int b, bool pressure, double *out);
void mpm_sim_figures(void *p, pm_figures *f, bool with_fields);
/* The history columns of its own (mpm_sim.hist_names), on rank 0.
 * PM_ERR_MEMORY. */
pm_err mpm_sim_history_setup(mpm_sim *r);
int mpm_sim_history_names(void *p, const char **names, int max);
void mpm_sim_history_values(void *p, double *v);

/* ---- summary and plan (mpm_summary.c, mpm_plan.c) ---- */

/* The names of a basis and of a particle update (upper: as the plan
 * prints it). */
const char *mpm_sim_basis_name(mpm_basis b);
const char *mpm_sim_update_name(mpm_update u, bool upper);
pm_err mpm_sim_summary(void *p, pm_json *j);
pm_err mpm_sim_implicit_summary(void *p, pm_json *j);
const pm_timers *mpm_sim_timers(void *p);
pm_err mpm_sim_plan(void *p, FILE *out);
/* The layers of ghosts around a rank's share (pm_backend.ghost_layers):
 * the grid's ghost node layers, at most 2 (quadratic B-splines), counted
 * as layers of particles (a bound: particles have no ghosts but linked
 * points'). */
double mpm_sim_ghost_layers(const pm_scene *s);
pm_err mpm_sim_implicit_plan(void *p, FILE *out);

#endif
