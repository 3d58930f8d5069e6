#include "gyro/selftest.h"

#include <stddef.h>

#include "dsp/fastmath.h"

static void set_cfg(selftest_t *st, const selftest_cfg_t *cfg)
{
  st->cfg = *cfg;
  st->inv_base = cfg->base_blocks != 0u ? 1.0f / (float)cfg->base_blocks : 0.0f;
  st->inv_meas = cfg->meas_blocks != 0u ? 1.0f / (float)cfg->meas_blocks : 0.0f;
  st->inv_expect = cfg->expect_dps != 0.0f ? 1.0f / cfg->expect_dps : 0.0f;
}

void selftest_init(selftest_t *st, const selftest_cfg_t *cfg)
{
  set_cfg(st, cfg);
  st->state = SELFTEST_IDLE;
  st->count = 0u;
  st->acc_base = st->acc_meas = 0.0f;
  st->result_dps = 0.0f;
  st->runs = 0u;
}

void selftest_retune(selftest_t *st, const selftest_cfg_t *cfg) { set_cfg(st, cfg); }

void selftest_start(selftest_t *st)
{
  if (selftest_running(st)) {
    return;
  }
  st->state = SELFTEST_BASE;
  st->count = 0u;
  st->acc_base = st->acc_meas = 0.0f;
}

void selftest_update(selftest_t *st, int locked, float rate_raw)
{
  if (!selftest_running(st)) {
    return;
  }
  if (!locked) {
    st->state = SELFTEST_ABORTED;
    return;
  }
  const selftest_cfg_t *c = &st->cfg;
  st->count++;
  if (st->state == SELFTEST_BASE) {
    st->acc_base += rate_raw;
    if (st->count >= c->base_blocks) {
      st->state = SELFTEST_FORCE;
      st->count = 0u;
    }
    return;
  }
  if (st->count > c->settle_blocks) {
    st->acc_meas += rate_raw;
  }
  if (st->count >= c->settle_blocks + c->meas_blocks) {
    const float base = st->acc_base * st->inv_base;
    const float meas = st->acc_meas * st->inv_meas;
    st->result_dps = (meas - base) * c->scale_dps;
    const float e = c->expect_dps != 0.0f ? fm_absf(st->result_dps * st->inv_expect - 1.0f) : 1.0f;
    st->state = e <= c->tol_rel ? SELFTEST_PASS : SELFTEST_FAIL;
    st->runs++;
  }
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
