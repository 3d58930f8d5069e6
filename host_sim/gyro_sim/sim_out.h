/* gyro-sim outputs: the CSV trace and the JSON of parameters and figures.
 *
 * CSV columns (stable; more may be appended, never reordered):
 *   t_s, rate_true_dps, rate_dps, quad_dps, drive_amp, drive_phase_deg, p_deg,
 *   t_ambient_c, t_struct_c, t_board_c, u1_v, u2_v, adc_drive_v, adc_sense_v, flags,
 *   mode, t_circuit_c, rate_unc_dps, p_f_deg, drive_amp_true_m, f_cmd_v2, rate_valid,
 *   rate_out_v, f_drive_hz, rate_invalid, clock_ppm, f_drive_true_hz, aout_v, quad_true_dps,
 *   fb_u1_v, fb_u2_v, quadnull_v, tune_v, t_board_meas_c, board_c
 * drive_amp (V) and drive_phase_deg are the firmware's demodulated drive pickoff
 * (amplitude and arg against the NCO); u1_v/u2_v what it wrote to the drive DAC; adc_*
 * the analog voltages at the ADC inputs; flags the GYRO_FLAG_* bits; quad_true_dps the
 * plant's true quadrature (plant_truth_t), to set beside the firmware's quad_dps; fb_u1_v ..
 * tune_v the sense electrodes' mean voltages over the sample as the plant sees them
 * (plant_truth_t elec_mean_v, quadnull_v: signed, +V1 or -V2), 0 on a part without
 * them; t_board_meas_c the board temperature sensor's latest result, the code the firmware
 * reads times its LSB (plant_truth_t board_meas_c; board_sensor.h): "nan" before its first
 * 1 s conversion, on a plant without the sensor (plant.board_sensor 0) and from
 * plant.board_sensor_fault_s on, so it stands beside t_board_c, the node it reads;
 * board_c the same reading as the firmware took it (gyro_out_t, nan before its first).
 * In open-loop runs the firmware columns are 0.
 */
#ifndef SIM_OUT_H
#define SIM_OUT_H

#include <stdio.h>

#include "gyro/gyro.h"
#include "plant/plant.h"

typedef struct {
  FILE *f;
} sim_csv_t;

int sim_csv_open(sim_csv_t *c, const char *path, char *err, size_t err_len);
/* One row; o NULL in open loop (the firmware's columns are 0). f_drive_hz: the drive
 * frequency the firmware's NCO runs at (its step to full precision), or in open loop the
 * frequency of the drive the simulator generates. */
void sim_csv_row(sim_csv_t *c, const plant_truth_t *tr, const gyro_out_t *o, double f_drive_hz);
void sim_csv_close(sim_csv_t *c);

#endif /* SIM_OUT_H */
