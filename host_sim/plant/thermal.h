/* Three-node thermal network of the gyro (host plant, double precision).
 *
 * Nodes (THERMAL_*): the sensor structure (its temperature moves the resonances,
 * (2-32)), the pickoff circuit (its temperature moves the circuit phases, (2-40)),
 * and the spot where a board temperature sensor would sit (what a sensor-based
 * compensation would read). The thesis's case for sensorless compensation (§2.4.2 C,
 * §7.3) is the lag between a sensor and the parts whose temperature matters; this
 * network makes that lag a set of parameters, not a conclusion.
 *
 * Each node i follows the ambient Ta with its own time constant tau_i, is heated by
 * its own dissipation (a steady rise r_i above ambient if it were alone), and
 * exchanges heat with the others at symmetric pair rates g_ij (1/s):
 *
 *   dT_i/dt = (Ta + r_i - T_i) / tau_i + sum_j g_ij (T_j - T_i)
 *
 * i.e. dT/dt = -L T + b Ta + h, L = diag(1/tau) + Laplacian(g), b_i = 1/tau_i,
 * h_i = r_i/tau_i. L is symmetric positive definite, so every eigenvector decays (real
 * eigenvalues). Exact discretisation over the update period dt with the ambient held
 * (zero-order hold; the caller passes the ambient at the middle of the period, which
 * makes a ramp exact to second order):
 *
 *   T(k+1) = Phi T(k) + g_a Ta(k) + g_h,   Phi = exp(-L dt),
 *   Gam = int_0^dt exp(-L s) ds,  g_a = Gam b,  g_h = Gam h,
 * evaluated as T(k+1) = T(k) + (Phi - I)(T(k) - Ta) + g_h (Phi - I = -L Gam exactly),
 * which keeps the rounding of a 300 K state per step at the level of the increment.
 *
 * Pair order of couple_per_s[]: THERMAL_PAIR_SC (structure-circuit),
 * THERMAL_PAIR_SB (structure-board), THERMAL_PAIR_CB (circuit-board).
 */
#ifndef PLANT_THERMAL_H
#define PLANT_THERMAL_H

enum { THERMAL_STRUCT = 0, THERMAL_CIRCUIT = 1, THERMAL_BOARD = 2, THERMAL_NODES = 3 };
enum { THERMAL_PAIR_SC = 0, THERMAL_PAIR_SB = 1, THERMAL_PAIR_CB = 2 };

typedef enum {
  THERMAL_PRESET_DEFAULT = 0, /* pickoff next to the head, sensor on the DSP board */
  THERMAL_PRESET_TIGHT = 1,   /* all three nodes strongly coupled */
  THERMAL_PRESET_LOOSE = 2    /* nodes nearly independent, different time constants */
} thermal_preset_t;

typedef struct {
  double tau_s[THERMAL_NODES];        /* time constant of each node to ambient alone */
  double couple_per_s[THERMAL_NODES]; /* pair exchange rates g_ij, 1/s, >= 0 */
  double rise_k[THERMAL_NODES];       /* self-heating rise of each node alone, K */
  double dt_s;                        /* update period */
} thermal_cfg_t;

typedef struct {
  thermal_cfg_t cfg;
  double dphi[THERMAL_NODES][THERMAL_NODES]; /* Phi - I */
  double g_heat[THERMAL_NODES];              /* g_h */
  double t_k[THERMAL_NODES];
} thermal_t;

/* Fills cfg with a preset (dt_s = 1 ms). Unknown presets give the default. */
void thermal_preset(thermal_cfg_t *cfg, thermal_preset_t which);
void thermal_default_cfg(thermal_cfg_t *cfg);

/* 0, or negative with *key naming the first bad field ("tau_s[1]" style). */
int thermal_cfg_check(const thermal_cfg_t *cfg, const char **key);

/* Validates and discretises; all nodes start in the steady state of a constant
 * ambient_k. Returns 0, -1 (bad cfg or temperature; th unchanged), -2 (expm). */
int thermal_init(thermal_t *th, const thermal_cfg_t *cfg, double ambient_k);

/* As thermal_init, for a power-on after a long power-off: every node starts at the
 * ambient (nothing has dissipated yet), and thermal_step then warms it towards the
 * steady state of thermal_steady through the network's own modes, T(t) = Tss +
 * exp(-L t)(Ta - Tss) at a constant ambient. Same returns; th unchanged on error. */
int thermal_init_cold(thermal_t *th, const thermal_cfg_t *cfg, double ambient_k);

/* Advance dt_s with the ambient held at ambient_k. Non-finite input is ignored
 * (returns -1, state unchanged). */
int thermal_step(thermal_t *th, double ambient_k);

/* Steady state of a constant ambient: solves L T = b Ta + h. */
void thermal_steady(const thermal_cfg_t *cfg, double ambient_k, double t_k[THERMAL_NODES]);

double thermal_temp(const thermal_t *th, int node);
/* Overwrite the node temperatures (tests, scenario starts off equilibrium). */
void thermal_set(thermal_t *th, const double t_k[THERMAL_NODES]);

#endif /* PLANT_THERMAL_H */
