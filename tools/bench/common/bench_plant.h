/* A minimal drive/sense plant for the benchmarks: ADC frames that keep gyro_tick in its
 * LOCKED steady state, so the counts are those of the normal branch paths.
 *
 * Envelope model of the drive resonance, the one the loop designer assumes: amplitude and
 * phase of the drive pickoff follow the force command and the force phase P as
 * first-order lags of time constant tau = 2 Q / wn ((6-12), (6-17)):
 *     a(k+1)     = a(k) + (K f_cmd(k) - a(k)) T / tau          K = drive.cal_gain
 *     theta(k+1) = theta(k) + (P(k) + theta0 - theta(k)) T / tau
 * with theta0 = phase_set - p_init, so the phase loop locks at P = p_init. The pickoff
 * voltage is a sin(phi + theta) with phi the NCO phase of the same tick (the plant runs
 * its own copy of the gyro's NCO in lockstep), the sense pickoff a Coriolis-plus-
 * quadrature phasor proportional to it, both quantised to ADC codes with +-2 LSB of
 * uniform dither. Starts at rest at the setpoint amplitude (the loops still have to
 * bring the force up from 0).
 */
#ifndef BENCH_PLANT_H
#define BENCH_PLANT_H

#include <stdint.h>

#include "dsp/nco.h"
#include "gyro/gyro.h"
#include "hal/hal_adc.h"
#include "params/params.h"

typedef struct {
  nco_t nco;
  float amp_v;     /* drive pickoff amplitude a */
  float theta_rad; /* drive pickoff phase theta */
  float gain;      /* K, V per Ks V^2 */
  float alpha;     /* T / tau */
  float theta0_rad;
  float sense_re, sense_im; /* sense phasor relative to the drive phasor */
  uint32_t lcg;
} bench_plant_t;

/* Returns 0, or -1 if the design's NCO cannot be copied. */
int bench_plant_init(bench_plant_t *p, const gyro_design_t *d, const param_values_t *v);

/* The ADC frame of the next tick, given the gyro's loop outputs after the last one. */
void bench_plant_frame(bench_plant_t *p, const gyro_t *g, hal_adc_frame_t *adc);

#endif /* BENCH_PLANT_H */
