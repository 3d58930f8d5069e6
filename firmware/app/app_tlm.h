/* The telemetry stream of the application: the stream/stop commands on the command line
 * and the glue between comm/tlm and the UART (frames share the tuning port with the
 * command line's replies; see comm/tlm_frame.h for how a host tells them apart).
 *
 * Command grammar (replies as in comm/cli.h):
 *   stream                          - NAME TYPE UNIT ...            ok N fields ...
 *       lists the streamable fields (app_tlm_fields.h), starts nothing
 *   stream FIELD... [@RATE_HZ]      ok stream ID RATE Hz decim D fields F per_frame N
 *                                      link B B/s P% [rounded from R]
 *       FIELD is a field name or `all`; fields go into records in table order whatever
 *       the order given; RATE_HZ (default: parameter tlm.rate_hz) is rounded to fs / D
 *       with an integer D >= 1, and the rate actually delivered is reported. Starts a new
 *       stream (stopping a running one first); the header frame and the data frames
 *       follow the ok line. Errors, nothing started: err ARGS (no field, a field twice,
 *       a second rate), err NAME (no such field), err VALUE (rate not a number),
 *       err RANGE (rate <= 0, above fs, or below fs / 65535), err BANDWIDTH (more than
 *       70 % of the UART: the message gives the load and the limit).
 *   stop                            ok stop ID records R lost L frames F dropped D
 *                                   | ok not streaming
 *       stops the stream; its last frames are sent before the ok line. R records were
 *       framed, L lost to ring overruns (the background loop fell behind), F frames
 *       sent, D frames dropped (the UART could not take them at stop).
 */
#ifndef APP_TLM_H
#define APP_TLM_H

#include "comm/cli.h"
#include "board.h"
#include "comm/tlm.h"
#include "gyro/gyro.h"
#include "params/params.h"

/* The tuning port's line rate, 8N1: the board's (board.h), which the link budget of a
 * stream (tlm_plan) is computed against. */
#define APP_TLM_BAUD BOARD_UART_BAUD
/* TX-ring bytes telemetry leaves free for command replies, so that the longest (list,
 * 14.9 KB with the board thermometer's rows; status about 2 KB) comes out whole while a
 * stream runs (test_app: every reply fits). The rings are 16 KB on the board and the
 * host, which leaves telemetry 1 KB (11 ms of the line) of backlog. */
#define APP_TLM_TX_RESERVE 15360u

typedef struct {
  tlm_t stream;
  cli_cmd_t cmds[2];
  const params_t *params;
} app_tlm_t;

/* Initialise the stream for fs = sys.fs_hz and register stream/stop with cli.
 * Returns 0, or -1 (bad configuration or the command table is full). */
int app_tlm_init(app_tlm_t *t, cli_t *cli, const params_t *params);

/* Sample ISR, after gyro_tick. */
static inline void app_tlm_isr(app_tlm_t *t, const gyro_out_t *out)
{
  tlm_isr_push(&t->stream, out);
}

/* Background loop: frames to the UART. */
void app_tlm_poll(app_tlm_t *t);

#endif /* APP_TLM_H */
