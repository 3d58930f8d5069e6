/* Resonance-tracking drive (drive.track 1): a phase-locked loop whose output is the NCO's
 * frequency, so that the drive follows the resonance instead of holding a fixed
 * frequency (the thesis's open problem, its introduction, item 5). The force phase P
 * stays at its calibrated value p_init; the amplitude loop (drive_loop.h) is unchanged.
 *
 * Plant. Near the resonance the envelope of the drive motion in the NCO frame obeys
 * (6-12), (6-17) with the detuning as a rotation: dZ/dt = (-1/tau + j 2 pi (f0 - f)) Z +
 * b F, tau = 2Q/wn. A move df of the NCO frequency turns arg Z by
 *     d(arg Z) = -2 pi tau / (tau s + 1) df      (rad per Hz)
 * whose static slope is 2Q/f0 rad per Hz at the resonance (the phase-to-frequency slope),
 * and above 1/tau an integrator 2 pi / s whatever Q: the phase of a free vibration runs
 * at the difference frequency. So one design serves Q = 20 ... 10^5.
 *
 * Controller. e = wrap(phase_set - arg Z) (rad; e > 0: more lag than at the resonance,
 * the drive sits above it), df = -(kp e + ki int e). The PI zero sits at
 * max(1/tau, wc/4): on the plant's pole at low Q (the loop is then kp 2 pi / s), a
 * quarter of the crossover at high Q, where the loop becomes type 2 and follows a
 * resonance ramping with temperature without a phase error. The crossover is capped for
 * 60 deg of phase margin with the demodulator's lag and the delays (drive_track_design).
 * Gain scheduling: wider gains in acquisition (pull-in from the calibrated frequency to
 * wherever temperature has moved the resonance), the designed ones once LOCKED; the
 * switch is bumpless (the integrator takes the proportional term's step).
 *
 * Resolution. The frequency is held and moved in the NCO's integer phase step
 * (half_step, fs / 2^31 = 2.3e-5 Hz per step, nco.h): the integrator is a whole number
 * of steps plus a float remainder below one step, never a float frequency (a float32 at
 * 1490 Hz resolves 1.2e-4 Hz: 0.9 deg of drive phase at Q = 10^5).
 *
 * Ripple. The drive LMSD's weights carry a ripple at the carrier wc (0.22 deg and 1.3 mV
 * rms on the default part, from the pickoff's DC and harmonics): kp turns it into 0.11 Hz
 * rms of frequency, and the amplitude loop's kp into force swings larger than the
 * holding force at high Q. Both tracking-drive measurements (phase error, amplitude)
 * pass a three-tap notch at wc at the block rate, H(z) = g (1 - c2 z^-1 + z^-2),
 * c2 = 2 cos(wc T_block), g = 1 / (2 - c2) (unit gain at DC): linear phase, one block of
 * delay in the loops' designs, 145x at the edge of the frequency window.
 *
 * Window. The offset from the calibrated step is clamped to +-window (0.5 % of f0); a
 * loop that stays at the edge (the resonance is outside, or the loop ran off) is a
 * fault (supervisor FREQ_WINDOW).
 *
 * Thermometer. P is constant here; the frequency carries the temperature. The output
 * p_eq is the force phase the fixed-frequency drive would hold for the same resonance:
 *     p_eq = p_init - (2Q/f0) (f - f_cal)
 * (the fixed drive moves P by the resonance's phase at f_cal, atan(2Q (f_cal - f0)/f0),
 * linear near the resonance; a drive-circuit phase change moves the tracked frequency by
 * f0/(2Q) per radian and p_eq by the same radian, as it moves P). So the rate channel's
 * compensation in P and the thermometer's range and slew checks (rate_valid.h) keep their
 * meaning in both modes; beyond the fixed drive's linear range p_eq stays linear.
 */
#ifndef DRIVE_TRACK_H
#define DRIVE_TRACK_H

#include <stdint.h>

/* What the tracker is told (gyro_design): constant while it runs. Gains are in NCO
 * half-steps per radian of phase error (kp) and per radian per update (ki_dt). */
typedef struct {
  float kp_acq, ki_dt_acq;   /* acquisition */
  float kp_lock, ki_dt_lock; /* LOCKED */
  int32_t win_steps;         /* +- window around the calibrated step */
  float p_eq_per_step_rad;   /* (2Q/f0) fs / 2^31: p_eq's move per step of offset */
  float p_init_rad;          /* the force phase held, p_eq at the calibrated step */
  float min_amp_rel;         /* below this fraction of the set point arg Z is noise: hold */
  float notch_c2, notch_g;   /* the ripple notch at wc (above) */
} drive_track_cfg_t;

/* The notch's memory: the last two inputs. */
typedef struct {
  float x1, x2;
} drive_notch_t;

static inline float drive_notch(float c2, float g, drive_notch_t *n, float x)
{
  const float y = g * (x - c2 * n->x1 + n->x2);
  n->x2 = n->x1;
  n->x1 = x;
  return y;
}

/* What the tracker remembers. */
typedef struct {
  int32_t int_steps;   /* integrator, whole steps off the calibrated one */
  float int_frac;      /* its remainder, within +-1/2 step */
  int32_t off_steps;   /* offset in use (integrator + proportional, in the window) */
  uint32_t locked;     /* the LOCKED gains are in use */
  uint32_t at_limit;   /* the offset sits at the window's edge */
  drive_notch_t notch; /* on the phase error */
} drive_track_t;

/* The thermometer's phase p_eq (above) of the offset in use. */
static inline float drive_track_p_eq_rad(const drive_track_cfg_t *cfg, const drive_track_t *t)
{
  return cfg->p_init_rad - cfg->p_eq_per_step_rad * (float)t->off_steps;
}

typedef struct {
  double q, f0_hz;      /* identified drive resonance (drive.cal_*) */
  double bw_hz;         /* wanted crossover of the locked loop */
  double acq_bw_factor; /* acquisition crossover: this x bw_hz, capped by the margin */
  double demod_bw_hz;   /* LMSD bandwidth */
  double fs_hz;
  double loop_decim;  /* samples per update */
  double lag_samples; /* from the measured sample to the first with the new frequency */
  double window_rel;  /* half-width of the frequency window, relative to f0 */
  double p_init_rad;
  double min_amp_rel;
} drive_track_design_in_t;

typedef struct {
  double bw_hz, acq_bw_hz;               /* achieved crossovers (after the phase-margin cap) */
  double phase_margin_deg;               /* of the locked loop */
  double kp_hz_per_rad, ki_hz_per_rad_s; /* locked gains, for status */
} drive_track_design_out_t;

/* Gains and window from the identified model (background, double). Returns 0, or -1 for
 * non-physical inputs (cfg and out untouched). */
int drive_track_design(const drive_track_design_in_t *in, drive_track_cfg_t *cfg,
                       drive_track_design_out_t *out);

/* Offset 0 (the calibrated step), integrator cleared, acquisition gains. */
void drive_track_reset(drive_track_t *t);

/* The notch's coefficients for a carrier f0_hz at the loop rate fs_hz / loop_decim
 * (background). */
void drive_track_notch(double f0_hz, double fs_hz, double loop_decim, float *c2, float *g);

/* The loop's error from the wrapped phase error e_rad: notched, or (amp_rel below
 * min_amp_rel: no vibration to measure) passed through with the notch re-seeded. */
float drive_track_error(const drive_track_cfg_t *cfg, drive_track_t *t, float e_rad,
                        float amp_rel);

/* One update (once per block) from the error drive_track_error made and the relative
 * amplitude amp_rel = |Z| / A_set; locked selects the gains. Returns the offset in steps
 * to add to the calibrated step. */
int32_t drive_track_update(const drive_track_cfg_t *cfg, drive_track_t *t, float e_rad,
                           float amp_rel, int locked);

#endif /* DRIVE_TRACK_H */
