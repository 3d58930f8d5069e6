#include "gyro/drive_synth.h"

#include <math.h> /* NAN (a constant, no call) */
#include <stddef.h>
#include <string.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"

#define SYNTH_INF_BITS 0x7F800000u /* +infinity's bit pattern */

int drive_synth_init(drive_synth_t *ds, const drive_synth_cfg_t *cfg)
{
  if (ds == NULL || cfg == NULL || !fm_isfinite(cfg->u_max_v) || !(cfg->u_max_v > 0.0f) ||
      !fm_isfinite(cfg->dc_bias_v)) {
    return -1;
  }
  if (cfg->scheme == GYRO_DRIVE_DC_AC) {
    if (!(cfg->dc_bias_v > 0.0f) || !(cfg->dc_bias_v < cfg->u_max_v)) {
      return -1;
    }
  } else if (cfg->scheme != GYRO_DRIVE_HALF_FREQ) {
    return -1;
  }
  ds->scheme = cfg->scheme;
  ds->dc_bias_v = cfg->dc_bias_v;
  ds->u_max_v = cfg->u_max_v;
  ds->inv_4d = (cfg->scheme == GYRO_DRIVE_DC_AC) ? 0.25f / cfg->dc_bias_v : 0.0f;
  ds->a_v = 0.0f;
  ds->off = 0u;
  ds->f_set_v2 = ds->p_set_rad = NAN;
  ds->p_turn_rad = 0.0f;
  return 0;
}

float drive_synth_f_cmd_max(const drive_synth_t *ds)
{
  if (ds->scheme == GYRO_DRIVE_DC_AC) {
    /* |U| <= D + A <= u_max  =>  A <= u_max - D, f = 4 D A. */
    return 4.0f * ds->dc_bias_v * (ds->u_max_v - ds->dc_bias_v);
  }
  return ds->u_max_v * ds->u_max_v;
}

/* P less the turns taken off, kept within 1.5 pi of them: out of the command's tick (a P
 * that has moved a turn, or a non-finite one), so that the common path of
 * drive_synth_set compares once. */
GYRO_RAMFUNC static float synth_wrap_turns(drive_synth_t *ds, float p_rad)
{
  if (p_rad > 1.5f * FM_PI_F) {
    ds->p_turn_rad += FM_TWO_PI_F;
    p_rad -= FM_TWO_PI_F;
  } else if (p_rad < -1.5f * FM_PI_F) {
    ds->p_turn_rad -= FM_TWO_PI_F;
    p_rad += FM_TWO_PI_F;
  }
  /* A non-finite command (a NaN the supervisor has not caught yet: it looks once per
   * block) drives nothing rather than a rail voltage; a P still outside the +-2 pi that
   * the phase conversion needs (NaN included: the comparison fails) is replaced by 0
   * and the turns are forgotten. */
  if (!(fm_absf(p_rad) < SINCOS_HALF_RAD_MAX_F)) {
    p_rad = 0.0f;
    ds->p_turn_rad = 0.0f;
  }
  return p_rad;
}

GYRO_RAMFUNC void drive_synth_set(drive_synth_t *ds, float f_cmd_v2, float p_rad)
{
  ds->f_set_v2 = f_cmd_v2;
  ds->p_set_rad = p_rad;
  p_rad -= ds->p_turn_rad;
  /* Within 1.5 pi of the turns (the common case) it is also within the conversion's
   * +-2 pi: one compare of the magnitude decides (VABS, exact; a NaN fails the compare
   * and takes the rare path too). */
  if (GYRO_UNLIKELY(!(__builtin_fabsf(p_rad) <= 1.5f * FM_PI_F))) {
    p_rad = synth_wrap_turns(ds, p_rad);
  }
  /* A positive finite force, else none: 0 < f < infinity as one unsigned compare of the
   * bit pattern (the positive finite floats are the patterns 1 .. that of infinity less
   * one), in a core register instead of two float compares; +0 by a mask, as a select
   * would become a literal load of 0.0f again. */
  uint32_t f_bits;
  memcpy(&f_bits, &f_cmd_v2, sizeof f_bits);
  f_bits &= 0u - (uint32_t)(f_bits - 1u < SYNTH_INF_BITS - 1u);
  float f;
  memcpy(&f, &f_bits, sizeof f);
  if (ds->scheme == GYRO_DRIVE_DC_AC) {
    /* Force phase P = twice the half-angle phase: exact modulo 2^32. */
    ds->off = 2u * sincos_half_rad_to_phase(p_rad);
    ds->a_v = f * ds->inv_4d;
  } else {
    ds->off = sincos_half_rad_to_phase(p_rad);
    ds->a_v = fm_sqrtf(f);
  }
}
