/* Converter scaling of the reference board, shared by the board HAL, the host stub and
 * the firmware core (which works in volts and converts at the HAL boundary).
 *
 *   ADC: 16-bit, bipolar +-5 V, two's complement, one code = 10 V / 65536.
 *        Drive and sense pickoffs are converted at every sample tick (started by the
 *        timer in hardware, never by software).
 *   DAC: quad 14-bit, offset binary over +-15 V after the output amplifier, one code =
 *        30 V / 16384. Channels: drive electrode U1, drive electrode U2, analog rate
 *        output, spare (sense feedback / self-test force).
 */
#ifndef HAL_CONVERTERS_H
#define HAL_CONVERTERS_H

#include <stdint.h>

#define HAL_ADC_BITS 16
#define HAL_ADC_FULL_SCALE_V 5.0f          /* +-5 V */
#define HAL_ADC_CODE_MAX 32767
#define HAL_ADC_CODE_MIN (-32768)
#define HAL_ADC_V_PER_CODE (HAL_ADC_FULL_SCALE_V / 32768.0f)

#define HAL_DAC_BITS 14
#define HAL_DAC_FULL_SCALE_V 15.0f         /* +-15 V */
#define HAL_DAC_CODE_MAX 16383u
#define HAL_DAC_CODE_MID 8192u
#define HAL_DAC_V_PER_CODE (2.0f * HAL_DAC_FULL_SCALE_V / 16384.0f)

/* DAC channel assignment of the reference board. */
enum hal_dac_channel {
  HAL_DAC_DRIVE_U1 = 0,
  HAL_DAC_DRIVE_U2 = 1,
  HAL_DAC_RATE_OUT = 2,
  HAL_DAC_SPARE = 3,
  HAL_DAC_NUM_CHANNELS = 4
};

#endif /* HAL_CONVERTERS_H */
