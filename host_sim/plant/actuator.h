/* Electrostatic actuators of the gyro (thesis §6.2.1): the differential drive comb on
 * the drive axis and optional feedback electrodes on the sense axis, with
 * 1/f + white noise on every electrode voltage (§6.3.2). Host plant, double precision.
 *
 * Force per unit mass, (6-7) divided by the proof mass, positive along +y (drive) and
 * +x (sense), i.e. the sign of the mechanics' input f_drv / f_sen:
 *   f_drv = ks_drive (U1^2 - U2^2),       U1 = DAC ch 0 + w1, U2 = DAC ch 1 + w2
 *   f_sen = ks_fb    (U3^2 - U4^2),       electrodes of the feedback pair, from DAC ch 3:
 *      FB_SINGLE:       U3 = u + w3,      U4 = 0 (grounded, noiseless)
 *                       -> f_sen = ks_fb u^2 + noise (with u = A cos(wc t / 2) this is a
 *                          force at wc plus a static part, the half-frequency idea)
 *      FB_DIFFERENTIAL: U3 = Vb + u + w3, U4 = Vb - u + w4 (bias +- the DAC voltage)
 *                       -> f_sen = 4 ks_fb Vb u + noise (linear in u, the DC+AC idea)
 * The same quadratic law gives both drive schemes with no special casing:
 *   half-frequency (6-18, 6-19): U1 = A cos(wc t/2 + p), U2 = A sin(wc t/2 + p)
 *                                -> f = ks A^2 cos(wc t + 2p)
 *   DC+AC (6-20, 6-21):          U1 = D + A cos(wc t), U2 = D - A cos(wc t)
 *                                -> f = 4 ks D A cos(wc t)
 * and the noise terms of (6-21)/(6-23) come out of the same algebra: 2 A cos(wc t)
 * (w1 + w2) puts low-frequency noise at wc under DC+AC; 2 A w1 cos(wc t/2) and
 * 2 A w2 sin(wc t/2) put it at wc/2 under half-frequency drive.
 *
 * Held force (what the mechanics integrates as a zero-order hold): the mean of the
 * force over the sample, from the DAC's exact per-sample mean and mean square,
 *   mean((v + w)^2) = mean(v^2) + 2 w mean(v) + w^2,
 * with the noise voltage w taken constant over the sample (one value of the noise
 * sequence per sample; its spectrum is defined up to fs/2). See dac.h for the size of
 * the remaining zero-order-hold approximation (sinc^2(wT/2), no phase error).
 * The electrostatic spring softening (6-3) of the parallel-plate feedback electrodes by
 * their DC bias is a stiffness of the mechanics (plant.fb_gap_m, plant_fb_softening,
 * mech.h). Not modelled: the forces' own dependence on the displacement (Ks(x) of
 * parallel plates; |Ke| << K2, (6-4)), the parametric stiffness of the AC part of the
 * electrode voltages, fringe-field variation of comb forces with stroke.
 *
 * Noise streams: rng_seed(seed, ACTUATOR_RNG_STREAM_U1 + i), i = 0..3 for U1, U2, U3,
 * U4; a source with zero density draws nothing.
 */
#ifndef PLANT_ACTUATOR_H
#define PLANT_ACTUATOR_H

#include <stdint.h>

#include "plant/dac.h"
#include "plant/flicker.h"

#define ACTUATOR_RNG_STREAM_U1 0x6101u /* U2, U3, U4 follow */

typedef enum {
  ACTUATOR_FB_OFF = 0,         /* no sense-axis force */
  ACTUATOR_FB_SINGLE = 1,      /* one electrode driven by the spare DAC */
  ACTUATOR_FB_DIFFERENTIAL = 2 /* bias +- spare DAC on the two electrodes */
} actuator_fb_t;

typedef struct {
  double fs_hz;
  double ks_drive_mps2_per_v2; /* Ks/m of the drive comb pair, (m/s^2)/V^2 */
  flicker_spec_t drive_noise;  /* on U1 and on U2 (independent), V/sqrt(Hz) one-sided */
  actuator_fb_t fb;            /* sense feedback electrodes (plant.fb_mode) */
  double ks_fb_mps2_per_v2;    /* Ks/m of the sense feedback pair, (m/s^2)/V^2 */
  double fb_bias_v;            /* Vb of FB_DIFFERENTIAL, V */
  flicker_spec_t fb_noise;     /* on U3 and U4 (independent) */
} actuator_cfg_t;

typedef struct {
  double f_drive_mps2; /* mean drive force per unit mass over the sample, m/s^2 */
  double f_sense_mps2; /* mean sense force per unit mass over the sample, m/s^2 */
  double noise_v[4];   /* w1..w4 drawn for this sample, V */
} actuator_out_t;

typedef struct {
  actuator_cfg_t cfg;
  flicker_t noise[4];
} actuator_t;

/* Thesis linear gyro: ks_drive 0.25 (m/s^2)/V^2, so the 26.3 m/s^2 that holds 10 um at
 * resonance (A0 wn1^2 / Q1) needs a 10.3 V half-frequency amplitude (table 7-1: up to
 * 12.75 V; the DAC gives 15 V). Drive-voltage noise 200 nV/sqrt(Hz) white, 2 uV/sqrt(Hz)
 * at 1 Hz (corner 100 Hz), flat below 1 mHz. Feedback off (ks_fb 0.01, Vb 5 V, same
 * noise when switched on). Placeholders for calibration: the thesis gives no numbers
 * for Ks or the noise (fig. 6-5 shows only the 1/f shape). */
void actuator_default_cfg(actuator_cfg_t *cfg);

/* Validates cfg (fs > 0; ks >= 0 and finite; |Vb| <= 100 V; noise specs as
 * flicker_init) and seeds the four noise sources. Returns 0, or -1 with a unchanged. */
int actuator_init(actuator_t *a, const actuator_cfg_t *cfg, uint64_t seed);

/* Forces over the sample described by dac (the same dac_step output the mechanics'
 * sample uses). */
void actuator_step(actuator_t *a, const dac_out_t *dac, actuator_out_t *out);

#endif /* PLANT_ACTUATOR_H */
