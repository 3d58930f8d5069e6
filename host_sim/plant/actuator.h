/* Electrostatic actuators of the gyro (thesis §6.2.1): the differential drive comb on
 * the drive axis and optional feedback electrodes on the sense axis, quadrature-nulling
 * and sense frequency-tuning electrodes, with 1/f + white noise on every electrode
 * voltage (§6.3.2). Host plant, double precision.
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
 *      FB_PAIR:         U3 = e3 + w3, U4 = e4 + w4, both voltages from the electrode input
 *                       (actuator_elec_in_t; the plant fills it from the DAC's spare channel
 *                       and the second converter's, plant.h): the drive's law on
 *                       the sense axis, so half-frequency feedback (e3 = A cos(wc t/2 + p),
 *                       e4 = A sin(wc t/2 + p): f_sen = ks_fb A^2 cos(wc t + 2p)) and DC+AC
 *                       (e3 = Vb + u, e4 = Vb - u) are the same electrodes with other
 *                       voltages, as on the drive axis below
 * The same quadratic law gives both drive schemes with no special casing:
 *   half-frequency (6-18, 6-19): U1 = A cos(wc t/2 + p), U2 = A sin(wc t/2 + p)
 *                                -> f = ks A^2 cos(wc t + 2p)
 *   DC+AC (6-20, 6-21):          U1 = D + A cos(wc t), U2 = D - A cos(wc t)
 *                                -> f = 4 ks D A cos(wc t)
 * and the noise terms of (6-21)/(6-23) come out of the same algebra: 2 A cos(wc t)
 * (w1 + w2) puts low-frequency noise at wc under DC+AC; 2 A w1 cos(wc t/2) and
 * 2 A w2 sin(wc t/2) put it at wc/2 under half-frequency drive.
 *
 * Stiffness of the sense electrodes (per unit mass, to the mechanics' mech_set_elec):
 *   quadrature nulling: k_yx = c_q (V1^2 - V2^2), the force -k_yx y on the sense axis,
 *     V1 = e5 + w5, V2 = e6 + w6. The standard quadrature-cancellation electrodes of a
 *     linear vibratory gyro (W. A. Clark, R. T. Howe, R. Horowitz, Solid-State Sensor and
 *     Actuator Workshop, Hilton Head 1996, 283; M. Saukoski, System and circuit design for
 *     a capacitive MEMS gyroscope, thesis, Helsinki Univ. of Technology 2008;
 *     E. Tatar, S. E. Alper, T. Akin, J. Microelectromech. Syst. 21 (2012) 656): plates
 *     facing the sense axis across a gap d, each with a thickness h and an overlap along
 *     the drive axis that the drive displacement changes. A plate pulls the proof mass
 *     towards itself with eps h l V^2 / (2 (d -+ x)^2), l its overlap. Set 1 has a plate
 *     on the +x side with overlap l0 - y and one on the -x side with l0 + y; set 2 the
 *     mirror. Over a set the static parts cancel and the parts in y add: -eps h y V1^2 /
 *     d^2 along x from set 1, +eps h y V2^2 / d^2 from set 2, a stiffness coupling from
 *     the drive displacement to the sense axis, k_yx = c_q (V1^2 - V2^2) with
 *     c_q = eps h / (m d^2) (1/s^2 per V^2; plant.quadnull_dps_per_v2 gives it as an
 *     equivalent quadrature c_q / (2 wc) per V^2), either sign by which set is driven
 *     (V1 adds to a positive k_q, V2 cancels it). Across x the same plates
 *     are parallel plates: each set softens the sense spring by eps h 2 l0 V^2 / d^3, in
 *     the same constant k_e = ke_q (V1^2 + V2^2), ke_q = 2 c_q (l0 / d)
 *     (plant.quadnull_overlap_per_gap), so nulling also tunes the sense mode down a little.
 *     Left out: the coupling's own dependence on x (a term in x y) and the force on the
 *     drive axis (mech.h).
 *   frequency tuning: k_e = ke_t Vt^2, Vt = e7 + w7, on a parallel-plate pair across the
 *     sense gap at the same voltage, whose forces cancel at x = 0 and whose stiffness
 *     eps A V^2 / g^3 each adds (thesis (6-3); Senturia, Microsystem Design, §6.4.3):
 *     ke_t = 2 eps A / (m g^3). Tuning only lowers the sense resonance.
 *   feedback pair (FB_PAIR with a gap, plant.fb_gap_m): the same parallel-plate softening
 *     of U3 and U4 each, 2 ks_fb U^2 / gap (plant_fb_softening gives the DC bias's in
 *     FB_DIFFERENTIAL, constant): k_e = ke_fb (U3^2 + U4^2), ke_fb = 2 ks_fb / gap. Under
 *     half-frequency feedback U3^2 + U4^2 = A^2 is steady; under DC+AC it has a part at
 *     2 wc (a parametric stiffness) that the per-sample means carry.
 * All are means over the sample like the forces (below), from the same mean squares.
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
 * voltages of FB_SINGLE and FB_DIFFERENTIAL, fringe-field variation of comb forces with
 * stroke.
 *
 * Electrode input: the voltages of FB_PAIR and of the nulling and tuning electrodes come
 * as per-sample means and mean squares (dac_chan_out_t, its mean_v and mean_sq_v2), the
 * form a converter with its reconstruction filter gives (dac.h); a level held over the
 * sample is mean v, mean square v^2. An electrode that is not there (constant 0, or the
 * feedback pair outside FB_PAIR) ignores its voltage and draws no noise.
 *
 * Noise streams: rng_seed(seed, ACTUATOR_RNG_STREAM_U1 + i), i = 0..6 for U1, U2, U3,
 * U4, V1, V2, Vt; a source with zero density (or of an electrode that is not there) draws
 * nothing.
 */
#ifndef PLANT_ACTUATOR_H
#define PLANT_ACTUATOR_H

#include <stdint.h>

#include "plant/dac.h"
#include "plant/flicker.h"

#define ACTUATOR_RNG_STREAM_U1 0x6101u /* U2, U3, U4, V1, V2, Vt follow */
#define ACTUATOR_NOISE 7               /* U1, U2, U3, U4, V1, V2, Vt */

typedef enum {
  ACTUATOR_FB_OFF = 0,          /* no sense-axis force */
  ACTUATOR_FB_SINGLE = 1,       /* one electrode driven by the spare DAC */
  ACTUATOR_FB_DIFFERENTIAL = 2, /* bias +- spare DAC on the two electrodes */
  ACTUATOR_FB_PAIR = 3          /* both electrodes from the electrode input */
} actuator_fb_t;

typedef struct {
  double fs_hz;
  double ks_drive_mps2_per_v2; /* Ks/m of the drive comb pair, (m/s^2)/V^2 */
  flicker_spec_t drive_noise;  /* on U1 and on U2 (independent), V/sqrt(Hz) one-sided */
  actuator_fb_t fb;            /* sense feedback electrodes (plant.fb_mode) */
  double ks_fb_mps2_per_v2;    /* Ks/m of the sense feedback pair, (m/s^2)/V^2 */
  double fb_bias_v;            /* Vb of FB_DIFFERENTIAL, V */
  flicker_spec_t fb_noise;     /* on U3 and U4 (independent) */
  double fb_ke_per_s2_per_v2;  /* ke_fb: FB_PAIR softening per V^2 of U3^2 + U4^2, 0 = none */
  double quadnull_kyx_per_s2_per_v2; /* c_q: nulling coupling per V^2 of V1^2 - V2^2, 0 = none */
  double quadnull_ke_per_s2_per_v2;  /* ke_q: their softening per V^2 of V1^2 + V2^2 */
  flicker_spec_t quadnull_noise;     /* on V1 and V2 (independent) */
  double tune_ke_per_s2_per_v2;      /* ke_t: tuning softening per V^2 of Vt^2, 0 = none */
  flicker_spec_t tune_noise;         /* on Vt */
} actuator_cfg_t;

/* The voltages of the sense electrodes over one sample (the header: mean and mean square;
 * end_v and the slope are not used), apart from the dac_out_t the drive takes. */
typedef struct {
  dac_chan_out_t fb[2];       /* U3, U4 of FB_PAIR */
  dac_chan_out_t quadnull[2]; /* V1, V2 */
  dac_chan_out_t tune;        /* Vt */
} actuator_elec_in_t;

typedef struct {
  double f_drive_mps2;            /* mean drive force per unit mass over the sample, m/s^2 */
  double f_sense_mps2;            /* mean sense force per unit mass over the sample, m/s^2 */
  double kyx_per_s2;              /* mean nulling coupling k_yx over the sample, 1/s^2 */
  double ke_per_s2;               /* mean softening k_e of the sense electrodes, 1/s^2 */
  double noise_v[ACTUATOR_NOISE]; /* w1..w7 drawn for this sample, V */
} actuator_out_t;

typedef struct {
  actuator_cfg_t cfg;
  int elec; /* an electrode of the electrode input is there */
  flicker_t noise[ACTUATOR_NOISE];
} actuator_t;

/* Thesis linear gyro: ks_drive 0.25 (m/s^2)/V^2, so the 26.3 m/s^2 that holds 10 um at
 * resonance (A0 wn1^2 / Q1) needs a 10.3 V half-frequency amplitude (table 7-1: up to
 * 12.75 V; the DAC gives 15 V). Drive-voltage noise 200 nV/sqrt(Hz) white, 2 uV/sqrt(Hz)
 * at 1 Hz (corner 100 Hz), flat below 1 mHz. Feedback off (ks_fb 0.01, Vb 5 V, same
 * noise when switched on). No nulling or tuning electrodes (their noise, when they are
 * there, the same). Placeholders for calibration: the thesis gives no numbers for Ks or
 * the noise (fig. 6-5 shows only the 1/f shape). */
void actuator_default_cfg(actuator_cfg_t *cfg);

/* Validates cfg (fs > 0; ks and the electrode constants >= 0 and finite; |Vb| <= 100 V;
 * noise specs as flicker_init) and seeds the noise sources. Returns 0, or -1 with a
 * unchanged. */
int actuator_init(actuator_t *a, const actuator_cfg_t *cfg, uint64_t seed);

/* Forces over the sample described by dac (the same dac_step output the mechanics'
 * sample uses), every electrode of the electrode input at 0 V. */
void actuator_step(actuator_t *a, const dac_out_t *dac, actuator_out_t *out);

/* The same with the electrode input's voltages over the sample (NULL: all at 0 V); also
 * the electrodes' stiffness. */
void actuator_step_elec(actuator_t *a, const dac_out_t *dac, const actuator_elec_in_t *elec,
                        actuator_out_t *out);

#endif /* PLANT_ACTUATOR_H */
