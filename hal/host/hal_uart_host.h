/* Host UART stub: the board's interrupt-driven RX/TX rings, filled and drained by the
 * host program (a pseudo-terminal bridge in gyro-sim, or a test). */
#ifndef HAL_UART_HOST_H
#define HAL_UART_HOST_H

#include <stddef.h>
#include <stdint.h>

#define HAL_UART_HOST_RX_SIZE 1024u
#define HAL_UART_HOST_TX_SIZE 16384u

/* Bytes "received on the wire": queued for hal_uart_read. Returns the number accepted
 * (the rest is dropped and counted, as the board's RX interrupt does; after a drop
 * nothing is accepted until the reader has seen the loss, hal_uart_rx_lost). */
size_t hal_uart_host_rx_push(const uint8_t *data, size_t len);
/* Bytes "sent on the wire": taken from the TX ring. Returns the number moved. */
size_t hal_uart_host_tx_pop(uint8_t *buf, size_t max);
/* Bytes dropped because a ring was full. */
uint32_t hal_uart_host_rx_dropped(void);
uint32_t hal_uart_host_tx_dropped(void);
/* Empty both rings and clear the counters. */
void hal_uart_host_reset(void);

#endif /* HAL_UART_HOST_H */
