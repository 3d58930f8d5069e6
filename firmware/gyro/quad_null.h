/* Quadrature nulling: the demodulated quadrature -> a DC voltage on the nulling
 * electrodes, so the quadrature is cancelled at its source (a coupling stiffness)
 * rather than rejected by the demodulation phase alone.
 *
 * The electrodes: a voltage pair V1, V2 over the sense comb adds a coupling stiffness
 * between the modes, k_yx = c' (V1^2 - V2^2) (parallel-plate force, its gradient across
 * the drive motion). In the rate channel's units the quadrature then reads
 *     q = q0(T) + c u,   u = V1^2 - V2^2 (V^2),   c in (deg/s)/V^2,
 * quasi-static as long as the sense mode answers within the loop's bandwidth (a split
 * of tens of Hz or a low sense Q; matched and high Q, the mode's envelope lag 2Q/w is
 * the force-rebalance loop's to take). One electrode is enough at a time: u >= 0 goes
 * on V1 = sqrt(u), u < 0 on V2 = sqrt(-u) (force goes as the voltage squared, so the
 * loop commands u and takes the root, as the drive synthesis does, (6-25)).
 *
 * Control: an integrator on e = -q (dsp/pi.h, position form, Kp = 0): with the plant's
 * gain c identified, Ki = 2 pi f_c / c puts the loop's crossover at f_c and the closed
 * loop is first order, time constant 1 / (2 pi f_c). A gain error scales f_c: half the
 * true c gives twice f_c, still first order while f_c stays well under the rate
 * channel's output filter (its 100 Hz Butterworth and the block rate). 1500 deg/s
 * falls under 1 deg/s in ln(1500) / (2 pi f_c): 0.58 s at f_c = 2 Hz. A drift of q0 at
 * r (deg/s)/s (temperature: k_q follows the structure) leaves r / (2 pi f_c) of
 * residual.
 *
 * Update rate: the integral's increment Ki T q must stay above half an ulp of u near
 * the null, else the float integrator stops short (a dead band of ulp(u) / (2 Ki T)):
 * with u = 75 V^2 (1500 deg/s at c = 20) and f_c = 2 Hz that is 0.03 deg/s at the rate
 * channel's 5 kHz block and 0.003 deg/s at its 500 Hz thermometer block
 * (RATE_P_DECIM), the rate it is meant to run at.
 *
 * Identification (every start): the gain c is the part's and its wiring's (sign
 * included), so the loop measures it before it closes: the quadrature's mean over
 * probe_avg_s with u = 0, then again with u = +probe_v^2 after probe_wait_s for the
 * channel's filters to settle; c = (q_step - q_base) / probe_v^2. A change under
 * min_step_dps means the electrodes do not act (not fitted, not wired, a dead driver):
 * the loop stops with both at 0 V and says so (failed). No stored value of a particular
 * part is needed; a calibrated gain may be given instead (quad_null_start_with_gain).
 *
 * Limits: |u| <= v_max^2 (the electrode driver's rail); a quadrature the electrodes
 * cannot reach holds the output at the limit (at_limit) and the loop never counts as
 * settled. Settled: |q| <= settle_dps for settle_s without a break, the monitor the
 * rate's validity waits on.
 */
#ifndef QUAD_NULL_H
#define QUAD_NULL_H

#include <stdint.h>

#include "dsp/pi.h"

typedef struct {
  float bw_hz;        /* f_c, the loop's crossover; > 0, under a tenth of the update rate */
  float v_max_v;      /* electrode limit; > 0 */
  float settle_dps;   /* |q| below this counts as nulled; > 0 */
  float settle_s;     /* for this long; >= 0 */
  float probe_v;      /* identification step; 0 < probe_v <= v_max_v */
  float probe_wait_s; /* settling before each mean; >= 0 */
  float probe_avg_s;  /* each mean's length; >= one update */
  float min_step_dps; /* the probe's smallest credible effect; > 0 */
  float dt_s;         /* update period; > 0 */
} quad_null_cfg_t;

/* What the update uses, from quad_null_design. */
typedef struct {
  float wc_dt;    /* 2 pi f_c T: Ki T = wc_dt / c */
  float u_max_v2; /* v_max^2 */
  float u_probe_v2;
  float settle_dps, min_step_dps;
  uint32_t settle_updates, wait_updates, avg_updates;
  float inv_avg, inv_u_probe_v2; /* 1 / avg_updates, 1 / u_probe_v2 */
} quad_null_design_t;

typedef enum {
  QUAD_NULL_OFF = 0,
  QUAD_NULL_PROBE_BASE, /* u = 0: the quadrature as it is */
  QUAD_NULL_PROBE_STEP, /* u = probe: the electrodes' effect */
  QUAD_NULL_RUN,        /* the loop closed on the identified gain */
  QUAD_NULL_FAILED      /* the probe saw no effect: both electrodes at 0 V */
} quad_null_mode_t;

typedef struct {
  quad_null_mode_t mode;
  uint32_t count;          /* updates in the current probe phase */
  float sum_dps, base_dps; /* the probe's sums and its base mean */
  float gain_dps_per_v2;   /* c, identified (0 until then) */
  pi_coeffs_t pi;          /* on e = -q, output u in V^2 */
  pi_t pi_state;
  float integ_v2;   /* the integrator (u before the clamp of the output) */
  uint32_t in_band; /* consecutive updates with |q| <= settle_dps */
  uint8_t settled;  /* in_band reached settle_updates */
  uint8_t at_limit; /* u is at +-v_max^2 */
  float v1_v, v2_v; /* the electrode voltages, one of them 0 */
} quad_null_t;

/* Validates cfg (every value finite and in its range) and derives the design. Returns
 * 0, or -1 with *d unchanged. */
int quad_null_design(const quad_null_cfg_t *cfg, quad_null_design_t *d);

/* Both electrodes to 0 V, the loop off. */
void quad_null_stop(quad_null_t *q);

/* Start: identify the gain (the probe), then close the loop from u = 0. */
void quad_null_start(const quad_null_design_t *d, quad_null_t *q);

/* Start with a known gain c (from a calibration): close the loop at once. Returns 0, or
 * -1 (c not finite or 0; q stopped). */
int quad_null_start_with_gain(const quad_null_design_t *d, quad_null_t *q, float c_dps_per_v2);

/* One update with the measured quadrature (deg/s, the rate channel's). A non-finite
 * value is no measurement: the voltages hold, the loop is not settled, and a probe
 * phase starts its mean again. */
void quad_null_update(const quad_null_design_t *d, quad_null_t *q, float quad_dps);

#endif /* QUAD_NULL_H */
