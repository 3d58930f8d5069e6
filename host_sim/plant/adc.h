/* 16-bit bipolar ADC of the reference board (board.h: +-5 V, two's complement,
 * one code = 10 V / 65536), for the host plant.
 *
 *   code = round(v / lsb) (nearest, half away from zero), lsb = full_scale_v / 32768
 *   saturated to [-32768, 32767]; every saturated conversion counts as a clip event of
 *   its channel (an input beyond the last code's rounding interval). A non-finite
 *   input converts to 0 and counts as a fault of its channel.
 * Quantisation noise is lsb/sqrt(12) rms (4-26): 44 uV, 0.28 uV/sqrt(Hz) one-sided at
 * 50 kHz (4-30), far below the Brownian floor (~10.6 uV/sqrt(Hz) at the ADC, §4.6.1).
 */
#ifndef PLANT_ADC_H
#define PLANT_ADC_H

#include <stdint.h>

#include "hal/hal_adc.h"

#define ADC_CH_DRIVE 0
#define ADC_CH_SENSE 1
#define ADC_NCH 2

typedef struct {
  double full_scale_v; /* +-full scale; the board's reference gives HAL_ADC_FULL_SCALE_V */
} adc_cfg_t;

typedef struct {
  adc_cfg_t cfg;
  double inv_lsb;                /* codes per volt */
  uint64_t clip_count[ADC_NCH];  /* saturated conversions */
  uint64_t fault_count[ADC_NCH]; /* non-finite inputs */
} adc_t;

/* full_scale_v = HAL_ADC_FULL_SCALE_V (5 V). */
void adc_default_cfg(adc_cfg_t *cfg);

/* Validates (0 < full_scale_v <= 100), clears the counters. Returns 0 or -1 (a unchanged). */
int adc_init(adc_t *a, const adc_cfg_t *cfg);

/* Convert one channel (ADC_CH_DRIVE or ADC_CH_SENSE; any other channel returns 0 and
 * counts nothing). */
int16_t adc_convert(adc_t *a, int ch, double v);

/* Convert both pickoffs into the HAL frame the firmware reads. */
void adc_convert_frame(adc_t *a, double drive_v, double sense_v, hal_adc_frame_t *frame);

/* Clear the clip and fault counters. */
void adc_clear_counts(adc_t *a);

/* Volts of a code (ideal, for tests and logs). */
double adc_code_to_v(const adc_t *a, int16_t code);

#endif /* PLANT_ADC_H */
