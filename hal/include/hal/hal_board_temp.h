/* The board's temperature sensor: a TI TMP117 on the board's I2C bus, converting on its
 * own at its factory setting (continuous conversion, eight averages, a 1 s cycle; data
 * sheet SNOSD82D 7.4), read by the background loop, never by the sample ISR. A result is
 * the sensor's 16-bit two's-complement code, BOARD_TEMP_LSB_C degC per LSB (7.3.3).
 *
 * The firmware fuses it with the drive phase's thermometer (firmware/gyro/board_therm.h):
 * the phase reads the sensor head's structure within seconds but carries the drive
 * pickoff's phase flicker; the board sensor reads the circuit's side of the part without
 * that flicker, minutes late. */
#ifndef HAL_BOARD_TEMP_H
#define HAL_BOARD_TEMP_H

#include <stdint.h>

typedef enum {
  HAL_BOARD_TEMP_NONE = 0,  /* nothing new: a conversion or a bus transfer is under way */
  HAL_BOARD_TEMP_NEW = 1,   /* *code holds a result not returned before */
  HAL_BOARD_TEMP_FAULT = 2, /* the sensor did not answer, or the bus failed; the HAL has
                              * reset the bus and tries again on the next calls */
  HAL_BOARD_TEMP_ABSENT = 3 /* the board (or the host's plant) has no sensor */
} hal_board_temp_event_t;

/* Set up the bus and the sensor. Non-blocking; 0, or a negative value if the bus cannot
 * be set up (every later poll then says ABSENT). */
int hal_board_temp_start(void);

/* Background: advance the bus's transfers by what is ready now and never wait. On NEW,
 * *code is the latest finished conversion; otherwise *code is not written. */
hal_board_temp_event_t hal_board_temp_poll(int16_t *code);

#endif /* HAL_BOARD_TEMP_H */
