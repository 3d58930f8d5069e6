/* The application instance and what its parts share: the request queue from the
 * background to the sample ISR, and the boot's record of stored values it dropped.
 * The parts (app_selfcal, app_cmds, app_tlm) and the top level (app.c: init, ISR,
 * background loop) all build on this; nothing here calls them, so the dependencies run
 * one way: app -> app_cmds -> app_selfcal -> app_core. The queue's rules are in app.h.
 */
#ifndef APP_CORE_H
#define APP_CORE_H

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
  APP_REQ_SWEEP = 3u,          /* enter SWEEP: self-calibration (app_selfcal.h) */
  APP_REQ_SWEEP_HANDOVER = 4u, /* SWEEP -> ACQUIRE with the newly applied design */
  APP_REQ_SELFTEST = 5u,       /* run the built-in self-test (selftest.h) */
  APP_REQ_CLEAR = 6u,          /* clear the shown fault; its record stays (last_fault) */
  APP_REQ_TUNE = 7u,           /* the mode tuning's code and verdict (app_tune.h) */
  APP_REQ_BOARD = 8u           /* the board thermometer's verdict (app_board.h) */
} app_req_t;

/* A request word: the kind in the low byte; APP_REQ_TUNE carries the tuning channel's
 * DAC code in bits 8..23 and its verdict (RATE_INVALID_TUNE set) in bit 31. */
#define APP_REQ_KIND(w) ((w)&0xFFu)
#define APP_REQ_TUNE_WORD(code, invalid) \
  ((uint32_t)APP_REQ_TUNE | ((uint32_t)(code) << 8) | ((invalid) ? 0x80000000u : 0u))
#define APP_REQ_TUNE_CODE(w) ((uint16_t)(((w) >> 8) & 0xFFFFu))
#define APP_REQ_TUNE_INVALID(w) (((w)&0x80000000u) != 0u)
/* APP_REQ_BOARD carries its verdict (RATE_INVALID_BOARD_TEMP set) in bit 31. */
#define APP_REQ_BOARD_WORD(invalid) ((uint32_t)APP_REQ_BOARD | ((invalid) ? 0x80000000u : 0u))
#define APP_REQ_BOARD_INVALID(w) (((w)&0x80000000u) != 0u)

/* Lines an image adds to the status reply (board figures: stack, sample clock), written
 * with cli_put / cli_emit_data before the final ok line; ctx is NULL. */
typedef void (*app_status_fn)(cli_t *cli, void *ctx);

typedef struct {
  /* What the sample ISR touches on every tick first, each within one load's immediate
   * offset of the instance (4 KB), so that it needs no address arithmetic: the bank
   * (its published generation), the block it runs with, the request queue, the DAC frame,
   * the gyro and the telemetry's ISR side (app_tlm_t begins with it). */
  params_t params;
  const void *applied;  /* derived block the ISR runs with */
  uint32_t applied_gen; /* the bank's generation of it (params_isr_ack) */
  /* Request queue: words written by the background before it advances req_head; the
   * ISR takes req_word[req_tail % APP_REQ_QUEUE] and advances req_tail. */
  volatile uint32_t req_word[APP_REQ_QUEUE];
  volatile uint32_t req_head, req_tail;
  /* The DAC frame handed to the HAL every tick, attached to the gyro, which writes each
   * channel when its value changes (gyro_tick); the sense electrodes' channels keep the
   * mid-scale (0 V) of app_init until a loop drives them (issue 19 item 3). Kept here
   * rather than rebuilt on the stack because four constant stores a tick were 5 of the
   * interrupt's cycles. */
  hal_dac_frame_t dac;
  gyro_t gyro;
  app_tlm_t tlm;            /* telemetry stream and its commands (app_tlm.c) */
  gyro_design_t derived[2]; /* the bank's derived blocks */
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
  bool sweep_owns_drive;     /* the sequencer, not a command, decides the drive's next mode */
  bool handing_over;         /* the sweep's hand-over commits its values: the loops are off
                              * in SWEEP and start from them, so drive.track may change */
  selfcal_t selfcal;         /* self-calibration sequencer (background, app_selfcal.c) */
  uint32_t selfcal_t0_ticks; /* app_ticks when the sweep was requested */
  uint32_t selfcal_ticks;    /* its length up to the hand-over */
  /* Set by the image's main after app_init (NULL: nothing added, as on the host). */
  app_status_fn status_board;
  sense_tune_out_t tune; /* mode tuning: the latest pass's target and voltage (app_tune.c) */
  bool tune_locked;      /* ... and whether it could apply them (LOCKED) */
  sense_tune_disc_t tune_disc;  /* its lost-match monitor (sense_tune.h, app_tune.c) */
  const void *tune_disc_design; /* the design it was fed under (a new one restarts it) */
  board_therm_t board;          /* the board thermometer (board_therm.h, app_board.c) */
  uint32_t board_tick;          /* app_ticks of its latest step */
} app_t;

/* The sample ISR's calls since app_init: the gyro's own count of its ticks (one per
 * call, gyro_out_t.tick), which the ISR keeps anyway; a second counter of the same
 * thing cost the interrupt 5 cycles. */
static inline uint32_t app_ticks(const app_t *a) { return a->gyro.out.tick; }

/* Boot: stored value i set back to its default because the stored set could not be
 * designed with it (status lists them). */
bool app_store_dropped(const app_t *a, param_idx_t i);

/* Background: queue a request for the ISR. Returns 0, or -1 (nothing queued) when full. */
int app_request(app_t *a, app_req_t r);
/* The same with a whole request word (APP_REQ_TUNE_WORD). */
int app_request_word(app_t *a, uint32_t w);
/* Background: requests queued and not yet taken. */
bool app_requests_pending(const app_t *a);

/* Background: the drive's mode once the queued requests are taken. */
gyro_mode_t app_mode_after_queue(const app_t *a);

#endif /* APP_CORE_H */
