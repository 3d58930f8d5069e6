#include "hal_host.h"

#include <stddef.h>

#include "hal/hal_board_temp.h"
#include "hal/hal_critical.h"
#include "hal/hal_sample_timer.h"

/* The stub stands in for hardware, of which there is one: its state is the one place
 * where file-scope state is the honest model. */
static struct {
  hal_host_plant_step_fn step;
  void *plant;
  hal_sample_isr_fn isr;
  void *isr_ctx;
  uint32_t rate_hz;
  hal_adc_frame_t adc;     /* sampled at the current tick, read by the ISR */
  hal_dac_frame_t active;  /* on the converter outputs during this interval */
  hal_dac_frame_t pending; /* written by the ISR, output from the next tick */
  uint64_t ticks;
  int running;
} host;

void hal_host_attach(hal_host_plant_step_fn step, void *plant)
{
  host.step = step;
  host.plant = plant;
  host.ticks = 0u;
  hal_dac_frame_midscale(&host.active);
  hal_dac_frame_midscale(&host.pending);
  host.adc.drive = 0;
  host.adc.sense = 0;
  if (step != NULL) {
    step(plant, &host.active, &host.adc);
  }
}

/* The host loses no sample unless a test says so (hal_host_lose_sample). */
static volatile uint32_t s_lost;

int hal_sample_timer_start(uint32_t rate_hz, hal_sample_isr_fn isr, void *ctx)
{
  if (rate_hz == 0u || isr == NULL) {
    return -1;
  }
  host.rate_hz = rate_hz;
  host.isr = isr;
  host.isr_ctx = ctx;
  host.running = 1;
  return 0;
}

void hal_sample_timer_stop(void) { host.running = 0; }

uint64_t hal_host_run(uint64_t n)
{
  if (host.step == NULL || host.isr == NULL || !host.running) {
    return 0u;
  }
  for (uint64_t i = 0; i < n; i++) {
    host.isr(host.isr_ctx);
    host.step(host.plant, &host.active, &host.adc);
    host.active = host.pending;
    host.ticks++;
  }
  return n;
}

uint64_t hal_host_ticks(void) { return host.ticks; }
uint32_t hal_host_rate_hz(void) { return host.rate_hz; }
const hal_dac_frame_t *hal_host_last_dac(void) { return &host.pending; }
const hal_adc_frame_t *hal_host_next_adc(void) { return &host.adc; }

const volatile hal_adc_frame_t *hal_adc_frame(void) { return &host.adc; }

const volatile uint32_t *hal_sample_lost_counter(void) { return &s_lost; }

void hal_dac_write_frame(const hal_dac_frame_t *frame) { host.pending = *frame; }

/* Simulated cycles of a 168 MHz core (the board's DWT counter), so that code measuring
 * itself sees sample periods of 3360 cycles; it says nothing of host speed. */
uint32_t hal_cycles_now(void)
{
  const uint64_t per_tick = host.rate_hz ? 168000000u / host.rate_hz : 0u;
  return (uint32_t)(host.ticks * per_tick);
}

void hal_host_lose_sample(void) { s_lost++; }

/* The host has no cycle counter for its own interrupt (it would measure the host). */
void hal_sample_isr_cycles(uint32_t *last, uint32_t *max)
{
  if (last != NULL) *last = 0u;
  if (max != NULL) *max = 0u;
}

/* The board temperature sensor: the host program's callback, and which of its results the
 * firmware has had (hal_host.h). */
static struct {
  hal_host_board_temp_fn fn;
  void *ctx;
  uint64_t last; /* number of the result (or the missed one) returned last; 0: none */
  int started;
} s_temp;

void hal_host_attach_board_temp(hal_host_board_temp_fn fn, void *ctx)
{
  s_temp.fn = fn;
  s_temp.ctx = ctx;
  s_temp.last = 0u;
}

/* The board's bus always comes up on the host; a board without a sensor says so on every
 * poll. A restart (start again) reads the sensor's latest result afresh. */
int hal_board_temp_start(void)
{
  s_temp.started = 1;
  s_temp.last = 0u;
  return 0;
}

hal_board_temp_event_t hal_board_temp_poll(int16_t *code)
{
  if (s_temp.fn == NULL) return HAL_BOARD_TEMP_ABSENT;
  if (!s_temp.started) return HAL_BOARD_TEMP_NONE;
  const double t_s = host.rate_hz ? (double)host.ticks / (double)host.rate_hz : 0.0;
  int16_t c = 0;
  uint64_t n = 0u;
  const hal_board_temp_event_t ev = s_temp.fn(s_temp.ctx, t_s, &c, &n);
  if (ev == HAL_BOARD_TEMP_ABSENT) return ev;
  if ((ev != HAL_BOARD_TEMP_NEW && ev != HAL_BOARD_TEMP_FAULT) || n == s_temp.last)
    return HAL_BOARD_TEMP_NONE;
  s_temp.last = n;
  if (ev == HAL_BOARD_TEMP_NEW && code != NULL) *code = c;
  return ev;
}

uint32_t hal_critical_enter(void) { return 0u; }

void hal_critical_exit(uint32_t state) { (void)state; }
