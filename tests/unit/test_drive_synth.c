#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "dsp/nco.h"
#include "gyro/drive_synth.h"

/* A synthesiser of the scheme (D 7 V, u_max 14 V) and the real NCO at the drive's
 * frequency. */
/* The NCO's output at a half phase (one sample's worth, for the steps' inputs). */
static const nco_out_t *at(uint32_t half_phase)
{
  static nco_out_t o;
  nco_out_at(half_phase, &o);
  return &o;
}

static void start(gyro_drive_scheme_t scheme, drive_synth_t *ds, nco_t *nco)
{
  drive_synth_cfg_t c = {.scheme = scheme, .dc_bias_v = 7.0f, .u_max_v = 14.0f};
  assert_int_equal(drive_synth_init(ds, &c), 0);
  nco_cfg_t nc = {.freq_hz = 1489.9, .fs_hz = 50000.0, .phase_rad = 0.0};
  assert_int_equal(nco_init(nco, &nc), 0);
}

/* (6-7) with (6-18..6-21): U1^2 - U2^2 = f cos(phi + P) for both schemes, at every
 * sample of a run of the real NCO through accumulator wraps. */
static void check_force(gyro_drive_scheme_t scheme)
{
  drive_synth_t ds;
  nco_t nco;
  start(scheme, &ds, &nco);
  const float f = 64.0f;
  double max_err = 0.0, prev_u1 = 0.0;
  double max_jump = 0.0;
  for (int n = 0; n < 200000; n++) {
    nco_out_t o;
    nco_step(&nco, &o);
    const float p = -2.0f + 4.0f * (float)n / 200000.0f; /* sweep P through +-2 rad */
    float u1, u2;
    drive_synth_set(&ds, f, p);
    drive_synth_step(&ds, &o, &u1, &u2);
    const double phi = 2.0 * M_PI * (double)o.phase / 4294967296.0; /* the NCO's own phase */
    const double force = (double)u1 * u1 - (double)u2 * u2;
    const double err = fabs(force - f * cos(phi + p));
    if (err > max_err) max_err = err;
    if (n > 0 && fabs(u1 - prev_u1) > max_jump) max_jump = fabs(u1 - prev_u1);
    prev_u1 = u1;
  }
  assert_true(max_err < 64.0 * 2e-5);
  /* Continuity: no step larger than one sample's advance of the waveform. */
  const double slope = (scheme == GYRO_DRIVE_DC_AC ? 2.0 * M_PI * 1489.9 * 64.0 / 28.0
                                                   : M_PI * 1489.9 * 8.0) /
                       50000.0;
  assert_true(max_jump < 1.05 * slope);
}

static void test_half_frequency_force(void **state)
{
  (void)state;
  check_force(GYRO_DRIVE_HALF_FREQ);
}
static void test_dc_ac_force(void **state)
{
  (void)state;
  check_force(GYRO_DRIVE_DC_AC);
}

/* Largest force each scheme can make within +-u_max on both electrodes. */
static void test_limits(void **state)
{
  (void)state;
  drive_synth_t ds;
  drive_synth_cfg_t c = {.scheme = GYRO_DRIVE_HALF_FREQ, .dc_bias_v = 0.0f, .u_max_v = 14.0f};
  assert_int_equal(drive_synth_init(&ds, &c), 0);
  assert_true(fabsf(drive_synth_f_cmd_max(&ds) - 196.0f) < 1e-4f);
  c.scheme = GYRO_DRIVE_DC_AC;
  c.dc_bias_v = 7.0f;
  assert_int_equal(drive_synth_init(&ds, &c), 0);
  assert_true(fabsf(drive_synth_f_cmd_max(&ds) - 196.0f) < 1e-4f);
  float u1, u2;
  drive_synth_set(&ds, 196.0f, 0.0f);
  drive_synth_step(&ds, at(0u), &u1, &u2);
  assert_true(u1 <= 14.0f + 1e-4f && u2 >= -1e-4f);
  c.dc_bias_v = 14.0f; /* no room for AC */
  assert_int_equal(drive_synth_init(&ds, &c), -1);
  c.scheme = (gyro_drive_scheme_t)7;
  assert_int_equal(drive_synth_init(&ds, &c), -1);
}

/* A NaN or infinite command gives zero volts, never a rail: the loop state is checked
 * once per block, the waveform runs every sample. */
static void test_non_finite_command(void **state)
{
  (void)state;
  const gyro_drive_scheme_t schemes[] = {GYRO_DRIVE_HALF_FREQ, GYRO_DRIVE_DC_AC};
  const float bad[] = {NAN, INFINITY, -INFINITY};
  for (int m = 0; m < 2; m++) {
    drive_synth_t ds;
    drive_synth_cfg_t c = {.scheme = schemes[m], .dc_bias_v = 7.0f, .u_max_v = 14.0f};
    assert_int_equal(drive_synth_init(&ds, &c), 0);
    for (int i = 0; i < 3; i++) {
      for (int j = 0; j < 3; j++) {
        drive_synth_set(&ds, bad[i], j == 0 ? 0.3f : bad[j]);
        for (uint32_t ph = 0u; ph < 0xF0000000u; ph += 0x10000000u) {
          float u1, u2;
          drive_synth_step(&ds, at(ph / 2u), &u1, &u2);
          const float rest = schemes[m] == GYRO_DRIVE_DC_AC ? 7.0f : 0.0f;
          assert_true(u1 == rest && u2 == rest);
        }
        drive_synth_set(&ds, 64.0f, bad[i]); /* finite force, bad phase: bounded */
        float u1, u2;
        drive_synth_step(&ds, at(45u), &u1, &u2);
        assert_true(isfinite(u1) && isfinite(u2) && fabsf(u1) <= 14.0f && fabsf(u2) <= 14.0f);
      }
    }
  }
}

/* What drive_synth_set says it does with a P the phase conversion cannot take (NaN
 * here): the phase is zeroed, not left where it was, and the whole turns it carried
 * are forgotten, so that the next finite P is converted as from a fresh start. */
static void test_bad_phase_zeroes_phase_and_turns(void **state)
{
  (void)state;
  drive_synth_t ds, fresh;
  const drive_synth_cfg_t c = {
      .scheme = GYRO_DRIVE_HALF_FREQ, .dc_bias_v = 0.0f, .u_max_v = 14.0f};
  assert_int_equal(drive_synth_init(&ds, &c), 0);
  assert_int_equal(drive_synth_init(&fresh, &c), 0);
  drive_synth_set(&ds, 64.0f, 1.0f);
  drive_synth_set(&ds, 64.0f, 5.0f); /* beyond 1.5 pi: a turn taken off */
  assert_true(ds.p_turn_rad != 0.0f);
  drive_synth_set(&ds, 64.0f, NAN);
  assert_int_equal(ds.off, 0u);
  assert_true(ds.p_turn_rad == 0.0f);
  drive_synth_set(&ds, 64.0f, 0.3f);
  drive_synth_set(&fresh, 64.0f, 0.3f);
  assert_int_equal(ds.off, fresh.off);
}

/* A phasor command (drive_synth_set_phasor): U1^2 - U2^2 = |F| cos(phi + frame + arg F)
 * for both schemes, with F turned once around the origin (arg F through +-pi, where the
 * half-frequency root changes sign), Re F = 0 and an F that is all negative real; a
 * non-finite F drives nothing. */
static void check_phasor(gyro_drive_scheme_t scheme)
{
  drive_synth_t ds;
  nco_t nco;
  start(scheme, &ds, &nco);
  double max_err = 0.0;
  for (int n = 0; n < 100000; n++) {
    nco_out_t o;
    nco_step(&nco, &o);
    const double a = -M_PI + 2.0 * M_PI * (double)n / 100000.0 + 1e-3;
    const float mag = n % 7 == 0 ? 0.0f : 30.0f + 20.0f * (float)(n % 5);
    float fr = (float)(mag * cos(a)), fi = (float)(mag * sin(a));
    if (n % 11 == 0) fr = 0.0f;
    if (n % 13 == 0) fi = 0.0f; /* on the branch cut when fr < 0 */
    const float frame = 0.7f - 1.3f * (float)n / 100000.0f;
    float u1, u2;
    drive_synth_phasor_t ph;
    drive_synth_phasor_mag(&ph, fr, fi);
    drive_synth_phasor_root(&ds, &ph);
    drive_synth_phasor_parts(&ds, &ph);
    drive_synth_set_phasor(&ds, &ph, frame);
    drive_synth_step(&ds, &o, &u1, &u2);
    const double phi = 2.0 * M_PI * (double)o.phase / 4294967296.0;
    const double want = (double)fr * cos(phi + frame) - (double)fi * sin(phi + frame);
    const double err = fabs((double)u1 * u1 - (double)u2 * u2 - want);
    if (err > max_err) max_err = err;
  }
  print_message("# max error %.3g V^2\n", max_err);
  assert_true(max_err < 150.0 * 2e-5);
  float u1, u2;
  drive_synth_phasor_t ph;
  drive_synth_phasor_mag(&ph, NAN, 1.0f);
  drive_synth_phasor_root(&ds, &ph);
  drive_synth_phasor_parts(&ds, &ph);
  drive_synth_set_phasor(&ds, &ph, 0.0f);
  drive_synth_step(&ds, at(0u), &u1, &u2);
  assert_true(u1 == u2 && isfinite(u1)); /* no force: 0 V, or the bias alone in DC+AC */
  drive_synth_phasor_mag(&ph, 1.0f, INFINITY);
  drive_synth_phasor_root(&ds, &ph);
  drive_synth_phasor_parts(&ds, &ph);
  drive_synth_set_phasor(&ds, &ph, 0.0f);
  drive_synth_step(&ds, at(0u), &u1, &u2);
  assert_true(u1 == u2 && isfinite(u1));
}

static void test_phasor_half_frequency(void **state)
{
  (void)state;
  check_phasor(GYRO_DRIVE_HALF_FREQ);
}

static void test_phasor_dc_ac(void **state)
{
  (void)state;
  check_phasor(GYRO_DRIVE_DC_AC);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_half_frequency_force),
      cmocka_unit_test(test_dc_ac_force),
      cmocka_unit_test(test_limits),
      cmocka_unit_test(test_bad_phase_zeroes_phase_and_turns),
      cmocka_unit_test(test_non_finite_command),
      cmocka_unit_test(test_phasor_half_frequency),
      cmocka_unit_test(test_phasor_dc_ac),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
