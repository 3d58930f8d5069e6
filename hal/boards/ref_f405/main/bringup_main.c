/* gyro-bringup: the board engineer's first image. It brings up the clock tree, starts
 * the 50 kHz sample chain with an ISR that reads the ADC frame and writes a DAC frame
 * through the HAL (exactly the product's ISR path, minus the gyro), counts ticks and
 * measures its own worst-case cycles and the tick period with the DWT counter, and
 * answers one-line commands on the tuning port (921600 8N1):
 *
 *   stat         ticks, ISR cycles (last/worst), tick period min/max in cycles,
 *                overruns, DMA errors, dropped UART bytes, uptime
 *   clear        reset the worst-case and period statistics
 *   adc          last ADC frame (codes)
 *   dac A B C D [E F G H]
 *                DAC codes (0..16383, mid-scale 8192 = 0 V) written at every tick: the
 *                first converter's four channels, then optionally the second's (the
 *                sense electrodes, hal_dac.h; mid-scale when left out)
 *   clk          clock status, frequencies and the reset cause
 *   fault        the fault record kept across the last reset ("fault clear" erases it)
 *   temp         the board temperature sensor (TMP117 on I2C1; not in QEMU): its state,
 *                the last result (code and mdegC), results and faults counted; the
 *                background loop reads it (hal_board_temp_poll), never the ISR
 *   crash        execute an undefined instruction (tests the fault record path)
 *   reset        software reset
 *
 * The same file builds gyro-bringup-qemu (STM32F4_QEMU): there the sample clock is
 * SysTick and the converters are a loopback (hal/boards/ref_f405/qemu). */
#include <stddef.h>
#include <stdint.h>

#include "hal/hal_adc.h"
#include "hal/hal_board_temp.h"
#include "hal/hal_critical.h"
#include "hal/hal_dac.h"
#include "board.h"
#include "hal/hal_sample_timer.h"
#include "hal/hal_uart.h"
#include "stm32f4_board.h"
#include "stm32f4_core.h"
#include "stm32f4_dac.h"
#include "cm4_fault.h"
#include "stm32f4_iwdg.h"
#include "stm32f4_sample.h"
#include "stm32f4_uptime.h"
#include "stm32f4_uart.h"

#define LINE_MAX 64u
#define WATCHDOG_MS 250u

typedef struct {
  /* written by the ISR */
  volatile uint32_t ticks;
  volatile uint32_t last_cycles;
  volatile uint32_t worst_cycles;
  volatile uint32_t period_min;
  volatile uint32_t period_max;
  uint32_t prev_entry;
  const volatile hal_adc_frame_t *adc_in; /* the HAL's frame (hal_adc_frame), set at start */
  hal_adc_frame_t adc;
  /* written by the background loop inside a critical section */
  hal_dac_frame_t dac;
  volatile uint32_t clear_request;
  /* background only */
  char line[LINE_MAX];
  uint32_t line_len;
  hal_board_temp_event_t temp_last; /* the last event other than NONE */
  int16_t temp_code;
  uint32_t temp_results, temp_faults;
} bringup_t;

static bringup_t s_bringup;

static CM4_RAMFUNC void bringup_isr(void *ctx)
{
  bringup_t *b = (bringup_t *)ctx;
  const uint32_t t0 = hal_cycles_now();
  if (b->ticks > 0u && b->clear_request == 0u) {
    const uint32_t period = t0 - b->prev_entry;
    if (period < b->period_min) b->period_min = period;
    if (period > b->period_max) b->period_max = period;
  }
  b->prev_entry = t0;
  b->adc.drive = b->adc_in->drive;
  b->adc.sense = b->adc_in->sense;
  hal_dac_write_frame(&b->dac);
  b->ticks = b->ticks + 1u;
  const uint32_t dt = hal_cycles_now() - t0;
  b->last_cycles = dt;
  if (b->clear_request != 0u) {
    b->worst_cycles = dt;
    b->period_min = 0xFFFFFFFFu;
    b->period_max = 0u;
    b->clear_request = 0u;
  } else if (dt > b->worst_cycles) {
    b->worst_cycles = dt;
  }
}

/* ---- output: fixed-size line, no stdio (nothing here may allocate) ---- */
typedef struct {
  char buf[160];
  size_t len;
} out_t;

static void out_str(out_t *o, const char *s)
{
  while (*s != '\0' && o->len < sizeof(o->buf)) o->buf[o->len++] = *s++;
}

static void out_u32(out_t *o, uint32_t v)
{
  char tmp[10];
  size_t n = 0u;
  do {
    tmp[n++] = (char)('0' + (char)(v % 10u));
    v /= 10u;
  } while (v != 0u);
  while (n > 0u && o->len < sizeof(o->buf)) o->buf[o->len++] = tmp[--n];
}

static void out_i32(out_t *o, int32_t v)
{
  if (v < 0) {
    out_str(o, "-");
    out_u32(o, (uint32_t)(-(v + 1)) + 1u);
  } else {
    out_u32(o, (uint32_t)v);
  }
}

static void out_hex(out_t *o, uint32_t v)
{
  static const char digits[] = "0123456789abcdef";
  out_str(o, "0x");
  for (int shift = 28; shift >= 0; shift -= 4) {
    if (o->len < sizeof(o->buf)) o->buf[o->len++] = digits[(v >> (uint32_t)shift) & 0xFu];
  }
}

static void out_kv(out_t *o, const char *key, uint32_t v)
{
  out_str(o, " ");
  out_str(o, key);
  out_str(o, "=");
  out_u32(o, v);
}

static void out_kx(out_t *o, const char *key, uint32_t v)
{
  out_str(o, " ");
  out_str(o, key);
  out_str(o, "=");
  out_hex(o, v);
}

/* Send the line; waits for TX ring space (background only, the ISR keeps running). */
static void out_send(out_t *o)
{
  out_str(o, "\r\n");
  size_t sent = 0u;
  while (sent < o->len) {
    sent += hal_uart_write((const uint8_t *)o->buf + sent, o->len - sent);
#ifdef STM32F4_QEMU
    stm32f4_uart_poll_tx();
#endif
    stm32f4_iwdg_kick();
  }
  o->len = 0u;
}

/* ---- commands ---- */
static int starts_with(const char *s, const char *prefix)
{
  while (*prefix != '\0') {
    if (*s++ != *prefix++) return 0;
  }
  return *s == '\0' || *s == ' ';
}

static const char *parse_u32(const char *s, uint32_t *v)
{
  while (*s == ' ') ++s;
  if (*s < '0' || *s > '9') return 0;
  uint32_t acc = 0u;
  while (*s >= '0' && *s <= '9') {
    const uint32_t d = (uint32_t)(*s - '0');
    if (acc > (0xFFFFFFFFu - d) / 10u) return 0;
    acc = acc * 10u + d;
    ++s;
  }
  *v = acc;
  return s;
}

static void cmd_stat(bringup_t *b, out_t *o)
{
  stm32f4_sample_stats_t st;
  stm32f4_sample_stats(&st);
  out_str(o, "stat");
  out_kv(o, "ticks", b->ticks);
  out_kv(o, "last_cyc", b->last_cycles);
  out_kv(o, "worst_cyc", b->worst_cycles);
  out_kv(o, "period_min", b->period_min);
  out_kv(o, "period_max", b->period_max);
  out_kv(o, "overruns", st.overruns);
  out_kv(o, "dac_late", stm32f4_dac_late());
  out_kv(o, "dma_err", st.dma_errors);
  out_kv(o, "uart_drop", stm32f4_uart_rx_dropped() + stm32f4_uart_rx_overruns());
  out_kv(o, "uptime_us", stm32f4_uptime_us());
}

static void cmd_fault(out_t *o, const char *args)
{
  while (*args == ' ') ++args;
  if (starts_with(args, "clear")) {
    cm4_fault_clear();
    out_str(o, "fault cleared");
    return;
  }
  cm4_fault_record_t r;
  if (!cm4_fault_get(&r)) {
    out_str(o, "fault none");
    return;
  }
  out_str(o, "fault");
  out_kv(o, "n", r.count);
  out_kv(o, "exc", r.exc_number);
  out_kx(o, "pc", r.pc);
  out_kx(o, "lr", r.lr);
  out_kx(o, "xpsr", r.xpsr);
  out_kx(o, "cfsr", r.cfsr);
  out_kx(o, "hfsr", r.hfsr);
  out_kx(o, "mmfar", r.mmfar);
  out_kx(o, "bfar", r.bfar);
}

/* 1 when nothing but spaces is left. */
static int at_end(const char *s)
{
  while (*s == ' ') ++s;
  return *s == '\0';
}

static void cmd_dac(bringup_t *b, out_t *o, const char *args)
{
  hal_dac_frame_t f;
  hal_dac_frame_midscale(&f);
  const char *p = args;
  for (uint32_t ch = 0u; ch < HAL_DAC_NUM_CHANNELS; ++ch) {
    if (ch == 4u && at_end(p)) break; /* the second converter's codes are optional */
    uint32_t v = 0u;
    p = (p != 0) ? parse_u32(p, &v) : 0;
    if (p == 0 || v > HAL_DAC_CODE_MAX) {
      out_str(o, "error: dac A B C D [E F G H], codes 0..16383");
      return;
    }
    f.code[ch] = (uint16_t)v;
  }
  if (!at_end(p)) {
    out_str(o, "error: dac A B C D [E F G H], codes 0..16383");
    return;
  }
  const uint32_t cs = hal_critical_enter();
  b->dac = f;
  hal_critical_exit(cs);
  out_str(o, "dac ok");
}

static void cmd_clk(out_t *o)
{
  const stm32f4_board_info_t *info = stm32f4_board_info();
  out_str(o, "clk");
  out_kv(o, "status", (uint32_t)(-(int32_t)info->clock_status));
  out_kv(o, "sysclk", info->clock.sysclk_hz);
  out_kv(o, "pclk1", info->clock.pclk1_hz);
  out_kv(o, "pclk2", info->clock.pclk2_hz);
  out_kx(o, "reset_flags", info->reset_flags);
}

#ifndef STM32F4_QEMU
static void poll_temp(bringup_t *b)
{
  int16_t code;
  const hal_board_temp_event_t ev = hal_board_temp_poll(&code);
  if (ev == HAL_BOARD_TEMP_NONE) return;
  b->temp_last = ev;
  if (ev == HAL_BOARD_TEMP_NEW) {
    b->temp_code = code;
    ++b->temp_results;
  } else if (ev == HAL_BOARD_TEMP_FAULT) {
    ++b->temp_faults;
  }
}

/* mdegC = code x 7.8125 = code x 125 / 16 (BOARD_TEMP_LSB_C), in integers. */
static void cmd_temp(const bringup_t *b, out_t *o)
{
  static const char *const names[] = {"none", "ok", "fault", "absent"};
  out_str(o, "temp state=");
  out_str(o, names[(uint32_t)b->temp_last & 3u]);
  out_str(o, " code=");
  out_i32(o, b->temp_code);
  out_str(o, " mdegc=");
  out_i32(o, (int32_t)b->temp_code * 125 / 16);
  out_kv(o, "results", b->temp_results);
  out_kv(o, "faults", b->temp_faults);
}
#endif

static void run_command(bringup_t *b, const char *line, out_t *o)
{
  if (starts_with(line, "stat")) {
    cmd_stat(b, o);
  } else if (starts_with(line, "clear")) {
    b->clear_request = 1u;
    out_str(o, "cleared");
  } else if (starts_with(line, "adc")) {
    const uint32_t cs = hal_critical_enter();
    const hal_adc_frame_t f = b->adc;
    hal_critical_exit(cs);
    out_str(o, "adc drive=");
    out_i32(o, f.drive);
    out_str(o, " sense=");
    out_i32(o, f.sense);
  } else if (starts_with(line, "dac")) {
    cmd_dac(b, o, line + 3);
  } else if (starts_with(line, "clk")) {
    cmd_clk(o);
  } else if (starts_with(line, "fault")) {
    cmd_fault(o, line + 5);
#ifndef STM32F4_QEMU
  } else if (starts_with(line, "temp")) {
    cmd_temp(b, o);
#endif
  } else if (starts_with(line, "crash")) {
    __builtin_trap();
  } else if (starts_with(line, "reset")) {
    cm4_system_reset();
  } else if (starts_with(line, "help") || line[0] == '\0') {
#ifdef STM32F4_QEMU
    out_str(o, "commands: stat clear adc dac clk fault crash reset");
#else
    out_str(o, "commands: stat clear adc dac clk fault temp crash reset");
#endif
  } else {
    out_str(o, "error: unknown command (help)");
  }
}

static void poll_uart(bringup_t *b)
{
  uint8_t rx[16];
  const size_t n = hal_uart_read(rx, sizeof(rx));
  for (size_t i = 0u; i < n; ++i) {
    const char c = (char)rx[i];
    if (c == '\r' || c == '\n') {
      if (b->line_len == 0u && c == '\n') continue;
      b->line[b->line_len] = '\0';
      out_t o;
      o.len = 0u;
      run_command(b, b->line, &o);
      out_send(&o);
      b->line_len = 0u;
    } else if (b->line_len + 1u < LINE_MAX) {
      b->line[b->line_len++] = c;
    }
  }
}

int main(void)
{
  bringup_t *b = &s_bringup;
  hal_dac_frame_midscale(&b->dac);
  b->adc_in = hal_adc_frame();
  b->period_min = 0xFFFFFFFFu;
  (void)stm32f4_board_init();
  stm32f4_uptime_init();
#ifndef STM32F4_QEMU
  b->temp_last = hal_board_temp_start() == 0 ? HAL_BOARD_TEMP_NONE : HAL_BOARD_TEMP_ABSENT;
#endif

  stm32f4_iwdg_plan_t wd;
  if (stm32f4_iwdg_plan(BOARD_LSI_HZ, WATCHDOG_MS, &wd) == 0) {
    stm32f4_iwdg_start(&wd);
  }

  out_t o;
  o.len = 0u;
  out_str(&o, "gyro-bringup ready");
  out_send(&o);
  if (hal_sample_timer_start(BOARD_SAMPLE_RATE_HZ, bringup_isr, b) != 0) {
    out_str(&o, "error: sample clock did not start");
    out_send(&o);
  }
  for (;;) {
    poll_uart(b);
#ifdef STM32F4_QEMU
    stm32f4_uart_poll_tx();
#else
    poll_temp(b);
#endif
    stm32f4_iwdg_kick();
#ifndef STM32F4_QEMU
    /* Sleep until the next interrupt (the sample tick at the latest): the background
     * loop has nothing to do in between. Not in QEMU: with -icount, a sleeping core
     * lets virtual time jump, and QEMU's SysTick model then drops periods. */
    cm4_wfi();
#endif
  }
}
