#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "gyro/drive_loop.h"

/* The design puts the PI zero on the plant pole: Ki/Kp = 1/tau, Kp = wc tau / K. */
static void test_design_formula(void **state)
{
  (void)state;
  const drive_loop_design_in_t in = {0.03125, 0.00712, 30.0, 270.0, 50000.0, 1.0, 0.0};
  drive_loop_design_out_t out;
  assert_int_equal(drive_loop_design(&in, &out), 0);
  const double wc = 2.0 * M_PI * 30.0;
  assert_true(fabs(out.kp - wc * 0.00712 / 0.03125) < 1e-9 * out.kp);
  assert_true(fabs(out.ki - out.kp / 0.00712) < 1e-9 * out.ki);
  assert_true(fabs(out.bw_hz - 30.0) < 1e-9);
  assert_true(out.phase_margin_deg > 80.0);
}

/* Asking for more bandwidth than the demodulator allows is capped at 60 deg margin. */
/* Reference phase margin of the first-order plant (corner f_p) under an integral
 * controller with a pure delay of delay_samples at fs: 90 deg - atan(wc/wp) - wc*T_d. */
static double ref_margin_deg(double bw_hz, double f_p_hz, double delay_samples, double fs_hz)
{
  const double wc = 2.0 * M_PI * bw_hz;
  return 90.0 - (atan(wc / (2 * M_PI * f_p_hz)) + wc * delay_samples / fs_hz) * 180.0 / M_PI;
}

static void test_design_caps_bandwidth(void **state)
{
  (void)state;
  const drive_loop_design_in_t in = {1.0, 0.1, 1000.0, 270.0, 50000.0, 1.0, 0.0};
  drive_loop_design_out_t out;
  /* Each sample of delay costs margin, so the capped bandwidth falls: every sample
   * (1 + 1/2 for the hold), once per 10 samples with the command held (1 + 10/2), and
   * with the command reaching the DAC 4 samples after the measured one (4 + 1 + 10/2). */
  const struct {
    double loop_decim, lag_samples, delay_samples;
  } cases[] = {{1.0, 0.0, 1.5}, {10.0, 0.0, 6.0}, {10.0, 4.0, 10.0}};
  double bw_prev = 1000.0;
  drive_loop_design_in_t late = in;
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    late = in;
    late.loop_decim = cases[i].loop_decim;
    late.lag_samples = cases[i].lag_samples;
    assert_int_equal(drive_loop_design(&late, &out), 0);
    const double pm = ref_margin_deg(out.bw_hz, 270.0, cases[i].delay_samples, 50000.0);
    assert_true(fabs(pm - out.phase_margin_deg) < 1e-9 && pm >= 60.0);
    assert_true(out.bw_hz < bw_prev);
    bw_prev = out.bw_hz;
  }
  drive_loop_design_out_t out_l;
  /* Where the cap is not reached the delay changes nothing but the margin. */
  drive_loop_design_in_t slow = late;
  slow.bw_hz = 30.0;
  assert_int_equal(drive_loop_design(&slow, &out_l), 0);
  assert_true(fabs(out_l.bw_hz - 30.0) < 1e-9);
  assert_true(fabs(out_l.phase_margin_deg - ref_margin_deg(30.0, 270.0, 10.0, 50000.0)) < 1e-9);
  drive_loop_design_in_t bad = in;
  bad.loop_decim = -1.0;
  assert_int_equal(drive_loop_design(&bad, &out), -1);
  bad = in;
  bad.lag_samples = -1.0;
  assert_int_equal(drive_loop_design(&bad, &out), -1);
  bad = in;
  bad.lag_samples = NAN;
  assert_int_equal(drive_loop_design(&bad, &out), -1);
  bad = in;
  bad.tau_s = -1.0;
  assert_int_equal(drive_loop_design(&bad, &out), -1);
  bad = in;
  bad.plant_gain = NAN;
  assert_int_equal(drive_loop_design(&bad, &out), -1);
}

/* Envelope model of the drive mode near resonance (6-12, 6-17): the complex amplitude
 * Z of the pickoff follows K f e^{jP} with a first-order lag tau, discretised exactly
 * (ZOH). Z = w_s + j w_c as the LMSD reports it. */
typedef struct {
  double zr, zi, a, k;
} env_plant_t;

static void env_step(env_plant_t *p, double f, double p_rad)
{
  const double tr = p->k * f * cos(p_rad), ti = p->k * f * sin(p_rad);
  p->zr = p->a * p->zr + (1.0 - p->a) * tr;
  p->zi = p->a * p->zi + (1.0 - p->a) * ti;
}

/* Small steps (no saturation): amplitude and phase errors decay as the designed
 * first-order closed loop, e^{-wc t}, to a few per cent of the step (the LMSD lag is
 * not in this model, so the response is the ideal one). */
/* The configuration the loops under test run with (derived by dl_init). */
static drive_loop_cfg_t s_cfg;

/* Derive c and start dl with it; -1 (nothing changed) for a bad configuration. */
static int dl_init(drive_loop_t *dl, const drive_loop_cfg_t *c)
{
  drive_loop_cfg_t t = *c;
  if (drive_loop_cfg_derive(&t) != 0) return -1;
  s_cfg = t;
  drive_loop_init(&s_cfg, dl);
  return 0;
}

/* Loops from the amplitude and phase designs, run every dt_s, starting in equilibrium
 * with the envelope plant (1.9 V at phase 0.3 rad, force matching) and then asked for
 * 2.0 V and 0.35 rad. */
static void loop_at_equilibrium(drive_loop_t *dl, env_plant_t *p,
                                const drive_loop_design_out_t *amp,
                                const drive_loop_design_out_t *ph, double dt_s, double fs,
                                double tau, double k)
{
  drive_loop_cfg_t c = {.dt_s = (float)dt_s,
                        .amp_set_v = 2.0f,
                        .phase_set_rad = 0.3f,
                        .amp_kp = (float)amp->kp,
                        .amp_ki = (float)amp->ki,
                        .phase_kp = (float)ph->kp,
                        .phase_ki = (float)ph->ki,
                        .f_cmd_max_v2 = 196.0f,
                        .p_init_rad = 0.3f};
  assert_int_equal(dl_init(dl, &c), 0);
  const env_plant_t p0 = {1.9 * cos(0.3), 1.9 * sin(0.3), exp(-1.0 / (fs * tau)), k};
  *p = p0;
  dl->amp_pi.u = (float)(1.9 / k);
  dl->f_cmd_v2 = dl->amp_pi.u;
  s_cfg.phase_set_rad = 0.35f; /* a setpoint step */
}

static void test_closed_loop_first_order(void **state)
{
  (void)state;
  const double fs = 50000.0, tau = 0.00712, k = 0.03125, bw = 30.0;
  drive_loop_design_in_t in = {k, tau, bw, 270.0, fs, 1.0, 0.0};
  drive_loop_design_out_t amp, ph;
  in.plant_gain = k;
  assert_int_equal(drive_loop_design(&in, &amp), 0);
  in.plant_gain = 1.0;
  assert_int_equal(drive_loop_design(&in, &ph), 0);

  drive_loop_t dl;
  env_plant_t p;
  loop_at_equilibrium(&dl, &p, &amp, &ph, 1.0 / fs, fs, tau, k);
  const double wc = 2.0 * M_PI * bw;
  double max_amp = 0.0;
  for (int n = 1; n <= 10000; n++) {
    drive_loop_step(&s_cfg, &dl, (float)p.zr, (float)p.zi);
    env_step(&p, dl.f_cmd_v2, dl.p_rad);
    const double t = n / fs;
    const double a = hypot(p.zr, p.zi), ph_now = atan2(p.zi, p.zr);
    if (a > max_amp) max_amp = a;
    if (n % 500 == 0) {
      const double expect_a = 2.0 - 0.1 * exp(-wc * t);
      const double expect_p = 0.35 - 0.05 * exp(-wc * t);
      assert_true(fabs(a - expect_a) < 0.004);
      assert_true(fabs(ph_now - expect_p) < 0.002);
    }
  }
  assert_true(max_amp < 2.0 * 1.001); /* no overshoot */
}

/* From rest: the amplitude PI saturates at the drive limit, then comes off the limit
 * without overshoot (no wind-up, exact square-law linearisation), within 1 % by 0.2 s. */
static void test_startup_no_overshoot(void **state)
{
  (void)state;
  const double fs = 50000.0, tau = 0.00712, k = 0.03125;
  drive_loop_design_in_t in = {k, tau, 30.0, 270.0, fs, 1.0, 0.0};
  drive_loop_design_out_t amp, ph;
  assert_int_equal(drive_loop_design(&in, &amp), 0);
  in.plant_gain = 1.0;
  assert_int_equal(drive_loop_design(&in, &ph), 0);
  drive_loop_cfg_t c = {.dt_s = (float)(1.0 / fs),
                        .amp_set_v = 2.0f,
                        .phase_set_rad = 0.0f,
                        .amp_kp = (float)amp.kp,
                        .amp_ki = (float)amp.ki,
                        .phase_kp = (float)ph.kp,
                        .phase_ki = (float)ph.ki,
                        .f_cmd_max_v2 = 80.0f,
                        .p_init_rad = 0.0f}; /* 2.5 V at the limit */
  drive_loop_t dl;
  assert_int_equal(dl_init(&dl, &c), 0);
  env_plant_t p = {1e-4, 0.0, exp(-1.0 / (fs * tau)), k};
  double max_amp = 0.0;
  int saturated = 0;
  double t_in = -1.0;
  for (int n = 1; n <= 20000; n++) {
    drive_loop_step(&s_cfg, &dl, (float)p.zr, (float)p.zi);
    saturated |= dl.f_cmd_v2 >= 80.0f;
    env_step(&p, dl.f_cmd_v2, dl.p_rad);
    const double a = hypot(p.zr, p.zi);
    if (a > max_amp) max_amp = a;
    if (fabs(a - 2.0) > 0.02) t_in = -1.0;
    else if (t_in < 0.0) t_in = n / fs;
  }
  assert_true(saturated);
  assert_true(t_in > 0.0 && t_in < 0.2);
  assert_true(max_amp < 2.0 * 1.01);
}

/* The loops as gyro_tick runs them (gyro.h slot table): one update per block of 10
 * samples, spread over the block - arg Z measured on tick 0, the phase PI on tick 1,
 * the amplitude loop on tick 2, the command to the synthesis on tick 3, on the DAC's
 * frame from tick 4 and at the electrodes one sample later, held for the block -
 * designed with those lags (4 and 2 samples). Small steps settle as the designed
 * first-order loop delayed by the loop's delay (lag + 1 + N/2 samples), without
 * overshoot. */
static void test_block_schedule(void **state)
{
  (void)state;
  const double fs = 50000.0, tau = 0.00712, k = 0.03125, bw = 30.0;
  const int n_blk = 10;
  drive_loop_design_in_t in = {k, tau, bw, 270.0, fs, (double)n_blk, 2.0};
  drive_loop_design_out_t amp, ph;
  assert_int_equal(drive_loop_design(&in, &amp), 0);
  in.plant_gain = 1.0;
  in.lag_samples = 4.0;
  assert_int_equal(drive_loop_design(&in, &ph), 0);
  assert_true(amp.phase_margin_deg > 60.0 && ph.phase_margin_deg > 60.0);
  drive_loop_t dl;
  env_plant_t p;
  loop_at_equilibrium(&dl, &p, &amp, &ph, n_blk / fs, fs, tau, k);
  dl.amp_v = 1.9f;
  double f_set = dl.f_cmd_v2, p_set = dl.p_rad; /* command of the synthesis */
  double f_out = f_set, p_out = p_set;          /* at the electrodes */
  const double wc = 2.0 * M_PI * bw, t_d = (3.0 + 1.0 + n_blk / 2.0) / fs;
  double max_amp = 0.0;
  for (int n = 0; n < 10000; n++) {
    const int slot = n % n_blk;
    const float zs = (float)p.zr, zc = (float)p.zi;
    double f_dac = f_set, p_dac = p_set; /* this tick's DAC frame */
    if (slot == 0) drive_loop_measure_phase(&dl, zs, zc);
    if (slot == 1) drive_loop_update_phase(&s_cfg, &dl);
    if (slot == 2) drive_loop_step_amp(&s_cfg, &dl, zs, zc);
    if (slot == 3) { /* after the frame: from the next tick's on */
      f_set = dl.f_cmd_v2;
      p_set = dl.p_rad;
    }
    env_step(&p, f_out, p_out); /* the electrodes hold the last frame for this sample */
    f_out = f_dac;
    p_out = p_dac;
    const double t = (n + 1) / fs;
    const double a = hypot(p.zr, p.zi), ph_now = atan2(p.zi, p.zr);
    if (a > max_amp) max_amp = a;
    if ((n + 1) % 500 == 0) {
      const double e = t > t_d ? exp(-wc * (t - t_d)) : 1.0;
      assert_true(fabs(a - (2.0 - 0.1 * e)) < 0.003);
      assert_true(fabs(ph_now - (0.35 - 0.05 * e)) < 0.0015);
    }
  }
  assert_true(max_amp < 2.0 * 1.002);
}

static void test_bad_cfg(void **state)
{
  (void)state;
  drive_loop_t dl = {.amp_set_v = 5.0f};
  drive_loop_cfg_t c = {.dt_s = 2e-5f, .amp_set_v = 0.0f, .f_cmd_max_v2 = 100.0f};
  assert_int_equal(dl_init(&dl, &c), -1);
  c.amp_set_v = 1.0f;
  c.amp_kp = NAN;
  assert_int_equal(dl_init(&dl, &c), -1);
  c.amp_kp = 1.0f;
  c.p_init_rad = 10.0f;
  assert_int_equal(dl_init(&dl, &c), -1);
  assert_true(dl.amp_set_v == 5.0f);
}

/* The drive phase's start value may be anything the parameter drive.p_init_deg allows
 * (+-360 deg): drive synthesis carries whole turns of P itself, so the drive loop has no
 * narrower limit to impose. 355.2 .. 360 deg were refused before (a limit of 6.2 rad, a
 * stale copy of the phase conversion's domain), so `set drive.p_init_deg 358` failed in
 * the design although the parameter range accepts it. */
static void test_p_init_whole_parameter_range(void **state)
{
  (void)state;
  const float deg[] = {355.5f, 358.0f, 360.0f, -358.0f, -360.0f};
  for (size_t i = 0; i < sizeof deg / sizeof deg[0]; i++) {
    drive_loop_t dl;
    drive_loop_cfg_t c = {.dt_s = 2e-5f,
                          .amp_set_v = 2.0f,
                          .f_cmd_max_v2 = 100.0f,
                          .p_init_rad = deg[i] * 0.0174532925199433f};
    assert_int_equal(dl_init(&dl, &c), 0);
    assert_true(dl.p_rad == c.p_init_rad);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_design_formula),
      cmocka_unit_test(test_design_caps_bandwidth),
      cmocka_unit_test(test_block_schedule),
      cmocka_unit_test(test_closed_loop_first_order),
      cmocka_unit_test(test_startup_no_overshoot),
      cmocka_unit_test(test_bad_cfg),
      cmocka_unit_test(test_p_init_whole_parameter_range),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
