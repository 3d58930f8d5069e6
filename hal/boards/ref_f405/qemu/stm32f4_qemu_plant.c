#include "stm32f4_qemu_plant.h"

#include "hal/hal_adc.h"
#include "hal/hal_board_temp.h"
#include "hal/hal_critical.h"
#include "hal/hal_dac.h"
#include "plant/plant.h"
#include "qemu_plant_setup.h"
#include "stm32f4_core.h"

/* The emulated hardware, of which there is one (as in the host HAL stub). SRAM: QEMU's
 * netduinoplus2 maps no CCM. */
static plant_t s_plant;
static plant_profiles_t s_prof;
static hal_adc_frame_t s_adc;     /* sampled at the current tick, read by the ISR */
static hal_dac_frame_t s_active;  /* on the converter outputs during this interval */
static hal_dac_frame_t s_pending; /* written by the ISR, output from the next tick */
static uint64_t s_samples;
static uint32_t s_ticks;               /* ticks of the sample clock (trace index) */
static volatile double s_rate_req_dps; /* written by the background before s_rate_req is set */
static volatile uint32_t s_rate_req;
static volatile int32_t s_part_req = -1; /* a part asked for (QEMU_PART_*), taken by a tick */
static const volatile float *s_trace_src;
static float s_trace[QEMU_TRACE_LEN];
static volatile uint32_t s_trace_n;
/* The board temperature sensor's reader (hal_board_temp_poll): the number of the plant
 * sensor's result returned last (0: none; reset when another part is put in, whose
 * sensor counts from 1 again), and whether hal_board_temp_start ran. */
static volatile uint64_t s_temp_last;
static volatile int s_temp_started;

int stm32f4_qemu_plant_init(void)
{
  if (qemu_plant_setup(&s_plant, &s_prof) != 0) return -1;
  hal_dac_frame_midscale(&s_active); /* all eight channels at 0 V, as RS leaves them */
  hal_dac_frame_midscale(&s_pending);
  s_adc.drive = 0;
  s_adc.sense = 0;
  plant_step(&s_plant, &s_active, &s_adc);
  s_samples = 1u;
  return 0;
}

void stm32f4_qemu_plant_tick(void)
{
  if (s_rate_req != 0u) {
    (void)qemu_plant_rate_ramp(&s_plant, &s_prof, s_rate_req_dps); /* range checked */
    s_rate_req = 0u;
  }
  if (s_part_req >= 0) {
    /* another part in the emulator's socket: a tick of its own (it overruns, counted) */
    (void)qemu_plant_setup_part(&s_plant, &s_prof, (int)s_part_req); /* checked */
    s_part_req = -1;
    s_temp_last = 0u;
  }
  plant_step(&s_plant, &s_active, &s_adc);
  s_active = s_pending;
  s_samples++;
  s_ticks++;
  if (s_trace_src != 0 && s_ticks % QEMU_TRACE_EVERY == 0u && s_trace_n < QEMU_TRACE_LEN) {
    s_trace[s_trace_n] = *s_trace_src;
    s_trace_n = s_trace_n + 1u;
  }
}

uint64_t stm32f4_qemu_plant_samples(void) { return s_samples; }

double stm32f4_qemu_plant_rate_dps(void) { return plant_truth(&s_plant)->rate_dps; }

int stm32f4_qemu_plant_set_rate(double rate_dps)
{
  if (!(rate_dps >= -1e4 && rate_dps <= 1e4)) return -1;
  if (s_rate_req != 0u) return -2;
  s_rate_req_dps = rate_dps;
  s_rate_req = 1u;
  return 0;
}

int stm32f4_qemu_plant_set_part(int part)
{
  if (part != QEMU_PART_DEFAULT && part != QEMU_PART_FR) return -1;
  if (s_part_req >= 0) return -2;
  s_part_req = part;
  return 0;
}

void stm32f4_qemu_plant_trace_from(const volatile float *rate_dps) { s_trace_src = rate_dps; }

uint32_t stm32f4_qemu_trace_count(void) { return s_trace_n; }

float stm32f4_qemu_trace_at(uint32_t i) { return i < s_trace_n ? s_trace[i] : 0.0f; }

const volatile hal_adc_frame_t *hal_adc_frame(void) { return &s_adc; }

CM4_RAMFUNC void hal_dac_write_frame(const hal_dac_frame_t *frame) { s_pending = *frame; }

/* The board temperature sensor (hal_board_temp.h) of the emulated board: the plant's TMP117
 * model (host_sim/plant/board_sensor.h), read as the host HAL stub reads it
 * (hal/host/hal_host.c) at the same time, the sample clock's ticks over its rate, so that
 * the host twin sees the same results at the same ticks. The product image (gyro-fw) gets
 * these functions from the board's I2C driver instead; this file is never linked into it. */
int hal_board_temp_start(void)
{
  const uint32_t cs = hal_critical_enter();
  s_temp_last = 0u;
  s_temp_started = 1;
  hal_critical_exit(cs);
  return 0;
}

/* Each result NEW once, each missed one FAULT once, NONE in between; read with the sample
 * interrupt masked (it steps the plant), a few compares long. */
hal_board_temp_event_t hal_board_temp_poll(int16_t *code)
{
  if (!s_temp_started) return HAL_BOARD_TEMP_NONE;
  int16_t c = 0;
  uint64_t n = 0u;
  hal_board_temp_event_t ev = HAL_BOARD_TEMP_NONE;
  const uint32_t cs = hal_critical_enter();
  const uint64_t k = s_plant.k; /* samples run: the sample clock's ticks plus one */
  const double t_s = k > 0u ? (double)(k - 1u) / s_plant.cfg.fs_hz : 0.0;
  const hal_board_temp_event_t got = plant_board_temp_hal(&s_plant, t_s, &c, &n);
  if (got == HAL_BOARD_TEMP_ABSENT) ev = got;
  else if ((got == HAL_BOARD_TEMP_NEW || got == HAL_BOARD_TEMP_FAULT) && n != s_temp_last) {
    s_temp_last = n;
    ev = got;
  }
  hal_critical_exit(cs);
  if (ev == HAL_BOARD_TEMP_NEW && code != 0) *code = c;
  return ev;
}
