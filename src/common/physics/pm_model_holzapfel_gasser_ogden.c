/* pm_model_holzapfel_gasser_ogden: the Holzapfel-Gasser-Ogden model of
 * fibre-reinforced soft tissue with dispersed fibres,
 *   W = mu/2 (Ibar1 - 3) + k1/(2 k2) sum_f [exp(k2 <E_f>^2) - 1]
 *       + K/2 (J - 1)^2,
 *   E_f = kappa (Ibar1 - 3) + (1 - 3 kappa)(Ibar4_f - 1),
 *   Ibar4_f = J^-2/3 a_f . C a_f,
 * <.> the Macaulay bracket: a family bears no load while E_f <= 0 (its
 * stress and stiffness are both zero there).  One or two families per body,
 * unit directions a_f in the reference configuration, kept per point.
 *
 * P = mu/2 D1 + sum_f psi'(E_f) (kappa D1 + (1 - 3 kappa) D4_f) + vol,
 * psi' = k1 E exp(k2 E^2), psi'' = k1 (1 + 2 k2 E^2) exp(k2 E^2), with D1,
 * D4 the derivatives of Ibar1, Ibar4 in F (pm_hyper.h); the tangent adds
 * psi'' (dE) dE for each loaded family.
 *
 * Reference P-wave modulus at F = I: linearized, E_f = (1 - 3 kappa) B0 :
 * eps with B0 = 2 a (x) a - 2/3 I, so a loaded family adds
 * k1 (1 - 3 kappa)^2 B0 (x) B0 to the elasticity tensor.  Its share of the
 * acoustic tensor along n is k1 (1 - 3 kappa)^2 (B0 n) (x) (B0 n), and
 * |B0 n|^2 = 4/3 (a.n)^2 + 4/9 <= 16/9 with equality along the fibre, so
 * the largest wave modulus over directions and polarizations is
 *   M0 = K + 4/3 mu + 16/9 k1 (1 - 3 kappa)^2. */
#include "pm_hyper.h"

enum { HGO_MU = 0, HGO_K1, HGO_K2, HGO_KAPPA, HGO_K };

static const pm_key keys[] = {
    {.name = "shear_modulus",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(HGO_MU),
     .def = "nan",
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .lo = 0,
     .unit = "Pa",
     .doc = "shear modulus mu of the matrix (mu/2 (Ibar1 - 3))"},
    {.name = "k1",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(HGO_K1),
     .def = "nan",
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GE,
     .lo = 0,
     .unit = "Pa",
     .doc = "fibre stiffness k1"},
    {.name = "k2",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(HGO_K2),
     .def = "nan",
     .flags = PM_KEY_REQUIRED,
     .range = PM_RANGE_GT,
     .lo = 0,
     .unit = "",
     .doc = "fibre exponential stiffening k2"},
    {.name = "dispersion",
     .type = PM_KEY_NUMBER,
     .offset = PM_SLOT(HGO_KAPPA),
     .def = "0",
     .range = PM_RANGE_GE | PM_RANGE_LE,
     .lo = 0,
     .hi = 1.0 / 3.0,
     .unit = "",
     .doc = "fibre dispersion kappa: 0 aligned, 1/3 isotropic"},
    PM_HYPER_BULK_KEY(HGO_K),
    {0},
};

/* Checks the keys; the reference figures with the fibres' share (see the
 * header) and room for the fibre directions per point. */
static pm_err init(pm_material *m, const char **key) {
  PM_CALL(pm_hyper_check_keys(m, key));
  const double mu = m->c[HGO_MU], K = m->c[HGO_K], k1 = m->c[HGO_K1];
  const double b = 1 - 3 * m->c[HGO_KAPPA];
  m->state_size = 3 * PM_FIBRES_MAX;
  pm_material_reference(m, mu, K, K + 4.0 / 3.0 * mu + 16.0 / 9.0 * k1 * b * b);
  return PM_SUCCESS;
}

/* The body's unit directions; families it does not give stay zero (and
 * bear nothing). */
static void state_init(const pm_material *m, const pm_material_point *pt,
                       double *state) {
  (void)m;
  for (int f = 0; f < PM_FIBRES_MAX; f++) {
    double *a = state + 3 * f;
    double n = f < pt->n_fibres ? pm_v_norm(pt->fibres[f]) : 0;
    for (int i = 0; i < 3; i++) a[i] = n > 0 ? pt->fibres[f][i] / n : 0;
  }
}

/* A loaded family: E > 0, psi'(E), psi''(E), dIbar4/dF and dE/dF. */
typedef struct {
  double E, dpsi, ddpsi;
  double D4[9], DE[9];
} family;

/* Family f of the state at k, with D1 = dIbar1/dF and Ibar1 - 3; false
 * when it is absent or bears no load. */
static bool fibre(const pm_material *m, const pm_hyper_kin *k, const double *st,
                  int f, double I1m3, const double D1[9], family *fa) {
  const double k1 = m->c[HGO_K1], k2 = m->c[HGO_K2], kappa = m->c[HGO_KAPPA];
  const double *a = st ? st + 3 * f : NULL;
  if (!a || pm_v_dot(a, a) == 0) return false;
  fa->E = kappa * I1m3 + (1 - 3 * kappa) * pm_hyper_ibar4(k, a, fa->D4);
  if (!(fa->E > 0)) return false;
  double ex = exp(k2 * fa->E * fa->E);
  fa->dpsi = k1 * fa->E * ex;
  fa->ddpsi = k1 * (1 + 2 * k2 * fa->E * fa->E) * ex;
  for (int i = 0; i < 9; i++)
    fa->DE[i] = kappa * D1[i] + (1 - 3 * kappa) * fa->D4[i];
  return true;
}

/* P and W of the matrix, of each loaded family and of the volume; st holds
 * the directions (NULL: no fibres). */
static bool stress(const pm_material *m, const double F[9], const double *st,
                   double P[9], double *W, double *Jout) {
  const double mu = m->c[HGO_MU], k1 = m->c[HGO_K1], k2 = m->c[HGO_K2];
  pm_hyper_kin k;
  if (!pm_hyper_kinematics(F, &k, Jout)) return false;
  pm_hyper_vol v = pm_hyper_vol_quadratic(&k, m->c[HGO_K]);
  double I1m3, D1[9], w;
  pm_hyper_ibar12(&k, &I1m3, NULL);
  pm_hyper_ibar1_stress(&k, D1);
  for (int i = 0; i < 9; i++) P[i] = 0.5 * mu * D1[i];
  w = 0.5 * mu * I1m3 + v.U;
  for (int f = 0; f < PM_FIBRES_MAX; f++) {
    family fa;
    if (!fibre(m, &k, st, f, I1m3, D1, &fa)) continue;
    for (int i = 0; i < 9; i++) P[i] += fa.dpsi * fa.DE[i];
    w += k1 / (2 * k2) * expm1(k2 * fa.E * fa.E);
  }
  pm_hyper_vol_stress(&k, v, P);
  if (W) *W = w;
  return pm_hyper_finite(P) && isfinite(w);
}

/* dP = mu/2 dD1 + sum over loaded families of psi'' (DE : dF) DE +
 * psi' (kappa dD1 + (1 - 3 kappa) dD4) + d(U' cof F). */
static bool tangent(const pm_material *m, const double F[9], const double *st,
                    const double dF[9], double dP[9]) {
  const double mu = m->c[HGO_MU], kappa = m->c[HGO_KAPPA];
  pm_hyper_kin k;
  pm_hyper_dir d;
  if (!pm_hyper_kinematics(F, &k, NULL)) return false;
  pm_hyper_direction(&k, dF, &d);
  double I1m3, D1[9], dD1[9];
  pm_hyper_ibar12(&k, &I1m3, NULL);
  pm_hyper_ibar1_stress(&k, D1);
  pm_hyper_ibar1_tangent(&k, &d, D1, dD1);
  for (int i = 0; i < 9; i++) dP[i] = 0.5 * mu * dD1[i];
  for (int f = 0; f < PM_FIBRES_MAX; f++) {
    family fa;
    if (!fibre(m, &k, st, f, I1m3, D1, &fa)) continue;
    double dD4[9];
    pm_hyper_ibar4_tangent(&k, &d, st + 3 * f, fa.D4, dD4);
    double dE = pm_t_ddot(fa.DE, dF);
    for (int i = 0; i < 9; i++)
      dP[i] += fa.ddpsi * dE * fa.DE[i] +
               fa.dpsi * (kappa * dD1[i] + (1 - 3 * kappa) * dD4[i]);
  }
  pm_hyper_vol_tangent(&k, &d, pm_hyper_vol_quadratic(&k, m->c[HGO_K]), dP);
  return true;
}

/* U(J) of the split W = W_iso + U(J). */
static void volumetric(const pm_material *m, double J, double U[3]) {
  pm_hyper_u_quadratic(m->c[HGO_K], J, U);
}

const pm_model pm_model_holzapfel_gasser_ogden = {
    .name = "holzapfel-gasser-ogden",
    .formula = "W = mu/2 (Ibar1 - 3) + k1/(2 k2) sum_f (exp(k2 <E_f>^2) - 1) "
               "+ K/2 (J - 1)^2, E_f = kappa (Ibar1 - 3) + (1 - 3 kappa) "
               "(Ibar4_f - 1)",
    .kind = PM_MATERIAL_SOLID,
    .keys = keys,
    .key_sets = "shear_modulus, k1, k2, bulk_modulus and optionally "
                "dispersion; fibre directions (1 or 2) from the body",
    .fibres_min = 1,
    .fibres_max = PM_FIBRES_MAX,
    .init = init,
    .stress = stress,
    .tangent = tangent,
    .volumetric = volumetric,
    .state_init = state_init,
};
