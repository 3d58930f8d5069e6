/* gyro_design's refusals: every status is reachable, and its reason names the
 * parameters at fault by their user-visible names (`set` and the boot report print it). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "gyro/gyro.h"
#include "params/params.h"

typedef struct {
  gyro_design_status_t status;
  const char *param; /* a parameter the reason must name */
  void (*spoil)(param_values_t *v);
} refusal_t;

/* In range one by one, refused together. */
static void drive_freq_high(param_values_t *v) { v->drive_freq_hz = 20000.0f; }
static void drive_freq_negative(param_values_t *v) { v->drive_freq_hz = -1.0f; }
static void dc_bias_over_u_max(param_values_t *v)
{
  v->drive_mode = 1u;
  v->drive_dc_bias_v = 14.0f;
  v->drive_u_max_v = 12.75f;
}
static void lost_below_lock(param_values_t *v)
{
  v->sup_lock_tol_rel = 0.1f;
  v->sup_lost_tol_rel = 0.05f;
}
static void fault_level_in_span(param_values_t *v) { v->rate_fault_out_v = 1.0f; }
static void cont_freq_in_band(param_values_t *v)
{
  v->selftest_continuous = 1u;
  v->selftest_cont_freq_hz = 100.0f; /* rate.lpf_cutoff_hz is 100 Hz */
}
static void cont_expect_zero(param_values_t *v)
{
  v->selftest_continuous = 1u;
  v->selftest_cont_expect_dps = 0.0f;
}
/* Quadrature nulling (quad_null.h): each of its cross-checks, refused whether the loop
 * is on or not (a part turned on later must not start from a bad set). */
static void quad_probe_over_limit(param_values_t *v)
{
  v->quad_v_max_v = 5.0f;
  v->quad_probe_v = 6.0f;
}
static void quad_limit_beyond_dac(param_values_t *v) { v->quad_v_max_v = 15.0f; }
static void quad_bw_over_rate(param_values_t *v)
{
  v->quad_null = 1u;
  v->quad_bw_hz = 60.0f; /* more than a tenth of the 500 Hz update */
}
static void quad_avg_under_update(param_values_t *v) { v->quad_probe_avg_s = 0.001f; }
/* Outside a parameter's range: refused by the parameter bank before a design, but
 * gyro_design is also called directly (simulator, bench) and names them too. */
static void fs_zero(param_values_t *v) { v->sys_fs_hz = 0u; }
static void p_init_beyond_reach(param_values_t *v) { v->drive_p_init_deg = 361.0f; }
static void mu_drive_high(param_values_t *v) { v->demod_mu_drive = 0.6f; }
static void mu_sense_zero(param_values_t *v) { v->demod_mu_sense = 0.0f; }
static void cal_gain_zero(param_values_t *v) { v->drive_cal_gain_v_per_v2 = 0.0f; }
static void phase_bw_zero(param_values_t *v) { v->drive_phase_bw_hz = 0.0f; }
/* Q = 10^4 in the fixed drive (drive.track 0): beyond its reach, refused with a pointer to
 * the tracking drive; the same Q with drive.track 1 designs (test_tracking_designs). */
static void fixed_q_beyond_reach(param_values_t *v) { v->drive_cal_q = 1.0e4f; }
static void lpf_above_nyquist(param_values_t *v) { v->rate_lpf_cutoff_hz = 3000.0f; }
static void lpf_odd_order(param_values_t *v) { v->rate_lpf_order = 3u; }
static void amp_set_over_adc(param_values_t *v) { v->drive_amp_set_v = 4.9f; }
static void amp_trip_low(param_values_t *v) { v->sup_amp_trip_rel = 1.05f; }
static void bias_slope_huge(param_values_t *v) { v->rate_bias_c1_dps_per_deg = 1e35f; }
static void clip_count_zero(param_values_t *v) { v->sup_clip_count = 0u; }
static void fb_bias_over_limit(param_values_t *v)
{
  v->sense_fb_scheme = 1u;
  v->sense_fb_bias_v = 12.0f;
}
static void fb_gain_zero(param_values_t *v) { v->sense_fb_gain_v_per_v2 = 0.0f; }
/* 2 zeta w beyond the demodulator's lag: the third root in the right half plane */
static void fr_bw_beyond_lag(param_values_t *v)
{
  v->sense_q = 1.0e4f;
  v->sense_fr_bw_hz = 240.0f;
}
static void fr_slow_demod(param_values_t *v)
{
  v->sense_q = 1.0e4f;
  v->sense_fr_mu = 0.01f;
}
static void tune_matched_open_loop(param_values_t *v) { v->sense_tune = 1u; }
/* a tuning calibration whose target (the drive's resonance) is above the untuned sense
 * resonance: tuning only lowers it */
static void tune_target_above(param_values_t *v)
{
  v->sense_mode = 1u;
  v->sense_tune = 1u;
  v->sense_cal_s0_hz = v->drive_freq_hz - 10.0f;
  v->sense_cal_tune_ref_hz = v->drive_freq_hz;
  v->sense_cal_tune_ke_per_s2_per_v2 = 1.0e5f;
}
static void fr_cont_selftest(param_values_t *v)
{
  v->sense_mode = 1u;
  v->selftest_continuous = 1u;
  v->selftest_cont_expect_dps = 1.0f;
  v->selftest_cont_fr_v2 = 30.0f; /* over a quarter of the electrodes' 100 V^2 */
}

static const refusal_t k_refusals[] = {
    {GYRO_DESIGN_FS, "sys.fs_hz", fs_zero},
    {GYRO_DESIGN_DRIVE_FREQ, "drive.freq_hz", drive_freq_high},
    {GYRO_DESIGN_DRIVE_FREQ, "drive.freq_hz", drive_freq_negative},
    {GYRO_DESIGN_DRIVE_VOLTAGES, "drive.dc_bias_v", dc_bias_over_u_max},
    {GYRO_DESIGN_MU_DRIVE, "demod.mu_drive", mu_drive_high},
    {GYRO_DESIGN_MU_SENSE, "demod.mu_sense", mu_sense_zero},
    {GYRO_DESIGN_AMP_LOOP, "drive.cal_gain_v_per_v2", cal_gain_zero},
    {GYRO_DESIGN_PHASE_LOOP, "drive.phase_bw_hz", phase_bw_zero},
    {GYRO_DESIGN_FIXED_Q, "drive.track", fixed_q_beyond_reach},
    {GYRO_DESIGN_P_INIT, "drive.p_init_deg", p_init_beyond_reach},
    {GYRO_DESIGN_RATE_LPF, "rate.lpf_cutoff_hz", lpf_above_nyquist},
    {GYRO_DESIGN_RATE_LPF, "rate.lpf_order", lpf_odd_order},
    {GYRO_DESIGN_AMP_SET, "drive.amp_set_v", amp_set_over_adc},
    {GYRO_DESIGN_LOST_TOL, "sup.lost_tol_rel", lost_below_lock},
    {GYRO_DESIGN_AMP_TRIP, "sup.amp_trip_rel", amp_trip_low},
    {GYRO_DESIGN_FAULT_OUT, "rate.fault_out_v", fault_level_in_span},
    {GYRO_DESIGN_BIAS_SLOPE, "rate.bias_c1_dps_per_deg", bias_slope_huge},
    {GYRO_DESIGN_CONT_FREQ, "selftest.cont_freq_hz", cont_freq_in_band},
    {GYRO_DESIGN_CONT_EXPECT, "selftest.cont_expect_dps", cont_expect_zero},
    {GYRO_DESIGN_SENSE_FB, "sense.fb_bias_v", fb_bias_over_limit},
    {GYRO_DESIGN_SENSE_FR, "sense.fb_gain_v_per_v2", fb_gain_zero},
    {GYRO_DESIGN_SENSE_FR, "sense.fr_bw_hz", fr_bw_beyond_lag},
    {GYRO_DESIGN_SENSE_FR, "sense.fr_mu", fr_slow_demod},
    {GYRO_DESIGN_SENSE_SELFTEST, "selftest.cont_fr_v2", fr_cont_selftest},
    {GYRO_DESIGN_SENSE_TUNE, "sense.tune", tune_matched_open_loop},
    {GYRO_DESIGN_SENSE_TUNE, "sense.cal_s0_hz", tune_target_above},
    {GYRO_DESIGN_QUAD_NULL, "quad.probe_v", quad_probe_over_limit},
    {GYRO_DESIGN_QUAD_NULL, "quad.v_max_v", quad_limit_beyond_dac},
    {GYRO_DESIGN_QUAD_NULL, "quad.bw_hz", quad_bw_over_rate},
    {GYRO_DESIGN_QUAD_NULL, "quad.probe_avg_s", quad_avg_under_update},
    {GYRO_DESIGN_MODULE, "range", clip_count_zero},
};
#define N_REFUSALS (sizeof k_refusals / sizeof k_refusals[0])

static void test_defaults_design(void **state)
{
  (void)state;
  param_values_t v;
  param_values_defaults(&v);
  gyro_design_t d;
  assert_int_equal(gyro_design(&v, &d), GYRO_DESIGN_OK);
  assert_string_equal(gyro_design_reason(GYRO_DESIGN_OK), "");
  /* The edges the reasons state: drive.p_init_deg within +-360 deg, its whole range. */
  v.drive_p_init_deg = -360.0f;
  assert_int_equal(gyro_design(&v, &d), GYRO_DESIGN_OK);
  v.drive_p_init_deg = 360.0f;
  assert_int_equal(gyro_design(&v, &d), GYRO_DESIGN_OK);
  v.drive_p_init_deg = -360.5f;
  assert_int_equal(gyro_design(&v, &d), GYRO_DESIGN_P_INIT);
}

/* A calibration is the drive mode's it was made in: the tracking drive's thermometer is
 * the tracked frequency (p_eq, drive_track.h), the fixed drive's the force phase, and the
 * demodulation phase and scale differ with them. Made in the one and run in the other it
 * is stale (calibrated no, the rate not valid). A fixed-drive calibration with
 * drive.track 1 was "calibrated yes" before (only the TRACKING reason kept it invalid). */
static void test_cal_belongs_to_its_drive_mode(void **state)
{
  (void)state;
  param_values_t v;
  param_values_defaults(&v);
  v.cal_ref_freq_hz = v.drive_freq_hz;
  gyro_design_t d;
  const uint32_t track[4] = {0u, 1u, 0u, 1u}, cal_track[4] = {0u, 1u, 1u, 0u};
  const uint32_t expect[4] = {GYRO_CAL_OK, GYRO_CAL_OK, GYRO_CAL_STALE, GYRO_CAL_STALE};
  for (int i = 0; i < 4; i++) {
    v.drive_track = track[i];
    v.cal_ref_track = cal_track[i];
    assert_int_equal(gyro_design(&v, &d), GYRO_DESIGN_OK);
    assert_int_equal(d.cal_state, expect[i]);
  }
}

/* So is it the sense configuration's: force rebalance reads the rate from the force and
 * quadrature nulling takes away the quadrature that leaks into it, so the bias against
 * the thermometer, the demodulation phase and the scale of a calibration made in one
 * differ in the other. A part calibrated open loop and run with force rebalance and
 * nulling read -51.5 deg/s at rest, valid, 20 K above its calibration's temperature
 * (README, the UNCALIBRATED reason); it is stale now. */
static void test_cal_belongs_to_its_sense_configuration(void **state)
{
  (void)state;
  param_values_t v;
  param_values_defaults(&v);
  v.cal_ref_freq_hz = v.drive_freq_hz;
  v.sense_fb_gain_v_per_v2 = 0.46f; /* a force-rebalance model (the bench's) */
  v.sense_f0_hz = 1600.0f;
  v.sense_q = 1.0e4f;
  gyro_design_t d;
  for (uint32_t k = 0u; k < 16u; k++) {
    v.sense_mode = k & 1u;
    v.quad_null = (k >> 1) & 1u;
    v.cal_ref_sense_mode = (k >> 2) & 1u;
    v.cal_ref_quad_null = (k >> 3) & 1u;
    const int same = v.sense_mode == v.cal_ref_sense_mode && v.quad_null == v.cal_ref_quad_null;
    assert_int_equal(gyro_design(&v, &d), GYRO_DESIGN_OK);
    assert_int_equal(d.cal_state, same ? GYRO_CAL_OK : GYRO_CAL_STALE);
  }
}

/* Each refusal gives its own status, leaves the output untouched, and its reason names
 * the parameter. */
static void test_each_refusal_named(void **state)
{
  (void)state;
  for (size_t k = 0; k < N_REFUSALS; k++) {
    param_values_t v;
    param_values_defaults(&v);
    k_refusals[k].spoil(&v);
    gyro_design_t d;
    memset(&d, 0xA5, sizeof d);
    const gyro_design_status_t s = gyro_design(&v, &d);
    const char *why = gyro_design_reason(s);
    print_message("# %s -> %d: %s\n", k_refusals[k].param, (int)s, why);
    assert_int_equal(s, k_refusals[k].status);
    assert_non_null(strstr(why, k_refusals[k].param));
    for (size_t i = 0; i < sizeof d; i++) {
      assert_int_equal(((const unsigned char *)&d)[i], 0xA5);
    }
  }
  assert_int_equal(gyro_design(NULL, NULL), GYRO_DESIGN_NO_VALUES);
}

/* Every status but OK is reached above (so none is dead), and has a reason of its own. */
static void test_every_status_reached(void **state)
{
  (void)state;
  for (int s = 1; s < (int)GYRO_DESIGN_STATUS_COUNT; s++) {
    int reached = s == (int)GYRO_DESIGN_NO_VALUES;
    for (size_t k = 0; k < N_REFUSALS; k++) reached |= (int)k_refusals[k].status == s;
    if (!reached) print_message("# status %d not reached\n", s);
    assert_true(reached);
    const char *why = gyro_design_reason((gyro_design_status_t)s);
    assert_true(strlen(why) > 0u);
    for (int t = 1; t < s; t++) {
      assert_string_not_equal(why, gyro_design_reason((gyro_design_status_t)t));
    }
  }
  assert_string_equal(gyro_design_reason(GYRO_DESIGN_STATUS_COUNT), "");
  assert_string_equal(gyro_design_reason((gyro_design_status_t)-1), "");
}

/* Every dotted word in a reason is a parameter's user-visible name: a rename of a
 * parameter cannot leave a reason naming one that no longer exists. */
static void test_reasons_name_real_parameters(void **state)
{
  (void)state;
  for (int s = 1; s < (int)GYRO_DESIGN_STATUS_COUNT; s++) {
    const char *p = gyro_design_reason((gyro_design_status_t)s);
    while (*p != '\0') {
      size_t n = strspn(p, "abcdefghijklmnopqrstuvwxyz0123456789_.");
      size_t w = n;
      while (w > 0u && p[w - 1u] == '.') w--; /* a full stop after the name */
      if (w > 0u && p[0] >= 'a' && p[0] <= 'z' && memchr(p, '.', w) != NULL) {
        if (param_lookup(p, w) >= PARAM_COUNT) {
          print_message("# status %d names \"%.*s\"\n", s, (int)w, p);
          fail();
        }
      }
      p += n > 0u ? n : 1u;
    }
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_defaults_design),
      cmocka_unit_test(test_cal_belongs_to_its_drive_mode),
      cmocka_unit_test(test_cal_belongs_to_its_sense_configuration),
      cmocka_unit_test(test_each_refusal_named),
      cmocka_unit_test(test_every_status_reached),
      cmocka_unit_test(test_reasons_name_real_parameters),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
