/* The application side of the board thermometer (board.fuse, gyro/board_therm.h): the
 * background takes the sensor's conversions from the HAL (hal_board_temp.h), steps the
 * fusion every BOARD_THERM_STEP_S of sample ticks, hands its correction of the bias to
 * the sample path (gyro_t.board_corr_dps, one word) and its verdict as a request
 * (APP_REQ_BOARD) when it changes. The sample path does nothing per tick for it. */
#ifndef APP_BOARD_H
#define APP_BOARD_H

#include "app/app_core.h"

/* Boot: the sensor's bus set up, the fusion at power-on. */
void app_board_init(app_t *a);

/* Background pass (from app_poll). */
void app_board_poll(app_t *a);

#endif /* APP_BOARD_H */
