/* posix_openpt, grantpt, unlockpt, ptsname_r need X/Open 600 and glibc's extensions. */
#define _GNU_SOURCE
#include "uart_pty.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include "hal_uart_host.h"

int uart_pty_open(uart_pty_t *p, char *path_out, size_t len)
{
  memset(p, 0, sizeof *p);
  p->master_fd = -1;
  p->slave_fd = -1;
  char name[UART_PTY_PATH_MAX];
  int m = posix_openpt(O_RDWR | O_NOCTTY);
  if (m < 0) {
    return -1;
  }
  p->master_fd = m;
  if (grantpt(m) != 0 || unlockpt(m) != 0 || ptsname_r(m, name, sizeof name) != 0) {
    goto fail;
  }
  /* the bridge's own slave descriptor: the pty stays up between clients, and the raw
   * settings made on it stay the pty's */
  p->slave_fd = open(name, O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (p->slave_fd < 0) {
    goto fail;
  }
  struct termios t;
  if (tcgetattr(p->slave_fd, &t) != 0) {
    goto fail;
  }
  cfmakeraw(&t);
  t.c_cc[VMIN] = 1;
  t.c_cc[VTIME] = 0;
  if (tcsetattr(p->slave_fd, TCSANOW, &t) != 0) {
    goto fail;
  }
  const int fl = fcntl(m, F_GETFL);
  if (fl < 0 || fcntl(m, F_SETFL, fl | O_NONBLOCK) != 0) {
    goto fail;
  }
  if (path_out != NULL && len > 0u) {
    if (strlen(name) + 1u > len) {
      errno = ENAMETOOLONG;
      goto fail;
    }
    memcpy(path_out, name, strlen(name) + 1u);
  }
  return 0;
fail:;
  const int e = errno;
  uart_pty_close(p);
  errno = e;
  return -1;
}

int uart_pty_link(uart_pty_t *p, const char *link_path)
{
  char name[UART_PTY_PATH_MAX];
  if (p->master_fd < 0 || link_path == NULL || strlen(link_path) + 1u > sizeof p->link_path ||
      ptsname_r(p->master_fd, name, sizeof name) != 0) {
    errno = EINVAL;
    return -1;
  }
  struct stat st;
  if (lstat(link_path, &st) == 0) {
    if (!S_ISLNK(st.st_mode)) {
      errno = EEXIST; /* never replace a real file */
      return -1;
    }
    if (unlink(link_path) != 0) {
      return -1;
    }
  }
  if (symlink(name, link_path) != 0) {
    return -1;
  }
  memcpy(p->link_path, link_path, strlen(link_path) + 1u);
  return 0;
}

int uart_pty_fd(const uart_pty_t *p) { return p->master_fd; }

void uart_pty_pump(uart_pty_t *p)
{
  if (p->master_fd < 0) {
    return;
  }
  /* client -> firmware */
  uint8_t buf[UART_PTY_RX_CHUNK];
  const ssize_t n = read(p->master_fd, buf, sizeof buf);
  if (n > 0) {
    const size_t took = hal_uart_host_rx_push(buf, (size_t)n);
    p->rx_dropped += (uint32_t)((size_t)n - took);
  }
  /* n < 0: EAGAIN (nothing), or EIO while no client has the pty open: nothing to do */

  /* firmware -> client */
  for (;;) {
    if (p->tx_off == p->tx_len) {
      p->tx_off = 0u;
      p->tx_len = hal_uart_host_tx_pop(p->tx, sizeof p->tx);
      if (p->tx_len == 0u) {
        return;
      }
    }
    const ssize_t w = write(p->master_fd, &p->tx[p->tx_off], p->tx_len - p->tx_off);
    if (w <= 0) {
      return; /* the pty's buffer is full (EAGAIN): keep the rest for the next call */
    }
    p->tx_off += (size_t)w;
    p->tx_bytes += (uint64_t)w;
  }
}

void uart_pty_close(uart_pty_t *p)
{
  if (p->link_path[0] != '\0') {
    struct stat st;
    if (lstat(p->link_path, &st) == 0 && S_ISLNK(st.st_mode)) {
      (void)unlink(p->link_path);
    }
    p->link_path[0] = '\0';
  }
  if (p->slave_fd >= 0) {
    (void)close(p->slave_fd);
    p->slave_fd = -1;
  }
  if (p->master_fd >= 0) {
    (void)close(p->master_fd);
    p->master_fd = -1;
  }
  p->tx_len = p->tx_off = 0u;
}
