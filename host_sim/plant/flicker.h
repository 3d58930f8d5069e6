/* Seeded 1/f (flicker) plus white noise generator for the plant's voltage-noise sources
 * (thesis §6.3.2: the drive voltages carry 1/f noise, fig. 6-5, 7-6, 7-7).
 *
 * Target one-sided PSD (unit^2/Hz), f above fmin_hz:
 *     S(f) = W^2 + K^2 / f,   W = white_rthz, K = flicker_1hz_rthz,
 * flat below about fmin_hz. The corner where the two meet is fc = (K / W)^2 (capped at
 * fs/20; with W = 0 the spectrum is 1/f up to fs/20 and white above).
 *
 * Design: one Gaussian white sequence per sample (variance fs/2, i.e. unit one-sided
 * density) through a cascade of first-order shelving sections
 *     H(s) = g prod_i (1 + s/z_i) / (1 + s/p_i),
 * zeros and poles interleaved one per decade from fmin up to the corner (slope
 * -10 dB/decade), the top two pairs placed relative to fc so the cascade also gives the
 * knee and the white floor (tools/flicker_design.py: peak error +-0.28 dB of the analog
 * layout against W^2 + K^2/f from four decades below to four above fc). Each section
 * is discretised by the bilinear transform (its flat top maps onto Nyquist, so the
 * white floor stays flat up to fs/2), and g is the least-squares (in dB) fit of the
 * discrete |H|^2 to S(f) over [10 fmin, 0.45 fs].
 *
 * Realisation: the discrete cascade in parallel form (partial fractions in z^-1),
 *     H(z) = c0 + sum_i r_i / (1 - rho_i z^-1),
 * the same filter; only the rounding differs. A branch whose pole is fast (above
 * fs / (FLICKER_BLOCK FLICKER_SLOW_MARGIN)) runs every sample. The slow branches (the
 * 1/f decades, most of them) change little within a block of FLICKER_BLOCK samples, so
 * they run once a block on the block's input sum,
 *     W_i <- rho_i^M W_i + r_i g_i S,   g_i = (1 - rho_i^M) / ((1 - rho_i) M)
 * (g_i keeps each branch's DC gain exact), and their sum is interpolated linearly
 * between block ends. The interpolation needs the next block end, so the slow part
 * comes out one block late; the fast part is delayed by the same M samples (a ring),
 * so the two stay aligned and the output is the cascade's, M samples late (0.64 ms at
 * 50 kHz: a delay of a noise source changes none of its statistics). How close:
 * tests/unit/test_flicker.c runs the cascade itself on the same draws; every octave
 * band's level agrees within 0.25 dB (measured: within 0.03 dB for the electrodes'
 * default, 0.14 dB near fs/64 for a pure 1/f to fs/20).
 * Cost per sample: one Gaussian, the fast branches (one to three) and the
 * interpolation, against 3 multiply-adds for every section of the cascade (about 6
 * for fmin 1 mHz, fc 100 Hz; 8 for a pure 1/f to fs/20). A generator with no slow
 * branch has no delay.
 *
 * The cascade starts at rest: spectral content below f needs about 1/(2 pi f) seconds
 * to reach its stationary level.
 */
#ifndef PLANT_FLICKER_H
#define PLANT_FLICKER_H

#include <stdint.h>

#include "plant/gauss_zig.h"
#include "plant/rng.h"

#define FLICKER_MAX_SECTIONS 16
#define FLICKER_BLOCK 32        /* M: samples per slow-branch update */
#define FLICKER_SLOW_MARGIN 100 /* slow: pole below the block rate / this */

typedef struct {
  double white_rthz;       /* one-sided white density W, unit/sqrt(Hz); >= 0 */
  double flicker_1hz_rthz; /* one-sided density of the 1/f part at 1 Hz, K; >= 0 */
  double fmin_hz;          /* 1/f spectrum flattens below this; > 0 */
} flicker_spec_t;

typedef struct {
  int active;       /* 0: W = K = 0, output 0, no random draws */
  int nsec;         /* 0: white only */
  double in_sd;     /* sd of the section input per sample, gain included */
  double corner_hz; /* fc actually used (0 for white only) */
  double c0;        /* direct term of the parallel form */
  int nfast, nslow; /* branches run every sample / once a block */
  double fast_r[FLICKER_MAX_SECTIONS], fast_rho[FLICKER_MAX_SECTIONS];
  double fast_w[FLICKER_MAX_SECTIONS];
  double slow_a[FLICKER_MAX_SECTIONS]; /* rho_i^M */
  double slow_b[FLICKER_MAX_SECTIONS]; /* r_i g_i */
  double slow_w[FLICKER_MAX_SECTIONS];
  double block_sum;           /* input summed over the block so far */
  int block_k;                /* position in the block, 0..M-1 */
  double slow_base, slow_end; /* slow part at the last two block ends */
  double slow_step;           /* (slow_end - slow_base) / M */
  double ring[FLICKER_BLOCK]; /* fast part, M samples late */
  rng_t rng;
} flicker_t;

/* The cascade a spec designs (the filter the generator realises, for tests and
 * reports): n sections y = b0 x + b1 x[-1] - a1 y[-1] with their analog poles, driven
 * by white input of sd in_sd per sample (gain included); n = 0: white only. */
typedef struct {
  int n;
  double in_sd, corner_hz;
  double b0[FLICKER_MAX_SECTIONS], b1[FLICKER_MAX_SECTIONS], a1[FLICKER_MAX_SECTIONS];
  double pole_hz[FLICKER_MAX_SECTIONS];
} flicker_cascade_t;

/* Designs the cascade of (spec, fs_hz): 0, or -1 (flicker_check fails; c unchanged). */
int flicker_design(const flicker_spec_t *spec, double fs_hz, flicker_cascade_t *c);

/* 0 if flicker_init would accept (spec, fs_hz): finite, W, K >= 0, fs > 0; if K > 0:
 * 0 < fmin <= fs/1000 and fc/fmin small enough for FLICKER_MAX_SECTIONS, about 1e13.
 * -1 otherwise (also for spec == NULL). */
int flicker_check(const flicker_spec_t *spec, double fs_hz);

/* Validates (flicker_check), designs the cascade and seeds the generator with
 * rng_seed(seed, stream). Returns 0, or -1 with f unchanged. Built in place (no copy of
 * flicker_t on the stack). */
int flicker_init(flicker_t *f, const flicker_spec_t *spec, double fs_hz, uint64_t seed,
                 uint64_t stream);

/* Next sample of an active generator (unit of the spec). */
double flicker_step_active(flicker_t *f);

/* Next sample (unit of the spec); 0 from a generator that is off. Inline: the plant asks
 * every generator every sample, most of them off in most parts. */
static inline double flicker_step(flicker_t *f)
{
  return f->active ? flicker_step_active(f) : 0.0;
}

/* The analytic target W^2 + K^2/f of the spec (fc cap applied), one-sided unit^2/Hz,
 * valid above about 10 fmin (for tests and reports). */
double flicker_target_psd(const flicker_spec_t *spec, double fs_hz, double f_hz);

#endif /* PLANT_FLICKER_H */
