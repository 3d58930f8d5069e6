/* Measurements of the comparison: frequency response of a demodulator alone by AM tones
 * (lock-in fit of its in-phase output), -3 dB bandwidth by bisection, tuning a
 * demodulator's parameter to a bandwidth by bisection, tone fit and settling time. */
#ifndef DEMOD_MEASURE_H
#define DEMOD_MEASURE_H

#include <stddef.h>

#include "demod_bank.h"

typedef struct {
  double fs_hz;
  double fc_hz;
  const float *ref_sin; /* NCO references, n_ref samples from phase 0 */
  const float *ref_cos;
  const double *carrier; /* the input carrier sin(wc k) in double, n_ref samples */
  size_t n_ref;
} bench_t;

/* Bandwidth search range; the transient skipped before a tone is fitted and the least
 * fit length. The skip is at least 12 time constants of a first-order lag of 50 Hz, the
 * lowest bandwidth the tool tunes to (MEAS_BW_MIN_HZ). */
#define MEAS_F_LO_HZ 5.0
#define MEAS_BW_MIN_HZ 50.0
#define MEAS_SKIP_S 0.04
#define MEAS_FIT_S 0.04
/* references needed: skip + fit, the fit rounded up to whole periods of MEAS_F_LO_HZ */
#define MEAS_REF_S (MEAS_SKIP_S + MEAS_FIT_S + 1.0 / MEAS_F_LO_HZ)

/* Fit y(k) ~ a sin(w k) + b cos(w k) + c over k in [k0, k1); returns the amplitude
 * hypot(a, b) and the phase atan2(b, a) in degrees (y = amp sin(w k + phase) + c). */
void fit_tone(const double *y, size_t k0, size_t k1, double f_hz, double fs_hz, double *amp,
              double *phase_deg);

/* Gain and phase (deg) of the in-phase output for the noise-free AM input
 * sin(2 pi fm t) sin(wc t), the demodulator alone, fitted over whole modulation periods
 * after MEAS_SKIP_S. Returns 0, or -1. */
int meas_am_response(const bench_t *b, demod_kind_t kind, double param, double fm_hz,
                     double *gain, double *phase_deg);

/* Measured -3 dB frequency of the demodulator alone: bisection on log f between
 * MEAS_F_LO_HZ and fc/2 for gain = 1/sqrt(2), to 1e-4 relative. +INFINITY when the gain at fc/2 is still
 * above it (no band limit below the carrier: the bare multiplier), 0 when the gain at
 * MEAS_F_LO_HZ is already below it, NaN for a parameter the kernel rejects. */
double meas_bw_hz(const bench_t *b, demod_kind_t kind, double param);

/* The parameter whose measured bandwidth is target_hz (MEAS_BW_MIN_HZ .. fc/3), with
 * the bandwidth it gives in *bw_hz (within 5e-4 relative): bisection on the log of the
 * parameter inside a bracket around the first-order estimate (lmsd mu ~ w, rlsd
 * 1 - lambda ~ w, kfd R ~ q / (2 w^2), mult cut-off ~ f, w = 2 pi f / fs), widened
 * until it holds the target. NaN when no bracket is found. */
double meas_tune(const bench_t *b, demod_kind_t kind, double target_hz, double *bw_hz);

/* Time after which y stays within rel_band * |final| of final (s); 0 if always. */
double settle_time_s(const double *y, size_t n, double final, double rel_band, double fs_hz);

#endif /* DEMOD_MEASURE_H */
