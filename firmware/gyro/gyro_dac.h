/* The DAC conversion of the sample path (drive electrodes, analog rate output, the
 * self-test force), and the design's fault level of the rate output. */
#ifndef GYRO_DAC_H
#define GYRO_DAC_H

#include <stdint.h>
#include <string.h>

#include "dsp/ramfunc.h" /* GYRO_UNLIKELY */
#include "hal/hal_dac.h"

#if defined(__ARM_FEATURE_DSP)
#include <arm_acle.h> /* __qadd, __usat */
#endif

/* Volts to an offset-binary DAC code, rounded to the nearest code (ties to even) and
 * clamped to the converter's range; NaN gives the mid code (0 V).
 * Per sample, for three channels, so without float compares (each a VCMP, a VMRS and a
 * branch on the FPv4-SP, which has no VMIN/VMAX).
 * On the Cortex-M4F the FPU rounds to an integer itself: VCVTR rounds by FPSCR's mode
 * (round to nearest, ties to even: the reset default of FPSCR and of FPDSCR, which an
 * interrupt's FPSCR comes from; the firmware changes neither),
 * saturates to int32 and gives 0 for NaN; QADD adds the mid code without wrapping and
 * USAT clamps to the code's 14 bits: with the VMUL and the VMOV to a core register five
 * instructions, one constant and no branch, where the portable form below needs two
 * constants (literal loads) and a compare and branch.
 * Elsewhere (the host): adding 1.5 * 2^23 to the code makes the float adder round it to
 * an integer (the sum's unit in the last place is 1 for sums in [2^23, 2^24)) and leaves
 * it in the low mantissa bits: in range, the code is the sum's bit pattern less that of
 * 1.5 * 2^23, and one unsigned compare tells that it is in range. Outside, the bit
 * pattern of a float grows with its value while the sign is clear: below 1.5 * 2^23 or
 * negative is code 0, above is the largest code (infinity included).
 * Both give the same code for every float: the mid code is an even integer, so rounding
 * before adding it or after is the same rounding (checked for all 2^32 inputs against a
 * model of the three instructions, and on the target for the ties and the special
 * values). IEEE 754 single precision with round-to-nearest, the same on host and target. */
#define GYRO_DAC_ROUND_F 12582912.0f    /* 1.5 * 2^23 */
#define GYRO_DAC_ROUND_BITS 0x4B400000u /* its bit pattern */
#if defined(__ARM_FP) && defined(__ARM_FEATURE_DSP) && defined(__thumb2__)
_Static_assert(HAL_DAC_CODE_MAX == (1u << 14) - 1u, "USAT's bit count is the code's width");
static inline uint16_t gyro_volts_to_dac(float v)
{
  float n_code; /* the signed code from mid-scale, rounded, as an int32 bit pattern */
  __asm__("vcvtr.s32.f32 %0, %1" : "=t"(n_code) : "t"(v * (1.0f / HAL_DAC_V_PER_CODE)));
  int32_t n;
  memcpy(&n, &n_code, sizeof n);
  return (uint16_t)__usat(__qadd(n, (int32_t)HAL_DAC_CODE_MID), 14);
}
#else
static inline uint16_t gyro_volts_to_dac(float v)
{
  const float m = v * (1.0f / HAL_DAC_V_PER_CODE) + ((float)HAL_DAC_CODE_MID + GYRO_DAC_ROUND_F);
  uint32_t u;
  memcpy(&u, &m, sizeof u);
  uint32_t code = u - GYRO_DAC_ROUND_BITS;
  if (GYRO_UNLIKELY(code > HAL_DAC_CODE_MAX)) {
    if ((u << 1) > 0xFF000000u) { /* exponent all ones, mantissa not zero: NaN */
      code = HAL_DAC_CODE_MID;
    } else {
      code = (u & 0x80000000u) != 0u || u < GYRO_DAC_ROUND_BITS ? 0u : HAL_DAC_CODE_MAX;
    }
  }
  return (uint16_t)code;
}
#endif

#endif /* GYRO_DAC_H */
