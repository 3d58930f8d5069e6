/* Self-calibration: identification of the drive resonance from measured frequency-response
 * points (background, double precision).
 *
 * Model (2-24 with the actuator and pickoff gains and the circuit's constant phase lag
 * lumped into one complex constant c; the converter latency as a pure delay D):
 *   H(w) e^{j w D} = 1 / ( c (wn^2 - w^2 + j w wn / Q) )
 * H is the measured ratio Z / (f_cmd e^{jP}) of the drive LMSD phasor to the force
 * command. With d = 1/c, p = wn^2, q = wn/Q the model is linear in (Re d, Im d, p, q):
 *   Re(d y) - p = -w^2,   Im(d y) - q w = 0,   y = 1 / (H e^{j w D}),
 * two real equations per point, solved by least squares. Each point's pair is weighted
 * by |H|, so that the residual is the relative error of H (the near-resonance points,
 * where |H| is large, are the informative ones). Frequencies are normalised to w0 =
 * 2 pi f0_ref for conditioning. wn is the undamped resonance (velocity resonance,
 * phase -90 deg), not the displacement peak wn sqrt(1 - 1/(2Q^2)).
 */
#ifndef SELFCAL_FIT_H
#define SELFCAL_FIT_H

#include <stdint.h>

typedef struct {
  double f_hz;
  double h_re, h_im; /* measured H = Z / (f_cmd e^{jP}), V per Ks*V^2 */
} selfcal_point_t;

typedef struct {
  double f0_hz; /* undamped resonance */
  double q;
  double gain_v_per_v2; /* |H| at f0 */
  double phase_rad;     /* arg H at f0, including the delay D */
  double rms_rel;       /* rms relative residual of H */
} selfcal_fit_t;

/* n >= 2 points (4 unknowns), delay_s >= 0. Returns 0, or -1 (out untouched) for bad
 * input or a non-physical result (wn^2 <= 0, Q <= 0, singular system). */
int selfcal_fit(const selfcal_point_t *pts, uint32_t n, double delay_s, selfcal_fit_t *out);

/* The same with the delay unknown in [delay_min_s, delay_max_s]: the analog chain
 * (anti-alias and reconstruction filters, pickoff circuit) adds a group delay the
 * firmware does not know, and a phase slope left in the data reads as a steeper
 * resonance: Q comes out high (+1.2 % at Q = 24 on the simulator's default chain, about
 * 1.5 samples beyond the converter's). The magnitude of H fixes
 * Q without the phase, so D is identifiable: golden-section search of the relative
 * residual over D (each step one linear fit). *delay_s_out gets the delay found. */
int selfcal_fit_delay(const selfcal_point_t *pts, uint32_t n, double delay_min_s,
                      double delay_max_s, selfcal_fit_t *out, double *delay_s_out);

#endif /* SELFCAL_FIT_H */
