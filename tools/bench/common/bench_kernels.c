#include "bench_kernels.h"

#include <stddef.h>
#include <string.h>

#include "bench_now.h" /* per platform: target/ or host/ */
#include "bench_plant.h"
#include "dsp/biquad.h"
#include "dsp/butter.h"
#include "dsp/kfd.h"
#include "dsp/lmsd.h"
#include "dsp/multdemod.h"
#include "dsp/nco.h"
#include "dsp/pi.h"
#include "dsp/rlsd.h"
#include "dsp/sincos.h"
#include "gyro/gyro.h"
#include "params/params.h"

/* noipa: the runners must not be cloned for a constant function pointer (the kernel
 * and the empty loop would then differ in more than the callee), and the wrappers and
 * empty functions must stay opaque calls. */
#if defined(__clang__)
#define BK_OPAQUE __attribute__((noinline, optnone))
#define BK_RUNNER __attribute__((noinline))
#else
#define BK_OPAQUE __attribute__((noipa))
#define BK_RUNNER __attribute__((noipa))
#endif

#define BK_LEN 256u
#define BK_MASK (BK_LEN - 1u)
#define BK_FS_HZ 50000.0
#define BK_CARRIER_HZ 1489.9
#define BK_WARMUP_MAX_TICKS 400000u
#define BK_SETTLE_TICKS 5000u

/* Realistic inputs, generated once: the NCO references at the drive frequency, a drive
 * pickoff of 1.8 V (the default setpoint) at 0.3 rad with 2 LSB of dither, PI errors of
 * a few mV, a slowly varying rate-channel value for the biquads. */
static struct {
  float d[BK_LEN], rs[BK_LEN], rc[BK_LEN];
  uint32_t phase[BK_LEN];
  float e[BK_LEN];
  float x[BK_LEN];
} s_in;

static lmsd_t s_lmsd;
static biquad_cascade_t s_bq1, s_bq2;
static nco_t s_nco;
/* The PI kernel's coefficients and state, as one argument for the filter runner. */
typedef struct {
  pi_coeffs_t c;
  pi_t s;
} bk_pi_t;
static bk_pi_t s_pi;
static rlsd_t s_rlsd;
static kfd_t s_kfd;
static multdemod_t s_md;
static gyro_t s_gyro;
static gyro_design_t s_design; /* the gyro runs with it by pointer */
static hal_dac_frame_t s_dac;  /* the frame its ticks write (attached) */
static bench_plant_t s_plant;
static int s_ready;

static volatile float s_sink_f;
static volatile uint32_t s_sink_u;

/* ---- wrappers of the inline kernels, and the empty calls of each type ---- */

BK_OPAQUE static void w_lmsd(lmsd_t *s, float d, float rs, float rc)
{
  lmsd_step(s, d, rs, rc);
}
BK_OPAQUE static void w_multdemod(multdemod_t *s, float d, float rs, float rc)
{
  multdemod_step(s, d, rs, rc);
}
BK_OPAQUE static float w_biquad(biquad_cascade_t *s, float x)
{
  return biquad_cascade_step(s, x);
}
BK_OPAQUE static float w_pi(bk_pi_t *p, float e) { return pi_step(&p->c, &p->s, e); }

BK_OPAQUE static void e_lmsd(lmsd_t *s, float d, float rs, float rc)
{
  (void)s, (void)d, (void)rs, (void)rc;
}
BK_OPAQUE static void e_rlsd(rlsd_t *s, float d, float rs, float rc)
{
  (void)s, (void)d, (void)rs, (void)rc;
}
BK_OPAQUE static void e_kfd(kfd_t *s, float d, float rs, float rc)
{
  (void)s, (void)d, (void)rs, (void)rc;
}
BK_OPAQUE static void e_multdemod(multdemod_t *s, float d, float rs, float rc)
{
  (void)s, (void)d, (void)rs, (void)rc;
}
BK_OPAQUE static float e_biquad(biquad_cascade_t *s, float x)
{
  (void)s;
  return x;
}
BK_OPAQUE static float e_pi(bk_pi_t *s, float e)
{
  (void)s;
  return e;
}
BK_OPAQUE static void e_sincos(uint32_t phase, float *s, float *c)
{
  (void)phase, (void)s, (void)c;
}
BK_OPAQUE static void e_nco(nco_t *nco, nco_out_t *out) { (void)nco, (void)out; }
BK_OPAQUE static void e_tick(gyro_t *g, const hal_adc_frame_t *adc) { (void)g, (void)adc; }

/* ---- runners: identical loops for the kernel and its empty call ---- */

#define BK_DEMOD_RUNNER(tag, T) \
  BK_RUNNER static void run_##tag(void (*fn)(T *, float, float, float), T *s, uint32_t n, \
                                  bk_stat_t *st) \
  { \
    for (uint32_t i = 0u; i < n; i++) { \
      const uint32_t k = i & BK_MASK; \
      const float d = s_in.d[k], rs = s_in.rs[k], rc = s_in.rc[k]; \
      const uint32_t t0 = bk_now(); \
      fn(s, d, rs, rc); \
      const uint32_t t1 = bk_now(); \
      if (st != NULL) bk_stat_add(st, t1 - t0); \
    } \
  }

BK_DEMOD_RUNNER(lmsd, lmsd_t)
BK_DEMOD_RUNNER(rlsd, rlsd_t)
BK_DEMOD_RUNNER(kfd, kfd_t)
BK_DEMOD_RUNNER(multdemod, multdemod_t)

#define BK_FILTER_RUNNER(tag, T, input) \
  BK_RUNNER static void run_##tag(float (*fn)(T *, float), T *s, uint32_t n, bk_stat_t *st) \
  { \
    for (uint32_t i = 0u; i < n; i++) { \
      const float x = s_in.input[i & BK_MASK]; \
      const uint32_t t0 = bk_now(); \
      const float y = fn(s, x); \
      const uint32_t t1 = bk_now(); \
      s_sink_f = y; \
      if (st != NULL) bk_stat_add(st, t1 - t0); \
    } \
  }

BK_FILTER_RUNNER(biquad, biquad_cascade_t, x)
BK_FILTER_RUNNER(pi, bk_pi_t, e)

BK_RUNNER static void run_sincos(void (*fn)(uint32_t, float *, float *), uint32_t n, bk_stat_t *st)
{
  float s = 0.0f, c = 0.0f;
  for (uint32_t i = 0u; i < n; i++) {
    const uint32_t ph = s_in.phase[i & BK_MASK];
    const uint32_t t0 = bk_now();
    fn(ph, &s, &c);
    const uint32_t t1 = bk_now();
    s_sink_f = s + c;
    if (st != NULL) bk_stat_add(st, t1 - t0);
  }
}

BK_RUNNER static void run_nco(void (*fn)(nco_t *, nco_out_t *), nco_t *nco, uint32_t n,
                              bk_stat_t *st)
{
  nco_out_t out;
  memset(&out, 0, sizeof out);
  for (uint32_t i = 0u; i < n; i++) {
    const uint32_t t0 = bk_now();
    fn(nco, &out);
    const uint32_t t1 = bk_now();
    s_sink_u = out.half_phase;
    if (st != NULL) bk_stat_add(st, t1 - t0);
  }
}

/* The gyro: each iteration makes the plant's frame for this tick (not counted), then
 * the tick. Returns 1 if the gyro was LOCKED after every tick. */
BK_RUNNER static uint32_t run_tick(void (*fn)(gyro_t *, const hal_adc_frame_t *), uint32_t n,
                                   bk_stat_t *st)
{
  hal_adc_frame_t adc;
  uint32_t locked = 1u;
  for (uint32_t i = 0u; i < n; i++) {
    bench_plant_frame(&s_plant, &s_gyro, &adc);
    const uint32_t t0 = bk_now();
    fn(&s_gyro, &adc);
    const uint32_t t1 = bk_now();
    s_sink_u = s_dac.code[0];
    if (s_gyro.sup.mode != GYRO_MODE_LOCKED) locked = 0u;
    if (st != NULL) bk_stat_add(st, t1 - t0);
  }
  return locked;
}

/* ---- set-up ---- */

void bk_stat_reset(bk_stat_t *s)
{
  s->sum = 0u;
  s->n = 0u;
  s->min = UINT32_MAX;
  s->max = 0u;
}

void bk_stat_add(bk_stat_t *s, uint32_t v)
{
  s->sum += v;
  s->n++;
  if (v < s->min) s->min = v;
  if (v > s->max) s->max = v;
}

static const char *const k_names[BK_COUNT] = {
    "lmsd_step", "biquad_1sec", "biquad_2sec_lp100", "sincos_lut",     "nco_step",
    "pi_step",   "rlsd_step",   "kfd_step",          "multdemod_step", "gyro_tick"};

const char *bk_name(bk_id_t id) { return (unsigned)id < BK_COUNT ? k_names[id] : NULL; }

static const char *const k_symbols[BK_COUNT] = {
    "w_lmsd", "w_biquad",  "w_biquad", "sincos_lut",  "nco_step",
    "w_pi",   "rlsd_step", "kfd_step", "w_multdemod", "gyro_tick"};

const char *bk_symbol(bk_id_t id) { return (unsigned)id < BK_COUNT ? k_symbols[id] : NULL; }

static void gen_inputs(void)
{
  nco_t nco;
  const nco_cfg_t nc = {BK_CARRIER_HZ, BK_FS_HZ, 0.0};
  (void)nco_init(&nco, &nc);
  const uint32_t off = sincos_rad_to_phase(0.3f);
  uint32_t lcg = 1u;
  for (uint32_t k = 0u; k < BK_LEN; k++) {
    nco_out_t r;
    nco_step(&nco, &r);
    float s, c;
    sincos_lut(r.phase + off, &s, &c);
    lcg = lcg * 1664525u + 1013904223u;
    const float u = (float)(lcg >> 16) * (1.0f / 32768.0f) - 1.0f; /* [-1, 1) */
    s_in.rs[k] = r.sin_wc;
    s_in.rc[k] = r.cos_wc;
    s_in.phase[k] = r.phase;
    s_in.d[k] = 1.8f * s + 2.0f * HAL_ADC_V_PER_CODE * u;
    s_in.e[k] = 0.005f * u;
    s_in.x[k] = 0.05f + 0.001f * s + 0.0005f * u;
  }
}

static int setup_gyro(void)
{
  param_values_t v;
  param_values_defaults(&v);
  if (gyro_design(&v, &s_design) != 0 || gyro_init_from_design(&s_gyro, &s_design) != 0 ||
      bench_plant_init(&s_plant, &s_design, &v) != 0) {
    return -1;
  }
  hal_dac_frame_midscale(&s_dac);
  gyro_attach_dac_frame(&s_gyro, &s_dac);
  gyro_start(&s_gyro);
  hal_adc_frame_t adc;
  uint32_t settled = 0u;
  for (uint32_t i = 0u; i < BK_WARMUP_MAX_TICKS && settled < BK_SETTLE_TICKS; i++) {
    bench_plant_frame(&s_plant, &s_gyro, &adc);
    gyro_tick(&s_gyro, &adc);
    settled = s_gyro.sup.mode == GYRO_MODE_LOCKED ? settled + 1u : 0u;
  }
  return settled >= BK_SETTLE_TICKS ? 0 : -2;
}

int bk_setup(void)
{
  s_ready = 0;
  gen_inputs();

  const lmsd_cfg_t lc = {0.034f};
  const rlsd_cfg_t rc = {RLSD_LAMBDA_DEFAULT, 1.0f};
  const kfd_cfg_t kc = {KFD_Q_DEFAULT, KFD_R_DEFAULT, 1.0f};
  const nco_cfg_t nc = {BK_CARRIER_HZ, BK_FS_HZ, 0.0};
  /* The drive amplitude PI with the gains and force limit the designer gives for the
   * default parameters, started mid-range (the errors below do not saturate it). */
  param_values_t v;
  param_values_defaults(&v);
  gyro_design_t d;
  if (gyro_design(&v, &d) != 0) return -1;
  const pi_cfg_t pc = {d.drive.amp_kp, d.drive.amp_ki,       d.drive.dt_s,
                       0.0f,           d.drive.f_cmd_max_v2, 0.5f * d.drive.f_cmd_max_v2};
  if (lmsd_init(&s_lmsd, &lc) != 0 || rlsd_init(&s_rlsd, &rc) != 0 || kfd_init(&s_kfd, &kc) != 0 ||
      nco_init(&s_nco, &nc) != 0 || pi_init(&pc, &s_pi.c, &s_pi.s) != 0) {
    return -1;
  }
  /* The rate output low-pass as the product runs it: 100 Hz, 4th order (two sections)
   * at fs/10; one section = the 2nd-order design. */
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  int n = butter_design(BUTTER_LOWPASS, 2u, 100.0, 0.0, BK_FS_HZ / 10.0, sec,
                        BIQUAD_MAX_SECTIONS);
  if (n != 1 || biquad_cascade_init(&s_bq1, sec, 1u) != 0) return -2;
  n = butter_design(BUTTER_LOWPASS, 4u, 100.0, 0.0, BK_FS_HZ / 10.0, sec, BIQUAD_MAX_SECTIONS);
  if (n != 2 || biquad_cascade_init(&s_bq2, sec, 2u) != 0) return -3;
  biquad_cascade_reset(&s_bq1, 0.05f);
  biquad_cascade_reset(&s_bq2, 0.05f);
  /* The multiplicative demodulator of the thesis comparison: the same 100 Hz 4th-order
   * low-pass, at the full rate. */
  n = butter_design(BUTTER_LOWPASS, 4u, 100.0, 0.0, BK_FS_HZ, sec, BIQUAD_MAX_SECTIONS);
  const multdemod_cfg_t mc = {sec, (uint32_t)(n > 0 ? n : 0)};
  if (n != 2 || multdemod_init(&s_md, &mc) != 0) return -4;

  /* Let the adaptive demodulators converge before they are counted. */
  for (uint32_t i = 0u; i < 4u * BK_LEN; i++) {
    const uint32_t k = i & BK_MASK;
    lmsd_step(&s_lmsd, s_in.d[k], s_in.rs[k], s_in.rc[k]);
    rlsd_step(&s_rlsd, s_in.d[k], s_in.rs[k], s_in.rc[k]);
    kfd_step(&s_kfd, s_in.d[k], s_in.rs[k], s_in.rc[k]);
    multdemod_step(&s_md, s_in.d[k], s_in.rs[k], s_in.rc[k]);
  }
  s_ready = 1;
  return 0;
}

static int run_case(bk_id_t id, uint32_t n, bk_stat_t *kern, bk_stat_t *base, uint32_t *locked)
{
  switch (id) {
  case BK_LMSD:
    run_lmsd(w_lmsd, &s_lmsd, n, kern);
    if (base != NULL) run_lmsd(e_lmsd, &s_lmsd, n, base);
    return 0;
  case BK_BIQUAD1:
    run_biquad(w_biquad, &s_bq1, n, kern);
    if (base != NULL) run_biquad(e_biquad, &s_bq1, n, base);
    return 0;
  case BK_BIQUAD2:
    run_biquad(w_biquad, &s_bq2, n, kern);
    if (base != NULL) run_biquad(e_biquad, &s_bq2, n, base);
    return 0;
  case BK_SINCOS:
    run_sincos(sincos_lut, n, kern);
    if (base != NULL) run_sincos(e_sincos, n, base);
    return 0;
  case BK_NCO:
    run_nco(nco_step, &s_nco, n, kern);
    if (base != NULL) run_nco(e_nco, &s_nco, n, base);
    return 0;
  case BK_PI:
    run_pi(w_pi, &s_pi, n, kern);
    if (base != NULL) run_pi(e_pi, &s_pi, n, base);
    return 0;
  case BK_RLSD:
    run_rlsd(rlsd_step, &s_rlsd, n, kern);
    if (base != NULL) run_rlsd(e_rlsd, &s_rlsd, n, base);
    return 0;
  case BK_KFD:
    run_kfd(kfd_step, &s_kfd, n, kern);
    if (base != NULL) run_kfd(e_kfd, &s_kfd, n, base);
    return 0;
  case BK_MULTDEMOD:
    run_multdemod(w_multdemod, &s_md, n, kern);
    if (base != NULL) run_multdemod(e_multdemod, &s_md, n, base);
    return 0;
  case BK_GYRO_TICK:
    *locked = run_tick(gyro_tick, n, kern);
    if (base != NULL) (void)run_tick(e_tick, n, base);
    return 0;
  case BK_COUNT:
  default: return -1;
  }
}

uint32_t bk_gyro_locked(void) { return s_gyro.sup.mode == GYRO_MODE_LOCKED ? 1u : 0u; }

int bk_prepare(bk_id_t id)
{
  if (!s_ready || (unsigned)id >= BK_COUNT) return -1;
  return id == BK_GYRO_TICK ? setup_gyro() : 0;
}

int bk_run(bk_id_t id, uint32_t n, bk_result_t *r)
{
  if (r == NULL || bk_prepare(id) != 0) return -1;
  bk_stat_reset(&r->kern);
  bk_stat_reset(&r->base);
  r->locked = 0u;
  return run_case(id, n, &r->kern, &r->base, &r->locked);
}

int bk_run_kernel_only(bk_id_t id, uint32_t n)
{
  if (!s_ready || (unsigned)id >= BK_COUNT) return -1;
  uint32_t locked = 0u;
  return run_case(id, n, NULL, NULL, &locked);
}
