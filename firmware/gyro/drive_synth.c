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
  ds->re_v = ds->im_v = 0.0f;
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
  if (!(fm_absf_cmp(p_rad) < SINCOS_HALF_RAD_MAX_F)) {
    p_rad = 0.0f;
    ds->p_turn_rad = 0.0f;
  }
  return p_rad;
}

/* P less the turns, ready for the half-angle conversion. Within 1.5 pi of the turns (the
 * common case) it is also within the conversion's +-2 pi: one compare of the magnitude
 * decides (a NaN fails it and takes the rare path too). */
GYRO_RAMFUNC static inline float synth_turns_off(drive_synth_t *ds, float p_rad)
{
  p_rad -= ds->p_turn_rad;
  if (GYRO_UNLIKELY(!(fm_absf_cmp(p_rad) <= 1.5f * FM_PI_F))) {
    p_rad = synth_wrap_turns(ds, p_rad);
  }
  return p_rad;
}

/* The amplitude phasor a + j b turned by the phase offset off: the waveform's phasor
 * (drive_synth_step), one table lookup per command instead of one per sample. */
GYRO_RAMFUNC static inline void synth_turn(drive_synth_t *ds, uint32_t off, float a_v, float b_v)
{
  float s, c;
  sincos_lut(off, &s, &c);
  ds->off = off;
  ds->re_v = a_v * c - b_v * s;
  ds->im_v = a_v * s + b_v * c;
}

GYRO_RAMFUNC void drive_synth_set(drive_synth_t *ds, float f_cmd_v2, float p_rad)
{
  ds->f_set_v2 = f_cmd_v2;
  ds->p_set_rad = p_rad;
  p_rad = synth_turns_off(ds, p_rad);
  /* A positive finite force, else none: 0 < f < infinity as one unsigned compare of the
   * bit pattern (the positive finite floats are the patterns 1 .. that of infinity less
   * one), in a core register instead of two float compares; +0 by a mask, as a select
   * would become a literal load of 0.0f again. */
  uint32_t f_bits;
  memcpy(&f_bits, &f_cmd_v2, sizeof f_bits);
  f_bits &= 0u - (uint32_t)(f_bits - 1u < SYNTH_INF_BITS - 1u);
  float f;
  memcpy(&f, &f_bits, sizeof f);
  const uint32_t half = sincos_half_rad_to_phase(p_rad);
  if (ds->scheme == GYRO_DRIVE_DC_AC) {
    /* Force phase P = twice the half-angle phase: exact modulo 2^32. */
    synth_turn(ds, 2u * half, f * ds->inv_4d, 0.0f);
  } else {
    synth_turn(ds, half, fm_sqrtf(f), 0.0f);
  }
}

/* x / 2, and 0 for a negative x: |F| - |Re F| is >= 0 but its rounding can leave an ulp
 * below, whose root would be NaN. */
GYRO_RAMFUNC static inline float half_nonneg(float x)
{
  x *= 0.5f;
  return x > 0.0f ? x : 0.0f;
}

/* The force as a phasor F = |F| e^(j arg F) in a frame turned by frame_rad: the force
 * |F| cos(phi + frame + arg F). Half-frequency: the voltage phasor is the square root of
 * F, A e^(j arg F / 2) with A^2 = |F| (6-25), taken as the principal root,
 *   Re sqrt(F) = sqrt((|F| + Re F) / 2),  Im sqrt(F) = sign(Im F) sqrt((|F| - Re F) / 2):
 * the larger of the two from its root, sqrt((|F| + |Re F|) / 2), the other as
 * Im F / (2 x larger), since the root of the difference of two near-equal numbers
 * (|F| - |Re F| with Im F small) would keep none of its digits; the larger part is at
 * least sqrt(|F| / 2), so the divide is safe except at F = 0. Two square roots and a
 * divide (drive_synth_phasor_parts), no arc tangent. Of the two roots +-sqrt(F) (both give
 * the force: U1^2 - U2^2 is the same) it keeps the one nearer the last, so that the
 * voltages do not flip where arg F crosses pi (the principal root's cut). DC+AC:
 * the AC amplitude phasor F / (4 D) (6-21), no root. A non-finite F drives nothing. */
GYRO_RAMFUNC void drive_synth_phasor_mag(drive_synth_phasor_t *ph, float f_re_v2, float f_im_v2)
{
  if (!fm_isfinite(f_re_v2 + f_im_v2)) f_re_v2 = f_im_v2 = 0.0f;
  ph->f_re_v2 = f_re_v2;
  ph->f_im_v2 = f_im_v2;
  ph->mag_v2 = fm_sqrtf(f_re_v2 * f_re_v2 + f_im_v2 * f_im_v2);
}

GYRO_RAMFUNC void drive_synth_phasor_root(const drive_synth_t *ds, drive_synth_phasor_t *ph)
{
  if (ds->scheme == GYRO_DRIVE_DC_AC) return;
  ph->root_v = fm_sqrtf(half_nonneg(ph->mag_v2 + fm_absf(ph->f_re_v2)));
}

GYRO_RAMFUNC void drive_synth_phasor_parts(const drive_synth_t *ds, drive_synth_phasor_t *ph)
{
  const float f_re = ph->f_re_v2, f_im = ph->f_im_v2;
  if (ds->scheme == GYRO_DRIVE_DC_AC) {
    ph->a_v = f_re * ds->inv_4d;
    ph->b_v = f_im * ds->inv_4d;
    return;
  }
  const float t = ph->root_v;
  float a, b;
  if (f_re >= 0.0f) {
    a = t;
    b = t > 0.0f ? f_im / (2.0f * t) : 0.0f;
  } else { /* t > 0: |Re F| > 0 */
    a = fm_absf(f_im) / (2.0f * t);
    b = f_im < 0.0f ? -t : t;
  }
  /* Of the two roots, the one nearer the last: a force near the principal root's cut
   * (Re F < 0, Im F ~ 0: a negative rate with the quadrature nulled, or none) would
   * otherwise flip both voltages whenever noise moves Im F across 0. */
  if (a * ph->a_v + b * ph->b_v < 0.0f) {
    a = -a;
    b = -b;
  }
  ph->a_v = a;
  ph->b_v = b;
}

GYRO_RAMFUNC void drive_synth_set_phasor(drive_synth_t *ds, const drive_synth_phasor_t *ph,
                                         float frame_rad)
{
  ds->f_set_v2 = ds->p_set_rad = NAN; /* not a (f_cmd, P) command: _follow sets again */
  const uint32_t half = sincos_half_rad_to_phase(synth_turns_off(ds, frame_rad));
  /* DC+AC: the frame's phase is twice the half-angle phase, exact modulo 2^32. */
  synth_turn(ds, ds->scheme == GYRO_DRIVE_DC_AC ? 2u * half : half, ph->a_v, ph->b_v);
}
