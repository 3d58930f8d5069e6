/* Entry point of the product image gyro-fw. Built with STM32F4_QEMU (the QEMU board
 * layer) it also runs in the emulator as gyro-fw-qemu, the plant model in place of the
 * converters: no WFI, the UART drained from the loop.
 *
 *   boot: Reset_Handler (clock tree, .data/.bss/.ccm) -> main: board (pins, converter
 *   resets, DAC sequencer, UART), app_init (parameters from the flash store, or the
 *   defaults; loop design), watchdog, then the 50 kHz sample clock with app_sample_isr.
 *   background: app_poll (command line, telemetry), watchdog reload; the core sleeps
 *   until the next interrupt (at the latest the next sample tick).
 *
 * app_t lives in the core-coupled RAM: the ISR and the background loop are the only
 * users (no DMA stream reaches CCM and none needs to: the converter frames go through
 * the HAL's own SRAM buffers), and CCM has no contention with the DMA traffic of the
 * sample chain. The watchdog starts after app_init, whose init-time design (double
 * precision, libm) is not bounded by the 250 ms timeout; a parameter save reloads it
 * from the flash driver's wait loop (stm32f4_flash.c), and is refused while the drive
 * runs (param_store), so an erase never stalls a running loop.
 *
 * status gains the board's lines (board_status): tick overruns, late DAC frames, and the
 * main stack's size and high-water marks (since reset, and of the running loop alone).
 * The emulator image also has the `emu` command (main_board_emu.h). */
#include <stdint.h>

#include "app/app.h"
#include "board.h"
#include "hal/hal_sample_timer.h"
#include "hal/hal_uart.h"
#include "stm32f4_board.h"
#include "stm32f4_core.h"
#include "stm32f4_dac.h"
#include "stm32f4_iwdg.h"
#include "stm32f4_sample.h"
#include "cm4_stack.h"
#include "stm32f4_uart.h"
#ifdef STM32F4_QEMU
#include "stm32f4_qemu.h"
#endif
#ifdef STM32F4_QEMU_PLANT
#include "main_board_emu.h"
#endif

_Static_assert(STM32F4_UART_TX_BYTES >= APP_TLM_TX_RESERVE + 1024u,
               "the tuning port's TX ring holds the longest reply and some telemetry");
#define WATCHDOG_MS 250u

/* In QEMU's netduinoplus2, which maps no CCM, the emulator images' memory map
 * (linker/stm32f405_qemu.ld) puts the CCM sections at the top of its SRAM. */
static STM32F4_CCM_BSS app_t s_app;

static void say(const char *s)
{
  uint32_t n = 0u;
  while (s[n] != '\0') ++n;
  (void)hal_uart_write((const uint8_t *)s, n);
}

/* The board's lines of the status reply: sample-clock health and the main stack. */
static void board_status(cli_t *cli, void *ctx)
{
  (void)ctx;
  /* What status's isr_cycles_last / isr_cycles_max count on this image: the board's
   * DWT cycles, or, in the emulator, SysTick counts under -icount, that is instructions
   * scaled by the tick stretch (`emu`), not a core's cycles. */
#ifdef STM32F4_QEMU
  cli_put(cli, "isr_cycles_kind emulated_instructions_x_stretch");
#else
  cli_put(cli, "isr_cycles_kind dwt_cycles");
#endif
  cli_emit_data(cli);
  stm32f4_sample_stats_t st;
  stm32f4_sample_stats(&st);
  const struct {
    const char *key;
    uint32_t v;
  } rows[] = {{"tick_overruns ", st.overruns},
              {"dac_late ", stm32f4_dac_late()},
              {"stack_size_bytes ", cm4_stack_size_bytes()},
              {"stack_hwm_bytes ", cm4_stack_hwm_bytes()},
              {"stack_run_bytes ", cm4_stack_run_bytes()}};
  for (uint32_t i = 0u; i < sizeof rows / sizeof rows[0]; ++i) {
    cli_put(cli, rows[i].key);
    cli_put_u32(cli, rows[i].v);
    cli_emit_data(cli);
  }
}

int main(void)
{
  app_t *a = &s_app;
  (void)stm32f4_board_init();
  const int rc = app_init(a);

  stm32f4_iwdg_plan_t wd;
  if (stm32f4_iwdg_plan(BOARD_LSI_HZ, WATCHDOG_MS, &wd) == 0) {
    stm32f4_iwdg_start(&wd);
  }
  if (rc != 0) {
    /* Not even the defaults could be designed: there is no loop to run. Keep the
     * watchdog fed and say so; the command line is not up. */
    say("gyro-fw error: app_init failed\r\n");
    for (;;) {
#ifdef STM32F4_QEMU
      stm32f4_uart_poll_tx();
#endif
      stm32f4_iwdg_kick();
    }
  }
  a->status_board = board_status;
#ifdef STM32F4_QEMU_PLANT
  if (main_board_emu_init(a) != 0) say("gyro-fw error: emu command not registered\r\n");
#endif
  /* The init-time design is done: what the stack holds from here on is the running
   * loop's (status: stack_run_bytes; stack_hwm_bytes keeps the deepest since reset). */
  cm4_stack_mark();
  say("gyro-fw ready\r\n");
  if (hal_sample_timer_start(BOARD_SAMPLE_RATE_HZ, app_sample_isr, a) != 0) {
    say("gyro-fw error: sample clock did not start\r\n");
  }
  for (;;) {
    app_poll(a);
#ifdef STM32F4_QEMU
    stm32f4_uart_poll_tx();
    stm32f4_qemu_idle(); /* fewer register polls per emulated instruction (stm32f4_qemu.h) */
#endif
    stm32f4_iwdg_kick();
#ifndef STM32F4_QEMU
    /* Nothing to do until the next interrupt. Not in QEMU: with -icount a sleeping
     * core lets virtual time jump and QEMU's SysTick then drops periods
     * (hal/boards/ref_f405/README.md). */
    cm4_wfi();
#endif
  }
}
