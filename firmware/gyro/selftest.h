/* Built-in self-test: a known force on the sense mode through the sense feedback
 * electrodes (spare DAC channel), and a check that the rate channel answers it as it
 * did when the part was calibrated, as commercial gyros do at power-on or on command.
 *
 * The force is put in phase with the drive velocity - the phase of the Coriolis force
 * (2-22) - using the drive phase the loop holds (drive.phase_set_deg), so the response
 * lands on the rate axis of the calibrated demodulation: u = A cos(phi + theta_set),
 * with the differential electrodes' force 4 Ks_fb V_bias u. The test runs only while
 * LOCKED: a baseline of the unfiltered rate over BASE blocks, then the force, SETTLE
 * blocks for the sense mode and the output path, the response over MEAS blocks, and the
 * force off. A block is the rate channel's (RATE_DECIM ticks): the sequence advances
 * once per block on the block's unfiltered rate (selftest_update), while the force is a
 * carrier and is formed every tick (selftest_force). Pass: |response / expected - 1| <= tolerance. The rate output carries the
 * test force while it runs (GYRO_FLAG_SELFTEST).
 */
#ifndef SELFTEST_H
#define SELFTEST_H

#include <stdint.h>

typedef enum {
  SELFTEST_IDLE = 0,
  SELFTEST_BASE = 1,
  SELFTEST_FORCE = 2,
  SELFTEST_PASS = 3,
  SELFTEST_FAIL = 4,
  SELFTEST_ABORTED = 5 /* lock lost while testing */
} selftest_state_t;

typedef struct {
  float amp_v;       /* force voltage amplitude A on the spare DAC channel */
  float expect_dps;  /* response expected on the rate axis (calibrated on the part) */
  float tol_rel;     /* pass band, relative */
  float ref_c, ref_s; /* cos, sin of the drive phase setpoint */
  float scale_dps;   /* rate channel scale: deg/s per unit of the unfiltered rate */
  uint32_t base_blocks, settle_blocks, meas_blocks;
} selftest_cfg_t;

typedef struct {
  selftest_cfg_t cfg;
  uint32_t state;    /* selftest_state_t */
  uint32_t count;     /* blocks in the current state */
  float acc_base, acc_meas; /* sums of the unfiltered rate */
  float result_dps;  /* measured response of the last test */
  uint32_t runs;
  /* 1 / base_blocks, 1 / meas_blocks, 1 / expect_dps (0 where the divisor is 0), set with
   * the configuration: the verdict block divides nothing (its tick's budget). */
  float inv_base, inv_meas, inv_expect;
} selftest_t;

void selftest_init(selftest_t *st, const selftest_cfg_t *cfg);
/* Coefficients only (a running test carries on). */
void selftest_retune(selftest_t *st, const selftest_cfg_t *cfg);
/* Start a test (ignored while one runs). */
void selftest_start(selftest_t *st);
/* Once per block: locked = drive LOCKED, rate_raw = the rate channel's unfiltered
 * rate of the block. */
void selftest_update(selftest_t *st, int locked, float rate_raw);

static inline int selftest_running(const selftest_t *st)
{
  return st->state == SELFTEST_BASE || st->state == SELFTEST_FORCE;
}

/* Every tick: the spare DAC voltage, (sin_wc, cos_wc) the NCO references. FORCE:
 * A cos(phi + theta_set), in phase with the drive velocity (gyro.h phasor convention:
 * the velocity of y = Im{Z e^{j phi}} is Re{Z e^{j phi}}). */
static inline float selftest_force(const selftest_t *st, float sin_wc, float cos_wc)
{
  if (st->state != SELFTEST_FORCE) {
    return 0.0f;
  }
  return st->cfg.amp_v * (st->cfg.ref_c * cos_wc - st->cfg.ref_s * sin_wc);
}

const char *selftest_state_name(uint32_t state);

#endif /* SELFTEST_H */
