/* Non-blocking I2C master on the STM32F4's I2C v1 peripheral (RM0090 §27), register
 * level, for the background loop: a transfer (a write of up to STM32F4_I2C_TX_MAX bytes,
 * then, after a repeated START, a read of up to STM32F4_I2C_RX_MAX bytes) is started by
 * stm32f4_i2c_begin and advanced by stm32f4_i2c_poll, which does only what the status
 * register says is ready (START sent, address acknowledged, data register empty or full,
 * byte transfer finished) and returns at once. No interrupt, no DMA, no wait loop.
 *
 * A NACK, a bus error, a lost arbitration, an overrun, or a transfer that has not ended
 * timeout_cycles after it began (a stuck bus: no START ever sent, a line held low) ends
 * the transfer with an error; the driver then resets the peripheral (CR1.SWRST) and
 * programs it again, so the next transfer starts from a clean peripheral.
 *
 * The caller owns the state (stm32f4_i2c_master_t) and supplies the time: now_cycles
 * from any free-running 32-bit counter (the board passes hal_cycles_now()). */
#ifndef STM32F4_I2C_H
#define STM32F4_I2C_H

#include <stdint.h>

#include "stm32f4_regs.h"

#define STM32F4_I2C_TX_MAX 4u
#define STM32F4_I2C_RX_MAX 2u /* RM0090 §27.3.3: the 1-byte and the 2-byte (POS) reads */

typedef enum {
  STM32F4_I2C_IDLE = 0,        /* no transfer */
  STM32F4_I2C_BUSY = 1,        /* under way: poll again */
  STM32F4_I2C_DONE = 2,        /* finished; stm32f4_i2c_rx holds what was read */
  STM32F4_I2C_ERR_NACK = -1,   /* address or data byte not acknowledged (SR1.AF) */
  STM32F4_I2C_ERR_BUS = -2,    /* misplaced START/STOP (BERR), lost arbitration, overrun */
  STM32F4_I2C_ERR_TIMEOUT = -3 /* not finished within timeout_cycles */
} stm32f4_i2c_status_t;

/* The peripheral's clock registers for one bus rate (RM0090 §27.6.2, §27.6.8-9). */
typedef struct {
  uint32_t cr2_freq; /* CR2.FREQ: PCLK1 in MHz */
  uint32_t ccr;      /* CCR with F/S and DUTY */
  uint32_t trise;    /* TRISE: the longest SCL rise in PCLK1 periods, + 1 */
} stm32f4_i2c_timing_t;

typedef struct {
  stm32f4_i2c_t *regs;
  uint32_t rcc_apb1enr_bit; /* the peripheral's clock enable in RCC_APB1ENR */
  uint32_t pclk1_hz;
  uint32_t scl_hz;         /* <= 100 kHz: standard mode; <= 400 kHz: fast mode */
  uint32_t timeout_cycles; /* longest transfer, in now_cycles counts */
} stm32f4_i2c_config_t;

typedef struct {
  stm32f4_i2c_config_t cfg;
  stm32f4_i2c_timing_t timing;
  uint32_t state; /* the transfer's step (stm32f4_i2c.c) */
  uint32_t t_begin;
  uint8_t addr7;
  uint8_t tx[STM32F4_I2C_TX_MAX];
  uint8_t rx[STM32F4_I2C_RX_MAX];
  uint8_t tx_len, tx_done, rx_len;
  uint32_t resets; /* peripheral resets after errors, since init */
} stm32f4_i2c_master_t;

/* The clock registers for scl_hz from pclk1_hz: standard mode (<= 100 kHz: Thigh = Tlow
 * = CCR periods, rise <= 1000 ns) or fast mode with DUTY 0 (<= 400 kHz: Tlow = 2 Thigh,
 * Thigh = CCR periods, rise <= 300 ns), the CCR rounded up so the bus is never faster than
 * asked. Returns 0, or -1 if the rate cannot be made (PCLK1 not 2..42 MHz, or under
 * 4 MHz in fast mode; scl_hz 0 or above 400 kHz; CCR out of range). */
int stm32f4_i2c_timing(uint32_t pclk1_hz, uint32_t scl_hz, stm32f4_i2c_timing_t *t);

/* Enable the peripheral's clock, reset it and program it as a master at cfg->scl_hz.
 * Returns 0, or -1 if the rate cannot be made (the peripheral is then left off). */
int stm32f4_i2c_init(stm32f4_i2c_master_t *m, const stm32f4_i2c_config_t *cfg);

/* Start a transfer with the 7-bit address addr7: write tx_len bytes, then read rx_len
 * (a repeated START between the two; either may be 0, not both). Nothing waits: the
 * START goes out from stm32f4_i2c_poll once the bus is free. Returns 0, or -1 if a
 * transfer is under way or the lengths are out of range. */
int stm32f4_i2c_begin(stm32f4_i2c_master_t *m, uint8_t addr7, const uint8_t *tx,
                      uint32_t tx_len, uint32_t rx_len, uint32_t now_cycles);

/* Advance the transfer by what the peripheral has ready now. BUSY while it runs; DONE
 * once (then IDLE); an error once, after the peripheral has been reset. */
stm32f4_i2c_status_t stm32f4_i2c_poll(stm32f4_i2c_master_t *m, uint32_t now_cycles);

/* The bytes read by the last finished transfer (rx_len of them). */
const uint8_t *stm32f4_i2c_rx(const stm32f4_i2c_master_t *m);

#endif /* STM32F4_I2C_H */
