/* fw_qemu_twin: the host twin of the emulator image gyro-fw-qemu, for the equivalence
 * test (tests/qemu/test_fw_qemu.py equiv). The same application (app_init_with the
 * default part's calibration, which the image holds as its factory parameter store,
 * stm32f4_qemu_flash.c; app_sample_isr) and the same plant configuration
 * (qemu_plant_setup: default plant, seed, rate step) with the same converter timing,
 * here through the host HAL stub (hal/host/hal_host.h), whose tick order is that of the
 * emulator's SysTick handler (ISR, then the plant step with the previous tick's DAC
 * frame). Prints the rate output every QEMU_TRACE_EVERY ticks from the first tick of the
 * sample clock, QEMU_TRACE_LEN lines "I VALUE" (VALUE: %.9g, exact for a float), as the
 * image's `emu trace` does, then "mode M" (the gyro mode at the end).
 *
 *   fw_qemu_twin
 */
#include <stdio.h>

#include "app/app.h"
#include "hal/hal_sample_timer.h"
#include "hal_host.h"
#include "paramset/param_set.h"
#include "plant/plant.h"
#include "qemu_plant_setup.h"

static plant_t plant;
static plant_profiles_t prof;
static app_t app;

int main(void)
{
  if (qemu_plant_setup(&plant, &prof) != 0) {
    fprintf(stderr, "fw_qemu_twin: plant: %s\n", plant_error(&plant));
    return 1;
  }
  hal_host_attach(plant_step_hal, &plant);
  hal_host_attach_board_temp(plant_board_temp_hal, &plant); /* the image's board sensor */
  param_values_t v;
  param_values_defaults(&v);
  char err[256];
  if (param_set_load_file(GYRO_DEFAULT_PART_CAL, &v, NULL, err, sizeof err) != 0) {
    fprintf(stderr, "fw_qemu_twin: %s\n", err);
    return 1;
  }
  if (app_init_with(&app, &v) != 0) {
    fprintf(stderr, "fw_qemu_twin: app_init failed\n");
    return 1;
  }
  if (hal_sample_timer_start(params_current(&app.params)->sys_fs_hz, app_sample_isr, &app) != 0) {
    fprintf(stderr, "fw_qemu_twin: sample clock refused\n");
    return 1;
  }
  for (unsigned i = 0; i < QEMU_TRACE_LEN; ++i) {
    if (hal_host_run(QEMU_TRACE_EVERY) != QEMU_TRACE_EVERY) return 1;
    printf("%u %.9g\n", i, (double)app.gyro.out.rate_dps);
  }
  printf("mode %d\n", (int)app.gyro.sup.mode);
  return 0;
}
