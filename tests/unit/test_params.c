/* Parameter table consistency, validation, and the double-buffered bank judged by a
 * simulated ISR that checks, at every tick, invariants a half-applied change would
 * break. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "params/params.h"

/* ---- table ---- */

static bool name_ok(const char *n)
{
  /* group.snake_case: lower-case letters, digits, '_' and at least one '.' */
  bool dot = false;
  if (n[0] < 'a' || n[0] > 'z') {
    return false;
  }
  for (const char *p = n; *p; p++) {
    if (*p == '.') {
      if (p[1] < 'a' || p[1] > 'z') {
        return false;
      }
      dot = true;
    } else if (!((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '_')) {
      return false;
    }
  }
  return dot;
}

static void test_table_consistent(void **state)
{
  (void)state;
  for (int i = 0; i < PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    assert_non_null(pi);
    assert_true(name_ok(pi->name));
    assert_true(strlen(pi->help) > 10u && strlen(pi->help) < 100u);
    assert_true(strlen(pi->unit) > 0u && strchr(pi->unit, ' ') == NULL);
    assert_int_equal(param_check((param_idx_t)i, pi->def), PARAM_OK);
    assert_int_equal(param_lookup(pi->name, strlen(pi->name)), i);
    assert_int_equal(param_lookup_id(pi->id), i);
    for (int j = 0; j < i; j++) {
      assert_string_not_equal(param_info((param_idx_t)j)->name, pi->name);
      assert_int_not_equal(param_info((param_idx_t)j)->id, pi->id);
    }
    /* read-only values are properties of the build, never stored */
    if (pi->flags & PF_READONLY) {
      assert_false(pi->flags & PF_PERSIST);
    }
    if (pi->type == PARAM_T_ENUM) {
      assert_true(pi->choices != 0u);
      assert_int_equal(1u << pi->min.u, pi->choices & -pi->choices);    /* lowest choice */
      assert_true(pi->max.u < 32u && (pi->choices >> pi->max.u) == 1u); /* highest */
    } else {
      assert_int_equal(pi->choices, 0u);
      if (pi->type == PARAM_T_F32) {
        assert_true(pi->min.f <= pi->max.f);
      } else {
        assert_true(pi->min.u <= pi->max.u);
      }
    }
  }
  assert_null(param_info(PARAM_COUNT));
  assert_int_equal(param_lookup("drive.freq", 10), PARAM_COUNT);
  assert_int_equal(param_lookup("drive.freq_hz", 13), PARAM_drive_freq_hz);
  assert_int_equal(param_lookup_id(0xFFFF), PARAM_COUNT);
}

/* The typed struct and the generic accessors address the same storage. */
static void test_typed_and_generic_agree(void **state)
{
  (void)state;
  param_values_t v;
  param_values_defaults(&v);
  assert_true(v.drive_freq_hz == 1750.0f);
  assert_int_equal(v.sys_fs_hz, 50000u);
  assert_int_equal(v.rate_lpf_order, 4u);
  param_value_t x = {.f = 1234.5f};
  param_put(&v, PARAM_drive_freq_hz, x);
  assert_true(v.drive_freq_hz == 1234.5f);
  v.tlm_rate_hz = 77u;
  assert_int_equal(param_get(&v, PARAM_tlm_rate_hz).u, 77u);
}

static void test_check(void **state)
{
  (void)state;
  param_value_t v;
  v.f = 500.0f;
  assert_int_equal(param_check(PARAM_drive_freq_hz, v), PARAM_OK);
  v.f = 5000.0f;
  assert_int_equal(param_check(PARAM_drive_freq_hz, v), PARAM_OK);
  v.f = nextafterf(500.0f, 0.0f);
  assert_int_equal(param_check(PARAM_drive_freq_hz, v), PARAM_ERR_RANGE);
  v.f = NAN;
  assert_int_equal(param_check(PARAM_drive_freq_hz, v), PARAM_ERR_NOT_FINITE);
  v.f = INFINITY;
  assert_int_equal(param_check(PARAM_drive_freq_hz, v), PARAM_ERR_NOT_FINITE);
  v.f = 0.0f; /* mu must be > 0 */
  assert_int_equal(param_check(PARAM_demod_mu_sense, v), PARAM_ERR_RANGE);
  v.f = 15.5f;
  assert_int_equal(param_check(PARAM_drive_u_max_v, v), PARAM_ERR_RANGE);
  for (uint32_t k = 0; k < 40u; k++) {
    v.u = k;
    const bool allowed = (k == 2u || k == 4u || k == 6u || k == 8u);
    assert_int_equal(param_check(PARAM_rate_lpf_order, v), allowed ? PARAM_OK : PARAM_ERR_CHOICE);
  }
  v.u = 0u;
  assert_int_equal(param_check(PARAM_tlm_rate_hz, v), PARAM_ERR_RANGE);
  v.u = 5001u;
  assert_int_equal(param_check(PARAM_tlm_rate_hz, v), PARAM_ERR_RANGE);
  assert_int_equal(param_check(PARAM_COUNT, v), PARAM_ERR_UNKNOWN);
}

/* ---- bank with a simulated ISR ---- */

#define TS (1.0f / 50000.0f)

typedef struct {
  float b0, b1; /* (6-26b) C(z) = (b0 + b1 z^-1) / (1 - z^-1), b0 = kp + ki T, b1 = -kp */
  float c0, c1; /* copy of a bias pair */
} derived_t;

typedef struct {
  params_t bank;
  derived_t derived[2];
  bool safe;
  bool isr_running;    /* the sample timer runs only after params_init */
  int ticks_in_derive; /* ISR ticks "preempting" the background inside derive() */
  unsigned ticks, violations, derive_calls;
  float last_kp_seen;
  unsigned kp_changes_seen;
} fixture_t;

/* Invariants the test keeps in every committed set: ki = 2 kp, c1 = -3 c0, and the
 * derived block belongs to the value block it is read with. */
static void sim_isr_tick(fixture_t *fx)
{
  const params_view_t view = params_isr_acquire(&fx->bank);
  const param_values_t *v = view.v;
  const derived_t *d = (const derived_t *)view.derived;
  fx->ticks++;
  const bool ok = v->drive_amp_ki == 2.0f * v->drive_amp_kp &&
                  v->rate_bias_c1_dps_per_deg == -3.0f * v->rate_bias_c0_dps &&
                  d->b0 == v->drive_amp_kp + v->drive_amp_ki * TS && d->b1 == -v->drive_amp_kp &&
                  d->c0 == v->rate_bias_c0_dps && d->c1 == v->rate_bias_c1_dps_per_deg;
  if (!ok) {
    fx->violations++;
  }
  if (v->drive_amp_kp != fx->last_kp_seen) {
    fx->kp_changes_seen++;
    fx->last_kp_seen = v->drive_amp_kp;
  }
}

static int derive(void *ctx, const param_values_t *v, void *out, const char **why)
{
  fixture_t *fx = ctx;
  derived_t *d = out;
  fx->derive_calls++;
  if (v->drive_amp_kp > 50.0f) {
    *why = "kp too high for this plant";
    return 1;
  }
  /* write the derived block piecewise with ticks in between: the ISR must not see it */
  const int ticks = fx->isr_running ? fx->ticks_in_derive : 0;
  for (int k = 0; k < ticks; k++) {
    sim_isr_tick(fx);
  }
  d->b0 = v->drive_amp_kp + v->drive_amp_ki * TS;
  if (fx->isr_running) {
    sim_isr_tick(fx);
  }
  d->b1 = -v->drive_amp_kp;
  if (fx->isr_running) {
    sim_isr_tick(fx);
  }
  d->c0 = v->rate_bias_c0_dps;
  d->c1 = v->rate_bias_c1_dps_per_deg;
  return 0;
}

static bool loop_safe(void *ctx) { return ((fixture_t *)ctx)->safe; }

static int setup(void **state)
{
  static fixture_t fx;
  memset(&fx, 0, sizeof fx);
  fx.ticks_in_derive = 3;
  param_values_t init;
  param_values_defaults(&init);
  init.drive_amp_kp = 1.0f;
  init.drive_amp_ki = 2.0f;
  init.rate_bias_c0_dps = 1.0f;
  init.rate_bias_c1_dps_per_deg = -3.0f;
  const params_cfg_t cfg = {derive, {&fx.derived[0], &fx.derived[1]}, loop_safe, &fx};
  params_err_t err;
  assert_int_equal(params_init(&fx.bank, &cfg, &init, &err), PARAM_OK);
  fx.last_kp_seen = 1.0f;
  fx.isr_running = true;
  *state = &fx;
  return 0;
}

static param_value_t fv(float f)
{
  param_value_t v = {.f = f};
  return v;
}

static uint32_t lcg(uint32_t *s)
{
  *s = *s * 1664525u + 1013904223u;
  return *s >> 8;
}

static void test_bank_never_half_applied(void **state)
{
  fixture_t *fx = *state;
  uint32_t seed = 12345u;
  unsigned committed = 0, rejected = 0, pending = 0;
  sim_isr_tick(fx);
  for (int n = 0; n < 20000; n++) {
    const param_values_t before = *params_current(&fx->bank);
    const uint32_t r = lcg(&seed);
    /* kp in (0, 60): above 50 derive() rejects */
    const float kp = 0.01f + (float)(r % 6000u) * 0.01f;
    const float c0 = (float)((int)(r % 200u) - 100);
    const int op = (int)(lcg(&seed) % 4u);
    if (op == 3) {
      /* an invalid stage in the middle of a transaction is refused on its own */
      assert_int_equal(params_stage(&fx->bank, PARAM_drive_amp_kp, fv(kp)), PARAM_OK);
      sim_isr_tick(fx);
      assert_int_equal(params_stage(&fx->bank, PARAM_drive_amp_ki, fv(NAN)),
                       PARAM_ERR_NOT_FINITE);
      sim_isr_tick(fx);
      params_discard(&fx->bank);
      assert_memory_equal(params_staged(&fx->bank), &before, sizeof before);
      continue;
    }
    assert_int_equal(params_stage(&fx->bank, PARAM_drive_amp_kp, fv(kp)), PARAM_OK);
    sim_isr_tick(fx);
    assert_int_equal(params_stage(&fx->bank, PARAM_drive_amp_ki, fv(2.0f * kp)), PARAM_OK);
    sim_isr_tick(fx);
    assert_int_equal(params_stage(&fx->bank, PARAM_rate_bias_c0_dps, fv(c0)), PARAM_OK);
    assert_int_equal(params_stage(&fx->bank, PARAM_rate_bias_c1_dps_per_deg, fv(-3.0f * c0)),
                     PARAM_OK);
    sim_isr_tick(fx);
    /* op 2: commit again before the ISR took the previous publish */
    params_err_t err;
    const param_status_t st = params_commit(&fx->bank, &err);
    if (st == PARAM_OK) {
      committed++;
      assert_true(params_current(&fx->bank)->drive_amp_kp == kp);
      const bool published = kp != before.drive_amp_kp || c0 != before.rate_bias_c0_dps;
      if (op == 2 && published) {
        assert_int_equal(params_set(&fx->bank, PARAM_drive_amp_kp, fv(kp * 0.5f), &err),
                         PARAM_ERR_PENDING);
        pending++;
        assert_true(params_current(&fx->bank)->drive_amp_kp == kp);
      }
    } else {
      assert_int_equal(st, PARAM_ERR_REJECTED);
      assert_true(kp > 50.0f);
      assert_string_equal(err.why, "kp too high for this plant");
      rejected++;
      assert_memory_equal(params_current(&fx->bank), &before, sizeof before);
    }
    /* after any commit, staged equals what the ISR will use */
    assert_memory_equal(params_staged(&fx->bank), params_current(&fx->bank), sizeof before);
    sim_isr_tick(fx);
  }
  assert_int_equal(fx->violations, 0);
  assert_true(committed > 1000 && rejected > 1000 && pending > 500);
  /* the ISR observed each committed kp (consecutive commits with equal kp aside) */
  assert_true(fx->kp_changes_seen <= committed && fx->kp_changes_seen > committed * 9 / 10);
}

/* The invariant checker is live: writing a live block directly is caught. */
static void test_checker_catches_half_update(void **state)
{
  fixture_t *fx = *state;
  sim_isr_tick(fx);
  assert_int_equal(fx->violations, 0);
  param_values_t *live = &fx->bank.block[atomic_load(&fx->bank.published) & 1u];
  live->drive_amp_kp += 1.0f; /* what a raw write from the background would do */
  sim_isr_tick(fx);
  assert_int_equal(fx->violations, 1);
}

static void test_non_live_needs_safe_loop(void **state)
{
  fixture_t *fx = *state;
  params_err_t err;
  param_value_t one = {.u = 1u};
  fx->safe = false;
  assert_int_equal(params_set(&fx->bank, PARAM_drive_mode, one, &err), PARAM_ERR_BUSY);
  assert_int_equal(err.idx, PARAM_drive_mode);
  assert_int_equal(params_current(&fx->bank)->drive_mode, 0u);
  assert_int_equal(params_staged(&fx->bank)->drive_mode, 0u);
  /* live parameters still change while the loop runs */
  assert_int_equal(params_set(&fx->bank, PARAM_drive_freq_hz, fv(1500.0f), &err), PARAM_OK);
  sim_isr_tick(fx);
  fx->safe = true;
  assert_int_equal(params_set(&fx->bank, PARAM_drive_mode, one, &err), PARAM_OK);
  assert_int_equal(params_current(&fx->bank)->drive_mode, 1u);
  sim_isr_tick(fx);
  assert_int_equal(fx->violations, 0);
}

static void test_readonly_and_stage_all(void **state)
{
  fixture_t *fx = *state;
  param_value_t v = {.u = 40000u};
  assert_int_equal(params_stage(&fx->bank, PARAM_sys_fs_hz, v), PARAM_ERR_READONLY);
  param_values_t all = *params_current(&fx->bank);
  all.sys_fs_hz = 1u; /* ignored: read-only */
  all.drive_freq_hz = 2000.0f;
  all.tlm_rate_hz = 0u; /* invalid: nothing staged */
  params_err_t err;
  assert_int_equal(params_stage_all(&fx->bank, &all, &err), PARAM_ERR_RANGE);
  assert_int_equal(err.idx, PARAM_tlm_rate_hz);
  assert_memory_equal(params_staged(&fx->bank), params_current(&fx->bank), sizeof all);
  all.tlm_rate_hz = 10u;
  assert_int_equal(params_stage_all(&fx->bank, &all, &err), PARAM_OK);
  assert_int_equal(params_commit(&fx->bank, &err), PARAM_OK);
  assert_int_equal(params_current(&fx->bank)->sys_fs_hz, 50000u);
  assert_true(params_current(&fx->bank)->drive_freq_hz == 2000.0f);
}

static void test_init_rejects_bad_initial(void **state)
{
  (void)state;
  params_t p;
  param_values_t bad;
  param_values_defaults(&bad);
  bad.demod_mu_drive = 0.6f;
  const params_cfg_t cfg = {NULL, {NULL, NULL}, NULL, NULL};
  params_err_t err;
  assert_int_equal(params_init(&p, &cfg, &bad, &err), PARAM_ERR_RANGE);
  assert_int_equal(err.idx, PARAM_demod_mu_drive);
  assert_int_equal(params_init(&p, &cfg, NULL, &err), PARAM_OK);
  /* without a loop_safe callback the loop is never considered safe */
  param_value_t one = {.u = 1u};
  assert_int_equal(params_set(&p, PARAM_drive_mode, one, &err), PARAM_ERR_BUSY);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_table_consistent),
      cmocka_unit_test(test_typed_and_generic_agree),
      cmocka_unit_test(test_check),
      cmocka_unit_test_setup(test_bank_never_half_applied, setup),
      cmocka_unit_test_setup(test_checker_catches_half_update, setup),
      cmocka_unit_test_setup(test_non_live_needs_safe_loop, setup),
      cmocka_unit_test_setup(test_readonly_and_stage_all, setup),
      cmocka_unit_test(test_init_rejects_bad_initial),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
