#include "plant/actuator.h"

#include <math.h>
#include <string.h>
#include "board.h"

void actuator_default_cfg(actuator_cfg_t *cfg)
{
  memset(cfg, 0, sizeof *cfg);
  cfg->fs_hz = (double)BOARD_SAMPLE_RATE_HZ;
  cfg->ks_drive_mps2_per_v2 = 0.25;
  cfg->drive_noise.white_rthz = 200e-9;
  cfg->drive_noise.flicker_1hz_rthz = 2e-6;
  cfg->drive_noise.fmin_hz = 1e-3;
  cfg->fb = ACTUATOR_FB_OFF;
  cfg->ks_fb_mps2_per_v2 = 0.01;
  cfg->fb_bias_v = 5.0;
  cfg->fb_noise = cfg->drive_noise;
  cfg->quadnull_noise = cfg->drive_noise;
  cfg->tune_noise = cfg->drive_noise;
  /* no nulling or tuning electrodes, no feedback-pair softening (memset) */
}

static int nonneg(double v) { return isfinite(v) && v >= 0.0; }

/* Everything of cfg but the noise specs. */
static int cfg_ok(const actuator_cfg_t *cfg)
{
  return isfinite(cfg->fs_hz) && cfg->fs_hz > 0.0 && nonneg(cfg->ks_drive_mps2_per_v2) &&
         nonneg(cfg->ks_fb_mps2_per_v2) && isfinite(cfg->fb_bias_v) &&
         fabs(cfg->fb_bias_v) <= 100.0 && nonneg(cfg->fb_ke_per_s2_per_v2) &&
         nonneg(cfg->quadnull_kyx_per_s2_per_v2) && nonneg(cfg->quadnull_ke_per_s2_per_v2) &&
         nonneg(cfg->tune_ke_per_s2_per_v2) &&
         (cfg->fb == ACTUATOR_FB_OFF || cfg->fb == ACTUATOR_FB_SINGLE ||
          cfg->fb == ACTUATOR_FB_DIFFERENTIAL || cfg->fb == ACTUATOR_FB_PAIR);
}

/* The noise spec of each electrode voltage; an electrode that is not there (or grounded)
 * gets none. */
static void noise_specs(const actuator_cfg_t *cfg, const flicker_spec_t *spec[ACTUATOR_NOISE])
{
  static const flicker_spec_t off = {0.0, 0.0, 0.0};
  const int quadnull = cfg->quadnull_kyx_per_s2_per_v2 > 0.0;
  spec[0] = spec[1] = &cfg->drive_noise;
  /* the grounded electrode of FB_SINGLE and both electrodes of FB_OFF carry no noise */
  spec[2] = cfg->fb == ACTUATOR_FB_OFF ? &off : &cfg->fb_noise;
  spec[3] = (cfg->fb == ACTUATOR_FB_DIFFERENTIAL || cfg->fb == ACTUATOR_FB_PAIR) ? &cfg->fb_noise
                                                                                 : &off;
  spec[4] = spec[5] = quadnull ? &cfg->quadnull_noise : &off;
  spec[6] = cfg->tune_ke_per_s2_per_v2 > 0.0 ? &cfg->tune_noise : &off;
}

int actuator_init(actuator_t *a, const actuator_cfg_t *cfg, uint64_t seed)
{
  if (a == NULL || cfg == NULL || !cfg_ok(cfg)) return -1;
  const flicker_spec_t *spec[ACTUATOR_NOISE];
  noise_specs(cfg, spec);
  /* everything that can fail is checked before a is touched; then built in place */
  for (int i = 0; i < ACTUATOR_NOISE; i++)
    if (flicker_check(spec[i], cfg->fs_hz) != 0) return -1;
  a->cfg = *cfg;
  noise_specs(&a->cfg, spec); /* cfg may have been a's own */
  a->elec = a->cfg.fb == ACTUATOR_FB_PAIR || a->cfg.quadnull_kyx_per_s2_per_v2 > 0.0 ||
            a->cfg.tune_ke_per_s2_per_v2 > 0.0;
  for (int i = 0; i < ACTUATOR_NOISE; i++)
    (void)flicker_init(&a->noise[i], spec[i], a->cfg.fs_hz, seed,
                       ACTUATOR_RNG_STREAM_U1 + (uint64_t)i);
  return 0;
}

/* mean((v + w)^2) over the sample, w held */
static double mean_sq_with_noise(const dac_chan_out_t *c, double w)
{
  return c->mean_sq_v2 + w * (2.0 * c->mean_v + w);
}

/* Sense force of the feedback electrodes (the header), pair voltages from elec. */
static double sense_force(const actuator_t *a, const dac_out_t *dac,
                          const actuator_elec_in_t *elec, const double *w)
{
  const dac_chan_out_t *s = &dac->ch[HAL_DAC_SPARE];
  const double vb = a->cfg.fb_bias_v;
  switch (a->cfg.fb) {
  case ACTUATOR_FB_SINGLE: return a->cfg.ks_fb_mps2_per_v2 * mean_sq_with_noise(s, w[2]);
  case ACTUATOR_FB_DIFFERENTIAL: {
    /* mean((Vb + u + w3)^2) - mean((Vb - u + w4)^2), expanded so that the Vb^2 terms
     * cancel exactly */
    const double p3 = vb + w[2], p4 = vb + w[3];
    const double m3 = p3 * p3 + 2.0 * p3 * s->mean_v + s->mean_sq_v2;
    const double m4 = p4 * p4 - 2.0 * p4 * s->mean_v + s->mean_sq_v2;
    return a->cfg.ks_fb_mps2_per_v2 * (m3 - m4);
  }
  case ACTUATOR_FB_PAIR: /* (6-7), as the drive comb */
    return a->cfg.ks_fb_mps2_per_v2 *
           (mean_sq_with_noise(&elec->fb[0], w[2]) - mean_sq_with_noise(&elec->fb[1], w[3]));
  case ACTUATOR_FB_OFF:
  default: return 0.0;
  }
}

/* Stiffness of the nulling, tuning and feedback-pair electrodes (the header). */
static void elec_stiffness(const actuator_t *a, const actuator_elec_in_t *e, const double *w,
                           actuator_out_t *out)
{
  const actuator_cfg_t *c = &a->cfg;
  out->kyx_per_s2 = out->ke_per_s2 = 0.0;
  if (c->quadnull_kyx_per_s2_per_v2 > 0.0) {
    const double m1 = mean_sq_with_noise(&e->quadnull[0], w[4]);
    const double m2 = mean_sq_with_noise(&e->quadnull[1], w[5]);
    out->kyx_per_s2 = c->quadnull_kyx_per_s2_per_v2 * (m1 - m2);
    out->ke_per_s2 += c->quadnull_ke_per_s2_per_v2 * (m1 + m2);
  }
  if (c->tune_ke_per_s2_per_v2 > 0.0)
    out->ke_per_s2 += c->tune_ke_per_s2_per_v2 * mean_sq_with_noise(&e->tune, w[6]);
  if (c->fb == ACTUATOR_FB_PAIR && c->fb_ke_per_s2_per_v2 > 0.0)
    out->ke_per_s2 += c->fb_ke_per_s2_per_v2 * (mean_sq_with_noise(&e->fb[0], w[2]) +
                                                mean_sq_with_noise(&e->fb[1], w[3]));
}

void actuator_step_elec(actuator_t *a, const dac_out_t *dac, const actuator_elec_in_t *elec,
                        actuator_out_t *out)
{
  static const actuator_elec_in_t zero;
  if (elec == NULL) elec = &zero;
  double w[ACTUATOR_NOISE];
  for (int i = 0; i < ACTUATOR_NOISE; i++) w[i] = flicker_step(&a->noise[i]);
  /* (6-7) on the drive comb */
  out->f_drive_mps2 = a->cfg.ks_drive_mps2_per_v2 *
                      (mean_sq_with_noise(&dac->ch[HAL_DAC_DRIVE_U1], w[0]) -
                       mean_sq_with_noise(&dac->ch[HAL_DAC_DRIVE_U2], w[1]));
  out->f_sense_mps2 = sense_force(a, dac, elec, w);
  if (a->elec) elec_stiffness(a, elec, w, out);
  else out->kyx_per_s2 = out->ke_per_s2 = 0.0;
  for (int i = 0; i < ACTUATOR_NOISE; i++) out->noise_v[i] = w[i];
}

void actuator_step(actuator_t *a, const dac_out_t *dac, actuator_out_t *out)
{
  actuator_step_elec(a, dac, NULL, out);
}
