/* The application: the parameter bank, its flash store, the gyro, the command line, and
 * the glue between them and the HAL. The same code runs on the board and on the host.
 *
 *   app_sample_isr (50 kHz, highest priority): take this tick's parameter view (apply a
 *     newly published design at the tick boundary) and at most one request, read the ADC
 *     frame, gyro_tick, the telemetry's record, write the DAC frame (the HAL measures
 *     the handler's cycles).
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

#include <stddef.h>
#include <stdint.h>

#include "app/app_core.h"

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

/* Feed command-line bytes directly (host programs and tests; the board uses the UART). */
void app_cli_feed(app_t *a, const uint8_t *data, size_t len);

#endif /* APP_H */
