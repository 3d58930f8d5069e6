/* The gyro's design: everything the parameters turn into (background, double-precision
 * design, gyro_design.c), the derived block the parameter bank publishes. Every module
 * of the sample path is told its part of it (a const X_cfg_t *) apart from what it
 * remembers (X_t, in gyro_t); the sample path reads the published block through one
 * pointer, so a new design takes over at a tick boundary as a whole (gyro_apply). */
#ifndef GYRO_DESIGN_H
#define GYRO_DESIGN_H

#include <stdint.h>

#include "dsp/lmsd.h"
#include "dsp/nco.h"
#include "gyro/board_therm.h"
#include "gyro/drive_loop.h"
#include "gyro/drive_synth.h"
#include "gyro/drive_track.h"
#include "gyro/quad_null.h"
#include "gyro/rate_channel.h"
#include "gyro/rate_valid.h"
#include "gyro/sense_fr.h"
#include "gyro/selftest.h"
#include "gyro/sense_tune.h"
#include "gyro/supervisor.h"
#include "params/params.h"

typedef struct {
  /* First: the blocks' jobs reach the rate channel's part at the design's own address. */
  rate_channel_cfg_t rate;
  rate_valid_cfg_t valid;
  supervisor_cfg_t sup;
  drive_loop_cfg_t drive;
  selftest_cfg_t selftest;
  float rate_out_v_per_dps;
  float rate_fault_out_v;   /* analog rate output while the rate is not valid */
  uint16_t rate_fault_code; /* its DAC code (derived) */
  uint32_t nco_half_step;   /* the NCO's step at the drive frequency: the NCO's start */
  lmsd_cfg_t lmsd_drive, lmsd_sense;
  drive_synth_cfg_t synth;
  drive_loop_design_out_t amp_design, phase_design; /* what the designer achieved */
  /* The tracking drive (drive.track 1, drive_track.h); its design is made in either mode
   * (status shows it), the sample path runs it only when track is 1. */
  uint32_t track;
  drive_track_cfg_t track_cfg;
  drive_track_design_out_t track_design;
  float f_cal_hz;    /* the calibrated drive frequency as the NCO realises it */
  float hz_per_step; /* fs / 2^31: the NCO's frequency per half-step */
  uint32_t autostart;
  /* The calibration record (cal.ref_freq_hz) against the drive frequency: GYRO_CAL_*;
   * anything but OK makes the rate not valid (rate_valid.h, UNCALIBRATED). */
  uint32_t cal_state;
  /* The tracking drive runs on a calibration made with the fixed drive (cal.ref_track 0):
   * the TRACKING reason of rate_valid.h (its cal_state is STALE as well). */
  uint32_t track_uncal;
  /* Quadrature nulling (quad.null 1, quad_null.h): its design is made in either state
   * (a bad configuration is refused even while off); the sample path runs it only when
   * quad_on is 1, at the thermometer's block rate (RATE_P_DECIM). */
  uint32_t quad_on;
  quad_null_design_t quad;
  /* Force rebalance (sense.mode 1, sense_fr.h): its design is made in either mode (a bad
   * configuration is refused even in open loop); the sample path runs it only when
   * sense_mode is 1. fb_synth realises its force on the feedback electrodes (the drive
   * synthesis's law, drive_synth.h); fb_theta_rad (sense.fb_phase_deg) turns the
   * Coriolis direction's force phase from the drive force's P (gyro_fr_synth), fb_off_v what the board adds to the
   * converters' voltages (DC+AC: its bias stage's sense.fb_bias_v; half-frequency: 0). */
  uint32_t sense_mode;
  drive_synth_cfg_t fb_synth;
  float fb_theta_rad;
  float fb_off_v;
  float fr_scale_dps_per_v2; /* the loop's scale factor: rate.scale_dps x g, for status */
  sense_fr_design_t fr;
  /* Mode tuning (sense.tune, sense_tune.h): the background's (app.c), which applies its
   * voltage through gyro_set_tune; the sample path reads none of it. */
  sense_tune_cfg_t tune;
  /* Its lost-match monitor (sense_tune.h): the background's too. */
  sense_tune_disc_cfg_t tune_disc;
  /* The board thermometer (board.*, board_therm.h): the background's (app_board.c); the
   * sample path adds the correction it hands over (gyro_t.board_in). */
  board_therm_cfg_t board;
  /* The sweep's sense demodulator step (demod.mu_sense, open loop's in every sense mode):
   * its sense jobs' means and back-off threshold are designed for it, and force
   * rebalance's sense.fr_mu (a pole at 1.2 kHz, for the loop) passes enough of the 2 wc
   * ripple to trip the back-off at wc (gyro_sweep_begin). Off the sample path. */
  float sweep_mu_sense;
  /* Last: the NCO's configuration is the background's (three doubles); before the sample
   * path's parts it pushed force rebalance's settling test past the 1020-byte reach of a
   * VLDR's offset (an extra address computation on a tick at its budget). */
  nco_cfg_t nco;
} gyro_design_t;

/* gyro_design_t.cal_state */
/* GYRO_CAL_OK: made at drive.freq_hz, drive.phase_set_deg, drive.track, the tuning,
 * sense.mode and quad.null now in force */
#define GYRO_CAL_NONE 0u /* no calibration: cal.ref_freq_hz 0 */
#define GYRO_CAL_OK 1u
#define GYRO_CAL_STALE \
  2u /* made at another drive frequency, phase setpoint, drive mode, mode tuning
      * (cal.ref_tune_v) or sense configuration (cal.ref_sense_mode, cal.ref_quad_null) */
/* cal.ref_freq_hz and drive.freq_hz agree within this, relative: two steps of a float,
 * so that a value printed and set again through the command line still matches. */
#define GYRO_CAL_FREQ_REL 2.0e-7
/* cal.ref_phase_set_deg and drive.phase_set_deg agree within this (two float steps at
 * 180 deg): 0.0001 deg turns the 1500 deg/s quadrature by 0.003 deg/s. */
#define GYRO_CAL_PHASE_DEG 3.1e-5

/* "no", "yes", "stale" for `status` */
const char *gyro_cal_state_name(uint32_t cal_state);

/* Why gyro_design refused a set of values: one status per check, each with a reason
 * (gyro_design_reason) that names the parameters at fault by their user-visible names.
 * GYRO_DESIGN_OK is 0, so `gyro_design(v, d) != 0` reads as "refused". */
typedef enum {
  GYRO_DESIGN_OK = 0,
  GYRO_DESIGN_NO_VALUES,      /* no values or nowhere to put the design (a caller's bug) */
  GYRO_DESIGN_FS,             /* sys.fs_hz */
  GYRO_DESIGN_DRIVE_FREQ,     /* drive.freq_hz against sys.fs_hz */
  GYRO_DESIGN_DRIVE_VOLTAGES, /* drive.u_max_v, drive.dc_bias_v (DC+AC) */
  GYRO_DESIGN_MU_DRIVE,       /* demod.mu_drive */
  GYRO_DESIGN_MU_SENSE,       /* demod.mu_sense */
  GYRO_DESIGN_AMP_LOOP,       /* drive.cal_*, drive.amp_bw_hz */
  GYRO_DESIGN_PHASE_LOOP,     /* drive.cal_f0_hz, drive.cal_q, drive.phase_bw_hz */
  GYRO_DESIGN_FIXED_Q,        /* drive.cal_q beyond the fixed-frequency drive's reach */
  GYRO_DESIGN_P_INIT,         /* drive.p_init_deg beyond one turn */
  GYRO_DESIGN_RATE_LPF,       /* rate.lpf_order, rate.lpf_cutoff_hz */
  GYRO_DESIGN_AMP_SET,        /* drive.amp_set_v against the ADC's range */
  GYRO_DESIGN_LOST_TOL,       /* sup.lost_tol_rel against sup.lock_tol_rel */
  GYRO_DESIGN_AMP_TRIP,       /* sup.amp_trip_rel against sup.lost_tol_rel */
  GYRO_DESIGN_FAULT_OUT,      /* rate.fault_out_v against the valid span */
  GYRO_DESIGN_BIAS_SLOPE,     /* rate.bias_c*, rate.p_range_deg */
  GYRO_DESIGN_CONT_FREQ,      /* selftest.cont_freq_hz against rate.lpf_cutoff_hz */
  GYRO_DESIGN_CONT_EXPECT,    /* selftest.cont_expect_dps, selftest.tol_rel */
  GYRO_DESIGN_QUAD_NULL,      /* quad.* against each other, the update rate, the DAC */
  GYRO_DESIGN_SENSE_FB, /* sense.fb_v_max_v, sense.fb_bias_v against the DAC, each other */
  GYRO_DESIGN_SENSE_FR, /* sense.fr_*, sense.f0_hz, sense.q, sense.fb_gain_v_per_v2 */
  GYRO_DESIGN_SENSE_SELFTEST, /* selftest.cont_fr_v2 with sense.mode 1 */
  GYRO_DESIGN_SENSE_TUNE,     /* sense.tune*, against sense.mode and its calibration */
  GYRO_DESIGN_MODULE,         /* a module refused its part: a value outside its range */
  GYRO_DESIGN_STATUS_COUNT
} gyro_design_status_t;

/* Turn parameter values into module configurations, checking that every module
 * accepts its part. Returns GYRO_DESIGN_OK, or the check that failed (then *d is
 * untouched). Background only (double precision, libm). */
gyro_design_status_t gyro_design(const param_values_t *v, gyro_design_t *d);

/* The reason for a status, for `set` and the boot report: a constant string naming
 * the parameters at fault ("drive.freq_hz must be below sys.fs_hz / 4"); "" for
 * GYRO_DESIGN_OK and for values outside the enum. Never NULL, never allocated. */
const char *gyro_design_reason(gyro_design_status_t s);

/* The derived fields of every module's configuration from the designer's (background),
 * and the check that every module accepts its part: a design that gyro_apply could not
 * apply is rejected here, where the error can be reported. Returns 0, or -1. */
int gyro_design_complete(gyro_design_t *d);

#endif /* GYRO_DESIGN_H */
