/* mpm_par_plan: the plan of a run across ranks: a decomposition's boxes,
 * what each rank would hold and send, and each rank's share. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpm_grid_stages.h"
#include "mpm_kind.h"
#include "mpm_par_impl.h"
#include "mpm_transfer.h"
#include "pm_par.h"
#include "pm_par_mpi.h"
#include "pm_progress.h"

/* ---- plan and counts -------------------------------------------------------
 */
/* Values a transfer of `mode` moves per node. */
static int dof_of(int mode, bool imp) {
  return (mode & MPM_P2G_MASS ? 1 : 0) + (mode & MPM_P2G_MOM ? 3 : 0) +
         (mode & MPM_P2G_FORCE ? 3 + (imp ? 2 : 0) : 0);
}

void mpm_decomp_print(const mpm_decomp *d, const pm_scene *s, FILE *out) {
  fprintf(out,
          "ranks        %d: boxes of the grid's cells by recursive bisection "
          "(cuts along x %d, y %d, z %d), %d ghost node layer%s\n",
          d->size, d->cuts[0], d->cuts[1], d->cuts[2], d->ghost,
          d->ghost == 1 ? "" : "s");
  if (d->held[0]) fprintf(out, "             not cut: %s\n", d->held);
  long most = 0, least = -1, total = 0;
  for (int r = 0; r < d->size; r++) {
    total += d->count[r];
    most = d->count[r] > most ? d->count[r] : most;
    least = least < 0 || d->count[r] < least ? d->count[r] : least;
  }
  fprintf(out,
          "             particles per rank %ld to %ld (imbalance %.3f: the "
          "most over the mean)\n",
          least, most, total > 0 ? most * (double)d->size / total : 0.0);
  const double balance = mpm_par_balance_of(s);
  if (balance > 0)
    fprintf(out,
            "             cut anew as the particles travel, when the busiest "
            "rank holds more than %g times the mean (mpm.rebalance; 0 keeps "
            "these boxes)\n",
            balance);
  else
    fprintf(out, "             these boxes kept for the whole run (%s)\n",
            strcmp(s->method, "mpm") != 0
                ? "the implicit MPM's particles keep their ranks"
            : s->time.qs != PM_QS_NONE
                ? "dynamic relaxation's nodal arrays span the steps"
                : "mpm.rebalance: 0");
}

/* Values per node the step's transfers exchange (mass, momentum, forces,
 * impedances; the MUSL remap's momentum). */
static int node_values_per_step(const mpm_model *m) {
  int v = 0;
  for (int k = 0; k < m->pipeline.n; k++) {
    const mpm_stage *stg = &m->pipeline.stage[k];
    if (stg->run == mpm_stage_p2g)
      v += dof_of(stg->mode, m->has_absorbing && (stg->mode & MPM_P2G_FORCE));
    if (stg->run == mpm_stage_remap) v += dof_of(MPM_P2G_MOM, false);
    /* each moving body's mass at the nodes, in the update (and before
     * the stress with USF) */
    if (stg->run == mpm_stage_grid_update ||
        stg->run == mpm_stage_grid_velocity)
      v += m->n_moving;
  }
  return v;
}

/* Whether rank r holds a node rank q owns (q is one of r's neighbours). */
static bool neighbours(const mpm_decomp *d, const mpm_grid *g, int r, int q) {
  long hl[3], hh[3], ol[3], oh[3];
  mpm_decomp_held(d, r, g, hl, hh);
  mpm_decomp_nodes(d, q, ol, oh);
  for (int a = 0; a < g->dim; a++)
    if (hh[a] <= ol[a] || oh[a] <= hl[a]) return false;
  return true;
}

void mpm_decomp_predict(const mpm_decomp *d, const mpm_model *m, FILE *out) {
  const mpm_grid *g = &m->grid;
  const int values = node_values_per_step(m);
  double ghost_sum = 0, ghost_max = 0, ratio_max = 0;
  int most_nb = 0;
  if (d->size <= 8)
    fprintf(out, "             rank  particles  nodes (owned + ghost)  "
                 "node bytes sent per step\n");
  for (int r = 0; r < d->size; r++) {
    long lo[3], hi[3], hl[3], hh[3];
    mpm_decomp_nodes(d, r, lo, hi);
    mpm_decomp_held(d, r, g, hl, hh);
    double own = 1, held = 1;
    for (int a = 0; a < g->dim; a++) {
      own *= (double)(hi[a] - lo[a]);
      held *= (double)(hh[a] - hl[a]);
    }
    int nb = 0;
    for (int q = 0; q < d->size; q++) nb += q != r && neighbours(d, g, r, q);
    most_nb = nb > most_nb ? nb : most_nb;
    const double ghost = held - own;
    ghost_sum += ghost;
    ghost_max = ghost > ghost_max ? ghost : ghost_max;
    ratio_max = ghost / own > ratio_max ? ghost / own : ratio_max;
    if (d->size <= 8)
      fprintf(out, "             %4d  %9ld  %9.0f (%.0f + %.0f)  %.0f\n", r,
              d->count[r], held, own, ghost,
              2 * ghost * values * sizeof(double));
  }
  fprintf(out,
          "             ghost nodes per rank %.0f on average, %.0f at most "
          "(%.3f of its own at most), %d neighbour ranks at most; %d values "
          "per node and step, so a rank sends %.0f bytes of node sums per "
          "step on average, %.0f at most\n",
          ghost_sum / d->size, ghost_max, ratio_max, most_nb, values,
          2 * ghost_sum / d->size * values * sizeof(double),
          2 * ghost_max * values * sizeof(double));
}

void mpm_par_plan(const mpm_model *m, const mpm_work *w, FILE *out) {
  const struct mpm_par *P = par_of(m);
  const int size = P->d.size;
  /* Per rank: particles, nodes held, nodes owned, bytes, ghost points. */
  double ghosts = 0;
  for (int gi = 0; gi < m->n_groups; gi++) {
    long nearby;
    const long *ids;
    mpm_ghosts_nearby(P->gh, gi, &nearby, &ids);
    ghosts += (double)(mpm_ghosts_count(P->gh, gi) + nearby);
  }
  double mine[5] = {
      (double)m->n, (double)m->grid.n_nodes, (double)P->n_owned,
      (double)(mpm_model_bytes(m) + (w ? mpm_work_bytes(m, w) : 0)), ghosts};
  double *all = NULL;
  if (P->rank == 0) all = calloc((size_t)size * 5, sizeof(double));
  MPI_Gather(mine, 5, MPI_DOUBLE, all, 5, MPI_DOUBLE, 0, pm_par_comm());
  if (P->rank != 0 || !out || !all) {
    free(all);
    return;
  }
  mpm_decomp_print(&P->d, P->scene, out);
  const bool linked = P->gh != NULL;
  fprintf(out,
          "             rank  particles  nodes (owned + ghost)  memory%s\n",
          linked ? "  ghost points (of membranes)" : "");
  for (int r = 0; r < size; r++) {
    const double *v = all + 5 * r;
    fprintf(out, "             %4d  %9.0f  %9.0f (%.0f + %.0f)  %.1f MiB", r,
            v[0], v[1], v[2], v[1] - v[2], v[3] / 1048576.0);
    if (linked) fprintf(out, "  %.0f", v[4]);
    fprintf(out, "\n");
  }
  free(all);
}
