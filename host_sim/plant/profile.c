#include "plant/profile.h"

#include <math.h>
#include <stddef.h>
#include <string.h>
#include "plant/plant_const.h"

static const double kTwoPi = PLANT_TWO_PI;
static const double kMaxAbs = 1e9;

static const char *const kKindNames[PROFILE_NKINDS] = {"const", "steps", "sine", "ramp",
                                                       "heat_cool"};

const char *profile_kind_name(profile_kind_t kind)
{
  /* unsigned: also rejects negatives, and stays meaningful where the enum is a short
   * unsigned type (arm-none-eabi) */
  if ((unsigned)kind >= (unsigned)PROFILE_NKINDS) return "?";
  return kKindNames[kind];
}

int profile_kind_from_name(const char *name)
{
  if (name == NULL) return -1;
  for (int i = 0; i < PROFILE_NKINDS; i++)
    if (strcmp(name, kKindNames[i]) == 0) return i;
  return -1;
}

void profile_const(profile_t *p, double value)
{
  memset(p, 0, sizeof(*p));
  p->kind = PROFILE_CONST;
  p->value = value;
  p->n_steps = 1;
  p->step_s[0] = 1.0;
  p->step_value[0] = value;
  p->tau_heat_s = 1.0;
  p->tau_cool_s = 1.0;
}

void profile_sine(profile_t *p, double offset, double amp, double freq_hz, double phase_rad)
{
  profile_const(p, offset);
  p->kind = PROFILE_SINE;
  p->amp = amp;
  p->freq_hz = freq_hz;
  p->phase_rad = phase_rad;
}

void profile_ramp(profile_t *p, double start, double slope_per_s, double t_start_s, double t_end_s)
{
  profile_const(p, start);
  p->kind = PROFILE_RAMP;
  p->slope_per_s = slope_per_s;
  p->t_start_s = t_start_s;
  p->t_end_s = t_end_s;
}

void profile_heat_cool(profile_t *p, double base, double hot, double t_start_s, double heat_s,
                       double tau_heat_s, double tau_cool_s)
{
  profile_const(p, base);
  p->kind = PROFILE_HEAT_COOL;
  p->hot_value = hot;
  p->t_start_s = t_start_s;
  p->heat_s = heat_s;
  p->tau_heat_s = tau_heat_s;
  p->tau_cool_s = tau_cool_s;
}

int profile_steps(profile_t *p, int n, const double *dur_s, const double *value, double edge_s,
                  int repeat)
{
  if (p == NULL || dur_s == NULL || value == NULL || n < 1 || n > PROFILE_MAX_STEPS) return -1;
  profile_t tmp;
  profile_const(&tmp, value[0]);
  tmp.kind = PROFILE_STEPS;
  tmp.n_steps = n;
  for (int i = 0; i < n; i++) {
    tmp.step_s[i] = dur_s[i];
    tmp.step_value[i] = value[i];
  }
  tmp.edge_s = edge_s;
  tmp.repeat = repeat;
  if (profile_check(&tmp, NULL) != 0) return -1;
  *p = tmp;
  return 0;
}

static int fin(double v) { return isfinite(v) && fabs(v) <= kMaxAbs; }

int profile_check(const profile_t *p, const char **key)
{
  static const char *const dur_keys[PROFILE_MAX_STEPS] = {
      "step_s[0]",  "step_s[1]",  "step_s[2]",  "step_s[3]",  "step_s[4]",  "step_s[5]",
      "step_s[6]",  "step_s[7]",  "step_s[8]",  "step_s[9]",  "step_s[10]", "step_s[11]",
      "step_s[12]", "step_s[13]", "step_s[14]", "step_s[15]", "step_s[16]", "step_s[17]",
      "step_s[18]", "step_s[19]", "step_s[20]", "step_s[21]", "step_s[22]", "step_s[23]",
      "step_s[24]", "step_s[25]", "step_s[26]", "step_s[27]", "step_s[28]", "step_s[29]",
      "step_s[30]", "step_s[31]", "step_s[32]", "step_s[33]", "step_s[34]", "step_s[35]",
      "step_s[36]", "step_s[37]", "step_s[38]", "step_s[39]", "step_s[40]", "step_s[41]",
      "step_s[42]", "step_s[43]", "step_s[44]", "step_s[45]", "step_s[46]", "step_s[47]",
      "step_s[48]", "step_s[49]", "step_s[50]", "step_s[51]", "step_s[52]", "step_s[53]",
      "step_s[54]", "step_s[55]", "step_s[56]", "step_s[57]", "step_s[58]", "step_s[59]",
      "step_s[60]", "step_s[61]", "step_s[62]", "step_s[63]"};
  static const char *const val_keys[PROFILE_MAX_STEPS] = {
      "step_value[0]",  "step_value[1]",  "step_value[2]",  "step_value[3]",  "step_value[4]",
      "step_value[5]",  "step_value[6]",  "step_value[7]",  "step_value[8]",  "step_value[9]",
      "step_value[10]", "step_value[11]", "step_value[12]", "step_value[13]", "step_value[14]",
      "step_value[15]", "step_value[16]", "step_value[17]", "step_value[18]", "step_value[19]",
      "step_value[20]", "step_value[21]", "step_value[22]", "step_value[23]", "step_value[24]",
      "step_value[25]", "step_value[26]", "step_value[27]", "step_value[28]", "step_value[29]",
      "step_value[30]", "step_value[31]", "step_value[32]", "step_value[33]", "step_value[34]",
      "step_value[35]", "step_value[36]", "step_value[37]", "step_value[38]", "step_value[39]",
      "step_value[40]", "step_value[41]", "step_value[42]", "step_value[43]", "step_value[44]",
      "step_value[45]", "step_value[46]", "step_value[47]", "step_value[48]", "step_value[49]",
      "step_value[50]", "step_value[51]", "step_value[52]", "step_value[53]", "step_value[54]",
      "step_value[55]", "step_value[56]", "step_value[57]", "step_value[58]", "step_value[59]",
      "step_value[60]", "step_value[61]", "step_value[62]", "step_value[63]"};
  const char *bad = NULL;
  if (p == NULL) bad = "profile";
  else if ((unsigned)p->kind >= (unsigned)PROFILE_NKINDS) bad = "kind";
  else if (!fin(p->value)) bad = "value";
  else if (p->kind == PROFILE_SINE) {
    if (!fin(p->amp)) bad = "amp";
    else if (!(isfinite(p->freq_hz) && p->freq_hz >= 0.0 && p->freq_hz <= 1e6)) bad = "freq_hz";
    else if (!(isfinite(p->phase_rad) && fabs(p->phase_rad) <= 1e3)) bad = "phase_rad";
  } else if (p->kind == PROFILE_RAMP) {
    if (!fin(p->slope_per_s)) bad = "slope_per_s";
    else if (!fin(p->t_start_s)) bad = "t_start_s";
    else if (!fin(p->t_end_s) || p->t_end_s < p->t_start_s) bad = "t_end_s";
    else if (!fin(p->value + p->slope_per_s * (p->t_end_s - p->t_start_s))) bad = "slope_per_s";
  } else if (p->kind == PROFILE_HEAT_COOL) {
    if (!fin(p->hot_value)) bad = "hot_value";
    else if (!fin(p->t_start_s)) bad = "t_start_s";
    else if (!(fin(p->heat_s) && p->heat_s >= 0.0)) bad = "heat_s";
    else if (!(fin(p->tau_heat_s) && p->tau_heat_s > 0.0)) bad = "tau_heat_s";
    else if (!(fin(p->tau_cool_s) && p->tau_cool_s > 0.0)) bad = "tau_cool_s";
  } else if (p->kind == PROFILE_STEPS) {
    if (p->n_steps < 1 || p->n_steps > PROFILE_MAX_STEPS) bad = "n_steps";
    else if (!(fin(p->edge_s) && p->edge_s >= 0.0)) bad = "edge_s";
    else if (p->repeat != 0 && p->repeat != 1) bad = "repeat";
    double total = 0.0;
    for (int i = 0; bad == NULL && i < p->n_steps; i++) {
      if (!(fin(p->step_s[i]) && p->step_s[i] > 0.0 && p->step_s[i] >= p->edge_s))
        bad = dur_keys[i];
      else if (!fin(p->step_value[i])) bad = val_keys[i];
      else total += p->step_s[i];
    }
    if (bad == NULL && !(total <= kMaxAbs)) bad = "step_s";
  }
  if (key != NULL) *key = bad;
  return bad == NULL ? 0 : -1;
}

/* Value and slope inside step i at time u from its start, entering from prev. */
static double step_at(const profile_t *p, int i, double u, double prev, double *slope)
{
  const double v = p->step_value[i];
  if (p->edge_s > 0.0 && u < p->edge_s) {
    const double k = (v - prev) / p->edge_s;
    if (slope) *slope = k;
    return prev + k * u;
  }
  if (slope) *slope = 0.0;
  return v;
}

static double eval_steps(const profile_t *p, double t, double *slope)
{
  const int n = p->n_steps;
  if (t < 0.0) {
    if (slope) *slope = 0.0;
    return p->step_value[0];
  }
  double total = 0.0;
  for (int i = 0; i < n; i++) total += p->step_s[i];
  int wrapped = 0;
  if (t >= total) {
    if (!p->repeat) {
      if (slope) *slope = 0.0;
      return p->step_value[n - 1];
    }
    t = fmod(t, total);
    wrapped = 1;
  }
  double start = 0.0;
  for (int i = 0; i < n; i++) {
    if (t < start + p->step_s[i] || i == n - 1) {
      double prev;
      if (i > 0) prev = p->step_value[i - 1];
      else prev = wrapped ? p->step_value[n - 1] : p->step_value[0];
      return step_at(p, i, t - start, prev, slope);
    }
    start += p->step_s[i];
  }
  if (slope) *slope = 0.0; /* not reached */
  return p->step_value[n - 1];
}

double profile_eval(const profile_t *p, double t, double *slope)
{
  double s = 0.0, v = p->value;
  switch (p->kind) {
  case PROFILE_CONST: break;
  case PROFILE_SINE: {
    const double w = kTwoPi * p->freq_hz;
    v = p->value + p->amp * sin(w * t + p->phase_rad);
    s = p->amp * w * cos(w * t + p->phase_rad);
    break;
  }
  case PROFILE_RAMP:
    if (t >= p->t_end_s) v = p->value + p->slope_per_s * (p->t_end_s - p->t_start_s);
    else if (t >= p->t_start_s) {
      v = p->value + p->slope_per_s * (t - p->t_start_s);
      s = p->slope_per_s;
    }
    break;
  case PROFILE_HEAT_COOL: {
    const double th = p->t_start_s + p->heat_s;
    if (t >= p->t_start_s && t < th) {
      const double e = exp(-(t - p->t_start_s) / p->tau_heat_s);
      v = p->hot_value + (p->value - p->hot_value) * e;
      s = (p->hot_value - p->value) * e / p->tau_heat_s;
    } else if (t >= th) {
      const double v_end = p->hot_value +
                           (p->value - p->hot_value) * exp(-p->heat_s / p->tau_heat_s);
      const double e = exp(-(t - th) / p->tau_cool_s);
      v = p->value + (v_end - p->value) * e;
      s = -(v_end - p->value) * e / p->tau_cool_s;
    }
    break;
  }
  case PROFILE_STEPS: v = eval_steps(p, t, &s); break;
  case PROFILE_NKINDS:
  default: break;
  }
  if (slope != NULL) *slope = s;
  return v;
}

void accel_profile_zero(accel_profile_t *a) { memset(a, 0, sizeof(*a)); }

/* The shocks' and bands' fields, checked after the constant and sine parts. */
static const char *shocks_bands_bad(const accel_profile_t *a)
{
  static const char *const sk[4][PROFILE_MAX_SHOCKS] = {
      {"shock_axis[0]", "shock_axis[1]", "shock_axis[2]", "shock_axis[3]", "shock_axis[4]",
       "shock_axis[5]", "shock_axis[6]", "shock_axis[7]"},
      {"shock_t_s[0]", "shock_t_s[1]", "shock_t_s[2]", "shock_t_s[3]", "shock_t_s[4]",
       "shock_t_s[5]", "shock_t_s[6]", "shock_t_s[7]"},
      {"shock_peak_g[0]", "shock_peak_g[1]", "shock_peak_g[2]", "shock_peak_g[3]",
       "shock_peak_g[4]", "shock_peak_g[5]", "shock_peak_g[6]", "shock_peak_g[7]"},
      {"shock_dur_s[0]", "shock_dur_s[1]", "shock_dur_s[2]", "shock_dur_s[3]", "shock_dur_s[4]",
       "shock_dur_s[5]", "shock_dur_s[6]", "shock_dur_s[7]"}};
  static const char *const bk[4][PROFILE_MAX_VIB_BANDS] = {
      {"band_axis[0]", "band_axis[1]", "band_axis[2]", "band_axis[3]"},
      {"band_psd_g2_per_hz[0]", "band_psd_g2_per_hz[1]", "band_psd_g2_per_hz[2]",
       "band_psd_g2_per_hz[3]"},
      {"band_f_lo_hz[0]", "band_f_lo_hz[1]", "band_f_lo_hz[2]", "band_f_lo_hz[3]"},
      {"band_f_hi_hz[0]", "band_f_hi_hz[1]", "band_f_hi_hz[2]", "band_f_hi_hz[3]"}};
  if (a->n_shocks < 0 || a->n_shocks > PROFILE_MAX_SHOCKS) return "n_shocks";
  for (int j = 0; j < a->n_shocks; j++) {
    if (a->shock_axis[j] < 0 || a->shock_axis[j] >= PROFILE_ACCEL_AXES) return sk[0][j];
    if (!(isfinite(a->shock_t_s[j]) && a->shock_t_s[j] >= 0.0 && a->shock_t_s[j] <= kMaxAbs))
      return sk[1][j];
    if (!(isfinite(a->shock_peak_g[j]) && fabs(a->shock_peak_g[j]) <= 1e5)) return sk[2][j];
    if (!(isfinite(a->shock_dur_s[j]) && a->shock_dur_s[j] >= 1e-6 && a->shock_dur_s[j] <= 10.0))
      return sk[3][j];
  }
  if (a->n_bands < 0 || a->n_bands > PROFILE_MAX_VIB_BANDS) return "n_bands";
  for (int j = 0; j < a->n_bands; j++) {
    const double lo = a->band_f_lo_hz[j], hi = a->band_f_hi_hz[j];
    if (a->band_axis[j] < 0 || a->band_axis[j] >= PROFILE_ACCEL_AXES) return bk[0][j];
    if (!(isfinite(a->band_psd_g2_per_hz[j]) && a->band_psd_g2_per_hz[j] > 0.0 &&
          a->band_psd_g2_per_hz[j] <= 1e3))
      return bk[1][j];
    if (!(isfinite(lo) && (lo == 0.0 || lo >= 0.1))) return bk[2][j];
    /* an octave at least, so that the band is flat in its middle (vib.h) */
    if (!(isfinite(hi) && hi > 0.0 && hi <= 1e6 && hi >= 2.0 * lo)) return bk[3][j];
  }
  return NULL;
}

int accel_profile_check(const accel_profile_t *a, const char **key)
{
  static const char *const keys[4][PROFILE_ACCEL_AXES] = {
      {"const_g[0]", "const_g[1]", "const_g[2]"},
      {"amp_g[0]", "amp_g[1]", "amp_g[2]"},
      {"freq_hz[0]", "freq_hz[1]", "freq_hz[2]"},
      {"phase_rad[0]", "phase_rad[1]", "phase_rad[2]"}};
  const char *bad = NULL;
  if (a == NULL) bad = "accel";
  for (int i = 0; bad == NULL && i < PROFILE_ACCEL_AXES; i++) {
    if (!(isfinite(a->const_g[i]) && fabs(a->const_g[i]) <= 1e4)) bad = keys[0][i];
    else if (!(isfinite(a->amp_g[i]) && fabs(a->amp_g[i]) <= 1e4)) bad = keys[1][i];
    else if (!(isfinite(a->freq_hz[i]) && a->freq_hz[i] >= 0.0 && a->freq_hz[i] <= 1e6))
      bad = keys[2][i];
    else if (!(isfinite(a->phase_rad[i]) && fabs(a->phase_rad[i]) <= 1e3)) bad = keys[3][i];
  }
  if (bad == NULL) bad = shocks_bands_bad(a);
  if (key != NULL) *key = bad;
  return bad == NULL ? 0 : -1;
}

int accel_profile_dynamic(const accel_profile_t *a)
{
  for (int i = 0; i < PROFILE_ACCEL_AXES; i++)
    if (a->amp_g[i] != 0.0) return 1;
  return a->n_shocks > 0 || a->n_bands > 0;
}

/* Half-sine shock j at t (0 outside it). */
static double shock_at(const accel_profile_t *a, int j, double t)
{
  const double u = (t - a->shock_t_s[j]) / a->shock_dur_s[j];
  if (!(u >= 0.0 && u <= 1.0)) return 0.0;
  return a->shock_peak_g[j] * sin(PLANT_PI * u);
}

/* Integral of half-sine shock j over [t0, t1]: peak dur / pi (cos(pi u0) - cos(pi u1))
 * over the part of the interval inside the pulse (exact), written as
 * 2 sin(pi (u0 + u1) / 2) sin(pi (u1 - u0) / 2) so that a sample deep inside a long pulse
 * loses no digits to the difference. */
static double shock_integral(const accel_profile_t *a, int j, double t0, double t1)
{
  const double ts = a->shock_t_s[j], d = a->shock_dur_s[j];
  const double lo = t0 > ts ? t0 : ts, hi = t1 < ts + d ? t1 : ts + d;
  if (!(hi > lo)) return 0.0;
  const double u0 = (lo - ts) / d, u1 = (hi - ts) / d;
  return a->shock_peak_g[j] * d / PLANT_PI * 2.0 * sin(0.5 * PLANT_PI * (u0 + u1)) *
         sin(0.5 * PLANT_PI * (u1 - u0));
}

void accel_profile_eval(const accel_profile_t *a, double t, double a_g[PROFILE_ACCEL_AXES])
{
  for (int i = 0; i < PROFILE_ACCEL_AXES; i++)
    a_g[i] = a->const_g[i] + a->amp_g[i] * sin(kTwoPi * a->freq_hz[i] * t + a->phase_rad[i]);
  for (int j = 0; j < a->n_shocks; j++) a_g[a->shock_axis[j]] += shock_at(a, j, t);
}

void accel_profile_mean(const accel_profile_t *a, double t0, double t1,
                        double a_g[PROFILE_ACCEL_AXES])
{
  const double dt = t1 - t0;
  for (int i = 0; i < PROFILE_ACCEL_AXES; i++) {
    if (a->amp_g[i] == 0.0) {
      a_g[i] = a->const_g[i];
      continue;
    }
    const double w = kTwoPi * a->freq_hz[i];
    const double p = a->phase_rad[i];
    double m;
    if (!(dt > 0.0)) m = sin(w * t0 + p);
    else if (w * dt < 1e-4) {
      /* mean of sin over a short interval: sin at the midpoint times sinc(w dt / 2) */
      const double x = 0.5 * w * dt;
      m = sin(w * 0.5 * (t0 + t1) + p) * (1.0 - x * x / 6.0);
    } else {
      m = (cos(w * t0 + p) - cos(w * t1 + p)) / (w * dt);
    }
    a_g[i] = a->const_g[i] + a->amp_g[i] * m;
  }
  if (dt > 0.0)
    for (int j = 0; j < a->n_shocks; j++)
      a_g[a->shock_axis[j]] += shock_integral(a, j, t0, t1) / dt;
}

void accel_profile_peak(const accel_profile_t *a, double peak_g[PROFILE_ACCEL_AXES])
{
  for (int i = 0; i < PROFILE_ACCEL_AXES; i++)
    peak_g[i] = fabs(a->const_g[i]) + fabs(a->amp_g[i]);
  for (int j = 0; j < a->n_shocks; j++) peak_g[a->shock_axis[j]] += fabs(a->shock_peak_g[j]);
}
