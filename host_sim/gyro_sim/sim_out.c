#include "sim_out.h"

#include <errno.h>
#include <string.h>

int sim_csv_open(sim_csv_t *c, const char *path, char *err, size_t err_len)
{
  c->f = fopen(path, "w");
  if (c->f == NULL) {
    snprintf(err, err_len, "%s: %s", path, strerror(errno));
    return -1;
  }
  fputs("t_s,rate_true_dps,rate_dps,quad_dps,drive_amp,drive_phase_deg,p_deg,t_ambient_c,"
        "t_struct_c,t_board_c,u1_v,u2_v,adc_drive_v,adc_sense_v,flags,mode,t_circuit_c,"
        "rate_unc_dps,p_f_deg,drive_amp_true_m,f_cmd_v2,rate_valid,rate_out_v,f_drive_hz,"
        "rate_invalid,clock_ppm,f_drive_true_hz,aout_v,quad_true_dps,fb_u1_v,fb_u2_v,quadnull_v,"
        "tune_v,t_board_meas_c,board_c\n",
        c->f);
  return 0;
}

void sim_csv_row(sim_csv_t *c, const plant_truth_t *tr, const gyro_out_t *o, double f_drive_hz)
{
  static const gyro_out_t none;
  if (o == NULL) o = &none;
  const double k0 = 273.15;
  fprintf(
      c->f,
      "%.6f,%.6f,%.7g,%.7g,%.7g,%.7g,%.7g,%.5f,%.5f,%.5f,%.5g,%.5g,%.6g,%.6g,%u,%u,%.5f,"
      "%.7g,%.7g,%.7g,%.6g,%u,%.6g,%.7f,%u,%.4f,%.7f,%.7g,%.7g,%.6g,%.6g,%.6g,%.6g,%.7f,%.7f\n",
      tr->t_s, tr->rate_dps, (double)o->rate_dps, (double)o->quad_dps, (double)o->drive_amp_v,
      (double)o->drive_phase_deg, (double)o->p_deg, tr->ambient_k - k0, tr->struct_k - k0,
      tr->board_k - k0, (double)o->u1_v, (double)o->u2_v, tr->adc_v[0], tr->adc_v[1], o->flags,
      o->mode, tr->circuit_k - k0, (double)o->rate_unc_dps, (double)o->p_f_deg, tr->drive_amp_m,
      (double)o->f_cmd_v2, o->rate_valid, (double)o->rate_out_v, f_drive_hz, o->rate_invalid,
      tr->clock_ppm,
      /* the NCO's frequency in true time: the firmware's, on a clock fast by e */
      f_drive_hz * (1.0 + 1e-6 * tr->clock_ppm),
      /* what a voltmeter on the analog output reads: the converter's level with its
           * INL, gain and offset, not the firmware's command (rate_out_v) */
      tr->dac_held_v[HAL_DAC_RATE_OUT],
      /* the plant's quadrature (k_q, its drift, the nulling electrodes), beside the
           * firmware's quad_dps */
      tr->quad_true_dps,
      /* the sense electrodes' voltages as the part sees them (DAC + series source,
           * plant.h), 0 on a part without them */
      tr->elec_mean_v.fb_u1_v, tr->elec_mean_v.fb_u2_v, tr->quadnull_v, tr->elec_mean_v.tune_v,
      /* the board sensor's latest result as the firmware reads it: whole LSB of
           * 2^-7 degC, exact in 7 decimals; nan before its first, without one, in a fault */
      tr->board_meas_c,
      /* the board sensor's latest reading as the firmware took it (nan before one) */
      (double)o->board_c);
}

void sim_csv_close(sim_csv_t *c)
{
  if (c->f != NULL) {
    fclose(c->f);
    c->f = NULL;
  }
}
