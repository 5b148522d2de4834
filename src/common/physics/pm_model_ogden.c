/* pm_model_ogden: the compressible Ogden model of N = 1..8 terms,
 *   W = sum_p mu_p/alpha_p (lb1^a_p + lb2^a_p + lb3^a_p - 3) + K/2 (J-1)^2,
 * lb_i = J^-1/3 lambda_i, from the principal stretches of C.
 *
 * Stress, in the eigenbasis N_i of C (c_i = lambda_i^2 = 1 + e_i, e_i the
 * eigenvalues of C - I = H + H^T + H^T H), with x_i = ln lb_i =
 * log1p(e_i)/2 - sum_k log1p(e_k)/6:
 *   tau_i = sum_p mu_p (lb_i^a - mean_k lb_k^a),  S = sum_i tau_i/c_i N_i N_i,
 * P = F S + K (J - 1) cof F, with lb^a - 1 = expm1(a x) so that P and W keep
 * their relative accuracy as F -> I.
 *
 * Tangent: the same S written with matrix powers,
 *   S_iso = sum_p mu_p J^-a/3 (C^s - T/3 C^-1),  s = a/2 - 1, T = tr C^a/2,
 * differentiated along dC = dF^T F + F^T dF: in the eigenbasis,
 *   dS_ij = sum_p mu_p J^-a/3 [ f_s(c_i, c_j) dC_ij + T/3 dC_ij/(c_i c_j)
 *          - d_ij (a/6) ((C^-1 : dC) M_i + (C^s : dC)/c_i) ],
 * M_i = c_i^s - T/(3 c_i), f_s the divided difference of c^s
 * (Daleckii-Krein), formed without cancellation at equal eigenvalues;
 * dP = dF S + F dS + d(K (J - 1) cof F). */
#include "pm_eigen.h"
#include "pm_hyper.h"

#define OG_TERMS 8
enum { OG_MU = 0, OG_ALPHA = OG_TERMS, OG_K = 2 * OG_TERMS };
enum { OG_N_MU = 0, OG_N_ALPHA };

static const pm_key keys[] = {
    {.name = "mu",
     .type = PM_KEY_NUMBERS,
     .offset = PM_SLOT(OG_MU),
     .flags = PM_KEY_REQUIRED,
     .count_offset = PM_COUNT(OG_N_MU),
     .min_count = 1,
     .max_count = OG_TERMS,
     .unit = "Pa",
     .doc = "mu_p of each term (mu_p alpha_p > 0; shear modulus "
            "sum mu_p alpha_p / 2)"},
    {.name = "alpha",
     .type = PM_KEY_NUMBERS,
     .offset = PM_SLOT(OG_ALPHA),
     .flags = PM_KEY_REQUIRED,
     .count_offset = PM_COUNT(OG_N_ALPHA),
     .min_count = 1,
     .max_count = OG_TERMS,
     .unit = "",
     .doc = "exponent alpha_p of each term (as many as mu)"},
    PM_HYPER_BULK_KEY(OG_K),
    {0},
};

/* Key paths of the terms, for messages (0-based, as the scene's lists). */
static const char *const mu_path[OG_TERMS] = {"mu.0", "mu.1", "mu.2", "mu.3",
                                              "mu.4", "mu.5", "mu.6", "mu.7"};
static const char *const alpha_path[OG_TERMS] = {
    "alpha.0", "alpha.1", "alpha.2", "alpha.3",
    "alpha.4", "alpha.5", "alpha.6", "alpha.7"};

/* Checks the keys, the lists' lengths and each term's mu_p alpha_p > 0;
 * the shear modulus is sum mu_p alpha_p / 2. */
static pm_err init(pm_material *m, const char **key) {
  PM_CALL(pm_hyper_check_keys(m, key));
  const int n = m->n[OG_N_MU];
  if (m->n[OG_N_ALPHA] != n) {
    *key = "alpha";
    return PM_ERROR(PM_ERR_ARG, "expected as many alpha as mu (%d), got %d", n,
                    m->n[OG_N_ALPHA]);
  }
  double mu0 = 0;
  for (int p = 0; p < n; p++) {
    const double mu = m->c[OG_MU + p], a = m->c[OG_ALPHA + p];
    if (!(isfinite(mu) && isfinite(a) && mu * a > 0)) {
      *key = a == 0 || !isfinite(a) ? alpha_path[p] : mu_path[p];
      return PM_ERROR(PM_ERR_ARG,
                      "expected mu_p alpha_p > 0 for every term (Ogden's "
                      "stability condition), got mu = %g and alpha = %g in "
                      "term %d",
                      mu, a, p);
    }
    mu0 += 0.5 * mu * a;
  }
  const double K = m->c[OG_K];
  pm_material_reference(m, mu0, K, K + 4.0 / 3.0 * mu0);
  return PM_SUCCESS;
}

/* The principal frame of C and the isochoric log stretches. */
typedef struct {
  double e[3]; /* eigenvalues of C - I */
  double V[9]; /* eigenvectors N_i as columns */
  double x[3]; /* ln lb_i */
} principal;

/* Eigen-decomposition of C - I = H + H^T + H^T H (no 1 + small to lose)
 * and ln lb_i = log1p(e_i)/2 - sum_k log1p(e_k)/6.  False when C is not
 * positive definite in floating point. */
static bool principal_stretches(const pm_hyper_kin *k, principal *pr) {
  double E[9];
  pm_t_tmul(k->H, k->H, E);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      E[3 * i + j] += k->H[3 * i + j] + k->H[3 * j + i];
  if (!pm_eigen_sym3(E, pr->e, pr->V)) return false;
  double l[3], mean = 0;
  for (int i = 0; i < 3; i++) {
    if (!(pr->e[i] > -1)) return false;
    l[i] = 0.5 * log1p(pr->e[i]);
    mean += l[i] / 3;
  }
  for (int i = 0; i < 3; i++) pr->x[i] = l[i] - mean;
  return true;
}

/* S = V diag(s) V^T. */
static void from_principal(const double V[9], const double s[3], double S[9]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      S[3 * i + j] = V[3 * i] * s[0] * V[3 * j] +
                     V[3 * i + 1] * s[1] * V[3 * j + 1] +
                     V[3 * i + 2] * s[2] * V[3 * j + 2];
}

/* The isochoric PK2 stress S_iso (and its energy when W is not NULL). */
static void iso_pk2(const pm_material *m, const principal *pr, double S[9],
                    double *W) {
  double tau[3] = {0, 0, 0}, w = 0;
  for (int p = 0; p < m->n[OG_N_MU]; p++) {
    const double mu = m->c[OG_MU + p], a = m->c[OG_ALPHA + p];
    double t[3], mean = 0; /* lb_i^a - 1 */
    for (int i = 0; i < 3; i++) {
      t[i] = expm1(a * pr->x[i]);
      mean += t[i] / 3;
      /* sum_i (lb_i^a - 1) = sum_i (e^ax_i - 1 - a x_i): sum_i x_i = 0 */
      w += mu / a * pm_hyper_expm1mx(a * pr->x[i]);
    }
    for (int i = 0; i < 3; i++) tau[i] += mu * (t[i] - mean);
  }
  double s[3];
  for (int i = 0; i < 3; i++) s[i] = tau[i] / (1 + pr->e[i]);
  from_principal(pr->V, s, S);
  if (W) *W = w;
}

/* P = F S_iso + K (J - 1) cof F (see the header). */
static bool stress(const pm_material *m, const double F[9], const double *st,
                   double P[9], double *W, double *Jout) {
  (void)st;
  pm_hyper_kin k;
  principal pr;
  if (!pm_hyper_kinematics(F, &k, Jout) || !principal_stretches(&k, &pr))
    return false;
  pm_hyper_vol v = pm_hyper_vol_quadratic(&k, m->c[OG_K]);
  double S[9], w;
  iso_pk2(m, &pr, S, &w);
  pm_t_mul(F, S, P);
  pm_hyper_vol_stress(&k, v, P);
  if (W) *W = w + v.U;
  return pm_hyper_finite(P) && isfinite(w);
}

/* (c_j^s - c_i^s) / (c_j - c_i) for c = 1 + e, as c_i^(s-1) expm1(s log1p
 * d) / d with d = (c_j - c_i) / c_i: no cancellation as c_j -> c_i, and
 * s c^(s-1) when equal. */
static double power_divided_difference(double s, double ei, double ej) {
  double base = exp((s - 1) * log1p(ei));
  if (ei == ej) return s * base;
  double d = (ej - ei) / (1 + ei);
  return base * expm1(s * log1p(d)) / d;
}

/* dP = dF S + F dS with dS from the matrix-power form (see the header). */
static bool tangent(const pm_material *m, const double F[9], const double *st,
                    const double dF[9], double dP[9]) {
  (void)st;
  pm_hyper_kin k;
  pm_hyper_dir d;
  principal pr;
  if (!pm_hyper_kinematics(F, &k, NULL) || !principal_stretches(&k, &pr))
    return false;
  pm_hyper_direction(&k, dF, &d);
  /* dC in the eigenbasis: V^T (dF^T F + F^T dF) V */
  double dC[9], t[9], dCt[9], c[3];
  pm_t_tmul(dF, F, t);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) dC[3 * i + j] = t[3 * i + j] + t[3 * j + i];
  pm_t_tmul(pr.V, dC, t);
  pm_t_mul(t, pr.V, dCt);
  double y = 0; /* C^-1 : dC */
  for (int i = 0; i < 3; i++) {
    c[i] = 1 + pr.e[i];
    y += dCt[4 * i] / c[i];
  }
  double dSt[9] = {0};
  for (int p = 0; p < m->n[OG_N_MU]; p++) {
    const double mu = m->c[OG_MU + p], a = m->c[OG_ALPHA + p], s = a / 2 - 1;
    const double Jp = exp(-a / 3 * k.lnJ);
    double cs[3], T = 0, z = 0; /* c_i^s, tr C^a/2, C^s : dC */
    for (int i = 0; i < 3; i++) {
      cs[i] = exp(s * log1p(pr.e[i]));
      T += cs[i] * c[i];
      z += cs[i] * dCt[4 * i];
    }
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        double v = (power_divided_difference(s, pr.e[i], pr.e[j]) +
                    T / (3 * c[i] * c[j])) *
                   dCt[3 * i + j];
        if (i == j) v -= a / 6 * (y * (cs[i] - T / (3 * c[i])) + z / c[i]);
        dSt[3 * i + j] += mu * Jp * v;
      }
  }
  double S[9], dS[9];
  pm_t_mul(pr.V, dSt, t);
  pm_t_mult(t, pr.V, dS);
  iso_pk2(m, &pr, S, NULL);
  pm_t_mul(dF, S, dP);
  pm_t_mul(F, dS, t);
  for (int i = 0; i < 9; i++) dP[i] += t[i];
  pm_hyper_vol_tangent(&k, &d, pm_hyper_vol_quadratic(&k, m->c[OG_K]), dP);
  return true;
}

/* U(J) of the split W = W_iso + U(J). */
static void volumetric(const pm_material *m, double J, double U[3]) {
  pm_hyper_u_quadratic(m->c[OG_K], J, U);
}

const pm_model pm_model_ogden = {
    .name = "ogden",
    .formula = "W = sum_p mu_p/alpha_p (lb1^a_p + lb2^a_p + lb3^a_p - 3) + "
               "K/2 (J - 1)^2, lb_i = J^-1/3 lambda_i",
    .kind = PM_MATERIAL_SOLID,
    .keys = keys,
    .key_sets = "mu and alpha of the same length (1 to 8 terms), and "
                "bulk_modulus",
    .init = init,
    .stress = stress,
    .tangent = tangent,
    .volumetric = volumetric,
};
