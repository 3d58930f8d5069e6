/* Configuration of the gyro firmware in physical units: what the parameter table maps
 * onto, and what gyro_design() turns into per-tick coefficients (outside the ISR).
 *
 * Phase conventions (used throughout firmware/gyro):
 *   The NCO phase phi(k) = 2 pi f_drive k / fs defines the reference frame. A pickoff
 *   voltage v = w_s sin(phi) + w_c cos(phi) (the LMSD weights, (5-1)) is the phasor
 *   Z = w_s + j w_c, with v = Im{Z e^{j phi}}; its amplitude is |Z| and its phase
 *   arg(Z) = atan2(w_c, w_s).
 *   The drive force is F = f_cmd cos(phi + P) (in units of Ks * V^2): P is the force
 *   phase, the output of the phase loop and the temperature signal of the sensorless
 *   compensation (thesis 7.3). Half-frequency drive realises it with a voltage phase of
 *   P/2 (6-25), DC+AC drive with a voltage phase of P.
 */
#ifndef GYRO_CFG_H
#define GYRO_CFG_H

#include <stdint.h>

typedef enum {
  GYRO_DRIVE_HALF_FREQ = 0, /* U1 = A cos(phi/2 + P/2), U2 = A sin(phi/2 + P/2), (6-18) */
  GYRO_DRIVE_DC_AC = 1      /* U1 = D + A cos(phi + P), U2 = D - A cos(phi + P), (6-20) */
} gyro_drive_mode_t;

typedef struct {
  float fs_hz; /* sample rate of the tick */

  /* Drive mode: fixed-frequency drive (thesis 6.4). */
  float drive_freq_hz;
  gyro_drive_mode_t drive_mode;
  float drive_amp_set_v;     /* setpoint of the demodulated drive pickoff amplitude, V at the ADC */
  float drive_phase_set_deg; /* setpoint of the drive pickoff phase arg(Z_drive) */
  float drive_u_max_v;       /* largest drive electrode voltage amplitude (DAC +-15 V) */
  float drive_dc_bias_v;     /* D of the DC+AC drive */
  float drive_p_init_deg;    /* force phase P the acquisition starts from */

  /* Identified drive-mode model (self-calibration, 6-12/6-17) and loop design targets. */
  float plant_f0_hz;          /* undamped drive resonance */
  float plant_q;              /* drive-mode quality factor */
  float plant_gain_v_per_v2;  /* pickoff volts per Ks*V^2 of force amplitude at resonance */
  float amp_loop_bw_hz;       /* closed-loop bandwidth of the amplitude loop */
  float phase_loop_bw_hz;     /* closed-loop bandwidth of the phase loop */
  /* Manual PI gains: used when nonzero, else designed from the model above. */
  float amp_kp, amp_ki;       /* Ks*V^2 per V of amplitude error; per V*s */
  float phase_kp, phase_ki;   /* rad of force phase per rad of phase error; per rad*s */

  /* Demodulation (5-5). */
  float mu_drive, mu_sense;

  /* Rate channel (ch. 5, 7). */
  float demod_phase_deg;     /* angle of the Coriolis phasor relative to the drive phasor */
  float rate_lpf_hz;         /* output low-pass cut-off, Butterworth */
  uint32_t rate_lpf_order;   /* even, 2..8 */
  float rate_scale_dps;      /* deg/s per unit of the normalised rate (sense/drive ratio) */
  float bias_c_dps[4];       /* bias(P) = c0 + c1 P + c2 P^2 + c3 P^3, P in degrees */
  float sf_c[4];             /* scale factor(P) = 1 + c1 P + c2 P^2 + c3 P^3 (c[0] unused) */
  float p_lpf_hz;            /* low-pass of P before it is used as a temperature */
  float rate_out_v_per_dps;  /* analog rate output scale on the DAC (thesis 7.25 mV/(deg/s)) */

  /* Supervisor. */
  float lock_tol_rel;        /* |A - A_set| / A_set to declare lock */
  float lock_phase_tol_deg;
  float lock_hold_s;         /* time inside tolerance before LOCKED */
  float lost_tol_rel;        /* |A - A_set| / A_set beyond which lock is lost */
  float lost_hold_s;
  float amp_trip_rel;        /* over-amplitude trip, A / A_set */
  float sat_hold_s;          /* time at the drive limit while LOCKED before a fault */
  float retry_s;             /* drive-off time after a fault before re-acquiring */
  uint32_t clip_max_count;   /* consecutive rail codes that count as clipping */
  uint32_t autostart;        /* start acquiring at power-on */
} gyro_cfg_t;

/* The defaults: thesis linear gyro, air package (system.md section 2), with the drive
 * loops designed for it. */
void gyro_cfg_default(gyro_cfg_t *cfg);

#endif /* GYRO_CFG_H */
