/* mpm_particles: group layouts, their state arrays, and the particles'
 * energies. */
#include "mpm_particles.h"

#include <stdlib.h>
#include <string.h>

#include "mpm_kind.h"
#include "mpm_state.h"
#include "pm_omp.h"

int mpm_group_add_array(mpm_group *g, const char *name, int ncomp) {
  PM_ASSERT(g->n_arrays < MPM_MAX_ARRAYS);
  int k = g->n_arrays++;
  g->layout[k] = (mpm_array){name, ncomp, g->end - g->begin, NULL};
  return k;
}

const mpm_array *mpm_group_state_find(const mpm_group_state *gs,
                                      const char *name) {
  for (int k = 0; k < gs->n; k++)
    if (strcmp(gs->array[k].name, name) == 0) return &gs->array[k];
  return NULL;
}

size_t mpm_particle_bytes_common(void) {
  /* x0, x, v, dx (3 each), mass, vol0, vol, sigma (9) */
  return sizeof(double) * (3 * 4 + 3 + 9);
}

size_t mpm_group_bytes_per_particle(const mpm_group *g) {
  size_t b = 0;
  for (int k = 0; k < g->n_arrays; k++) b += (size_t)g->layout[k].ncomp;
  return b * sizeof(double);
}

pm_err mpm_group_state_alloc(const mpm_group *g, mpm_group_state *gs) {
  const long room = g->cap > g->end - g->begin ? g->cap : g->end - g->begin;
  gs->n = g->n_arrays;
  for (int k = 0; k < g->n_arrays; k++) {
    gs->array[k] = g->layout[k];
    PM_CALL(PM_ALLOC(gs->array[k].data, g->layout[k].ncomp * room,
                     g->layout[k].name));
  }
  return PM_SUCCESS;
}

void mpm_group_state_free(mpm_group_state *gs) {
  for (int k = 0; k < gs->n; k++) free(gs->array[k].data);
  memset(gs, 0, sizeof *gs);
}

void mpm_energies(const mpm_model *m, const mpm_state *s, double *kinetic,
                  double *strain, double *internal) {
  const long n = m->n;
  const double *mass = m->mass, *v = s->v;
  double ke = 0, se = 0, ie = 0;
  PM_OMP(parallel for schedule(static) default(none) shared(n, mass, v)
         reduction(+ : ke))
  for (long p = 0; p < n; p++) {
    const double *vp = v + 3 * p;
    ke += 0.5 * mass[p] * (vp[0] * vp[0] + vp[1] * vp[1] + vp[2] * vp[2]);
  }
  for (int gi = 0; gi < m->n_groups; gi++)
    m->group[gi].kind->energies(m, s, &m->group[gi], &se, &ie);
  *kinetic = ke;
  *strain = se;
  *internal = ie;
}
