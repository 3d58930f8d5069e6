/* Tuning UART: interrupt-driven RX/TX ring buffers inside the HAL. Both calls are
 * non-blocking and may only be used from the background loop. */
#ifndef HAL_UART_H
#define HAL_UART_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Move up to max received bytes into buf; returns the number moved (0 if none). */
size_t hal_uart_read(uint8_t *buf, size_t max);
/* Received bytes lost (RX ring full, or a receiver overrun): from the loss on nothing is
 * stored until the reader has taken every byte before it and called this, so the gap
 * sits exactly after the last byte read. Returns true once per loss, when the ring is
 * empty; false while bytes before the gap are still waiting or nothing was lost. */
bool hal_uart_rx_lost(void);
/* Queue up to len bytes for transmission; returns the number accepted (the rest did not
 * fit in the TX ring and must be offered again). */
size_t hal_uart_write(const uint8_t *data, size_t len);
/* Free space in the TX ring, bytes. */
size_t hal_uart_tx_free(void);

#endif /* HAL_UART_H */
