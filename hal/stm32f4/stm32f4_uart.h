/* Tuning port on USART1 (PB6 TX, PB7 RX, 8N1): interrupt-driven RX and TX rings behind
 * hal_uart.h. RX: every received byte goes into the RX ring from the USART1 interrupt;
 * a full ring drops the byte and counts it. TX: hal_uart_write queues bytes and enables
 * the TXE interrupt, which feeds the data register until the ring is empty. The line
 * rate is the board's (board.h: BOARD_UART_BAUD). */
#ifndef STM32F4_UART_H
#define STM32F4_UART_H

#include <stdint.h>

#define STM32F4_UART_RX_BYTES 256u
#define STM32F4_UART_TX_BYTES 16384u /* the longest reply (list, ~8.3 KB) beside telemetry */

/* BRR for 16x oversampling: USARTDIV = f_pclk / (16 baud), mantissa = integer part,
 * fraction = 16ths rounded, i.e. BRR = round(f_pclk / baud) (RM0090 §30.3.4).
 * Returns 0 if the baud rate cannot be made (BRR < 16 or > 0xFFFF). */
uint32_t stm32f4_usart_brr(uint32_t pclk_hz, uint32_t baud);

/* Configure USART1 for baud at pclk_hz, empty both rings, enable the RX interrupt at
 * STM32F4_PRIO_UART. Returns 0, or -1 if the baud rate cannot be made. */
int stm32f4_uart_init(uint32_t pclk_hz, uint32_t baud);

/* Bytes lost: RX ring full, and receiver overruns (a byte arrived before DR was read). */
uint32_t stm32f4_uart_rx_dropped(void);
uint32_t stm32f4_uart_rx_overruns(void);

/* Feed the data register from the TX ring outside the interrupt (emulator builds: the
 * QEMU USART model raises no TXE interrupt). Harmless on the board. */
void stm32f4_uart_poll_tx(void);

void USART1_IRQHandler(void);

#endif /* STM32F4_UART_H */
