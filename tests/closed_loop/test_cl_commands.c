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

/* ---- the cases ---- *//* Subnormal values: refused from a flash record and from gyro-sim --set as they are
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
  assert_string_equal(cmd("diff\n"), "ok 0 differ\r\n");
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
  const char *const lines[] = {"help x\n", "version x\n", "save x\n", "load x\n",
                               "defaults x\n", "diff x\n", "list a b\n", "get a b\n"};
  for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
    assert_non_null(strstr(cmd(lines[i]), "err ARGS "));
  }
}



int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_subnormal_refused_everywhere),
      cmocka_unit_test(test_minus_zero_normalised),
      cmocka_unit_test(test_duplicate_record_ids_take_default),
      cmocka_unit_test(test_newer_format_image_not_overwritten),
      cmocka_unit_test(test_extra_words_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
