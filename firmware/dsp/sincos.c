#include "dsp/sincos.h"

#include "dsp/math_const.h"

#define SINCOS_TWO_PI_OVER_2P32_F 1.46291808e-9f /* 2*pi/2^32, rad per phase count */
#define SINCOS_TURNS_LIMIT_F 8388608.0f          /* 2^23 turns: no fraction left */
#define SINCOS_2P31_F 2147483648.0f

uint32_t sincos_rad_to_phase(float rad)
{
  const float turns = rad * FM_INV_TWO_PI_F;
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
