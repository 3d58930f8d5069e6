/* The application side of mode tuning (sense.tune, gyro/sense_tune.h): the background
 * recomputes the tuning voltage for the drive's resonance now (the tracked frequency's
 * temperature hold) and hands a changed code or verdict to the ISR as a request
 * (APP_REQ_TUNE), so the sample path does nothing per tick for it. */
#ifndef APP_TUNE_H
#define APP_TUNE_H

#include "app/app_core.h"

/* Background pass (from app_poll). The voltage is applied while LOCKED only: before the
 * lock, force rebalance is not running, and a sense mode tuned to the drive would ring up
 * on the quadrature to the ADC's rails (at Q 1e4 the matched response is 1400 times the
 * 110 Hz split's); not LOCKED, 0 V. The verdict (RATE_INVALID_TUNE) is set while the
 * voltage is not applied or the target is out of reach, and with force rebalance while
 * the lost-match monitor (sense_tune.h) has no estimate yet (LOCKED, the continuous
 * test's notch converged, then SENSE_TUNE_DISC_SETTLE_WINDOWS windows) or finds the
 * sense resonance beyond its tolerance from the model's. In SWEEP, or while a sweep runs
 * or a request waits, nothing is sent (the sweep's jobs own the channel). */
void app_tune_poll(app_t *a);

#endif /* APP_TUNE_H */
