/* The reference board's description: every hardware fact the firmware, the parameter
 * table, the host simulator and the board's own code need, written once. The build
 * selects the board (CMake GYRO_BOARD, default ref_f405): everything that links hal_api
 * finds this file as "board.h". A new board supplies its own board.h with the same
 * names (hal/PORTING.md).
 *
 * The board: an STM32F405 (Cortex-M4F, 1 MB flash, 128 KB SRAM + 64 KB CCM), an AD7606
 * ADC on SPI1, two AD5554 DACs (SPI2: drive, rate output, sense feedback; SPI3: the sense
 * electrodes of the closed sense loop) behind x1.5 electrode driver stages, the tuning
 * port on USART1, a TMP117 board temperature sensor on I2C1 (hal/boards/ref_f405/README.md: why these parts, the timing of a tick). */
#ifndef BOARD_H
#define BOARD_H

#include <stdint.h>

/* ---- Sample clock -------------------------------------------------------------------
 * The 50 kHz tick (thesis 4.4.2): the ADC converts both pickoffs, the ISR runs the gyro,
 * the DAC latches the previous tick's frame. Made by TIM1 from the 168 MHz timer clock
 * (3360 counts); the filter designs and the parameter table (sys.fs_hz) assume it. */
#define BOARD_SAMPLE_RATE_HZ 50000u

/* ---- Converter scaling ----------------------------------------------------------------
 * The HAL's converter contract (hal/include/hal/hal_adc.h, hal/include/hal/hal_dac.h): the firmware core works in
 * volts and converts at the HAL boundary with these.
 *   ADC: AD7606, 16-bit, bipolar +-5 V (RANGE strapped low), two's complement, one
 *        code = 10 V / 65536. Drive pickoff on V1, sense pickoff on V2, both sampled by
 *        one CONVST edge.
 *   DAC: 2 x AD5554, quad 14-bit, 4-quadrant output stage on a 10 V reference, then x1.5
 *        electrode drivers: offset binary over +-15 V, one code = 30 V / 16384, the same
 *        on all eight channels. */
#define HAL_ADC_BITS 16
#define HAL_ADC_FULL_SCALE_V 5.0f /* +-5 V */
#define HAL_ADC_CODE_MAX 32767
#define HAL_ADC_CODE_MIN (-32768)
#define HAL_ADC_V_PER_CODE (HAL_ADC_FULL_SCALE_V / 32768.0f)

#define HAL_DAC_BITS 14
#define HAL_DAC_FULL_SCALE_V 15.0f /* +-15 V */
#define HAL_DAC_CODE_MAX 16383u
#define HAL_DAC_CODE_MID 8192u
#define HAL_DAC_V_PER_CODE (2.0f * HAL_DAC_FULL_SCALE_V / 16384.0f)

/* ---- Clocks ---------------------------------------------------------------------------
 * 8 MHz crystal -> PLL (M 4, N 168, P 2, Q 7) -> 168 MHz SYSCLK = HCLK; APB1 /4 = 42 MHz,
 * APB2 /2 = 84 MHz, timers on both buses at twice their bus clock (84 / 168 MHz);
 * 5 flash wait states; the planner (stm32f4_clock.h) derives all of it from these two. */
#define BOARD_HSE_HZ 8000000u
#define BOARD_SYSCLK_HZ 168000000u
#define BOARD_LSI_HZ 32000u /* the watchdog's RC clock, +-50 % over the part */

/* ---- Tuning port ----------------------------------------------------------------------
 * USART1 on PB6/PB7, 8N1 (BRR 0x5B from PCLK2 84 MHz: +0.16 %). The telemetry budget of
 * the application (app_tlm.h) is computed for this rate. */
#define BOARD_UART_BAUD 921600u

/* ---- Board temperature sensor ---------------------------------------------------------
 * TI TMP117 (SNOSD82D) on I2C1, PB8/PB9, 400 kHz, address 0x48 (ADD0 to GND): 16-bit
 * two's complement, 7.8125 mdegC per LSB (7.3.3); +-0.1 degC over -20..50 degC, +-0.2
 * over -40..100 degC (6.5); its factory cycle, eight averages every 1 s (7.4), untouched.
 * hal/include/hal/hal_board_temp.h. */
#define BOARD_TEMP_LSB_C 0.0078125f
#define BOARD_TEMP_CYCLE_S 1.0f
#define BOARD_TEMP_I2C_ADDR 0x48u

/* ---- Pins -----------------------------------------------------------------------------
 * (alternate functions from the STM32F405 data sheet, table 9; set up by
 * stm32f4_board_init, the sample chain by stm32f4_sample.c / stm32f4_dac.c)
 *
 *   pin   function         AF  direction  purpose
 *   PA8   TIM1_CH1         1   out        ADC CONVST A+B: its rising edge is the sample instant
 *   PA9   TIM1_CH2         1   out        DAC LDAC (both AD5554): latches all eight words at once
 *   PA10  TIM1_CH3         1   out        ADC CS: frames the 32-clock read of V1, V2
 *   PA5   SPI1_SCK         5   out        ADC SCLK (10.5 MHz)
 *   PA6   SPI1_MISO        5   in         ADC DOUTA (V1 drive pickoff, V2 sense pickoff)
 *   PC6   TIM8_CH1         3   out        DAC CS (both AD5554): one slot per word pair
 *   PB13  SPI2_SCK         5   out        DAC A CLK (21 MHz): drive, rate out, feedback U3
 *   PB15  SPI2_MOSI        5   out        DAC A SDI
 *   PC10  SPI3_SCK         6   out        DAC B CLK (21 MHz): feedback U4, nulling, tuning
 *   PC12  SPI3_MOSI        6   out        DAC B SDI
 *   PB0   GPIO             -   out        ADC RESET (pulsed high at start-up)
 *   PB1   GPIO             -   out        DAC RS (both), low = reset to mid-scale (0 V)
 *   PC7   GPIO             -   in         ADC BUSY (diagnostics only)
 *   PB6   USART1_TX        7   out        tuning port TX
 *   PB7   USART1_RX        7   in         tuning port RX (pull-up)
 *   PB8   I2C1_SCL         4   open-drain board temperature sensor (TMP117), 4.7 k pull-up
 *   PB9   I2C1_SDA         4   open-drain board temperature sensor (TMP117), 4.7 k pull-up
 *
 * Strapped on the board: AD7606 PAR/SER/BYTE SEL high (serial), RANGE low (+-5 V),
 * OS[2:0] = 000 (no oversampling); both AD5554 MSB high (RS resets to mid-scale = 0 V). */

#endif /* BOARD_H */
