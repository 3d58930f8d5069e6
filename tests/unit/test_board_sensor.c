/* The board's TMP117 temperature sensor (host_sim/plant/board_sensor.h) and its place in
 * the plant: a result every 1 s at a phase drawn once, the node's temperature at the
 * middle of the 124 ms of averaging before it, the accuracy error, the averaged noise,
 * the register's rounding, held in between; a fault time and an absent sensor; and the
 * plant's other samples unchanged by it (its random numbers are its own). Through the
 * host HAL stub (hal/host/hal_host.h) the firmware sees each result once. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "hal/hal_board_temp.h"
#include "hal/hal_sample_timer.h"
#include "hal_host.h"
#include "plant/board_sensor.h"
#include "plant/plant.h"

static const double kLsb = 0.0078125;    /* 7.3.3 */
static const double kHalfActive = 0.062; /* 8 x 15.5 ms / 2 (7.4) */

static board_sensor_cfg_t tmp117(double offset_c, double slope, double fault_s)
{
  const board_sensor_cfg_t c = {BOARD_SENSOR_TMP117, offset_c, slope, fault_s};
  return c;
}

/* Step s at every time it is due up to t_end_s, with the node at node_c(t); the results'
 * end times (when read first sees them) and codes into end_s[] / code[] (up to max).
 * Returns the number of results. */
typedef double (*node_fn)(double t_s, void *ctx);
static int run_events(board_sensor_t *s, double t_end_s, node_fn node, void *ctx, double *end_s,
                      int16_t *code, int max)
{
  int n = 0;
  uint64_t seen = 0u;
  while (s->due_s <= t_end_s) {
    const double t = s->due_s;
    board_sensor_step(s, t, node(t, ctx));
    int16_t c = 0;
    uint64_t conv = 0u;
    if (board_sensor_read(s, t, &c, &conv) == HAL_BOARD_TEMP_NEW && conv != seen) {
      assert_true(conv == seen + 1u);
      seen = conv;
      if (n < max) {
        end_s[n] = t;
        code[n] = c;
      }
      n++;
    }
  }
  return n;
}

static double node_const(double t_s, void *ctx)
{
  (void)t_s;
  return *(const double *)ctx;
}

/* One result per second, the first within the first second at the drawn phase; the
 * register holds its code from one result to the next, also when read between them
 * (at 1 ms steps, as a plant's thermal updates would): no result is read early or twice. */
static void test_cycle_and_hold(void **state)
{
  (void)state;
  board_sensor_t s;
  const board_sensor_cfg_t c = tmp117(0.0, 0.0, -1.0);
  assert_int_equal(board_sensor_init(&s, &c, 42u), 0);
  const double first_end = s.first_mid_s + kHalfActive;
  assert_true(first_end >= 0.0 && first_end < 1.0);
  double node = 25.0;
  double end_s[8];
  int16_t code[8];
  board_sensor_t copy = s;
  const int n = run_events(&copy, 6.5, node_const, &node, end_s, code, 8);
  assert_int_equal(n, (int)floor(6.5 - first_end) + 1);
  for (int i = 0; i < n; i++) assert_float_equal(end_s[i], first_end + i, 1e-12);
  /* read at 1 ms steps: NONE before the first result, then the code of the latest */
  int k_new = 0;
  for (int ms = 0; ms <= 6500; ms++) {
    const double t = ms * 1e-3;
    if (board_sensor_due(&s, t)) board_sensor_step(&s, t, node);
    int16_t got = -1;
    uint64_t conv = 0u;
    const hal_board_temp_event_t ev = board_sensor_read(&s, t, &got, &conv);
    while (k_new < n && t >= end_s[k_new]) k_new++;
    assert_int_equal(conv, (uint64_t)k_new);
    if (k_new == 0) {
      assert_int_equal(ev, HAL_BOARD_TEMP_NONE);
      assert_int_equal(got, -1); /* not written */
      assert_true(isnan(board_sensor_reading_c(&s, t)));
    } else {
      assert_int_equal(ev, HAL_BOARD_TEMP_NEW);
      assert_int_equal(got, code[k_new - 1]);
      assert_true(board_sensor_reading_c(&s, t) == code[k_new - 1] * kLsb);
    }
  }
  /* the phase is the seed's: uniform over the cycle across seeds */
  double sum = 0.0;
  for (uint64_t seed = 0; seed < 2000u; seed++) {
    assert_int_equal(board_sensor_init(&s, &c, seed), 0);
    sum += s.first_mid_s + kHalfActive;
  }
  print_message("first result after %.4f s (seed 42); mean over 2000 seeds %.4f s\n", first_end,
                sum / 2000.0);
  assert_true(fabs(sum / 2000.0 - 0.5) < 0.03); /* sd of the mean 0.0065 s */
}

static double node_ramp(double t_s, void *ctx)
{
  const double *r = ctx; /* start degC, slope K/s */
  return r[0] + r[1] * t_s;
}

/* On a fast ramp (2 K/s, -40 to 160 degC in 100 s) each result is the node at the middle of
 * its 124 ms of averaging, 62 ms before it is ready: within the noise and the rounding (4
 * LSB at most over 100 results, 0.6 LSB sd), where the node at the end would be 16 LSB
 * off. */
static void test_value_at_middle_of_averaging(void **state)
{
  (void)state;
  board_sensor_t s;
  const board_sensor_cfg_t c = tmp117(0.0, 0.0, -1.0);
  assert_int_equal(board_sensor_init(&s, &c, 7u), 0);
  double ramp[2] = {-40.0, 2.0};
  double end_s[128];
  int16_t code[128];
  const int n = run_events(&s, 100.0, node_ramp, ramp, end_s, code, 128);
  assert_true(n >= 100 && n <= 101);
  double worst = 0.0, mean = 0.0;
  for (int i = 0; i < n; i++) {
    const double d = code[i] - node_ramp(end_s[i] - kHalfActive, ramp) / kLsb;
    mean += d / n;
    if (fabs(d) > worst) worst = fabs(d);
  }
  print_message("ramp: result - node at the middle: mean %.3f, worst %.3f LSB\n", mean, worst);
  assert_true(worst < 4.0);
  assert_true(fabs(mean) < 0.25); /* sd of the mean 0.06 LSB */
}

/* Round half to even (numpy.round's, the study's), clamped to the register. */
static void test_rounding(void **state)
{
  (void)state;
  assert_int_equal(board_sensor_round(0.5), 0);
  assert_int_equal(board_sensor_round(1.5), 2);
  assert_int_equal(board_sensor_round(2.5), 2);
  assert_int_equal(board_sensor_round(-0.5), 0);
  assert_int_equal(board_sensor_round(-1.5), -2);
  assert_int_equal(board_sensor_round(2.49999), 2);
  assert_int_equal(board_sensor_round(-2.50001), -3);
  assert_int_equal(board_sensor_round(3200.0), 3200); /* 25 degC */
  assert_int_equal(board_sensor_round(40000.0), INT16_MAX);
  assert_int_equal(board_sensor_round(-40000.0), INT16_MIN);
  assert_int_equal(board_sensor_round(NAN), INT16_MAX);
  /* a node beyond the register's reach reads at its end (256 degC) */
  board_sensor_t s;
  const board_sensor_cfg_t c = tmp117(0.0, 0.0, -1.0);
  assert_int_equal(board_sensor_init(&s, &c, 1u), 0);
  double node = 300.0, end_s[2];
  int16_t code[2];
  assert_int_equal(run_events(&s, 1.5, node_const, &node, end_s, code, 2), 1);
  assert_int_equal(code[0], INT16_MAX);
}

/* The mean of n results at a node held at node_c, minus the node, degC. */
static double mean_error_c(const board_sensor_cfg_t *c, double node_c, int n, uint64_t seed)
{
  board_sensor_t s;
  assert_int_equal(board_sensor_init(&s, c, seed), 0);
  double *end_s = malloc(sizeof(double) * (size_t)n);
  int16_t *code = malloc(sizeof(int16_t) * (size_t)n);
  assert_non_null(end_s);
  assert_non_null(code);
  const int got = run_events(&s, s.first_mid_s + kHalfActive + (n - 1) + 0.5, node_const,
                             &node_c, end_s, code, n);
  assert_int_equal(got, n);
  double sum = 0.0;
  for (int i = 0; i < n; i++) sum += code[i] * kLsb - node_c;
  free(end_s);
  free(code);
  return sum / n;
}

/* The accuracy error offset + slope (T - 25 degC): the default part's (+0.04 degC,
 * -0.8 mK/K) at -40, 25 and 85 degC, within the data sheet's +-0.1 degC (6.5), read as the
 * mean of 4000 results (noise and rounding leave 0.15 mdegC sd on it). */
static void test_accuracy_error(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  const board_sensor_cfg_t c = tmp117(pc.board_sensor_offset_c, pc.board_sensor_slope, -1.0);
  const double nodes_c[3] = {-40.0, 25.0, 85.0};
  for (int i = 0; i < 3; i++) {
    /* a node off the LSB lattice, so that the noise dithers the rounding */
    const double node = nodes_c[i] + 0.37 * kLsb;
    const double want = c.offset_c + c.slope * (node - 25.0);
    const double got = mean_error_c(&c, node, 4000, 11u + (uint64_t)i);
    print_message("accuracy error at %.0f degC: %.5f degC (model %.5f)\n", nodes_c[i], got, want);
    assert_true(fabs(got - want) < 1e-3);
    assert_true(fabs(want) <= 0.1);
  }
  const board_sensor_cfg_t none = tmp117(0.0, 0.0, -1.0);
  assert_true(fabs(mean_error_c(&none, 25.0 + 0.37 * kLsb, 4000, 3u)) < 1e-3);
}

/* The noise: 1.5 / sqrt(8) = 0.530 LSB per result before the rounding; with the node
 * spread uniformly over the LSB lattice the rounding adds 1/12 LSB^2 exactly, so the
 * result's sd about the node is sqrt(0.2813 + 0.0833) = 0.604 LSB (20000 results: 0.5 %
 * sd). Gaussian: 1.96 sd hold 95 %. */
static void test_noise_statistics(void **state)
{
  (void)state;
  board_sensor_t s;
  const board_sensor_cfg_t c = tmp117(0.0, 0.0, -1.0);
  assert_int_equal(board_sensor_init(&s, &c, 2024u), 0);
  rng_t spread;
  rng_seed(&spread, 5u, 1u);
  const int n = 20000;
  double s1 = 0.0, s2 = 0.0, node = 25.0;
  int done = 0, within = 0;
  uint64_t seen = 0u;
  while (done < n) {
    const double t = s.due_s;
    const int latch = t >= s.mid_s; /* this step makes a result of the node below */
    const double node_now = 25.0 + rng_uniform(&spread) * kLsb;
    board_sensor_step(&s, t, node_now);
    if (latch) node = node_now;
    int16_t code = 0;
    uint64_t conv = 0u;
    if (board_sensor_read(&s, t, &code, &conv) == HAL_BOARD_TEMP_NEW && conv != seen) {
      seen = conv;
      const double d = code - node / kLsb;
      s1 += d;
      s2 += d * d;
      if (fabs(d) < 1.96 * 0.6038) within++;
      done++;
    }
  }
  const double mean = s1 / n, sd = sqrt(s2 / n - mean * mean);
  print_message("noise: mean %.4f LSB, sd %.4f LSB (0.6038), %.2f %% within 1.96 sd\n", mean,
                sd, 100.0 * within / n);
  assert_true(fabs(mean) < 0.02);
  assert_true(fabs(sd / 0.6038 - 1.0) < 0.03);
  /* the rounded Gaussian's share within 1.96 sd: 95.07 % (numpy, 2e6 draws); 0.15 % sd */
  assert_true(fabs((double)within / n - 0.9507) < 0.01);
}

/* From fault_s on the sensor does not answer: FAULT, the results still counted (one
 * failed read per result), no reading; before it, NEW. Without a sensor: ABSENT, never
 * due, nothing drawn. Bad configurations refused. */
static void test_fault_and_absent(void **state)
{
  (void)state;
  board_sensor_t s;
  const board_sensor_cfg_t c = tmp117(0.0, 0.0, 3.5);
  assert_int_equal(board_sensor_init(&s, &c, 9u), 0);
  double node = 30.0;
  uint64_t before_fault = 0u;
  for (int ms = 0; ms <= 6000; ms++) {
    const double t = ms * 1e-3;
    if (board_sensor_due(&s, t)) board_sensor_step(&s, t, node);
    int16_t code = 0;
    uint64_t conv = 0u;
    const hal_board_temp_event_t ev = board_sensor_read(&s, t, &code, &conv);
    if (t < 3.5) {
      assert_true(ev == HAL_BOARD_TEMP_NEW || (ev == HAL_BOARD_TEMP_NONE && conv == 0u));
      before_fault = conv;
    } else {
      assert_int_equal(ev, HAL_BOARD_TEMP_FAULT);
      assert_true(isnan(board_sensor_reading_c(&s, t)));
      assert_true(conv >= before_fault);
    }
  }
  uint64_t conv = 0u;
  assert_int_equal(board_sensor_read(&s, 6.0, NULL, &conv), HAL_BOARD_TEMP_FAULT);
  assert_true(conv == before_fault + 2u || conv == before_fault + 3u); /* counted on */
  /* the step at the fault time is due, so a copy of the reading turns to NaN then */
  assert_int_equal(board_sensor_init(&s, &c, 9u), 0);
  int stepped_at_fault = 0;
  while (s.due_s <= 4.0) {
    if (s.due_s == 3.5) stepped_at_fault = 1;
    board_sensor_step(&s, s.due_s, node);
  }
  assert_true(stepped_at_fault);

  const board_sensor_cfg_t none = {BOARD_SENSOR_NONE, 0.0, 0.0, -1.0};
  assert_int_equal(board_sensor_init(&s, &none, 9u), 0);
  assert_false(board_sensor_due(&s, 1e9));
  int16_t code = 123;
  assert_int_equal(board_sensor_read(&s, 10.0, &code, NULL), HAL_BOARD_TEMP_ABSENT);
  assert_int_equal(code, 123);
  assert_true(isnan(board_sensor_reading_c(&s, 10.0)));
  rng_t fresh;
  rng_seed(&fresh, 9u, BOARD_SENSOR_RNG_STREAM);
  assert_memory_equal(s.rng.s, fresh.s, sizeof fresh.s);

  const board_sensor_cfg_t bad[4] = {{2, 0.0, 0.0, -1.0},
                                     {BOARD_SENSOR_TMP117, NAN, 0.0, -1.0},
                                     {BOARD_SENSOR_TMP117, 0.0, INFINITY, -1.0},
                                     {BOARD_SENSOR_TMP117, 0.0, 0.0, NAN}};
  for (int i = 0; i < 4; i++) {
    board_sensor_t before = s;
    assert_int_equal(board_sensor_init(&s, &bad[i], 1u), -1);
    assert_memory_equal(&s, &before, sizeof s);
  }
  assert_int_equal(board_sensor_init(NULL, &c, 1u), -1);
  assert_int_equal(board_sensor_check(NULL), -1);
}

/* ------------------------------------------------------------ in the plant ------- */

/* The default part with its sensor, without it, and with another sensor error and a
 * fault, from one seed: every ADC frame and the motion the same, sample for sample, over
 * 2.2 s (two results at least): the sensor draws from its own stream only. The sensor's
 * results are the board node's, and the truth's copy is what the HAL reads. */
static void test_plant_samples_unchanged(void **state)
{
  (void)state;
  static plant_t a, b, d;
  plant_cfg_t ca, cb, cd;
  plant_default_cfg(&ca);
  cb = ca;
  cb.board_sensor = BOARD_SENSOR_NONE;
  cd = ca;
  cd.board_sensor_offset_c = -0.09;
  cd.board_sensor_slope = 0.001;
  cd.board_sensor_fault_s = 1.7;
  assert_int_equal(plant_init(&a, &ca, 77u), 0);
  assert_int_equal(plant_init(&b, &cb, 77u), 0);
  assert_int_equal(plant_init(&d, &cd, 77u), 0);
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  fr.code[HAL_DAC_DRIVE_U1] = HAL_DAC_CODE_MID + 3000u;
  const long n = (long)(2.2 * ca.fs_hz);
  uint64_t results = 0u;
  double last = NAN;
  for (long k = 0; k < n; k++) {
    hal_adc_frame_t fa, fb, fd;
    plant_step(&a, &fr, &fa);
    plant_step(&b, &fr, &fb);
    plant_step(&d, &fr, &fd);
    if (fa.drive != fb.drive || fa.sense != fb.sense || fa.drive != fd.drive ||
        fa.sense != fd.sense)
      fail_msg("ADC frames differ at sample %ld", k);
    const plant_truth_t *ta = plant_truth(&a), *tb = plant_truth(&b);
    if (ta->y_m != tb->y_m || ta->x_m != tb->x_m || ta->adc_v[1] != plant_truth(&d)->adc_v[1])
      fail_msg("motion differs at sample %ld", k);
    if (a.board_sensor.done != results) { /* a result finished at this sample */
      results = a.board_sensor.done;
      last = ta->board_meas_c;
      /* the node moves by microkelvin here: the result is the node within the error */
      const double node_c = ta->board_k - 273.15;
      const double err = ca.board_sensor_offset_c + ca.board_sensor_slope * (node_c - 25.0);
      assert_true(fabs(ta->board_meas_c - node_c - err) < 4.0 * kLsb);
    }
    assert_true(isnan(tb->board_meas_c));
  }
  assert_true(results >= 2u);
  int16_t code = 0;
  uint64_t conv = 0u;
  const double t_now = (double)(n - 1) / ca.fs_hz; /* the HAL's time: one sample behind */
  assert_int_equal(plant_board_temp_hal(&a, t_now, &code, &conv), HAL_BOARD_TEMP_NEW);
  assert_true(code * kLsb == plant_truth(&a)->board_meas_c);
  assert_int_equal(plant_board_temp_hal(&b, t_now, &code, &conv), HAL_BOARD_TEMP_ABSENT);
  assert_int_equal(plant_board_temp_hal(&d, t_now, &code, &conv), HAL_BOARD_TEMP_FAULT);
  assert_true(isnan(plant_truth(&d)->board_meas_c));
  print_message("2.2 s: %llu results, the last %.7f degC on a board node at %.5f degC\n",
                (unsigned long long)results, last, plant_truth(&a)->board_k - 273.15);
}

/* The plant's parameters reach the sensor; board_sensor is 0 or 1. */
static void test_plant_parameters(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_default_cfg(&c);
  assert_int_equal(c.board_sensor, BOARD_SENSOR_TMP117);
  assert_true(c.board_sensor_fault_s < 0.0);
  char err[200];
  assert_int_equal(plant_param_set(&c, "board_sensor_fault_s", 100.0, err, sizeof err), 0);
  assert_int_equal(plant_param_set(&c, "board_sensor", 2.0, err, sizeof err), -1);
  assert_non_null(strstr(err, "board_sensor"));
  assert_int_equal(plant_param_set(&c, "board_sensor_offset_c", 0.05, err, sizeof err), 0);
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 1u), 0);
  assert_true(p.board_sensor.cfg.fault_s == 100.0);
  assert_true(p.board_sensor.cfg.offset_c == 0.05);
  assert_true(p.board_sensor.cfg.slope == c.board_sensor_slope);
  assert_true(isnan(plant_truth(&p)->board_meas_c));
  plant_cfg_t ideal;
  plant_ideal_cfg(&ideal);
  assert_int_equal(ideal.board_sensor, BOARD_SENSOR_TMP117);
}

/* ------------------------------------------------------ through the host HAL ----- */

static void quiet_isr(void *ctx)
{
  (void)ctx;
  hal_dac_frame_t f;
  hal_dac_frame_midscale(&f);
  hal_dac_write_frame(&f);
}

/* The firmware's view: the plant attached to the host HAL, polled every 20 ms as a
 * background loop would: each result NEW exactly once, its code the plant's; NONE in
 * between; FAULT once per missed result from board_sensor_fault_s on; ABSENT with the
 * sensor off or nothing attached. */
static void test_hal_host_sees_each_result_once(void **state)
{
  (void)state;
  static plant_t p;
  plant_cfg_t c;
  plant_default_cfg(&c);
  c.board_sensor_fault_s = 3.3;
  assert_int_equal(plant_init(&p, &c, 5u), 0);
  hal_host_attach(plant_step_hal, &p);
  hal_host_attach_board_temp(plant_board_temp_hal, &p);
  assert_int_equal(hal_sample_timer_start(50000u, quiet_isr, NULL), 0);
  int16_t code = 0;
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_NONE); /* not started */
  assert_int_equal(hal_board_temp_start(), 0);
  int news = 0, faults = 0, nones = 0;
  for (int poll = 0; poll < 250; poll++) { /* 5 s */
    hal_host_run(1000u);
    const hal_board_temp_event_t ev = hal_board_temp_poll(&code);
    if (ev == HAL_BOARD_TEMP_NEW) {
      news++;
      assert_true(code * kLsb == plant_truth(&p)->board_meas_c);
      assert_true((double)hal_host_ticks() / 50000.0 < 3.3);
    } else if (ev == HAL_BOARD_TEMP_FAULT) {
      faults++;
      assert_true((double)hal_host_ticks() / 50000.0 >= 3.3);
    } else {
      assert_int_equal(ev, HAL_BOARD_TEMP_NONE);
      nones++;
    }
    assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_NONE); /* once only */
  }
  uint64_t conv = 0u;
  (void)plant_board_temp_hal(&p, (double)hal_host_ticks() / 50000.0, NULL, &conv);
  print_message("5 s polled every 20 ms: %d NEW, %d FAULT, %d NONE (%llu results)\n", news,
                faults, nones, (unsigned long long)conv);
  assert_int_equal(news + faults, (int)conv);
  assert_true(news >= 3 && news <= 4);
  assert_true(faults >= 1 && faults <= 2);
  /* a restart reads the latest result afresh: here the sensor does not answer */
  assert_int_equal(hal_board_temp_start(), 0);
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_FAULT);

  c.board_sensor = BOARD_SENSOR_NONE;
  assert_int_equal(plant_init(&p, &c, 5u), 0);
  hal_host_attach(plant_step_hal, &p);
  hal_host_attach_board_temp(plant_board_temp_hal, &p);
  hal_host_run(60000u);
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_ABSENT);
  hal_host_attach_board_temp(NULL, NULL);
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_ABSENT);
  hal_sample_timer_stop();
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_cycle_and_hold),
      cmocka_unit_test(test_value_at_middle_of_averaging),
      cmocka_unit_test(test_rounding),
      cmocka_unit_test(test_accuracy_error),
      cmocka_unit_test(test_noise_statistics),
      cmocka_unit_test(test_fault_and_absent),
      cmocka_unit_test(test_plant_samples_unchanged),
      cmocka_unit_test(test_plant_parameters),
      cmocka_unit_test(test_hal_host_sees_each_result_once),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
