/* One command line into an application through the host UART stub, the background loop
 * run once, the whole reply out: how the C tests talk to the application as gyroctl
 * would. Header-only (static buffer: one reply at a time). */
#ifndef APP_CMD_H
#define APP_CMD_H

#include <string.h>

#include "app/app.h"
#include "hal_uart_host.h"

static inline const char *app_cmd_line(app_t *a, const char *line)
{
  static char reply[HAL_UART_HOST_TX_SIZE + 1u]; /* what the TX ring can hold: `list` is 8 KB */
  hal_uart_host_rx_push((const uint8_t *)line, strlen(line));
  app_poll(a);
  const size_t n = hal_uart_host_tx_pop((uint8_t *)reply, sizeof reply - 1u);
  reply[n] = '\0';
  return reply;
}

#endif /* APP_CMD_H */
