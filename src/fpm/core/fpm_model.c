/* fpm_model: everything the FPM time loop reads but never changes, computed
 * once from the scene and the median-dual subdomains. */
#include "fpm_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fpm_contact.h"
#include "fpm_stream.h"
#include "fpm_gfd.h"
#include "fpm_volumetric.h"
#include "gm_shape.h"
#include "pm_omp.h"

/* Supports whose scaled moment matrix is worse than this cannot give a
 * usable gradient. */

void fpm_model_destroy(fpm_model *m) {
  if (!m) return;
  fpm_contact_destroy(m->contact);
  free(m->g);
  free(m->gsum);
  free(m->mirror);
  free(m->cond);
  free(m->nbr);
  free(m->erec);
  free(m->p_area);
  free(m->p_mrel);
  free(m->fs_ptr);
  free(m->fs_nbr);
  free(m->fs_rec);
  free(m->fs_g);
  free(m->fs_gm);
  free(m->mat);
  free(m->mstate);
  free(m->mass);
  free(m->dpt_point);
  free(m->dpt_area);
  free(m->dpt_mrel);
  free(m->tf_point);
  free(m->tf_bc);
  free(m->tf_area);
  free(m->tf_rel);
  free(m->tf_centroid);
  free(m->tf_base);
  free(m->tf_normal);
  free(m->bf_base);
  free(m->pf_point);
  free(m->pf_bc);
  free(m->pf_share);
  free(m->cd_point);
  free(m->cd_comp);
  free(m->cd_bc);
  free(m->cd_base);
  free(m->fixed);
  free(m->bcf_ptr);
  free(m->bcf_facet);
  free(m->qs_ptr);
  free(m->qt_ptr);
  free(m->qs_nbr);
  free(m->qs_own);
  free(m->qt_entry);
  free(m->q);
  free(m->qsum);
  free(m->vavg);
  free(m->vself);
  free(m->gid);
  free(m->tf_gid);
  gm_dual_destroy(m->own_dual);
  if (m->xc) m->xc->release(m->xc->ctx);
  free(m);
}

void fpm_model_drop_static(fpm_model *m) {
  if (!m->fs_rec) return;
  free(m->erec);
  free(m->g);
  m->erec = NULL;
  m->g = NULL;
}

size_t fpm_model_bytes(const fpm_model *m) {
  size_t d = sizeof(double);
  return m->nnz * ((m->g ? 3 : 0) + (m->erec ? FPM_EREC : 0)) * d +
         m->nnz * 2 * sizeof(int) + m->n * (3 + 1 + 3 + 9 + 1) * d +
         m->n * (sizeof(int) + 3) + m->n_dpts * (36 * d + sizeof(long)) +
         m->n_tfacets * (7 * d + sizeof(long) + sizeof(int)) +
         m->n_cdofs * (d + sizeof(long) + 2 * sizeof(int)) +
         (m->q ? (size_t)m->qs_ptr[m->n] * (FPM_QFIT * d + 3 * sizeof(int)) +
                     (size_t)m->n * (FPM_QFIT * d + 2 * sizeof(long))
               : 0) +
         (m->vavg ? (size_t)(m->nnz + m->n) * d : 0) +
         (m->fs_ptr
              ? fpm_stream_bytes(m->n_stress,
                                 FPM_LANES * m->fs_ptr[m->n_stress], m->fs_rec)
              : 0);
}

/* Entry (k, i) for every entry (i, k): supports are symmetric (mesh
 * edges), and the sorted CSR rows make it a binary search. */
static pm_err build_mirror(fpm_model *m) {
  for (long i = 0; i < m->n; i++)
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
      long k = m->nbr[e], lo = m->nbr_ptr[k], hi = m->nbr_ptr[k + 1] - 1;
      long found = -1;
      if (m->gid && lo > hi) { /* a part's edge: k's row is not held */
        m->mirror[e] = -1;
        continue;
      }
      while (lo <= hi) {
        long mid = (lo + hi) / 2;
        if (m->nbr[mid] == i) {
          found = mid;
          break;
        }
        if (m->nbr[mid] < i)
          lo = mid + 1;
        else
          hi = mid - 1;
      }
      PM_CHECK(found >= 0, PM_ERR_GEOMETRY,
               "support of point %ld holds %ld but not the reverse", i, k);
      m->mirror[e] = (int)found;
    }
  return PM_SUCCESS;
}

/* Each point takes the material of the last body that holds it (a body
 * meshed as the domain holds every point), and the per-point state its
 * model derives from that body (fibre directions). */
static pm_err assign_materials(fpm_model *m, const pm_scene *s,
                               int domain_body) {
  pm_err ret = PM_SUCCESS;
  int *body_of = NULL;
  gm_shape *shape = NULL;
  PM_ENSURE(s->n_materials >= 1 && s->n_materials <= FPM_MAX_MATERIALS,
            PM_ERR_SCENE,
            "%s: between 1 and %d materials are supported (got %d)", s->path,
            FPM_MAX_MATERIALS, s->n_materials);
  m->n_mats = s->n_materials;
  for (int k = 0; k < s->n_materials; k++) m->mats[k] = s->materials[k].mat;
  PM_TRY(PM_ALLOC(body_of, m->n, "point bodies"));
  for (long i = 0; i < m->n; i++) body_of[i] = -1;
  for (int b = 0; b < s->n_bodies; b++) {
    if (b == domain_body) {
      for (long i = 0; i < m->n; i++) body_of[i] = b;
      continue;
    }
    PM_TRY(gm_shape_create(&s->bodies[b], s->dimension, s->box_min, s->box_max,
                           s->mesh_size, &shape));
    for (long i = 0; i < m->n; i++)
      if (gm_shape_contains(shape, m->x + 3 * i)) body_of[i] = b;
    gm_shape_destroy(shape);
    shape = NULL;
  }
  for (long i = 0; i < m->n; i++) {
    PM_ENSURE(body_of[i] >= 0, PM_ERR_SCENE,
              "%s: point %ld at (%g, %g, %g) lies in no body", s->path, i,
              m->x[3 * i], m->x[3 * i + 1], m->x[3 * i + 2]);
    m->mat[i] = s->bodies[body_of[i]].material;
    m->mass[i] = m->mats[m->mat[i]].density * m->dual->volume[i];
  }
  for (int k = 0; k < m->n_mats; k++)
    if (m->mats[k].state_size > m->mstate_stride)
      m->mstate_stride = m->mats[k].state_size;
  if (m->mstate_stride > 0) {
    PM_TRY(PM_ALLOC(m->mstate, (size_t)m->mstate_stride * m->n,
                    "per-point material state"));
    for (long i = 0; i < m->n; i++) {
      const pm_material *mat = &m->mats[m->mat[i]];
      if (mat->model->state_init)
        mat->model->state_init(mat, &s->bodies[body_of[i]].point,
                               m->mstate + m->mstate_stride * i);
    }
  }
done:
  gm_shape_destroy(shape);
  free(body_of);
  return ret;
}

/* beta |e| / p = E / h |e| of interface f between points i and k (E the
 * mean of their Young's moduli, h their distance). */
static double unit_beta(const fpm_model *m, long i, long k, long f) {
  const double *xi = m->x + 3 * i, *xk = m->x + 3 * k;
  const double h = sqrt((xk[0] - xi[0]) * (xk[0] - xi[0]) +
                        (xk[1] - xi[1]) * (xk[1] - xi[1]) +
                        (xk[2] - xi[2]) * (xk[2] - xi[2]));
  const double E = 0.5 * (m->mats[m->mat[i]].youngs_modulus +
                          m->mats[m->mat[k]].youngs_modulus);
  return E / h * m->dual->if_area[f];
}

/* Interface records per support entry and the per-point sums of the
 * consistency geometry (oriented outward from each point). */
static void build_interfaces(fpm_model *m) {
  const gm_dual *d = m->dual;
  for (long i = 0; i < m->n; i++) {
    const double *xi = m->x + 3 * i;
    double *pa = m->p_area + 3 * i, *pm = m->p_mrel + 9 * i;
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
      long k = m->nbr[e], f = d->nbr_iface[e];
      const double *xk = m->x + 3 * k, *xe = d->if_centroid + 3 * f;
      const double *af = d->if_area_vec + 3 * f, *Mf = d->if_moment + 9 * f;
      double sign = d->if_pair[2 * f] == i ? 1.0 : -1.0;
      double *r = m->erec + FPM_EREC * e;
      for (int p = 0; p < 3; p++) {
        r[p] = sign * af[p];
        r[12 + p] = xe[p] - xi[p];
        r[15 + p] = xe[p] - xk[p];
        for (int q = 0; q < 3; q++)
          r[3 + 3 * p + q] = sign * (Mf[3 * p + q] - af[p] * xe[q]);
      }
      for (int p = 0; p < 3; p++) {
        pa[p] += r[p];
        for (int q = 0; q < 3; q++)
          pm[3 * p + q] += r[3 + 3 * p + q] + r[p] * r[12 + q];
      }
      r[18] = m->penalty * unit_beta(m, i, k, f);
      r[19] = 0;
      {
        const double h2 = (xk[0] - xi[0]) * (xk[0] - xi[0]) +
                          (xk[1] - xi[1]) * (xk[1] - xi[1]) +
                          (xk[2] - xi[2]) * (xk[2] - xi[2]);
        r[20] = m->stiffening * unit_beta(m, i, k, f) / h2;
        r[22] = m->stiffening_onset * m->stiffening_onset * h2;
      }
      r[21] = m->volume_penalty * unit_beta(m, i, k, f);
    }
  }
}

/* With the quadratic jump, the linear-jump penalty beta_b |e| = p_b E /
 * h_e |e| (record slot 19) on every interface of a point that has a
 * boundary facet (where the quadratic fits are one-sided). */
static pm_err boundary_penalty(fpm_model *m) {
  pm_err ret = PM_SUCCESS;
  const gm_dual *d = m->dual;
  unsigned char *on = NULL;
  PM_TRY(PM_ALLOC(on, m->n, "boundary points"));
  for (long f = 0; f < d->n_facets; f++) on[d->facet_point[f]] = 1;
  for (long i = 0; i < m->n; i++)
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
      const long k = m->nbr[e];
      if (!on[i] && !on[k]) continue;
      m->erec[FPM_EREC * e + 19] =
          m->boundary_penalty * unit_beta(m, i, k, d->nbr_iface[e]);
    }
done:
  free(on);
  return ret;
}

/* A support with fewer points than this, or a fit worse conditioned than
 * QFIT_COND_NARROW, takes its two rings; a two-ring fit worse than
 * QFIT_COND_MAX falls back to the linear reconstruction. */
#define QFIT_COND_NARROW 1e5
#define QFIT_COND_MAX 1e8

/* The two rings of point i (its support and theirs, without i), sorted,
 * into out (capacity cap); returns the count. */
static long two_rings(const fpm_model *m, long i, long *out, long cap) {
  long c = 0;
  for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
    long k = m->nbr[e];
    if (c < cap) out[c++] = k;
    for (long f = m->nbr_ptr[k]; f < m->nbr_ptr[k + 1]; f++)
      if (m->nbr[f] != i && c < cap) out[c++] = m->nbr[f];
  }
  /* insertion sort and unique (short lists) */
  for (long a = 1; a < c; a++)
    for (long b = a; b > 0 && out[b - 1] > out[b]; b--) {
      long t = out[b];
      out[b] = out[b - 1];
      out[b - 1] = t;
    }
  long u = 0;
  for (long a = 0; a < c; a++)
    if (u == 0 || out[a] != out[u - 1]) out[u++] = out[a];
  return u;
}

/* The quadratic reconstruction of fpm.jump: quadratic: each point's fit
 * over its support, or its two rings where the support cannot determine a
 * quadratic, and the transpose lists of the fits. */
static pm_err build_quadratic(fpm_model *m) {
  pm_err ret = PM_SUCCESS;
  const long n = m->n, nnz = m->nnz;
  const int unknowns = m->dim == 2 ? 5 : 9;
  const long *nbr = m->dual->nbr;
  double *q1 = NULL, *cond = NULL;
  long *ring = NULL, *nbrq = NULL, *fill = NULL;
  unsigned char *wide = NULL;
  const long cap = 4096;
  PM_TRY(PM_ALLOC(q1, FPM_QFIT * nnz, "quadratic fit weights"));
  PM_TRY(PM_ALLOC(cond, n, "quadratic fit conditions"));
  fpm_gfd_quadratic(m->dim, n, m->x, m->nbr_ptr, nbr, NULL, q1, cond);
  /* Which points need their two rings, and the fit supports' sizes. */
  PM_TRY(PM_ALLOC(wide, n, "quadratic fit rings"));
  PM_TRY(PM_ALLOC(ring, cap, "two rings"));
  PM_TRY(PM_ALLOC(m->qs_ptr, n + 1, "quadratic fit supports"));
  m->n_qwide = 0;
  for (long i = 0; i < n; i++) {
    long cnt = m->nbr_ptr[i + 1] - m->nbr_ptr[i];
    wide[i] = cnt < unknowns + 3 || !(cond[i] <= QFIT_COND_NARROW);
    if (wide[i]) {
      cnt = two_rings(m, i, ring, cap);
      m->n_qwide++;
    }
    m->qs_ptr[i + 1] = m->qs_ptr[i] + cnt;
  }
  const long nq = m->qs_ptr[n];
  PM_ENSURE(nq < 2147483647L, PM_ERR_ARG,
            "%ld quadratic-fit entries exceed the 32-bit index range", nq);
  PM_TRY(PM_ALLOC(nbrq, nq, "quadratic fit supports"));
  PM_TRY(PM_ALLOC(m->qs_nbr, nq, "quadratic fit supports"));
  PM_TRY(PM_ALLOC(m->qs_own, nq, "quadratic fit owners"));
  PM_TRY(PM_ALLOC(m->qsum, FPM_QFIT * n, "quadratic fit sums"));
  /* A narrow point keeps its first fit; a wide one is fitted again over
   * its two rings (each fit zeroes its entries first).  The first fits
   * become the fits' weights in place, each narrow point's moved to its
   * entries, the last point first (no row moves down: a fit's entries
   * are at least its support's), so that the two arrays are never held
   * together. */
  PM_TRY(pm_realloc((void **)&q1, (size_t)FPM_QFIT * nq, sizeof(double),
                    "quadratic fit weights"));
  m->q = q1;
  q1 = NULL;
  for (long i = n - 1; i >= 0; i--) {
    const long b = m->qs_ptr[i], e0 = m->nbr_ptr[i];
    if (wide[i]) {
      long c = two_rings(m, i, ring, cap);
      for (long a = 0; a < c; a++) nbrq[b + a] = ring[a];
      continue;
    }
    for (long e = e0; e < m->nbr_ptr[i + 1]; e++) nbrq[b + e - e0] = nbr[e];
    memmove(m->q + FPM_QFIT * b, m->q + FPM_QFIT * e0,
            sizeof(double) * FPM_QFIT * (size_t)(m->nbr_ptr[i + 1] - e0));
  }
  fpm_gfd_quadratic(m->dim, n, m->x, m->qs_ptr, nbrq, wide, m->q, cond);
  m->n_qlinear = 0;
  for (long i = 0; i < n; i++) {
    if (!(cond[i] <= QFIT_COND_MAX)) {
      /* No usable quadratic: the point's linear GFD field, its support
       * being part of the fit support (both sorted). */
      m->n_qlinear++;
      long f = m->qs_ptr[i];
      for (long e = m->qs_ptr[i]; e < m->qs_ptr[i + 1]; e++)
        for (int a = 0; a < FPM_QFIT; a++) m->q[FPM_QFIT * e + a] = 0;
      for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++) {
        while (nbrq[f] != nbr[e]) f++;
        for (int a = 0; a < 3; a++) m->q[FPM_QFIT * f + a] = m->g[3 * e + a];
      }
    }
    for (long e = m->qs_ptr[i]; e < m->qs_ptr[i + 1]; e++) {
      m->qs_nbr[e] = (int)nbrq[e];
      m->qs_own[e] = (int)i;
      for (int a = 0; a < FPM_QFIT; a++)
        m->qsum[FPM_QFIT * i + a] += m->q[FPM_QFIT * e + a];
    }
  }
  /* Transpose: the entries whose neighbour is each point. */
  PM_TRY(PM_ALLOC(m->qt_ptr, n + 1, "quadratic fit transpose"));
  PM_TRY(PM_ALLOC(m->qt_entry, nq, "quadratic fit transpose"));
  PM_TRY(PM_ALLOC(fill, n, "quadratic fit transpose"));
  for (long e = 0; e < nq; e++) m->qt_ptr[m->qs_nbr[e] + 1]++;
  for (long i = 0; i < n; i++) m->qt_ptr[i + 1] += m->qt_ptr[i];
  for (long i = 0; i < n; i++) fill[i] = m->qt_ptr[i];
  for (long e = 0; e < nq; e++) m->qt_entry[fill[m->qs_nbr[e]]++] = (int)e;
done:
  free(q1);
  free(cond);
  free(wide);
  free(ring);
  free(nbrq);
  free(fill);
  return ret;
}

int fpm_domain_body(const pm_scene *s) {
  return s->n_bodies == 1 && s->bodies[0].shape == PM_BODY_MESH ? 0 : -1;
}

/* The model on cells d (of a part: gid, its interfaces let go after the
 * records where part is d; of the whole: both NULL). */
static pm_err model_create(const pm_scene *s, const fpm_options *o,
                           const gm_mesh *mesh, const gm_dual *d,
                           const long *gid, gm_dual *part, fpm_model **out) {
  pm_err ret = PM_SUCCESS;
  fpm_model *m = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(m, 1, "FPM model"));
  if (gid) {
    PM_TRY(PM_ALLOC(m->gid, d->n_points + 1, "part's point indices"));
    memcpy(m->gid, gid, sizeof(long) * (size_t)d->n_points);
  }
  m->dim = d->dim;
  m->n = d->n_points;
  m->dual = d;
  m->x = d->x;
  m->nbr_ptr = d->nbr_ptr;
  m->nnz = d->nbr_ptr[d->n_points];
  m->scene = s;
  m->penalty = o->penalty;
  m->boundary_penalty = o->boundary_penalty;
  m->stiffening = o->stiffening;
  m->stiffen_quadratic =
      o->stiffening_jump == FPM_JUMP_QUADRATIC && o->jump == FPM_JUMP_QUADRATIC;
  m->volume_penalty = o->volume_penalty;
  m->stiffening_onset = o->stiffening_onset;
  m->stiffen_current = o->stiffening_spacing == FPM_SPACING_CURRENT;
  m->flux = (fpm_flux)o->flux;
  m->jump = (fpm_jump)o->jump;
  m->n_own = m->n_flux = m->n_stress = m->n;
  long n = m->n, nnz = m->nnz;
  PM_TRY(PM_ALLOC(m->g, 3 * nnz, "GFD weights"));
  PM_TRY(PM_ALLOC(m->gsum, 3 * n, "GFD weight sums"));
  PM_ENSURE(nnz < 2147483647L, PM_ERR_ARG,
            "%ld support entries exceed the 32-bit index range", nnz);
  PM_TRY(PM_ALLOC(m->nbr, nnz, "support"));
  for (long e = 0; e < nnz; e++) m->nbr[e] = (int)d->nbr[e];
  PM_TRY(PM_ALLOC(m->mirror, nnz, "support mirror"));
  PM_TRY(PM_ALLOC(m->cond, n, "support condition numbers"));
  PM_TRY(PM_ALLOC(m->erec, FPM_EREC * nnz, "interface records"));
  PM_TRY(PM_ALLOC(m->p_area, 3 * n, "point area sums"));
  PM_TRY(PM_ALLOC(m->p_mrel, 9 * n, "point moment sums"));
  PM_TRY(PM_ALLOC(m->mat, n, "point materials"));
  PM_TRY(PM_ALLOC(m->mass, n, "point masses"));
  PM_TRY(PM_ALLOC(m->fixed, 3 * n, "constraint mask"));
  PM_TRY(fpm_gfd_weights(m->dim, n, m->x, m->nbr_ptr, d->nbr, FPM_COND_MAX,
                         m->g, m->cond));
  for (long i = 0; i < n; i++)
    for (long e = m->nbr_ptr[i]; e < m->nbr_ptr[i + 1]; e++)
      for (int a = 0; a < 3; a++) m->gsum[3 * i + a] += m->g[3 * e + a];
  PM_TRY(build_mirror(m));
  PM_TRY(assign_materials(m, s, fpm_domain_body(s)));
  build_interfaces(m);
  if (m->jump == FPM_JUMP_QUADRATIC && m->boundary_penalty > 0)
    PM_TRY(boundary_penalty(m));
  /* Nothing reads a part's interfaces past the records: they go before
   * the fits, the largest arrays, are built. */
  if (part) gm_dual_drop(part, true, false);
  if (m->jump == FPM_JUMP_QUADRATIC) PM_TRY(build_quadratic(m));
  /* A part's share streams its own entries (fpm_model_subset); the part
   * is never stepped. */
  if (!gid) PM_TRY(fpm_stream_build(m));
  if (o->volumetric == FPM_VOLUMETRIC_AVERAGED) PM_TRY(fpm_volumetric_build(m));
  PM_TRY(fpm_build_boundary(m, s, mesh));
  PM_TRY(fpm_contact_create(m, s, &m->contact));
  *out = m;
  m = NULL;
done:
  fpm_model_destroy(m);
  return ret;
}

pm_err fpm_model_create(const pm_scene *s, const fpm_options *o,
                        const gm_mesh *mesh, const gm_dual *d,
                        fpm_model **out) {
  return model_create(s, o, mesh, d, NULL, NULL, out);
}

pm_err fpm_model_create_part(const pm_scene *s, const fpm_options *o,
                             const gm_mesh *mesh, gm_dual *d, const long *gid,
                             fpm_model **out) {
  return model_create(s, o, mesh, d, gid, d, out);
}

pm_err fpm_state_create(const fpm_model *m, fpm_state **out) {
  pm_err ret = PM_SUCCESS;
  fpm_state *st = NULL;
  *out = NULL;
  PM_TRY(PM_ALLOC(st, 1, "FPM state"));
  long n = m->n;
  PM_TRY(PM_ALLOC(st->u, 3 * n, "displacement"));
  PM_TRY(PM_ALLOC(st->v, 3 * n, "velocity"));
  PM_TRY(PM_ALLOC(st->f, 3 * n, "force"));
  PM_TRY(PM_ALLOC(st->H, 9 * n, "displacement gradient"));
  PM_TRY(PM_ALLOC(st->P, 9 * n, "stress"));
  PM_TRY(PM_ALLOC(st->T, 9 * n, "flux tensor"));
  PM_TRY(PM_ALLOC(st->r, 3 * n, "interface force"));
  PM_TRY(PM_ALLOC(st->W, n, "strain energy density"));
  PM_TRY(PM_ALLOC(st->J, n, "volume ratio"));
  if (m->volume_penalty > 0) PM_TRY(PM_ALLOC(st->vphi, n, "volume penalty"));
  if (m->q) {
    PM_TRY(PM_ALLOC(st->theta, 27 * n, "quadratic fits"));
    PM_TRY(PM_ALLOC(st->zq, 3 * n, "penalty forces"));
    PM_TRY(PM_ALLOC(st->Zq, 27 * n, "penalty fit forces"));
  }
  if (m->vavg) {
    PM_TRY(PM_ALLOC(st->Jbar, n, "averaged volume ratio"));
    PM_TRY(PM_ALLOC(st->dUbar, n, "averaged pressure"));
  }
  PM_TRY(PM_ALLOC(st->tf_value, 3 * m->n_tfacets, "tractions"));
  PM_TRY(PM_ALLOC(st->tf_p, m->n_tfacets + 1, "pressures"));
  PM_TRY(PM_ALLOC(st->tf_load, 3 * m->n_tfacets + 1, "tractions"));
  PM_TRY(PM_ALLOC(st->fload, 3 * n, "body and point forces"));
  PM_TRY(PM_ALLOC(st->fload_prev, 3 * n, "body and point forces"));
  PM_TRY(PM_ALLOC(st->bflux, 3 * m->n_dpts, "boundary flux"));
  PM_TRY(PM_ALLOC(st->support_prev,
                  m->n_cdofs + 3 * m->n_dpts + 6 * m->n_tfacets,
                  "support forces"));
  if (m->contact) PM_TRY(fpm_contact_state_init(m->contact, &st->contact));
  *out = st;
  st = NULL;
done:
  fpm_state_destroy(st);
  return ret;
}

void fpm_state_destroy(fpm_state *st) {
  if (!st) return;
  free(st->u);
  free(st->v);
  free(st->f);
  free(st->H);
  free(st->P);
  free(st->T);
  free(st->r);
  free(st->W);
  free(st->J);
  free(st->vphi);
  free(st->theta);
  free(st->zq);
  free(st->Zq);
  free(st->Jbar);
  free(st->dUbar);
  free(st->tf_value);
  free(st->tf_p);
  free(st->tf_load);
  free(st->fload);
  free(st->fload_prev);
  free(st->bflux);
  free(st->support_prev);
  free(st->contact);
  free(st);
}

size_t fpm_state_bytes(const fpm_model *m) {
  return (size_t)m->n * (3 * 6 + 9 * 3 + 2) * sizeof(double) +
         (size_t)(2 * m->n_tfacets + 2 * m->n_dpts) * 3 * sizeof(double) +
         (size_t)m->n_tfacets * sizeof(double) +
         (size_t)m->n_cdofs * sizeof(double) +
         (size_t)fpm_contact_state_size(m->contact) * sizeof(double) +
         (m->q ? (size_t)m->n * 57 * sizeof(double) : 0) +
         (m->vavg ? (size_t)m->n * 2 * sizeof(double) : 0) +
         (m->volume_penalty > 0 ? (size_t)m->n * sizeof(double) : 0);
}

double fpm_stable_dt(const fpm_model *m, long *critical_point) {
  return fpm_stable_dt_of(m, fpm_stable_lambda(m, critical_point));
}

double fpm_stable_lambda(const fpm_model *m, long *critical_point) {
  double lam_max = 0;
  long crit = 0;
  for (long j = 0; j < m->n_own; j++) {
    double c2 = m->mats[m->mat[j]].wave_speed;
    c2 *= c2;
    double C2 = 0;
    for (long e = m->nbr_ptr[j]; e < m->nbr_ptr[j + 1]; e++)
      for (int a = 0; a < 3; a++) C2 += m->g[3 * e + a] * m->g[3 * e + a];
    for (int a = 0; a < 3; a++) C2 += m->gsum[3 * j + a] * m->gsum[3 * j + a];
    double mj = (double)(m->nbr_ptr[j + 1] - m->nbr_ptr[j]);
    double lam = mj * c2 * C2;
    if (lam > lam_max) {
      lam_max = lam;
      crit = j;
    }
  }
  if (critical_point) *critical_point = fpm_point_id(m, crit);
  return lam_max;
}

double fpm_stable_dt_of(const fpm_model *m, double lam_max) {
  double p = m->penalty > 1 ? m->penalty : 1;
  if (m->q && m->boundary_penalty > p) p = m->boundary_penalty;
  /* the stiffening's penalty p_s (3 |j|^2 - (tau h)^2) / h^2, taken at
   * |j| <= h / 4 */
  {
    const double tau2 = m->stiffening_onset * m->stiffening_onset;
    const double ps = (0.1875 - tau2) * m->stiffening;
    if (ps > p) p = ps;
  }
  /* the volume penalty's p_v (ln J)^2, taken at J >= 1/2 */
  if (0.48 * m->volume_penalty > p) p = 0.48 * m->volume_penalty;
  return fpm_contact_stable_dt(m->contact, 2.0 / sqrt(lam_max) / sqrt(p));
}
