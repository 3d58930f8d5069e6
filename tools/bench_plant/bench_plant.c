/* Per-sample cost of the plant with default settings (Brownian noise, 1/f drive noise,
 * thermal network, truth) driven by a half-frequency drive at resonance:
 *   static   constant rate and ambient
 *   sine     rate sine (100 deg/s, 10 Hz): the transition matrix is re-summed every sample
 *   cool     ambient falling at 0.05 K/s (a chamber ramp or the §7.3.2 cool-down)
 *   heat     heat-gun ambient (+60 K with a 2 s time constant): the circuit warms at up
 *            to 0.2 K/s and the pickoffs are re-discretised every 5 ms
 *   vibe     rate sine + sense-axis vibration (0.25 g, 100 Hz)
 *   mech     the mechanics alone (mech_step with a varying rate)
 * plus the cost of one re-discretisation of the mechanics (algebra exponential).
 * Usage: bench_plant [samples]   (default 2,000,000; CPU time of this process) */
#define _POSIX_C_SOURCE 199309L /* clock_gettime */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "plant/plant.h"
#include "plant/plant_const.h"

static double now_s(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static const double kPi = PLANT_PI;

/* precomputed DAC frames of one period pair (no libm in the timed loop) */
#define NFR 4096
static hal_dac_frame_t g_frames[NFR];

static double run_plant(int variant, long n, uint64_t *refreshes)
{
  plant_cfg_t c;
  plant_default_cfg(&c);
  static plant_t p;
  if (plant_init(&p, &c, 1u) != 0) {
    fprintf(stderr, "init: %s\n", plant_error(&p));
    exit(1);
  }
  if (variant >= 1) {
    plant_profiles_t pr = p.prof;
    if (variant == 1 || variant == 4) profile_sine(&pr.rate_dps, 0.0, 100.0, 10.0, 0.0);
    if (variant == 2) profile_ramp(&pr.ambient_k, c.temp_k, -0.05, 0.0, 1e6);
    if (variant == 3)
      profile_heat_cool(&pr.ambient_k, c.temp_k, c.temp_k + 60.0, 0.0, 1e6, 2.0, 20.0);
    if (variant == 4) {
      pr.accel_g.amp_g[ACCEL_AXIS_SENSE] = 0.25;
      pr.accel_g.freq_hz[ACCEL_AXIS_SENSE] = 100.0;
    }
    if (plant_set_profiles(&p, &pr) != 0) exit(1);
  }
  hal_adc_frame_t a;
  long sink = 0;
  const double t0 = now_s();
  for (long k = 0; k < n; k++) {
    plant_step(&p, &g_frames[k % NFR], &a);
    sink += a.drive ^ a.sense;
  }
  const double dt = now_s() - t0;
  *refreshes = plant_truth(&p)->mech_refreshes;
  if (sink == 42) printf(" ");
  return 1e9 * dt / (double)n;
}

static double run_mech(long n)
{
  mech_cfg_t mc;
  mech_default_cfg(&mc);
  static mech_t m;
  if (mech_init(&m, &mc, 300.0, 1u) != 0) exit(1);
  const double w = 2.0 * kPi * mc.f1_hz / mc.fs_hz;
  const double cw = cos(w), sw = sin(w);
  double c = 1.0, s = 0.0, sink = 0.0;
  const double t0 = now_s();
  for (long k = 0; k < n; k++) {
    mech_step(&m, 26.3 * c, 0.0, 1.0 + 1e-6 * (double)(k & 1023), 0.0);
    const double nc = c * cw - s * sw;
    s = s * cw + c * sw;
    c = nc;
    sink += m.z[2];
  }
  const double dt = now_s() - t0;
  if (sink == 42.0) printf(" ");
  return 1e9 * dt / (double)n;
}

int main(int argc, char **argv)
{
  const long n = (argc > 1) ? atol(argv[1]) : 2000000L;
  plant_cfg_t c;
  plant_default_cfg(&c);
  /* 8 V at the default resonance: 10 um; the frame set is an integer number of
   * periods only approximately, which does not matter for timing */
  const double wc = 2.0 * kPi * c.f_drive_hz, T = 1.0 / c.fs_hz;
  for (int k = 0; k < NFR; k++) {
    hal_dac_frame_midscale(&g_frames[k]);
    g_frames[k].code[0] = dac_v_to_code(8.0 * cos(0.5 * wc * k * T));
    g_frames[k].code[1] = dac_v_to_code(8.0 * sin(0.5 * wc * k * T));
    g_frames[k].code[2] = g_frames[k].code[3] = (uint16_t)HAL_DAC_CODE_MID;
  }
  const char *names[5] = {"static", "sine  ", "cool  ", "heat  ", "vibe  "};
  for (int v = 0; v < 5; v++) {
    uint64_t r = 0;
    const double ns = run_plant(v, n, &r);
    printf("plant %s: %6.1f ns/sample, %5.0fx real time at 50 kHz (%llu mechanics refreshes)\n",
           names[v], ns, 1e9 / (ns * c.fs_hz), (unsigned long long)r);
  }
  const double nm = run_mech(n);
  printf("mech alone (rate changing every sample): %.1f ns/sample\n", nm);
  /* one refresh: re-initialise the mechanics (dominated by the algebra exponential) */
  mech_cfg_t mc;
  mech_default_cfg(&mc);
  static mech_t m;
  const int reps = 50;
  const double t0 = now_s();
  for (int i = 0; i < reps; i++)
    if (mech_init(&m, &mc, 300.0 + i, 1u) != 0) return 1;
  printf("mechanics discretisation (init or refresh): %.2f ms\n", 1e3 * (now_s() - t0) / reps);
  return 0;
}
