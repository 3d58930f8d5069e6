/* Parameter flash driver (hal/stm32f4/stm32f4_flash.c) against a fake flash controller:
 * the poll hook plays the hardware (accepts the keys, erases the selected sector, reports
 * errors) and records the control register each time the driver waits on it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "hal/hal_flash.h"
#include "stm32f4_host_regs.h"

#define SECTOR STM32F4_PARAM_SECTOR_BYTES

static uint32_t s_cr_log[64];
static int s_cr_n;
static int s_keys_work;
static uint32_t s_inject_sr;

static void flash_controller(void)
{
  if (s_keys_work && FLASH_R->KEYR == FLASH_KEY2) FLASH_R->CR &= ~FLASH_CR_LOCK;
  const uint32_t cr = FLASH_R->CR;
  if ((cr & (FLASH_CR_STRT | FLASH_CR_PG)) != 0u && s_cr_n < 64) s_cr_log[s_cr_n++] = cr;
  if ((cr & FLASH_CR_STRT) != 0u && (cr & FLASH_CR_SER) != 0u) {
    const uint32_t snb = (cr & FLASH_CR_SNB_MASK) >> FLASH_CR_SNB_POS;
    if (snb >= 1u && snb <= 2u && s_inject_sr == 0u) {
      memset(stm32f4_host_param_flash() + (snb - 1u) * SECTOR, 0xFF, SECTOR);
    }
    FLASH_R->CR = cr & ~FLASH_CR_STRT;
  }
  /* Not busy any more; the status shows only the injected error (the driver's
   * write-1-to-clear of stale flags is taken as done). */
  FLASH_R->SR = s_inject_sr;
}

static int setup(void **state)
{
  (void)state;
  stm32f4_host_reset();
  stm32f4_host_map.poll_hook = flash_controller;
  s_cr_n = 0;
  s_keys_work = 1;
  s_inject_sr = 0u;
  return 0;
}

static void test_geometry(void **state)
{
  (void)state;
  hal_flash_geometry_t g;
  hal_flash_geometry(&g);
  assert_int_equal(g.num_sectors, 2);
  assert_int_equal(g.sector_size, 16384);
  hal_flash_geometry(NULL);
}

static void test_erase_sequence(void **state)
{
  (void)state;
  memset(stm32f4_host_param_flash() + SECTOR, 0x00, SECTOR); /* store sector 1 dirty */
  assert_int_equal(hal_flash_erase(1u), HAL_FLASH_OK);
  /* While the erase ran: sector erase of flash sector 2, 32-bit parallelism, started. */
  assert_true(s_cr_n >= 1);
  assert_int_equal(s_cr_log[0], FLASH_CR_PSIZE_X32 | FLASH_CR_SER | (2u << FLASH_CR_SNB_POS) |
                                    FLASH_CR_STRT);
  assert_int_equal(FLASH_R->KEYR, FLASH_KEY2);
  assert_int_equal(FLASH_R->CR, FLASH_CR_LOCK); /* operation bits cleared, locked again */
  for (uint32_t i = 0; i < SECTOR; ++i)
    assert_int_equal(stm32f4_host_param_flash()[SECTOR + i], 0xFF);

  s_cr_n = 0;
  assert_int_equal(hal_flash_erase(0u), HAL_FLASH_OK);
  assert_int_equal((s_cr_log[0] & FLASH_CR_SNB_MASK) >> FLASH_CR_SNB_POS, 1u);
}

static void test_erase_out_of_range_touches_nothing(void **state)
{
  (void)state;
  assert_int_equal(hal_flash_erase(2u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(FLASH_R->KEYR, 0u);
  assert_int_equal(FLASH_R->CR, FLASH_CR_LOCK);
}

static void test_erase_reports_hardware_error(void **state)
{
  (void)state;
  s_inject_sr = FLASH_SR_WRPERR; /* write-protected sector */
  assert_int_equal(hal_flash_erase(0u), HAL_FLASH_ERR_WRITE);
  assert_int_equal(FLASH_R->CR, FLASH_CR_LOCK);
}

static void test_locked_controller_is_an_error(void **state)
{
  (void)state;
  s_keys_work = 0;
  assert_int_equal(hal_flash_erase(0u), HAL_FLASH_ERR_WRITE);
  assert_int_equal(s_cr_n, 0); /* never started */
}

static void test_program_bytes_then_words(void **state)
{
  (void)state;
  const uint8_t data[7] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77};
  assert_int_equal(hal_flash_program(0u, 1u, data, sizeof(data)), HAL_FLASH_OK);
  /* Offsets 1..3 are not word aligned: three x8 programs, then one x32 word at 4. */
  assert_int_equal(s_cr_n, 4);
  for (int i = 0; i < 3; ++i) {
    assert_int_equal(s_cr_log[i], FLASH_CR_PSIZE_X8 | FLASH_CR_PG);
  }
  assert_int_equal(s_cr_log[3], FLASH_CR_PSIZE_X32 | FLASH_CR_PG);
  uint8_t back[9];
  assert_int_equal(hal_flash_read(0u, 0u, back, sizeof(back)), HAL_FLASH_OK);
  assert_int_equal(back[0], 0xFF);
  assert_memory_equal(back + 1, data, sizeof(data));
  assert_int_equal(back[8], 0xFF);
  assert_int_equal(FLASH_R->CR, FLASH_CR_LOCK);
}

static void test_program_cannot_set_bits(void **state)
{
  (void)state;
  const uint8_t zero = 0x0F;
  const uint8_t one = 0xF0;
  assert_int_equal(hal_flash_program(1u, 100u, &zero, 1u), HAL_FLASH_OK);
  const uint32_t keyr_before = FLASH_R->KEYR;
  FLASH_R->KEYR = 0u;
  assert_int_equal(hal_flash_program(1u, 100u, &one, 1u), HAL_FLASH_ERR_WRITE);
  assert_int_equal(FLASH_R->KEYR, 0u); /* refused before unlocking */
  (void)keyr_before;
  uint8_t b;
  assert_int_equal(hal_flash_read(1u, 100u, &b, 1u), HAL_FLASH_OK);
  assert_int_equal(b, 0x0F);
  /* Clearing more bits is allowed (NOR semantics). */
  const uint8_t fewer = 0x05;
  assert_int_equal(hal_flash_program(1u, 100u, &fewer, 1u), HAL_FLASH_OK);
}

static void test_range_checks(void **state)
{
  (void)state;
  uint8_t buf[8] = {0};
  assert_int_equal(hal_flash_program(0u, SECTOR - 4u, buf, 8u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_program(0u, SECTOR + 1u, buf, 0u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_program(0u, 4u, buf, SIZE_MAX), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_program(2u, 0u, buf, 1u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_program(0u, 0u, NULL, 1u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_read(0u, SECTOR - 4u, buf, 8u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_read(5u, 0u, buf, 1u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_read(0u, 0u, NULL, 1u), HAL_FLASH_ERR_RANGE);
  assert_int_equal(hal_flash_read(1u, SECTOR - 8u, buf, 8u), HAL_FLASH_OK);
  assert_int_equal(FLASH_R->KEYR, 0u);
  assert_int_equal(s_cr_n, 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_geometry, setup),
      cmocka_unit_test_setup(test_erase_sequence, setup),
      cmocka_unit_test_setup(test_erase_out_of_range_touches_nothing, setup),
      cmocka_unit_test_setup(test_erase_reports_hardware_error, setup),
      cmocka_unit_test_setup(test_locked_controller_is_an_error, setup),
      cmocka_unit_test_setup(test_program_bytes_then_words, setup),
      cmocka_unit_test_setup(test_program_cannot_set_bits, setup),
      cmocka_unit_test_setup(test_range_checks, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
