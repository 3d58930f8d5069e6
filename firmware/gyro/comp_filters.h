/* The temperature compensation's filters of the thermometer P_f (rate_channel.h):
 *   lag = P_f - P_c          P_c, the compensation's thermometer, P_f through
 *                            rate.comp_stages first-order low-passes of rate.comp_tau_s
 *                            each (per P update the weight comp_a); lag1 = P_f - P_1,
 *                            P_1 the first of two stages (0 with one stage)
 *   hp  = P_c - LP_tau(P_c)  the gradient term's input (rate.grad_tau_s, grad_a)
 * advanced by one step of P_f. Two stages: the thermometer's noise (the drive pickoff's
 * phase flicker, 1/f) falls as 1/f^2 above 1 / (2 pi tau) instead of 1/f, for a ramp lag
 * of 2 tau that the gradient term takes (docs/compensation-noise.md). Each is kept as a high-pass x - LP(x) = (1 - a)(its last
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

static inline void comp_filters_step(float *lag_deg, float *lag1_deg, float *hp_deg,
                                     float step_deg, float comp_a, float grad_a, uint32_t stages)
{
  float step_c; /* P_c's step */
  if (stages >= 2u) {
    const float d1 = *lag1_deg + step_deg;           /* P_f - P_1, P_f moved */
    const float step1 = comp_a * d1;                 /* P_1's step */
    const float d2 = (*lag_deg - *lag1_deg) + step1; /* P_1 - P_c, P_1 moved */
    step_c = comp_a * d2;
    *lag1_deg = d1 - step1;
    *lag_deg = *lag1_deg + (d2 - step_c);
  } else {
    const float d = *lag_deg + step_deg;
    step_c = comp_a * d;
    *lag_deg = d - step_c;
  }
  *hp_deg = (1.0f - grad_a) * (*hp_deg + step_c);
}

#endif /* COMP_FILTERS_H */
