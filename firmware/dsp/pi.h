/* Discrete PI controller of the drive loop (thesis 6.4), single precision.
 *
 * Transfer function (6-26b), the discretisation of C(s) = Kp + Ki/s (6-26a) with
 * sample time T used by the thesis:
 *     C(z) = (Kp - (Kp - Ki T) z^-1) / (1 - z^-1) = Kp + Ki T z^-1 / (1 - z^-1)
 * i.e. the integral acts on e(k-1) (forward rectangle). Realised in velocity
 * (incremental) form, state {u(k-1), e(k-1)}:
 *     u(k) = sat( u(k-1) + Kp (e(k) - e(k-1)) + Ki T e(k-1) ),  sat = clamp to [u_min, u_max]
 * which is u(k-1) + b0 e(k) + b1 e(k-1) with b0 = Kp, b1 = Ki T - Kp, evaluated through
 * the difference e(k) - e(k-1): with Ki T << Kp (1/200 in the example below) the sum
 * b0 e(k) + b1 e(k-1) would cancel to Ki T e and lose its low bits in float.
 * (The form u(k-1) + Kp (e(k) - e(k-1)) + Ki T e(k) would be the backward rectangle,
 * b0 = Kp + Ki T, b1 = -Kp: not (6-26b), whose worked example below has b0 = Kp.)
 * Sign convention: e = setpoint - measurement, u increases with a positive e for
 * positive gains; negative gains are allowed for a plant of negative gain.
 *
 * Anti-windup: the only integrating state is the previous output itself, and it is
 * stored after clamping. Saturation therefore stops the integration where it is: no
 * hidden integrator winds up, and the output leaves the limit on the first sample the
 * increment changes sign, however long it was saturated (the thesis loop has no limits;
 * a real drive stage has them).
 *
 * Bumpless gain change: u(k-1) carries the whole past, so new gains act only on the
 * next increment; a gain change makes no step in u.
 *
 * Worked example (6.4): C(s) = 2e-5 + 5.7e-3/s at 57 kHz gives
 * C(z) = (2e-5 - 1.99e-5 z^-1) / (1 - z^-1).
 */
#ifndef PI_H
#define PI_H

typedef struct {
  float kp;    /* proportional gain Kp */
  float ki;    /* integral gain Ki, per second */
  float dt_s;  /* sample time T, > 0 */
  float u_min; /* output limits, u_min < u_max */
  float u_max;
  float u_init; /* output at start, within the limits */
} pi_cfg_t;

/* What the step uses, derived from a pi_cfg_t (pi_design): constant while it runs. */
typedef struct {
  float kp;   /* Kp = b0 */
  float ki_t; /* Ki T = b0 + b1 */
  float u_min, u_max;
} pi_coeffs_t;

/* What the controller remembers. */
typedef struct {
  float u;      /* u(k-1), the clamped output (the integrator) */
  float e_prev; /* e(k-1) */
} pi_t;

/* Validate cfg (finite gains and Ki T, 0 < dt_s, finite u_min < u_max, u_min <= u_init
 * <= u_max) and derive the step's coefficients. Returns 0, or -1 and leaves *c
 * unchanged. */
int pi_design(const pi_cfg_t *cfg, pi_coeffs_t *c);

/* pi_design, then u = u_init, e(k-1) = 0. Returns 0, or -1 and changes nothing. */
int pi_init(const pi_cfg_t *cfg, pi_coeffs_t *c, pi_t *pi);

/* New coefficients c take over (new gains: bumpless, the next increment uses them; new
 * limits: u is clamped into them now). */
void pi_limit(const pi_coeffs_t *c, pi_t *pi);

/* Restart from output u (clamped into the limits) with e(k-1) = e_prev: pass the
 * current error so that the first increment has no proportional kick. Returns 0, or -1
 * and changes nothing for non-finite values. */
int pi_reset(const pi_coeffs_t *c, pi_t *pi, float u, float e_prev);

/* One sample of (6-26b) in velocity form with clamping; returns u(k). */
static inline float pi_step(const pi_coeffs_t *restrict c, pi_t *restrict pi, float e)
{
  float u = pi->u + c->kp * (e - pi->e_prev) + c->ki_t * pi->e_prev;
  u = (u > c->u_max) ? c->u_max : u;
  u = (u < c->u_min) ? c->u_min : u;
  pi->e_prev = e;
  pi->u = u;
  return u;
}

/* One sample of (6-26b) in position form: the integral *integ (its own state, clamped to
 * the limits on its own) takes Ki T e(k-1), the output is integral + Kp e(k), clamped.
 * Unlike the velocity form the output's clamp does not stop the integral where the
 * proportional part pushed it: a noisy error on a limit (a holding force of a few codes
 * near u_min = 0) cannot ratchet the integral up. pi->u and pi->e_prev are kept as in
 * pi_step, so either form can take over. Returns u(k). */
static inline float pi_step_position(const pi_coeffs_t *restrict c, pi_t *restrict pi,
                                     float *restrict integ, float e)
{
  float i = *integ + c->ki_t * pi->e_prev;
  i = (i > c->u_max) ? c->u_max : i;
  i = (i < c->u_min) ? c->u_min : i;
  *integ = i;
  float u = i + c->kp * e;
  u = (u > c->u_max) ? c->u_max : u;
  u = (u < c->u_min) ? c->u_min : u;
  pi->e_prev = e;
  pi->u = u;
  return u;
}

static inline float pi_output(const pi_t *pi) { return pi->u; }

#endif /* PI_H */
