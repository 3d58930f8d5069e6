/* 16-bit bipolar ADC of the reference board (board.h: +-5 V, two's complement,
 * one code = 10 V / 65536), for the host plant.
 *
 *   code = round(v / lsb) (nearest, half away from zero), lsb = full_scale_v / 32768
 *   saturated to [-32768, 32767]; every saturated conversion counts as a clip event of
 *   its channel (an input beyond the last code's rounding interval). A non-finite
 *   input converts to 0 and counts as a fault of its channel.
 * Quantisation noise is lsb/sqrt(12) rms (4-26): 44 uV, 0.28 uV/sqrt(Hz) one-sided at
 * 50 kHz (4-30), far below the Brownian floor (~10.6 uV/sqrt(Hz) at the ADC, §4.6.1).
 *
 * Imperfections, each off at zero:
 *   INL (cfg.inl, inl.h): code = round(x + INL(c)), x = v / lsb, c the code x would
 *   ideally give (offset binary): the bow and the per-code pattern of a 16-bit SAR
 *   (one converter for both channels, as the board's multiplexed part).
 *   Reference (adc_set_ref): with the shared reference off by r (vref.h), the converter
 *   reads x = v / (lsb (1 + r)).
 *   Aperture jitter (cfg.aperture_jitter_s): the conversion clock's random timing error,
 *   one draw per frame, common to both channels (simultaneous sampling); the plant hands
 *   it to the pickoffs, which alone know the signal's slope (pickoff_step_at). On a sine
 *   of amplitude A at f it is noise of rms 2 pi f A sigma_t / sqrt(2) (Kester (ed.), The
 *   Data Conversion Handbook, 2005, §2.3: SNR = -20 log10(2 pi f sigma_t)). The pickoffs'
 *   own pick_*_jitter_s are the independent per-channel part (track-and-hold).
 */
#ifndef PLANT_ADC_H
#define PLANT_ADC_H

#include <stdint.h>

#include "hal/hal_adc.h"
#include "plant/inl.h"
#include "plant/rng.h"

#define ADC_CH_DRIVE 0
#define ADC_CH_SENSE 1
#define ADC_NCH 2
#define ADC_BITS 16
#define ADC_RNG_STREAM_INL 0x7401u
#define ADC_RNG_STREAM_APERTURE 0x7402u

typedef struct {
  double full_scale_v;      /* +-full scale; the board's reference gives HAL_ADC_FULL_SCALE_V */
  inl_cfg_t inl;            /* integral nonlinearity, LSB; zero: ideal */
  double aperture_jitter_s; /* rms timing error of the conversion clock, s; 0: none */
  uint64_t seed;            /* the run's jitter draws */
  uint64_t inl_seed;        /* the board's INL pattern: the same board in every run */
} adc_cfg_t;

typedef struct {
  adc_cfg_t cfg;
  double inv_lsb;                /* codes per volt */
  uint64_t clip_count[ADC_NCH];  /* saturated conversions */
  uint64_t fault_count[ADC_NCH]; /* non-finite inputs */
  double ref_rel;                /* reference error r of this frame (adc_set_ref) */
  inl_t inl;
  rng_t rng_aperture;
} adc_t;

/* full_scale_v = HAL_ADC_FULL_SCALE_V (5 V), ideal (no INL, no jitter). */
void adc_default_cfg(adc_cfg_t *cfg);

/* Validates (0 < full_scale_v <= 100, inl_check, 0 <= jitter <= 1e-3 s), clears the
 * counters. Returns 0 or -1 (a unchanged). */
int adc_init(adc_t *a, const adc_cfg_t *cfg);

/* The reference's relative error r for the conversions that follow (0: exact). */
void adc_set_ref(adc_t *a, double ref_rel);

/* The timing error of the next frame, s (0 without aperture jitter: nothing drawn). */
double adc_aperture_draw(adc_t *a);

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
