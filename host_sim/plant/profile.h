/* Input profiles of the plant: scalar time functions for the angular rate (deg/s) and
 * the ambient temperature (K), and the case acceleration/vibration (g) that the
 * g-sensitivity model (accel.h) reads. Host plant, double precision. Bounded
 * fixed-size storage, validated; evaluation never fails on a validated profile.
 *
 * Scalar profile kinds (t in seconds from the start of the run):
 *   CONST      v(t) = value
 *   STEPS      a rate table / chamber program: n_steps pairs (step_s[i], step_value[i]);
 *              step i lasts step_s[i] and holds step_value[i]; the first edge_s of every
 *              step but the first (and of the first when repeating) is a linear
 *              transition from the previous value (a rate table or a chamber cannot
 *              jump). After the last step the last value is held, or with repeat the
 *              table starts again. Before t = 0: the first value.
 *   SINE       v(t) = value + amp sin(2 pi freq_hz t + phase_rad)
 *   RAMP       v = value for t < t_start_s, value + slope_per_s (t - t_start_s) until
 *              t_end_s, then held.
 *   HEAT_COOL  heat-gun then cool-down (§7.3.2): value until t_start_s; then an
 *              exponential approach to hot_value with tau_heat_s for heat_s seconds;
 *              then an exponential return towards value with tau_cool_s.
 * profile_eval() returns v(t) and dv/dt (the rate's slope feeds the Euler term of the
 * mechanics; on a step edge it is the edge slope; at a jump, zero).
 *
 * Acceleration profile, per axis i (ACCEL_AXIS_DRIVE 0 = along the drive motion y,
 * ACCEL_AXIS_SENSE 1 = along the sense motion x, ACCEL_AXIS_NORMAL 2 = along the rate
 * axis z, as in accel.h):
 *   a_i(t) = const_g[i] + amp_g[i] sin(2 pi freq_hz[i] t + phase_rad[i])   (g)
 * accel_profile_mean() gives the exact mean over a sample, which is what the
 * mechanics holds.
 */
#ifndef PLANT_PROFILE_H
#define PLANT_PROFILE_H

#define PROFILE_MAX_STEPS 64
#define PROFILE_ACCEL_AXES 3

typedef enum {
  PROFILE_CONST = 0,
  PROFILE_STEPS = 1,
  PROFILE_SINE = 2,
  PROFILE_RAMP = 3,
  PROFILE_HEAT_COOL = 4,
  PROFILE_NKINDS = 5
} profile_kind_t;

typedef struct {
  profile_kind_t kind;
  double value;                     /* CONST value; SINE offset; RAMP start; HEAT_COOL base */
  double amp;                       /* SINE */
  double freq_hz;                   /* SINE, >= 0 */
  double phase_rad;                 /* SINE */
  double slope_per_s;               /* RAMP */
  double t_start_s;                 /* RAMP, HEAT_COOL */
  double t_end_s;                   /* RAMP, >= t_start_s */
  double hot_value;                 /* HEAT_COOL */
  double heat_s;                    /* HEAT_COOL heating duration, >= 0 */
  double tau_heat_s;                /* HEAT_COOL, > 0 */
  double tau_cool_s;                /* HEAT_COOL, > 0 */
  int n_steps;                      /* STEPS, 1..PROFILE_MAX_STEPS */
  double step_s[PROFILE_MAX_STEPS]; /* durations, > 0 */
  double step_value[PROFILE_MAX_STEPS];
  double edge_s; /* STEPS transition time, 0 <= edge_s <= every duration */
  int repeat;    /* STEPS: 0 hold the last value, 1 repeat the table */
} profile_t;

typedef struct {
  double const_g[PROFILE_ACCEL_AXES];
  double amp_g[PROFILE_ACCEL_AXES];
  double freq_hz[PROFILE_ACCEL_AXES];
  double phase_rad[PROFILE_ACCEL_AXES];
} accel_profile_t;

/* Name of a kind ("const", "steps", "sine", "ramp", "heat_cool") and back (-1 if
 * unknown). */
const char *profile_kind_name(profile_kind_t kind);
int profile_kind_from_name(const char *name);

/* Constructors: fill every field (the unused ones zero). */
void profile_const(profile_t *p, double value);
void profile_sine(profile_t *p, double offset, double amp, double freq_hz, double phase_rad);
void profile_ramp(profile_t *p, double start, double slope_per_s, double t_start_s,
                  double t_end_s);
void profile_heat_cool(profile_t *p, double base, double hot, double t_start_s, double heat_s,
                       double tau_heat_s, double tau_cool_s);
/* Copies n pairs; returns 0, or -1 (p unchanged) if n is outside 1..PROFILE_MAX_STEPS or
 * the result does not pass profile_check(). */
int profile_steps(profile_t *p, int n, const double *dur_s, const double *value, double edge_s,
                  int repeat);

/* 0, or -1 with *key naming the first bad field (e.g. "step_s[3]"). Values must be
 * finite with |value| <= 1e9, times within 1e9 s, frequencies 0..1e6 Hz. */
int profile_check(const profile_t *p, const char **key);

/* v(t) and, if slope != NULL, dv/dt. The profile must have passed profile_check(). */
double profile_eval(const profile_t *p, double t_s, double *slope_per_s);

void accel_profile_zero(accel_profile_t *a);
int accel_profile_check(const accel_profile_t *a, const char **key);
/* a(t) in g per axis. */
void accel_profile_eval(const accel_profile_t *a, double t_s, double a_g[PROFILE_ACCEL_AXES]);
/* Exact mean of a over [t0_s, t1_s] (t1 > t0), g per axis. */
void accel_profile_mean(const accel_profile_t *a, double t0_s, double t1_s,
                        double a_g[PROFILE_ACCEL_AXES]);
/* Largest |a_i(t)| over all t per axis (const + amp), for range budgets. */
void accel_profile_peak(const accel_profile_t *a, double peak_g[PROFILE_ACCEL_AXES]);

#endif /* PLANT_PROFILE_H */
