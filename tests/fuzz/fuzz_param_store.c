/* The parameter-store loader fed arbitrary flash content in both slots. Byte 0 picks
 * options: bit 0 repairs the CRC and commit word of each slot (so the fuzzer reaches
 * the record decoder), bit 1 swaps the slot order. Whatever is loaded must be a valid
 * parameter set, a save over a newer-format image needs forcing, and a save over that
 * content must load back exactly. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <zlib.h>

#include "fuzz_check.h"
#include "hal_flash_host.h"
#include "params/param_store.h"

#define SECTOR 2048u /* holds an image of every parameter (param_store_init) */

static uint32_t le32(const uint8_t *p)
{
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put32(uint8_t *p, uint32_t v)
{
  for (int i = 0; i < 4; i++) {
    p[i] = (uint8_t)(v >> (8 * i));
  }
}

static void fill_slot(uint32_t sector, const uint8_t *d, size_t n, bool repair)
{
  uint8_t img[SECTOR];
  memset(img, 0xFF, sizeof img);
  memcpy(img, d, n < SECTOR ? n : SECTOR);
  if (repair && n >= 20) {
    const uint32_t count = le32(img + 16) % ((SECTOR - 28u) / 8u + 1u);
    put32(img + 16, count);
    const uint32_t body = 20u + 8u * count;
    put32(img + body, (uint32_t)crc32(0uL, img, body));
    put32(img + body + 4u, 0x5AFEC0DEu);
  }
  /* program from erased: any byte pattern is reachable by clearing bits */
  FUZZ_CHECK(hal_flash_program(sector, 0u, img, sizeof img) == HAL_FLASH_OK);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  const hal_flash_host_cfg_t cfg = {2u, SECTOR, NULL, 0u, 0u, 0u};
  FUZZ_CHECK(hal_flash_host_configure(&cfg) == 0);
  param_store_t st;
  const param_store_cfg_t sc = {0u, 1u};
  FUZZ_CHECK(param_store_init(&st, &sc) == PARAM_STORE_OK);
  const uint8_t opt = size > 0 ? data[0] : 0u;
  const uint8_t *rest = size > 0 ? data + 1 : data;
  const size_t n = size > 0 ? size - 1 : 0;
  const size_t half = n / 2;
  const uint32_t first = (opt & 2u) ? 1u : 0u;
  fill_slot(first, rest, half, (opt & 1u) != 0);
  fill_slot(1u - first, rest + half, n - half, (opt & 1u) != 0);

  param_values_t v;
  param_values_defaults(&v);
  param_store_report_t rep;
  const param_store_status_t ls = param_store_load(&st, &v, &rep);
  FUZZ_CHECK(ls == PARAM_STORE_OK || ls == PARAM_STORE_NONE || ls == PARAM_STORE_NEWER);
  for (int i = 0; i < PARAM_COUNT; i++) {
    FUZZ_CHECK(param_check((param_idx_t)i, param_get(&v, (param_idx_t)i)) == PARAM_OK);
  }
  if (ls == PARAM_STORE_OK) {
    FUZZ_CHECK(rep.slot == 0 || rep.slot == 1);
    FUZZ_CHECK(rep.slot_state[rep.slot] == PARAM_SLOT_VALID);
    FUZZ_CHECK(rep.defaulted <= PARAM_COUNT);
  } else {
    FUZZ_CHECK(rep.slot == -1 && rep.slot_state[0] != PARAM_SLOT_VALID &&
               rep.slot_state[1] != PARAM_SLOT_VALID);
  }
  /* a save never destroys the newest valid image and reads back exactly */
  v.drive_freq_hz = 1234.5f;
  const bool newer = rep.slot_state[0] == PARAM_SLOT_NEWER ||
                     rep.slot_state[1] == PARAM_SLOT_NEWER;
  FUZZ_CHECK((ls == PARAM_STORE_NEWER) == (newer && ls != PARAM_STORE_OK));
  param_store_status_t ss = param_store_save(&st, &v, PARAM_SAVE_LOOP_SAFE, &rep);
  /* a newer-format image is only overwritten by a forced save */
  if (newer) {
    FUZZ_CHECK(ss == PARAM_STORE_ERR_NEWER);
    ss = param_store_save(&st, &v, PARAM_SAVE_LOOP_SAFE | PARAM_SAVE_FORCE, &rep);
  }
  FUZZ_CHECK(ss == PARAM_STORE_OK);
  param_values_t back;
  param_values_defaults(&back);
  FUZZ_CHECK(param_store_load(&st, &back, &rep) == PARAM_STORE_OK);
  FUZZ_CHECK(memcmp(&back, &v, sizeof v) == 0);
  return 0;
}
