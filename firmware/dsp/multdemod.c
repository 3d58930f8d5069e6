#include "dsp/multdemod.h"

#include <math.h>
#include <stddef.h>

int multdemod_init(multdemod_t *m, const multdemod_cfg_t *cfg)
{
  if (m == NULL || cfg == NULL || cfg->num_sections > BIQUAD_MAX_SECTIONS ||
      (cfg->num_sections > 0u && cfg->sections == NULL)) {
    return -1;
  }
  if (cfg->num_sections == 0u) {
    /* No low-pass: an empty cascade passes its input through. */
    m->lp_i.num_sections = 0u;
    m->lp_q.num_sections = 0u;
  } else {
    biquad_cascade_t lp;
    if (biquad_cascade_init(&lp, cfg->sections, cfg->num_sections) != 0) {
      return -1; /* checked on a copy so that *m stays unchanged */
    }
    m->lp_i = lp;
    m->lp_q = lp;
  }
  m->i = 0.0f;
  m->q = 0.0f;
  return 0;
}

int multdemod_reset(multdemod_t *m, float in_phase, float quadrature)
{
  if (m == NULL || !isfinite(in_phase) || !isfinite(quadrature)) {
    return -1;
  }
  /* The products' mean is (A1, A2); their 2 wc part averages out of the low-pass. */
  biquad_cascade_reset(&m->lp_i, in_phase);
  biquad_cascade_reset(&m->lp_q, quadrature);
  m->i = in_phase;
  m->q = quadrature;
  return 0;
}
