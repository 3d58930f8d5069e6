#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "hal_host.h"
#include "hal/hal_sample_timer.h"

/* A plant that reports, on the drive ADC channel, the U1 code it was driven with over
 * the last period, and on the sense channel how many periods it has integrated. */
typedef struct {
  int periods;
} echo_plant_t;

static void echo_step(void *p, const hal_dac_frame_t *dac, hal_adc_frame_t *adc)
{
  echo_plant_t *e = p;
  e->periods++;
  adc->drive = (int16_t)dac->code[HAL_DAC_DRIVE_U1];
  adc->sense = (int16_t)e->periods;
}

typedef struct {
  int n;
  int16_t seen_drive[16];
  int16_t seen_sense[16];
} isr_log_t;

/* The ISR writes U1 = 100 + tick number and logs what it read. */
static void isr(void *ctx)
{
  isr_log_t *log = ctx;
  const volatile hal_adc_frame_t *f = hal_adc_frame();
  log->seen_drive[log->n] = f->drive;
  log->seen_sense[log->n] = f->sense;
  hal_dac_frame_t d = {{0, 0, 0, 0}};
  d.code[HAL_DAC_DRIVE_U1] = (uint16_t)(100 + log->n);
  hal_dac_write_frame(&d);
  log->n++;
}

/* A frame written at tick n drives the plant over [t_n+1, t_n+2] and is first seen in
 * the ADC frame read at tick n+2: one sample of DAC latency plus the hold, as on the
 * board (conversion at the timer event, LDAC at the next one). */
static void test_latency(void **state)
{
  (void)state;
  echo_plant_t plant = {0};
  isr_log_t log = {0};
  hal_host_attach(echo_step, &plant);
  assert_int_equal(hal_sample_timer_start(50000u, isr, &log), 0);
  assert_int_equal(hal_host_run(10u), 10u);
  assert_int_equal(log.n, 10);
  /* Ticks 0 and 1 see the mid-scale outputs of power-on. */
  assert_int_equal(log.seen_drive[0], (int16_t)HAL_DAC_CODE_MID);
  assert_int_equal(log.seen_drive[1], (int16_t)HAL_DAC_CODE_MID);
  for (int n = 2; n < 10; n++) {
    assert_int_equal(log.seen_drive[n], 100 + n - 2);
  }
  /* Tick n reads the frame sampled after n + 1 plant periods (one at attach). */
  for (int n = 0; n < 10; n++) {
    assert_int_equal(log.seen_sense[n], n + 1);
  }
  assert_int_equal(hal_host_ticks(), 10u);
  assert_int_equal(hal_cycles_now(), 10u * 3360u);
}

static void test_not_started(void **state)
{
  (void)state;
  echo_plant_t plant = {0};
  hal_host_attach(echo_step, &plant);
  hal_sample_timer_stop();
  assert_int_equal(hal_host_run(5u), 0u);
  assert_int_equal(hal_sample_timer_start(0u, isr, NULL), -1);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_latency),
      cmocka_unit_test(test_not_started),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
