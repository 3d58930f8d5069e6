#include "stm32f4_qemu_plant.h"

#include "hal/hal_adc.h"
#include "hal/hal_dac.h"
#include "plant/plant.h"
#include "stm32f4_core.h"

#ifndef STM32F4_QEMU_PLANT_SEED
#define STM32F4_QEMU_PLANT_SEED 1u
#endif
#ifndef STM32F4_QEMU_RATE_DPS
#define STM32F4_QEMU_RATE_DPS 100.0
#endif
#ifndef STM32F4_QEMU_RATE_STEP_S
#define STM32F4_QEMU_RATE_STEP_S 0.5
#endif
#define RATE_EDGE_S 0.01

/* The emulated hardware, of which there is one (as in the host HAL stub). SRAM: QEMU's
 * netduinoplus2 maps no CCM. */
static plant_t s_plant;
static plant_profiles_t s_prof;
static hal_adc_frame_t s_adc;     /* sampled at the current tick, read by the ISR */
static hal_dac_frame_t s_active;  /* on the converter outputs during this interval */
static hal_dac_frame_t s_pending; /* written by the ISR, output from the next tick */
static uint64_t s_samples;

static void midscale(hal_dac_frame_t *f)
{
  for (uint32_t i = 0u; i < HAL_DAC_NUM_CHANNELS; ++i) f->code[i] = (uint16_t)HAL_DAC_CODE_MID;
}

int stm32f4_qemu_plant_init(void)
{
  plant_cfg_t cfg;
  plant_default_cfg(&cfg);
  if (plant_init(&s_plant, &cfg, STM32F4_QEMU_PLANT_SEED) != 0) return -1;
  s_prof = s_plant.prof; /* constant ambient, no acceleration */
  const double dur_s[2] = {STM32F4_QEMU_RATE_STEP_S, 1.0};
  const double rate_dps[2] = {0.0, STM32F4_QEMU_RATE_DPS};
  if (profile_steps(&s_prof.rate_dps, 2, dur_s, rate_dps, RATE_EDGE_S, 0) != 0 ||
      plant_set_profiles(&s_plant, &s_prof) != 0) {
    return -1;
  }
  midscale(&s_active);
  midscale(&s_pending);
  s_adc.drive = 0;
  s_adc.sense = 0;
  plant_step(&s_plant, &s_active, &s_adc);
  s_samples = 1u;
  return 0;
}

void stm32f4_qemu_plant_tick(void)
{
  plant_step(&s_plant, &s_active, &s_adc);
  s_active = s_pending;
  s_samples++;
}

uint64_t stm32f4_qemu_plant_samples(void) { return s_samples; }

STM32F4_RAMFUNC void hal_adc_read_frame(hal_adc_frame_t *frame) { *frame = s_adc; }

STM32F4_RAMFUNC void hal_dac_write_frame(const hal_dac_frame_t *frame) { s_pending = *frame; }
