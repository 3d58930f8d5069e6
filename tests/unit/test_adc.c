#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "plant/adc.h"
#include "plant/rng.h"

#define LSB (10.0 / 65536.0)

static adc_t make(void)
{
  adc_cfg_t c;
  adc_default_cfg(&c);
  adc_t a;
  assert_int_equal(adc_init(&a, &c), 0);
  return a;
}

/* Round to nearest: codes k - 0.4, k, k + 0.4 LSB give k; k + 0.6 LSB gives k + 1. */
static void test_rounding(void **state)
{
  (void)state;
  adc_t a = make();
  const int ks[] = {0, 1, -1, 1234, -20000, 32766, -32767};
  for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++) {
    const int k = ks[i];
    assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, (k - 0.4) * LSB), k);
    assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, k * LSB), k);
    assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, (k + 0.4) * LSB), k);
    assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, (k + 0.6) * LSB), k + 1);
    assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, (k - 0.6) * LSB), k - 1);
  }
  /* ties go away from zero, as round() (the converter rounds without libm), and a
   * hair below a tie goes down */
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, 2.5 * LSB), 3);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, -2.5 * LSB), -3);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, 0.49999999999999994 * LSB), 0);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, -0.49999999999999994 * LSB), 0);
  for (int i = -4000; i <= 4000; i++) {
    const double x = 8.1234567 * i + 0.37;
    assert_int_equal(adc_convert(&a, ADC_CH_SENSE, x * LSB), (int)round(x * LSB * a.inv_lsb));
  }
  assert_int_equal(a.clip_count[ADC_CH_DRIVE], 0);
  assert_true(fabs(adc_code_to_v(&a, -32768) + 5.0) < 1e-15);
  assert_true(fabs(adc_code_to_v(&a, 16384) - 2.5) < 1e-15);
}

/* The rails: +5 V is one LSB past the top code and clips; -5 V is the bottom code. */
static void test_clipping_per_channel(void **state)
{
  (void)state;
  adc_t a = make();
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, 32767.4 * LSB), 32767);
  assert_int_equal(a.clip_count[ADC_CH_SENSE], 0);
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, 32767.6 * LSB), 32767);
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, 5.0), 32767);
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, -5.0), -32768);
  assert_int_equal(a.clip_count[ADC_CH_SENSE], 2);
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, -32768.6 * LSB), -32768);
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, 1e300), 32767);
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, -1e300), -32768);
  assert_int_equal(a.clip_count[ADC_CH_SENSE], 5);
  assert_int_equal(a.clip_count[ADC_CH_DRIVE], 0);
  hal_adc_frame_t fr;
  adc_convert_frame(&a, 7.0, 1.0, &fr);
  assert_int_equal(fr.drive, 32767);
  assert_int_equal(fr.sense, 6554); /* 1 V = 6553.6 LSB */
  assert_int_equal(a.clip_count[ADC_CH_DRIVE], 1);
  assert_int_equal(a.clip_count[ADC_CH_SENSE], 5);
  adc_clear_counts(&a);
  assert_int_equal(a.clip_count[ADC_CH_DRIVE] + a.clip_count[ADC_CH_SENSE], 0);
}

/* Non-finite inputs give code 0 and count as faults, not clips; bad channels do nothing. */
static void test_faults(void **state)
{
  (void)state;
  adc_t a = make();
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, NAN), 0);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, INFINITY), 0);
  assert_int_equal(a.fault_count[ADC_CH_DRIVE], 2);
  assert_int_equal(a.clip_count[ADC_CH_DRIVE], 0);
  assert_int_equal(adc_convert(&a, 2, 1.0), 0);
  assert_int_equal(adc_convert(&a, -1, 1.0), 0);
  assert_int_equal(a.fault_count[ADC_CH_SENSE], 0);
  adc_cfg_t c;
  adc_default_cfg(&c);
  c.full_scale_v = 0.0;
  adc_t before = a;
  assert_int_equal(adc_init(&a, &c), -1);
  c.full_scale_v = NAN;
  assert_int_equal(adc_init(&a, &c), -1);
  assert_memory_equal(&a, &before, sizeof a);
}

/* Quantisation error of in-range inputs: never beyond LSB/2, variance LSB^2/12 (4-26). */
static void test_quantisation_noise(void **state)
{
  (void)state;
  adc_t a = make();
  rng_t r;
  rng_seed(&r, 4u, 4u);
  const int n = 200000;
  double s2 = 0.0;
  for (int i = 0; i < n; i++) {
    const double v = (2.0 * rng_uniform(&r) - 1.0) * 4.99;
    const double e = v - adc_convert(&a, ADC_CH_DRIVE, v) * LSB;
    assert_true(fabs(e) <= 0.5 * LSB * (1.0 + 1e-12));
    s2 += e * e;
  }
  const double want = LSB * LSB / 12.0;
  assert_true(fabs(s2 / n / want - 1.0) < 5.0 * sqrt(0.8 / n)); /* var of e^2 = 0.8 want^2 */
}

/* INL (inl.h): a bow of 4 LSB moves the code of mid-scale inputs by 4 and of inputs at a
 * quarter of the range by 3 (4 (1 - 1/4)), none at the ends; with the per-code pattern
 * the codes follow round(x + INL(c)) for the part's own pattern. Both channels alike. */
static void test_inl(void **state)
{
  (void)state;
  adc_cfg_t c;
  adc_default_cfg(&c);
  c.inl.bow_lsb = 4.0;
  adc_t a;
  assert_int_equal(adc_init(&a, &c), 0);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, 0.0), 4);
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, 0.0), 4);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, -16384 * LSB), -16384 + 3);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, 32767 * LSB), 32767);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, -32768 * LSB), -32768);
  c.inl.bow_lsb = 0.0;
  c.inl.code_lsb = 3.0;
  c.inl_seed = 12u;
  assert_int_equal(adc_init(&a, &c), 0);
  int moved = 0;
  for (int x = -32000; x <= 32000; x += 250) {
    const int want = (int)lround((double)x + inl_lsb(&a.inl, x + 32768L));
    assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, x * LSB), want);
    moved |= want != x;
  }
  assert_true(moved);
}

/* The shared reference r (vref.h): the converter reads v / (lsb (1 + r)). */
static void test_reference_error(void **state)
{
  (void)state;
  adc_t a = make();
  adc_set_ref(&a, 1e-3);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, 20000 * LSB), 19980); /* 20000 / 1.001 */
  adc_set_ref(&a, -1e-3);
  assert_int_equal(adc_convert(&a, ADC_CH_SENSE, -20000 * LSB), -20020);
  adc_set_ref(&a, 0.0);
  assert_int_equal(adc_convert(&a, ADC_CH_DRIVE, 20000 * LSB), 20000);
}

/* Aperture jitter: draws of rms sigma from the seeded stream (the pickoffs apply them,
 * test_pickoff_effects); none without it, and 0 returned. Bad values refused. */
static void test_aperture_jitter(void **state)
{
  (void)state;
  adc_t a = make();
  const rng_t r0 = a.rng_aperture;
  assert_true(adc_aperture_draw(&a) == 0.0);
  assert_memory_equal(&a.rng_aperture, &r0, sizeof r0); /* nothing drawn */
  adc_cfg_t c;
  adc_default_cfg(&c);
  c.aperture_jitter_s = 5e-9;
  c.seed = 3u;
  assert_int_equal(adc_init(&a, &c), 0);
  const int n = 100000;
  double s2 = 0.0;
  for (int i = 0; i < n; i++) {
    const double d = adc_aperture_draw(&a);
    s2 += d * d;
  }
  assert_true(fabs(sqrt(s2 / n) / 5e-9 - 1.0) < 5.0 / sqrt(2.0 * n));
  const adc_t before = a;
  const double bad[3] = {-1e-9, NAN, 2e-3};
  for (int i = 0; i < 3; i++) {
    c.aperture_jitter_s = bad[i];
    assert_int_equal(adc_init(&a, &c), -1);
    assert_memory_equal(&a, &before, sizeof a);
  }
  adc_default_cfg(&c);
  c.inl.code_lsb = -1.0;
  assert_int_equal(adc_init(&a, &c), -1);
  assert_memory_equal(&a, &before, sizeof a);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_rounding),
      cmocka_unit_test(test_clipping_per_channel),
      cmocka_unit_test(test_faults),
      cmocka_unit_test(test_quantisation_noise),
      cmocka_unit_test(test_inl),
      cmocka_unit_test(test_reference_error),
      cmocka_unit_test(test_aperture_jitter),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
