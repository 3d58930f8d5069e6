/* The temperature compensation's filters of the thermometer P_f (rate_channel.h):
 *   lag = P_f - P_c          P_c, the compensation's thermometer, P_f through
 *                            rate.comp_stages first-order low-passes of rate.comp_tau_s
 *                            each (per P update the weight comp_a); mid = P_f - P_k
 *                            for the stages before the last
 *   hp  = P_c - LP_tau(P_c)  the gradient term's input (rate.grad_tau_s, grad_a)
 * advanced by one step of P_f. n stages: the thermometer's noise (the drive pickoff's
 * phase flicker, 1/f) falls as 1/f^(n+1) above 1 / (2 pi tau) instead of 1/f^2, for a
 * ramp lag of n tau that the gradient term takes (docs/compensation-noise.md). Each is kept as a high-pass x - LP(x) = (1 - a)(its last
 * value + x's step): the states stay small, so that no float low-pass of minutes has a
 * dead band. rate_channel runs them on P_f; rate_valid runs a shadow of them, window by
 * window (rate_valid_spur_matrix), on the moves of P_f no temperature makes, to know what
 * those moves left in the compensation. */
#ifndef COMP_FILTERS_H
#define COMP_FILTERS_H

#include <stdint.h>

/* The filters take P_f's steps once the value P_f was held at (rate_channel_hold_p)
 * weighs less than this in it: P_f's way from there to P is no temperature change.
 * 1e-4: a restart 5 deg of P from the held value (a part that cooled by 60 K while off)
 * leaves 5e-4 deg of it to the gradient term, 0.005 deg/s at 10 (deg/s)/deg. */
#define COMP_FILTERS_HELD_W_MAX 1e-4f

/* The most stages of P_c's low-pass (rate.comp_stages). */
#define COMP_STAGES_MAX 3u

/* lag_deg: P_f - P_c; mid_deg[k]: P_f - P_(k+1) for the stages before the last (0 where
 * there are fewer). Per stage the step of the stage before it (P_f's for the first) moves
 * the stage by comp_a of the distance left; each lag then grows by P_f's step less its
 * stage's. */
static inline void comp_filters_step(float *lag_deg, float mid_deg[COMP_STAGES_MAX - 1u],
                                     float *hp_deg, float step_deg, float comp_a, float grad_a,
                                     uint32_t stages)
{
  float lag_before = 0.0f;      /* P_f - P_(k-1) before this step (P_0 = P_f) */
  float step_before = step_deg; /* P_(k-1)'s step */
  for (uint32_t k = 0u; k < stages; k++) {
    float *lag = k + 1u == stages ? lag_deg : &mid_deg[k];
    const float d = (*lag - lag_before) + step_before; /* P_(k-1) - P_k, P_(k-1) moved */
    const float step_k = comp_a * d;                   /* P_k's step */
    lag_before = *lag;
    *lag = (*lag + step_deg) - step_k;
    step_before = step_k;
  }
  *hp_deg = (1.0f - grad_a) * (*hp_deg + step_before);
}

#endif /* COMP_FILTERS_H */
