/* pm_material: the table of constitutive models, materials built from code,
 * and what every model gets for free from its stress (energy alone, PK2,
 * Cauchy stress, uniaxial states). */
#include "pm_material.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pm_models.h"

static const pm_model *const table[] = {
    &pm_model_neo_hookean,
    &pm_model_neo_hookean_log,
    &pm_model_mooney_rivlin,
    &pm_model_ogden,
    &pm_model_holzapfel_gasser_ogden,
    &pm_model_linear_elastic,
    &pm_model_fluid,
};
#define N_MODELS ((int)(sizeof table / sizeof *table))

int pm_model_count(void) { return N_MODELS; }

const pm_model *pm_model_at(int k) {
  return k >= 0 && k < N_MODELS ? table[k] : NULL;
}

const pm_model *pm_model_find(const char *name) {
  for (int k = 0; name && k < N_MODELS; k++)
    if (strcmp(table[k]->name, name) == 0) return table[k];
  return NULL;
}

void pm_model_names(char *buf, size_t size) {
  size_t used = 0;
  if (size) buf[0] = '\0';
  for (int k = 0; k < N_MODELS && used < size; k++)
    used += (size_t)snprintf(buf + used, size - used, "%s%s", k ? ", " : "",
                             table[k]->name);
}

/* ---- building from code ------------------------------------------------- */

/* The key at a dotted path of table keys, with the offset of its value. */
static const pm_key *key_at(const pm_key *keys, const char *path,
                            size_t *offset) {
  char seg[64];
  *offset = 0;
  for (const char *p = path;;) {
    size_t len = strcspn(p, ".");
    if (len == 0 || len >= sizeof seg) return NULL;
    memcpy(seg, p, len);
    seg[len] = '\0';
    const pm_key *k = pm_key_find(keys, seg);
    if (!k) return NULL;
    *offset += k->offset;
    if (p[len] == '\0') return k;
    if (k->type != PM_KEY_MAPPING) return NULL;
    keys = k->keys;
    p += len + 1;
  }
}

/* Defaults of the number keys of a table (recursively), NaN without one. */
static void set_defaults(pm_material *m, const pm_key *keys, size_t base) {
  for (const pm_key *k = keys; k && k->type != PM_KEY_END; k++) {
    char *at = (char *)m + base + k->offset;
    if (k->type == PM_KEY_NUMBER)
      *(double *)at = k->def ? strtod(k->def, NULL) : NAN;
    else if (k->type == PM_KEY_NUMBERS)
      for (int i = 0; i < k->max_count; i++) ((double *)at)[i] = NAN;
    else if (k->type == PM_KEY_MAPPING)
      set_defaults(m, k->keys, base + k->offset);
  }
}

pm_err pm_material_begin(pm_material *m, const char *model, double density) {
  const pm_model *md = pm_model_find(model);
  char names[256];
  pm_model_names(names, sizeof names);
  PM_CHECK(md, PM_ERR_ARG, "unknown material model %s (expected one of %s)",
           model ? model : "(null)", names);
  memset(m, 0, sizeof *m);
  m->model = md;
  m->density = density;
  set_defaults(m, md->keys, 0);
  return PM_SUCCESS;
}

pm_err pm_material_set(pm_material *m, const char *key, double value) {
  size_t off;
  const pm_key *k = key_at(m->model->keys, key, &off);
  PM_CHECK(k && (k->type == PM_KEY_NUMBER || k->type == PM_KEY_ENUM),
           PM_ERR_ARG, "model %s has no number key %s", m->model->name, key);
  if (k->type == PM_KEY_ENUM) {
    *(int *)((char *)m + off) = (int)value;
    return PM_SUCCESS;
  }
  if (!pm_key_in_range(k, value)) {
    char what[128];
    pm_key_describe(k, what, sizeof what);
    return PM_ERROR(PM_ERR_ARG, "%s must be %s (got %g)", key, what, value);
  }
  *(double *)((char *)m + off) = value;
  return PM_SUCCESS;
}

pm_err pm_material_set_list(pm_material *m, const char *key, int n,
                            const double *values) {
  size_t off;
  const pm_key *k = key_at(m->model->keys, key, &off);
  PM_CHECK(k && k->type == PM_KEY_NUMBERS, PM_ERR_ARG,
           "model %s has no list key %s", m->model->name, key);
  PM_CHECK(n >= k->min_count && n <= k->max_count, PM_ERR_ARG,
           "%s takes %d to %d numbers (got %d)", key, k->min_count,
           k->max_count, n);
  for (int i = 0; i < n; i++) ((double *)((char *)m + off))[i] = values[i];
  *(int *)((char *)m + (off - k->offset) + k->count_offset) = n;
  return PM_SUCCESS;
}

pm_err pm_material_finish(pm_material *m) {
  const char *key = NULL;
  PM_CHECK(m->density > 0 && isfinite(m->density), PM_ERR_ARG,
           "density must be > 0 (got %g)", m->density);
  pm_err e = m->model->init(m, &key);
  if (e != PM_SUCCESS && key) {
    char msg[512];
    snprintf(msg, sizeof msg, "%s", pm_error_message());
    return PM_ERROR(e, "%s: %s", key, msg);
  }
  return e;
}

pm_err pm_material_elastic(pm_material *m, const char *model, double density,
                           double youngs, double poisson) {
  PM_CALL(pm_material_begin(m, model, density));
  PM_CALL(pm_material_set(m, "youngs_modulus", youngs));
  PM_CALL(pm_material_set(m, "poisson_ratio", poisson));
  return pm_material_finish(m);
}

/* ---- what follows from the stress -------------------------------------- */

double pm_material_energy(const pm_material *m, const double F[9],
                          const double *state) {
  double P[9], W;
  if (!pm_material_stress(m, F, state, P, &W, NULL)) return NAN;
  return W;
}

bool pm_material_pk2(const pm_material *m, const double F[9],
                     const double *state, double S[9]) {
  double P[9], Finv[9];
  if (!pm_material_stress(m, F, state, P, NULL, NULL)) return false;
  if (!(pm_t_inverse(F, Finv) > 0)) return false;
  pm_t_mul(Finv, P, S);
  return true;
}

bool pm_material_cauchy(const pm_material *m, const double F[9],
                        const double *state, double sig[9]) {
  double P[9], J;
  if (!pm_material_stress(m, F, state, P, NULL, &J)) return false;
  /* sigma = P F^T / J */
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      sig[3 * i + j] = (P[3 * i] * F[3 * j] + P[3 * i + 1] * F[3 * j + 1] +
                        P[3 * i + 2] * F[3 * j + 2]) /
                       J;
  return true;
}

/* P_xx and P_yy of F = diag(s[0], s[1], lambda). */
static bool lateral_stress(const pm_material *m, const double *state,
                           const double s[2], double lambda, double r[2]) {
  double F[9] = {s[0], 0, 0, 0, s[1], 0, 0, 0, lambda}, P[9];
  if (!pm_material_stress(m, F, state, P, NULL, NULL)) return false;
  r[0] = P[0];
  r[1] = P[4];
  return true;
}

pm_err pm_material_uniaxial(const pm_material *m, const double *state,
                            double lambda, double lateral[2]) {
  PM_CHECK(lambda > 0, PM_ERR_ARG, "axial stretch must be > 0 (got %g)",
           lambda);
  PM_CHECK(!pm_material_is_fluid(m), PM_ERR_ARG,
           "a fluid has no uniaxial stress state");
  /* Newton's method on (P_xx, P_yy) = 0 with a central-difference
   * Jacobian, from the incompressible guess, steps limited to halve. */
  double s[2] = {1 / sqrt(lambda), 1 / sqrt(lambda)};
  for (int it = 0; it < 100; it++) {
    double r[2], Jm[2][2];
    if (!lateral_stress(m, state, s, lambda, r)) break;
    bool ok = true;
    for (int j = 0; j < 2 && ok; j++) {
      double sp[2] = {s[0], s[1]}, sm[2] = {s[0], s[1]}, rp[2] = {0, 0},
             rm[2] = {0, 0};
      double ds = 1e-7 * s[j];
      sp[j] += ds;
      sm[j] -= ds;
      ok = lateral_stress(m, state, sp, lambda, rp) &&
           lateral_stress(m, state, sm, lambda, rm);
      for (int i = 0; i < 2; i++) Jm[i][j] = (rp[i] - rm[i]) / (2 * ds);
    }
    double det = Jm[0][0] * Jm[1][1] - Jm[0][1] * Jm[1][0];
    if (!ok || !(fabs(det) > 0)) break;
    double step[2] = {-(Jm[1][1] * r[0] - Jm[0][1] * r[1]) / det,
                      -(-Jm[1][0] * r[0] + Jm[0][0] * r[1]) / det};
    double big = 0;
    for (int i = 0; i < 2; i++) {
      if (step[i] < -0.5 * s[i]) step[i] = -0.5 * s[i];
      s[i] += step[i];
      big = fmax(big, fabs(step[i]) / s[i]);
    }
    if (big <= 1e-15) {
      lateral[0] = s[0];
      lateral[1] = s[1];
      return PM_SUCCESS;
    }
  }
  return PM_ERROR(PM_ERR_NOT_CONVERGED,
                  "no lateral stretch in uniaxial stress for axial stretch %g "
                  "(model %s)",
                  lambda, m->model->name);
}
