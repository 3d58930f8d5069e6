#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "hal_host.h"
#include "hal/hal_board_temp.h"
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

/* A board temperature sensor with a result every second, at 0.5, 1.5, ... s, its code
 * 100 + its number; from fault_s on (if >= 0) it does not answer. Counts the calls. */
typedef struct {
  double fault_s;
  int absent;
  int calls;
  double last_t_s;
} fake_temp_t;

static hal_board_temp_event_t fake_temp(void *ctx, double t_s, int16_t *code, uint64_t *conv)
{
  fake_temp_t *f = ctx;
  f->calls++;
  f->last_t_s = t_s;
  if (f->absent) return HAL_BOARD_TEMP_ABSENT;
  const uint64_t n = t_s < 0.5 ? 0u : (uint64_t)(t_s - 0.5) + 1u;
  *conv = n;
  if (f->fault_s >= 0.0 && t_s >= f->fault_s) return HAL_BOARD_TEMP_FAULT;
  if (n == 0u) return HAL_BOARD_TEMP_NONE;
  *code = (int16_t)(100 + (int)n);
  return HAL_BOARD_TEMP_NEW;
}

static void quiet_isr(void *ctx)
{
  (void)ctx;
  hal_dac_frame_t d;
  hal_dac_frame_midscale(&d);
  hal_dac_write_frame(&d);
}

/* Nothing attached: the board has no sensor, whatever the firmware does (the unit tests
 * that attach nothing see ABSENT); *code is never written. */
static void test_board_temp_absent(void **state)
{
  (void)state;
  hal_host_attach_board_temp(NULL, NULL);
  int16_t code = 7;
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_ABSENT);
  assert_int_equal(hal_board_temp_start(), 0);
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_ABSENT);
  fake_temp_t f = {.fault_s = -1.0, .absent = 1};
  hal_host_attach_board_temp(fake_temp, &f);
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_ABSENT);
  assert_int_equal(code, 7);
  hal_host_attach_board_temp(NULL, NULL);
}

/* Polled every 10 ms for 4 s: results 1 and 2 each NEW once with its code, at the first poll
 * at or after its time (the callback is asked at ticks / rate); NONE otherwise, and a second
 * poll at the same time NONE; from 2.2 s the missed results 3 and 4 each FAULT once. A
 * restart (start again) returns the latest result once more. */
static void test_board_temp_new_once(void **state)
{
  (void)state;
  echo_plant_t plant = {0};
  fake_temp_t f = {.fault_s = 2.2};
  hal_host_attach(echo_step, &plant);
  hal_host_attach_board_temp(fake_temp, &f);
  assert_int_equal(hal_sample_timer_start(50000u, quiet_isr, NULL), 0);
  assert_int_equal(hal_board_temp_start(), 0);
  int16_t code = 0;
  int news = 0, faults = 0;
  for (int poll = 1; poll <= 400; poll++) {
    assert_int_equal(hal_host_run(500u), 500u);
    const hal_board_temp_event_t ev = hal_board_temp_poll(&code);
    assert_true(f.last_t_s == (double)(poll * 500) / 50000.0);
    const int due = poll == 50 || poll == 150 || poll == 250 || poll == 350;
    if (!due) {
      assert_int_equal(ev, HAL_BOARD_TEMP_NONE);
    } else if (poll < 220) {
      assert_int_equal(ev, HAL_BOARD_TEMP_NEW);
      assert_int_equal(code, 100 + ++news);
    } else {
      assert_int_equal(ev, HAL_BOARD_TEMP_FAULT);
      faults++;
    }
    assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_NONE);
  }
  assert_int_equal(news, 2);
  assert_int_equal(faults, 2);
  f.fault_s = -1.0;                                                  /* answering again */
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_NONE); /* result 4 was had */
  assert_int_equal(hal_board_temp_start(), 0);
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_NEW);
  assert_int_equal(code, 104);
  /* attaching again forgets what was returned */
  hal_host_attach_board_temp(fake_temp, &f);
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_NEW);
  hal_host_attach_board_temp(NULL, NULL);
  hal_sample_timer_stop();
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_latency),
      cmocka_unit_test(test_not_started),
      cmocka_unit_test(test_board_temp_absent),
      cmocka_unit_test(test_board_temp_new_once),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
