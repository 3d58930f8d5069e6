/* The application side of self-calibration: starting a sweep, and handing its result
 * to the parameter bank (params_stage / params_commit, never live variables) and the
 * loops to the drive (SWEEP -> ACQUIRE). */
#ifndef APP_SELFCAL_H
#define APP_SELFCAL_H

#include "app/app_core.h"

/* Request SWEEP and start the sequencer. Returns 0, or -1 (nothing changed) when a
 * sweep is running, the request queue is full or the configuration is refused. */
int app_selfcal_start(app_t *a);

/* Background pass (from app_poll): timeouts (selfcal_watch); once the ISR has taken
 * every queued request, the sequencer step; on READY stage and commit
 * drive.freq_hz, drive.cal_f0_hz, drive.cal_q, drive.cal_gain_v_per_v2,
 * drive.p_init_deg (and, sense.cal 1, the sense mode's sense.f0_hz, sense.q,
 * sense.fb_gain_v_per_v2, sense.fb_phase_deg when all were identified,
 * sense.cal_tune_ke_per_s2_per_v2 when it was), then request the hand-over; a failed
 * sweep requests drive off. */
void app_selfcal_poll(app_t *a);

#endif /* APP_SELFCAL_H */
