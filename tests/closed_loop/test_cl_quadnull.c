/* Quadrature nulling (quad_null.h, issue 19) on the default plant with nulling electrodes
 * (quadnull_dps_per_v2, actuator.h) through the whole firmware and the host HAL: with
 * quad.null 1 the part's true quadrature (plant truth: its ~1500 deg/s coupling plus the
 * electrodes' k_yx) falls under 1 deg/s within 1 s of power-on, and the rate is not valid
 * (QUAD_NULL) until the loop has settled, valid after. Negative controls: quad.null 0
 * leaves the quadrature and the electrodes alone; on a part without electrodes the
 * probe sees no effect, the loop stops with both at 0 V and the rate is never valid.
 * Bad values of quad.* are refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app_plant.h"

/* The nulling electrodes' coupling of the test part: 1500 deg/s at 8.7 V on one set
 * (quad_null.h's example), within the 10 V default limit. */
#define QN_DPS_PER_V2 20.0

static void start(double quadnull_dps_per_v2, uint32_t quad_null)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.quadnull_dps_per_v2 = quadnull_dps_per_v2;
  param_values_t v;
  default_part_values(&v);
  v.quad_null = quad_null;
  v.cal_ref_quad_null = quad_null; /* the calibration declared the nulling's */
  app_plant_start(&pc, 19u, &v);
}

static double quad_true_dps(void) { return plant_truth(&plant)->quad_true_dps; }

/* The first time after which |quad_true| stayed <= 1 deg/s up to t_end_s, and whether
 * the rate's QUAD_NULL bit agreed with the loop's settled flag on every block (the
 * verdict of a block takes the flag as the block before left it: the loop's steps run
 * one a block before the verdict, and the one after its settling test passes it on),
 * the first block the rate was valid, and whether it was valid on every block after
 * the loop settled for good. */
typedef struct {
  double t_nulled_s;    /* -1: never */
  double t_valid_s;     /* first valid block, -1: never */
  double t_settled_s;   /* the loop settled (for good), -1: never */
  int valid_unsettled;  /* a valid block while the loop was not settled */
  int bit_disagrees;    /* the QUAD_NULL bit against the loop's state */
  double valid_after_s; /* fraction of the blocks valid after settling + 0.1 s */
} run_t;

static run_t run_to(double t_end_s)
{
  run_t r = {-1.0, -1.0, -1.0, 0, 0, 0.0};
  long n_after = 0, valid_after = 0;
  /* settled as the verdict sees it: as the block before left it */
  int settled_before = app.gyro.quad.settled != 0u;
  const long blocks = (long)(t_end_s * 50000.0 / GYRO_BLOCK);
  for (long n = 1; n <= blocks; n++) {
    hal_host_run(GYRO_BLOCK);
    const double t = (double)n * GYRO_BLOCK / 50000.0;
    const double q = quad_true_dps();
    if (fabs(q) <= 1.0) {
      if (r.t_nulled_s < 0.0) r.t_nulled_s = t;
    } else {
      r.t_nulled_s = -1.0;
    }
    const gyro_out_t *o = &app.gyro.out;
    const int settled = app.gyro.quad.settled != 0u;
    if (settled) {
      if (r.t_settled_s < 0.0) r.t_settled_s = t;
    } else {
      r.t_settled_s = -1.0;
    }
    if (o->rate_valid != 0u && r.t_valid_s < 0.0) r.t_valid_s = t;
    if (o->rate_valid != 0u && !settled_before) r.valid_unsettled = 1;
    if (((o->rate_invalid & RATE_INVALID_QUAD_NULL) != 0u) == settled_before) {
      r.bit_disagrees = 1;
    }
    settled_before = settled;
    if (r.t_settled_s >= 0.0 && t >= r.t_settled_s + 0.1) {
      n_after++;
      valid_after += o->rate_valid != 0u;
    }
  }
  r.valid_after_s = n_after > 0 ? (double)valid_after / (double)n_after : 0.0;
  return r;
}

static void test_nulls_within_one_second(void **state)
{
  (void)state;
  start(QN_DPS_PER_V2, 1u);
  const double q0 = quad_true_dps();
  const run_t r = run_to(1.5);
  const quad_null_t *qn = &app.gyro.quad;
  printf("# quadrature %.1f deg/s at power-on; under 1 deg/s from %.3f s, residual %.4f "
         "deg/s at 1.5 s; loop settled at %.3f s, rate first valid at %.3f s, valid %.1f %% "
         "after; identified gain %.2f (deg/s)/V^2 (plant %.1f), V1 %.3f V, V2 %.3f V\n",
         q0, r.t_nulled_s, quad_true_dps(), r.t_settled_s, r.t_valid_s, 100.0 * r.valid_after_s,
         (double)qn->gain_dps_per_v2, QN_DPS_PER_V2, (double)qn->v1_v, (double)qn->v2_v);
  assert_true(fabs(q0) > 1000.0);
  assert_true(r.t_nulled_s > 0.0 && r.t_nulled_s <= 1.0);
  assert_true(fabs(quad_true_dps()) <= 1.0);
  assert_int_equal(qn->mode, QUAD_NULL_RUN);
  assert_true(r.t_settled_s > 0.0 && r.t_settled_s <= 1.0);
  /* never valid before the loop settled; the bit is the loop's state on every block */
  assert_false(r.valid_unsettled);
  assert_false(r.bit_disagrees);
  assert_true(r.t_valid_s >= r.t_settled_s);
  assert_true(r.valid_after_s == 1.0);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  /* one electrode at a time, and its code is in the frame the plant's DAC reads */
  assert_true(qn->v1_v == 0.0f || qn->v2_v == 0.0f);
  assert_int_equal(app.dac.code[HAL_DAC_QUADNULL_V1], gyro_volts_to_dac(qn->v1_v));
  assert_int_equal(app.dac.code[HAL_DAC_QUADNULL_V2], gyro_volts_to_dac(qn->v2_v));
  const char *s = cmd("status\n");
  assert_non_null(strstr(s, "quad_null run"));
  assert_non_null(strstr(s, "quad_gain_dps_per_v2 "));
  assert_non_null(strstr(s, "rate_valid 1"));
}

/* quad.null 0 (the default) on the same part: the quadrature stays, the electrodes at
 * mid-scale, the new reason never set. */
static void test_off_leaves_quadrature(void **state)
{
  (void)state;
  start(QN_DPS_PER_V2, 0u);
  run_to(1.0);
  printf("# quad.null 0: quadrature %.1f deg/s at 1 s\n", quad_true_dps());
  assert_true(fabs(quad_true_dps()) > 1000.0);
  assert_int_equal(app.gyro.quad.mode, QUAD_NULL_OFF);
  assert_int_equal(app.dac.code[HAL_DAC_QUADNULL_V1], HAL_DAC_CODE_MID);
  assert_int_equal(app.dac.code[HAL_DAC_QUADNULL_V2], HAL_DAC_CODE_MID);
  assert_int_equal(app.gyro.out.rate_invalid & RATE_INVALID_QUAD_NULL, 0u);
  assert_int_equal(app.gyro.out.rate_valid, 1u);
}

/* A part without nulling electrodes and quad.null 1: the probe's step moves nothing, the
 * loop stops (failed) with both electrodes at 0 V, and the rate is never valid. */
static void test_no_electrodes_probe_fails(void **state)
{
  (void)state;
  start(0.0, 1u);
  const run_t r = run_to(1.5);
  printf("# no electrodes: loop mode %d, quadrature %.1f deg/s, rate first valid at %.3f s\n",
         (int)app.gyro.quad.mode, quad_true_dps(), r.t_valid_s);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_int_equal(app.gyro.quad.mode, QUAD_NULL_FAILED);
  assert_true(app.gyro.quad.v1_v == 0.0f && app.gyro.quad.v2_v == 0.0f);
  assert_int_equal(app.dac.code[HAL_DAC_QUADNULL_V1], HAL_DAC_CODE_MID);
  assert_int_equal(app.dac.code[HAL_DAC_QUADNULL_V2], HAL_DAC_CODE_MID);
  assert_true(r.t_valid_s < 0.0);
  assert_true((app.gyro.out.rate_invalid & RATE_INVALID_QUAD_NULL) != 0u);
  const char *s = cmd("status\n");
  assert_non_null(strstr(s, "quad_null failed"));
  assert_non_null(strstr(s, "QUAD_NULL"));
}

/* The loop stops when the drive does (both electrodes at 0 V) and starts again, with its
 * probe, at the next lock. */
static void test_stops_with_drive(void **state)
{
  (void)state;
  start(QN_DPS_PER_V2, 1u);
  run_to(1.0);
  assert_int_equal(app.gyro.quad.mode, QUAD_NULL_RUN);
  assert_true(strncmp(cmd("drive off\n"), "ok", 2) == 0);
  run_s(0.01);
  assert_int_equal(app.gyro.quad.mode, QUAD_NULL_OFF);
  assert_int_equal(app.dac.code[HAL_DAC_QUADNULL_V1], HAL_DAC_CODE_MID);
  assert_int_equal(app.dac.code[HAL_DAC_QUADNULL_V2], HAL_DAC_CODE_MID);
  assert_true(strncmp(cmd("drive on\n"), "ok", 2) == 0);
  run_to(1.0);
  assert_int_equal(app.gyro.quad.mode, QUAD_NULL_RUN);
  assert_true(fabs(quad_true_dps()) <= 1.0);
}

static void test_bad_values_refused(void **state)
{
  (void)state;
  start(QN_DPS_PER_V2, 0u);
  /* a probe above the limit, a limit beyond the converter, a crossover too fast for the
   * 500 Hz update, a mean shorter than one update: each refused, nothing applied */
  assert_non_null(strstr(cmd("set quad.probe_v 12\n"), "err "));
  assert_non_null(strstr(cmd("set quad.v_max_v 15\n"), "err "));
  assert_non_null(strstr(cmd("set quad.bw_hz 60\n"), "err "));
  assert_non_null(strstr(cmd("set quad.probe_avg_s 0.001\n"), "err "));
  assert_non_null(strstr(cmd("set quad.null 2\n"), "err "));
  assert_non_null(strstr(cmd("set quad.v_max_v nan\n"), "err "));
  assert_true(params_current(&app.params)->quad_probe_v == 2.0f);
  assert_true(params_current(&app.params)->quad_v_max_v == 10.0f);
  assert_true(strncmp(cmd("set quad.v_max_v 14.5\n"), "ok", 2) == 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_nulls_within_one_second),
      cmocka_unit_test(test_off_leaves_quadrature),
      cmocka_unit_test(test_no_electrodes_probe_fails),
      cmocka_unit_test(test_stops_with_drive),
      cmocka_unit_test(test_bad_values_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
