/* The temperature compensation's two filters of the thermometer P_f (rate_channel.h):
 *   lag = P_f - P_c          P_c, the compensation's thermometer, P_f low-passed
 *                            (rate.comp_tau_s, per P update the weight comp_a)
 *   hp  = P_c - LP_tau(P_c)  the gradient term's input (rate.grad_tau_s, grad_a)
 * advanced by one step of P_f. Each is kept as a high-pass x - LP(x) = (1 - a)(its last
 * value + x's step): the states stay small, so that no float low-pass of minutes has a
 * dead band. rate_channel runs them on P_f; rate_valid runs a shadow of them, window by
 * window (rate_valid_spur_matrix), on the moves of P_f no temperature makes, to know what
 * those moves left in the compensation. */
#ifndef COMP_FILTERS_H
#define COMP_FILTERS_H

/* The filters take P_f's steps once the value P_f was held at (rate_channel_hold_p)
 * weighs less than this in it: P_f's way from there to P is no temperature change.
 * 1e-4: a restart 5 deg of P from the held value (a part that cooled by 60 K while off)
 * leaves 5e-4 deg of it to the gradient term, 0.005 deg/s at 10 (deg/s)/deg. */
#define COMP_FILTERS_HELD_W_MAX 1e-4f

static inline void comp_filters_step(float *lag_deg, float *hp_deg, float step_deg,
                                     float comp_a, float grad_a)
{
  const float d = *lag_deg + step_deg;
  const float step_c = comp_a * d; /* P_c's step */
  *lag_deg = d - step_c;
  *hp_deg = (1.0f - grad_a) * (*hp_deg + step_c);
}

#endif /* COMP_FILTERS_H */
