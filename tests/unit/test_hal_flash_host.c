/* Host NOR-flash stub: the semantics the parameter store's power-cut proofs rely on. */
#define _POSIX_C_SOURCE 200809L /* mkstemp */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "hal_flash_host.h"

static int setup(void **state)
{
  (void)state;
  const hal_flash_host_cfg_t cfg = {4u, 1024u, NULL, 0u, 0u, 0u};
  return hal_flash_host_configure(&cfg);
}

static void test_geometry_and_erased_start(void **state)
{
  (void)state;
  hal_flash_geometry_t g;
  hal_flash_geometry(&g);
  assert_int_equal(g.num_sectors, 4u);
  assert_int_equal(g.sector_size, 1024u);
  uint8_t buf[1024];
  for (uint32_t s = 0; s < 4u; s++) {
    assert_int_equal(hal_flash_read(s, 0u, buf, sizeof buf), HAL_FLASH_OK);
    for (size_t i = 0; i < sizeof buf; i++) {
      assert_int_equal(buf[i], 0xFF);
    }
  }
}

static void test_nor_semantics(void **state)
{
  (void)state;
  const uint8_t a[4] = {0xF0, 0x0F, 0xAA, 0x55};
  assert_int_equal(hal_flash_program(1u, 8u, a, 4u), HAL_FLASH_OK);
  /* clearing more bits is allowed (STM32F4: 1 -> 0 without erase) */
  const uint8_t b[4] = {0x30, 0x0F, 0x0A, 0x00};
  assert_int_equal(hal_flash_program(1u, 8u, b, 4u), HAL_FLASH_OK);
  uint8_t r[4];
  assert_int_equal(hal_flash_read(1u, 8u, r, 4u), HAL_FLASH_OK);
  assert_memory_equal(r, b, 4u);
  /* setting a 0 bit back to 1 fails whole: not even the valid first byte is written */
  const uint8_t c[4] = {0x10, 0x1F, 0x0A, 0x00};
  assert_int_equal(hal_flash_program(1u, 8u, c, 4u), HAL_FLASH_ERR_WRITE);
  assert_int_equal(hal_flash_read(1u, 8u, r, 4u), HAL_FLASH_OK);
  assert_memory_equal(r, b, 4u);
  /* erase restores 0xFF on that sector only */
  assert_int_equal(hal_flash_program(2u, 0u, a, 4u), HAL_FLASH_OK);
  assert_int_equal(hal_flash_erase(1u), HAL_FLASH_OK);
  assert_int_equal(hal_flash_read(1u, 8u, r, 4u), HAL_FLASH_OK);
  const uint8_t ff[4] = {0xFF, 0xFF, 0xFF, 0xFF};
  assert_memory_equal(r, ff, 4u);
  assert_int_equal(hal_flash_read(2u, 0u, r, 4u), HAL_FLASH_OK);
  assert_memory_equal(r, a, 4u);
}

static void test_range_checks(void **state)
{
  (void)state;
  uint8_t r[8] = {0};
  assert_int_equal(hal_flash_erase(4u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_read(0u, 1020u, r, 8u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_program(0u, 1024u, r, 1u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_program(0u, 0xFFFFFFF0u, r, 0x20u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_read(0u, 1016u, r, 8u), HAL_FLASH_OK);
  const hal_flash_host_cfg_t too_big = {64u, 16384u, NULL, 0u, 0u, 0u};
  assert_int_equal(hal_flash_host_configure(&too_big), -1);
  const hal_flash_host_cfg_t odd = {2u, 1022u, NULL, 0u, 0u, 0u};
  assert_int_equal(hal_flash_host_configure(&odd), -1);
}

/* Busy time: erase_us per erase, program_word_us per started 32-bit word. */
static void test_busy_clock(void **state)
{
  (void)state;
  const hal_flash_host_cfg_t cfg = {2u, 16384u, NULL, 0u, 0u, 0u}; /* datasheet defaults */
  assert_int_equal(hal_flash_host_configure(&cfg), 0);
  hal_flash_host_stats_t st;
  hal_flash_host_stats(&st);
  assert_int_equal(st.busy_us, 0u);
  assert_int_equal(hal_flash_erase(0u), HAL_FLASH_OK);
  const uint8_t d[10] = {0};
  assert_int_equal(hal_flash_program(0u, 0u, d, 10u), HAL_FLASH_OK); /* 3 words */
  hal_flash_host_stats(&st);
  assert_int_equal(st.busy_us, 250000u + 3u * 16u);
  assert_int_equal(st.longest_stall_us, 250000u);
  assert_int_equal(st.erases, 1u);
  assert_int_equal(st.programmed_bytes, 10u);
}

static void test_power_cut_in_program(void **state)
{
  (void)state;
  uint8_t d[16];
  memset(d, 0x00, sizeof d);
  hal_flash_host_power_cut_after(5u);
  assert_int_equal(hal_flash_program(0u, 0u, d, 3u), HAL_FLASH_OK); /* 2 left */
  assert_int_equal(hal_flash_program(0u, 3u, d, 8u), HAL_FLASH_ERR_POWER);
  assert_true(hal_flash_host_power_is_down());
  uint8_t r[16];
  assert_int_equal(hal_flash_read(0u, 0u, r, 16u), HAL_FLASH_OK);
  for (int i = 0; i < 5; i++) {
    assert_int_equal(r[i], 0x00);
  }
  assert_int_equal(r[5], 0xF0); /* torn: low nibble programmed, high nibble not */
  for (int i = 6; i < 16; i++) {
    assert_int_equal(r[i], 0xFF);
  }
  /* nothing later is written until power returns */
  assert_int_equal(hal_flash_program(1u, 0u, d, 4u), HAL_FLASH_ERR_POWER);
  assert_int_equal(hal_flash_erase(0u), HAL_FLASH_ERR_POWER);
  assert_int_equal(hal_flash_read(1u, 0u, r, 4u), HAL_FLASH_OK);
  assert_int_equal(r[0], 0xFF);
  hal_flash_host_power_restore();
  assert_int_equal(hal_flash_program(1u, 0u, d, 4u), HAL_FLASH_OK);
}

static void test_power_cut_in_erase_and_bit_flip(void **state)
{
  (void)state;
  uint8_t d[64];
  memset(d, 0x12, sizeof d);
  assert_int_equal(hal_flash_program(0u, 0u, d, sizeof d), HAL_FLASH_OK);
  hal_flash_host_power_cut_in_erase(20u);
  assert_int_equal(hal_flash_erase(0u), HAL_FLASH_ERR_POWER);
  uint8_t r[64];
  assert_int_equal(hal_flash_read(0u, 0u, r, sizeof r), HAL_FLASH_OK);
  for (int i = 0; i < 64; i++) {
    assert_int_equal(r[i], i < 20 ? 0xFF : 0x12);
  }
  hal_flash_host_power_restore();
  assert_int_equal(hal_flash_host_flip_bit(0u, 30u, 7u), 0);
  assert_int_equal(hal_flash_read(0u, 30u, r, 1u), HAL_FLASH_OK);
  assert_int_equal(r[0], 0x92);
  assert_int_equal(hal_flash_host_flip_bit(0u, 1024u, 0u), -1);
  assert_int_equal(hal_flash_host_flip_bit(0u, 0u, 8u), -1);
}

/* File backing: the content survives a close and re-open ("reboot"). */
static void test_file_backed(void **state)
{
  (void)state;
  char path[] = "/tmp/gyro_flash_XXXXXX";
  const int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd); /* empty file: wrong size, so it starts as a blank part */
  const hal_flash_host_cfg_t cfg = {2u, 512u, path, 0u, 0u, 0u};
  assert_int_equal(hal_flash_host_configure(&cfg), 0);
  uint8_t r[4];
  assert_int_equal(hal_flash_read(1u, 100u, r, 4u), HAL_FLASH_OK);
  assert_int_equal(r[0], 0xFF);
  const uint8_t d[4] = {1, 2, 3, 4};
  assert_int_equal(hal_flash_program(1u, 100u, d, 4u), HAL_FLASH_OK);
  hal_flash_host_close();
  assert_int_equal(hal_flash_host_configure(&cfg), 0);
  assert_int_equal(hal_flash_read(1u, 100u, r, 4u), HAL_FLASH_OK);
  assert_memory_equal(r, d, 4u);
  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  fseek(f, 0, SEEK_END);
  assert_int_equal(ftell(f), 1024);
  fclose(f);
  hal_flash_host_close();
  remove(path);
}

/* program_bytes 8 models ECC flash (an STM32G4): whole aligned units, each once. */
static void test_ecc_program_unit(void **state)
{
  (void)state;
  const hal_flash_host_cfg_t cfg = {2u, 1024u, NULL, 0u, 0u, 8u};
  assert_int_equal(hal_flash_host_configure(&cfg), 0);
  hal_flash_geometry_t geo;
  hal_flash_geometry(&geo);
  assert_int_equal(geo.program_bytes, 8u);
  const uint8_t d[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
  assert_int_equal(hal_flash_program(0u, 4u, d, 8u), HAL_FLASH_ERR_RANGE); /* misaligned */
  assert_int_equal(hal_flash_program(0u, 0u, d, 4u), HAL_FLASH_ERR_RANGE); /* part unit */
  assert_int_equal(hal_flash_program(0u, 0u, d, 16u), HAL_FLASH_OK);
  /* once: even clearing more bits of a programmed unit is refused */
  const uint8_t z[8] = {0};
  assert_int_equal(hal_flash_program(0u, 8u, z, 8u), HAL_FLASH_ERR_WRITE);
  assert_int_equal(hal_flash_erase(0u), HAL_FLASH_OK);
  assert_int_equal(hal_flash_program(0u, 8u, z, 8u), HAL_FLASH_OK);
  /* the default is the STM32F4 word, with byte-wise NOR rules */
  assert_int_equal(hal_flash_host_configure(NULL), 0);
  hal_flash_geometry(&geo);
  assert_int_equal(geo.program_bytes, 4u);
  const hal_flash_host_cfg_t bad = {2u, 1024u, NULL, 0u, 0u, 12u};
  assert_int_equal(hal_flash_host_configure(&bad), -1);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_geometry_and_erased_start, setup),
      cmocka_unit_test_setup(test_nor_semantics, setup),
      cmocka_unit_test_setup(test_range_checks, setup),
      cmocka_unit_test_setup(test_busy_clock, setup),
      cmocka_unit_test_setup(test_power_cut_in_program, setup),
      cmocka_unit_test_setup(test_power_cut_in_erase_and_bit_flip, setup),
      cmocka_unit_test_setup(test_file_backed, setup),
      cmocka_unit_test_setup(test_ecc_program_unit, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
