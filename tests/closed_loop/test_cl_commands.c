/* Commands and storage that keep what they acknowledge: the whole application on the
 * plant, driven over its command line. One test per case of the field report: each
 * pins what an acknowledged command (or a stored image) must do. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app_plant.h"
#include "params/crc32.h"
#include "sim.h"

static void start(void)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  app_plant_start(&pc, 7u, NULL);
}

/* Start over the flash as it is (an image written by the test), not an empty store. */
static void start_on_flash(void)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  if (plant_init(&plant, &pc, 7u) != 0) fail_msg("plant: %s", plant_error(&plant));
  hal_uart_host_reset();
  hal_host_attach(plant_step_hal, &plant);
  assert_int_equal(app_init(&app), 0);
  assert_int_equal(hal_sample_timer_start(50000u, app_sample_isr, &app), 0);
}

/* The background loop runs n times with the clock going on between: what a batch of
 * commands sees on the board. Returns everything sent meanwhile. */
static const char *drain(int n)
{
  static char out[65536];
  size_t len = 0u;
  for (int i = 0; i < n; i++) {
    app_poll(&app);
    len += hal_uart_host_tx_pop((uint8_t *)&out[len], sizeof out - 1u - len);
    run_s(0.001);
  }
  out[len] = '\0';
  return out;
}

static size_t count_of(const char *hay, const char *needle)
{
  size_t n = 0u;
  for (const char *p = strstr(hay, needle); p != NULL; p = strstr(p + 1, needle)) n++;
  return n;
}

static float param_f(param_idx_t i) { return param_get(params_current(&app.params), i).f; }

/* ---- flash images written by hand ---- */

typedef struct {
  uint16_t id;
  uint8_t type;
  uint32_t value;
} rec_t;

static void put32(uint8_t *p, uint32_t v)
{
  for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t bits_of(float f)
{
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

/* A committed image in sector 0 (slot A) in the layout of param_store.h. */
static void write_image(uint16_t format, const rec_t *r, uint32_t n)
{
  assert_int_equal(hal_flash_host_configure(NULL), 0);
  uint8_t img[512];
  assert_true(20u + 8u * n + 8u <= sizeof img);
  put32(&img[0], PARAM_STORE_MAGIC);
  img[4] = (uint8_t)format;
  img[5] = (uint8_t)(format >> 8);
  img[6] = (uint8_t)PARAM_LAYOUT_VERSION;
  img[7] = 0u;
  put32(&img[8], 0x00010000u);
  put32(&img[12], 5u);
  put32(&img[16], n);
  for (uint32_t k = 0; k < n; k++) {
    uint8_t *p = &img[20u + 8u * k];
    p[0] = (uint8_t)r[k].id;
    p[1] = (uint8_t)(r[k].id >> 8);
    p[2] = r[k].type;
    p[3] = 0u;
    put32(&p[4], r[k].value);
  }
  const uint32_t body = 20u + 8u * n;
  put32(&img[body], crc32_update(0u, img, body));
  put32(&img[body + 4u], PARAM_STORE_COMMIT);
  assert_int_equal(hal_flash_program(0u, 0u, img, body + 8u), HAL_FLASH_OK);
}

static uint16_t id_of(param_idx_t i) { return param_info(i)->id; }

/* ---- the cases ---- */

/* `drive off` and `selftest` in one write: both used to share one request word, so the
 * self-test replaced the drive off and the drive kept running. Now the drive off is
 * queued, and the self-test, judged against the drive as it will be, is refused. */
static void test_drive_off_then_selftest_in_one_write(void **state)
{
  (void)state;
  start();
  run_s(0.3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  const char *r = cmd("drive off\nselftest\n");
  assert_non_null(strstr(r, "ok drive off\r\n"));
  assert_non_null(strstr(r, "err STATE "));
  run_s(0.01);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_OFF);
  assert_int_equal(app.gyro.selftest.state, SELFTEST_IDLE);
}

/* `sweep` and `drive off` (or `drive on`) in one write: the sweep was never entered and
 * the sequencer waited for it forever, refusing every later sweep. Now the drive command
 * aborts the sweep, both take effect in order, and a new sweep is accepted. */
static void check_sweep_then_drive(const char *drive, gyro_mode_t after)
{
  start();
  run_s(0.05);
  char line[64];
  snprintf(line, sizeof line, "sweep\n%s\n", drive);
  const char *r = cmd(line);
  assert_non_null(strstr(r, "ok sweep started\r\n"));
  assert_int_equal(count_of(r, "ok "), 2u);
  (void)drain(10);
  assert_int_equal(app.gyro.sup.mode, after);
  assert_int_equal(app.selfcal.state, SELFCAL_FAILED);
  assert_non_null(strstr(cmd("status\n"), "- selfcal_why sweep aborted by a drive command"));
  assert_string_equal(cmd("sweep\n"), "ok sweep started\r\n");
  (void)drain(5);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_SWEEP);
}

static void test_sweep_then_drive_off_in_one_write(void **state)
{
  (void)state;
  check_sweep_then_drive("drive off", GYRO_MODE_OFF);
}

static void test_sweep_then_drive_on_in_one_write(void **state)
{
  (void)state;
  check_sweep_then_drive("drive on", GYRO_MODE_ACQUIRE);
}

/* A sweep whose request the ISR never takes (the clock stopped) cannot hold the
 * sequencer: WAIT_SWEEP times out after 0.1 s of the caller's ticks. */
static void test_sweep_request_never_taken_times_out(void **state)
{
  (void)state;
  start();
  /* no tick runs: the background's first look starts the clock at app_ticks = 0 */
  assert_string_equal(cmd("sweep\n"), "ok sweep started\r\n");
  assert_int_equal(app_ticks(&app), 0u);
  selfcal_watch(&app.selfcal, 4900u);
  assert_int_equal(app.selfcal.state, SELFCAL_WAIT_SWEEP);
  selfcal_watch(&app.selfcal, 5100u);
  assert_int_equal(app.selfcal.state, SELFCAL_FAILED);
  assert_string_equal(app.selfcal.why, "the drive never entered SWEEP");
  (void)drain(3); /* the failed sweep takes the drive off */
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_OFF);
  assert_string_equal(cmd("sweep\n"), "ok sweep started\r\n");
}

/* RX overflow in a batch (the loop stalled by a flash save): the ring held
 * "set rate.bias_c0_dps 10" when the "0" was lost; the line must be discarded with
 * err OVERFLOW, never executed as 10, and the loss counted in status. */
static void test_rx_overflow_discards_the_line(void **state)
{
  (void)state;
  start();
  run_s(0.01);
  const float before = param_f(PARAM_rate_bias_c0_dps);
  static const char head[] = "set rate.bias_c0_dps 10";
  uint8_t fill[HAL_UART_HOST_RX_SIZE];
  const size_t room = HAL_UART_HOST_RX_SIZE - 1u; /* one slot of the ring stays free */
  const size_t pad = room - (sizeof head - 1u);
  memset(fill, '\n', pad); /* blank lines: no reply */
  memcpy(&fill[pad], head, sizeof head - 1u);
  assert_int_equal(hal_uart_host_rx_push(fill, room), room);
  assert_int_equal(hal_uart_host_rx_push((const uint8_t *)"0", 1u), 0u); /* lost */
  (void)cmd("");
  const char *r = cmd("\n");
  assert_non_null(strstr(r, "err OVERFLOW "));
  assert_null(strstr(r, "ok"));
  assert_true(param_f(PARAM_rate_bias_c0_dps) == before);
  assert_non_null(strstr(cmd("status\n"), "- rx_overflows 1\r\n"));
  /* the line discipline recovers: the next line is executed */
  assert_non_null(strstr(cmd("set rate.bias_c0_dps 10\n"), "ok "));
  assert_string_equal(cmd("get rate.bias_c0_dps\n"), "ok rate.bias_c0_dps 10 deg/s\r\n");
}

/* Two `list` pipelined: the second reply used to be cut where the TX ring was full and
 * the next reply glued on. Every reply now comes out whole, in order. */
static void test_pipelined_lists_come_out_whole(void **state)
{
  (void)state;
  start();
  run_s(0.01);
  const char *batch = "list\nlist\nversion\n";
  assert_int_equal(hal_uart_host_rx_push((const uint8_t *)batch, strlen(batch)), strlen(batch));
  const char *out = drain(20);
  assert_int_equal(hal_uart_host_tx_dropped(), 0u);
  assert_int_equal(count_of(out, " parameters\r\n"), 2u);
  const char *second = strstr(strstr(out, " parameters\r\n") + 1, "- drive.freq_hz ");
  assert_non_null(second);
  assert_non_null(strstr(out, "\r\nok fw "));
  /* every line is a data line or a final line: nothing cut or glued */
  for (const char *p = out; *p != '\0';) {
    assert_true(strncmp(p, "- ", 2) == 0 || strncmp(p, "ok", 2) == 0);
    const char *e = strstr(p, "\r\n");
    assert_non_null(e);
    assert_null(memchr(p, '\n', (size_t)(e - p)));
    p = e + 2;
  }
}

/* The README's own tuning step: from 0.349 V to 0.2 V the over-amplitude trip (1.5 x the
 * new setpoint, 0.3 V) used to fire on the vibration still at 0.349 V. The setpoint now
 * slews and the trip follows it. */
static void test_amp_setpoint_step_down_no_fault(void **state)
{
  (void)state;
  start();
  run_s(0.3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_true(strncmp(cmd("set drive.amp_set_v 0.2\n"), "ok", 2) == 0);
  run_s(1.0);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_true(fabsf(app.gyro.drive.amp_v / 0.2f - 1.0f) < 0.02f);
  /* and back up, and a phase setpoint across most of its range */
  assert_true(strncmp(cmd("set drive.amp_set_v 0.349 drive.phase_set_deg 170\n"), "ok", 2) == 0);
  run_s(2.5);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
}

/* A fault stays shown until cleared (`clear`, or `drive on`); it stays readable as
 * history (last_fault with its time). */
static void test_fault_clear_and_history(void **state)
{
  (void)state;
  start();
  run_s(0.3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  app.gyro.drive.amp_pi.u = NAN; /* a broken loop state */
  run_s(0.01);
  /* the fault's wait ends in a restart by itself: the drive is not off */
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_FAULT);
  assert_non_null(strstr(cmd("save\n"), "err BUSY "));
  run_s(1.0);
  assert_int_equal(app.gyro.sup.fault_count, 1u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  const char *s = cmd("status\n");
  assert_non_null(strstr(s, "- fault NAN\r\n"));
  assert_non_null(strstr(s, "- last_fault NAN\r\n"));
  assert_non_null(strstr(s, "- last_fault_s 0.3"));
  assert_string_equal(cmd("clear\n"), "ok fault cleared\r\n");
  assert_non_null(strstr(cmd("clear x\n"), "err ARGS"));
  run_s(0.001);
  s = cmd("status\n");
  assert_non_null(strstr(s, "- fault none\r\n"));
  assert_non_null(strstr(s, "- last_fault NAN\r\n"));
  assert_non_null(strstr(s, "- fault_count 1\r\n"));
  /* drive on after a fault clears it too */
  app.gyro.drive.amp_pi.u = NAN;
  run_s(1.0);
  assert_non_null(strstr(cmd("status\n"), "- fault NAN\r\n"));
  assert_string_equal(cmd("drive on\n"), "ok drive on\r\n");
  run_s(0.001);
  assert_non_null(strstr(cmd("status\n"), "- fault none\r\n"));
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
}

/* `save` and a non-live `set` during a sweep: the sweep excites the drive, which a
 * flash stall would leave running uncontrolled. Both refused. */
static void test_save_and_nonlive_set_refused_during_sweep(void **state)
{
  (void)state;
  start();
  run_s(0.01);
  assert_string_equal(cmd("sweep\n"), "ok sweep started\r\n");
  (void)drain(3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_SWEEP);
  assert_non_null(strstr(cmd("save\n"), "err BUSY "));
  assert_non_null(strstr(cmd("set drive.mode 1\n"), "err BUSY "));
  assert_int_equal(params_current(&app.params)->drive_mode, 0u);
  /* a queued drive on makes the loop unsafe at once */
  assert_string_equal(cmd("drive off\n"), "ok drive off\r\n");
  run_s(0.001);
  assert_non_null(strstr(cmd("drive on\nsave\n"), "err BUSY "));
}

/* A stored set whose values are each in range but cannot be designed together: keep
 * every parameter that can be kept, drop the rest, say which and why. */
static void test_undesignable_stored_set_keeps_the_rest(void **state)
{
  (void)state;
  const rec_t r[] = {
      {id_of(PARAM_rate_out_v_per_dps), PARAM_T_F32, bits_of(0.05f)}, /* span 15 V > fault 10 V */
      {id_of(PARAM_rate_bias_c0_dps), PARAM_T_F32, bits_of(1.5f)},
      {id_of(PARAM_drive_cal_q), PARAM_T_F32, bits_of(40.0f)},
  };
  write_image(PARAM_STORE_FORMAT, r, 3u);
  start_on_flash();
  assert_true(param_f(PARAM_rate_bias_c0_dps) == 1.5f);
  assert_true(param_f(PARAM_drive_cal_q) == 40.0f);
  assert_true(param_f(PARAM_rate_out_v_per_dps) == param_info(PARAM_rate_out_v_per_dps)->def.f);
  const char *s = cmd("status\n");
  assert_non_null(strstr(s, "- store ok\r\n"));
  assert_non_null(strstr(s, "- store_dropped rate.out_v_per_dps: "));
  assert_non_null(strstr(s, gyro_design_reason(GYRO_DESIGN_FAULT_OUT))); /* the boot's reason */
  /* the same value at `set` time is refused with the reason */
  const char *e = cmd("set rate.out_v_per_dps 0.05\n");
  assert_non_null(strstr(e, "err REJECTED "));
  assert_non_null(strstr(e, ": rate.fault_out_v must lie outside"));
}

/* Subnormal values: refused from a flash record and from gyro-sim --set as they are
 * by the command line. */
static void test_subnormal_refused_everywhere(void **state)
{
  (void)state;
  const rec_t r[] = {{id_of(PARAM_rate_bias_c0_dps), PARAM_T_F32, 1u}}; /* 1.4e-45 */
  write_image(PARAM_STORE_FORMAT, r, 1u);
  start_on_flash();
  assert_int_equal(app.store_status, PARAM_STORE_OK);
  assert_true(param_get(params_current(&app.params), PARAM_rate_bias_c0_dps).u == 0u);
  assert_non_null(strstr(cmd("set rate.bias_c0_dps 1e-45\n"), "err "));
  assert_non_null(strstr(cmd("load\n"), " rejected 1 "));
  sim_scenario_t sc;
  memset(&sc, 0, sizeof sc);
  snprintf(sc.fw_set[0].key, sizeof sc.fw_set[0].key, "rate.bias_c0_dps");
  sc.fw_set[0].value = 1e-45;
  sc.n_fw_set = 1;
  param_values_t v;
  char err[256];
  assert_int_equal(sim_fw_params(&sc, &v, err, sizeof err), -1);
}

/* -0 is the same value as 0: normalised wherever it enters, so it is neither listed by
 * diff nor saved as 0x80000000. */
static void test_minus_zero_normalised(void **state)
{
  (void)state;
  start();
  run_s(0.01);
  assert_string_equal(cmd("set drive.amp_kp -0\n"), "ok drive.amp_kp 0\r\n");
  assert_true(param_get(params_current(&app.params), PARAM_drive_amp_kp).u == 0u);
  assert_null(strstr(cmd("diff\n"), "drive.amp_kp"));
  const rec_t r[] = {{id_of(PARAM_rate_bias_c0_dps), PARAM_T_F32, 0x80000000u}};
  write_image(PARAM_STORE_FORMAT, r, 1u);
  start_on_flash();
  assert_true(param_get(params_current(&app.params), PARAM_rate_bias_c0_dps).u == 0u);
  sim_scenario_t sc;
  memset(&sc, 0, sizeof sc);
  snprintf(sc.fw_set[0].key, sizeof sc.fw_set[0].key, "drive.amp_kp");
  sc.fw_set[0].value = -0.0;
  sc.n_fw_set = 1;
  param_values_t v;
  char err[256];
  assert_int_equal(sim_fw_params(&sc, &v, err, sizeof err), 0);
  assert_true(param_get(&v, PARAM_drive_amp_kp).u == 0u);
}

/* Duplicate record ids: as param_store.h says, the parameter keeps its default (which of
 * two records was meant cannot be told) and both records count as rejected. */
static void test_duplicate_record_ids_take_default(void **state)
{
  (void)state;
  const rec_t r[] = {
      {id_of(PARAM_rate_bias_c0_dps), PARAM_T_F32, bits_of(1.5f)},
      {id_of(PARAM_rate_scale_dps), PARAM_T_F32, bits_of(1.0f)},
      {id_of(PARAM_rate_bias_c0_dps), PARAM_T_F32, bits_of(2.5f)},
      {id_of(PARAM_rate_bias_c0_dps), PARAM_T_F32, bits_of(3.5f)},
  };
  write_image(PARAM_STORE_FORMAT, r, 4u);
  start_on_flash();
  assert_int_equal(app.store_status, PARAM_STORE_OK);
  assert_true(param_f(PARAM_rate_bias_c0_dps) == 0.0f);
  assert_true(param_f(PARAM_rate_scale_dps) == 1.0f);
  assert_non_null(strstr(cmd("load\n"), " rejected 3 "));
}

/* An image of a newer format is not ours to overwrite: save refused with a clear error,
 * `save force` writes the other slot and keeps it. */
static void test_newer_format_image_not_overwritten(void **state)
{
  (void)state;
  const rec_t r[] = {{id_of(PARAM_rate_bias_c0_dps), PARAM_T_F32, bits_of(1.5f)}};
  write_image(PARAM_STORE_FORMAT + 1u, r, 1u);
  uint8_t before[64];
  assert_int_equal(hal_flash_read(0u, 0u, before, sizeof before), HAL_FLASH_OK);
  start_on_flash();
  assert_non_null(strstr(cmd("status\n"), "- store newer format image (not loaded)\r\n"));
  assert_string_equal(cmd("drive off\n"), "ok drive off\r\n");
  run_s(0.001);
  const char *e = cmd("save\n");
  assert_non_null(strstr(e, "err FORMAT "));
  assert_non_null(strstr(e, "save force"));
  assert_non_null(strstr(cmd("save forc\n"), "err ARGS"));
  uint8_t after[64];
  assert_int_equal(hal_flash_read(0u, 0u, after, sizeof after), HAL_FLASH_OK);
  assert_memory_equal(before, after, sizeof before);
  assert_string_equal(cmd("save force\n"), "ok saved slot B seq 1\r\n");
  assert_int_equal(hal_flash_read(0u, 0u, after, sizeof after), HAL_FLASH_OK);
  assert_memory_equal(before, after, sizeof before);
}

/* Extra words are refused by every built-in, help and version included. */
static void test_extra_words_refused(void **state)
{
  (void)state;
  start();
  const char *const lines[] = {"help x\n",     "version x\n", "save x\n",   "load x\n",
                               "defaults x\n", "diff x\n",    "list a b\n", "get a b\n"};
  for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
    assert_non_null(strstr(cmd(lines[i]), "err ARGS "));
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_drive_off_then_selftest_in_one_write),
      cmocka_unit_test(test_sweep_then_drive_off_in_one_write),
      cmocka_unit_test(test_sweep_then_drive_on_in_one_write),
      cmocka_unit_test(test_sweep_request_never_taken_times_out),
      cmocka_unit_test(test_rx_overflow_discards_the_line),
      cmocka_unit_test(test_pipelined_lists_come_out_whole),
      cmocka_unit_test(test_amp_setpoint_step_down_no_fault),
      cmocka_unit_test(test_fault_clear_and_history),
      cmocka_unit_test(test_save_and_nonlive_set_refused_during_sweep),
      cmocka_unit_test(test_undesignable_stored_set_keeps_the_rest),
      cmocka_unit_test(test_subnormal_refused_everywhere),
      cmocka_unit_test(test_minus_zero_normalised),
      cmocka_unit_test(test_duplicate_record_ids_take_default),
      cmocka_unit_test(test_newer_format_image_not_overwritten),
      cmocka_unit_test(test_extra_words_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
