#include "hal_host.h"

#include <stddef.h>

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

uint32_t hal_critical_enter(void) { return 0u; }

void hal_critical_exit(uint32_t state) { (void)state; }
