#include "hal_uart_host.h"

#include "hal/hal_uart.h"

/* One UART, as on the board: file-scope state stands in for the peripheral. */
static struct {
  uint8_t rx[HAL_UART_HOST_RX_SIZE];
  uint8_t tx[HAL_UART_HOST_TX_SIZE];
  size_t rx_head, rx_tail, tx_head, tx_tail; /* head: write index, tail: read index */
  uint32_t rx_dropped, tx_dropped;
  bool rx_gap; /* bytes lost: nothing stored until the reader reaches the gap */
} uart;

static size_t used(size_t head, size_t tail, size_t size)
{
  return (head + size - tail) % size;
}

size_t hal_uart_host_rx_push(const uint8_t *data, size_t len)
{
  size_t n = 0;
  for (; n < len; n++) {
    if (uart.rx_gap ||
        used(uart.rx_head, uart.rx_tail, HAL_UART_HOST_RX_SIZE) == HAL_UART_HOST_RX_SIZE - 1u) {
      uart.rx_dropped += (uint32_t)(len - n);
      uart.rx_gap = true;
      break;
    }
    uart.rx[uart.rx_head] = data[n];
    uart.rx_head = (uart.rx_head + 1u) % HAL_UART_HOST_RX_SIZE;
  }
  return n;
}

size_t hal_uart_host_tx_pop(uint8_t *buf, size_t max)
{
  size_t n = 0;
  while (n < max && uart.tx_tail != uart.tx_head) {
    buf[n++] = uart.tx[uart.tx_tail];
    uart.tx_tail = (uart.tx_tail + 1u) % HAL_UART_HOST_TX_SIZE;
  }
  return n;
}

uint32_t hal_uart_host_rx_dropped(void) { return uart.rx_dropped; }
uint32_t hal_uart_host_tx_dropped(void) { return uart.tx_dropped; }

void hal_uart_host_reset(void)
{
  uart.rx_head = uart.rx_tail = uart.tx_head = uart.tx_tail = 0u;
  uart.rx_dropped = uart.tx_dropped = 0u;
  uart.rx_gap = false;
}

bool hal_uart_rx_lost(void)
{
  if (!uart.rx_gap || uart.rx_tail != uart.rx_head) return false;
  uart.rx_gap = false;
  return true;
}

size_t hal_uart_read(uint8_t *buf, size_t max)
{
  size_t n = 0;
  while (n < max && uart.rx_tail != uart.rx_head) {
    buf[n++] = uart.rx[uart.rx_tail];
    uart.rx_tail = (uart.rx_tail + 1u) % HAL_UART_HOST_RX_SIZE;
  }
  return n;
}

size_t hal_uart_tx_free(void)
{
  return HAL_UART_HOST_TX_SIZE - 1u - used(uart.tx_head, uart.tx_tail, HAL_UART_HOST_TX_SIZE);
}

size_t hal_uart_write(const uint8_t *data, size_t len)
{
  size_t n = 0;
  for (; n < len; n++) {
    if (hal_uart_tx_free() == 0u) {
      uart.tx_dropped += (uint32_t)(len - n);
      break;
    }
    uart.tx[uart.tx_head] = data[n];
    uart.tx_head = (uart.tx_head + 1u) % HAL_UART_HOST_TX_SIZE;
  }
  return n;
}
