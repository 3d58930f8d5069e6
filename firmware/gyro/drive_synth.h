/* Drive voltage synthesis: force command (f_cmd, P) -> electrode voltages U1, U2.
 *
 * The electrostatic force is F = Ks (U1^2 - U2^2) (6-7); f_cmd is in Ks*V^2.
 *   Half-frequency drive (6-18, 6-19, 6-25):
 *     A = sqrt(f_cmd), U1 = A cos(phi/2 + P/2), U2 = A sin(phi/2 + P/2)
 *     => U1^2 - U2^2 = A^2 cos(phi + P). The voltages sit at wc/2, so their feedthrough
 *     into the pickoffs and their low-frequency noise land at wc/2 and are rejected by
 *     demodulation at wc (thesis 6.3).
 *   DC+AC drive (6-20, 6-21):
 *     A = f_cmd / (4 D), U1 = D + A cos(phi + P), U2 = D - A cos(phi + P)
 *     => U1^2 - U2^2 = 4 D A cos(phi + P) = f_cmd cos(phi + P).
 * Both give the same force for the same (f_cmd, P), so the loops need no retuning when
 * the scheme changes. The half phase comes from the NCO's half-rate accumulator, so the
 * voltage phase stays continuous across the main accumulator's wrap.
 *
 * The command changes at the drive loops' rate (fs / GYRO_BLOCK), the waveform every
 * sample: drive_synth_set() turns (f_cmd, P) into an amplitude phasor, A turned by the
 * phase offset (the square root, the radian-to-phase conversion and one table lookup,
 * once per command), and drive_synth_step() turns the NCO's unit phasor by it: four
 * multiplies per sample, no table lookup (the NCO's one lookup serves every synthesis).
 */
#ifndef DRIVE_SYNTH_H
#define DRIVE_SYNTH_H

#include <math.h> /* NAN (a constant, no call) */
#include <stdint.h>

#include "dsp/nco.h"
#include "dsp/sincos.h"

typedef enum {
  GYRO_DRIVE_HALF_FREQ = 0, /* U1 = A cos(phi/2 + P/2), U2 = A sin(phi/2 + P/2), (6-18) */
  GYRO_DRIVE_DC_AC = 1      /* U1 = D + A cos(phi + P), U2 = D - A cos(phi + P), (6-20) */
} gyro_drive_scheme_t;

/* The synthesiser's state. Its scheme and electrode levels are the drive's own, taken
 * from the configuration by drive_synth_init (gyro_apply: at a design change that keeps
 * the scheme, or with the drive off; the scheme itself changes only with the drive off),
 * so that the per-sample step reads nothing but this. */
typedef struct {
  gyro_drive_scheme_t scheme;
  float dc_bias_v; /* D */
  float u_max_v;   /* largest voltage magnitude on either electrode */
  float inv_4d;    /* 1 / (4 D) */
  /* The current command: its amplitude phasor (A, or a + j b of drive_synth_set_phasor)
   * turned by its phase offset off, so that the waveform is
   * (re + j im) e^(j theta) with theta the NCO's phase (DC+AC) or half phase: */
  float re_v, im_v;
  uint32_t off;              /* the phase offset: P/2 (half-freq) or P (DC+AC), 2^32 = 2 pi */
  float f_set_v2, p_set_rad; /* the command as last passed to drive_synth_set (NaN: none) */
  float p_turn_rad;          /* whole turns taken off P before the conversion (hysteresis) */
} drive_synth_t;

typedef struct {
  gyro_drive_scheme_t scheme;
  float dc_bias_v;
  float u_max_v;
} drive_synth_cfg_t;

/* Returns 0, or -1 (nothing changed) for a bad configuration (DC+AC needs
 * 0 < D < u_max). The command starts at zero force. */
int drive_synth_init(drive_synth_t *ds, const drive_synth_cfg_t *cfg);

/* Largest force command the electrodes can deliver (Ks*V^2). */
float drive_synth_f_cmd_max(const drive_synth_t *ds);

/* A new force command (f_cmd in Ks*V^2, negative = 0; P in rad). The conversion needs
 * |P| < 2 pi: a P that moves continuously beyond +-1.5 pi is taken modulo 2 pi, with
 * hysteresis, so that the voltages' sign flip of a whole turn of P (the force is
 * unchanged, (6-25)) happens once, not on every noise crossing. */
void drive_synth_set(drive_synth_t *ds, float f_cmd_v2, float p_rad);

/* A force command as a phasor (f_re + j f_im, Ks*V^2) in a frame turned by frame_rad
 * (the force |F| cos(phi + frame + arg F), |frame| as drive_synth_set's P), for a loop
 * that computes its force as a complex number (sense_fr.h), without the arc tangent of
 * arg F; in four steps, so that a sample interrupt can put them on four ticks, one
 * long operation each: |F| (drive_synth_phasor_mag: a square root), the root
 * (drive_synth_phasor_root: another), the voltage phasor a + j b in the frame
 * (drive_synth_phasor_parts: the divide), then the command (drive_synth_set_phasor: the
 * frame's phase and its turn of a + j b, a table lookup), whose waveform is
 * drive_synth_step's. */
typedef struct {
  float f_re_v2, f_im_v2; /* F (0 for a non-finite one) */
  float mag_v2;           /* |F| */
  float root_v;           /* the larger part of sqrt(F) in magnitude (half-frequency) */
  float a_v, b_v;         /* the voltage phasor in the frame: sqrt(F), or F / (4 D) */
} drive_synth_phasor_t;
void drive_synth_phasor_mag(drive_synth_phasor_t *ph, float f_re_v2, float f_im_v2);
void drive_synth_phasor_root(const drive_synth_t *ds, drive_synth_phasor_t *ph);
void drive_synth_phasor_parts(const drive_synth_t *ds, drive_synth_phasor_t *ph);
void drive_synth_set_phasor(drive_synth_t *ds, const drive_synth_phasor_t *ph, float frame_rad);

/* No force from the next sample on (amplitude 0; in DC+AC the bias alone), without the
 * square root and phase conversion of drive_synth_set: a fault's clear, on a tick near
 * its budget. The next drive_synth_set or _follow sets a command again. */
static inline void drive_synth_silence(drive_synth_t *ds)
{
  ds->re_v = ds->im_v = 0.0f;
  ds->f_set_v2 = ds->p_set_rad = NAN;
}

/* drive_synth_set, skipped when the command is the one last set (a NaN never is, and
 * drive_synth_init forgets it). For a caller that passes a command every tick though it
 * changes rarely: the self-calibration sweep, which would otherwise pay the square root
 * and the phase conversion on every sample. */
static inline void drive_synth_follow(drive_synth_t *ds, float f_cmd_v2, float p_rad)
{
  if (f_cmd_v2 != ds->f_set_v2 || p_rad != ds->p_set_rad) {
    drive_synth_set(ds, f_cmd_v2, p_rad);
  }
}

/* One sample of the electrode voltages for the current command (drive_synth_set or
 * drive_synth_set_phasor), from the NCO's output at this sample: the command's phasor
 * turns the unit phasor at the half phase (half-frequency: U1 + j U2 is the voltage
 * phasor, (6-25)) or at the phase (DC+AC: its real part is the AC voltage, (6-20)). */
static inline void drive_synth_step(const drive_synth_t *ds, const nco_out_t *ref, float *u1_v,
                                    float *u2_v)
{
  if (ds->scheme == GYRO_DRIVE_DC_AC) {
    const float ac = ds->re_v * ref->cos_wc - ds->im_v * ref->sin_wc;
    *u1_v = ds->dc_bias_v + ac;
    *u2_v = ds->dc_bias_v - ac;
  } else {
    *u1_v = ds->re_v * ref->cos_half - ds->im_v * ref->sin_half;
    *u2_v = ds->re_v * ref->sin_half + ds->im_v * ref->cos_half;
  }
}

#endif /* DRIVE_SYNTH_H */
