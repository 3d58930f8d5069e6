#include "dsp/sincos.h"

/* Bits of the phase below the table index: the interpolation position. */
#define SINCOS_FRAC_BITS (32u - SINCOS_TABLE_BITS)
#define SINCOS_FRAC_MASK ((1u << SINCOS_FRAC_BITS) - 1u)
/* 2^-SINCOS_FRAC_BITS, exact in float; scales the low phase bits to [0, 1). */
#define SINCOS_FRAC_SCALE (1.0f / (float)(1u << SINCOS_FRAC_BITS))
/* cos(t) = sin(t + pi/2): a quarter turn. Its low SINCOS_FRAC_BITS bits are zero, so
 * the cosine shares the sine's interpolation position. */
#define SINCOS_QUARTER_TURN 0x40000000u

#define SINCOS_INV_TWO_PI_F 0.159154943f        /* 1/(2*pi) */
#define SINCOS_TWO_PI_OVER_2P32_F 1.46291808e-9f /* 2*pi/2^32, rad per phase count */
#define SINCOS_TURNS_LIMIT_F 8388608.0f          /* 2^23 turns: no fraction left */
#define SINCOS_2P31_F 2147483648.0f

void sincos_lut(uint32_t phase, float *sin_out, float *cos_out)
{
  const uint32_t is = phase >> SINCOS_FRAC_BITS;
  const uint32_t ic = (phase + SINCOS_QUARTER_TURN) >> SINCOS_FRAC_BITS;
  /* The low bits are < 2^20, so the conversion to float is exact. */
  const float x = (float)(phase & SINCOS_FRAC_MASK) * SINCOS_FRAC_SCALE;
  const float s0 = sincos_table[is];
  const float c0 = sincos_table[ic];
  *sin_out = s0 + x * (sincos_table[is + 1u] - s0); /* (5-14) */
  *cos_out = c0 + x * (sincos_table[ic + 1u] - c0);
}

uint32_t sincos_rad_to_phase(float rad)
{
  const float turns = rad * SINCOS_INV_TWO_PI_F;
  /* Written so that NaN fails it too. */
  if (!(turns > -SINCOS_TURNS_LIMIT_F && turns < SINCOS_TURNS_LIMIT_F)) {
    return 0u;
  }
  /* |turns| < 2^23: the integer part fits int32_t and the subtraction is exact, so the
   * fraction lies in (-1, 1) and frac * 2^31 in (-2^31, 2^31): no overflow below. */
  const float frac = turns - (float)(int32_t)turns;
  const int32_t half_counts = (int32_t)(frac * SINCOS_2P31_F);
  /* Conversion to unsigned is modulo 2^32: a negative fraction becomes 2*pi - |frac|. */
  return (uint32_t)half_counts * 2u;
}

float sincos_phase_to_rad(uint32_t phase)
{
  /* Two's-complement reading of the phase without an implementation-defined cast. */
  const int32_t s = (phase < 0x80000000u) ? (int32_t)phase : -(int32_t)(~phase) - 1;
  return (float)s * SINCOS_TWO_PI_OVER_2P32_F;
}
