/* Phase slips of a closed-loop run (gyro-sim's figure phase_slips): the plant's true
 * drive phase, displacement against the force's fundamental (plant_truth_t), leaving the
 * value it had when the firmware locked by more than 90 deg, counted while the drive
 * runs; each slip re-references (a drift counts again every 90 deg).
 *
 * The phase judged is that of the force-weighted phasor F e^{j phi} averaged over
 * SLIP_AVG_S, not each sample's phi: the truth's force phasor covers only its last
 * millisecond (plant.truth_force_tau_s), and when the amplitude loop's command touches
 * zero for a block or two (a vacuum part at Q = 10^5 holds its amplitude with a few per
 * cent of the drive's range, and the command's noise reaches zero) that millisecond's
 * force is a small residue whose phase is anything (+170 deg measured), while the
 * motion, with a time constant 2Q/w of seconds, has not moved. Weighted by the force, a
 * moment without force carries no weight; a slip of the motion lasts far longer than
 * SLIP_AVG_S (7 drive periods, the drive time constant of a Q = 33 part) and is
 * counted. */
#ifndef GYRO_SIM_SLIP_H
#define GYRO_SIM_SLIP_H

#include <stdint.h>

#define SLIP_AVG_S 5e-3

typedef struct {
  double k_avg;     /* the average's weight per sample */
  int armed;        /* locked once since the drive (re)started */
  double re, im;    /* the averaged phasor F e^{j phi} */
  double ref, prev; /* phase at the last re-reference; last phase (wrapped) */
  double unwrapped; /* last phase, unwrapped */
  uint32_t count;   /* slips */
} slip_t;

/* A counter for samples dt_s apart (> 0). */
void slip_init(slip_t *s, double dt_s);

/* One sample: running (the drive runs: ACQUIRE or LOCKED), locked (LOCKED), the true
 * drive phase (rad) and the amplitude of the force's fundamental (any unit, >= 0). */
void slip_sample(slip_t *s, int running, int locked, double phase_rad, double force);

#endif /* GYRO_SIM_SLIP_H */
