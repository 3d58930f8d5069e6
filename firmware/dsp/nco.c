#include "dsp/nco.h"

#include <math.h>
#include <stddef.h>

#include "dsp/math_const.h"
#include "dsp/sincos.h"

#define NCO_SIGN_BIT 0x80000000u

static int freq_valid(double freq_hz, double fs_hz)
{
  return isfinite(freq_hz) && isfinite(fs_hz) && fs_hz > 0.0 && freq_hz >= 0.0 &&
         freq_hz < 0.5 * fs_hz;
}

uint32_t nco_half_step_of(double freq_hz, double fs_hz)
{
  /* llround: the conversion of a negative value to uint32_t is then the defined one of
   * an integer (modulo 2^32), never that of a double (undefined). */
  return (uint32_t)llround(freq_hz / fs_hz * 2147483648.0);
}

double nco_freq_of(uint32_t half_step, double fs_hz)
{
  return (double)half_step * fs_hz / 2147483648.0;
}

/* Move the wc phase by a signed change d (two's complement, [-pi, pi)): the wc/2
 * accumulator moves by d/2, an arithmetic shift written without relying on the
 * implementation-defined right shift of a negative int. The lowest bit of d is below
 * the wc resolution (2^-31 turn) and is dropped. */
static void shift_raw(nco_t *nco, uint32_t d)
{
  nco->half_phase += (d >> 1) | (d & NCO_SIGN_BIT);
}

int nco_init(nco_t *nco, const nco_cfg_t *cfg)
{
  if (nco == NULL || cfg == NULL || !freq_valid(cfg->freq_hz, cfg->fs_hz) ||
      !isfinite(cfg->phase_rad)) {
    return -1;
  }
  /* Wrap to [0, 1) turn in double; the wc/2 oscillator starts at half of that. */
  const double turns = cfg->phase_rad / FM_TWO_PI;
  double frac = turns - floor(turns);
  if (!(frac < 1.0)) {
    frac = 0.0; /* -tiny rounds up to exactly 1 turn */
  }
  nco->half_phase = (uint32_t)floor(frac * 2147483648.0 + 0.5);
  nco->half_step = nco_half_step_of(cfg->freq_hz, cfg->fs_hz);
  return 0;
}

int nco_set_freq(nco_t *nco, double freq_hz, double fs_hz)
{
  if (nco == NULL || !freq_valid(freq_hz, fs_hz)) {
    return -1;
  }
  nco->half_step = nco_half_step_of(freq_hz, fs_hz);
  return 0;
}

int nco_set_phase(nco_t *nco, float phase_rad)
{
  if (nco == NULL || !isfinite(phase_rad)) {
    return -1;
  }
  const uint32_t target = sincos_rad_to_phase(phase_rad);
  shift_raw(nco, target - (nco->half_phase << 1));
  return 0;
}

int nco_shift_phase(nco_t *nco, float delta_rad)
{
  if (nco == NULL || !isfinite(delta_rad)) {
    return -1;
  }
  shift_raw(nco, sincos_rad_to_phase(delta_rad));
  return 0;
}
