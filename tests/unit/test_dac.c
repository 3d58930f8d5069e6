#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "plant/dac.h"
#include "plant/rng.h"

static const double k_pi = 3.14159265358979323846;
#define LSB_V (30.0 / 16384.0)

static hal_dac_frame_t frame_all(uint16_t c)
{
  hal_dac_frame_t f;
  for (int i = 0; i < DAC_NCH; i++) f.code[i] = c;
  return f;
}

/* Offset binary over +-15 V: the end points and mid-scale of board.h. */
static void test_code_to_volts(void **state)
{
  (void)state;
  assert_true(fabs(dac_code_to_v(0) + 15.0) < 1e-12);
  assert_true(fabs(dac_code_to_v(8192)) < 1e-12);
  assert_true(fabs(dac_code_to_v(16383) - (15.0 - LSB_V)) < 1e-12);
  assert_true(fabs(dac_code_to_v(8193) - LSB_V) < 1e-12);
  for (uint16_t c = 0; c <= 16383; c = (uint16_t)(c + 97))
    assert_int_equal(dac_v_to_code(dac_code_to_v(c)), c);
  assert_int_equal(dac_v_to_code(100.0), 16383);
  assert_int_equal(dac_v_to_code(-100.0), 0);
}

/* A frame written before step k is held over step k+1 (one-sample latency, ZOH), and
 * gain and offset act on the held level. Filter removed so the staircase is visible. */
static void test_latency_and_hold(void **state)
{
  (void)state;
  dac_cfg_t cfg;
  dac_default_cfg(&cfg);
  cfg.recon_cutoff_hz = 0.0;
  cfg.gain[2] = 0.99;
  cfg.offset_v[2] = 0.01;
  dac_t d;
  assert_int_equal(dac_init(&d, &cfg), 0);
  dac_out_t o;
  hal_dac_frame_t f = frame_all(12000);
  assert_int_equal(dac_write(&d, &f), 0);
  dac_step(&d, &o); /* holds the initial mid-scale code */
  for (int c = 0; c < DAC_NCH; c++) {
    const double want = cfg.offset_v[c];
    assert_true(fabs(o.ch[c].held_v - want) < 1e-12);
    assert_true(fabs(o.ch[c].mean_v - want) < 1e-12);
  }
  dac_step(&d, &o); /* now the written frame */
  const double v = dac_code_to_v(12000);
  assert_true(fabs(o.ch[0].held_v - v) < 1e-12);
  assert_true(fabs(o.ch[0].mean_sq_v2 - v * v) < 1e-9);
  assert_true(fabs(o.ch[2].held_v - (0.99 * v + 0.01)) < 1e-12);
  /* and it stays until the next write */
  dac_step(&d, &o);
  assert_true(fabs(o.ch[1].end_v - v) < 1e-12);
}

/* Out-of-range codes are refused and the queued frame is kept. */
static void test_bad_write(void **state)
{
  (void)state;
  dac_cfg_t cfg;
  dac_default_cfg(&cfg);
  cfg.recon_cutoff_hz = 0.0;
  dac_t d;
  assert_int_equal(dac_init(&d, &cfg), 0);
  hal_dac_frame_t good = frame_all(9000), bad = frame_all(9000);
  bad.code[3] = 16384;
  assert_int_equal(dac_write(&d, &good), 0);
  assert_int_equal(dac_write(&d, &bad), -1);
  assert_int_equal(dac_write(&d, NULL), -1);
  dac_out_t o;
  dac_step(&d, &o);
  dac_step(&d, &o);
  for (int c = 0; c < DAC_NCH; c++)
    assert_true(fabs(o.ch[c].held_v - dac_code_to_v(9000)) < 1e-12);
}

/* Invalid configurations are refused with the instance untouched. */
static void test_bad_cfg(void **state)
{
  (void)state;
  dac_t d, before;
  memset(&d, 0x5a, sizeof d);
  before = d;
  dac_cfg_t good;
  dac_default_cfg(&good);
  dac_cfg_t c = good;
  c.recon_cutoff_hz = NAN;
  assert_int_equal(dac_init(&d, &c), -1);
  c = good;
  c.recon_q = 0.0;
  assert_int_equal(dac_init(&d, &c), -1);
  c = good;
  c.fs_hz = -1.0;
  assert_int_equal(dac_init(&d, &c), -1);
  c = good;
  c.gain[1] = 0.0;
  assert_int_equal(dac_init(&d, &c), -1);
  c = good;
  c.initial_code[0] = 20000;
  assert_int_equal(dac_init(&d, &c), -1);
  c = good;
  c.offset_v[3] = INFINITY;
  assert_int_equal(dac_init(&d, &c), -1);
  assert_int_equal(dac_init(NULL, &good), -1);
  assert_memory_equal(&d, &before, sizeof d);
}

/* Unit step response of w0^2 / (s^2 + (w0/Q) s + w0^2), underdamped (Q > 1/2). */
static void step_resp(double t, double w0, double q, double *y, double *dy)
{
  if (t <= 0.0) {
    *y = 0.0;
    *dy = 0.0;
    return;
  }
  const double z = 0.5 / q, wd = w0 * sqrt(1.0 - z * z), e = exp(-z * w0 * t);
  *y = 1.0 - e * (cos(wd * t) + z / sqrt(1.0 - z * z) * sin(wd * t));
  *dy = w0 / sqrt(1.0 - z * z) * e * sin(wd * t);
}

#define NSTEP 160

/* Random staircase through the filter: the output at every tick, its slope, and the
 * mean and mean square over every sample, against the analytic continuous output (a
 * superposition of closed-form step responses) integrated by Simpson's rule. */
static void test_filtered_staircase(void **state)
{
  (void)state;
  const double qs[2] = {0.70710678118654752, 2.0};
  for (int qi = 0; qi < 2; qi++) {
    dac_cfg_t cfg;
    dac_default_cfg(&cfg);
    cfg.recon_q = qs[qi];
    cfg.initial_code[0] = dac_v_to_code(3.0);
    dac_t d;
    assert_int_equal(dac_init(&d, &cfg), 0);
    const double T = 1.0 / cfg.fs_hz, w0 = 2.0 * k_pi * cfg.recon_cutoff_hz;
    rng_t r;
    rng_seed(&r, 5u, 9u);
    double lev[NSTEP + 1]; /* held level over sample j */
    lev[0] = dac_code_to_v(cfg.initial_code[0]);
    dac_out_t o;
    double worst_end = 0, worst_slope = 0, worst_mean = 0, worst_ms = 0;
    for (int j = 0; j < NSTEP; j++) {
      hal_dac_frame_t f = frame_all(HAL_DAC_CODE_MID);
      f.code[0] = (uint16_t)(rng_uniform(&r) * 16384.0);
      assert_int_equal(dac_write(&d, &f), 0);
      lev[j + 1] = dac_code_to_v(f.code[0]);
      dac_step(&d, &o);
      /* analytic output on [jT, (j+1)T]: settled at lev[0], steps at t = iT, i >= 1 */
      const int ns = 256;
      double sm = 0.0, sq = 0.0;
      for (int s = 0; s <= ns; s++) {
        const double t = (double)j * T + (double)s * T / ns;
        double y = lev[0];
        for (int i = 1; i <= j; i++) {
          double st, dst;
          step_resp(t - (double)i * T, w0, cfg.recon_q, &st, &dst);
          y += (lev[i] - lev[i - 1]) * st;
        }
        const double wgt = (s == 0 || s == ns) ? 1.0 : (s % 2) ? 4.0 : 2.0;
        sm += wgt * y;
        sq += wgt * y * y;
      }
      sm /= 3.0 * ns;
      sq /= 3.0 * ns;
      double ye = lev[0], dye = 0.0;
      for (int i = 1; i <= j; i++) {
        double st, dst;
        step_resp((double)(j + 1) * T - (double)i * T, w0, cfg.recon_q, &st, &dst);
        ye += (lev[i] - lev[i - 1]) * st;
        dye += (lev[i] - lev[i - 1]) * dst;
      }
      worst_end = fmax(worst_end, fabs(o.ch[0].end_v - ye));
      worst_slope = fmax(worst_slope, fabs(o.ch[0].end_dvdt_v_per_s - dye));
      worst_mean = fmax(worst_mean, fabs(o.ch[0].mean_v - sm));
      worst_ms = fmax(worst_ms, fabs(o.ch[0].mean_sq_v2 - sq));
      assert_true(fabs(o.ch[0].held_v - lev[j]) < 1e-12);
    }
    print_message("Q %.3f: end %.3g V slope %.3g V/s mean %.3g V ms %.3g V2\n", cfg.recon_q,
                  worst_end, worst_slope, worst_mean, worst_ms);
    assert_true(worst_end < 1e-9);        /* V, on a +-15 V staircase */
    assert_true(worst_slope < 1e-9 * w0); /* V/s */
    assert_true(worst_mean < 1e-8);       /* V (Simpson error ~1e-9) */
    assert_true(worst_ms < 3e-7);         /* V^2, on up to 225 V^2 */
  }
}

/* The other channels, held at mid-scale, stay at 0 V with no ringing from channel 0. */
static void test_channels_independent(void **state)
{
  (void)state;
  dac_cfg_t cfg;
  dac_default_cfg(&cfg);
  dac_t d;
  assert_int_equal(dac_init(&d, &cfg), 0);
  dac_out_t o;
  for (int k = 0; k < 50; k++) {
    hal_dac_frame_t f = frame_all(HAL_DAC_CODE_MID);
    f.code[0] = (k % 2) ? 0 : 16383;
    dac_write(&d, &f);
    dac_step(&d, &o);
    for (int c = 1; c < DAC_NCH; c++) {
      assert_true(fabs(o.ch[c].mean_v) < 1e-15);
      assert_true(fabs(o.ch[c].mean_sq_v2) < 1e-15);
    }
  }
}

/* Held level of every channel after one latched frame of code (no filter). */
static void held_levels(const dac_cfg_t *cfg, uint16_t code, double ref, double out[DAC_NCH])
{
  dac_t d;
  assert_int_equal(dac_init(&d, cfg), 0);
  dac_set_ref(&d, ref);
  hal_dac_frame_t f = frame_all(code);
  assert_int_equal(dac_write(&d, &f), 0);
  dac_out_t o;
  dac_step(&d, &o);
  dac_step(&d, &o);
  for (int c = 0; c < DAC_NCH; c++) out[c] = o.ch[c].held_v;
}

/* INL (inl.h): a bow of 2 LSB raises the mid-scale level by 2 LSB times the channel's
 * gain, a quarter-scale code by 1.5 LSB, the end codes not at all; the per-code pattern
 * is each channel's own (its own weight errors), zero at the ends. */
static void test_inl(void **state)
{
  (void)state;
  dac_cfg_t cfg;
  dac_default_cfg(&cfg);
  cfg.recon_cutoff_hz = 0.0;
  cfg.gain[1] = 1.5;
  cfg.offset_v[1] = 0.2;
  double ideal[DAC_NCH], v[DAC_NCH];
  const uint16_t codes[3] = {8192, 4096, 0};
  const double bow[3] = {2.0, 1.5, 0.0};
  for (int i = 0; i < 3; i++) {
    held_levels(&cfg, codes[i], 0.0, ideal);
    dac_cfg_t b = cfg;
    b.inl.bow_lsb = 2.0;
    held_levels(&b, codes[i], 0.0, v);
    for (int c = 0; c < DAC_NCH; c++)
      assert_true(fabs(v[c] - ideal[c] - bow[i] * LSB_V * cfg.gain[c]) < 1e-12);
  }
  dac_cfg_t p = cfg;
  p.inl.code_lsb = 1.0;
  p.inl_seed = 4u;
  held_levels(&p, 8192, 0.0, v);
  held_levels(&cfg, 8192, 0.0, ideal);
  assert_true(v[0] != v[2] || v[2] != v[3]); /* each channel its own ladder */
  for (int c = 0; c < DAC_NCH; c++) {
    dac_t d;
    assert_int_equal(dac_init(&d, &p), 0);
    assert_true(fabs(v[c] - ideal[c] - inl_lsb(&d.inl[c], 8192) * LSB_V * p.gain[c]) < 1e-12);
    assert_true(fabs(inl_lsb(&d.inl[c], 0)) < 1e-12 && fabs(inl_lsb(&d.inl[c], 16383)) < 1e-12);
  }
}

/* The shared reference r (vref.h) scales the converter's part of the level, not the
 * amplifier's offset: offset + (level - offset) (1 + r). */
static void test_reference_error(void **state)
{
  (void)state;
  dac_cfg_t cfg;
  dac_default_cfg(&cfg);
  cfg.recon_cutoff_hz = 0.0;
  cfg.offset_v[2] = 0.5;
  double ideal[DAC_NCH], v[DAC_NCH];
  held_levels(&cfg, 12000, 0.0, ideal);
  held_levels(&cfg, 12000, 2e-3, v);
  for (int c = 0; c < DAC_NCH; c++) {
    const double off = cfg.offset_v[c];
    assert_true(fabs(v[c] - (off + (ideal[c] - off) * 1.002)) < 1e-12);
  }
}

/* Off by default (zero INL, no draws); a bad INL is refused and changes nothing. */
static void test_inl_off_and_bad(void **state)
{
  (void)state;
  dac_cfg_t cfg;
  dac_default_cfg(&cfg);
  assert_true(cfg.inl.bow_lsb == 0.0 && cfg.inl.code_lsb == 0.0);
  dac_t d, before;
  assert_int_equal(dac_init(&d, &cfg), 0);
  for (int c = 0; c < DAC_NCH; c++) assert_false(d.inl[c].active);
  before = d;
  cfg.inl.bow_lsb = NAN;
  assert_int_equal(dac_init(&d, &cfg), -1);
  cfg.inl.bow_lsb = 0.0;
  cfg.inl.code_lsb = -0.5;
  assert_int_equal(dac_init(&d, &cfg), -1);
  assert_memory_equal(&d, &before, sizeof d);
}

/* A channel not modelled (cfg.modelled 0: no electrode on it) is never converted: dac_step
 * leaves its output as the caller had it, while its codes are still checked and latched
 * (a bad code refuses the frame as on any channel) and the modelled channels run as in a
 * converter of all channels, bit for bit; modelled must be 0 or 1. */
static void test_unmodelled_channel(void **state)
{
  (void)state;
  dac_cfg_t cfg;
  dac_default_cfg(&cfg);
  cfg.inl.code_lsb = 0.5;
  cfg.inl_seed = 9u;
  dac_cfg_t part = cfg;
  part.modelled[HAL_DAC_QUADNULL_V2] = 0u;
  part.modelled[HAL_DAC_TUNE] = 0u;
  dac_t all, d;
  assert_int_equal(dac_init(&all, &cfg), 0);
  assert_int_equal(dac_init(&d, &part), 0);
  assert_int_equal(d.n_on, DAC_NCH - 2);
  dac_out_t oa, o;
  memset(&o, 0, sizeof o);
  o.ch[HAL_DAC_TUNE].held_v = 123.0; /* the caller's */
  for (int k = 0; k < 50; k++) {
    hal_dac_frame_t f = frame_all((uint16_t)(4000 + 211 * k));
    assert_int_equal(dac_write(&all, &f), 0);
    assert_int_equal(dac_write(&d, &f), 0);
    dac_step(&all, &oa);
    dac_step(&d, &o);
    for (int c = 0; c < DAC_NCH; c++) {
      if (!part.modelled[c]) continue;
      assert_true(o.ch[c].mean_sq_v2 == oa.ch[c].mean_sq_v2);
      assert_true(o.ch[c].end_v == oa.ch[c].end_v);
    }
    assert_true(o.ch[HAL_DAC_TUNE].held_v == 123.0);
    assert_true(o.ch[HAL_DAC_QUADNULL_V2].held_v == 0.0);
    assert_int_equal(d.latched[HAL_DAC_TUNE], f.code[HAL_DAC_TUNE]);
  }
  hal_dac_frame_t bad = frame_all(100);
  bad.code[HAL_DAC_TUNE] = 16384;
  assert_int_equal(dac_write(&d, &bad), -1);
  part.modelled[HAL_DAC_TUNE] = 2u;
  assert_int_equal(dac_init(&d, &part), -1);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_code_to_volts),
      cmocka_unit_test(test_latency_and_hold),
      cmocka_unit_test(test_bad_write),
      cmocka_unit_test(test_bad_cfg),
      cmocka_unit_test(test_filtered_staircase),
      cmocka_unit_test(test_channels_independent),
      cmocka_unit_test(test_inl),
      cmocka_unit_test(test_reference_error),
      cmocka_unit_test(test_inl_off_and_bad),
      cmocka_unit_test(test_unmodelled_channel),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
