/* Quality factor against temperature: the laws of qlaw.h. */
#include "plant/qlaw.h"

#include <math.h>
#include <stddef.h>

double qlaw_air_viscosity_rel(double temp_k)
{
  /* Sutherland, U.S. Standard Atmosphere 1976 eq. (51): mu = beta T^1.5 / (T + S); the
   * constant beta cancels in the ratio */
  const double s = QLAW_AIR_SUTHERLAND_K, t0 = 298.15;
  return pow(temp_k / t0, 1.5) * (t0 + s) / (temp_k + s);
}

double qlaw_si_expansion_per_k(double temp_k)
{
  /* Okada & Tokumaru (1984), 120..1500 K */
  return (3.725 * (1.0 - exp(-5.88e-3 * (temp_k - 124.0))) + 5.548e-4 * temp_k) * 1e-6;
}

double qlaw_si_conductivity_rel(double temp_k) { return pow(temp_k / 300.0, -1.3); }

/* temp_k held to [lo, hi]; *out set when it had to move */
static double held(double temp_k, double lo, double hi, int *out)
{
  if (!isfinite(temp_k)) {
    *out = 1;
    return 0.5 * (lo + hi);
  }
  if (temp_k < lo) {
    *out = 1;
    return lo;
  }
  if (temp_k > hi) {
    *out = 1;
    return hi;
  }
  return temp_k;
}

double qlaw_factor(int law, double temp_k, double temp_ref_k, double wn_ratio, int *outside)
{
  int out = 0;
  double f = 1.0;
  if (law == QLAW_GAS) {
    const double t = held(temp_k, QLAW_GAS_T_MIN_K, QLAW_GAS_T_MAX_K, &out);
    int dummy = 0;
    const double t0 = held(temp_ref_k, QLAW_GAS_T_MIN_K, QLAW_GAS_T_MAX_K, &dummy);
    /* c ~ mu, Q = m wn / c */
    f = wn_ratio * qlaw_air_viscosity_rel(t0) / qlaw_air_viscosity_rel(t);
  } else if (law == QLAW_TED) {
    const double t = held(temp_k, QLAW_TED_T_MIN_K, QLAW_TED_T_MAX_K, &out);
    int dummy = 0;
    const double t0 = held(temp_ref_k, QLAW_TED_T_MIN_K, QLAW_TED_T_MAX_K, &dummy);
    /* Zener below the relaxation peak: Q ~ kappa / (E w alpha^2 T), E w ~ wn^3 */
    const double a = qlaw_si_expansion_per_k(t0) / qlaw_si_expansion_per_k(t);
    f = (qlaw_si_conductivity_rel(t) / qlaw_si_conductivity_rel(t0)) * a * a * (t0 / t) /
        (wn_ratio * wn_ratio * wn_ratio);
  }
  if (outside != NULL) *outside = out;
  return f;
}
