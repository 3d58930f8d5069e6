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

#include "dsp/fastmath.h"
#include "dsp/pi.h"
#include "dsp/ramfunc.h"
#include "gyro/settle_count.h"

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
  float integ_v2;    /* the integrator (u before the clamp of the output) */
  float u_cmd_v2;    /* the command u = V1^2 - V2^2 the voltages follow (quad_null_output) */
  float x_dps;       /* the update's measurement (quad_null_take) */
  float mean_dps;    /* the probe's latest mean (quad_null_mean) */
  float step_dps;    /* its step's effect, the step's mean less the base (verdict) */
  float root_v;      /* sqrt |u| (quad_null_root) */
  uint32_t in_band;  /* consecutive updates with |q| <= settle_dps */
  uint8_t settled;   /* in_band reached settle_updates */
  uint8_t at_limit;  /* u is at +-v_max^2 */
  uint8_t close_due; /* the probe's gain is in: the loop closes (gain, close, engage) */
  uint8_t mean_due;  /* a probe mean is complete (accumulate -> mean) */
  uint8_t skip;      /* the update's measurement was not finite */
  float v1_v, v2_v;  /* the electrode voltages, one of them 0 */
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
 * phase starts its mean again. The steps below in turn. */
void quad_null_update(const quad_null_design_t *d, quad_null_t *q, float quad_dps);

/* The sample interrupt's stop: the electrodes' voltages and command to 0, the loop off and
 * not settled, at once; the rest (the identified gain, shown by status) is cleared by
 * the next start. */
void quad_null_halt(quad_null_t *q);

/* quad_null_update's steps, for a caller that spreads one update over several ticks
 * (the sample interrupt: each fits beside a tick's other job, gyro_block.c). Each step
 * does its own part only, with no test of whether it is due: the caller takes the same
 * path through them as quad_null_update does (the mode, the flags named), all of them
 * before the next update.
 *   take        the measurement: skip when it is not finite (no measurement: the loop
 *               not settled, a probe mean starts again; nothing more this update)
 *   probe modes:
 *   accumulate  the probe's sums; mean_due when a mean is complete (else nothing more)
 *   mean        the mean
 *   verdict     the base (the step on), or (PROBE_STEP) the step's effect
 *   judge       after the step's: close_due if its effect is large enough, else
 *   fail_a, _b  FAILED: both electrodes at 0 V (nothing more)
 *   gain        close_due: the gain and the integrator's coefficient (one divide)
 *   close       close_due: the integrator from the probe's command, bumpless
 *   engage      then: RUN on the probe's command (the voltages stay: nothing more)
 *   RUN:
 *   integrate   the integrator
 *   limit       the command and its limit flag
 *   settle      the settling test (settled is final for the update)
 *   then (not after engage; not in OFF, FAILED):
 *   root        the square root of the command
 *   sign        the electrodes' voltages: the root on the one its sign selects
 * Inline, so that the tick's step is one call (gyro_block.c). */

/* The command u: the limit flag now (the settling test of the same update reads it), the
 * electrodes' voltages from it in quad_null_root and quad_null_sign. */
GYRO_RAMFUNC static inline void quad_null_command(quad_null_t *q, float u, float u_max)
{
  q->u_cmd_v2 = u;
  q->at_limit = (u >= u_max || u <= -u_max) ? 1u : 0u;
}

/* quad_null_stop in three parts (the sample interrupt starts the loop with them, one a
 * tick, then the mode PROBE_BASE), field by field rather than memset, whose library copy
 * lies in flash (linker/check_ramfunc.py): the integrator, the values, the counts,
 * flags and voltages. */
GYRO_RAMFUNC static inline void quad_null_clear_a(quad_null_t *q)
{
  q->pi.kp = 0.0f;
  q->pi.ki_t = 0.0f;
  q->pi.u_min = 0.0f;
  q->pi.u_max = 0.0f;
  q->pi_state.u = 0.0f;
  q->pi_state.e_prev = 0.0f;
  q->integ_v2 = 0.0f;
}

GYRO_RAMFUNC static inline void quad_null_clear_b(quad_null_t *q)
{
  q->sum_dps = 0.0f;
  q->base_dps = 0.0f;
  q->gain_dps_per_v2 = 0.0f;
  q->x_dps = 0.0f;
  q->step_dps = 0.0f;
  q->mean_dps = 0.0f;
  q->root_v = 0.0f;
}

GYRO_RAMFUNC static inline void quad_null_clear_c(quad_null_t *q)
{
  q->mode = QUAD_NULL_OFF;
  q->count = 0u;
  q->u_cmd_v2 = 0.0f;
  q->in_band = 0u;
  q->settled = 0u;
  q->at_limit = 0u;
  q->close_due = 0u;
  q->mean_due = 0u;
  q->skip = 0u;
  q->v1_v = 0.0f;
  q->v2_v = 0.0f;
}

/* The probe saw no effect: FAILED, the command and both electrodes at 0 V (fail_a), the
 * rest of its state cleared (fail_b); two halves for the tick's budget. */
GYRO_RAMFUNC static inline void quad_null_fail_a(quad_null_t *q)
{
  q->mode = QUAD_NULL_FAILED;
  q->u_cmd_v2 = 0.0f;
  q->v1_v = 0.0f;
  q->v2_v = 0.0f;
}

GYRO_RAMFUNC static inline void quad_null_fail_b(quad_null_t *q)
{
  q->root_v = 0.0f;
  q->settled = 0u;
  q->at_limit = 0u;
  q->close_due = 0u;
  q->gain_dps_per_v2 = 0.0f;
  q->integ_v2 = 0.0f;
  q->in_band = 0u;
}

GYRO_RAMFUNC static inline void quad_null_take(quad_null_t *q, float quad_dps)
{
  if (!fm_isfinite(quad_dps)) { /* no measurement: hold, and a probe mean starts again */
    q->skip = 1u;
    q->in_band = 0u;
    q->settled = 0u;
    q->count = 0u;
    q->sum_dps = 0.0f;
    return;
  }
  q->skip = 0u;
  q->x_dps = quad_dps;
}

GYRO_RAMFUNC static inline void quad_null_accumulate(const quad_null_design_t *d, quad_null_t *q)
{
  /* the probe's phases: wait, then average */
  const uint32_t n = ++q->count;
  if (n <= d->wait_updates) return;
  q->sum_dps += q->x_dps;
  if (n >= d->wait_updates + d->avg_updates) q->mean_due = 1u;
}

GYRO_RAMFUNC static inline void quad_null_mean(const quad_null_design_t *d, quad_null_t *q)
{
  q->mean_due = 0u;
  q->close_due = 0u;
  q->mean_dps = q->sum_dps * d->inv_avg;
  q->count = 0u;
  q->sum_dps = 0.0f;
}

GYRO_RAMFUNC static inline void quad_null_verdict(const quad_null_design_t *d, quad_null_t *q)
{
  if (q->mode == QUAD_NULL_PROBE_BASE) {
    q->base_dps = q->mean_dps;
    q->mode = QUAD_NULL_PROBE_STEP;
    quad_null_command(q, d->u_probe_v2, d->u_max_v2);
    return;
  }
  q->step_dps = q->mean_dps - q->base_dps;
}

GYRO_RAMFUNC static inline void quad_null_judge(const quad_null_design_t *d, quad_null_t *q)
{
  /* (A mean is of finite measurements, so the step is finite: an infinite one would need
   * a quadrature near 1e37 deg/s.) */
  const float step = q->step_dps;
  q->close_due = (step < 0.0f ? -step : step) >= d->min_step_dps ? 1u : 0u;
}

GYRO_RAMFUNC static inline void quad_null_integrate(quad_null_t *q)
{
  /* pi_step_position with Kp = 0 (quad_null_start_with_gain, _close): the output is the
   * clamped integral itself, so its second clamp is left out */
  float i = q->integ_v2 + q->pi.ki_t * q->pi_state.e_prev;
  i = (i > q->pi.u_max) ? q->pi.u_max : i;
  i = (i < q->pi.u_min) ? q->pi.u_min : i;
  q->integ_v2 = i;
  q->pi_state.u = i;
  q->pi_state.e_prev = -q->x_dps;
}

GYRO_RAMFUNC static inline void quad_null_limit(const quad_null_design_t *d, quad_null_t *q)
{
  quad_null_command(q, q->pi_state.u, d->u_max_v2);
}

GYRO_RAMFUNC static inline void quad_null_settle(const quad_null_design_t *d, quad_null_t *q)
{
  const float x = q->x_dps;
  const float a = x < 0.0f ? -x : x;
  const uint32_t n = settle_count(q->in_band, a <= d->settle_dps && !q->at_limit,
                                  d->settle_updates);
  q->in_band = n;
  q->settled = n >= d->settle_updates ? 1u : 0u;
}

GYRO_RAMFUNC static inline void quad_null_gain(const quad_null_design_t *d, quad_null_t *q)
{
  /* c, at least min_step / probe^2 in size: Ki T = 2 pi f_c T / c is finite (the
   * update's one divide) */
  const float c = q->step_dps * d->inv_u_probe_v2;
  q->gain_dps_per_v2 = c;
  q->pi.ki_t = d->wc_dt / c;
}

GYRO_RAMFUNC static inline void quad_null_close(const quad_null_design_t *d, quad_null_t *q)
{
  /* bumpless: the integrator takes over from the probe's command (within the limits:
   * the design holds probe_v <= v_max) with no error behind it */
  q->pi.kp = 0.0f;
  q->pi.u_min = -d->u_max_v2;
  q->pi.u_max = d->u_max_v2;
  q->pi_state.u = d->u_probe_v2;
  q->pi_state.e_prev = 0.0f;
  q->integ_v2 = d->u_probe_v2;
  q->base_dps = 0.0f;
}

GYRO_RAMFUNC static inline void quad_null_engage(const quad_null_design_t *d, quad_null_t *q)
{
  q->close_due = 0u;
  q->mode = QUAD_NULL_RUN;
  quad_null_command(q, d->u_probe_v2, d->u_max_v2);
}

/* u -> the electrode pair: one electrode carries sqrt(|u|), the other nothing */
GYRO_RAMFUNC static inline void quad_null_root(quad_null_t *q)
{
  const float u = q->u_cmd_v2;
  q->root_v = fm_sqrtf(u < 0.0f ? -u : u);
}

GYRO_RAMFUNC static inline void quad_null_sign(quad_null_t *q)
{
  const float u = q->u_cmd_v2, r = q->root_v;
  q->v1_v = u > 0.0f ? r : 0.0f;
  q->v2_v = u < 0.0f ? r : 0.0f;
}


#endif /* QUAD_NULL_H */
