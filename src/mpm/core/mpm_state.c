/* mpm_state: allocation and copy of a run's state and workspace. */
#include "mpm_state.h"

#include "mpm_kind.h"
#include "mpm_exchange.h"

#include <stdlib.h>
#include <string.h>

#include "pm_omp.h"

pm_err mpm_state_create(const mpm_model *m, mpm_state **out) {
  pm_err ret = PM_SUCCESS;
  mpm_state *s = NULL;
  const long n = mpm_model_room(m), n3 = 3 * m->grid.n_nodes;
  *out = NULL;
  PM_TRY(PM_ALLOC(s, 1, "MPM state"));
  PM_TRY(PM_ALLOC(s->x, 3 * n, "particle positions"));
  PM_TRY(PM_ALLOC(s->v, 3 * n, "particle velocities"));
  PM_TRY(PM_ALLOC(s->vol, n, "particle volumes"));
  PM_TRY(PM_ALLOC(s->sigma, 9 * n, "particle stresses"));
  for (int gi = 0; gi < m->n_groups; gi++)
    PM_TRY(mpm_group_state_alloc(&m->group[gi], &s->group[gi]));
  if (m->opt.qs == PM_QS_DYNAMIC_RELAXATION) {
    PM_TRY(PM_ALLOC(s->force_prev, n3, "previous grid forces"));
    if (m->n_bcs > 0) PM_TRY(PM_ALLOC(s->fixed, n3, "previous fixed dofs"));
  }
  *out = s;
  s = NULL;
done:
  mpm_state_destroy(s);
  return ret;
}

void mpm_state_destroy(mpm_state *s) {
  if (!s) return;
  free(s->x);
  free(s->v);
  free(s->vol);
  free(s->sigma);
  for (int gi = 0; gi < MPM_MAX_GROUPS; gi++)
    mpm_group_state_free(&s->group[gi]);
  free(s->force_prev);
  free(s->fixed);
  free(s);
}

int mpm_state_arrays(const mpm_model *m, const mpm_state *s, mpm_array *out,
                     int max) {
  const long n = m->n;
  const mpm_array common[] = {{"position", 3, n, s->x},
                              {"velocity", 3, n, s->v},
                              {"volume", 1, n, s->vol},
                              {"stress", 9, n, s->sigma}};
  int k = 0;
  for (int c = 0; c < 4; c++, k++)
    if (k < max) out[k] = common[c];
  for (int gi = 0; gi < m->n_groups; gi++)
    for (int a = 0; a < s->group[gi].n; a++, k++)
      if (k < max) out[k] = s->group[gi].array[a];
  return k;
}

void mpm_state_copy(const mpm_model *m, mpm_state *dst, const mpm_state *src) {
  mpm_array from[MPM_STATE_MAX_ARRAYS], to[MPM_STATE_MAX_ARRAYS];
  int n = mpm_state_arrays(m, src, from, MPM_STATE_MAX_ARRAYS);
  mpm_state_arrays(m, dst, to, MPM_STATE_MAX_ARRAYS);
  for (int k = 0; k < n; k++)
    memcpy(to[k].data, from[k].data,
           sizeof(double) * from[k].ncomp * from[k].count);
  const size_t n3 = 3 * (size_t)m->grid.n_nodes;
  if (dst->force_prev)
    memcpy(dst->force_prev, src->force_prev, n3 * sizeof(double));
  if (dst->fixed) memcpy(dst->fixed, src->fixed, n3);
  mpm_state_copy_values(dst, src);
}

void mpm_state_copy_values(mpm_state *dst, const mpm_state *src) {
  mpm_state keep = *dst;
  *dst = *src;
  dst->x = keep.x;
  dst->v = keep.v;
  dst->vol = keep.vol;
  dst->sigma = keep.sigma;
  memcpy(dst->group, keep.group, sizeof keep.group);
  dst->force_prev = keep.force_prev;
  dst->fixed = keep.fixed;
}

size_t mpm_state_bytes(const mpm_model *m, const mpm_state *s) {
  mpm_array a[MPM_STATE_MAX_ARRAYS];
  int n = mpm_state_arrays(m, s, a, MPM_STATE_MAX_ARRAYS);
  size_t bytes = 0;
  for (int k = 0; k < n; k++)
    bytes += sizeof(double) * a[k].ncomp * (size_t)a[k].count;
  size_t n3 = 3 * (size_t)m->grid.n_nodes;
  if (s->force_prev) bytes += n3 * sizeof(double);
  if (s->fixed) bytes += n3;
  return bytes;
}

pm_err mpm_work_create(const mpm_model *m, mpm_work **out) {
  pm_err ret = PM_SUCCESS;
  mpm_work *w = NULL;
  const long n = mpm_model_room(m);
  *out = NULL;
  PM_TRY(PM_ALLOC(w, 1, "MPM workspace"));
  PM_TRY(mpm_nodes_create(&w->nodes, &m->grid, m->opt.update != MPM_USL,
                          m->has_absorbing, pm_omp_threads()));
  PM_TRY(mpm_cond_work_create(&w->cond, &m->grid, m->bcs, m->n_bcs));
  PM_TRY(PM_ALLOC(w->dx, 3 * n, "particle increments"));
  PM_TRY(PM_ALLOC(w->cp, n, "particle wave speeds"));
  if (m->has_absorbing) PM_TRY(PM_ALLOC(w->cs, n, "particle wave speeds"));
  for (int gi = 0; gi < m->n_groups; gi++) {
    const mpm_group *g = &m->group[gi];
    w->n_scratch[gi] = g->kind->scratch ? g->kind->scratch(m, g) : 0;
    if (w->n_scratch[gi] > 0)
      PM_TRY(PM_ALLOC(w->scratch[gi], w->n_scratch[gi], "kind workspace"));
    if (g->kind->work_create) {
      w->kind_work_free[gi] = g->kind->work_free;
      PM_TRY(g->kind->work_create(m, g, &w->kind_work[gi],
                                  &w->kind_work_bytes[gi]));
    }
  }
  if (m->n_moving > 0)
    PM_TRY(PM_ALLOC(w->rigid_mass, m->grid.n_nodes, "moving bodies' masses"));
  bool solids = false;
  for (int gi = 0; gi < m->n_groups; gi++)
    solids |= m->group[gi].kind == &mpm_kind_solid;
  if (m->opt.fbar != MPM_FBAR_NONE && solids)
    PM_TRY(mpm_fbar_work_create(&w->fbar, m->opt.fbar, n, m->grid.n_nodes,
                                pm_omp_threads()));
  pm_timers_init(&w->timers);
  for (int k = 0; k < m->pipeline.n; k++)
    w->timer[k] = pm_timers_add(&w->timers, m->pipeline.stage[k].name);
  w->timer_migrate = -1;
  mpm_xc_work_attach(m, w);
  *out = w;
  w = NULL;
done:
  mpm_work_destroy(w);
  return ret;
}

void mpm_work_destroy(mpm_work *w) {
  if (!w) return;
  mpm_nodes_destroy(&w->nodes);
  mpm_cond_work_destroy(&w->cond);
  free(w->dx);
  free(w->cp);
  free(w->cs);
  for (int gi = 0; gi < MPM_MAX_GROUPS; gi++) {
    free(w->scratch[gi]);
    if (w->kind_work[gi]) w->kind_work_free[gi](w->kind_work[gi]);
  }
  free(w->rigid_mass);
  mpm_fbar_work_destroy(&w->fbar);
  free(w);
}

size_t mpm_work_bytes(const mpm_model *m, const mpm_work *w) {
  size_t per_particle = 3 + 1 + (w->cs ? 1 : 0); /* dx, cp, cs */
  size_t scratch = 0;
  for (int gi = 0; gi < m->n_groups; gi++)
    scratch +=
        sizeof(double) * (size_t)w->n_scratch[gi] + w->kind_work_bytes[gi];
  if (w->rigid_mass) scratch += sizeof(double) * (size_t)m->grid.n_nodes;
  return mpm_nodes_bytes(&w->nodes, &m->grid) +
         mpm_cond_work_bytes(&w->cond, &m->grid) +
         mpm_fbar_work_bytes(&w->fbar) +
         per_particle * sizeof(double) *
             (size_t)(w->dx ? mpm_model_room(m) : 0) +
         scratch;
}

/* The state's values before its arrays in a checkpoint. */
static pm_err values_head(mpm_state *s, pm_ckpt *ck) {
  PM_CALL(pm_ckpt_double(ck, "mpm.t", &s->t));
  PM_CALL(pm_ckpt_long(ck, "mpm.step", &s->step));
  PM_CALL(pm_ckpt_double(ck, "mpm.dt", &s->dt));
  PM_CALL(pm_ckpt_double(ck, "mpm.dt_stable", &s->dt_stable));
  return pm_ckpt_double(ck, "mpm.max_div_prev", &s->max_div_prev);
}

/* The state's values after its arrays, with the nodal arrays of dynamic
 * relaxation (n3 values: 0 without them) between the accounts and the
 * counters. */
static pm_err values_tail(mpm_state *s, long n3, pm_ckpt *ck) {
  const long n_acc = (long)(sizeof s->energy / (sizeof(double)));
  long iter_max = s->iter_max_total;
  PM_CALL(pm_ckpt_doubles(ck, "mpm.energy", n_acc, (double *)s->energy));
  PM_CALL(pm_ckpt_doubles(ck, "mpm.iso", (long)(sizeof s->iso / sizeof(double)),
                          (double *)&s->iso));
  PM_CALL(pm_ckpt_double(ck, "mpm.external_work", &s->external_work));
  PM_CALL(pm_ckpt_double(ck, "mpm.dissipated", &s->dissipated));
  PM_CALL(pm_ckpt_double(ck, "mpm.damping", &s->damping));
  PM_CALL(pm_ckpt_doubles(ck, "mpm.force_prev", s->force_prev ? n3 : 0,
                          s->force_prev));
  PM_CALL(pm_ckpt_bytes(ck, "mpm.fixed", s->fixed ? n3 : 0, s->fixed));
  PM_CALL(pm_ckpt_long(ck, "mpm.iter_max_total", &iter_max));
  s->iter_max_total = (int)iter_max;
  return pm_ckpt_long(ck, "mpm.iter_capped_total", &s->iter_capped_total);
}

pm_err mpm_state_checkpoint(const mpm_model *m, mpm_state *s, pm_ckpt *ck) {
  mpm_array a[MPM_STATE_MAX_ARRAYS];
  PM_CALL(values_head(s, ck));
  int na = mpm_state_arrays(m, s, a, MPM_STATE_MAX_ARRAYS);
  for (int k = 0; k < na; k++) {
    char name[96];
    snprintf(name, sizeof name, "mpm.%02d.%s", k, a[k].name);
    PM_CALL(pm_ckpt_doubles(ck, name, a[k].ncomp * a[k].count, a[k].data));
  }
  return values_tail(s, 3 * m->grid.n_nodes, ck);
}

pm_err mpm_state_checkpoint_values(mpm_state *s, pm_ckpt *ck) {
  PM_CALL(values_head(s, ck));
  return values_tail(s, 0, ck);
}
