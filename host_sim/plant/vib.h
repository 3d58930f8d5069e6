/* Random vibration: the stationary Gaussian part of the case acceleration (profile.h,
 * accel_profile_t bands), generated per sample for the g-sensitivity forces (accel.h).
 * Host plant, double precision.
 *
 * A random-vibration test specifies the one-sided acceleration spectral density G
 * (g^2/Hz) over a band (IEC 60068-2-64; MIL-STD-810 method 514); its rms is about
 * sqrt(G (f_hi - f_lo)) (C. M. Harris & A. G. Piersol, Harris' Shock and Vibration
 * Handbook, 5th ed., McGraw-Hill 2002, ch. 24). Each band is white Gaussian noise of
 * one-sided density G (variance G fs / 2 per sample) through a 4th-order Butterworth
 * high-pass at f_lo (none for f_lo = 0: flat from DC) and a 4th-order Butterworth
 * low-pass at f_hi, each as two biquads by the bilinear transform with the corner
 * pre-warped (exact -3 dB corners; maximally flat in between, 24 dB/octave skirts, as a
 * shaker controller's band edges). The gain is set so that the PSD equals G at the
 * band's geometric centre sqrt(f_lo f_hi) (at DC for f_lo = 0); in a band of an octave
 * or more (profile.h requires it) it is within 0.3 dB of G from sqrt(2) f_lo to
 * f_hi / sqrt(2), and the variance is G times the filters' noise bandwidth (about
 * 1.03 (f_hi - f_lo) for a wide band). The values are the per-sample means the mechanics
 * holds, as its Brownian force is. The filters start at rest: the band settles within
 * a few periods of f_lo.
 *
 * Streams: rng_seed(seed, VIB_RNG_STREAM + j) for band j; nothing is drawn without a
 * band. */
#ifndef PLANT_VIB_H
#define PLANT_VIB_H

#include <stdint.h>

#include "plant/profile.h"
#include "plant/rng.h"

#define VIB_RNG_STREAM 0x7301u
#define VIB_MAX_SOS 4

typedef struct {
  int axis;
  int nsos;
  double in_sd; /* sd of the white input per sample, gain included (g) */
  double b[VIB_MAX_SOS][3], a[VIB_MAX_SOS][2];
  double st[VIB_MAX_SOS][2]; /* transposed direct form II states */
  rng_t rng;
} vib_band_t;

typedef struct {
  int n;
  vib_band_t band[PROFILE_MAX_VIB_BANDS];
} vib_t;

/* 0 if the bands of a (which passed accel_profile_check) can be generated at fs_hz: every
 * f_hi below 0.45 fs. Else -1 and *key names the band's field ("band_f_hi_hz[j]"). */
int vib_check(const accel_profile_t *a, double fs_hz, const char **key);

/* Designs and seeds the bands of a. Returns 0, or -1 (vib_check) with v unchanged. */
int vib_init(vib_t *v, const accel_profile_t *a, double fs_hz, uint64_t seed);

/* Adds the next sample of every band to a_g (g, per axis). */
void vib_step(vib_t *v, double a_g[PROFILE_ACCEL_AXES]);

/* The one-sided PSD (g^2/Hz) that band j is designed to have at f_hz: G at its centre,
 * G |H(f)|^2 / |H(centre)|^2 elsewhere. For tests against the generated samples. */
double vib_band_psd(const vib_t *v, int j, double fs_hz, double f_hz);

#endif /* PLANT_VIB_H */
