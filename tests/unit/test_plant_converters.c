/* The sense electrodes through the board's converters (issue 19 item 2): the firmware's DAC
 * frame, through the host HAL stub's one-sample latency and the plant's DAC model
 * (host_sim/plant/dac.h, channels 4..7 and the spare), reaches the feedback pair, the
 * quadrature-nulling sets and the tuning electrodes (host_sim/plant/plant.h), with the laws
 * of actuator.h; a bad code is refused; a part without the electrodes ignores their
 * channels and does not convert them. The electrodes' own physics is tested with
 * plant_set_electrodes in test_plant_effects. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "hal/hal_sample_timer.h"
#include "hal_host.h"
#include "plant/plant.h"

static const double kTwoPi = 6.28318530717958647692;

/* The ideal part with every sense electrode: the half-frequency feedback pair (fb_mode 3),
 * nulling electrodes of c = 20 (deg/s)/V^2 and tuning electrodes of 1e6 (1/s^2)/V^2; no
 * Brownian noise, no electrode noise and no reconstruction filter, so that a held code is
 * the electrode's voltage exactly. */
static void electrode_part(plant_cfg_t *c)
{
  plant_ideal_cfg(c);
  c->brownian = false;
  c->q_sense = 1000.0;
  c->fb_mode = 3;
  c->quadnull_dps_per_v2 = 20.0;
  c->tune_ke_per_s2_per_v2 = 1e6;
  c->fb_noise_white_v_rthz = c->fb_noise_1hz_v_rthz = 0.0;
  c->quadnull_noise_white_v_rthz = c->quadnull_noise_1hz_v_rthz = 0.0;
  c->tune_noise_white_v_rthz = c->tune_noise_1hz_v_rthz = 0.0;
  c->dac_recon_hz = 0.0;
}

/* The frame a scripted ISR writes at its n-th call: each electrode channel a code of its
 * own that changes every tick. */
static uint16_t script_code(int ch, uint32_t n)
{
  return (uint16_t)(HAL_DAC_CODE_MID + 37u * (uint32_t)ch + 101u * (n % 40u));
}

typedef struct {
  uint32_t n; /* ticks run */
} script_t;

static void script_isr(void *ctx)
{
  script_t *s = ctx;
  hal_dac_frame_t f;
  hal_dac_frame_midscale(&f);
  for (int ch = HAL_DAC_SENSE_FB_U1; ch < HAL_DAC_NUM_CHANNELS; ch++)
    f.code[ch] = script_code(ch, s->n);
  hal_dac_write_frame(&f);
  s->n++;
}

/* Each electrode channel's code reaches its electrode one sample after the ISR wrote it
 * (the board's LDAC at the next tick: hal_host.h), through its channel's gain and offset:
 * after the tick whose ISR wrote frame n, the plant held frame n - 1 over the sample. */
static void test_frame_reaches_electrodes_one_sample_late(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c);
  c.dac_gain_tune = 0.98;
  c.dac_offset_tune_v = 0.02;
  c.dac_gain_fb_u2 = 1.01;
  c.dac_offset_quadnull_v1_v = -0.005;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 31u), 0);
  script_t s = {0u};
  assert_int_equal(hal_sample_timer_start(BOARD_SAMPLE_RATE_HZ, script_isr, &s), 0);
  hal_host_attach(plant_step_hal, &p);
  const plant_truth_t *t = plant_truth(&p);
  assert_int_equal(hal_host_run(1u), 1u); /* frame 0 written, mid-scale held: the offsets */
  assert_true(t->dac_held_v[HAL_DAC_SENSE_FB_U1] == 0.0);
  assert_true(t->dac_held_v[HAL_DAC_SENSE_FB_U2] == 0.0);
  assert_true(fabs(t->dac_held_v[HAL_DAC_QUADNULL_V1] + 0.005) < 1e-12);
  assert_true(fabs(t->dac_held_v[HAL_DAC_TUNE] - 0.02) < 1e-12);
  for (uint32_t k = 1u; k < 60u; k++) {
    assert_int_equal(hal_host_run(1u), 1u);
    const uint32_t n = k - 1u; /* the frame on the outputs over this sample */
    const double u3 = dac_code_to_v(script_code(HAL_DAC_SENSE_FB_U1, n));
    const double u4 = 1.01 * dac_code_to_v(script_code(HAL_DAC_SENSE_FB_U2, n));
    const double v1 = dac_code_to_v(script_code(HAL_DAC_QUADNULL_V1, n)) - 0.005;
    const double v2 = dac_code_to_v(script_code(HAL_DAC_QUADNULL_V2, n));
    const double vt = 0.98 * dac_code_to_v(script_code(HAL_DAC_TUNE, n)) + 0.02;
    assert_true(fabs(t->dac_held_v[HAL_DAC_SENSE_FB_U1] - u3) < 1e-12);
    assert_true(fabs(t->elec_mean_v.fb_u1_v - u3) < 1e-12);
    assert_true(fabs(t->elec_mean_v.fb_u2_v - u4) < 1e-12);
    assert_true(fabs(t->elec_mean_v.quadnull_v1_v - v1) < 1e-12);
    assert_true(fabs(t->elec_mean_v.quadnull_v2_v - v2) < 1e-12);
    assert_true(fabs(t->elec_mean_v.tune_v - vt) < 1e-12);
    /* the signed nulling voltage: sqrt|V1^2 - V2^2| with the sign of the larger set */
    const double d = v1 * v1 - v2 * v2;
    assert_true(fabs(t->quadnull_v - (d >= 0.0 ? sqrt(d) : -sqrt(-d))) < 1e-9);
    /* the pair's force, (6-7) on the sense axis */
    assert_true(fabs(t->f_sense_mps2 - c.ks_fb_mps2_per_v2 * (u3 * u3 - u4 * u4)) <
                1e-12 * c.ks_fb_mps2_per_v2 * 225.0);
  }
  assert_int_equal(t->dac_rejects, 0);
  hal_sample_timer_stop();
}

/* Runs n samples of p with frame f held (written every tick, so held every sample). */
static void hold(plant_t *p, const hal_dac_frame_t *f, long n)
{
  for (long k = 0; k < n; k++) plant_step(p, f, NULL);
}

/* A DC code on a nulling channel adds the coupling c V^2 (V1, set 1) or takes it away (V2,
 * set 2) to the truth's quadrature, with V the converter's level of the code (the part is
 * at rest: the truth's drive frequency is the nominal one, so c V^2 in deg/s exactly); the
 * CSV's signed quadnull_v is +V1 or -V2. */
static void test_quadnull_code_moves_quadrature(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c);
  static plant_t p;
  hal_dac_frame_t f;
  hal_dac_frame_midscale(&f);
  assert_int_equal(plant_init(&p, &c, 32u), 0);
  hold(&p, &f, 200);
  const plant_truth_t *t = plant_truth(&p);
  const double q0 = t->quad_true_dps;
  assert_true(t->quadnull_v == 0.0);
  const uint16_t code = dac_v_to_code(6.0);
  const double v = dac_code_to_v(code);
  for (int set = 0; set < 2; set++) {
    hal_dac_frame_midscale(&f);
    f.code[set == 0 ? HAL_DAC_QUADNULL_V1 : HAL_DAC_QUADNULL_V2] = code;
    assert_int_equal(plant_init(&p, &c, 32u), 0);
    hold(&p, &f, 200); /* the coupling is rebased at the thermal updates (1 ms) */
    const double want = (set == 0 ? 1.0 : -1.0) * c.quadnull_dps_per_v2 * v * v;
    print_message("set %d at %.4f V: quad_true_dps %.4f -> %.4f (c V^2 %+.4f)\n", set + 1, v,
                  q0, t->quad_true_dps, want);
    assert_true(fabs((t->quad_true_dps - q0) - want) < 1e-9 * fabs(want));
    assert_true(fabs(t->quadnull_v - (set == 0 ? v : -v)) < 1e-12);
  }
}

/* A tuning code lowers the sense resonance by the law sqrt(w2^2 - ke_t Vt^2) (actuator.h),
 * Vt the converter's level; the drive resonance does not move. */
static void test_tune_code_lowers_sense(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c);
  c.fb_mode = 0; /* the tuning electrodes alone */
  c.quadnull_dps_per_v2 = 0.0;
  static plant_t p;
  hal_dac_frame_t f;
  hal_dac_frame_midscale(&f);
  f.code[HAL_DAC_TUNE] = dac_v_to_code(4.0);
  assert_int_equal(plant_init(&p, &c, 33u), 0);
  hold(&p, &f, 200);
  const plant_truth_t *t = plant_truth(&p);
  const double vt = dac_code_to_v(f.code[HAL_DAC_TUNE]);
  const double s = t->wn_drive_rad_s / (kTwoPi * c.f_drive_hz); /* (2-32) at the structure */
  const double w2 = kTwoPi * c.f_sense_hz * s;
  const double want = sqrt(w2 * w2 - c.tune_ke_per_s2_per_v2 * vt * vt) / kTwoPi;
  print_message("Vt %.5f V: sense resonance %.4f Hz (law %.4f Hz, %.3f Hz below %.4f)\n", vt,
                t->sense_freq_hz, want, w2 / kTwoPi - want, w2 / kTwoPi);
  assert_true(fabs(t->sense_freq_hz / want - 1.0) < 1e-9);
  assert_true(t->sense_freq_hz < w2 / kTwoPi - 10.0);
  assert_true(fabs(t->elec_mean_v.tune_v - vt) < 1e-12);
  assert_true(t->wn_drive_rad_s == kTwoPi * c.f_drive_hz * s);
}

/* A code above 16383 on any electrode channel refuses the whole frame: counted, the
 * previous frame held on every channel. */
static void test_bad_code_refused(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c);
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 34u), 0);
  hal_dac_frame_t good;
  hal_dac_frame_midscale(&good);
  for (int ch = HAL_DAC_SENSE_FB_U2; ch < HAL_DAC_NUM_CHANNELS; ch++)
    good.code[ch] = (uint16_t)(9000 + ch);
  hold(&p, &good, 3);
  const plant_truth_t *t = plant_truth(&p);
  double held[HAL_DAC_NUM_CHANNELS];
  memcpy(held, t->dac_held_v, sizeof held);
  for (int ch = HAL_DAC_SENSE_FB_U2; ch < HAL_DAC_NUM_CHANNELS; ch++) {
    hal_dac_frame_t bad = good;
    bad.code[ch] = (uint16_t)(HAL_DAC_CODE_MAX + 1u);
    bad.code[HAL_DAC_DRIVE_U1] = 100u; /* not taken either */
    plant_step(&p, &bad, NULL);
    assert_int_equal(t->dac_rejects, (uint64_t)(ch - HAL_DAC_SENSE_FB_U2 + 1));
    assert_memory_equal(t->dac_held_v, held, sizeof held);
  }
}

/* The default part has none of the sense electrodes: whatever codes the electrode channels
 * carry, the run is bit for bit the one at mid-scale (the ADC frames, the truth), the
 * channels are not converted (their levels read 0 V, dac.h) and the electrodes' voltages
 * read 0. Driven at its resonance, 8 V half-frequency, for 0.1 s. */
static void test_default_part_ignores_electrode_channels(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_default_cfg(&c);
  static plant_t a, b;
  assert_int_equal(plant_init(&a, &c, 35u), 0);
  assert_int_equal(plant_init(&b, &c, 35u), 0);
  assert_int_equal(a.dac.n_on, 4);
  const double wc = kTwoPi * c.f_drive_hz;
  for (long k = 0; k < 5000; k++) {
    hal_dac_frame_t fa;
    hal_dac_frame_midscale(&fa);
    fa.code[HAL_DAC_DRIVE_U1] = dac_v_to_code(8.0 * cos(0.5 * wc * (double)k * a.T));
    fa.code[HAL_DAC_DRIVE_U2] = dac_v_to_code(8.0 * sin(0.5 * wc * (double)k * a.T));
    hal_dac_frame_t fb = fa;
    fb.code[HAL_DAC_SENSE_FB_U2] = 0u;
    fb.code[HAL_DAC_QUADNULL_V1] = (uint16_t)HAL_DAC_CODE_MAX;
    fb.code[HAL_DAC_QUADNULL_V2] = (uint16_t)(k % 16384);
    fb.code[HAL_DAC_TUNE] = 1234u;
    hal_adc_frame_t ra, rb;
    plant_step(&a, &fa, &ra);
    plant_step(&b, &fb, &rb);
    assert_int_equal(ra.drive, rb.drive);
    assert_int_equal(ra.sense, rb.sense);
  }
  const plant_truth_t *ta = plant_truth(&a), *tb = plant_truth(&b);
  assert_true(ta->x_m == tb->x_m && ta->y_m == tb->y_m);
  assert_true(ta->quad_true_dps == tb->quad_true_dps);
  assert_true(ta->sense_freq_hz == tb->sense_freq_hz);
  for (int ch = HAL_DAC_SENSE_FB_U2; ch < HAL_DAC_NUM_CHANNELS; ch++)
    assert_true(tb->dac_held_v[ch] == 0.0);
  const plant_electrodes_t zero = {0.0, 0.0, 0.0, 0.0, 0.0};
  assert_memory_equal(&tb->elec_mean_v, &zero, sizeof zero);
  assert_true(tb->quadnull_v == 0.0);
  assert_int_equal(tb->dac_rejects, 0);
}

/* plant_set_electrodes is a source in series with the converter: the electrode sees both,
 * and their cross term in the mean square (the nulling coupling of V1 = DAC 3 V + 1 V is
 * that of 4 V). */
static void test_series_source_adds(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c);
  static plant_t p, q;
  hal_dac_frame_t f, g;
  hal_dac_frame_midscale(&f);
  f.code[HAL_DAC_QUADNULL_V1] = dac_v_to_code(3.0);
  f.code[HAL_DAC_TUNE] = dac_v_to_code(2.0);
  g = f;
  g.code[HAL_DAC_QUADNULL_V1] = dac_v_to_code(4.0);
  g.code[HAL_DAC_TUNE] = dac_v_to_code(3.0);
  assert_int_equal(plant_init(&p, &c, 36u), 0);
  assert_int_equal(plant_init(&q, &c, 36u), 0);
  /* the 1 V steps land on codes: 1 V is 546.13 LSB, so the series adds what the code lacks */
  const double dv = dac_code_to_v(g.code[HAL_DAC_QUADNULL_V1]) -
                    dac_code_to_v(f.code[HAL_DAC_QUADNULL_V1]);
  const double dt = dac_code_to_v(g.code[HAL_DAC_TUNE]) - dac_code_to_v(f.code[HAL_DAC_TUNE]);
  const plant_electrodes_t e = {0.0, 0.0, dv, 0.0, dt};
  assert_int_equal(plant_set_electrodes(&p, &e), 0);
  hold(&p, &f, 200);
  hold(&q, &g, 200);
  const plant_truth_t *tp = plant_truth(&p), *tq = plant_truth(&q);
  assert_true(fabs(tp->elec_mean_v.quadnull_v1_v - tq->elec_mean_v.quadnull_v1_v) < 1e-12);
  assert_true(fabs(tp->elec_mean_v.tune_v - tq->elec_mean_v.tune_v) < 1e-12);
  assert_true(fabs(tp->quad_true_dps / tq->quad_true_dps - 1.0) < 1e-12);
  assert_true(fabs(tp->sense_freq_hz / tq->sense_freq_hz - 1.0) < 1e-12);
  assert_true(tp->elec_v.quadnull_v1_v == dv); /* the series source itself */
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_frame_reaches_electrodes_one_sample_late),
      cmocka_unit_test(test_quadnull_code_moves_quadrature),
      cmocka_unit_test(test_tune_code_lowers_sense),
      cmocka_unit_test(test_bad_code_refused),
      cmocka_unit_test(test_default_part_ignores_electrode_channels),
      cmocka_unit_test(test_series_source_adds),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
