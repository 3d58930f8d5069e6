#include "gyro/selftest.h"

#include <stddef.h>

#include "dsp/fastmath.h"
#include "dsp/sincos.h"
#include "dsp/ramfunc.h"

/* The force formed every tick from the on-demand test's state and the continuous test's
 * modulation of the block. */
GYRO_RAMFUNC static void set_force(const selftest_cfg_t *restrict c, selftest_t *restrict st)
{
  float a = st->state == SELFTEST_FORCE ? c->amp_v : 0.0f;
  if (c->cont_on != 0u) a += c->cont_amp_v * st->cont_c;
  st->a_c = a * c->ref_c;
  st->a_s = a * c->ref_s;
  st->force_on = (st->state == SELFTEST_FORCE || c->cont_on != 0u) ? 1u : 0u;
}

static void cont_reset(selftest_t *st)
{
  st->cont_phase = 0u;
  st->cont_c = 1.0f;
  st->cont_s = 0.0f;
  for (int i = 0; i < 4; i++) st->w[i] = 0.0f;
  st->w_avg[0] = st->w_avg[1] = 0.0f;
  st->cont_blocks = 0u;
  st->cont_fail = 0u;
  st->cont_settle_bits = 0u;
}

void selftest_cfg_derive(selftest_cfg_t *cfg)
{
  cfg->inv_base = cfg->base_blocks != 0u ? 1.0f / (float)cfg->base_blocks : 0.0f;
  cfg->inv_meas = cfg->meas_blocks != 0u ? 1.0f / (float)cfg->meas_blocks : 0.0f;
  cfg->inv_expect = cfg->expect_dps != 0.0f ? 1.0f / cfg->expect_dps : 0.0f;
}

void selftest_init(const selftest_cfg_t *cfg, selftest_t *st)
{
  st->state = SELFTEST_IDLE;
  cont_reset(st);
  set_force(cfg, st);
  st->count = 0u;
  st->acc_base = st->acc_meas = 0.0f;
  st->result_dps = 0.0f;
  st->runs = 0u;
}

void selftest_reconfigure(const selftest_cfg_t *old, const selftest_cfg_t *cfg, selftest_t *st)
{
  if (cfg->cont_on != old->cont_on || cfg->cont_step != old->cont_step) cont_reset(st);
  set_force(cfg, st);
}

void selftest_start(selftest_t *st)
{
  if (selftest_running(st)) {
    return;
  }
  st->state = SELFTEST_BASE;
  st->count = 0u;
  st->acc_base = st->acc_meas = 0.0f;
  /* The force is the one it was (the test's own comes on with SELFTEST_FORCE). */
}

GYRO_RAMFUNC void selftest_update(const selftest_cfg_t *restrict c, selftest_t *restrict st,
                                  int locked, float rate_raw)
{
  if (!selftest_running(st)) {
    return;
  }
  if (!locked) {
    st->state = SELFTEST_ABORTED;
    set_force(c, st);
    return;
  }
  st->count++;
  if (st->state == SELFTEST_BASE) {
    st->acc_base += rate_raw;
    if (st->count >= c->base_blocks) {
      st->state = SELFTEST_FORCE;
      st->count = 0u;
      set_force(c, st);
    }
    return;
  }
  if (st->count > c->settle_blocks) {
    st->acc_meas += rate_raw;
  }
  if (st->count >= c->settle_blocks + c->meas_blocks) {
    const float base = st->acc_base * c->inv_base;
    const float meas = st->acc_meas * c->inv_meas;
    st->result_dps = (meas - base) * c->scale_dps;
    const float e = c->expect_dps != 0.0f ? fm_absf(st->result_dps * c->inv_expect - 1.0f) : 1.0f;
    st->state = e <= c->tol_rel ? SELFTEST_PASS : SELFTEST_FAIL;
    st->runs++;
    set_force(c, st);
  }
}

GYRO_RAMFUNC void selftest_cont_advance(const selftest_cfg_t *restrict c, selftest_t *restrict st)
{
  if (c->cont_on == 0u) return;
  st->cont_phase += c->cont_step;
  sincos_lut(st->cont_phase, &st->cont_s, &st->cont_c);
  set_force(c, st);
}

GYRO_RAMFUNC uint32_t selftest_cont_judge(const selftest_cfg_t *restrict c,
                                          selftest_t *restrict st, int locked)
{
  if (c->cont_on == 0u || !locked) {
    st->cont_blocks = 0u;
    st->cont_fail = 0u;
    st->cont_settle_bits = 0u;
    return 0u;
  }
  /* The rate axis only: the force's feedthrough into the sense pickoff (a voltage with
   * no response of the resonance) lands mostly on the quadrature axis, and a test of the rate path
   * is what the rate's validity needs. A rate (DC at the notch's input) makes the weights
   * ripple at f_m by mu x rate / (2 pi f_m / f_block), as large as the response itself
   * at full scale: their 2 Hz low-pass takes it out (-42 dB at 250 Hz). The low-pass runs
   * through the LMS's settling, so that it has caught up with the response when the
   * verdict starts (from zero it would take a fifth of a second, flagged all along). */
  st->w_avg[0] += SELFTEST_CONT_AVG_K * (st->w[0] - st->w_avg[0]);
  st->w_avg[1] += SELFTEST_CONT_AVG_K * (st->w[1] - st->w_avg[1]);
  if (st->cont_blocks < c->cont_settle_blocks) {
    st->cont_blocks++;
    st->cont_settle_bits = st->cont_blocks < c->cont_gate_blocks ? c->cont_gate_bits : 0u;
    return st->cont_fail;
  }
  st->cont_settle_bits = 0u;
  const float m2 = st->w_avg[0] * st->w_avg[0] + st->w_avg[1] * st->w_avg[1];
  st->cont_fail = (m2 >= c->cont_lo2 && m2 <= c->cont_hi2) ? 0u : 1u;
  return st->cont_fail;
}

const char *selftest_state_name(uint32_t state)
{
  switch ((selftest_state_t)state) {
  case SELFTEST_IDLE: return "idle";
  case SELFTEST_BASE: return "baseline";
  case SELFTEST_FORCE: return "force";
  case SELFTEST_PASS: return "PASS";
  case SELFTEST_FAIL: return "FAIL";
  case SELFTEST_ABORTED: return "aborted";
  }
  return "?";
}
