/* Host NOR-flash stub behind hal_flash.h; semantics and controls in hal_flash_host.h.
 * The HAL has exactly one flash, so this stub keeps a single instance in file scope. */
#include "hal_flash_host.h"

#include <stdio.h>
#include <string.h>

#define DEFAULT_SECTORS 2u
#define DEFAULT_SECTOR_SIZE 16384u
/* STM32F405/407 datasheet, flash programming characteristics, x32 parallelism:
 * tERASE16KB 250 ms typ (500 ms max), tPROG word 16 us typ. */
#define DEFAULT_ERASE_US 250000u
#define DEFAULT_PROGRAM_WORD_US 16u
#define DEFAULT_PROGRAM_BYTES 4u /* the STM32F4 word */
#define ECC_PROGRAM_BYTES 8u     /* from here on: whole units, each programmed once */
#define NO_LIMIT UINT32_MAX

typedef struct {
  bool configured;
  uint32_t num_sectors;
  uint32_t sector_size;
  uint32_t erase_us;
  uint32_t program_word_us;
  uint32_t program_bytes;
  FILE *file;
  uint32_t program_budget; /* bytes that may still be programmed before the cut */
  uint32_t erase_cut;      /* NO_LIMIT, or bytes erased by the next (interrupted) erase */
  bool power_down;
  hal_flash_host_stats_t stats;
  uint8_t *mem; /* g_flash_mem */
} flash_sim_t;

static uint8_t g_flash_mem[HAL_FLASH_HOST_MAX_BYTES];
static flash_sim_t g_flash;

static void add_busy(uint32_t us)
{
  g_flash.stats.busy_us += us;
  if (us > g_flash.stats.longest_stall_us) {
    g_flash.stats.longest_stall_us = us;
  }
}

static void write_through(uint32_t addr, uint32_t len)
{
  if (g_flash.file == NULL || len == 0u) {
    return;
  }
  if (fseek(g_flash.file, (long)addr, SEEK_SET) == 0) {
    (void)fwrite(&g_flash.mem[addr], 1u, len, g_flash.file);
    (void)fflush(g_flash.file);
  }
}

static int open_backing(const char *path, uint32_t total)
{
  FILE *f = fopen(path, "r+b");
  if (f != NULL) {
    if (fseek(f, 0, SEEK_END) == 0 && ftell(f) == (long)total && fseek(f, 0, SEEK_SET) == 0 &&
        fread(g_flash.mem, 1u, total, f) == total) {
      g_flash.file = f;
      return 0;
    }
    (void)fclose(f);
  }
  /* missing or wrongly sized: a blank, erased part */
  f = fopen(path, "w+b");
  if (f == NULL) {
    return -1;
  }
  g_flash.file = f;
  memset(g_flash.mem, 0xFF, total);
  write_through(0u, total);
  return 0;
}

int hal_flash_host_configure(const hal_flash_host_cfg_t *cfg)
{
  hal_flash_host_close();
  memset(&g_flash, 0, sizeof g_flash);
  g_flash.mem = g_flash_mem;
  const hal_flash_host_cfg_t def = {0u, 0u, NULL, 0u, 0u, 0u};
  const hal_flash_host_cfg_t *c = (cfg != NULL) ? cfg : &def;
  const uint32_t n = (c->num_sectors != 0u) ? c->num_sectors : DEFAULT_SECTORS;
  const uint32_t sz = (c->sector_size != 0u) ? c->sector_size : DEFAULT_SECTOR_SIZE;
  const uint32_t unit = (c->program_bytes != 0u) ? c->program_bytes : DEFAULT_PROGRAM_BYTES;
  if ((sz % 4u) != 0u || (uint64_t)n * sz > HAL_FLASH_HOST_MAX_BYTES ||
      (unit & (unit - 1u)) != 0u || unit > sz || (sz % unit) != 0u) {
    return -1;
  }
  g_flash.program_bytes = unit;
  g_flash.num_sectors = n;
  g_flash.sector_size = sz;
  g_flash.erase_us = (c->erase_us != 0u) ? c->erase_us : DEFAULT_ERASE_US;
  g_flash.program_word_us = (c->program_word_us != 0u) ? c->program_word_us
                                                       : DEFAULT_PROGRAM_WORD_US;
  g_flash.program_budget = NO_LIMIT;
  g_flash.erase_cut = NO_LIMIT;
  memset(g_flash.mem, 0xFF, (size_t)n * sz);
  if (c->path != NULL && open_backing(c->path, n * sz) != 0) {
    return -1;
  }
  g_flash.configured = true;
  return 0;
}

void hal_flash_host_close(void)
{
  if (g_flash.file != NULL) {
    (void)fclose(g_flash.file);
    g_flash.file = NULL;
  }
}

static void ensure_configured(void)
{
  if (!g_flash.configured) {
    (void)hal_flash_host_configure(NULL);
  }
}

void hal_flash_host_power_cut_after(uint32_t program_bytes)
{
  ensure_configured();
  g_flash.program_budget = program_bytes;
}

void hal_flash_host_power_cut_in_erase(uint32_t erased_bytes)
{
  ensure_configured();
  g_flash.erase_cut = erased_bytes;
}

void hal_flash_host_power_restore(void)
{
  g_flash.power_down = false;
  g_flash.program_budget = NO_LIMIT;
  g_flash.erase_cut = NO_LIMIT;
}

bool hal_flash_host_power_is_down(void) { return g_flash.power_down; }

int hal_flash_host_flip_bit(uint32_t sector, uint32_t offset, uint32_t bit)
{
  ensure_configured();
  if (sector >= g_flash.num_sectors || offset >= g_flash.sector_size || bit > 7u) {
    return -1;
  }
  const uint32_t addr = sector * g_flash.sector_size + offset;
  g_flash.mem[addr] ^= (uint8_t)(1u << bit);
  write_through(addr, 1u);
  return 0;
}

void hal_flash_host_stats(hal_flash_host_stats_t *st)
{
  ensure_configured();
  *st = g_flash.stats;
}

void hal_flash_host_stats_clear(void) { memset(&g_flash.stats, 0, sizeof g_flash.stats); }

const uint8_t *hal_flash_host_data(void)
{
  ensure_configured();
  return g_flash.mem;
}

/* ---- hal_flash.h ---- */

void hal_flash_geometry(hal_flash_geometry_t *geo)
{
  ensure_configured();
  geo->num_sectors = g_flash.num_sectors;
  geo->sector_size = g_flash.sector_size;
  geo->program_bytes = g_flash.program_bytes;
}

static bool in_range(uint32_t sector, uint32_t offset, size_t len)
{
  return sector < g_flash.num_sectors && offset <= g_flash.sector_size &&
         len <= (size_t)(g_flash.sector_size - offset);
}

hal_flash_status_t hal_flash_erase(uint32_t sector)
{
  ensure_configured();
  if (sector >= g_flash.num_sectors) {
    return HAL_FLASH_ERR_RANGE;
  }
  if (g_flash.power_down) {
    return HAL_FLASH_ERR_POWER;
  }
  const uint32_t base = sector * g_flash.sector_size;
  add_busy(g_flash.erase_us);
  g_flash.stats.erases++;
  if (g_flash.erase_cut != NO_LIMIT) {
    const uint32_t k = (g_flash.erase_cut < g_flash.sector_size) ? g_flash.erase_cut
                                                                 : g_flash.sector_size;
    memset(&g_flash.mem[base], 0xFF, k);
    write_through(base, k);
    g_flash.power_down = true;
    return HAL_FLASH_ERR_POWER;
  }
  memset(&g_flash.mem[base], 0xFF, g_flash.sector_size);
  write_through(base, g_flash.sector_size);
  return HAL_FLASH_OK;
}

hal_flash_status_t hal_flash_program(uint32_t sector, uint32_t offset, const void *data,
                                     size_t len)
{
  ensure_configured();
  if ((data == NULL && len != 0u) || !in_range(sector, offset, len)) {
    return HAL_FLASH_ERR_RANGE;
  }
  if (g_flash.power_down) {
    return HAL_FLASH_ERR_POWER;
  }
  const uint8_t *src = (const uint8_t *)data;
  const uint32_t addr = sector * g_flash.sector_size + offset;
  const uint32_t n = (uint32_t)len;
  if (g_flash.program_bytes >= ECC_PROGRAM_BYTES) {
    /* ECC flash: whole units, each written once between erases */
    if ((offset % g_flash.program_bytes) != 0u || (n % g_flash.program_bytes) != 0u) {
      return HAL_FLASH_ERR_RANGE;
    }
    for (uint32_t i = 0; i < n; i++) {
      if (g_flash.mem[addr + i] != 0xFFu) {
        return HAL_FLASH_ERR_WRITE;
      }
    }
  }
  /* NOR: programming can only clear bits; a 1 wanted where a 0 is stored fails whole */
  for (uint32_t i = 0; i < n; i++) {
    if ((uint8_t)(src[i] & (uint8_t)~g_flash.mem[addr + i]) != 0u) {
      return HAL_FLASH_ERR_WRITE;
    }
  }
  uint32_t done = n;
  bool cut = false;
  if (g_flash.program_budget != NO_LIMIT && g_flash.program_budget < n) {
    done = g_flash.program_budget;
    cut = true;
  }
  for (uint32_t i = 0; i < done; i++) {
    g_flash.mem[addr + i] &= src[i];
  }
  if (cut) {
    /* torn cell: the low nibble of the interrupted byte was programmed, the high not */
    g_flash.mem[addr + done] &= (uint8_t)(src[done] | 0xF0u);
    write_through(addr, done + 1u);
    g_flash.program_budget = 0u;
    g_flash.power_down = true;
  } else {
    write_through(addr, done);
    if (g_flash.program_budget != NO_LIMIT) {
      g_flash.program_budget -= done;
    }
  }
  g_flash.stats.programmed_bytes += done;
  add_busy(((done + 3u) / 4u) * g_flash.program_word_us);
  return cut ? HAL_FLASH_ERR_POWER : HAL_FLASH_OK;
}

hal_flash_status_t hal_flash_read(uint32_t sector, uint32_t offset, void *buf, size_t len)
{
  ensure_configured();
  if ((buf == NULL && len != 0u) || !in_range(sector, offset, len)) {
    return HAL_FLASH_ERR_RANGE;
  }
  if (len != 0u) {
    memcpy(buf, &g_flash.mem[sector * g_flash.sector_size + offset], len);
  }
  return HAL_FLASH_OK;
}
