/* The pty bridge of the host UART (host_sim/sim/uart_pty): bytes written on the slave
 * side reach the firmware's RX ring unchanged, bytes the firmware queues reach the slave
 * unchanged (raw mode: no echo, no CR/LF translation, NUL and 0xFF pass), a transfer
 * larger than the kernel's pty buffer completes across pumps, and pumping with nothing
 * to do or no client returns at once. Waits use poll(2) on readiness, never a delay. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cmocka.h>

#include "hal/hal_uart.h"
#include "hal_uart_host.h"
#include "sim/uart_pty.h"

static uart_pty_t pty;
static char path[UART_PTY_PATH_MAX];

static int open_client(void)
{
  const int fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK);
  assert_true(fd >= 0);
  return fd;
}

/* Pump until the firmware's RX ring has produced want bytes into got. */
static void pump_rx(uint8_t *got, size_t want)
{
  size_t have = 0u;
  for (int spins = 0; have < want && spins < 10000; spins++) {
    struct pollfd p = {uart_pty_fd(&pty), POLLIN, 0};
    (void)poll(&p, 1, 2000);
    uart_pty_pump(&pty);
    have += hal_uart_read(&got[have], want - have);
  }
  assert_int_equal(have, want);
}

/* Pump the TX side and read the client until want bytes arrived. */
static void pump_tx(int fd, uint8_t *got, size_t want)
{
  size_t have = 0u;
  for (int spins = 0; have < want && spins < 10000; spins++) {
    uart_pty_pump(&pty);
    struct pollfd p = {fd, POLLIN, 0};
    (void)poll(&p, 1, 2000);
    const ssize_t n = read(fd, &got[have], want - have);
    if (n > 0) have += (size_t)n;
  }
  assert_int_equal(have, want);
}

static int setup(void **state)
{
  (void)state;
  hal_uart_host_reset();
  assert_int_equal(uart_pty_open(&pty, path, sizeof path), 0);
  assert_true(strncmp(path, "/dev/pts/", 9u) == 0);
  return 0;
}

static int teardown(void **state)
{
  (void)state;
  uart_pty_close(&pty);
  return 0;
}

static void test_both_directions_byte_exact(void **state)
{
  (void)state;
  const int fd = open_client();
  static const uint8_t msg[] = "get drive.freq_hz\r\nset x 1\n\x00\x01\xff\x7f\x03\x11\x13 end\r";
  assert_int_equal(write(fd, msg, sizeof msg), (ssize_t)sizeof msg);
  uint8_t got[sizeof msg];
  pump_rx(got, sizeof msg);
  assert_memory_equal(got, msg, sizeof msg);
  /* firmware -> client: a reply and a frame with zeros */
  static const uint8_t out[] = "ok drive.freq_hz 1489.9 Hz\r\n\x00\x01\x05H\x01\x02\x03\x00\n\r\xff";
  assert_int_equal(hal_uart_write(out, sizeof out), sizeof out);
  uint8_t back[sizeof out];
  pump_tx(fd, back, sizeof out);
  assert_memory_equal(back, out, sizeof out);
  /* no echo: the client has nothing more to read */
  uart_pty_pump(&pty);
  uint8_t extra;
  assert_int_equal(read(fd, &extra, 1u), -1);
  assert_true(errno == EAGAIN || errno == EWOULDBLOCK);
  close(fd);
}

/* 64 KB from the firmware: far more than the TX ring or the pty buffer holds at once. */
static void test_large_transfer(void **state)
{
  (void)state;
  const int fd = open_client();
  static uint8_t big[65536], got[65536];
  for (size_t i = 0; i < sizeof big; i++) big[i] = (uint8_t)(i * 131u + (i >> 8));
  size_t queued = 0u, have = 0u;
  for (int spins = 0; have < sizeof big && spins < 100000; spins++) {
    const size_t room = hal_uart_tx_free();
    const size_t n_w = (sizeof big - queued < room) ? sizeof big - queued : room;
    queued += hal_uart_write(&big[queued], n_w);
    uart_pty_pump(&pty);
    struct pollfd p = {fd, POLLIN, 0};
    (void)poll(&p, 1, 2000);
    const ssize_t n = read(fd, &got[have], sizeof got - have);
    if (n > 0) have += (size_t)n;
  }
  assert_int_equal(have, sizeof big);
  assert_memory_equal(got, big, sizeof big);
  assert_int_equal(hal_uart_host_tx_dropped(), 0u);
  assert_true(pty.tx_bytes == sizeof big);
  close(fd);
}

/* With no client, and with nothing to move, pump returns; the firmware's bytes wait for
 * the next client (the pty stays up between clients). */
static void test_no_client(void **state)
{
  (void)state;
  uart_pty_pump(&pty);
  assert_int_equal(hal_uart_write((const uint8_t *)"ok\r\n", 4u), 4u);
  uart_pty_pump(&pty);
  const int fd = open_client();
  uint8_t got[4];
  pump_tx(fd, got, 4u);
  assert_memory_equal(got, "ok\r\n", 4u);
  close(fd);
  /* a client came and went: the bridge still works for the next one */
  const int fd2 = open_client();
  assert_int_equal(write(fd2, "x\n", 2u), 2);
  uint8_t in[2];
  pump_rx(in, 2u);
  assert_memory_equal(in, "x\n", 2u);
  close(fd2);
}

static void test_symlink(void **state)
{
  (void)state;
  char link[64];
  snprintf(link, sizeof link, "/tmp/test_uart_pty_%ld", (long)getpid());
  assert_int_equal(uart_pty_link(&pty, link), 0);
  char target[UART_PTY_PATH_MAX] = {0};
  assert_true(readlink(link, target, sizeof target - 1u) > 0);
  assert_string_equal(target, path);
  /* a regular file is never replaced */
  char file[80];
  snprintf(file, sizeof file, "%s.file", link);
  FILE *f = fopen(file, "w");
  assert_non_null(f);
  fclose(f);
  assert_int_equal(uart_pty_link(&pty, file), -1);
  struct stat st;
  assert_int_equal(lstat(file, &st), 0);
  assert_true(S_ISREG(st.st_mode));
  unlink(file);
  uart_pty_close(&pty);
  assert_int_equal(lstat(link, &st), -1); /* removed with the bridge */
  assert_int_equal(uart_pty_open(&pty, path, sizeof path), 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_both_directions_byte_exact, setup, teardown),
      cmocka_unit_test_setup_teardown(test_large_transfer, setup, teardown),
      cmocka_unit_test_setup_teardown(test_no_client, setup, teardown),
      cmocka_unit_test_setup_teardown(test_symlink, setup, teardown),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
