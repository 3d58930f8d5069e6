/* The board's voltage reference, shared by the ADC and the DAC (host plant, double).
 *
 * A converter's full scale is a multiple of its reference, so a relative reference error
 * r(t) scales the DAC's output (code * lsb (1 + r)) and divides what the ADC reads
 * (code = v / (lsb (1 + r))): one noise, seen with opposite signs by the two converters,
 * which is why a shared reference partly cancels in a ratio. Band-gap and buried-Zener
 * references have a white floor and 1/f noise below a corner of a few to tens of Hz
 * (W. Kester (ed.), The Data Conversion Handbook, Analog Devices / Newnes 2005, §7.1:
 * reference noise, the 0.1-10 Hz peak-to-peak figure of the 1/f region). Here:
 *   r(t): one-sided PSD W^2 + K^2 / f (relative, 1/Hz), flat below fmin_hz,
 * generated per sample by flicker.h (the same generator as the electrode-voltage noise).
 * W = K = 0: r = 0 and nothing is drawn. Stream: rng_seed(seed, VREF_RNG_STREAM). */
#ifndef PLANT_VREF_H
#define PLANT_VREF_H

#include <stdint.h>

#include "plant/flicker.h"

#define VREF_RNG_STREAM 0x7201u

typedef struct {
  flicker_spec_t noise; /* relative: white_rthz, flicker_1hz_rthz in 1/sqrt(Hz) */
} vref_cfg_t;

typedef struct {
  int active;
  double rel; /* r of the current sample */
  flicker_t gen;
} vref_t;

/* 0 if flicker_check accepts the spec at fs_hz. */
int vref_check(const vref_cfg_t *cfg, double fs_hz);

/* Validates and seeds. Returns 0, or -1 with v unchanged. */
int vref_init(vref_t *v, const vref_cfg_t *cfg, double fs_hz, uint64_t seed);

/* Next sample's relative error r (0 when not active). */
double vref_step(vref_t *v);

#endif /* PLANT_VREF_H */
