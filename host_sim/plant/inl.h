/* Integral nonlinearity of a converter's transfer function, in LSB, for the plant's ADC
 * and DAC (host plant, double precision).
 *
 * INL(c) is the deviation of the converter's level at code c from the straight line
 * through its end points (W. Kester (ed.), The Data Conversion Handbook, Analog Devices /
 * Newnes 2005, §2.4: "integral nonlinearity", end-point definition), c = 0..2^bits - 1
 * in offset binary. Two parts, each off at zero:
 *   bow:  INL_bow(c) = bow_lsb (1 - ((c - m) / m)^2),  m = 2^(bits-1): the smooth
 *         parabolic bow of a converter whose gain varies along the range (a resistor
 *         string's or a capacitor array's voltage coefficient); bow_lsb at mid-scale,
 *         zero at both ends; an even-order distortion (second harmonic).
 *   code: the per-code pattern of a binary-weighted converter (charge-redistribution
 *         SAR or R-2R ladder, McCreary & Gray, IEEE J. Solid-State Circuits 10 (1975)
 *         371): bit i weighs 2^i (1 + e_i) LSB, so the level of code c is off by
 *         sum_i b_i(c) e_i 2^i, which jumps at the major carries. A bit made of 2^i unit
 *         elements with independent mismatch has a weight error of rms sigma_u 2^(i/2)
 *         (Pelgrom et al., IEEE J. Solid-State Circuits 24 (1989) 1433: sigma ~ 1/sqrt
 *         (area)), so the weight errors are drawn once, E_i = e_i 2^i ~ N(0, code_lsb^2
 *         2^(i - (bits-1))): code_lsb is the rms error of the most significant bit, in
 *         LSB. The end-point line is taken out: INL_code(c) = sum_i b_i(c) E_i -
 *         c / (2^bits - 1) sum_i E_i, zero at both ends.
 * The pattern belongs to the part: drawn from rng_seed(seed, stream) at init. */
#ifndef PLANT_INL_H
#define PLANT_INL_H

#include <stdint.h>

#define INL_MAX_BITS 16

typedef struct {
  double bow_lsb;  /* INL at mid-scale of the parabolic bow, LSB (either sign) */
  double code_lsb; /* rms weight error of the most significant bit, LSB (>= 0) */
} inl_cfg_t;

typedef struct {
  int bits;
  int active;                   /* 0: INL 0 at every code, nothing drawn */
  int pattern;                  /* the per-code part is on (code_lsb > 0) */
  double bow_lsb;               /* as configured */
  double mid;                   /* 2^(bits-1) */
  double err_lsb[INL_MAX_BITS]; /* E_i, weight error of bit i, LSB */
  double slope_lsb;             /* sum_i E_i / (2^bits - 1): the end-point line */
  /* sum_i b_i(c) E_i by nibbles of the code, built at init: four lookups per conversion
   * instead of a loop over the bits (the DAC converts four channels every sample) */
  double nib_lsb[INL_MAX_BITS / 4][16];
} inl_t;

/* 0 if cfg is usable for a converter of bits (1..INL_MAX_BITS): finite, |bow| <= 2^bits,
 * 0 <= code_lsb <= 2^bits. -1 otherwise. */
int inl_check(const inl_cfg_t *cfg, int bits);

/* Validates, draws the weight errors. Returns 0, or -1 with n unchanged. */
int inl_init(inl_t *n, const inl_cfg_t *cfg, int bits, uint64_t seed, uint64_t stream);

/* INL at code c (offset binary, clamped to the range), LSB. 0 when not active. Inline:
 * the DAC converts four channels every sample. */
static inline double inl_lsb(const inl_t *n, long code)
{
  if (!n->active) return 0.0;
  const long top = (1L << n->bits) - 1L;
  if (code < 0) code = 0;
  if (code > top) code = top;
  double e = 0.0;
  if (n->bow_lsb != 0.0) {
    const double u = ((double)code - n->mid) / n->mid;
    e = n->bow_lsb * (1.0 - u * u);
  }
  if (n->pattern) {
    const unsigned long c = (unsigned long)code;
    const double s = n->nib_lsb[0][c & 15u] + n->nib_lsb[1][(c >> 4) & 15u] +
                     n->nib_lsb[2][(c >> 8) & 15u] + n->nib_lsb[3][(c >> 12) & 15u];
    e += s - (double)code * n->slope_lsb;
  }
  return e;
}

#endif /* PLANT_INL_H */
