#include "stm32f4_board_temp.h"

#include "board.h"
#include "hal/hal_sample_timer.h"
#include "stm32f4_board.h"
#include "stm32f4_gpio.h"
#include "stm32f4_i2c.h"

/* The driver's steps. OFF (never started) and ABSENT answer every poll with ABSENT. */
enum { BT_OFF = 0, BT_ABSENT, BT_WAIT, BT_READ_ID, BT_READ_CONFIG, BT_READ_TEMP };

static stm32f4_i2c_master_t s_bus;
static uint32_t s_state;
static uint32_t s_last_cycles;  /* when the last check began */
static uint32_t s_wait_cycles;  /* from then to the next: a check, or a retry after a fault */
static uint32_t s_check_cycles; /* STM32F4_BOARD_TEMP_CHECK_MS */
static uint32_t s_retry_cycles; /* STM32F4_BOARD_TEMP_RETRY_MS */
static uint32_t s_faults;
static uint32_t s_identified; /* the Device ID read back right since the last fault */

int stm32f4_board_temp_start_at(uint32_t pclk1_hz, uint32_t cycles_hz)
{
  s_state = BT_ABSENT;
  s_faults = 0u;
  s_identified = 0u;
  const uint32_t cycles_per_ms = cycles_hz / 1000u;
  if (cycles_per_ms == 0u) return -1;
  const stm32f4_i2c_config_t cfg = {
      .regs = I2C1,
      .rcc_apb1enr_bit = RCC_APB1ENR_I2C1EN,
      .pclk1_hz = pclk1_hz,
      .scl_hz = STM32F4_BOARD_TEMP_SCL_HZ,
      .timeout_cycles = cycles_per_ms * (STM32F4_BOARD_TEMP_XFER_TIMEOUT_US / 1000u)};
  /* The peripheral first (enabled, lines released), then the pins handed to it, so the
   * bus sees no glitch. Open drain: the I2C lines are wired-AND, nothing may drive them
   * high; the board's resistors pull them up. */
  if (stm32f4_i2c_init(&s_bus, &cfg) != 0) return -1;
  RCC->AHB1ENR |= RCC_AHB1ENR_GPIOBEN;
  stm32f4_gpio_config_open_drain(GPIOB, 8u, 4u); /* I2C1_SCL */
  stm32f4_gpio_config_open_drain(GPIOB, 9u, 4u); /* I2C1_SDA */
  s_check_cycles = cycles_per_ms * STM32F4_BOARD_TEMP_CHECK_MS;
  s_retry_cycles = cycles_per_ms * STM32F4_BOARD_TEMP_RETRY_MS;
  s_wait_cycles = 0u; /* the first check (the Device ID) at the first poll */
  s_last_cycles = hal_cycles_now();
  s_state = BT_WAIT;
  return 0;
}

int hal_board_temp_start(void)
{
  const stm32f4_board_info_t *b = stm32f4_board_info();
  return stm32f4_board_temp_start_at(b->clock.pclk1_hz, b->clock.hclk_hz);
}

uint32_t stm32f4_board_temp_faults(void) { return s_faults; }

/* A register read: the pointer byte written, then (repeated START) its two bytes, MSB
 * first (SNOSD82D 7.5.3.1.3). */
static int read_reg(uint8_t reg, uint32_t next_state, uint32_t now)
{
  if (stm32f4_i2c_begin(&s_bus, BOARD_TEMP_I2C_ADDR, &reg, 1u, 2u, now) != 0) return -1;
  s_state = next_state;
  return 0;
}

static hal_board_temp_event_t fault(uint32_t now)
{
  ++s_faults;
  s_identified = 0u; /* whatever answers after a fault is identified again */
  s_state = BT_WAIT;
  s_last_cycles = now;
  s_wait_cycles = s_retry_cycles;
  return HAL_BOARD_TEMP_FAULT;
}

static hal_board_temp_event_t wait_next(uint32_t now, uint32_t wait)
{
  s_state = BT_WAIT;
  s_last_cycles = now;
  s_wait_cycles = wait;
  return HAL_BOARD_TEMP_NONE;
}

/* Data_Ready is cleared by the read of the Configuration register that reports it
 * (and by a read of the result; SNOSD82D 7.6, Configuration register): a set flag is
 * seen once per conversion, so each result is returned once. */
static hal_board_temp_event_t on_read(int16_t *code, uint32_t value, uint32_t now)
{
  switch (s_state) {
  case BT_READ_ID:
    if (value != STM32F4_BOARD_TEMP_DEVICE_ID) {
      s_state = BT_ABSENT; /* another part at the address: not ours to read */
      return HAL_BOARD_TEMP_ABSENT;
    }
    s_identified = 1u;
    return read_reg(TMP117_REG_CONFIG, BT_READ_CONFIG, now) == 0 ? HAL_BOARD_TEMP_NONE
                                                                 : fault(now);
  case BT_READ_CONFIG:
    if ((value & TMP117_CONFIG_DATA_READY) == 0u) return wait_next(now, s_check_cycles);
    return read_reg(TMP117_REG_TEMP, BT_READ_TEMP, now) == 0 ? HAL_BOARD_TEMP_NONE : fault(now);
  default: /* BT_READ_TEMP: 16-bit two's complement, BOARD_TEMP_LSB_C per LSB (7.3.3) */
    *code = (int16_t)(value >= 0x8000u ? (int32_t)value - 65536 : (int32_t)value);
    (void)wait_next(s_last_cycles, s_check_cycles); /* the 50 ms run from the check */
    return HAL_BOARD_TEMP_NEW;
  }
}

hal_board_temp_event_t hal_board_temp_poll(int16_t *code)
{
  if (s_state == BT_OFF || s_state == BT_ABSENT) return HAL_BOARD_TEMP_ABSENT;
  const uint32_t now = hal_cycles_now();
  if (s_state == BT_WAIT) {
    /* Unsigned difference: exact across the cycle counter's wrap (25.6 s at 168 MHz). */
    if (now - s_last_cycles < s_wait_cycles) return HAL_BOARD_TEMP_NONE;
    s_last_cycles = now;
    const uint8_t reg = s_identified != 0u ? TMP117_REG_CONFIG : TMP117_REG_DEVICE_ID;
    const uint32_t next = s_identified != 0u ? BT_READ_CONFIG : BT_READ_ID;
    return read_reg(reg, next, now) == 0 ? HAL_BOARD_TEMP_NONE : fault(now);
  }
  const stm32f4_i2c_status_t st = stm32f4_i2c_poll(&s_bus, now);
  if (st == STM32F4_I2C_BUSY) return HAL_BOARD_TEMP_NONE;
  if (st != STM32F4_I2C_DONE) return fault(now);
  const uint8_t *rx = stm32f4_i2c_rx(&s_bus);
  const uint32_t value = ((uint32_t)rx[0] << 8) | rx[1];
  int16_t dummy;
  return on_read(code != 0 ? code : &dummy, value, now);
}
