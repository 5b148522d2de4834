/* fpm_static_unknowns: the unknowns of FPM's static solve: the free dofs
 * numbered over the ranks (through the exchange), the load stepping's state
 * over them and their displacements, and the rigid motions on them. */
#include <stdlib.h>
#include <string.h>

#include "fpm_static_impl.h"

/* Across ranks: the unknowns of the ghosts, numbered after the own ones,
 * and their numbers over all ranks (each rank's own unknowns follow the
 * ranks' before it; a ghost's are its owner's, by the exchange of the
 * displacements).  A ghost's dof is an unknown where its owner's is. */
pm_err fpm_static_number_ghosts(const fpm_model *m, long *free_of,
                                fpm_static_ctx *c) {
  const long n = m->n;
  double *g = c->du; /* 3 n: the numbers, exact in doubles */
  const long first = fpm_exchange_offset(m->xc, c->nf);
  for (long d = 0; d < 3 * n; d++)
    g[d] = free_of[d] >= 0 ? (double)(first + free_of[d]) : -1;
  fpm_exchange_ghosts(m->xc, g);
  long count = 0;
  for (long d = 3 * m->n_own; d < 3 * n; d++) count += g[d] >= 0;
  PM_CALL(PM_ALLOC(c->ghost, count + 1, "ghost unknowns"));
  for (long d = 3 * m->n_own; d < 3 * n; d++) {
    if (g[d] < 0) continue;
    c->ghost[c->nheld - c->nf] = (long)g[d];
    free_of[d] = c->nheld;
    c->dof[c->nheld++] = d;
  }
  return PM_SUCCESS;
}

/* The rigid motions of the body restricted to the free dofs: translations
 * along each axis and rotations about the centroid (3 and 3 in 3D; x, y
 * and the rotation about z in 2D), into rigid (count x nf). */
int fpm_static_rigid_modes(const fpm_model *m, const long *dof, long nf,
                           double *rigid) {
  double c[3] = {0, 0, 0};
  if (m->xc) { /* the body's centroid: every rank's own points */
    double sum[4] = {0, 0, 0, (double)m->n_own};
    for (long i = 0; i < m->n_own; i++)
      for (int a = 0; a < 3; a++) sum[a] += m->x[3 * i + a];
    fpm_exchange_sum(m->xc, sum, 4);
    for (int a = 0; a < 3; a++) c[a] = sum[a] / sum[3];
  } else {
    for (long i = 0; i < m->n; i++)
      for (int a = 0; a < 3; a++) c[a] += m->x[3 * i + a] / (double)m->n;
  }
  /* rotation about axis r: u = e_r x (x - c) */
  const int rots3[3] = {0, 1, 2}, rots2[1] = {2};
  const int nt = m->dim, nr = m->dim == 3 ? 3 : 1;
  const int *rots = m->dim == 3 ? rots3 : rots2;
  for (long j = 0; j < nf; j++) {
    const long i = dof[j] / 3;
    const int comp = (int)(dof[j] % 3);
    const double *x = m->x + 3 * i;
    for (int t = 0; t < nt; t++) rigid[t * nf + j] = comp == t ? 1 : 0;
    for (int q = 0; q < nr; q++) {
      const int r = rots[q], a = (r + 1) % 3, b = (r + 2) % 3;
      /* (e_r x d)_a = -d_b, (e_r x d)_b = d_a */
      double val = 0;
      if (comp == a) val = -(x[b] - c[b]);
      if (comp == b) val = x[a] - c[a];
      rigid[(nt + q) * nf + j] = val;
    }
  }
  return nt + nr;
}

void fpm_static_nodal(const fpm_model *m, const double *x, double *u) {
  fpm_static_nodal_fixed(m->n_own, m->fixed, x, u);
}

void fpm_static_nodal_fixed(long n, const unsigned char *fixed, const double *x,
                            double *u) {
  long j = 0;
  for (long d = 0; d < 3 * n; d++) u[d] = fixed[d] ? 0 : x[j++];
}

void fpm_static_unknowns(const fpm_model *m, const double *u, double *x) {
  long j = 0;
  for (long d = 0; d < 3 * m->n_own; d++)
    if (!m->fixed[d]) x[j++] = u[d];
}

pm_err fpm_static_state_init(fpm_static_state *s, const fpm_model *m) {
  memset(s, 0, sizeof *s);
  for (long d = 0; d < 3 * m->n_own; d++) s->free_dofs += !m->fixed[d];
  return pm_load_state_init(&s->load, s->free_dofs > 0 ? s->free_dofs : 1);
}

void fpm_static_state_free(fpm_static_state *s) {
  pm_load_state_free(&s->load);
}

int fpm_static_block_size(const long *dof, long nf) {
  int size = 0;
  for (long j = 0; j < nf;) {
    long k = j + 1; /* the run of dofs of point dof[j] / 3 */
    while (k < nf && dof[k] / 3 == dof[j] / 3) k++;
    if (size == 0) size = (int)(k - j);
    if (k - j != size) return 1;
    j = k;
  }
  return size > 1 ? size : 1;
}
