#include "plant/pickoff.h"

#include <math.h>
#include <string.h>

#include "plant/expm.h"
#include "plant/plant_const.h"
#include "board.h"

static const double k_pi = PLANT_PI;
static const double k_deg = PLANT_RAD_PER_DEG;

/* SISO state space in time normalised to the sample period. */
typedef struct {
  int n;
  double a[PICKOFF_MAX_N][PICKOFF_MAX_N];
  double b[PICKOFF_MAX_N];
  double c[PICKOFF_MAX_N];
  double d;
} ss_t;

/* acc <- next(acc(.)) : acc's output feeds next's input */
static void series(ss_t *acc, const ss_t *next)
{
  ss_t r;
  memset(&r, 0, sizeof r);
  const int n1 = acc->n, n2 = next->n;
  r.n = n1 + n2;
  for (int i = 0; i < n1; i++) {
    for (int j = 0; j < n1; j++) r.a[i][j] = acc->a[i][j];
    r.b[i] = acc->b[i];
    r.c[i] = next->d * acc->c[i];
  }
  for (int i = 0; i < n2; i++) {
    for (int j = 0; j < n1; j++) r.a[n1 + i][j] = next->b[i] * acc->c[j];
    for (int j = 0; j < n2; j++) r.a[n1 + i][n1 + j] = next->a[i][j];
    r.b[n1 + i] = next->b[i] * acc->d;
    r.c[n1 + i] = next->c[i];
  }
  r.d = next->d * acc->d;
  *acc = r;
}

void pickoff_default_cfg(pickoff_cfg_t *cfg, pickoff_axis_t axis)
{
  memset(cfg, 0, sizeof *cfg);
  cfg->axis = axis;
  cfg->fs_hz = (double)BOARD_SAMPLE_RATE_HZ;
  cfg->gain_tc_per_k = 0.0;
  cfg->preamp_rail_v = 13.5;
  cfg->lag_kind = PICKOFF_LAG_LOWPASS;
  cfg->lag_ref_hz = 1489.9;
  cfg->temp_ref_k = 298.15;
  cfg->phi0_rad = 3.0 * k_deg;
  cfg->phi2_rad_per_k2 = 0.0;
  cfg->hp_hz = 100.0;
  cfg->lp_hz = 8000.0;
  cfg->lp_q = 0.70710678118654752;
  cfg->noise_v_rthz = 2e-6;
  cfg->jitter_rms_s = 0.0;
  cfg->phase_step_rad = 1e-6;
  cfg->flicker_fmin_hz = 1e-3; /* the flicker itself is off (zero density) */
  if (axis == PICKOFF_SENSE) {
    cfg->gain_v_per_m = 6.18e7;
    cfg->ft_u1 = 1e-4;
    cfg->ft_u2 = 6e-5;
    cfg->ft_spare = 1e-3;
    cfg->phi1_rad_per_k = 0.1 * k_deg;
    cfg->offset_v = -3e-3;
    cfg->sample_delay_s = 4e-6;
  } else {
    cfg->gain_v_per_m = 3.0e5;
    cfg->ft_u1 = 2e-4;
    cfg->ft_u2 = -1.5e-4;
    cfg->ft_spare = 0.0;
    cfg->phi1_rad_per_k = 0.01 * k_deg;
    cfg->offset_v = 5e-3;
    cfg->sample_delay_s = 0.0;
  }
}

static int finite_all(const double *v, int n)
{
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

/* The flicker specs of the gain (relative) and the phase (rad). */
static void flicker_specs(const pickoff_cfg_t *c, flicker_spec_t *gain, flicker_spec_t *phase)
{
  gain->white_rthz = phase->white_rthz = 0.0;
  gain->flicker_1hz_rthz = c->gain_flicker_1hz_rthz;
  phase->flicker_1hz_rthz = c->phase_flicker_1hz_rad_rthz;
  gain->fmin_hz = phase->fmin_hz = c->flicker_fmin_hz;
}

/* The imperfections' fields (pickoff.h). */
static int imperfections_ok(const pickoff_cfg_t *c)
{
  const double vals[] = {c->gap_m, c->gap_asym, c->gain_flicker_1hz_rthz,
                         c->phase_flicker_1hz_rad_rthz, c->flicker_fmin_hz};
  if (!finite_all(vals, (int)(sizeof vals / sizeof vals[0]))) return 0;
  if (!(c->gap_m >= 0.0 && c->gap_m <= 1.0 && c->gap_asym >= 0.0 && c->gap_asym <= 1.0))
    return 0;
  if (!(c->gain_flicker_1hz_rthz >= 0.0 && c->gain_flicker_1hz_rthz <= 0.1 &&
        c->phase_flicker_1hz_rad_rthz >= 0.0 && c->phase_flicker_1hz_rad_rthz <= 0.1))
    return 0;
  flicker_spec_t g, ph;
  flicker_specs(c, &g, &ph);
  return flicker_check(&g, c->fs_hz) == 0 && flicker_check(&ph, c->fs_hz) == 0;
}

static int cfg_ok(const pickoff_cfg_t *c)
{
  const double vals[] = {
      c->fs_hz,        c->gain_v_per_m,   c->gain_tc_per_k,  c->preamp_rail_v,
      c->ft_u1,        c->ft_u2,          c->ft_spare,       c->lag_ref_hz,
      c->temp_ref_k,   c->phi0_rad,       c->phi1_rad_per_k, c->phi2_rad_per_k2,
      c->hp_hz,        c->lp_hz,          c->lp_q,           c->offset_v,
      c->noise_v_rthz, c->sample_delay_s, c->jitter_rms_s,   c->phase_step_rad};
  if (!finite_all(vals, (int)(sizeof vals / sizeof vals[0]))) return 0;
  if (c->axis != PICKOFF_DRIVE && c->axis != PICKOFF_SENSE) return 0;
  if (c->lag_kind != PICKOFF_LAG_LOWPASS && c->lag_kind != PICKOFF_LAG_ALLPASS) return 0;
  if (!(c->fs_hz > 0.0 && c->fs_hz <= 1e7)) return 0;
  const double T = 1.0 / c->fs_hz;
  if (!(c->gain_v_per_m > 0.0 && fabs(c->gain_tc_per_k) < 0.1 && c->preamp_rail_v > 0.0))
    return 0;
  if (!(fabs(c->ft_u1) <= 1.0 && fabs(c->ft_u2) <= 1.0 && fabs(c->ft_spare) <= 1.0)) return 0;
  if (!(c->lag_ref_hz > 0.0 && c->lag_ref_hz < c->fs_hz / 2.0 && c->temp_ref_k > 0.0)) return 0;
  if (!(c->hp_hz >= 0.0 && c->hp_hz < c->fs_hz / 2.0)) return 0;
  if (!(c->lp_hz > 0.0 && c->lp_hz <= 10.0 * c->fs_hz && c->lp_q >= 0.1 && c->lp_q <= 10.0))
    return 0;
  if (!(fabs(c->offset_v) <= 10.0 && c->noise_v_rthz >= 0.0 && c->phase_step_rad >= 0.0 &&
        c->phase_step_rad <= 0.01))
    return 0;
  if (!(fabs(c->sample_delay_s) <= 0.5 * T && c->jitter_rms_s >= 0.0 &&
        c->jitter_rms_s <= 0.05 * T))
    return 0;
  return imperfections_ok(c);
}

static double phase_at(const pickoff_cfg_t *c, double temp_k)
{
  const double dt = temp_k - c->temp_ref_k;
  return c->phi0_rad + c->phi1_rad_per_k * dt + 0.5 * c->phi2_rad_per_k2 * dt * dt; /* (2-40) */
}

double pickoff_phi_clamp(pickoff_lag_kind_t kind, double phi_rad, int *outside)
{
  const double lo = (kind == PICKOFF_LAG_ALLPASS) ? PICKOFF_LEAD_MIN_ALLPASS_RAD
                                                  : PICKOFF_LEAD_MIN_LOWPASS_RAD;
  const double hi = (kind == PICKOFF_LAG_ALLPASS) ? PICKOFF_LAG_MAX_ALLPASS_RAD
                                                  : PICKOFF_LAG_MAX_LOWPASS_RAD;
  int out = 1;
  double v = phi_rad;
  if (!isfinite(v)) v = 0.0;
  else if (v < lo) v = lo;
  else if (v > hi) v = hi;
  else out = 0;
  if (outside != NULL) *outside = out;
  return v;
}

double pickoff_gain_factor(double tc_per_k, double dt_k, int *outside)
{
  const double g = 1.0 + tc_per_k * dt_k; /* (4-12): gain ~ Vc - V_D */
  const int out = !(g >= PICKOFF_GAIN_MIN_FACTOR);
  if (outside != NULL) *outside = out;
  return out ? PICKOFF_GAIN_MIN_FACTOR : g;
}

void pickoff_lag_section(pickoff_lag_kind_t kind, double phi_rad, double *b0, double *b1_w,
                         double *tp_w)
{
  const double pm = PICKOFF_PHI_POLE_MIN_RAD;
  if (kind == PICKOFF_LAG_ALLPASS) {
    /* (1 - s tau)/(1 + s tau), tau = tan(Phi/2)/w: phase -Phi, unit gain */
    const double hm = 0.5 * (phi_rad >= pm ? phi_rad : pm);
    *tp_w = tan(hm);
    if (phi_rad >= pm) {
      *b0 = 1.0;
      *b1_w = -*tp_w;
    } else {
      /* continued below pm with the pole held: the numerator turns by Phi - pm, its
       * size kept, so the gain at w stays 1 and the phase -Phi (a lead for Phi < 0) */
      *b0 = cos(hm - phi_rad) / cos(hm);
      *b1_w = sin(hm - phi_rad) / cos(hm);
    }
    return;
  }
  /* 1 / (1 + s tau), tau = tan(Phi)/w: phase -Phi, gain cos(Phi) at w */
  *b0 = 1.0;
  if (phi_rad >= pm) {
    *tp_w = tan(phi_rad);
    *b1_w = 0.0;
  } else {
    /* continued below pm as a lead-lag network (1 + s tz)/(1 + s tp) with the pole
     * held at tan(pm)/w and the zero at tan(pm - Phi)/w: phase -Phi, gain
     * cos(pm)/cos(pm - Phi); identical to the low-pass at Phi = pm */
    *tp_w = tan(pm);
    *b1_w = tan(pm - phi_rad);
  }
}

/* Build the chain of c at phase phi and discretise it into p (n, phi, g, output rows,
 * phi_rad). The only failure (the exponential) comes before the first write to p. */
static int discretise(pickoff_t *p, const pickoff_cfg_t *c, double phi)
{
  const double T = 1.0 / c->fs_hz;
  const double wref = 2.0 * k_pi * c->lag_ref_hz;
  ss_t chain, sec;

  /* circuit lag (2-40) realised as a real filter (b0 + s b1)/(1 + s tp) */
  memset(&chain, 0, sizeof chain);
  chain.n = 1;
  {
    double b0, b1w, tpw;
    pickoff_lag_section(c->lag_kind, phi, &b0, &b1w, &tpw);
    const double tau = tpw / wref / T, r = b1w / tpw; /* r = b1 / tp */
    chain.a[0][0] = -1.0 / tau;
    chain.b[0] = 1.0 / tau;
    chain.c[0] = b0 - r;
    chain.d = r;
  }
  if (c->hp_hz > 0.0) {
    const double tau = 1.0 / (2.0 * k_pi * c->hp_hz) / T;
    memset(&sec, 0, sizeof sec);
    sec.n = 1;
    sec.a[0][0] = -1.0 / tau;
    sec.b[0] = 1.0 / tau;
    sec.c[0] = -1.0;
    sec.d = 1.0;
    series(&chain, &sec);
  }
  {
    const double w = 2.0 * k_pi * c->lp_hz * T;
    memset(&sec, 0, sizeof sec);
    sec.n = 2;
    sec.a[0][1] = w;
    sec.a[1][0] = -w;
    sec.a[1][1] = -w / c->lp_q;
    sec.b[1] = w;
    sec.c[0] = 1.0;
    sec.d = 0.0;
    series(&chain, &sec);
  }

  /* augmented generator: chain driven by the cubic q = [u, u_s, u_ss, u_sss] */
  _Static_assert(PICKOFF_MAX_N + 4 <= EXPM_MAX_N, "augmented pickoff chain exceeds expm");
  const int n = chain.n, na = n + 4;
  double f[EXPM_MAX_N * EXPM_MAX_N], e[EXPM_MAX_N * EXPM_MAX_N];
  memset(f, 0, sizeof f);
  for (int i = 0; i < n; i++) {
    for (int j = 0; j < n; j++) f[i * na + j] = chain.a[i][j];
    f[i * na + n] = chain.b[i];
  }
  for (int j = 0; j < 3; j++) f[(n + j) * na + n + j + 1] = 1.0;
  if (expm(na, f, e) != 0) return -1;

  /* Hermite data [s0, m0, s1, m1] (m = T s') -> Taylor coefficients at s = 0 */
  static const double herm[4][4] = {{1.0, 0.0, 0.0, 0.0},
                                    {0.0, 1.0, 0.0, 0.0},
                                    {-6.0, -4.0, 6.0, -2.0},
                                    {12.0, 6.0, -12.0, 6.0}};
  p->n = n;
  memset(p->phi, 0, sizeof p->phi);
  memset(p->g, 0, sizeof p->g);
  for (int i = 0; i < n; i++) {
    for (int j = 0; j < n; j++) p->phi[i][j] = e[i * na + j];
    for (int j = 0; j < 4; j++) {
      double s = 0.0;
      for (int k = 0; k < 4; k++) s += e[i * na + n + k] * herm[k][j];
      p->g[i][j] = s;
    }
  }
  /* output derivatives in normalised time: Y_j = crow_j z + sum_{i<j} hb_ji u_i + D u_j */
  double crow[4][PICKOFF_MAX_N], hb[4][4];
  memset(crow, 0, sizeof crow);
  memset(hb, 0, sizeof hb);
  for (int i = 0; i < n; i++) crow[0][i] = chain.c[i];
  for (int j = 1; j < 4; j++)
    for (int i = 0; i < n; i++) {
      double s = 0.0;
      for (int k = 0; k < n; k++) s += crow[j - 1][k] * chain.a[k][i];
      crow[j][i] = s;
    }
  for (int j = 0; j < 4; j++) {
    for (int i = 0; i < j; i++) {
      double s = 0.0;
      for (int k = 0; k < n; k++) s += crow[j - 1 - i][k] * chain.b[k];
      hb[j][i] = s;
    }
    hb[j][j] = chain.d;
  }
  /* fold the Taylor series at the nominal delay dn = d / T into rows:
   *   y(dn)  = sum_j dn^j / j! Y_j,   T y'(dn) = sum_{j>=1} dn^(j-1) / (j-1)! Y_j */
  const double dn = c->sample_delay_s / T;
  const double cy[4] = {1.0, dn, dn * dn / 2.0, dn * dn * dn / 6.0};
  const double cd[4] = {0.0, 1.0, dn, dn * dn / 2.0};
  memset(p->out_z, 0, sizeof p->out_z);
  memset(p->out_u, 0, sizeof p->out_u);
  memset(p->dout_z, 0, sizeof p->dout_z);
  memset(p->dout_u, 0, sizeof p->dout_u);
  for (int j = 0; j < 4; j++) {
    for (int i = 0; i < PICKOFF_MAX_N; i++) {
      p->out_z[i] += cy[j] * crow[j][i];
      p->dout_z[i] += cd[j] * crow[j][i];
    }
    for (int i = 0; i < 4; i++) {
      p->out_u[i] += cy[j] * hb[j][i];
      p->dout_u[i] += cd[j] * hb[j][i];
    }
  }
  p->phi_rad = phi;
  return 0;
}

/* Phase and gain laws at temp_k, each kept to its range (flags: PICKOFF_OUT_*). */
static double laws_at(const pickoff_cfg_t *c, double temp_k, double *gain, unsigned *flags)
{
  int out_phi = 0, out_gain = 0;
  const double phi = pickoff_phi_clamp(c->lag_kind, phase_at(c, temp_k), &out_phi);
  *gain = c->gain_v_per_m *
          pickoff_gain_factor(c->gain_tc_per_k, temp_k - c->temp_ref_k, &out_gain);
  *flags = (out_phi ? PICKOFF_OUT_PHASE : 0u) | (out_gain ? PICKOFF_OUT_GAIN : 0u);
  return phi;
}

int pickoff_init(pickoff_t *p, const pickoff_cfg_t *cfg, double temp_k, uint64_t seed)
{
  if (p == NULL || cfg == NULL || !cfg_ok(cfg) || !isfinite(temp_k)) return -1;
  double gain;
  unsigned flags;
  const double phi = laws_at(cfg, temp_k, &gain, &flags);
  /* built in place: discretise fails (if ever) before it writes; cfg is copied first in
   * case it lives inside p */
  const pickoff_cfg_t c = *cfg;
  if (discretise(p, &c, phi) != 0) return -1;
  p->cfg = c;
  p->t_s = 1.0 / c.fs_hz;
  p->inv_t = c.fs_hz;
  p->temp_k = temp_k;
  p->rediscretise_count = 0;
  p->gain_now = gain;
  p->out_of_range = flags;
  memset(p->z, 0, sizeof p->z);
  p->s_prev = 0.0;
  p->m_prev = 0.0;
  p->noise_sd = c.noise_v_rthz * sqrt(c.fs_hz / 2.0);
  rng_seed(&p->rng_noise, seed, PICKOFF_RNG_STREAM_NOISE + (uint64_t)c.axis);
  rng_seed(&p->rng_jitter, seed, PICKOFF_RNG_STREAM_JITTER + (uint64_t)c.axis);
  p->preamp_clip_count = 0;
  /* imperfections (checked by cfg_ok, so the flicker inits cannot fail) */
  p->gap_on = c.gap_m > 0.0;
  p->inv_gap = p->gap_on ? 1.0 / c.gap_m : 0.0;
  p->inv_wref = 1.0 / (2.0 * k_pi * c.lag_ref_hz);
  p->gain_fl_on = c.gain_flicker_1hz_rthz > 0.0;
  p->phase_fl_on = c.phase_flicker_1hz_rad_rthz > 0.0;
  p->gain_noise = p->phase_noise_rad = 0.0;
  p->gap_out = 0u;
  flicker_spec_t g, ph;
  flicker_specs(&c, &g, &ph);
  (void)flicker_init(&p->gain_fl, &g, c.fs_hz, seed,
                     PICKOFF_RNG_STREAM_GAIN_FLICKER + (uint64_t)c.axis);
  (void)flicker_init(&p->phase_fl, &ph, c.fs_hz, seed,
                     PICKOFF_RNG_STREAM_PHASE_FLICKER + (uint64_t)c.axis);
  return 0;
}

unsigned pickoff_gap_out(pickoff_t *p)
{
  const unsigned f = p->gap_out;
  p->gap_out = 0u;
  return f;
}

/* The capacitive law of pickoff.h: x_read = x (1 + beta u + u^2), u = x / d held to
 * PICKOFF_GAP_MAX_U, and its time derivative (1 + 2 beta u + 3 u^2) x'. */
static void gap_law(pickoff_t *p, double *pos, double *vel)
{
  double u = *pos * p->inv_gap;
  if (u > PICKOFF_GAP_MAX_U || u < -PICKOFF_GAP_MAX_U) {
    u = u > 0.0 ? PICKOFF_GAP_MAX_U : -PICKOFF_GAP_MAX_U;
    p->gap_out |= PICKOFF_OUT_GAP;
  }
  const double b = p->cfg.gap_asym;
  *vel *= 1.0 + u * (2.0 * b + 3.0 * u);
  *pos *= 1.0 + u * (b + u);
}

int pickoff_set_temp(pickoff_t *p, double temp_k)
{
  if (p == NULL || !isfinite(temp_k)) return -1;
  double gain;
  unsigned flags;
  const double phi = laws_at(&p->cfg, temp_k, &gain, &flags);
  if (fabs(phi - p->phi_rad) >= p->cfg.phase_step_rad) {
    if (discretise(p, &p->cfg, phi) != 0) return -1; /* p unchanged then */
    p->rediscretise_count++;
  }
  p->temp_k = temp_k;
  p->gain_now = gain;
  p->out_of_range = flags;
  return (int)flags;
}

double pickoff_step(pickoff_t *p, double pos_m, double vel_mps, const dac_out_t *dac)
{
  return pickoff_step_at(p, pos_m, vel_mps, dac, 0.0);
}

double pickoff_step_at(pickoff_t *p, double pos_m, double vel_mps, const dac_out_t *dac,
                       double dt_s)
{
  const pickoff_cfg_t *c = &p->cfg;
  if (p->gap_on) gap_law(p, &pos_m, &vel_mps);
  double g = p->gain_now;
  if (p->gain_fl_on) {
    p->gain_noise = flicker_step(&p->gain_fl);
    g *= 1.0 + p->gain_noise;
  }
  /* ring-diode output (4-12) plus feedthrough, and its slope */
  double s1 = g * pos_m;
  double ds1 = g * vel_mps;
  if (dac != NULL) {
    const dac_chan_out_t *u1 = &dac->ch[HAL_DAC_DRIVE_U1], *u2 = &dac->ch[HAL_DAC_DRIVE_U2];
    const dac_chan_out_t *u3 = &dac->ch[HAL_DAC_SPARE];
    s1 += c->ft_u1 * u1->end_v + c->ft_u2 * u2->end_v + c->ft_spare * u3->end_v;
    ds1 += c->ft_u1 * u1->end_dvdt_v_per_s + c->ft_u2 * u2->end_dvdt_v_per_s +
           c->ft_spare * u3->end_dvdt_v_per_s;
  }
  double m1 = p->t_s * ds1;
  if (s1 > c->preamp_rail_v || s1 < -c->preamp_rail_v) {
    s1 = (s1 > 0.0) ? c->preamp_rail_v : -c->preamp_rail_v;
    m1 = 0.0;
    p->preamp_clip_count++;
  }
  const double s0 = p->s_prev, m0 = p->m_prev;

  /* fixed-size loops: unused states have zero rows and stay zero */
  double zn[PICKOFF_MAX_N];
  for (int i = 0; i < PICKOFF_MAX_N; i++) {
    double acc = p->g[i][0] * s0 + p->g[i][1] * m0 + p->g[i][2] * s1 + p->g[i][3] * m1;
    for (int j = 0; j < PICKOFF_MAX_N; j++) acc += p->phi[i][j] * p->z[j];
    zn[i] = acc;
  }
  for (int i = 0; i < PICKOFF_MAX_N; i++) p->z[i] = zn[i];
  p->s_prev = s1;
  p->m_prev = m1;

  /* output at t_{k+1} + d from the folded Taylor rows; input derivatives are those of
   * the cubic of the sample just finished, at its end */
  const double u[4] = {s1, m1, 6.0 * (s0 - s1) + 2.0 * m0 + 4.0 * m1,
                       12.0 * (s0 - s1) + 6.0 * (m0 + m1)};
  double v = 0.0;
  for (int i = 0; i < PICKOFF_MAX_N; i++) v += p->out_z[i] * zn[i];
  for (int i = 0; i < 4; i++) v += p->out_u[i] * u[i];
  /* the ADC's timing error and the phase flicker's delay (pickoff.h) */
  double te = dt_s;
  if (p->phase_fl_on) {
    p->phase_noise_rad = flicker_step(&p->phase_fl);
    te -= p->phase_noise_rad * p->inv_wref;
  }
  if (c->jitter_rms_s > 0.0 || te != 0.0) {
    double dy = 0.0;
    for (int i = 0; i < PICKOFF_MAX_N; i++) dy += p->dout_z[i] * zn[i];
    for (int i = 0; i < 4; i++) dy += p->dout_u[i] * u[i];
    if (c->jitter_rms_s > 0.0) v += c->jitter_rms_s * p->inv_t * gauss_zig(&p->rng_jitter) * dy;
    if (te != 0.0) v += te * p->inv_t * dy;
  }
  v += c->offset_v;
  if (p->noise_sd > 0.0) v += p->noise_sd * gauss_zig(&p->rng_noise);
  return v;
}
