/* Quad 14-bit DAC of the reference board with its output amplifier and reconstruction
 * low-pass (thesis §4.4.2 fig. 4-14), for the host plant (double precision).
 *
 * Code to volts (board.h): offset binary over +-15 V,
 *   u = gain[c] * (code - 8192) * 30 V / 16384 + offset_v[c]
 * so code 0 -> -15 V, 8192 -> 0 V, 16383 -> +15 V - 1 LSB (1.831 mV).
 *
 * Timing (one-sample latency, zero-order hold). dac_write() queues a frame; the frame
 * is latched at the END of the next dac_step(). dac_step() covers one sample period
 * [t_k, t_k + T) and holds the frame latched at t_k over it. With the top-level order
 *   ISR at tick k reads the ADC (sampled at t_k) and calls dac_write(frame_k);
 *   plant step: dac_step() over [t_k, t_k+1) holds frame_{k-1}, then latches frame_k;
 * the frame written at tick k is at the output from t_k+1 to t_k+2, like the board's
 * converter (loaded by the ISR, updated by the next timer tick).
 *
 * Reconstruction filter: second-order low-pass, unity DC gain,
 *   H(s) = w0^2 / (s^2 + (w0/Q) s + w0^2),  w0 = 2 pi recon_cutoff_hz,
 * driven by the held level u. State x = [v, v'/w0] (V, V), continuous
 *   x' = w0 [[0, 1], [-1, -1/Q]] x + w0 [0, 1]^T u,   v = x[0].
 * Discretised exactly for the held input (augmented exponential): x(t_k+T) = Ad x + Bd u.
 * recon_cutoff_hz = 0 removes the filter (the output is the held staircase itself).
 *
 * What the actuator needs (force is quadratic in voltage, F ~ U1^2 - U2^2 (6-7)): the
 * mechanics holds ONE force value over each sample, so that value must be the mean
 * force over the sample, which needs the mean of v^2, not the square of a sampled v.
 * Both are exact quadratic/linear forms in z = [x(t_k), u]:
 *   mean_v     = m^T z,   m^T = (1/T) h^T int_0^T e^{F t} dt
 *   mean_sq_v2 = z^T M z, M   = (1/T) int_0^T e^{F^T t} h h^T e^{F t} dt   (Van Loan)
 * with F = [[A, B], [0, 0]], h = [1, 0, 0]. They hold for any voltage waveform the
 * filter produces inside the sample (steps, ringing), so the impulse of the force over
 * every sample is exact. The remaining approximation is the mechanics' zero-order hold
 * of that mean: a force F cos(w t + p) replaced by its per-sample means, held, has a
 * fundamental of sinc^2(w T / 2) F cos(w t + p) (one sinc from the averaging, one
 * from the hold; the T/2 lead of "hold the mean of the coming sample" cancels the T/2
 * lag of the hold): no phase error, gain -0.29 % at 1490 Hz (force of a 745 Hz
 * half-frequency drive) at 50 kHz, plus images at k fs +- f that the resonator
 * rejects. Conversely the true force has small components near k fs +- f (products of
 * the staircase's images); their per-sample means are indistinguishable from a force at
 * f, so held by the mechanics they act at f: -2.7e-4 of the drive force for a 745 Hz
 * half-frequency drive with the default filter (test_actuator compares the held force
 * with the exact spectrum). Sampling v at the tick and squaring it instead would cost a
 * T/2 lag (5.4 deg at 1490 Hz) that is not in the real hardware.
 *
 * Voltages at the end of the sample (end_v, end_dvdt_v_per_s) are for the pickoff's
 * electrical feedthrough, which interpolates between ticks.
 *
 * Imperfections, each off at zero: the INL of each channel's 14-bit ladder (cfg.inl,
 * inl.h: the bow and a per-code pattern of its own per channel), the level of code c
 * being gain (c + INL(c) - 8192) lsb + offset; and the shared reference's relative
 * error r (dac_set_ref, vref.h), which scales the converter's part of the level:
 * offset + (level - offset) (1 + r).
 *
 * Channels (hal/include/hal/hal_dac.h): 0 drive U1, 1 drive U2, 2 analog rate output, 3 spare
 * (sense feedback; the feedback pair's U3 in plant fb_mode 3), then the second converter of
 * the board: 4 the pair's U4, 5 and 6 the quadrature-nulling sets V1 and V2, 7 the tuning
 * electrodes. Every channel is the same part (AD5554) behind the same x1.5 driver stage,
 * with its own gain, offset and INL pattern (stream DAC_RNG_STREAM_INL + channel, so the
 * first four keep the patterns they had before the second converter existed).
 *
 * Channels not modelled (cfg.modelled[c] = 0: the plant's part has no electrode there):
 * their codes are still checked and latched, but dac_step never computes their output and
 * leaves out->ch[c] as the caller had it (a zeroed dac_out_t reads 0 V). A channel without
 * a load costs a compare per sample, not a filter update (the simulator's speed is a
 * product goal; the default part has none of the sense electrodes).
 *
 * One plant sample [t_k, t_k+1) with the electrical modules (the top level's order):
 *   dac_step(&dac, &dout)                         voltages over the sample
 *   actuator_step(&act, &dout, &f)                mean forces per unit mass, m/s^2
 *   accel_step(&acc, a_g, &fa)                    + g-sensitivity forces, m/s^2
 *   mechanics: hold f + fa (+ Brownian) over the sample, state at t_k+1
 *   vd = pickoff_step(&pd, y, y', &dout)          drive pickoff at its sampling instant
 *   vs = pickoff_step(&ps, x, x', &dout)          sense pickoff
 *   adc_convert_frame(&adc, vd, vs, &frame)       -> firmware ISR of tick k+1
 *   dac_write(&dac, &firmware_frame)              latched at the end of the next step
 * Lag from a code written by the ISR to the force (both schemes, 1490 Hz force):
 * 1.5 samples of the voltage (one latency + half a hold: 8.0 deg at 745 Hz, doubled by
 * the square law to 16.1 deg at 1490 Hz) plus the filter (3.0 deg at 745 Hz, 6.0 deg in
 * force), about 22 deg in total; these are real hardware lags for the drive loop to
 * absorb, not artefacts.
 */
#ifndef PLANT_DAC_H
#define PLANT_DAC_H

#include <stdint.h>

#include "hal/hal_dac.h"
#include "plant/inl.h"

#define DAC_NCH HAL_DAC_NUM_CHANNELS
#define DAC_BITS 14
#define DAC_FIRST 4 /* channels of the board's first converter (drive, rate output, spare) */
#define DAC_RNG_STREAM_INL 0x7501u /* + channel */

typedef struct {
  double fs_hz;                   /* latch (sample) rate, Hz */
  double recon_cutoff_hz;         /* reconstruction low-pass natural frequency; 0: none */
  double recon_q;                 /* its quality factor (0.7071: Butterworth) */
  double gain[DAC_NCH];           /* output amplifier gain, 1 = ideal */
  double offset_v[DAC_NCH];       /* output offset, V */
  uint16_t initial_code[DAC_NCH]; /* held before the first latched frame */
  uint8_t modelled[DAC_NCH];      /* 1: output computed by dac_step; 0: codes only */
  inl_cfg_t inl;                  /* integral nonlinearity of every channel, LSB */
  uint64_t inl_seed;              /* the part's INL patterns */
} dac_cfg_t;

typedef struct {
  double held_v;           /* ZOH level u over this sample (before the filter), V */
  double mean_v;           /* mean of the filtered output over the sample, V */
  double mean_sq_v2;       /* mean of its square over the sample, V^2 */
  double end_v;            /* output at the end of the sample, V */
  double end_dvdt_v_per_s; /* its slope there, V/s */
} dac_chan_out_t;

typedef struct {
  dac_chan_out_t ch[DAC_NCH];
} dac_out_t;

/* The reconstruction filter over one sample (the header's exact forms). */
typedef struct {
  double ad[2][2], bd[2]; /* exact ZOH discretisation */
  double mv[3];           /* mean form */
  double msq[3][3];       /* mean-square form */
  double q2[6];           /* msq as q00, 2q01, 2q02, q11, 2q12, q22 (per-sample use) */
} dac_forms_t;

typedef struct {
  dac_cfg_t cfg;
  int filtered;              /* 0 when recon_cutoff_hz == 0 */
  double w0;                 /* rad/s */
  dac_forms_t form;          /* the filter's exact forms over one sample */
  double scale[DAC_NCH];     /* volts per code, gain included */
  double zero[DAC_NCH];      /* volts at code 0, gain and offset included */
  double x[DAC_NCH][2];      /* filter states [v, v'/w0] */
  uint16_t latched[DAC_NCH]; /* code held over the current sample */
  uint16_t pending[DAC_NCH]; /* code latched at the end of the current sample */
  double ref_rel;            /* reference error r (dac_set_ref) */
  int n_on;                  /* modelled channels, */
  uint8_t on[DAC_NCH];       /* their indices in ascending order */
  int first_all;             /* channels 0..DAC_FIRST-1 all modelled (on[] starts with them) */
  inl_t inl[DAC_NCH];
  /* the INL of the code last converted on each channel, in volts: the rate output and the
   * spare hold a code for a block or longer, so most samples need no new lookup */
  uint32_t inl_code[DAC_NCH]; /* > HAL_DAC_CODE_MAX: none yet */
  double inl_v[DAC_NCH];
} dac_t;

/* fs 50 kHz, 2nd-order Butterworth at 20 kHz, ideal gain, no offset, mid-scale codes, every
 * channel modelled. */
void dac_default_cfg(dac_cfg_t *cfg);

/* Validates cfg (fs > 0; cutoff 0 or in (0, fs]; Q in [0.1, 10]; |gain| in (0, 2];
 * |offset| <= 15 V; codes <= 16383; modelled 0 or 1; inl_check). Returns 0, or -1 with d
 * unchanged. The filters start settled at the initial codes. Built in place once nothing
 * can fail (a scratch dac_t, eight channels' INL tables, was 6 kB of a target's stack). */
int dac_init(dac_t *d, const dac_cfg_t *cfg);

/* The reference's relative error r for the samples that follow (0: exact). */
void dac_set_ref(dac_t *d, double ref_rel);

/* Queue a frame for the next latch. Any code > HAL_DAC_CODE_MAX: returns -1 and keeps
 * the previously queued frame. */
int dac_write(dac_t *d, const hal_dac_frame_t *frame);

/* Advance one sample period: outputs over [t_k, t_k + T) for every modelled channel (the
 * others' entries of out untouched), then latch the queued frame on every channel. */
void dac_step(dac_t *d, dac_out_t *out);

/* Ideal transfer (gain 1, no offset): volts of an offset-binary code. */
double dac_code_to_v(uint16_t code);

/* Nearest code for a voltage, saturated to 0..16383 (for tests and scenarios). */
uint16_t dac_v_to_code(double v);

#endif /* PLANT_DAC_H */
