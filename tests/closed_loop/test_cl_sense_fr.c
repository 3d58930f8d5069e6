/* Force rebalance (sense.mode 1, sense_fr.h, issue 19) through the whole firmware and the
 * host HAL, on the default plant with a sense mode of Q = 10^4 at 1600 Hz (a 110 Hz split
 * above the drive) and a half-frequency feedback pair (plant fb_mode 3): a 0 -> 100 deg/s
 * step settles within 1 % of the step in at most 10 ms, with the part's 1500 deg/s
 * quadrature rebalanced as well (open loop it would put 6 times the ADC's range on the
 * sense pickoff), and the rate is never valid and wrong (against the plant's rate).
 * Negative control: open loop (sense.mode 0) on the same part, its quadrature removed so
 * that the pickoff does not clip, rings at the split for seconds, and its rate is not
 * valid while it does (the settling monitor sees the ringing on the quadrature axis,
 * rate_valid.h RATE_VALID_RING_TOLS).
 * The same step on parts of sense Q 300 and 3 (the thesis's), the same split, force
 * rebalance against open loop (issue 19 item 4's table; the README's force-rebalance
 * section); a matched part is test_cl_sense_tune.c's. The continuous self-test with the
 * loop closed, and what it catches (a dead sense pickoff).
 * The DC+AC scheme (sense.fb_scheme 1, plant fb_mode 2: a 5 V bias +- the AC voltage) on
 * the same part: the same step, the same figures. With parallel-plate electrodes (a gap)
 * the bias softens the sense spring (6-3); the model's f0 is then the softened resonance,
 * and a model that leaves the softening out misses the 10 ms (a control).
 *
 * The part's model as its identification would give it, from the plant's own values:
 * the demodulation phase and scale of the default part's calibration moved by the sense
 * mode's static response at the drive frequency (the mode's phase and gain at wc, 2-24),
 * and g from the electrode: the feedback force Ks_fb per V^2 balances 2 Omega A0 wc. The
 * electrode and electronic noise sources are off, so that the 1 % band of the step (1
 * deg/s) measures the loop and its filter, not the noise of a 500 Hz output. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app_plant.h"
#include "sense_mode_model.h"

#define F_SENSE_HZ SENSE_TEST_F_HZ
#define STEP_DPS 100.0
#define T_STEP_S 0.8 /* past the continuous self-test's 0.5 s of settling after LOCKED */

/* A part of the step test: its sense mode, its feedback electrodes and the model the
 * firmware gets of them. fb_scheme 0 is the half-frequency pair (plant fb_mode 3,
 * sense.fb_scheme 0); 1 is DC+AC (plant fb_mode 2: the plant's bias fb_bias_v +- the spare
 * converter's AC voltage, sense.fb_bias_v the same 5 V, sense.fb_scheme 1). */
typedef struct {
  uint32_t sense_mode;
  double quad_dps, q_sense;
  uint32_t fb_scheme;
  double gap_m;       /* the feedback electrodes' gap (plant.fb_gap_m), 0: no softening */
  double f_sense_hz;  /* the plant's sense resonance, before any softening */
  int model_softened; /* the model's f0 with the DC bias's softening (1), or without (0) */
  int pickoff_noise;  /* the default plant's sense pickoff noise and Brownian force on (1) */
  double dtemp_k;     /* the ambient (all nodes at steady state) this far from the model's */
} fr_part_t;

/* The sense resonance the loop sees: under DC+AC with a gap the bias softens the sense
 * spring by k_e / m = 4 Ks Vb^2 / gap ((6-3), plant_fb_softening), so the mode rings at
 * sqrt(ws^2 - k_e / m); without a gap, or with no DC on the electrodes, at ws. */
static double softened_f_hz(const plant_cfg_t *pc)
{
  const double ws = 2.0 * FM_PI * pc->f_sense_hz;
  return sqrt(ws * ws - plant_fb_softening(pc)) / (2.0 * FM_PI);
}

/* The part fp, its model as above: the mode's response at wc (phase, scale) and sense.f0_hz
 * from the resonance the loop sees (the softened one) unless fp says otherwise. */
static void start_part(const fr_part_t *fp)
{
  plant_cfg_t pc;
  sense_test_part(&pc, fp->q_sense);
  pc.quad_dps = fp->quad_dps;
  pc.f_sense_hz = fp->f_sense_hz;
  pc.fb_gap_m = fp->gap_m;
  if (fp->fb_scheme == 1u) pc.fb_mode = 2;
  pc.temp_k += fp->dtemp_k;
  if (fp->pickoff_noise) {
    plant_cfg_t d;
    plant_default_cfg(&d);
    pc.pick_sense_noise_v_rthz = d.pick_sense_noise_v_rthz;
    pc.brownian = d.brownian;
  }
  const double f0 = fp->model_softened ? softened_f_hz(&pc) : pc.f_sense_hz;
  param_values_t v;
  default_part_values(&v);
  sense_test_cal_moved(&v, f0, fp->q_sense);
  /* g = rate per V^2 (Ks_fb / (2 A0 wc)) over the scale, in the pickoff's volts: the same
   * in both schemes, whose synthesis makes the same force of the same command */
  const double k_dps_per_v2 = plant_fb_rate_dps_per_v2(&pc, (double)v.drive_freq_hz,
                                                       pc.drive_amp_m);
  v.sense_fb_gain_v_per_v2 = (float)(k_dps_per_v2 / (double)v.rate_scale_dps *
                                     (double)v.drive_amp_set_v);
  v.sense_f0_hz = (float)f0;
  v.sense_q = (float)fp->q_sense;
  v.sense_mode = fp->sense_mode;
  v.cal_ref_sense_mode = fp->sense_mode; /* the model's calibration is this mode's */
  v.sense_fb_scheme = fp->fb_scheme;
  v.sense_fb_bias_v = (float)pc.fb_bias_v;
  app_plant_start(&pc, 21u, &v);
}

/* The part with a sense mode of quality q_sense at F_SENSE_HZ, the half-frequency pair. */
static void start_q(uint32_t sense_mode, double quad_dps, double q_sense)
{
  const fr_part_t fp = {sense_mode, quad_dps, q_sense, 0u, 0.0, F_SENSE_HZ, 1, 0, 0.0};
  start_part(&fp);
}

static void start(uint32_t sense_mode, double quad_dps)
{
  start_q(sense_mode, quad_dps, 1.0e4);
}

typedef struct {
  double settle_ms;  /* last block outside 1 % of the step, after the step */
  double peak_dps;   /* the largest rate after the step */
  double final_dps;  /* mean over the last 20 ms */
  int valid_wrong;   /* a valid block more than 1 % of the step from the plant's rate */
  long valid_blocks; /* valid blocks in all */
  long valid_before; /* of the VALID_SPAN blocks before the step */
  long valid_tail;   /* of the last VALID_SPAN blocks */
} step_t;

#define BLOCK_S ((double)GYRO_BLOCK / 50000.0)
#define N_AFTER 500    /* 0.1 s of blocks after the step */
#define VALID_SPAN 250 /* 50 ms of blocks */

/* Runs to the step, steps, runs N_AFTER blocks; the rate of every block after it.
 * Valid and wrong is judged against the plant's rate times the loop's own scale (the
 * final value over the step): the model-made scale of start() is off by its accuracy
 * (0.9 %), which a calibration takes out, and that is no failure of the monitors. */
static step_t run_step(void)
{
  step_t r = {0.0, -1e9, 0.0, 0, 0, 0, 0};
  static float rate[N_AFTER + VALID_SPAN];
  static double truth[N_AFTER + VALID_SPAN];
  static uint8_t valid[N_AFTER + VALID_SPAN];
  const long before = (long)(T_STEP_S / BLOCK_S);
  for (long n = 0; n < before + N_AFTER; n++) {
    if (n == before) app_plant_hold_rate(STEP_DPS);
    hal_host_run(GYRO_BLOCK);
    const gyro_out_t *o = &app.gyro.out;
    r.valid_blocks += o->rate_valid != 0u;
    if (n >= before - VALID_SPAN) {
      const long i = n - (before - VALID_SPAN);
      rate[i] = o->rate_dps;
      truth[i] = plant_truth(&plant)->rate_dps;
      valid[i] = o->rate_valid != 0u;
    }
  }
  const int tail = (int)(0.020 / BLOCK_S);
  const float *after = rate + VALID_SPAN;
  for (int i = N_AFTER - tail; i < N_AFTER; i++) r.final_dps += (double)after[i] / tail;
  const double gain = r.final_dps / STEP_DPS;
  for (int i = 0; i < N_AFTER + VALID_SPAN; i++) {
    /* outside the 10 ms the step takes to pass any output filter */
    const int in_step = i >= VALID_SPAN && i < VALID_SPAN + (int)(0.010 / BLOCK_S);
    if (valid[i] && !in_step && fabs((double)rate[i] - gain * truth[i]) > 0.01 * STEP_DPS)
      r.valid_wrong = 1;
    r.valid_before += i < VALID_SPAN && valid[i];
    r.valid_tail += i >= N_AFTER && valid[i];
  }
  for (int i = 0; i < N_AFTER; i++) {
    if (fabs((double)after[i] - r.final_dps) > 0.01 * STEP_DPS)
      r.settle_ms = (i + 1) * BLOCK_S * 1e3;
    if (after[i] > r.peak_dps) r.peak_dps = after[i];
  }
  return r;
}

/* After run_step: on until the rate is valid again (at most max_s from the step), then
 * VALID_SPAN blocks more, judged as run_step judges, the loop's scale taken from their
 * own mean (run_step's final value, 0.1 s after the step, still carries the ringing of
 * a Q 10^4 part). Returns the time from the step to the first valid block, in ms (-1:
 * not valid within max_s); *wrong: a valid block of those more than 1 % of the step
 * from the plant's rate. */
static double invalid_after_step_ms(double max_s, int *wrong)
{
  long n = N_AFTER;
  const long n_max = (long)(max_s / BLOCK_S);
  while (app.gyro.out.rate_valid == 0u && n < n_max) {
    hal_host_run(GYRO_BLOCK);
    n++;
  }
  if (app.gyro.out.rate_valid == 0u) return -1.0;
  const double ms = (double)n * BLOCK_S * 1e3;
  static float rate[VALID_SPAN];
  static double truth[VALID_SPAN];
  static uint8_t valid[VALID_SPAN];
  double mean = 0.0;
  for (int i = 0; i < VALID_SPAN; i++) {
    const gyro_out_t *o = &app.gyro.out;
    rate[i] = o->rate_dps;
    truth[i] = plant_truth(&plant)->rate_dps;
    valid[i] = o->rate_valid != 0u;
    mean += (double)rate[i] / VALID_SPAN;
    hal_host_run(GYRO_BLOCK);
  }
  const double gain = mean / STEP_DPS;
  *wrong = 0;
  for (int i = 0; i < VALID_SPAN; i++)
    if (valid[i] && fabs((double)rate[i] - gain * truth[i]) > 0.01 * STEP_DPS) *wrong = 1;
  return ms;
}

/* The step with the loop closed on the part started: settles within 10 ms at the model's
 * scale, valid before the step and after settling, never valid and wrong, the loop
 * balanced and the sense motion held near zero. Returns the step's figures. */
static step_t check_closed_step(const char *what)
{
  const step_t r = run_step();
  const sense_fr_t *fr = &app.gyro.fr;
  printf("# force rebalance, %s, Q 1e4, 110 Hz split, 1500 deg/s quadrature: 0 -> 100 deg/s "
         "settles to 1 %% in %.1f ms (overshoot %.1f %%), peak %.2f, final %.2f deg/s (true "
         "%.1f); force I %.2f "
         "Q %.2f V^2, settled %u, at limit %u; valid blocks %ld (50 ms before the step %ld, "
         "last 50 ms %ld), valid and wrong %d, reasons 0x%x\n",
         what, r.settle_ms, 100.0 * (r.peak_dps - r.final_dps) / STEP_DPS, r.peak_dps,
         r.final_dps, plant_truth(&plant)->rate_dps, (double)fr->f_re, (double)fr->f_im,
         fr->settled, fr->at_limit, r.valid_blocks, r.valid_before, r.valid_tail, r.valid_wrong,
         app.gyro.out.rate_invalid);
  assert_true(r.settle_ms <= 10.0);
  assert_true(fabs(r.final_dps - STEP_DPS) <= 0.02 * STEP_DPS); /* the model's scale */
  assert_false(r.valid_wrong);
  /* valid with the loop closed: at rest before the step, and once the step has settled
   * (the settling monitor judges the wide output band's difference through its own
   * low-pass, rate_valid.h) */
  assert_int_equal(r.valid_before, VALID_SPAN);
  assert_int_equal(r.valid_tail, VALID_SPAN);
  assert_true(fr->run != 0u && fr->settled != 0u && fr->at_limit == 0u);
  assert_int_equal(app.gyro.out.rate_invalid & RATE_INVALID_SENSE_FR, 0u);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  /* the sense motion held near zero: the pickoff far inside the ADC's range */
  assert_true(fabs(plant_truth(&plant)->sense_vel_m) < 1e-9);
  const char *s = cmd("status\n");
  assert_non_null(strstr(s, "sense_fr balanced"));
  return r;
}

static void test_step_settles_within_10_ms(void **state)
{
  (void)state;
  start(1u, 1500.0);
  (void)check_closed_step("half-frequency pair");
}

/* The DC+AC scheme (sense.fb_scheme 1, plant fb_mode 2: 5 V of bias +- the AC voltage, the
 * force 4 Ks Vb u (6-20)) on the same part: the same step, the same figures. Its synthesis
 * makes the same force of the same command (drive_synth.h), so the loop's design and the
 * model's g are the half-frequency case's. The AC voltage for the 1500 deg/s of quadrature
 * is |F| / (4 Vb) = 2.5 V on the 5 V bias. */
static void test_dcac_step_settles_within_10_ms(void **state)
{
  (void)state;
  const fr_part_t fp = {1u, 1500.0, 1.0e4, 1u, 0.0, F_SENSE_HZ, 1, 0, 0.0};
  start_part(&fp);
  (void)check_closed_step("DC+AC");
  assert_int_equal(app.gyro.fb_synth.scheme, GYRO_DRIVE_DC_AC);
}

/* DC+AC on parallel-plate electrodes (a gap of 2 um): the 5 V bias softens the sense
 * spring by 4 Ks Vb^2 / gap = 5e6 1/s^2 ((6-3), plant_fb_softening), 40 Hz at 1600 Hz.
 * The part is made so that the mode the loop sees is the step test's (the plant's own
 * resonance sqrt(1600^2 + 4 Ks Vb^2 / (gap (2 pi)^2)) = 1639.1 Hz, softened to 1600 Hz);
 * the model's f0 is the softened resonance (an identification with the bias on measures
 * it so): the step settles as on the unsoftened part. The control: a model at the
 * unsoftened resonance (the bias left out) sees a 149 Hz split where the loop has 110 Hz,
 * and misses the 10 ms. */
#define GAP_M 2e-6
static double unsoftened_f_hz(void)
{
  const double ke = 4.0 * SENSE_TEST_KS_FB * 5.0 * 5.0 / GAP_M; /* the 5 V plant bias */
  const double ws = 2.0 * FM_PI * F_SENSE_HZ;
  return sqrt(ws * ws + ke) / (2.0 * FM_PI);
}

static void test_dcac_softened_model(void **state)
{
  (void)state;
  const fr_part_t fp = {1u, 1500.0, 1.0e4, 1u, GAP_M, unsoftened_f_hz(), 1, 0, 0.0};
  start_part(&fp);
  /* the model's split, wd - wc of its pole (sense_fr.h), is the step test's 110 Hz */
  assert_true(fabs((double)app.gyro.design->fr.p_im / (2.0 * FM_PI) - 110.1) < 0.5);
  (void)check_closed_step("DC+AC, 2 um gap, model at the softened resonance");
}

static void test_dcac_unsoftened_model_misses(void **state)
{
  (void)state;
  const fr_part_t fp = {1u, 1500.0, 1.0e4, 1u, GAP_M, unsoftened_f_hz(), 0, 0, 0.0};
  start_part(&fp);
  const step_t r = run_step();
  printf("# force rebalance, DC+AC, 2 um gap, model at the unsoftened %.1f Hz (the loop sees "
         "%.1f Hz): settles to 1 %% in %.1f ms, final %.2f deg/s, valid and wrong %d\n",
         unsoftened_f_hz(), F_SENSE_HZ, r.settle_ms, r.final_dps, r.valid_wrong);
  assert_true(r.settle_ms > 10.0);
  assert_false(r.valid_wrong);
}

/* Open loop on the same part (its quadrature removed: open loop it would clip the ADC):
 * the step rings at the 110 Hz split, far from 1 % 0.1 s later; the loop's reason is
 * never set, but the rate is never valid and wrong (the rule of integrity_judge.h,
 * max(1 deg/s, 1 % of the input): 1 deg/s for this step): the ringing is seen. */
static void test_open_loop_rings(void **state)
{
  (void)state;
  start(0u, 0.0);
  const step_t r = run_step();
  int wrong = 1;
  const double inv_ms = invalid_after_step_ms(20.0, &wrong);
  printf("# open loop, same part: after 100 ms still %.0f ms outside 1 %%, peak %.1f deg/s; "
         "valid and wrong %d; invalid for %.0f ms after the step (valid and wrong %d in the "
         "50 ms after)\n",
         r.settle_ms, r.peak_dps, r.valid_wrong, inv_ms, wrong);
  assert_true(r.settle_ms >= 99.0);
  assert_true(r.peak_dps > 1.5 * STEP_DPS);
  assert_false(r.valid_wrong);
  /* valid again once the ringing has decayed (tau = 2Q / w_sense = 2 s; the difference
   * of the quadrature filter from its reference, 1.4 times the beat, back inside the
   * 0.25 deg/s tolerance: about 6 tau, 12.3 s), and right then */
  assert_true(inv_ms > 0.0);
  assert_false(wrong);
  assert_int_equal(app.gyro.out.rate_invalid & RATE_INVALID_SENSE_FR, 0u);
  assert_int_equal(app.gyro.fr.run, 0u);
}

/* Issue 19 item 4's step table: 0 -> 100 deg/s on each part (sense Q 3, the thesis's;
 * 300; 10^4; all with the 110 Hz split), force rebalance against open loop. Prints the
 * settling time to 1 % of the step (within the 100 ms looked at) and the overshoot. */
static step_t step_row(uint32_t sense_mode, double q_sense)
{
  /* open loop without its quadrature, as test_open_loop_rings */
  start_q(sense_mode, sense_mode != 0u ? 1500.0 : 0.0, q_sense);
  const step_t r = run_step();
  printf("# step table: sense Q %g, 110 Hz split, %s: settles to 1 %% in %s%.1f ms, overshoot "
         "%.1f %%, final %.2f deg/s; valid and wrong %d\n",
         q_sense, sense_mode != 0u ? "force rebalance" : "open loop",
         r.settle_ms >= N_AFTER * BLOCK_S * 1e3 ? "more than " : "", r.settle_ms,
         100.0 * (r.peak_dps - r.final_dps) / STEP_DPS, r.final_dps, r.valid_wrong);
  return r;
}

/* Force rebalance settles each part within 10 ms (the goal), at the model's
 * scale, never valid and wrong. */
static void check_fr_row(double q_sense)
{
  const step_t r = step_row(1u, q_sense);
  assert_true(r.settle_ms <= 10.0);
  assert_true(fabs(r.final_dps - STEP_DPS) <= 0.02 * STEP_DPS);
  assert_false(r.valid_wrong);
  assert_true(app.gyro.fr.settled != 0u && app.gyro.fr.at_limit == 0u);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
}

static void test_table_fr_q300(void **state)
{
  (void)state;
  check_fr_row(300.0);
}

static void test_table_fr_q3(void **state)
{
  (void)state;
  check_fr_row(3.0);
}

/* The controls, open loop on the same parts: at Q 300 the step rings at the split (55 %
 * overshoot, still outside 1 % after the 100 ms looked at; the issue measured 0.26 s);
 * at Q 3 the mode is fast but the open-loop output filter (100 Hz 4th-order Butterworth
 * and the demodulator's pole) takes 17-18 ms: both miss the 10 ms goal. (Open loop the
 * rate is also valid while it is more than 1 % from the plant's after the first 10 ms:
 * the filter's lag at Q 3, the ringing at Q 300, which no monitor saw. Now the ringing
 * disturbs the settling monitor through the quadrature axis, where the step's free
 * response shows as much as on the rate's: the rate is not valid until it has decayed,
 * 376 ms at Q 300 (6 tau), and at Q 3 the step's short free response holds it invalid
 * through the filter's lag.) */
static void test_table_open_q300(void **state)
{
  (void)state;
  const step_t r = step_row(0u, 300.0);
  assert_true(r.settle_ms >= 99.0);
  assert_true(r.peak_dps - r.final_dps > 0.4 * STEP_DPS);
  assert_false(r.valid_wrong); /* the ringing is seen (test_open_loop_rings) */
  int wrong = 1;
  const double inv_ms = invalid_after_step_ms(2.0, &wrong);
  printf("# open loop, sense Q 300: invalid for %.0f ms after the step (tau 60 ms), valid "
         "and wrong %d in the 50 ms after\n",
         inv_ms, wrong);
  assert_true(inv_ms > 0.0);
  assert_false(wrong);
  assert_int_equal(app.gyro.fr.run, 0u);
}

static void test_table_open_q3(void **state)
{
  (void)state;
  const step_t r = step_row(0u, 3.0);
  assert_true(r.settle_ms > 10.0 && r.settle_ms < 25.0);
  assert_false(r.valid_wrong);
  assert_int_equal(app.gyro.fr.run, 0u);
}

/* `set`, retried while the sample loop has not taken the previous change. */
static void set_ok(const char *line)
{
  const char *r = cmd(line);
  for (int i = 0; i < 100 && strstr(r, "PENDING") != NULL; i++) {
    hal_host_run(50u);
    r = cmd(line);
  }
  if (strncmp(r, "ok", 2) != 0) fail_msg("%s -> %s", line, r);
}

/* The blocks of s seconds at which the rate is valid and off the plant's by more than
 * 1 deg/s (integrity_judge.h's floor) plus the model-made scale's 2 % (start_q), after
 * the 10 ms a step takes to pass the output filter (run_step's rule). */
static long valid_wrong_blocks(double s)
{
  long wrong = 0;
  hal_host_run((uint64_t)(0.010 * 50000.0));
  for (long n = 0; n < (long)(s / BLOCK_S); n++) {
    hal_host_run(GYRO_BLOCK);
    const gyro_out_t *o = &app.gyro.out;
    const double truth = plant_truth(&plant)->rate_dps;
    wrong += o->rate_valid != 0u && fabs((double)o->rate_dps - truth) > 1.0 + 0.02 * fabs(truth);
  }
  return wrong;
}

/* The sense pickoff dies (its preamplifier's gain to 0, as an open input would): force
 * rebalance sees no residual, calls itself balanced and its readout freezes. */
static void kill_sense_pickoff(void)
{
  plant.pick[1].cfg.gain_v_per_m = 0.0;
  plant.pick[1].gain_now = 0.0;
}

/* The continuous self-test with the loop closed (selftest.h): its force goes into the
 * loop's command and the readout carries the tone, measured and taken out, and judged
 * against the loop model's expectation (status selftest_cont_expect_dps: no calibration
 * needed); the rate is valid and right through a step. Then a dead sense pickoff: the
 * tone vanishes and the rate is not valid (CONT_SELFTEST) within 0.1 s, and stays so
 * while the rate moves. The same with selftest.continuous 0 (the default): force
 * rebalance runs the test regardless, since without it the frozen readout stayed valid
 * and wrong (nothing else sees a dead pickoff: it failed so before the design made it
 * so, 2 s valid and wrong). */

static float status_f32(const char *key)
{
  char pat[64];
  snprintf(pat, sizeof pat, "%s ", key);
  const char *r = strstr(cmd("status\n"), pat);
  assert_non_null(r);
  float x = 0.0f;
  assert_int_equal(sscanf(r + strlen(pat), "%f", &x), 1);
  return x;
}

static void test_cont_selftest_closed_loop(void **state)
{
  (void)state;
  for (int with_test = 1; with_test >= 0; with_test--) {
    start(1u, 1500.0);
    if (with_test) {
      set_ok("set selftest.continuous 1\n");
      hal_host_run(100000u);
      const float tone = status_f32("selftest_cont_dps");
      const float model = status_f32("selftest_cont_expect_dps");
      printf("# continuous self-test, loop closed: tone %.3f deg/s at "
             "the readout, the loop model's %.3f (%+.1f %%), rate invalid 0x%x\n",
             (double)tone, (double)model, 100.0 * ((double)tone / (double)model - 1.0),
             app.gyro.out.rate_invalid);
      assert_true(tone > 1.0f);
      assert_true(fabsf(tone / model - 1.0f) < 0.05f);
      assert_int_equal(app.gyro.out.rate_invalid, 0u);
      /* a step's own content at the tone's frequency moves the test's weights: the
       * time the verdict is out of its band after it, printed */
      app_plant_hold_rate(STEP_DPS);
      long cont_blocks = 0, last = 0;
      for (long b = 1; b <= (long)(0.5 / BLOCK_S); b++) {
        hal_host_run(GYRO_BLOCK);
        if ((app.gyro.out.rate_invalid & RATE_INVALID_CONT_SELFTEST) != 0u) {
          cont_blocks++;
          last = b;
        }
      }
      printf("# a 0 -> %.0f deg/s step: CONT_SELFTEST for %.1f ms of the 0.5 s after it, "
             "the last %.1f ms after the step\n",
             STEP_DPS, (double)cont_blocks * BLOCK_S * 1e3, (double)last * BLOCK_S * 1e3);
      assert_int_equal(valid_wrong_blocks(0.5), 0);
      assert_int_equal(app.gyro.out.rate_invalid, 0u);
    } else {
      hal_host_run(50000u);
      app_plant_hold_rate(STEP_DPS);
      hal_host_run(25000u);
    }
    /* the pickoff dies; the time to the verdict (the tone's mean falls out of its band),
     * then the rate moves: never valid and wrong from the verdict on */
    kill_sense_pickoff();
    long blocks = 0;
    while (app.gyro.out.rate_valid != 0u && blocks < (long)(2.0 / BLOCK_S)) {
      hal_host_run(GYRO_BLOCK);
      blocks++;
    }
    app_plant_hold_rate(0.0);
    const long wrong = valid_wrong_blocks(2.0);
    printf("# dead sense pickoff, selftest.continuous %s: not valid %.1f ms after it "
           "(%s); then 100 -> 0 deg/s: %ld valid blocks off by more than 1 deg/s in 2 s, "
           "rate %.1f deg/s (true 0), reasons 0x%x\n",
           with_test ? "1" : "0", (double)blocks * BLOCK_S * 1e3,
           app.gyro.out.rate_valid ? "still valid" : "flagged", wrong,
           (double)app.gyro.out.rate_dps, app.gyro.out.rate_invalid);
    assert_true((double)blocks * BLOCK_S <= 0.1);
    assert_int_equal(wrong, 0);
    assert_true((app.gyro.out.rate_invalid & RATE_INVALID_CONT_SELFTEST) != 0u);
  }
}

/* A part without quadrature (as a nulled one looks to the loop: quad.null moves it to the
 * nulling electrodes), turning at +-200 deg/s: for one sign of the rate the force the
 * loop commands lies on the negative real axis, where the half-frequency root's
 * principal branch has its cut (drive_synth_phasor_parts). The pickoff's noise moves
 * Im F across 0 every few blocks and each crossing turned both voltages by 180 degrees:
 * before, here +200 read 203.0 deg/s, valid, sd 0.96 against -200's 0.06 (and in
 * gyro-sim, on the part tools/calibrate --sense fr calibrated, whose feedback gain has
 * the other sign, -200 read -201.4 deg/s, valid, 25 times the noise of +200; with
 * quad.null the nulling flagged QUAD_NULL for most of every dwell of that sign). The
 * two signs are judged against each other. */
static void held_rate(double rate_dps, double *mean, double *sd, long *valid)
{
  app_plant_hold_rate(rate_dps);
  hal_host_run((uint64_t)(0.3 * 50000.0));
  const long n = (long)(0.5 / BLOCK_S);
  double s = 0.0, s2 = 0.0;
  *valid = 0;
  for (long i = 0; i < n; i++) {
    hal_host_run(GYRO_BLOCK);
    const double r = (double)app.gyro.out.rate_dps;
    s += r;
    s2 += r * r;
    *valid += app.gyro.out.rate_valid != 0u;
  }
  *mean = s / (double)n;
  *sd = sqrt(fmax(s2 / (double)n - *mean * *mean, 0.0));
}

static void test_negative_rate_on_the_branch_cut(void **state)
{
  (void)state;
  const fr_part_t fp = {1u, 0.0, 1.0e4, 0u, 0.0, F_SENSE_HZ, 1, 1, 0.0};
  start_part(&fp);
  hal_host_run((uint64_t)(T_STEP_S * 50000.0));
  double m_rest, sd_rest, m_pos, sd_pos, m_neg, sd_neg;
  long v_rest, v_pos, v_neg;
  held_rate(0.0, &m_rest, &sd_rest, &v_rest);
  held_rate(200.0, &m_pos, &sd_pos, &v_pos);
  held_rate(-200.0, &m_neg, &sd_neg, &v_neg);
  printf("# no quadrature, pickoff noise on: at rest %.3f deg/s (sd %.3f), +200 deg/s reads "
         "%.3f (sd %.3f, valid %ld), -200 reads %.3f (sd %.3f, valid %ld)\n",
         m_rest, sd_rest, m_pos, sd_pos, v_pos, m_neg, sd_neg, v_neg);
  /* the scale is the model's (0.9 %): the two signs agree about the bias at rest, each
   * within its noise */
  assert_true(fabs(m_pos + m_neg - 2.0 * m_rest) <= 0.05);
  assert_true(fmax(sd_pos, sd_neg) <= 2.0 * fmin(sd_pos, sd_neg) + 0.01);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
}

/* The rebalanced quadrature over temperature, with the fixed drive: the feedback force's
 * frame is the drive force's P, low-passed (gyro_fr_synth), which at the fixed drive is
 * the thermometer: the resonance's phase at the fixed frequency moves with temperature
 * (6-12) while the drive's velocity, which the Coriolis force follows, is held by the
 * phase loop. So the frame turns the 1500 deg/s of rebalanced quadrature into rate at
 * 1500 pi / 180 = 26.2 deg/s per degree of P, a bias linear in P that the temperature
 * compensation in P takes out (a calibration made in force rebalance: tools/calibrate
 * --sense fr, its bias slope 26.25 deg/s per degree). A frame held to the drive
 * motion instead (the rate channel's reference, set + delta) left the bias flat over
 * 20 K (+0.002 deg/s) but did not follow the drive pickoff's phase flicker, which the
 * drive's true motion does: the flow's noise run read 43.3 deg/h of Allan deviation at
 * 1 s and 24.6 at 10 s, against 11.5 and 12.4 with this frame and its compensation
 * (README, "Calibrating closed-loop sense"). Measured here:
 * the part started at two ambients (every node at steady state), the model made at the
 * first; the bias's move against P's. */
static double rest_unc_dps(double dtemp_k, double *p_deg)
{
  const fr_part_t fp = {1u, 1500.0, 1.0e4, 0u, 0.0, F_SENSE_HZ, 1, 0, dtemp_k};
  start_part(&fp);
  hal_host_run((uint64_t)(1.0 * 50000.0));
  const long n = (long)(0.3 / BLOCK_S);
  double s = 0.0, p = 0.0;
  for (long i = 0; i < n; i++) {
    hal_host_run(GYRO_BLOCK);
    s += (double)app.gyro.out.rate_unc_dps;
    p += (double)app.gyro.out.p_deg;
  }
  *p_deg = p / (double)n;
  return s / (double)n;
}

static void test_rebalanced_quadrature_over_temperature(void **state)
{
  (void)state;
  double p0, p1;
  const double b0 = rest_unc_dps(0.0, &p0);
  const double b1 = rest_unc_dps(20.0, &p1);
  const double k = (b1 - b0) / (p1 - p0), k_model = 1500.0 * FM_PI / 180.0;
  printf("# fixed drive, 1500 deg/s rebalanced: uncompensated rate at rest %.3f deg/s (P %.3f "
         "deg), 20 K warmer %.3f deg/s (P %.3f deg): %.2f deg/s per degree of P (model "
         "%.2f)\n",
         b0, p0, b1, p1, k, k_model);
  assert_true(fabs(p1 - p0) > 0.5); /* the thermometer moved */
  assert_true(fabs(k / k_model - 1.0) <= 0.05);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_step_settles_within_10_ms),
      cmocka_unit_test(test_negative_rate_on_the_branch_cut),
      cmocka_unit_test(test_rebalanced_quadrature_over_temperature),
      cmocka_unit_test(test_cont_selftest_closed_loop),
      cmocka_unit_test(test_dcac_step_settles_within_10_ms),
      cmocka_unit_test(test_dcac_softened_model),
      cmocka_unit_test(test_dcac_unsoftened_model_misses),
      cmocka_unit_test(test_open_loop_rings),
      cmocka_unit_test(test_table_fr_q300),
      cmocka_unit_test(test_table_fr_q3),
      cmocka_unit_test(test_table_open_q300),
      cmocka_unit_test(test_table_open_q3),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
