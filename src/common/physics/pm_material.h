/* pm_material: the table of constitutive models shared by every backend.
 * A material is an entry of the table (its model) and the constants the
 * model derives from the scene's parameters.  Backends call the model
 * (stress, tangent, energy, optional rate form, per-point state) and read
 * only the reference figures every model gives (shear, bulk, Young's and
 * P-wave moduli, wave speed); never a model's own constants. */
#ifndef PM_MATERIAL_H
#define PM_MATERIAL_H

#include <math.h>
#include <stdbool.h>

#include "pm_error.h"
#include "pm_fluid.h"
#include "pm_keys.h"
#include "pm_tensor.h"

typedef enum {
  PM_MATERIAL_SOLID = 0, /* stress from the deformation (P(F), or a rate) */
  PM_MATERIAL_FLUID      /* pressure from an equation of state (pm_fluid) */
} pm_material_kind;

/* Storage for a model's parameters and derived constants (layout private
 * to the model: its keys point into c and n). */
#define PM_MATERIAL_CONSTANTS 48
#define PM_MATERIAL_COUNTS 4
/* Largest per-point state of any model, doubles. */
#define PM_MATERIAL_STATE_MAX 6
/* Fibre families a body may give (Holzapfel-Gasser-Ogden). */
#define PM_FIBRES_MAX 2

typedef struct pm_model pm_model;

typedef struct pm_material {
  const pm_model *model;
  double density; /* reference density rho_0, kg/m^3 */
  /* Reference figures at F = I, derived by every model's init: */
  double shear_modulus;  /* mu_0, Pa */
  double bulk_modulus;   /* K_0, Pa */
  double youngs_modulus; /* E_0 = 9 K_0 mu_0 / (3 K_0 + mu_0), Pa */
  double poisson_ratio;  /* (3 K_0 - 2 mu_0) / (2 (3 K_0 + mu_0)) */
  double wave_modulus;   /* P-wave modulus M_0 (lambda + 2 mu, with the
                            fibres' share), Pa: sets stable steps */
  double wave_speed;     /* sqrt(M_0 / rho_0), m/s */
  int state_size;        /* doubles of per-point state (0: none) */
  /* The model's parameters and derived constants. */
  double c[PM_MATERIAL_CONSTANTS];
  int n[PM_MATERIAL_COUNTS];
  pm_fluid fluid; /* fluids: equation of state and viscosities */
} pm_material;

/* What a body gives the points it holds, for models with per-point state:
 * fibre directions (unit vectors in the reference configuration). */
typedef struct {
  int n_fibres;
  double fibres[PM_FIBRES_MAX][3];
} pm_material_point;

/* An entry of the table.  Solid entries give stress and tangent (and W);
 * fluid entries give none of those (pm_fluid has the EOS). */
struct pm_model {
  const char *name;    /* scene name: "neo-hookean" */
  const char *formula; /* one line: "W = mu/2 (Ibar1 - 3) + K/2 (J-1)^2" */
  pm_material_kind kind;
  const pm_key *keys;         /* its parameters, targets in pm_material */
  const char *key_sets;       /* how they combine, for messages ("youngs_modulus
                                 and poisson_ratio, or shear_modulus and
                                 bulk_modulus"); NULL: every key it has */
  int fibres_min, fibres_max; /* fibre families a body must give */
  /* Check the parameters read into m (absent optional ones are NaN) and
   * derive the constants and the reference figures.  On failure returns
   * PM_ERR_ARG with a message of the form "expected ..., got ..." and
   * points *key at the offending key's path within the material
   * ("poisson_ratio", "eos.p_inf", "mu.1"), or NULL when no one key is at
   * fault (a missing key set). */
  pm_err (*init)(pm_material *m, const char **key);
  /* P(F) (row-major), and W and J when non-NULL.  False when J <= 0 or
   * the result is not finite (P unspecified). */
  bool (*stress)(const pm_material *m, const double F[9], const double *state,
                 double P[9], double *W, double *J);
  /* dP = A : dF, A = d2W/dF dF (major symmetry).  False when J <= 0. */
  bool (*tangent)(const pm_material *m, const double F[9], const double *state,
                  const double dF[9], double dP[9]);
  /* Optional, for models split as W = W_iso(J^-1/3 F) + U(J): U(J), U'(J)
   * and U''(J) into U[0..2] (J > 0).  NULL: the model has no such split
   * (averaged-volume treatments refuse it). */
  void (*volumetric)(const pm_material *m, double J, double U[3]);
  /* Optional rate form for updated-Lagrangian backends: the Cauchy stress
   * advanced over dt by the rate of deformation D and the spin W
   * (objective, Jaumann).  NULL: the backend uses P(F). */
  void (*rate)(const pm_material *m, const double D[9], const double W[9],
               double dt, double sigma[9]);
  /* Optional: per-point state from the body (state_size doubles). */
  void (*state_init)(const pm_material *m, const pm_material_point *pt,
                     double *state);
};

/* ---- the table ---------------------------------------------------------- */

/* Number of models, the k-th, and lookup by scene name (NULL if none). */
int pm_model_count(void);
const pm_model *pm_model_at(int k);
const pm_model *pm_model_find(const char *name);
/* Scene names of the models joined by ", " (for messages). */
void pm_model_names(char *buf, size_t size);

/* ---- building a material from code (scenes use the key reader) ---------- */

/* Start a material of the named model: every key at its default (NaN when
 * it has none).  Fails with PM_ERR_ARG for an unknown model. */
pm_err pm_material_begin(pm_material *m, const char *model, double density);
/* Set a number key (a dotted path inside mappings: "eos.gamma"; ENUM keys
 * take their value) or a list key.  PM_ERR_ARG for an unknown key. */
pm_err pm_material_set(pm_material *m, const char *key, double value);
pm_err pm_material_set_list(pm_material *m, const char *key, int n,
                            const double *values);
/* Check and derive (the model's init). */
pm_err pm_material_finish(pm_material *m);
/* The classic form: a model taking youngs_modulus and poisson_ratio
 * (neo-hookean, neo-hookean-log, linear-elastic) from E and nu. */
pm_err pm_material_elastic(pm_material *m, const char *model, double density,
                           double youngs, double poisson);

/* ---- evaluation (inline: one indirect call) ----------------------------- */

static inline bool pm_material_is_fluid(const pm_material *m) {
  return m->model->kind == PM_MATERIAL_FLUID;
}

static inline bool pm_material_stress(const pm_material *m, const double F[9],
                                      const double *state, double P[9],
                                      double *W, double *J) {
  return m->model->stress(m, F, state, P, W, J);
}

static inline bool pm_material_tangent(const pm_material *m, const double F[9],
                                       const double *state, const double dF[9],
                                       double dP[9]) {
  return m->model->tangent(m, F, state, dF, dP);
}

/* Whether the model splits off a volumetric energy U(J) (pm_model.volumetric),
 * and U, U', U'' at J > 0 (only for a model that has it). */
static inline bool pm_material_has_volumetric(const pm_material *m) {
  return m->model->volumetric != NULL;
}

static inline void pm_material_volumetric(const pm_material *m, double J,
                                          double U[3]) {
  m->model->volumetric(m, J, U);
}

/* W(F) alone; NaN when J <= 0. */
double pm_material_energy(const pm_material *m, const double F[9],
                          const double *state);
/* Second Piola-Kirchhoff stress S = F^-1 P; false when J <= 0. */
bool pm_material_pk2(const pm_material *m, const double F[9],
                     const double *state, double S[9]);
/* Cauchy stress sigma = P F^T / J; false when J <= 0. */
bool pm_material_cauchy(const pm_material *m, const double F[9],
                        const double *state, double sigma[9]);

/* Uniaxial stress along z at axial stretch lambda: the lateral stretches
 * (s_x, s_y) of F = diag(s_x, s_y, lambda) with P_xx = P_yy = 0 (equal for
 * isotropic models; fibres in the coordinate planes keep F diagonal), by
 * Newton's method.  PM_ERR_NOT_CONVERGED when no root is found. */
pm_err pm_material_uniaxial(const pm_material *m, const double *state,
                            double lambda, double lateral[2]);

#endif
