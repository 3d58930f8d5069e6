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
}

int actuator_init(actuator_t *a, const actuator_cfg_t *cfg, uint64_t seed)
{
  if (a == NULL || cfg == NULL) return -1;
  if (!(isfinite(cfg->fs_hz) && cfg->fs_hz > 0.0)) return -1;
  if (!(isfinite(cfg->ks_drive_mps2_per_v2) && cfg->ks_drive_mps2_per_v2 >= 0.0)) return -1;
  if (!(isfinite(cfg->ks_fb_mps2_per_v2) && cfg->ks_fb_mps2_per_v2 >= 0.0)) return -1;
  if (!(isfinite(cfg->fb_bias_v) && fabs(cfg->fb_bias_v) <= 100.0)) return -1;
  if (cfg->fb != ACTUATOR_FB_OFF && cfg->fb != ACTUATOR_FB_SINGLE &&
      cfg->fb != ACTUATOR_FB_DIFFERENTIAL)
    return -1;
  const flicker_spec_t off = {0.0, 0.0, 0.0};
  const flicker_spec_t *spec[4] = {&cfg->drive_noise, &cfg->drive_noise, &cfg->fb_noise,
                                   &cfg->fb_noise};
  /* the grounded electrode of FB_SINGLE and both electrodes of FB_OFF carry no noise */
  if (cfg->fb == ACTUATOR_FB_OFF) spec[2] = &off;
  if (cfg->fb != ACTUATOR_FB_DIFFERENTIAL) spec[3] = &off;
  /* everything that can fail is checked before a is touched; then built in place */
  for (int i = 0; i < 4; i++)
    if (flicker_check(spec[i], cfg->fs_hz) != 0) return -1;
  a->cfg = *cfg;
  for (int i = 0; i < 4; i++)
    (void)flicker_init(&a->noise[i], spec[i], a->cfg.fs_hz, seed,
                       ACTUATOR_RNG_STREAM_U1 + (uint64_t)i);
  return 0;
}

/* mean((v + w)^2) over the sample, w held */
static double mean_sq_with_noise(const dac_chan_out_t *c, double w)
{
  return c->mean_sq_v2 + w * (2.0 * c->mean_v + w);
}

void actuator_step(actuator_t *a, const dac_out_t *dac, actuator_out_t *out)
{
  double w[4];
  for (int i = 0; i < 4; i++) w[i] = flicker_step(&a->noise[i]);
  /* (6-7) on the drive comb */
  out->f_drive_mps2 = a->cfg.ks_drive_mps2_per_v2 *
                      (mean_sq_with_noise(&dac->ch[HAL_DAC_DRIVE_U1], w[0]) -
                       mean_sq_with_noise(&dac->ch[HAL_DAC_DRIVE_U2], w[1]));
  const dac_chan_out_t *s = &dac->ch[HAL_DAC_SPARE];
  const double vb = a->cfg.fb_bias_v;
  switch (a->cfg.fb) {
  case ACTUATOR_FB_SINGLE:
    out->f_sense_mps2 = a->cfg.ks_fb_mps2_per_v2 * mean_sq_with_noise(s, w[2]);
    break;
  case ACTUATOR_FB_DIFFERENTIAL: {
    /* mean((Vb + u + w3)^2) - mean((Vb - u + w4)^2), expanded so that the Vb^2 terms
     * cancel exactly */
    const double p3 = vb + w[2], p4 = vb + w[3];
    const double m3 = p3 * p3 + 2.0 * p3 * s->mean_v + s->mean_sq_v2;
    const double m4 = p4 * p4 - 2.0 * p4 * s->mean_v + s->mean_sq_v2;
    out->f_sense_mps2 = a->cfg.ks_fb_mps2_per_v2 * (m3 - m4);
    break;
  }
  case ACTUATOR_FB_OFF:
  default: out->f_sense_mps2 = 0.0; break;
  }
  for (int i = 0; i < 4; i++) out->noise_v[i] = w[i];
}
