/* Numerically controlled oscillator: the sample-clocked sine source of the demodulator
 * references at wc and of the half-frequency drive at wc/2 (thesis 5.5.2, (5-14);
 * half-frequency drive (6-18), (6-19)).
 *
 * Phases are uint32_t fractions of a turn, 2^32 = 2*pi (dsp/sincos.h).
 *
 * State: one accumulator at HALF the drive frequency,
 *     half_phase[n+1] = half_phase[n] + half_step            (mod 2^32)
 *     phase[n]        = 2 * half_phase[n]                      (mod 2^32)
 * with half_step = round(freq_hz / fs_hz * 2^31), so the wc oscillator advances by
 * step = 2 * half_step (always even) and the two oscillators stay locked exactly,
 * forever, through every wrap and every frequency or phase change: the wc/2 phase is
 * phase/2 modulo pi by construction. Deriving the wc/2 phase as phase >> 1 instead
 * would jump by pi every time the wc accumulator wraps and flip both drive voltages
 * U1 = A cos(wc t/2 + pc), U2 = A sin(wc t/2 + pc) once per cycle.
 *
 * Frequency resolution fs/2^31 (2.3e-5 Hz at 50 kHz); the realised frequency is
 * half_step * fs / 2^31, within fs/2^32 of the request.
 *
 * Sample timing: nco_step returns the oscillator at the current sample and then
 * advances. The first nco_step after nco_init returns the configured phase.
 */
#ifndef NCO_H
#define NCO_H

#include <stdint.h>

#include "dsp/sincos.h"

typedef struct {
  double freq_hz;   /* wc/(2*pi), 0 <= freq_hz < fs_hz/2 */
  double fs_hz;     /* sample rate, > 0 */
  double phase_rad; /* wc phase at the first sample (any finite value, wrapped); the
                     * wc/2 oscillator starts at phase_rad/2 after wrapping to [0, 2*pi) */
} nco_cfg_t;

typedef struct {
  uint32_t half_phase; /* wc/2 oscillator phase, 2^32 = 2*pi */
  uint32_t half_step;  /* wc/2 phase advance per sample */
} nco_t;

typedef struct {
  float sin_wc;        /* sin(wc t) at this sample */
  float cos_wc;        /* cos(wc t) at this sample */
  float sin_half;      /* sin(wc t / 2): the half-frequency pair's unit phasor */
  float cos_half;      /* cos(wc t / 2) */
  uint32_t phase;      /* wc t as a phase; phase == 2 * half_phase (mod 2^32) */
  uint32_t half_phase; /* wc t / 2 as a phase */
} nco_out_t;

/* The wc/2 phase step of a frequency: round(freq_hz / fs_hz * 2^31), halves away from
 * zero; below fs_hz / 2 it is below 2^30. A negative frequency wraps modulo 2^32 (the
 * oscillator turns backwards). The one conversion of a frequency to a step, for the
 * NCO and for the self-calibration's sweep plans. Background: double, libm. */
uint32_t nco_half_step_of(double freq_hz, double fs_hz);

/* The frequency a step realises: half_step * fs_hz / 2^31 (within fs_hz / 2^32 of the
 * frequency it was made from). */
double nco_freq_of(uint32_t half_step, double fs_hz);

/* Set frequency and phase. Returns 0, or -1 (nco unchanged) for a NULL pointer, a
 * non-finite value, fs_hz <= 0, or freq_hz outside [0, fs_hz/2). Init-time: uses double. */
int nco_init(nco_t *nco, const nco_cfg_t *cfg);

/* Change the frequency: the phase of the next sample is already fixed (nco_step
 * advances after it outputs), the advance from that sample on uses the new frequency.
 * The phase runs on without a step (both oscillators). Same validation and return as nco_init. Uses double arithmetic (a
 * software routine on the Cortex-M4F): call it from the background or at a sweep step,
 * not every sample. */
int nco_set_freq(nco_t *nco, double freq_hz, double fs_hz);

/* Move the wc phase to phase_rad (absolute) or by delta_rad (relative) from the next
 * sample on. The wc/2 oscillator moves by half the change, where the change is taken in
 * [-pi, pi) (the smallest move of the wc phase; the wc/2 phase is only defined modulo
 * pi by the wc phase). Resolution 2^-31 turn. Returns 0, or -1 (nco unchanged) for a
 * NULL pointer or a non-finite angle. Single precision, no libm: usable in the ISR. */
int nco_set_phase(nco_t *nco, float phase_rad);
int nco_shift_phase(nco_t *nco, float delta_rad);

/* The oscillator at a half phase: one table lookup at wc t / 2, and wc t from it by the
 * double angle, sin 2x = 2 sin x cos x, cos 2x = (cos x - sin x)(cos x + sin x): five
 * operations where a second lookup costs about twenty, on every sample. Each synthesis
 * turns these unit phasors by its command's phasor (drive_synth.h) rather than looking
 * the table up at its own phase. The interpolation's error (dsp/sincos.h, <= 2.9e-7) is
 * doubled at wc. */
static inline void nco_out_at(uint32_t half_phase, nco_out_t *out)
{
  float s, c;
  sincos_lut(half_phase, &s, &c);
  out->sin_half = s;
  out->cos_half = c;
  out->sin_wc = 2.0f * s * c;
  out->cos_wc = (c - s) * (c + s);
  out->phase = half_phase << 1;
  out->half_phase = half_phase;
}

/* The oscillator at this sample, then advance by one sample. */
static inline void nco_step(nco_t *nco, nco_out_t *out)
{
  nco_out_at(nco->half_phase, out);
  nco->half_phase += nco->half_step;
}

#endif /* NCO_H */
