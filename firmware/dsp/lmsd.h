/* LMS demodulator (LMSD), thesis 5.4.1, single precision.
 *
 * Signal model (5-1): d(k) = A1 sin(wc k) + A2 cos(wc k) + n(k), reference
 * r(k) = [sin(wc k), cos(wc k)]'. State W = [w_i, w_q]' estimates [A1, A2]' (in-phase =
 * coefficient of the sine reference, quadrature = coefficient of the cosine reference;
 * the sign follows the references the caller passes, nothing is negated here).
 *
 * Difference equation (5-2), (5-5), one sample:
 *     err(k) = d(k) - W(k-1)' r(k)
 *     W(k)   = W(k-1) + 2 mu err(k) r(k)
 * 5 multiplies and 4 adds (2 mu is stored premultiplied).
 *
 * Bandwidth as a function of mu. Because |r(k)| = 1 this is normalised LMS (thesis
 * 5.4.1): the same mu gives the same dynamics on any carrier. Averaged over a carrier
 * period, E[r r'] = I/2, so the weight error W - [A1 A2]' decays as (1 - mu)^k: a
 * first-order low-pass on the complex envelope. Exactly, the map from d to the estimate
 * W'r is linear time-invariant (Glover's adaptive notch): with the rotating-frame
 * variable v(k) = (w_q + j w_i) e^{-j wc k} the update is v(k+1) = e^{-j wc}(v - 2 mu
 * Re{v} + 2 mu d), whose poles are the roots of z^2 - 2(1 - mu) cos(wc) z + (1 - 2 mu),
 * radius rho = sqrt(1 - 2 mu) = 1 - mu - mu^2/2 - ... The baseband equivalent is the lag
 * (1 - rho) / (1 - rho z^-1), whose -3 dB frequency is
 *     f_3dB = fs / (2 pi) * acos(1 - (1 - rho)^2 / (2 rho))  ~=  mu fs / (2 pi)
 * (lmsd_bandwidth_hz). Measured with AM tones at fc = 1750 Hz, fs = 50 kHz it holds to
 * 0.6 % at mu = 0.034 and 1.5 % at mu = 0.05 (the bandpass is slightly asymmetric
 * about wc, which the baseband model ignores); mu = 0.034 gives 280 Hz by the formula,
 * 282 Hz measured, and a time constant of 29 samples. The same update also puts a 2 wc
 * ripple of amplitude about mu |err| / (2 sin wc) on the weights (the cos 2wc part of
 * r r' integrated), which is there only while err is non-zero (transients, noise) and
 * is 4 % of err at mu = 0.034: a multiplicative demodulator leaves 100 % of the
 * amplitude at 2 wc.
 *
 * Stability: 0 < mu <= 0.5 (at 0.5 each step cancels the error along r; beyond it the
 * poles turn negative and the estimate rings). The inputs are ADC- and NCO-derived and
 * always finite; a non-finite sample would stay in W until lmsd_reset().
 */
#ifndef LMSD_H
#define LMSD_H

#include <stdint.h>

#define LMSD_MU_MAX 0.5f

typedef struct {
  float mu; /* step size (5-5), 0 < mu <= LMSD_MU_MAX; thesis 0.034 at 50 kHz */
} lmsd_cfg_t;

typedef struct {
  float w_i;    /* in-phase estimate, coefficient of ref_sin (A1) */
  float w_q;    /* quadrature estimate, coefficient of ref_cos (A2) */
  float two_mu; /* 2 mu of (5-5) */
} lmsd_t;

/* Validate cfg and start from W = 0 (thesis initialisation). Returns 0, or -1 and
 * leaves *s unchanged for a NULL pointer or mu not in (0, LMSD_MU_MAX]. */
int lmsd_init(lmsd_t *s, const lmsd_cfg_t *cfg);

/* Change mu without touching W: the output continues from where it is (bumpless).
 * Returns 0, or -1 and changes nothing for mu not in (0, LMSD_MU_MAX]. */
int lmsd_set_mu(lmsd_t *s, float mu);

/* W = 0. */
void lmsd_reset(lmsd_t *s);

/* W = [w_i, w_q]' (e.g. the last good estimate after a restart). Returns 0,
 * or -1 and changes nothing for non-finite values. */
int lmsd_preset(lmsd_t *s, float w_i, float w_q);

/* -3 dB bandwidth of the in-phase/quadrature outputs for a given mu (formula above);
 * init-time analysis in double, returns a negative value for invalid arguments. */
double lmsd_bandwidth_hz(double mu, double fs_hz);

/* One sample of (5-5). ref_sin, ref_cos: the NCO references at this sample. */
static inline void lmsd_step(lmsd_t *s, float d, float ref_sin, float ref_cos)
{
  const float err = d - (s->w_i * ref_sin + s->w_q * ref_cos);
  const float g = s->two_mu * err;
  s->w_i += g * ref_sin;
  s->w_q += g * ref_cos;
}

static inline float lmsd_in_phase(const lmsd_t *s) { return s->w_i; }
static inline float lmsd_quadrature(const lmsd_t *s) { return s->w_q; }

#endif /* LMSD_H */
