#include "params/param_store.h"

#include <string.h>

#include "params/fw_version.h"
#include "hal/hal_flash.h"
#include "params/crc32.h"

#define CHUNK_RECORDS 8u

static void put_u16(uint8_t *p, uint16_t v)
{
  p[0] = (uint8_t)v;
  p[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *p, uint32_t v)
{
  p[0] = (uint8_t)v;
  p[1] = (uint8_t)(v >> 8);
  p[2] = (uint8_t)(v >> 16);
  p[3] = (uint8_t)(v >> 24);
}

static uint16_t get_u16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }

static uint32_t get_u32(const uint8_t *p)
{
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* Serial-number order: a is newer than b. */
/* End of the commit word's programming unit, for an image of len bytes (commit word
 * included): the commit word starts at len - 4, a multiple of 8 and so of the unit. */
static uint32_t commit_end(uint32_t len, uint32_t unit)
{
  return (unit > 4u) ? len - 4u + unit : len;
}

static bool seq_newer(uint32_t a, uint32_t b) { return (int32_t)(a - b) > 0; }

typedef struct {
  uint32_t seq;
  uint32_t count;
  uint32_t fw_version;
  uint16_t layout;
} slot_hdr_t;

static void report_clear(param_store_report_t *rep)
{
  memset(rep, 0, sizeof *rep);
  rep->slot = -1;
}

param_store_status_t param_store_init(param_store_t *st, const param_store_cfg_t *cfg)
{
  memset(st, 0, sizeof *st);
  hal_flash_geometry_t geo = {0u, 0u, 0u};
  hal_flash_geometry(&geo);
  const uint32_t unit = geo.program_bytes;
  if (cfg->sector_a == cfg->sector_b || cfg->sector_a >= geo.num_sectors ||
      cfg->sector_b >= geo.num_sectors || unit == 0u || (unit & (unit - 1u)) != 0u ||
      unit > PARAM_STORE_PROGRAM_MAX ||
      geo.sector_size < commit_end(PARAM_STORE_IMAGE_MAX, unit)) {
    return PARAM_STORE_ERR_CONFIG;
  }
  st->program_bytes = unit;
  st->sector[0] = cfg->sector_a;
  st->sector[1] = cfg->sector_b;
  st->sector_size = geo.sector_size;
  return PARAM_STORE_OK;
}

/* Check one slot; on PARAM_SLOT_VALID fill *h. */
static param_slot_state_t slot_check(const param_store_t *st, unsigned slot, slot_hdr_t *h)
{
  const uint32_t sec = st->sector[slot];
  uint8_t hdr[PARAM_STORE_HDR_BYTES];
  if (st->sector_size == 0u || hal_flash_read(sec, 0u, hdr, sizeof hdr) != HAL_FLASH_OK) {
    return PARAM_SLOT_CORRUPT;
  }
  bool blank = true;
  for (size_t i = 0; i < sizeof hdr; i++) {
    blank = blank && (hdr[i] == 0xFFu);
  }
  if (blank) {
    return PARAM_SLOT_EMPTY;
  }
  const uint32_t count = get_u32(&hdr[16]);
  /* A newer writer's image: its layout is not ours to check. A format with the high byte
   * set is an erased or torn field (0xFFFF, 0xFF01 after a cut), not a newer writer. */
  const uint16_t format = get_u16(&hdr[4]);
  if (get_u32(&hdr[0]) == PARAM_STORE_MAGIC && format > PARAM_STORE_FORMAT && format <= 0xFFu) {
    return PARAM_SLOT_NEWER;
  }
  if (get_u32(&hdr[0]) != PARAM_STORE_MAGIC || format != PARAM_STORE_FORMAT ||
      count > PARAM_STORE_MAX_RECORDS ||
      PARAM_STORE_HDR_BYTES + PARAM_STORE_REC_BYTES * count + 8u > st->sector_size) {
    return PARAM_SLOT_CORRUPT;
  }
  const uint32_t body = PARAM_STORE_HDR_BYTES + PARAM_STORE_REC_BYTES * count;
  uint8_t tail[8];
  if (hal_flash_read(sec, body, tail, sizeof tail) != HAL_FLASH_OK ||
      get_u32(&tail[4]) != PARAM_STORE_COMMIT) {
    return PARAM_SLOT_CORRUPT;
  }
  uint32_t crc = crc32_update(0u, hdr, sizeof hdr);
  uint8_t chunk[CHUNK_RECORDS * PARAM_STORE_REC_BYTES];
  for (uint32_t off = PARAM_STORE_HDR_BYTES; off < body;) {
    const uint32_t n = (body - off < sizeof chunk) ? body - off : (uint32_t)sizeof chunk;
    if (hal_flash_read(sec, off, chunk, n) != HAL_FLASH_OK) {
      return PARAM_SLOT_CORRUPT;
    }
    crc = crc32_update(crc, chunk, n);
    off += n;
  }
  if (crc != get_u32(&tail[0])) {
    return PARAM_SLOT_CORRUPT;
  }
  h->seq = get_u32(&hdr[12]);
  h->count = count;
  h->fw_version = get_u32(&hdr[8]);
  h->layout = get_u16(&hdr[6]);
  return PARAM_SLOT_VALID;
}

/* Check both slots; return the newest valid one (0/1) or -1. */
static int newest_slot(const param_store_t *st, param_store_report_t *rep, slot_hdr_t hdr[2])
{
  int best = -1;
  for (unsigned s = 0; s < 2u; s++) {
    const param_slot_state_t state = slot_check(st, s, &hdr[s]);
    rep->slot_state[s] = (uint8_t)state;
    if (state == PARAM_SLOT_VALID && (best < 0 || seq_newer(hdr[s].seq, hdr[best].seq))) {
      best = (int)s;
    }
  }
  return best;
}

static bool holds_newer(const param_store_report_t *rep)
{
  return rep->slot_state[0] == (uint8_t)PARAM_SLOT_NEWER ||
         rep->slot_state[1] == (uint8_t)PARAM_SLOT_NEWER;
}

static bool type_compatible(uint8_t rec_type, uint8_t table_type)
{
  const bool rec_float = (rec_type == (uint8_t)PARAM_T_F32);
  const bool tab_float = (table_type == (uint8_t)PARAM_T_F32);
  const bool rec_known = rec_type <= (uint8_t)PARAM_T_ENUM;
  return rec_known && rec_float == tab_float;
}

param_store_status_t param_store_load(param_store_t *st, param_values_t *v,
                                      param_store_report_t *rep)
{
  param_store_report_t local;
  if (rep == NULL) {
    rep = &local;
  }
  report_clear(rep);
  slot_hdr_t hdr[2];
  const int s = newest_slot(st, rep, hdr);
  if (s < 0) {
    return holds_newer(rep) ? PARAM_STORE_NEWER : PARAM_STORE_NONE;
  }
  param_values_t out = *v;
  /* per parameter: 0 not in the image, 1 loaded, 2 one rejected record, 3 duplicated */
  uint8_t got[PARAM_COUNT];
  memset(got, 0, sizeof got);
  uint8_t chunk[CHUNK_RECORDS * PARAM_STORE_REC_BYTES];
  const uint32_t sec = st->sector[s];
  for (uint32_t r = 0; r < hdr[s].count; r++) {
    const uint32_t k = r % CHUNK_RECORDS;
    if (k == 0u) {
      const uint32_t left = hdr[s].count - r;
      const uint32_t nrec = (left < CHUNK_RECORDS) ? left : CHUNK_RECORDS;
      if (hal_flash_read(sec, PARAM_STORE_HDR_BYTES + r * PARAM_STORE_REC_BYTES, chunk,
                         nrec * PARAM_STORE_REC_BYTES) != HAL_FLASH_OK) {
        return PARAM_STORE_NONE;
      }
    }
    const uint8_t *rec = &chunk[k * PARAM_STORE_REC_BYTES];
    const param_idx_t idx = param_lookup_id(get_u16(rec));
    const param_info_t *pi = param_info(idx);
    if (pi == NULL || (pi->flags & PF_PERSIST) == 0u) {
      rep->dropped++;
      continue;
    }
    const param_value_t val = {.u = get_u32(&rec[4])};
    if (got[idx] != 0u) {
      /* the first one was taken as loaded: both count */
      rep->rejected = (uint16_t)(rep->rejected + ((got[idx] == 1u) ? 2u : 1u));
      got[idx] = 3u;
      continue;
    }
    if (!type_compatible(rec[2], pi->type) || param_check(idx, val) != PARAM_OK) {
      rep->rejected++;
      got[idx] = 2u;
      continue;
    }
    got[idx] = 1u;
    param_put(&out, idx, val);
  }
  /* persistent parameters not validly in the image start from their defaults */
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    if ((pi->flags & PF_PERSIST) != 0u && got[i] != 1u) {
      param_put(&out, (param_idx_t)i, pi->def);
      if (got[i] == 0u) {
        rep->defaulted++;
      }
    }
  }
  rep->slot = (int8_t)s;
  rep->seq = hdr[s].seq;
  rep->fw_version = hdr[s].fw_version;
  rep->layout = hdr[s].layout;
  *v = out;
  return PARAM_STORE_OK;
}

/* Encode the persistent parameters of *v into st->buf; returns the image length. */
static uint32_t encode(param_store_t *st, const param_values_t *v, uint32_t seq)
{
  uint8_t *b = st->buf;
  uint32_t n = 0u;
  uint32_t off = PARAM_STORE_HDR_BYTES;
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    if ((pi->flags & PF_PERSIST) == 0u) {
      continue;
    }
    put_u16(&b[off], pi->id);
    b[off + 2u] = pi->type;
    b[off + 3u] = 0u;
    put_u32(&b[off + 4u], param_get(v, (param_idx_t)i).u);
    off += PARAM_STORE_REC_BYTES;
    n++;
  }
  put_u32(&b[0], PARAM_STORE_MAGIC);
  put_u16(&b[4], (uint16_t)PARAM_STORE_FORMAT);
  put_u16(&b[6], (uint16_t)PARAM_LAYOUT_VERSION);
  put_u32(&b[8], fw_version_number());
  put_u32(&b[12], seq);
  put_u32(&b[16], n);
  put_u32(&b[off], crc32_update(0u, b, off));
  put_u32(&b[off + 4u], PARAM_STORE_COMMIT);
  return off + 8u;
}

/* The records of slot s equal the ones just encoded (same count, same bytes)? */
static bool records_equal(const param_store_t *st, unsigned s, uint32_t count, uint32_t enc_count)
{
  if (count != enc_count) {
    return false;
  }
  uint8_t chunk[CHUNK_RECORDS * PARAM_STORE_REC_BYTES];
  const uint32_t body = PARAM_STORE_HDR_BYTES + PARAM_STORE_REC_BYTES * count;
  for (uint32_t off = PARAM_STORE_HDR_BYTES; off < body;) {
    const uint32_t n = (body - off < sizeof chunk) ? body - off : (uint32_t)sizeof chunk;
    if (hal_flash_read(st->sector[s], off, chunk, n) != HAL_FLASH_OK ||
        memcmp(chunk, &st->buf[off], n) != 0) {
      return false;
    }
    off += n;
  }
  return true;
}

param_store_status_t param_store_save(param_store_t *st, const param_values_t *v, uint32_t how,
                                      param_store_report_t *rep)
{
  param_store_report_t local;
  if (rep == NULL) {
    rep = &local;
  }
  report_clear(rep);
  if (st->sector_size == 0u) {
    return PARAM_STORE_ERR_CONFIG;
  }
  if ((how & PARAM_SAVE_LOOP_SAFE) == 0u) {
    return PARAM_STORE_ERR_BUSY;
  }
  slot_hdr_t hdr[2];
  const int newest = newest_slot(st, rep, hdr);
  uint32_t seq = (newest >= 0) ? hdr[newest].seq + 1u : 1u;
  if (seq == 0u || seq == 0xFFFFFFFFu) {
    seq = 1u; /* keep clear of values an erased or zeroed word could show */
  }
  const uint32_t len = encode(st, v, seq);
  const uint32_t enc_count = (len - PARAM_STORE_HDR_BYTES - 8u) / PARAM_STORE_REC_BYTES;
  if (newest >= 0 && records_equal(st, (unsigned)newest, hdr[newest].count, enc_count)) {
    rep->slot = (int8_t)newest;
    rep->seq = hdr[newest].seq;
    return PARAM_STORE_UNCHANGED;
  }
  /* never touch the newest valid image: write the other slot (with neither valid, A
   * unless A holds a newer-format image) */
  const unsigned target = (newest == 0 ||
                           (newest < 0 && rep->slot_state[0] == (uint8_t)PARAM_SLOT_NEWER))
                              ? 1u
                              : 0u;
  /* refused while either slot holds one: the save after this one would take the other */
  if (holds_newer(rep) && (how & PARAM_SAVE_FORCE) == 0u) {
    return PARAM_STORE_ERR_NEWER;
  }
  const uint32_t sec = st->sector[target];
  hal_flash_status_t fs = hal_flash_erase(sec);
  if (fs == HAL_FLASH_OK) {
    /* 24 + 8n bytes: whole units of any programming unit up to 8 */
    fs = hal_flash_program(sec, 0u, st->buf, len - 4u);
  }
  if (fs == HAL_FLASH_OK) {
    /* the commit word last, in a unit of its own: only now does the new image become
     * valid */
    const uint32_t end = commit_end(len, st->program_bytes);
    memset(&st->buf[len], 0xFF, end - len);
    fs = hal_flash_program(sec, len - 4u, &st->buf[len - 4u], end - (len - 4u));
  }
  if (fs != HAL_FLASH_OK) {
    return PARAM_STORE_ERR_FLASH;
  }
  slot_hdr_t check;
  if (slot_check(st, target, &check) != PARAM_SLOT_VALID || check.seq != seq ||
      !records_equal(st, target, check.count, enc_count)) {
    return PARAM_STORE_ERR_VERIFY;
  }
  rep->slot_state[target] = (uint8_t)PARAM_SLOT_VALID;
  rep->slot = (int8_t)target;
  rep->seq = seq;
  return PARAM_STORE_OK;
}

const char *param_store_status_str(param_store_status_t s)
{
  switch (s) {
  case PARAM_STORE_OK: return "ok";
  case PARAM_STORE_UNCHANGED: return "unchanged";
  case PARAM_STORE_NONE: return "no valid parameter image";
  case PARAM_STORE_ERR_BUSY: return "drive running: stop the drive first";
  case PARAM_STORE_ERR_FLASH: return "flash erase/program failed";
  case PARAM_STORE_ERR_VERIFY: return "written image did not verify";
  case PARAM_STORE_ERR_CONFIG: return "bad store configuration";
  case PARAM_STORE_NEWER: return "newer format image (not loaded)";
  case PARAM_STORE_ERR_NEWER: return "the save would erase an image of a newer format";
  default: return "?";
  }
}
