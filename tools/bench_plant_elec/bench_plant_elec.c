/* Per-sample cost of the electrical half of the plant with default settings: DAC
 * (4 channels, filtered), actuator (two 1/f sources), drive and sense pickoffs, ADC.
 * The mechanics is replaced by an analytic motion so only these modules are timed.
 * Usage: bench_plant_elec [samples]   (default 2,000,000) */
#define _POSIX_C_SOURCE 199309L /* clock_gettime */
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <time.h>

#include "plant/actuator.h"
#include "plant/adc.h"
#include "plant/dac.h"
#include "plant/pickoff.h"
#include "plant/plant_const.h"

static double now_s(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
  const long n = (argc > 1) ? atol(argv[1]) : 2000000L;
  dac_cfg_t dc;
  dac_default_cfg(&dc);
  actuator_cfg_t ac;
  actuator_default_cfg(&ac);
  pickoff_cfg_t pdc, psc;
  pickoff_default_cfg(&pdc, PICKOFF_DRIVE);
  pickoff_default_cfg(&psc, PICKOFF_SENSE);
  adc_cfg_t adcc;
  adc_default_cfg(&adcc);
  dac_t d;
  actuator_t a;
  pickoff_t pd, ps;
  adc_t adc;
  if (dac_init(&d, &dc) || actuator_init(&a, &ac, 1u) || pickoff_init(&pd, &pdc, 298.15, 1u) ||
      pickoff_init(&ps, &psc, 298.15, 1u) || adc_init(&adc, &adcc)) {
    fprintf(stderr, "init failed\n");
    return 1;
  }
  const double T = 1.0 / 50000.0, w = 2.0 * PLANT_PI * 1489.9;
  /* precomputed rotation for the motion and the drive voltages (no libm in the loop) */
  const double cw = cos(w * T), sw = sin(w * T), ch = cos(0.5 * w * T), sh = sin(0.5 * w * T);
  double c1 = 1.0, s1 = 0.0, c2 = 1.0, s2 = 0.0, sink = 0.0;
  const double t0 = now_s();
  for (long k = 0; k < n; k++) {
    hal_dac_frame_t fr;
    hal_dac_frame_midscale(&fr);
    fr.code[0] = dac_v_to_code(10.0 * c2);
    fr.code[1] = dac_v_to_code(10.0 * s2);
    fr.code[2] = (uint16_t)HAL_DAC_CODE_MID;
    fr.code[3] = (uint16_t)HAL_DAC_CODE_MID;
    dac_write(&d, &fr);
    dac_out_t o;
    dac_step(&d, &o);
    actuator_out_t f;
    actuator_step(&a, &o, &f);
    const double y = 1e-5 * s1, vy = 1e-5 * w * c1;
    const double vd = pickoff_step(&pd, y, vy, &o);
    const double vs = pickoff_step(&ps, 6e-8 * c1, -6e-8 * w * s1, &o);
    hal_adc_frame_t af;
    adc_convert_frame(&adc, vd, vs, &af);
    sink += f.f_drive_mps2 + af.drive + af.sense;
    const double nc1 = c1 * cw - s1 * sw, ns1 = s1 * cw + c1 * sw;
    const double nc2 = c2 * ch - s2 * sh, ns2 = s2 * ch + c2 * sh;
    c1 = nc1;
    s1 = ns1;
    c2 = nc2;
    s2 = ns2;
  }
  const double dt = now_s() - t0;
  printf("%ld samples: %.1f ns/sample (DAC + actuator + 2 pickoffs + ADC), %.0fx real time at 50 kHz\n",
         n, 1e9 * dt / (double)n, (double)n * T / dt);
  printf("(checksum %.6g)\n", sink);
  return 0;
}
