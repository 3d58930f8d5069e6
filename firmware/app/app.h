/* The application: the parameter bank, its flash store, the gyro, the command line, and
 * the glue between them and the HAL. The same code runs on the board and on the host.
 *
 *   app_sample_isr (50 kHz, highest priority): take this tick's parameter view (apply a
 *     newly published design at the tick boundary), read the ADC frame, gyro_tick, write
 *     the DAC frame, measure its own cycles.
 *   app_poll (background loop): UART bytes -> command line -> parameter bank / store. A
 *     line is only executed when the TX ring has room for the longest reply
 *     (APP_TLM_TX_RESERVE, which telemetry leaves free): otherwise the loop waits for the
 *     UART to drain, so replies are never cut or interleaved. Bytes lost on reception
 *     discard the line they belong to (err OVERFLOW, counted in status).
 * Requests from the background to the loop (drive on/off, sweep, self-test, clear) go
 * through a queue of single words: every acknowledged request is taken by the ISR, in
 * order, one per tick at the tick boundary, so the ISR never sees a half-made change and
 * no request replaces another. Commands judge the drive as it will be once the queue is
 * taken (app_mode_after_queue), so "drive off" then "selftest" in one write refuses the
 * self-test.
 */
#ifndef APP_H
#define APP_H

#include <stdbool.h>
#include <stdint.h>

#include "app/app_tlm.h"
#include "comm/cli.h"
#include "gyro/gyro.h"
#include "gyro/selfcal.h"
#include "params/param_store.h"
#include "params/params.h"

#define APP_MAX_CMDS 8u
/* Requests waiting for the ISR (a power of two); it takes one per tick, so a full queue
 * drains in 160 us: a command finding it full is refused (err BUSY), never dropped. */
#define APP_REQ_QUEUE 8u

typedef enum {
  APP_REQ_NONE = 0u,
  APP_REQ_DRIVE_ON = 1u,
  APP_REQ_DRIVE_OFF = 2u,
  APP_REQ_SWEEP = 3u,         /* enter SWEEP: self-calibration (app_selfcal.h) */
  APP_REQ_SWEEP_HANDOVER = 4u, /* SWEEP -> ACQUIRE with the newly applied design */
  APP_REQ_SELFTEST = 5u,       /* run the built-in self-test (selftest.h) */
  APP_REQ_CLEAR = 6u           /* clear the shown fault; its record stays (last_fault) */
} app_req_t;

/* Lines an image adds to the status reply (board figures: stack, sample clock), written
 * with cli_put / cli_emit_data before the final ok line. */
typedef void (*app_status_fn)(cli_t *cli, void *ctx);

typedef struct {
  params_t params;
  gyro_design_t derived[2];  /* the bank's derived blocks */
  const void *applied;       /* derived block the ISR runs with */
  gyro_t gyro;
  param_store_t store;
  param_store_status_t store_status; /* result of the boot-time load */
  /* Stored values the boot could not design with the rest, set back to their defaults
   * (bit i: parameter i), and why the stored set as a whole was refused. */
  uint32_t store_dropped[(PARAM_COUNT + 31u) / 32u];
  const char *store_dropped_why;
  cli_t cli;
  cli_cmd_t cmds[APP_MAX_CMDS]; /* the application's command rows (app_cmds.c) */
  /* Bytes read from the UART, fed to the command line a line at a time (app_poll). */
  uint8_t rx_buf[64];
  uint32_t rx_len, rx_pos;
  /* Request queue: words written by the background before it advances req_head; the
   * ISR takes req_word[req_tail % APP_REQ_QUEUE] and advances req_tail. */
  volatile uint32_t req_word[APP_REQ_QUEUE];
  volatile uint32_t req_head, req_tail;
  bool sweep_owns_drive;     /* the sequencer, not a command, decides the drive's next mode */
  app_tlm_t tlm;             /* telemetry stream and its commands (app_tlm.c) */
  selfcal_t selfcal;         /* self-calibration sequencer (background, app_selfcal.c) */
  uint32_t selfcal_t0_ticks; /* isr_ticks when the sweep was requested */
  uint32_t selfcal_ticks;    /* its length up to the hand-over */
  /* Self-measurement of the sample ISR (DWT cycles on the board). */
  uint32_t isr_ticks;
  /* Set by the image's main after app_init (NULL: nothing added, as on the host). */
  app_status_fn status_board;
  void *status_board_ctx;
} app_t;

/* Load the stored parameters (defaults if the store is empty or corrupt), design, init
 * the gyro and the command line. Returns 0, or a negative value if even the defaults
 * cannot be designed. Does not start the sample clock. */
int app_init(app_t *a);
/* The same with given parameter values instead of the stored ones (the simulator and
 * tests). Returns -1 if they cannot be designed (no fallback to defaults). */
int app_init_with(app_t *a, const param_values_t *values);

/* The sample ISR: register with hal_sample_timer_start(fs, app_sample_isr, a). */
void app_sample_isr(void *ctx);

/* One pass of the background loop: never blocks. */
void app_poll(app_t *a);

/* Boot: stored value i set back to its default because the stored set could not be
 * designed with it (status lists them). */
bool app_store_dropped(const app_t *a, param_idx_t i);

/* Feed command-line bytes directly (host programs and tests; the board uses the UART). */
void app_cli_feed(app_t *a, const uint8_t *data, size_t len);

/* Background: queue a request for the ISR. Returns 0, or -1 (nothing queued) when full. */
int app_request(app_t *a, app_req_t r);
/* Background: requests queued and not yet taken. */
bool app_requests_pending(const app_t *a);
/* Background: the drive's mode once the queued requests are taken. */
gyro_mode_t app_mode_after_queue(const app_t *a);

#endif /* APP_H */
