/* The board's temperature sensor: a TI TMP117 (SNOSD82D) reading the thermal network's
 * board node (thermal.h, THERMAL_BOARD) (host plant, double precision). The model of the
 * offline study (tools/gyrotools/boardstudy.py: BoardSensor, sensor_reading;
 * docs/compensation-noise.md, "Thermal couplings, board sensor, fusion", item 2):
 *   - the sensor converts on its own, continuously, one result every BOARD_TEMP_CYCLE_S
 *     (board.h: 1 s, the factory setting, 7.4), the first one ready at a phase drawn
 *     uniformly within the first cycle;
 *   - a result is the mean of BOARD_SENSOR_AVERAGES conversions of
 *     BOARD_SENSOR_CONVERSION_S (eight of 15.5 ms, 124 ms of active time, the factory
 *     averaging, 7.4). The node moves over minutes, so that mean is the node's
 *     temperature at the middle of the active time, half of it (62 ms) before the result
 *     is ready;
 *   - plus the part's accuracy error, offset + slope (T - 25 degC) (6.5: within
 *     +-0.1 degC from -20 to 50 degC, +-0.2 degC from -40 to 100 degC; the plant's
 *     board_sensor_offset_c and board_sensor_slope);
 *   - plus the repeatability as Gaussian noise: about +-3 LSB for one conversion, read as
 *     +-2 sigma, 1.5 LSB, so 1.5 / sqrt(8) = 0.53 LSB for the mean of eight (6.5,
 *     7.3.2's noise histograms: about +-1 LSB with eight averages);
 *   - rounded to 1 LSB = BOARD_TEMP_LSB_C (7.8125 mdegC, 7.3.3; half to even, as the
 *     study's numpy.round), clamped to the 16-bit two's-complement result register, and
 *     held until the next result.
 * Not modelled: the sensor's self-heating (3.5 uA at 1 Hz), its drift over months, the bus
 * itself. From cfg.fault_s on the sensor does not answer: each result it would have
 * delivered is a failed read (HAL_BOARD_TEMP_FAULT), as a driver that reads once per
 * conversion sees it.
 *
 * Its random numbers (the phase, the noise) come from a stream of its own,
 * rng_seed(seed, BOARD_SENSOR_RNG_STREAM), drawn only when a result is made: every other
 * noise source of the plant draws the same sequence with the sensor or without it. */
#ifndef PLANT_BOARD_SENSOR_H
#define PLANT_BOARD_SENSOR_H

#include <stdint.h>

#include "hal/hal_board_temp.h"
#include "plant/rng.h"

#define BOARD_SENSOR_RNG_STREAM 0x7701u
#define BOARD_SENSOR_AVERAGES 8          /* AVG = 01, the factory setting (7.4) */
#define BOARD_SENSOR_CONVERSION_S 0.0155 /* one active conversion (6.5, 7.4) */
#define BOARD_SENSOR_SIGMA_LSB 1.5       /* one conversion's repeatability, 1 sigma */

typedef enum {
  BOARD_SENSOR_NONE = 0,  /* no sensor on the board: the HAL says ABSENT */
  BOARD_SENSOR_TMP117 = 1 /* the reference board's (board.h) */
} board_sensor_kind_t;

typedef struct {
  int kind;        /* board_sensor_kind_t */
  double offset_c; /* accuracy error at 25 degC */
  double slope;    /* its change per degC away from 25 degC (degC/degC) */
  double fault_s;  /* from this time on the sensor does not answer; negative: never */
} board_sensor_cfg_t;

typedef struct {
  board_sensor_cfg_t cfg;
  rng_t rng;
  double lsb_c, cycle_s;
  double half_active_s; /* half the averaging's active time: the middle to the result */
  double sigma_lsb;     /* the noise of one result (the mean of the averages), LSB */
  double first_mid_s;   /* middle of the first result's active time (may be < 0) */
  uint64_t made;        /* results made (their value latched at the middle) */
  uint64_t done;        /* results finished by the last board_sensor_step */
  double mid_s;         /* middle of the next result's active time */
  double end_s;         /* when the result made last is ready (pending) */
  int pending;          /* a result made, not ready yet */
  int16_t pend_code;    /* its code */
  int16_t code;         /* the latest finished result */
  double due_s;         /* board_sensor_step has work at or after this time */
} board_sensor_t;

/* 0 if kind is known, offset_c and slope finite and fault_s not NaN; else -1. */
int board_sensor_check(const board_sensor_cfg_t *cfg);

/* Validates, seeds (rng_seed(seed, BOARD_SENSOR_RNG_STREAM)) and draws the conversion's
 * phase. Returns 0, or -1 with s unchanged. Without a sensor nothing is drawn and
 * board_sensor_step is never due. */
int board_sensor_init(board_sensor_t *s, const board_sensor_cfg_t *cfg, uint64_t seed);

/* Whether board_sensor_step has work at time t_s (one compare, for the plant's sample). */
static inline int board_sensor_due(const board_sensor_t *s, double t_s)
{
  return t_s >= s->due_s;
}

/* Advance to time t_s with the board node at node_c (degC) from t_s on: the result under
 * way finishes when its time has come, and the next one's value is latched at the middle of
 * its active time. Call it at least once per half active time (the plant: every sample
 * on which it is due). */
void board_sensor_step(board_sensor_t *s, double t_s, double node_c);

/* The result register's code for a reading of lsb LSB: rounded half to even, clamped to
 * int16 (NaN reads as the largest code). */
int16_t board_sensor_round(double lsb);

/* The sensor as a reader sees it at time t_s (not before the last board_sensor_step):
 * HAL_BOARD_TEMP_ABSENT without a sensor; HAL_BOARD_TEMP_FAULT from cfg.fault_s on;
 * HAL_BOARD_TEMP_NONE before the first result; else HAL_BOARD_TEMP_NEW with *code the
 * latest finished result. *conversion (if not NULL) is the number of results finished by
 * t_s (1, 2, ...; counted on during a fault), so a reader tells a new one from the one it
 * has. *code is written on NEW only. */
hal_board_temp_event_t board_sensor_read(const board_sensor_t *s, double t_s, int16_t *code,
                                         uint64_t *conversion);

/* The latest finished result at t_s in degC, NaN when board_sensor_read says anything but
 * NEW (no sensor, not answering, nothing finished yet). */
double board_sensor_reading_c(const board_sensor_t *s, double t_s);

#endif /* PLANT_BOARD_SENSOR_H */
