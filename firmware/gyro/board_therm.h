/* The board thermometer (board.fuse 1): the board sensor's model of the bias, fused with
 * the compensation in P (rate_channel.h) below a crossover.
 *
 * P reads the sensor head's structure within seconds, but carries the drive pickoff's
 * phase flicker (1/f), which the compensation turns into rate at the bias slope: above
 * 10 s the compensated output's noise is P's (docs/compensation-noise.md). And where the
 * bias is made on the circuit's side of the part (a loose thermal coupling, a pickoff
 * gain's tempco), P reads the wrong node. The board sensor (hal_board_temp.h) has no
 * flicker and sits on the circuit's side, but reads the board, minutes late.
 *
 * In a network of lumped thermal nodes driven by one input (the surroundings), every node
 * is the board's temperature through two zeros over two poles; so is the bias, a mix of
 * node temperatures through the part's static laws. The model of the bias is that
 * transfer of unit DC gain, then a cubic:
 *     y = H(s) b,  H = (1 + s tz1)(1 + s tz2) / ((1 + s tp1)(1 + s tp2))
 *     M = c0 + c1 (y - ref) + c2 (y - ref)^2 + c3 (y - ref)^3
 * fitted by the calibration flow on its chamber run at rest (gyrotools/boardcal.py) to
 * the linearised output at rest, the bias as the pickoff delivers it (a pickoff gain's
 * tempco is in it, on the circuit's node); the compensation's scale factor sf (in P)
 * makes it the output's, sf M. The fused bias keeps P's compensation above the crossover
 * and the model below it:
 *     B = B_s - LP_T(B_s - sf M)
 * B_s the compensation's static bias in P, its cubic in P_c (the gradient term and the
 * fast path left out: they turn P's flicker into rate above the crossover, 1.13 times the
 * uncompensated noise at 10 s on a loose part when they stayed in), LP_T a first-order
 * low-pass of board.crossover_s. P's flicker is in excess from 10 s on, so the crossover
 * lies below that; above it the fused bias passes T times the rate of change of P's
 * disagreement with the model (1 s: gyrotools/boardcal.py, CROSSOVER_S, the trade). The sample path keeps its bias B_P (gradient
 * term and fast path included); the correction is w (B - B_P).
 *
 * The model knows one heat input, the surroundings; after a power-on the board's own
 * dissipation is a second one, so the weight w is 0 until board.start_s after power-on
 * and rises linearly to 1 over board.fade_s (the output is P's own until then).
 *
 * Never a valid wrong rate: with w > 0 the rate is not valid (RATE_INVALID_BOARD_TEMP)
 * while the sensor has not given a reading for board.stale_s, and while the model's
 * variable y lies outside the span the model was fitted on (board.min_c .. max_c), and
 * while LP_T(B_s - sf M) exceeds board.agree_dps: a sensor that reads but is wrong (stuck,
 * come off the board) parts the model from P by more than either misses the part.
 *
 * Background only (app_board.c), at a fixed step of BOARD_THERM_STEP_S counted in sample
 * ticks; the sample path adds the correction w (B - B_P) to the compensation's bias when
 * it refreshes it (gyro_block.c, p_refresh). The lead-lag runs in its lag form,
 * e = u - LP(u) (comp_filters.h's reason: a low-pass of minutes on a temperature in float
 * would have a dead band). */
#ifndef GYRO_BOARD_THERM_H
#define GYRO_BOARD_THERM_H

#include <stdint.h>

/* The step of the background's filters: a tenth of the sensor's 1 s cycle. */
#define BOARD_THERM_STEPS_PER_S 10u
#define BOARD_THERM_STEP_S (1.0f / (float)BOARD_THERM_STEPS_PER_S)

typedef enum {
  BOARD_THERM_OFF = 0, /* board.fuse 0: P's compensation alone */
  BOARD_THERM_WAIT,    /* no reading yet */
  BOARD_THERM_OK,      /* the model follows the sensor */
  BOARD_THERM_STALE,   /* no reading for board.stale_s (a fault, or the sensor absent) */
  BOARD_THERM_RANGE,   /* the model's variable is outside the fitted span */
  BOARD_THERM_DISAGREE /* P's bias and the model part by more than board.agree_dps */
} board_therm_state_t;

typedef struct {
  uint32_t on;        /* board.fuse */
  float r[2];         /* tz / tp of each section: H = prod (r + (1 - r) / (1 + s tp)) */
  float a[2];         /* 1 - exp(-step / tp): each section's low-pass per step */
  float ref_c;        /* the cubic's reference */
  float c[4];         /* c0 .. c3, deg/s per degC^k */
  float min_c, max_c; /* the span of y the model was fitted on */
  float lp_a;         /* 1 - exp(-step / crossover) */
  float agree_dps;    /* the most |LP_T(B_s - sf M)| may be */
  uint32_t start_steps, fade_steps, stale_steps;
} board_therm_cfg_t;

typedef struct {
  uint32_t have;      /* a reading has come since the start */
  float x_c;          /* the latest reading, held */
  float in[2];        /* each section's input at the latest step (deviation from ref) */
  float e[2];         /* each section's input less its low-pass (the lag form) */
  float y_c;          /* the lead-lag's output, the model's variable */
  float model_dps;    /* M(y) */
  float d_dps;        /* LP_T(B_s - sf M) */
  uint32_t d_on;      /* d_dps runs (a settled B_P since the last unsettled one) */
  float w;            /* the fusion's weight, 0..1 */
  float corr_dps;     /* w (B - B_P): what the sample path adds to its bias */
  uint32_t steps;     /* steps since power-on (saturating) */
  uint32_t age_steps; /* steps since the latest reading (saturating) */
  uint32_t readings;  /* readings taken */
  uint32_t faults;    /* bus faults the HAL reported */
  uint32_t absent;    /* the HAL says the board has no sensor */
  board_therm_state_t state;
} board_therm_t;

/* The configuration from the parameters (design time, double precision). tz, tp > 0. */
void board_therm_design(board_therm_cfg_t *c, uint32_t on, const float tz_s[2],
                        const float tp_s[2], float ref_c, const float c_dps[4], float min_c,
                        float max_c, float crossover_s, float start_s, float fade_s,
                        float stale_s, float agree_dps);

/* Power-on: nothing read, weight 0. */
void board_therm_init(board_therm_t *s);

/* A finished conversion, degC. The first starts the lead-lag in its steady state. */
void board_therm_reading(const board_therm_cfg_t *c, board_therm_t *s, float x_c);

/* The compensation in P at a step, and whether it is the part's: settled 1 (the drive
 * locked, P settled and within its span), 0 not (the crossover's low-pass starts again
 * from the next settled step), BOARD_THERM_BIAS_HOLD not read (it holds). */
#define BOARD_THERM_BIAS_HOLD 2u
typedef struct {
  float dps;        /* B_P, the sample path's bias */
  float static_dps; /* B_s, its cubic in P_c alone */
  float sf;         /* its scale factor */
  uint32_t settled;
} board_therm_bias_t;

/* One step of BOARD_THERM_STEP_S: the lead-lag on the held reading, the model, the
 * crossover's low-pass of (B_s - sf M), the weight, the state, the correction. */
void board_therm_step(const board_therm_cfg_t *c, board_therm_t *s, board_therm_bias_t b);

/* Whether the rate must not be valid: the fusion weighs in and the sensor or the model
 * cannot be trusted (the header's comment). */
static inline uint32_t board_therm_invalid(const board_therm_t *s)
{
  return s->w > 0.0f && s->state != BOARD_THERM_OK;
}

const char *board_therm_state_name(board_therm_state_t st);

#endif /* GYRO_BOARD_THERM_H */
