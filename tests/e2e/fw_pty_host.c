/* fw_pty_host: the real application (app_init, app_sample_isr through the host HAL,
 * app_poll) behind a pseudo-terminal, for end-to-end tests of the UART tools (gyroctl)
 * without the simulator. The plant is trivial - the ADC reads 0 V whatever the DAC does,
 * so the drive never locks - because these tests are about the command line, the
 * telemetry stream and the parameter store, not the physics.
 *
 *   fw_pty_host --flash FILE [--link PATH]
 *
 * Prints "pty PATH" (the slave device) on stdout once the port is ready, then runs the
 * sample ISR paced to real time (50000 ticks per second of wall clock; slower if the
 * machine cannot keep up, never faster) and the background loop about once a
 * millisecond, until SIGTERM or SIGINT. FILE backs the parameter flash: start the program
 * again over the same file and the saved parameters load.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "app/app.h"
#include "hal/hal_sample_timer.h"
#include "hal_flash_host.h"
#include "hal_host.h"
#include "hal_uart_host.h"
#include "sim/uart_pty.h"

static volatile sig_atomic_t g_stop;

static void on_signal(int sig)
{
  (void)sig;
  g_stop = 1;
}

static void quiet_plant(void *p, const hal_dac_frame_t *dac, hal_adc_frame_t *adc)
{
  (void)p;
  (void)dac;
  adc->drive = 0;
  adc->sense = 0;
}

static uint64_t now_ns(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static app_t app;

int main(int argc, char **argv)
{
  const char *flash = NULL, *link = NULL;
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--flash") == 0 && i + 1 < argc) {
      flash = argv[++i];
    } else if (strcmp(argv[i], "--link") == 0 && i + 1 < argc) {
      link = argv[++i];
    } else {
      fprintf(stderr, "usage: %s --flash FILE [--link PATH]\n", argv[0]);
      return 2;
    }
  }
  if (flash == NULL) {
    fprintf(stderr, "usage: %s --flash FILE [--link PATH]\n", argv[0]);
    return 2;
  }
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGINT, &sa, NULL);

  const hal_flash_host_cfg_t fc = {2u, 16384u, flash, 0u, 0u, 0u};
  if (hal_flash_host_configure(&fc) != 0) {
    fprintf(stderr, "fw_pty_host: cannot use flash file %s\n", flash);
    return 1;
  }
  hal_uart_host_reset();
  hal_host_attach(quiet_plant, NULL);
  if (app_init(&app) != 0) {
    fprintf(stderr, "fw_pty_host: app_init failed\n");
    return 1;
  }
  const uint32_t fs = params_current(&app.params)->sys_fs_hz;
  if (hal_sample_timer_start(fs, app_sample_isr, &app) != 0) {
    return 1;
  }
  uart_pty_t pty;
  char path[UART_PTY_PATH_MAX];
  if (uart_pty_open(&pty, path, sizeof path) != 0) {
    perror("fw_pty_host: pty");
    return 1;
  }
  if (link != NULL && uart_pty_link(&pty, link) != 0) {
    perror("fw_pty_host: link");
    uart_pty_close(&pty);
    return 1;
  }
  printf("pty %s\n", path);
  fflush(stdout);

  const uint64_t t0 = now_ns();
  uint64_t done = 0u;
  while (!g_stop) {
    const uint64_t due = (now_ns() - t0) * fs / 1000000000ull;
    if (due > done) {
      /* at most 20 ms of ticks per pass: the background loop keeps running even when the
       * host is slower than real time (the simulated clock then just runs late) */
      const uint64_t n = (due - done < fs / 50u) ? due - done : fs / 50u;
      hal_host_run(n);
      done += n;
      if (due - done > fs / 5u) {
        done = due - fs / 5u;
      }
    }
    uart_pty_pump(&pty);
    app_poll(&app);
    uart_pty_pump(&pty);
    struct pollfd pfd = {uart_pty_fd(&pty), POLLIN, 0};
    if (poll(&pfd, 1, 1) < 0 && errno != EINTR) {
      break;
    }
  }
  uart_pty_close(&pty);
  hal_flash_host_close();
  return 0;
}
