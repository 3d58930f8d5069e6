/* A/B parameter store on the NOR-flash stub. Images are checked and hand-built from the
 * layout documented in param_store.h with zlib's crc32 (an independent encoder and
 * decoder), and every power-cut point of a save is tried. */
#define _POSIX_C_SOURCE 200809L /* mkstemp */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#include <zlib.h>

#include "hal_flash_host.h"
#include "params/param_store.h"

#define SECTOR_SIZE 16384u

static param_store_t g_store;

static int setup(void **state)
{
  (void)state;
  const hal_flash_host_cfg_t cfg = {2u, SECTOR_SIZE, NULL, 0u, 0u, 0u};
  if (hal_flash_host_configure(&cfg) != 0) {
    return -1;
  }
  const param_store_cfg_t sc = {0u, 1u};
  return (param_store_init(&g_store, &sc) == PARAM_STORE_OK) ? 0 : -1;
}

static void values_a(param_values_t *v)
{
  param_values_defaults(v);
  v->drive_freq_hz = 1502.25f;
  v->rate_bias_c0_dps = 58.533f; /* the thesis's fit, 7.3.2 */
  v->rate_bias_c1_dps_per_deg = 34.59f;
  v->rate_lpf_order = 6u;
  v->tlm_rate_hz = 250u;
}

static void values_b(param_values_t *v)
{
  values_a(v);
  v->drive_amp_kp = 1.25f;
  v->drive_amp_ki = 120.0f;
  v->rate_bias_c0_dps = -12.0f;
  v->drive_mode = 1u;
}

static uint32_t le32(const uint8_t *p)
{
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static unsigned persistent_count(void)
{
  unsigned n = 0;
  for (int i = 0; i < PARAM_COUNT; i++) {
    n += (param_info((param_idx_t)i)->flags & PF_PERSIST) ? 1u : 0u;
  }
  return n;
}

/* Independent decode of a slot straight from the flash array, per the documented layout. */
static void check_slot_bytes(uint32_t sector, uint32_t seq, const param_values_t *v)
{
  const uint8_t *img = hal_flash_host_data() + sector * SECTOR_SIZE;
  assert_int_equal(le32(img), 0x4D524750u);
  assert_int_equal(img[4] | img[5] << 8, 1);
  assert_int_equal(le32(img + 12), seq);
  const uint32_t n = le32(img + 16);
  assert_int_equal(n, persistent_count());
  const uint32_t body = 20u + 8u * n;
  assert_int_equal(le32(img + body), (uint32_t)crc32(0uL, img, body));
  assert_int_equal(le32(img + body + 4u), 0x5AFEC0DEu);
  for (uint32_t r = 0; r < n; r++) {
    const uint8_t *rec = img + 20u + 8u * r;
    const param_idx_t i = param_lookup_id((uint16_t)(rec[0] | rec[1] << 8));
    assert_int_not_equal(i, PARAM_COUNT);
    assert_int_equal(rec[2], param_info(i)->type);
    assert_int_equal(le32(rec + 4), param_get(v, i).u);
  }
  for (uint32_t k = body + 8u; k < SECTOR_SIZE; k++) {
    assert_int_equal(img[k], 0xFF);
  }
}

static void test_empty_store(void **state)
{
  (void)state;
  param_values_t v, before;
  values_a(&v);
  before = v;
  param_store_report_t rep;
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_NONE);
  assert_memory_equal(&v, &before, sizeof v);
  assert_int_equal(rep.slot_state[0], PARAM_SLOT_EMPTY);
  assert_int_equal(rep.slot_state[1], PARAM_SLOT_EMPTY);
  assert_int_equal(rep.slot, -1);
}

static void test_roundtrip_and_alternation(void **state)
{
  (void)state;
  param_values_t a, b, got;
  values_a(&a);
  values_b(&b);
  param_store_report_t rep;
  assert_int_equal(param_store_save(&g_store, &a, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 0);
  assert_int_equal(rep.seq, 1u);
  check_slot_bytes(0u, 1u, &a);
  assert_int_equal(param_store_save(&g_store, &b, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 1);
  assert_int_equal(rep.seq, 2u);
  check_slot_bytes(1u, 2u, &b);
  check_slot_bytes(0u, 1u, &a); /* the older image is untouched */
  assert_int_equal(param_store_save(&g_store, &a, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 0);
  assert_int_equal(rep.seq, 3u);
  param_values_defaults(&got);
  assert_int_equal(param_store_load(&g_store, &got, &rep), PARAM_STORE_OK);
  assert_memory_equal(&got, &a, sizeof got);
  assert_int_equal(rep.slot, 0);
  assert_int_equal(rep.seq, 3u);
  assert_int_equal(rep.dropped + rep.rejected + rep.defaulted, 0);
  assert_int_equal(rep.layout, PARAM_LAYOUT_VERSION);
}

static void test_unchanged_save_writes_nothing(void **state)
{
  (void)state;
  param_values_t a;
  values_a(&a);
  param_store_report_t rep;
  assert_int_equal(param_store_save(&g_store, &a, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  hal_flash_host_stats_t s0, s1;
  hal_flash_host_stats(&s0);
  assert_int_equal(param_store_save(&g_store, &a, PARAM_SAVE_LOOP_SAFE, &rep),
                   PARAM_STORE_UNCHANGED);
  assert_int_equal(rep.slot, 0);
  hal_flash_host_stats(&s1);
  assert_int_equal(s1.erases, s0.erases);
  assert_int_equal(s1.programmed_bytes, s0.programmed_bytes);
  /* a non-persistent member does not count as a change */
  a.sys_fs_hz = 50000u;
  assert_int_equal(param_store_save(&g_store, &a, PARAM_SAVE_LOOP_SAFE, &rep),
                   PARAM_STORE_UNCHANGED);
}

/* Why a save needs the loop stopped, measured on the stub's simulated clock. */
static void test_save_refused_while_running(void **state)
{
  (void)state;
  param_values_t a;
  values_a(&a);
  hal_flash_host_stats_clear();
  param_store_report_t rep;
  assert_int_equal(param_store_save(&g_store, &a, 0u, &rep), PARAM_STORE_ERR_BUSY);
  hal_flash_host_stats_t st;
  hal_flash_host_stats(&st);
  assert_int_equal(st.busy_us, 0u); /* flash never touched: no stall */
  assert_int_equal(st.erases, 0u);
  param_values_t v;
  param_values_defaults(&v);
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_NONE);

  assert_int_equal(param_store_save(&g_store, &a, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  hal_flash_host_stats(&st);
  /* the drive amplitude decays with tau = 2 Q1 / wn1 (6-12); Q1 = 33.33 (7.2.2) */
  const double tau_s = 2.0 * 33.33 / (2.0 * 3.14159265358979 * (double)a.drive_freq_hz);
  const double stall_s = (double)st.longest_stall_us * 1e-6;
  print_message("save stall %.0f ms, drive tau %.2f ms: %.0f time constants\n", stall_s * 1e3,
                tau_s * 1e3, stall_s / tau_s);
  assert_true(stall_s > 30.0 * tau_s);
}

/* Old set in the store (optionally in both slots), then a save of the new set cut after
 * `cut` programmed bytes; returns 0 if load gives the old set, 1 if the new. */
static int save_with_cut(uint32_t cut, bool erase_cut, bool two_old)
{
  const hal_flash_host_cfg_t cfg = {2u, SECTOR_SIZE, NULL, 0u, 0u, 0u};
  assert_int_equal(hal_flash_host_configure(&cfg), 0);
  param_values_t old, nw, got;
  values_a(&old);
  values_b(&nw);
  param_store_report_t rep;
  if (two_old) {
    param_values_t older = old;
    older.tlm_rate_hz = 7u;
    assert_int_equal(param_store_save(&g_store, &older, PARAM_SAVE_LOOP_SAFE, &rep),
                     PARAM_STORE_OK);
  }
  assert_int_equal(param_store_save(&g_store, &old, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  const int old_slot = rep.slot;
  if (erase_cut) {
    hal_flash_host_power_cut_in_erase(cut);
  } else {
    hal_flash_host_power_cut_after(cut);
  }
  const param_store_status_t st = param_store_save(&g_store, &nw, PARAM_SAVE_LOOP_SAFE, &rep);
  hal_flash_host_power_restore(); /* reboot */
  /* protocol: a complete commit word implies a complete image before it */
  const uint8_t *tgt = hal_flash_host_data() + (uint32_t)(1 - old_slot) * SECTOR_SIZE;
  const uint32_t body = 20u + 8u * persistent_count();
  if (!erase_cut && le32(tgt + body + 4u) == 0x5AFEC0DEu) {
    assert_int_equal(le32(tgt + body), (uint32_t)crc32(0uL, tgt, body));
  }
  param_values_defaults(&got);
  assert_int_equal(param_store_load(&g_store, &got, &rep), PARAM_STORE_OK);
  const bool is_old = memcmp(&got, &old, sizeof got) == 0;
  const bool is_new = memcmp(&got, &nw, sizeof got) == 0;
  assert_true(is_old != is_new);
  if (is_old) {
    assert_int_equal(st, PARAM_STORE_ERR_FLASH);
    assert_int_equal(rep.slot, old_slot);
  } else {
    assert_int_equal(st, PARAM_STORE_OK);
  }
  /* and the store keeps working after the reboot */
  param_values_t again = nw;
  again.drive_freq_hz = 1600.0f;
  assert_int_equal(param_store_save(&g_store, &again, PARAM_SAVE_LOOP_SAFE, &rep),
                   PARAM_STORE_OK);
  param_values_defaults(&got);
  assert_int_equal(param_store_load(&g_store, &got, &rep), PARAM_STORE_OK);
  assert_memory_equal(&got, &again, sizeof got);
  return is_new ? 1 : 0;
}

static void test_every_power_cut_point(void **state)
{
  (void)state;
  const uint32_t len = 20u + 8u * persistent_count() + 8u;
  for (int two_old = 0; two_old < 2; two_old++) {
    unsigned n_old = 0, n_new = 0;
    for (uint32_t cut = 0; cut <= len + 1u; cut++) {
      const int r = save_with_cut(cut, false, two_old != 0);
      /* only a fully programmed commit word publishes the new set */
      assert_int_equal(r, cut >= len ? 1 : 0);
      if (r) {
        n_new++;
      } else {
        n_old++;
      }
    }
    assert_int_equal(n_old, len);
    assert_int_equal(n_new, 2u);
    const uint32_t erase_cuts[] = {0u,         1u, 19u, 20u, 21u, 100u, len, SECTOR_SIZE - 1u,
                                   SECTOR_SIZE};
    for (size_t k = 0; k < sizeof erase_cuts / sizeof erase_cuts[0]; k++) {
      assert_int_equal(save_with_cut(erase_cuts[k], true, two_old != 0), 0);
    }
  }
}

static void test_bit_flips_fall_back(void **state)
{
  (void)state;
  param_values_t a, b, got;
  values_a(&a);
  values_b(&b);
  param_store_report_t rep;
  assert_int_equal(param_store_save(&g_store, &a, PARAM_SAVE_LOOP_SAFE, &rep),
                   PARAM_STORE_OK); /* A, seq 1 */
  assert_int_equal(param_store_save(&g_store, &b, PARAM_SAVE_LOOP_SAFE, &rep),
                   PARAM_STORE_OK); /* B, seq 2 */
  const uint32_t len = 20u + 8u * persistent_count() + 8u;
  for (uint32_t slot = 0; slot < 2u; slot++) {
    for (uint32_t off = 0; off < len; off++) {
      const uint32_t bit = (off * 5u) % 8u;
      assert_int_equal(hal_flash_host_flip_bit(slot, off, bit), 0);
      param_values_defaults(&got);
      assert_int_equal(param_store_load(&g_store, &got, &rep), PARAM_STORE_OK);
      /* format 1 -> 17: a newer writer's image for all it shows (not read either) */
      assert_int_equal(rep.slot_state[slot], off == 4u ? PARAM_SLOT_NEWER : PARAM_SLOT_CORRUPT);
      assert_int_equal(rep.slot, slot == 1u ? 0 : 1); /* the other slot is used */
      assert_memory_equal(&got, slot == 1u ? &a : &b, sizeof got);
      assert_int_equal(hal_flash_host_flip_bit(slot, off, bit), 0);
    }
  }
  /* a flip past the image (erased area) does not matter */
  assert_int_equal(hal_flash_host_flip_bit(1u, len + 10u, 3u), 0);
  assert_int_equal(param_store_load(&g_store, &got, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 1);
  /* both corrupt: nothing loaded, caller keeps its values, states say why */
  assert_int_equal(hal_flash_host_flip_bit(0u, 40u, 1u), 0);
  assert_int_equal(hal_flash_host_flip_bit(1u, 40u, 1u), 0);
  param_values_defaults(&got);
  param_values_t def = got;
  assert_int_equal(param_store_load(&g_store, &got, &rep), PARAM_STORE_NONE);
  assert_memory_equal(&got, &def, sizeof got);
  assert_int_equal(rep.slot_state[0], PARAM_SLOT_CORRUPT);
  assert_int_equal(rep.slot_state[1], PARAM_SLOT_CORRUPT);
  /* a save over two corrupt slots works and starts again */
  assert_int_equal(param_store_save(&g_store, &b, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  assert_int_equal(param_store_load(&g_store, &got, &rep), PARAM_STORE_OK);
  assert_memory_equal(&got, &b, sizeof got);
}

/* ---- hand-built images (older/newer layouts) ---- */

typedef struct {
  uint16_t id;
  uint8_t type;
  uint32_t value;
} rec_t;

static void put32(uint8_t *p, uint32_t v)
{
  for (int i = 0; i < 4; i++) {
    p[i] = (uint8_t)(v >> (8 * i));
  }
}

static uint32_t fbits(float f)
{
  uint32_t u;
  memcpy(&u, &f, 4);
  return u;
}

static void write_image(uint32_t sector, uint16_t format, uint16_t layout, uint32_t seq,
                        const rec_t *r, uint32_t n, uint32_t count_field)
{
  static uint8_t img[4096];
  memset(img, 0, sizeof img);
  put32(img, 0x4D524750u);
  img[4] = (uint8_t)format;
  img[5] = (uint8_t)(format >> 8);
  img[6] = (uint8_t)layout;
  img[7] = (uint8_t)(layout >> 8);
  put32(img + 8, 0x00000900u); /* "0.9.0" */
  put32(img + 12, seq);
  put32(img + 16, count_field);
  for (uint32_t k = 0; k < n; k++) {
    uint8_t *p = img + 20 + 8 * k;
    p[0] = (uint8_t)r[k].id;
    p[1] = (uint8_t)(r[k].id >> 8);
    p[2] = r[k].type;
    put32(p + 4, r[k].value);
  }
  const uint32_t body = 20u + 8u * n;
  put32(img + body, (uint32_t)crc32(0uL, img, body));
  put32(img + body + 4, 0x5AFEC0DEu);
  assert_int_equal(hal_flash_erase(sector), HAL_FLASH_OK);
  assert_int_equal(hal_flash_program(sector, 0u, img, body + 8u), HAL_FLASH_OK);
}

static void test_migration_field_by_field(void **state)
{
  (void)state;
  const rec_t recs[] = {
      {0x0101, 0, fbits(1600.0f)}, /* drive.freq_hz: loaded */
      {0x7777, 0, fbits(1.0f)},    /* id unknown to this firmware: dropped */
      {0x0601, 1, 40000u},         /* sys.fs_hz: not persistent: dropped */
      {0x0103, 0, fbits(9.0f)},    /* drive.amp_set_v 9 V > 4.5: rejected */
      {0x0104, 0, fbits(NAN)},     /* drive.phase_set_deg NaN: rejected */
      {0x0105, 1, 3u},             /* drive.amp_kp as an integer: wrong type, rejected */
      {0x0303, 2, 5u},             /* rate.lpf_order 5: not a choice, rejected */
      {0x0501, 1, 500u},           /* tlm.rate_hz: loaded */
      {0x0501, 1, 600u},           /* duplicate: both rejected, the default stays */
      {0x0302, 0, fbits(50.0f)},   /* rate.lpf_cutoff_hz: loaded */
      {0x0102, 1, 1u},             /* drive.mode as U32 into an ENUM: integer, loaded */
  };
  const uint32_t n = sizeof recs / sizeof recs[0];
  write_image(0u, 1u, 7u, 10u, recs, n, n);
  param_values_t v, def;
  param_values_defaults(&def);
  v = def;
  v.drive_amp_kp = 5.0f; /* a rejected field takes its default, not the caller's value */
  param_store_report_t rep;
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 0);
  assert_int_equal(rep.seq, 10u);
  assert_int_equal(rep.layout, 7u);
  assert_int_equal(rep.fw_version, 0x900u);
  assert_int_equal(rep.dropped, 2);
  assert_int_equal(rep.rejected, 6);
  /* persistent parameters with no record at all: 8 known persistent ids appear (3
   * loaded, 5 only rejected), the rest are missing */
  assert_int_equal(rep.defaulted, persistent_count() - 8u);
  assert_true(v.drive_freq_hz == 1600.0f);
  assert_int_equal(v.tlm_rate_hz, def.tlm_rate_hz);
  assert_true(v.rate_lpf_cutoff_hz == 50.0f);
  assert_int_equal(v.drive_mode, 1u);
  assert_true(v.drive_amp_set_v == def.drive_amp_set_v);
  assert_true(v.drive_phase_set_deg == def.drive_phase_set_deg);
  assert_true(v.drive_amp_kp == def.drive_amp_kp);
  assert_int_equal(v.rate_lpf_order, def.rate_lpf_order);
  assert_int_equal(v.sys_fs_hz, 50000u);
  /* the next save writes the migrated set in the current layout, into slot B */
  assert_int_equal(param_store_save(&g_store, &v, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 1);
  assert_int_equal(rep.seq, 11u);
  check_slot_bytes(1u, 11u, &v);
}

static void test_bad_headers_are_corrupt(void **state)
{
  (void)state;
  const rec_t r[] = {{0x0101, 0, fbits(1600.0f)}};
  param_values_t v;
  param_store_report_t rep;
  /* a newer image format this firmware cannot read: not read, and a save that would
   * erase it is refused unless forced */
  write_image(0u, 2u, 1u, 5u, r, 1u, 1u);
  param_values_defaults(&v);
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_NEWER);
  assert_int_equal(rep.slot_state[0], PARAM_SLOT_NEWER);
  assert_int_equal(param_store_save(&g_store, &v, PARAM_SAVE_LOOP_SAFE, &rep),
                   PARAM_STORE_ERR_NEWER);
  assert_int_equal(param_store_save(&g_store, &v, PARAM_SAVE_LOOP_SAFE | PARAM_SAVE_FORCE, &rep),
                   PARAM_STORE_OK);
  assert_int_equal(rep.slot, 1); /* the newer image is kept while there is room */
  /* a torn format field (high byte still erased) is corrupt, not newer */
  write_image(0u, 0xFF01u, 1u, 5u, r, 1u, 1u);
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot_state[0], PARAM_SLOT_CORRUPT);
  assert_int_equal(hal_flash_erase(1u), HAL_FLASH_OK);
  /* a count that runs past the sector */
  write_image(0u, 1u, 1u, 5u, r, 1u, 4000u);
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_NONE);
  /* a count that disagrees with where the CRC was written */
  write_image(0u, 1u, 1u, 5u, r, 1u, 2u);
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_NONE);
  /* an empty but valid image: every persistent parameter defaulted */
  write_image(0u, 1u, 1u, 5u, r, 0u, 0u);
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.defaulted, persistent_count());
}

/* Serial-number order: after a wrap, the small sequence number is the newer. */
static void test_sequence_wrap(void **state)
{
  (void)state;
  const rec_t ra[] = {{0x0101, 0, fbits(1000.0f)}};
  const rec_t rb[] = {{0x0101, 0, fbits(2000.0f)}};
  write_image(0u, 1u, 1u, 0xFFFFFFF0u, ra, 1u, 1u);
  write_image(1u, 1u, 1u, 3u, rb, 1u, 1u);
  param_values_t v;
  param_values_defaults(&v);
  param_store_report_t rep;
  assert_int_equal(param_store_load(&g_store, &v, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 1);
  assert_true(v.drive_freq_hz == 2000.0f);
  /* and the next save goes over the older slot A with seq 4 */
  v.drive_freq_hz = 3000.0f;
  assert_int_equal(param_store_save(&g_store, &v, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 0);
  assert_int_equal(rep.seq, 4u);
}

static void test_config_errors(void **state)
{
  (void)state;
  param_store_t st;
  const param_store_cfg_t same = {1u, 1u};
  assert_int_equal(param_store_init(&st, &same), PARAM_STORE_ERR_CONFIG);
  const param_store_cfg_t out = {0u, 2u};
  assert_int_equal(param_store_init(&st, &out), PARAM_STORE_ERR_CONFIG);
  const hal_flash_host_cfg_t tiny = {2u, 64u, NULL, 0u, 0u, 0u};
  assert_int_equal(hal_flash_host_configure(&tiny), 0);
  const param_store_cfg_t ok = {0u, 1u};
  assert_int_equal(param_store_init(&st, &ok), PARAM_STORE_ERR_CONFIG);
  param_values_t v;
  param_values_defaults(&v);
  assert_int_equal(param_store_save(&st, &v, PARAM_SAVE_LOOP_SAFE, NULL), PARAM_STORE_ERR_CONFIG);
}

/* A file-backed store survives a "reboot" (close, re-open). */
static void test_file_backed_reboot(void **state)
{
  (void)state;
  char path[] = "/tmp/gyro_params_XXXXXX";
  const int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  const hal_flash_host_cfg_t cfg = {2u, SECTOR_SIZE, path, 0u, 0u, 0u};
  assert_int_equal(hal_flash_host_configure(&cfg), 0);
  param_store_t st;
  const param_store_cfg_t sc = {0u, 1u};
  assert_int_equal(param_store_init(&st, &sc), PARAM_STORE_OK);
  param_values_t a, got;
  values_b(&a);
  assert_int_equal(param_store_save(&st, &a, PARAM_SAVE_LOOP_SAFE, NULL), PARAM_STORE_OK);
  hal_flash_host_close();
  assert_int_equal(hal_flash_host_configure(&cfg), 0);
  param_values_defaults(&got);
  assert_int_equal(param_store_load(&st, &got, NULL), PARAM_STORE_OK);
  assert_memory_equal(&got, &a, sizeof got);
  hal_flash_host_close();
  remove(path);
}

/* A part that programs 64-bit units once between erases (an STM32G4's double word, the
 * flash stub with program_bytes 8): saves and loads work, every program call is whole
 * units, and an image written with 32-bit programming (the STM32F4's, the images in the
 * field) loads there, and back. */
static void test_program_unit_64_bit(void **state)
{
  (void)state;
  char path[] = "/tmp/gyro_params_XXXXXX";
  const int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  const hal_flash_host_cfg_t word = {2u, SECTOR_SIZE, path, 0u, 0u, 4u};
  const hal_flash_host_cfg_t dword = {2u, SECTOR_SIZE, path, 0u, 0u, 8u};
  param_store_t st;
  const param_store_cfg_t sc = {0u, 1u};
  param_values_t a, b, got;
  values_a(&a);
  values_b(&b);

  /* written with 32-bit programming, read back on the 64-bit part */
  assert_int_equal(hal_flash_host_configure(&word), 0);
  assert_int_equal(param_store_init(&st, &sc), PARAM_STORE_OK);
  assert_int_equal(param_store_save(&st, &a, PARAM_SAVE_LOOP_SAFE, NULL), PARAM_STORE_OK);
  hal_flash_host_close();
  assert_int_equal(hal_flash_host_configure(&dword), 0);
  assert_int_equal(param_store_init(&st, &sc), PARAM_STORE_OK);
  param_values_defaults(&got);
  assert_int_equal(param_store_load(&st, &got, NULL), PARAM_STORE_OK);
  assert_memory_equal(&got, &a, sizeof got);

  /* saved on the 64-bit part (the stub refuses a partial or repeated unit), into slot B */
  param_store_report_t rep;
  assert_int_equal(param_store_save(&st, &b, PARAM_SAVE_LOOP_SAFE, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 1);
  const uint32_t len = 20u + 8u * persistent_count() + 8u;
  const uint8_t *img = hal_flash_host_data() + SECTOR_SIZE;
  assert_int_equal(le32(&img[len - 4u]), PARAM_STORE_COMMIT);
  for (uint32_t i = len; i < len + 4u; i++)
    assert_int_equal(img[i], 0xFF); /* rest of the unit */
  param_values_defaults(&got);
  assert_int_equal(param_store_load(&st, &got, NULL), PARAM_STORE_OK);
  assert_memory_equal(&got, &b, sizeof got);
  /* and an unchanged save still writes nothing */
  assert_int_equal(param_store_save(&st, &b, PARAM_SAVE_LOOP_SAFE, NULL), PARAM_STORE_UNCHANGED);

  /* back on the 32-bit part, the image written with 64-bit units loads */
  hal_flash_host_close();
  assert_int_equal(hal_flash_host_configure(&word), 0);
  assert_int_equal(param_store_init(&st, &sc), PARAM_STORE_OK);
  param_values_defaults(&got);
  assert_int_equal(param_store_load(&st, &got, NULL), PARAM_STORE_OK);
  assert_memory_equal(&got, &b, sizeof got);
  hal_flash_host_close();
  remove(path);

  /* a unit the layout cannot serve is a configuration error */
  const hal_flash_host_cfg_t wide = {2u, SECTOR_SIZE, NULL, 0u, 0u, 16u};
  assert_int_equal(hal_flash_host_configure(&wide), 0);
  assert_int_equal(param_store_init(&st, &sc), PARAM_STORE_ERR_CONFIG);
}

/* An image as the firmware before the configuration/state split saved it (commit
 * 0090480; tests/vectors/param_image_0090480.bin: two saves, 1 KB sectors, the second
 * with six values changed) loads unchanged: stored parts keep their calibration across
 * the update. */
static void test_loads_image_of_earlier_firmware(void **state)
{
  (void)state;
  /* Its 1 KB images, each at the start of a 2 KB sector: a sector must hold an image of
   * the present firmware's parameters (param_store_init), which 1 KB no longer does. */
  const hal_flash_host_cfg_t cfg = {2u, 2048u, NULL, 0u, 0u, 0u};
  assert_int_equal(hal_flash_host_configure(&cfg), 0);
  uint8_t img[2048];
  FILE *f = fopen(GYRO_TEST_VECTORS_DIR "/param_image_0090480.bin", "rb");
  assert_non_null(f);
  assert_int_equal(fread(img, 1, sizeof img, f), sizeof img);
  fclose(f);
  assert_int_equal(hal_flash_program(0u, 0u, img, 1024u), HAL_FLASH_OK);
  assert_int_equal(hal_flash_program(1u, 0u, img + 1024, 1024u), HAL_FLASH_OK);
  const param_store_cfg_t sc = {0u, 1u};
  assert_int_equal(param_store_init(&g_store, &sc), PARAM_STORE_OK);
  param_values_t got, want;
  param_values_defaults(&got); /* the non-persistent values come from the caller */
  param_store_report_t rep;
  assert_int_equal(param_store_load(&g_store, &got, &rep), PARAM_STORE_OK);
  assert_int_equal(rep.slot, 1); /* the newer save */
  /* Nothing dropped or refused; what the image does not hold starts from its default:
   * the parameters added since (drive.track; cal.ref_freq_hz, cal.part_id, cal.date,
   * cal.ref_p_deg: 0, so that the image's polynomials keep their absolute P;
   * rate.bias_grad_dps_per_deg 0: no gradient term, and its rate.grad_tau_s;
   * rate.p_rate_deg_per_dps 0; rate.comp_tau_s 0: P_f itself; rate.sf_c4_per_deg4 0;
   * cal.ref_phase_set_deg 0; rate.lin_c2_per_dps, rate.lin_c3_per_dps2 0: no
   * linearisation; rate.p_rate_c1_per_dps, rate.p_rate2_deg_per_dps2 0; cal.ref_track
   * 0: the fixed drive; rate.comp_stages 1: one stage, as that firmware had;
   * rate.comp_fast_tau_s 0: no fast path, its rate.grad_fast_dps_per_deg and
   * rate.comp_blend_dps; quad.null 0: no quadrature nulling, and its eight quad.*;
   * sense.mode 0: the open sense loop, and its thirteen sense.*; sense.cal 0: the sweep
   * identifies the drive alone, and its two sense.cal_*; sense.tune 0: no mode tuning,
   * its sense.tune_split_hz, sense.tune_v_max_v, sense.cal_s0_hz and
   * sense.cal_tune_ref_hz, and cal.ref_tune_v 0: made untuned; selftest.cont_fr_v2,
   * used only with force rebalance; cal.ref_sense_mode and cal.ref_quad_null 0: made
   * open loop without nulling, as that firmware could only; sense.tune_disc_zero_hz 0:
   * the lost-match monitor's reading as its model gives it; board.fuse 0: no board
   * thermometer, and its sixteen board.*).
   * Without a calibration record the part then says `calibrated no` and its rate is not
   * valid until its calibration is confirmed (set cal.ref_freq_hz, save): an image of
   * before the record cannot tell a calibration from values set by hand. */
  assert_int_equal(rep.dropped + rep.rejected, 0);
  assert_int_equal(rep.defaulted, 73);
  param_values_defaults(&want);
  /* The image holds every persistent value: those it did not change are that
   * firmware's defaults, some of which were the default part's and are generic now. */
  want.drive_cal_f0_hz = 1489.9f;
  want.drive_cal_q = 33.33f;
  want.drive_cal_gain_v_per_v2 = 0.00546f;
  want.rate_demod_phase_deg = 63.16f;
  want.selftest_expect_dps = 5.49f;
  want.selftest_cont_expect_dps = 4.24f;
  want.drive_freq_hz = 1491.25f;
  want.rate_scale_dps = 140.5f;
  want.drive_p_init_deg = 27.5f;
  want.rate_bias_c0_dps = -1.25f;
  want.selftest_continuous = 0u;
  want.drive_mode = 1u;
  assert_memory_equal(&got, &want, sizeof got);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_empty_store, setup),
      cmocka_unit_test_setup(test_roundtrip_and_alternation, setup),
      cmocka_unit_test_setup(test_unchanged_save_writes_nothing, setup),
      cmocka_unit_test_setup(test_save_refused_while_running, setup),
      cmocka_unit_test_setup(test_every_power_cut_point, setup),
      cmocka_unit_test_setup(test_bit_flips_fall_back, setup),
      cmocka_unit_test_setup(test_migration_field_by_field, setup),
      cmocka_unit_test_setup(test_bad_headers_are_corrupt, setup),
      cmocka_unit_test_setup(test_sequence_wrap, setup),
      cmocka_unit_test_setup(test_config_errors, setup),
      cmocka_unit_test_setup(test_file_backed_reboot, setup),
      cmocka_unit_test_setup(test_program_unit_64_bit, setup),
      cmocka_unit_test(test_loads_image_of_earlier_firmware),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
