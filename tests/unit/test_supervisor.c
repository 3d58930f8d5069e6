#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "gyro/supervisor.h"

static supervisor_cfg_t cfg(void)
{
  supervisor_cfg_t c = {.dt_s = 1e-3f,
                        .lock_tol_rel = 0.01f,
                        .lock_phase_tol_rad = 0.02f,
                        .lock_hold_s = 0.01f,
                        .lost_tol_rel = 0.1f,
                        .lost_hold_s = 0.005f,
                        .amp_trip_rel = 1.5f,
                        .sat_hold_s = 0.02f,
                        .retry_s = 0.1f,
                        .clip_max_count = 3u,
                        .lost_phase_tol_rad = 0.05f,
                        .amp_max_v = 4.75f,
                        .amp_set_v = 0.35f,
                        .acq_timeout_s = 0.5f};
  return c;
}

/* The configuration the supervisor under test runs with (sup_step passes it). */
static supervisor_cfg_t s_cfg;

/* Derive c and start sv with it; -1 (nothing changed) for a bad configuration. */
static int sup_init(supervisor_t *sv, const supervisor_cfg_t *c)
{
  supervisor_cfg_t t = *c;
  if (supervisor_cfg_derive(&t) != 0) return -1;
  s_cfg = t;
  supervisor_init(sv);
  return 0;
}

static int sup_step(supervisor_t *sv, const supervisor_in_t *in)
{
  return supervisor_step(&s_cfg, sv, in);
}

static supervisor_in_t good(void)
{
  supervisor_in_t in = {.amp_rel_err = 0.0f,
                        .amp_rel = 1.0f,
                        .phase_err_rad = 0.0f,
                        .drive_at_limit = 0,
                        .clip_count = 0u,
                        .state_finite = 1,
                        .sample_lost = 0};
  return in;
}

static void run(supervisor_t *sv, const supervisor_in_t *in, int n)
{
  for (int i = 0; i < n; i++) (void)sup_step(sv, in);
}

static void test_bad_cfg_rejected(void **state)
{
  (void)state;
  supervisor_t sv = {.mode = GYRO_MODE_LOCKED, .fault_count = 77u};
  supervisor_cfg_t c = cfg();
  c.amp_trip_rel = 1.05f; /* inside the lost-lock band: could never see lost lock first */
  assert_int_equal(sup_init(&sv, &c), -1);
  c = cfg();
  c.clip_max_count = 0u;
  assert_int_equal(sup_init(&sv, &c), -1);
  c = cfg();
  c.dt_s = 0.0f;
  assert_int_equal(sup_init(&sv, &c), -1);
  assert_int_equal(sv.mode, GYRO_MODE_LOCKED);
  assert_int_equal(sv.fault_count, 77u);
}

/* OFF until started; ACQUIRE -> LOCKED after lock_hold_s (10 ticks) inside tolerance;
 * a tick outside restarts the count. */
static void test_lock_sequence(void **state)
{
  (void)state;
  supervisor_t sv;
  supervisor_cfg_t c = cfg();
  assert_int_equal(sup_init(&sv, &c), 0);
  supervisor_in_t in = good();
  run(&sv, &in, 50);
  assert_int_equal(sv.mode, GYRO_MODE_OFF);
  supervisor_start(&sv);
  assert_int_equal(sv.mode, GYRO_MODE_ACQUIRE);
  run(&sv, &in, 9);
  in.amp_rel_err = 0.02f;
  run(&sv, &in, 1);
  in = good();
  run(&sv, &in, 9);
  assert_int_equal(sv.mode, GYRO_MODE_ACQUIRE);
  run(&sv, &in, 1);
  assert_int_equal(sv.mode, GYRO_MODE_LOCKED);
  /* Phase outside tolerance also blocks lock. */
  supervisor_stop(&sv);
  supervisor_start(&sv);
  in.phase_err_rad = 0.05f;
  run(&sv, &in, 100);
  assert_int_equal(sv.mode, GYRO_MODE_ACQUIRE);
}

/* Lost lock after lost_hold_s (5 ticks) outside 10 %; retry after retry_s (100 ticks)
 * with a request to clear the loop state on both edges. */
static void test_lost_lock_and_retry(void **state)
{
  (void)state;
  supervisor_t sv;
  supervisor_cfg_t c = cfg();
  assert_int_equal(sup_init(&sv, &c), 0);
  supervisor_start(&sv);
  supervisor_in_t in = good();
  run(&sv, &in, 10);
  assert_int_equal(sv.mode, GYRO_MODE_LOCKED);
  in.amp_rel_err = -0.2f;
  in.amp_rel = 0.8f;
  run(&sv, &in, 4);
  assert_int_equal(sv.mode, GYRO_MODE_LOCKED);
  assert_int_equal(sup_step(&sv, &in), 1);
  assert_int_equal(sv.mode, GYRO_MODE_FAULT);
  assert_int_equal(sv.fault, GYRO_FAULT_LOST_LOCK);
  int cleared = 0;
  for (int i = 0; i < 100; i++) cleared += sup_step(&sv, &in);
  assert_int_equal(cleared, 1);
  assert_int_equal(sv.mode, GYRO_MODE_ACQUIRE);
  assert_int_equal(sv.fault_count, 1u);
}

static void test_immediate_faults(void **state)
{
  (void)state;
  supervisor_t sv;
  supervisor_cfg_t c = cfg();
  supervisor_in_t in;

  assert_int_equal(sup_init(&sv, &c), 0);
  supervisor_start(&sv);
  in = good();
  in.amp_rel = 1.6f;
  assert_int_equal(sup_step(&sv, &in), 1);
  assert_int_equal(sv.fault, GYRO_FAULT_OVER_AMP);

  assert_int_equal(sup_init(&sv, &c), 0);
  supervisor_start(&sv);
  in = good();
  in.state_finite = 0;
  assert_int_equal(sup_step(&sv, &in), 1);
  assert_int_equal(sv.fault, GYRO_FAULT_NAN);

  /* Clipping: clip_max_count rail codes within GYRO_CLIP_WINDOW steps (gyro_tick counts
   * them per block), sparse or in a run. */
  assert_int_equal(sup_init(&sv, &c), 0);
  supervisor_start(&sv);
  in = good();
  in.clip_count = c.clip_max_count - 1u;
  run(&sv, &in, 1);
  in.clip_count = 0u;
  run(&sv, &in, GYRO_CLIP_WINDOW);
  assert_int_not_equal(sv.mode, GYRO_MODE_FAULT);
  in.clip_count = 1u; /* one code per step: the window's sum reaches the count */
  run(&sv, &in, (int)c.clip_max_count - 1);
  assert_int_not_equal(sv.mode, GYRO_MODE_FAULT);
  run(&sv, &in, 1);
  assert_int_equal(sv.mode, GYRO_MODE_FAULT);
  assert_int_equal(sv.fault, GYRO_FAULT_ADC_CLIP);
}

/* Pinned at the drive limit while LOCKED for sat_hold_s (20 ticks): drive saturation. */
static void test_drive_saturation(void **state)
{
  (void)state;
  supervisor_t sv;
  supervisor_cfg_t c = cfg();
  assert_int_equal(sup_init(&sv, &c), 0);
  supervisor_start(&sv);
  supervisor_in_t in = good();
  run(&sv, &in, 10);
  in.drive_at_limit = 1;
  run(&sv, &in, 19);
  assert_int_equal(sv.mode, GYRO_MODE_LOCKED);
  run(&sv, &in, 1);
  assert_int_equal(sv.fault, GYRO_FAULT_DRIVE_SAT);
}

/* The lock test sees the errors through a 100 Hz low-pass: a +-1.5 % ripple at 745 Hz
 * (feedthrough residue at wc/2) is not a lost lock, a 1.5 % offset is. */
static void test_ripple_filtered(void **state)
{
  (void)state;
  supervisor_t sv;
  supervisor_cfg_t c = cfg();
  c.dt_s = 2e-5f; /* 50 kHz */
  c.lock_hold_s = 0.02f;
  assert_int_equal(sup_init(&sv, &c), 0);
  supervisor_start(&sv);
  supervisor_in_t in = good();
  for (int k = 0; k < 5000; k++) {
    in.amp_rel_err = 0.015f * sinf(6.2831853f * 745.0f * 2e-5f * (float)k);
    (void)sup_step(&sv, &in);
  }
  assert_int_equal(sv.mode, GYRO_MODE_LOCKED);
  supervisor_stop(&sv);
  supervisor_start(&sv);
  in.amp_rel_err = 0.015f;
  for (int k = 0; k < 5000; k++) (void)sup_step(&sv, &in);
  assert_int_equal(sv.mode, GYRO_MODE_ACQUIRE);
}

/* Every 1 that supervisor_step returns is latched in clear_req until the caller takes
 * it, and nothing else sets it: the gyro acts on it one tick after the supervisor. */
static void test_clear_request_latched(void **state)
{
  (void)state;
  supervisor_t sv;
  supervisor_cfg_t c = cfg();
  assert_int_equal(sup_init(&sv, &c), 0);
  assert_int_equal(sv.clear_req, 0u);
  supervisor_start(&sv);
  supervisor_in_t in = good();
  int requests = 0;
  for (int k = 0; k < 400; k++) {
    /* lock, lose it (fault), retry, lock again, a NaN (fault), retry */
    in.amp_rel_err = (k >= 20 && k < 40) ? -0.2f : 0.0f;
    in.amp_rel = 1.0f + in.amp_rel_err;
    in.state_finite = k != 250;
    const int r = sup_step(&sv, &in);
    assert_int_equal(sv.clear_req, (uint32_t)r);
    requests += r;
    sv.clear_req = 0u; /* taken */
  }
  assert_int_equal(requests, 4); /* two faults, two retries */
  assert_int_equal(sv.fault_count, 2u);
  assert_int_equal(sv.mode, GYRO_MODE_LOCKED);
}

/* OFF judges nothing; SWEEP trips on a NaN and on clipping but not on the amplitude
 * (the sweep drives the mode through resonance on purpose). */
static void test_off_and_sweep_faults(void **state)
{
  (void)state;
  supervisor_t sv;
  supervisor_cfg_t c = cfg();
  supervisor_in_t in = good();
  assert_int_equal(sup_init(&sv, &c), 0);
  in.state_finite = 0;
  in.clip_count = 100u;
  in.amp_rel = 9.0f;
  run(&sv, &in, 10);
  assert_int_equal(sv.mode, GYRO_MODE_OFF);
  assert_int_equal(sv.fault_count, 0u);

  supervisor_enter_sweep(&sv);
  in = good();
  in.amp_rel = 9.0f;
  in.amp_rel_err = 8.0f;
  run(&sv, &in, 10);
  assert_int_equal(sv.mode, GYRO_MODE_SWEEP);
  in.clip_count = c.clip_max_count;
  assert_int_equal(sup_step(&sv, &in), 1);
  assert_int_equal(sv.fault, GYRO_FAULT_ADC_CLIP);

  supervisor_enter_sweep(&sv);
  in = good();
  in.state_finite = 0;
  in.clip_count = c.clip_max_count; /* both: the NaN is reported */
  assert_int_equal(sup_step(&sv, &in), 1);
  assert_int_equal(sv.fault, GYRO_FAULT_NAN);
}

static void lock(supervisor_t *sv, const supervisor_cfg_t *c)
{
  assert_int_equal(sup_init(sv, c), 0);
  supervisor_start(sv);
  const supervisor_in_t in = good();
  run(sv, &in, 20);
  assert_int_equal(sv->mode, GYRO_MODE_LOCKED);
}

/* LOCKED with the amplitude held but the phase run off (a phase loop at a dead end):
 * PHASE_LOST after lost_hold_s, not before. */
static void test_phase_lost(void **state)
{
  (void)state;
  supervisor_t sv;
  const supervisor_cfg_t c = cfg();
  lock(&sv, &c);
  supervisor_in_t in = good();
  in.phase_err_rad = 0.5f;
  run(&sv, &in, 3);
  assert_int_equal(sv.mode, GYRO_MODE_LOCKED);
  run(&sv, &in, 20);
  assert_int_equal(sv.mode, GYRO_MODE_FAULT);
  assert_int_equal(sv.fault, GYRO_FAULT_PHASE_LOST);
  assert_int_equal(sv.kind_count[5], 1u);
}

/* ACQUIRE that never locks faults at acq_timeout_s: ACQ_TIMEOUT, or DRIVE_SAT when the
 * drive sits at its limit. */
static void test_acquisition_timeout(void **state)
{
  (void)state;
  supervisor_t sv;
  const supervisor_cfg_t c = cfg();
  assert_int_equal(sup_init(&sv, &c), 0);
  supervisor_start(&sv);
  supervisor_in_t in = good();
  in.amp_rel_err = -0.5f;
  in.amp_rel = 0.5f;
  run(&sv, &in, 490);
  assert_int_equal(sv.mode, GYRO_MODE_ACQUIRE);
  run(&sv, &in, 20);
  assert_int_equal(sv.mode, GYRO_MODE_FAULT);
  assert_int_equal(sv.fault, GYRO_FAULT_ACQ_TIMEOUT);
  run(&sv, &in, 200); /* retry */
  assert_int_equal(sv.mode, GYRO_MODE_ACQUIRE);
  in.drive_at_limit = 1;
  run(&sv, &in, 600);
  assert_int_equal(sv.fault, GYRO_FAULT_DRIVE_SAT);
  assert_int_equal(sv.kind_count[6], 1u);
  assert_int_equal(sv.kind_count[3], 1u);
}

/* Over-amplitude is absolute too: with a setpoint near the ADC's range, the relative
 * trip would lie beyond what the ADC can measure; amp_max_v trips first. */
static void test_absolute_over_amplitude(void **state)
{
  (void)state;
  supervisor_t sv;
  supervisor_cfg_t c = cfg();
  c.amp_set_v = 4.0f;
  lock(&sv, &c);
  supervisor_in_t in = good();
  in.amp_rel = 4.8f / 4.0f; /* 1.2 < amp_trip_rel 1.5, above 4.75 V */
  in.amp_rel_err = in.amp_rel - 1.0f;
  assert_int_equal(sup_step(&sv, &in), 1);
  assert_int_equal(sv.fault, GYRO_FAULT_OVER_AMP);
  c.amp_max_v = 3.9f; /* below the setpoint: refused */
  assert_int_equal(sup_init(&sv, &c), -1);
}

static void test_lost_sample(void **state)
{
  (void)state;
  supervisor_t sv;
  const supervisor_cfg_t c = cfg();
  lock(&sv, &c);
  supervisor_in_t in = good();
  in.sample_lost = 1;
  assert_int_equal(sup_step(&sv, &in), 1);
  assert_int_equal(sv.fault, GYRO_FAULT_LOST_SAMPLE);
  assert_int_equal(sv.kind_count[7], 1u);
  assert_true(sv.kind_last_step[7] > 0u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_phase_lost),
      cmocka_unit_test(test_acquisition_timeout),
      cmocka_unit_test(test_absolute_over_amplitude),
      cmocka_unit_test(test_lost_sample),
      cmocka_unit_test(test_bad_cfg_rejected),
      cmocka_unit_test(test_lock_sequence),
      cmocka_unit_test(test_lost_lock_and_retry),
      cmocka_unit_test(test_immediate_faults),
      cmocka_unit_test(test_drive_saturation),
      cmocka_unit_test(test_ripple_filtered),
      cmocka_unit_test(test_clear_request_latched),
      cmocka_unit_test(test_off_and_sweep_faults),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
