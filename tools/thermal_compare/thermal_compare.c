/* Which thermometer predicts the bias better: the drive phase P (sensorless, thesis
 * §2.4.2, §7.3) or a board temperature sensor? Computed from the plant's own laws and
 * thermal network, not assumed:
 *   structure node Ts -> resonances (2-32) -> drive phase (2-34) and sense phase (2-38)
 *   circuit laws (2-40) on the node chosen by pick_*_temp_node
 *   P   = change of the force phase the phase loop needs to hold the measured drive
 *         phase: -(d phi_mech(Ts)) + d lag_drive
 *   B   = quad_dps * sin(d lag_sense - d lag_drive + d phi_sense_struct(Ts)), the
 *         quadrature leaking into the rate channel (§2.4.2 B)
 *   sensor = board node Tb
 * Two runs of the thesis: the chamber (§7.3.1: 26, 28, 30, 35 degC, 30 min each, read at
 * the end of each step) and the heat-gun cool-down (§7.3.2: heat, then fit from 790 s
 * on). For each, B is fitted linearly (the thesis's method) against P, against the
 * board sensor and against the ambient; the residuals are printed for the default,
 * tight and loose thermal presets, and for the sense circuit law on each node.
 * Usage: thermal_compare   (no arguments; about a second) */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "plant/plant.h"
#include "plant/plant_const.h"

static const double kPi = PLANT_PI;
static const double kDeg = PLANT_RAD_PER_DEG;

typedef struct {
  double p_deg, b_dps, tb_k, ta_k;
} obs_t;

static double lag_law(double phi1, double phi2, double dt)
{
  return (phi1 * dt + 0.5 * phi2 * dt * dt) * kDeg;
}

static void observe(const plant_cfg_t *c, const thermal_t *th, double ta, obs_t *o)
{
  const double t0 = c->temp_ref_k;
  const double ts = thermal_temp(th, THERMAL_STRUCT);
  const double tnd = thermal_temp(th, c->pick_drive_temp_node);
  const double tns = thermal_temp(th, c->pick_sense_temp_node);
  const double wc = 2.0 * kPi * c->f_drive_hz;
  const double s = 1.0 - 0.5 * c->ket_per_k * (ts - t0); /* (2-32) */
  const double wn1 = wc * s, wn2 = 2.0 * kPi * c->f_sense_hz * s;
  const double wn20 = 2.0 * kPi * c->f_sense_hz;
  /* (2-34): drive displacement phase at fixed wc; (2-38): sense lag */
  const double phi_d = -atan2(wn1 * wc / c->q_drive, wn1 * wn1 - wc * wc);
  const double phi_d0 = -atan2(wc * wc / c->q_drive, 0.0);
  const double lag_s = atan2(wn2 * wc / c->q_sense, wn2 * wn2 - wc * wc);
  const double lag_s0 = atan2(wn20 * wc / c->q_sense, wn20 * wn20 - wc * wc);
  const double dlag_d = lag_law(c->pick_drive_phi1_deg_per_k, c->pick_drive_phi2_deg_per_k2,
                                tnd - t0);
  const double dlag_s = lag_law(c->pick_sense_phi1_deg_per_k, c->pick_sense_phi2_deg_per_k2,
                                tns - t0);
  o->p_deg = (-(phi_d - phi_d0) + dlag_d) / kDeg;
  o->b_dps = c->quad_dps * sin(dlag_s - dlag_d + (lag_s - lag_s0));
  o->tb_k = thermal_temp(th, THERMAL_BOARD);
  o->ta_k = ta;
}

/* least-squares line y = a + b x; returns rms and peak-to-peak of the residual */
static void fit(const double *x, const double *y, int n, double *rms, double *pp)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int i = 0; i < n; i++) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx), a = (sy - b * sx) / n;
  double s2 = 0, lo = 1e300, hi = -1e300;
  for (int i = 0; i < n; i++) {
    const double r = y[i] - (a + b * x[i]);
    s2 += r * r;
    lo = fmin(lo, r);
    hi = fmax(hi, r);
  }
  *rms = sqrt(s2 / n);
  *pp = hi - lo;
}

#define NMAX 8000

static void report(const char *what, const obs_t *o, int n)
{
  static double p[NMAX], b[NMAX], tb[NMAX], ta[NMAX];
  for (int i = 0; i < n; i++) {
    p[i] = o[i].p_deg;
    b[i] = o[i].b_dps;
    tb[i] = o[i].tb_k;
    ta[i] = o[i].ta_k;
  }
  double r1, p1, r2, p2, r3, p3;
  fit(p, b, n, &r1, &p1);
  fit(tb, b, n, &r2, &p2);
  fit(ta, b, n, &r3, &p3);
  printf("  %-22s bias span %6.2f deg/s | residual rms/pp (deg/s): P %.3f/%.3f  board %.3f/%.3f  ambient %.3f/%.3f\n",
         what, b[n - 1] - b[0], r1, p1, r2, p2, r3, p3);
}

static void run(const char *name, const plant_cfg_t *c)
{
  thermal_cfg_t thc;
  thermal_default_cfg(&thc);
  thc.tau_s[0] = c->tau_struct_s;
  thc.tau_s[1] = c->tau_circuit_s;
  thc.tau_s[2] = c->tau_board_s;
  thc.couple_per_s[0] = c->couple_sc_per_s;
  thc.couple_per_s[1] = c->couple_sb_per_s;
  thc.couple_per_s[2] = c->couple_cb_per_s;
  thc.rise_k[0] = c->rise_struct_k;
  thc.rise_k[1] = c->rise_circuit_k;
  thc.rise_k[2] = c->rise_board_k;
  thc.dt_s = 0.5;
  static thermal_t th;
  static obs_t o[NMAX];
  printf("%s\n", name);
  /* chamber: 26, 28, 30, 35 degC, 30 min each, read at the end of each step (table 7-4) */
  const double steps[4] = {299.15, 301.15, 303.15, 308.15};
  if (thermal_init(&th, &thc, steps[0]) != 0) return;
  int n = 0;
  for (int s = 0; s < 4; s++) {
    for (int k = 0; k < 3600; k++) thermal_step(&th, steps[s]);
    observe(c, &th, steps[s], &o[n++]);
  }
  report("chamber (4 readings)", o, n);
  /* heat gun then cool-down (§7.3.2): room 22.5 degC, hot air +60 K for 400 s, fit
   * 790 s .. 4000 s, one reading every 2 s */
  profile_t amb;
  profile_heat_cool(&amb, 295.65, 355.65, 0.0, 400.0, 5.0, 30.0);
  if (thermal_init(&th, &thc, 295.65) != 0) return;
  n = 0;
  for (int k = 0; k < 8000; k++) {
    const double t = k * thc.dt_s;
    const double ta = profile_eval(&amb, t + 0.5 * thc.dt_s, NULL);
    thermal_step(&th, ta);
    if (t >= 790.0 && (k % 4) == 0 && n < NMAX) observe(c, &th, ta, &o[n++]);
  }
  report("cool-down (790-4000 s)", o, n);
}

int main(void)
{
  plant_cfg_t c;
  plant_default_cfg(&c);
  printf("bias against thermometers, linear fits (thesis: B = 34.59 P + 58.53, 0.46 deg/s "
         "residual over its cool-down)\n");
  const char *presets[3] = {"default", "tight", "loose"};
  for (int i = 0; i < 3; i++) {
    plant_cfg_t d = c;
    plant_thermal_preset(&d, presets[i]);
    char name[96];
    snprintf(name, sizeof name, "preset %s, sense circuit law on the circuit node", presets[i]);
    run(name, &d);
  }
  const char *nodes[3] = {"structure", "circuit", "board"};
  for (int nd = 0; nd < 3; nd += 2) {
    plant_cfg_t d = c;
    d.pick_sense_temp_node = nd;
    d.pick_drive_temp_node = nd;
    char name[96];
    snprintf(name, sizeof name, "preset default, circuit laws on the %s node", nodes[nd]);
    run(name, &d);
  }
  return 0;
}
