/* The board temperature sensor (hal_board_temp.h) on the reference board: a TI TMP117
 * (SNOSD82D) at BOARD_TEMP_I2C_ADDR on I2C1 (PB8 SCL, PB9 SDA, AF4, open drain with the
 * board's 4.7 k pull-ups), 400 kHz, through the family's non-blocking master
 * (stm32f4_i2c.h), from the background loop only.
 *
 * The sensor keeps its factory setting (continuous conversion, 8 averages, a 1 s cycle;
 * 7.4), so the driver writes nothing to it. It reads the Device ID once after start and
 * after every bus fault (0x0117, 7.6: another part at the address is ABSENT), then, no
 * more often than every STM32F4_BOARD_TEMP_CHECK_MS, the Configuration register for
 * Data_Ready, and when it is set the temperature result. */
#ifndef STM32F4_BOARD_TEMP_H
#define STM32F4_BOARD_TEMP_H

#include <stdint.h>

#include "hal/hal_board_temp.h"

#define STM32F4_BOARD_TEMP_SCL_HZ 400000u
#define STM32F4_BOARD_TEMP_CHECK_MS 50u   /* Data_Ready checks: 20 a second, 20 a cycle */
#define STM32F4_BOARD_TEMP_RETRY_MS 1000u /* after a fault: one try per sensor cycle */
#define STM32F4_BOARD_TEMP_XFER_TIMEOUT_US 10000u /* a transfer takes ~0.12 ms on the wire */
#define STM32F4_BOARD_TEMP_DEVICE_ID 0x0117u

/* TMP117 registers (SNOSD82D 7.6) and the Data_Ready flag (Configuration bit 13). */
#define TMP117_REG_TEMP 0x00u
#define TMP117_REG_CONFIG 0x01u
#define TMP117_REG_DEVICE_ID 0x0Fu
#define TMP117_CONFIG_DATA_READY (1u << 13)

/* hal_board_temp_start with the clocks given: PCLK1 (the I2C's kernel clock) and the
 * rate of hal_cycles_now (HCLK). hal_board_temp_start passes the board's clocks in force
 * (stm32f4_board_info); the host tests pass their own. 0, or -1 (then ABSENT). */
int stm32f4_board_temp_start_at(uint32_t pclk1_hz, uint32_t cycles_hz);

/* Bus faults since start (each one reset the peripheral). */
uint32_t stm32f4_board_temp_faults(void);

#endif /* STM32F4_BOARD_TEMP_H */
