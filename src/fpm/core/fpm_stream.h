/* fpm_stream: the explicit force's support entries in blocks of FPM_LANES
 * (padded, structure-of-arrays) and the gather and flux passes over them,
 * vectorised across the entries of a block. */
#ifndef FPM_STREAM_H
#define FPM_STREAM_H

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "fpm_model.h"
#include "pm_v4.h"

/* Whether the model's formulation is the plain one whose flux pass the
 * stream serves (linear jump, incomplete flux, no stiffening or volume
 * penalty). */
bool fpm_stream_plain(const fpm_model *m);

/* Bytes of a stream of rows points holding entries padded entries
 * (FPM_LANES times its blocks), with the flux records when plain. */
size_t fpm_stream_bytes(long rows, long entries, bool plain);

/* Builds m->fs_ptr, fs_nbr, fs_g, fs_gm (and fs_rec with the plain
 * formulation) from m->nbr, m->g, m->mirror and m->erec, for the rows of
 * points [0, m->n_stress) (the mirrors' weights of [0, m->n_own)).  Padding
 * entries point at the row's own point with zero weights and records, so they
 * add exact zeros.  Errors: PM_ERR_MEMORY (the arrays freed by
 * fpm_model_destroy). */
pm_err fpm_stream_build(fpm_model *m);

/* The flux pass (fpm_force.c's pass 2) of the plain formulation: r and T
 * of points [0, m->n_flux) from u, H, P; returns this thread's share of the
 * interface energy of the model's own points.  Inside a parallel region
 * the team shares the points (a static schedule, no barrier after); alone,
 * one thread takes them all.  Needs m->fs_rec.  Equal to the general pass
 * to round-off (the entries' sums are taken FPM_LANES at a time). */
double fpm_stream_flux(const fpm_model *m, const double *u, const double *H,
                       const double *P, double *T, double *r);

/* The gather pass (fpm_force.c's pass 3): f of points [0, m->n_own) from T
 * and r, shared by the team as the flux pass (no barrier after).  Equal
 * to the general pass to round-off. */
void fpm_stream_gather(const fpm_model *m, const double *T, const double *r,
                       double *f);

_Static_assert(FPM_LANES == 4, "a block of the stream is one pm_v4");

/* Component c of the items at offsets k[0..3] of A (four lanes). */
#define FPM_GATHER(A, k, c)                                                    \
  (pm_v4) { A[(k)[0] + (c)], A[(k)[1] + (c)], A[(k)[2] + (c)], A[(k)[3] + (c)] }

/* The nine components of the items at offsets k[0..3] of A (tensors of
 * nine doubles), out[c] lane l = A[k[l] + c]: each item's components 0-3
 * and 4-7 as two vector loads, transposed, and the ninth gathered; the
 * values of FPM_GATHER in fewer instructions. */
static inline void fpm_gather9(const double *A, const int k[4], pm_v4 out[9]) {
  pm_v4 lo[4], hi[4];
  for (int l = 0; l < 4; l++) {
    lo[l] = pm_v4_load(A + k[l]);
    hi[l] = pm_v4_load(A + k[l] + 4);
  }
  pm_v4_transpose(lo, out);
  pm_v4_transpose(hi, out + 4);
  out[8] = FPM_GATHER(A, k, 8);
}

/* The displacement gradient of point i < m->n_stress over its streamed
 * entries: h = sum_k (u_k - u_i) (x) g_ik (row-major 3 x 3, out).  Equal to
 * the entry-by-entry sum to round-off. */
static inline void fpm_stream_gradient(const fpm_model *m,
                                       const double *restrict u, long i,
                                       double h[9]) {
  pm_v4 acc[9] = {0};
  const double *ui = u + 3 * i;
  for (long b = m->fs_ptr[i]; b < m->fs_ptr[i + 1]; b++) {
    const int *kb = m->fs_nbr + FPM_LANES * b;
    const int k3[4] = {3 * kb[0], 3 * kb[1], 3 * kb[2], 3 * kb[3]};
    const double *gb = m->fs_g + 3 * FPM_LANES * b;
    const pm_v4 g0 = pm_v4_load(gb), g1 = pm_v4_load(gb + FPM_LANES),
                g2 = pm_v4_load(gb + 2 * FPM_LANES);
    for (int c = 0; c < 3; c++) {
      const pm_v4 d = FPM_GATHER(u, k3, c) - ui[c];
      acc[3 * c] += d * g0;
      acc[3 * c + 1] += d * g1;
      acc[3 * c + 2] += d * g2;
    }
  }
  for (int a = 0; a < 9; a++)
    h[a] = acc[a][0] + acc[a][1] + acc[a][2] + acc[a][3];
}

/* The closing terms of point i's flux: r_i = ri - 1/2 P_i A_i and
 * T_i = V_i P_i - Q + Tv - 1/2 P_i Bm_i (A_i, Bm_i the point's sums of area
 * vectors and moments, m->p_area and m->p_mrel); writes r_i and T_i. */
static inline void fpm_flux_close(const fpm_model *m, long i, const double *Pi,
                                  const double Q[9], const double ri[3],
                                  const double Tv[9], double *r, double *T) {
  const double *A = m->p_area + 3 * i, *Bm = m->p_mrel + 9 * i;
  const double vol = m->dual->volume[i];
  for (int c = 0; c < 3; c++) {
    r[3 * i + c] = ri[c] - 0.5 * (Pi[3 * c] * A[0] + Pi[3 * c + 1] * A[1] +
                                  Pi[3 * c + 2] * A[2]);
    for (int q = 0; q < 3; q++)
      T[9 * i + 3 * c + q] =
          vol * Pi[3 * c + q] - Q[3 * c + q] + Tv[3 * c + q] -
          0.5 * (Pi[3 * c] * Bm[q] + Pi[3 * c + 1] * Bm[3 + q] +
                 Pi[3 * c + 2] * Bm[6 + q]);
  }
}

#endif
