/* Pseudo-terminal bridge for the host UART stub: a host program running the firmware
 * (gyro-sim, tests/e2e/fw_pty_host) exposes the tuning UART as a pty, so gyroctl, a
 * terminal program or pyserial talk to it exactly as to the board's USB-serial port.
 *
 *   pty slave (/dev/pts/N) <-> kernel <-> master fd <-> uart_pty_pump <-> hal_uart_host
 *                                                                   RX ring / TX ring
 * The pty is raw (no echo, no CR/LF translation, 8-bit clean: 0x00 and 0xFF
 * pass, as on the wire), and the bridge keeps its own slave descriptor open so that
 * clients may come and go without the pty hanging up.
 *
 * uart_pty_pump never blocks: it moves what the kernel has (RX, at most
 * UART_PTY_RX_CHUNK bytes per call so the stub's 1 KB RX ring - drained by every
 * app_poll - never overflows if pump and app_poll alternate) and what the TX ring holds
 * (TX; bytes the pty cannot take yet are kept and offered again at the next call, so
 * nothing the firmware wrote is lost while no client reads: the TX ring fills and the
 * firmware's own flow control - telemetry waits, ring overruns counted - takes over).
 * Call it from the main loop after app_poll, and poll(2) uart_pty_fd() to sleep until
 * the client writes.
 */
#ifndef UART_PTY_H
#define UART_PTY_H

#include <stddef.h>
#include <stdint.h>

#define UART_PTY_RX_CHUNK 256u
#define UART_PTY_TX_CHUNK 4096u
#define UART_PTY_PATH_MAX 256u

typedef struct {
  int master_fd;                     /* -1 when closed */
  int slave_fd;                      /* held open by the bridge */
  char link_path[UART_PTY_PATH_MAX]; /* symlink made by uart_pty_link, "" if none */
  uint8_t tx[UART_PTY_TX_CHUNK];     /* popped from the TX ring, not yet written */
  size_t tx_len, tx_off;
  uint64_t tx_bytes;   /* written to the pty so far */
  uint32_t rx_dropped; /* bytes the RX ring refused */
} uart_pty_t;

/* Open a pty pair (posix_openpt, grantpt, unlockpt), raw, non-blocking; write the
 * slave's path into path_out (len bytes, may be NULL). Returns 0, or -1 with errno set
 * (then p is closed). */
int uart_pty_open(uart_pty_t *p, char *path_out, size_t len);
/* Make link_path a symlink to the slave (replacing an existing symlink, never a regular
 * file). Removed again by uart_pty_close. Returns 0, or -1 with errno set. */
int uart_pty_link(uart_pty_t *p, const char *link_path);
/* Move bytes both ways without blocking. */
void uart_pty_pump(uart_pty_t *p);
/* The master descriptor, for poll(2) (POLLIN: the client wrote). */
int uart_pty_fd(const uart_pty_t *p);
void uart_pty_close(uart_pty_t *p);

#endif /* UART_PTY_H */
