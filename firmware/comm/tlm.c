#include "comm/tlm.h"

#include <string.h>
#include "dsp/ramfunc.h"

static uint32_t popcount32(uint32_t m)
{
  uint32_t n = 0u;
  for (; m != 0u; m &= m - 1u) {
    n++;
  }
  return n;
}

static bool fields_ok(const tlm_fields_t *f)
{
  if (f == NULL || f->row == NULL || f->count == 0u || f->count > TLM_FIELDS_MAX) {
    return false;
  }
  for (uint32_t i = 0; i < f->count; i++) {
    if (f->row[i].name == NULL || strlen(f->row[i].name) > TLM_NAME_MAX ||
        f->row[i].offset % 4u != 0u) {
      return false;
    }
  }
  return true;
}

int tlm_init(tlm_t *t, const tlm_cfg_t *cfg)
{
  memset(t, 0, sizeof *t);
  if (cfg == NULL || cfg->room == NULL || cfg->write == NULL || cfg->fs_hz == 0u ||
      cfg->baud == 0u || !fields_ok(cfg->fields)) {
    return -1;
  }
  t->cfg = *cfg;
  t->rows = cfg->fields->row;
  tlm_ring_init(&t->ring);
  atomic_store_explicit(&t->isr_gen, 0u, memory_order_relaxed);
  atomic_store_explicit(&t->isr_rec, 0u, memory_order_relaxed);
  return 0;
}

/* ---- plan and link budget ---- */

static uint32_t rec_per_frame(uint32_t fs_hz, uint32_t decim, uint32_t n_fields)
{
  const uint32_t by_rate = fs_hz / decim / TLM_FRAMES_PER_S;
  const uint32_t by_size = TLM_DATA_RECORD_BYTES_MAX / (4u * n_fields);
  uint32_t n = (by_rate < 1u) ? 1u : by_rate;
  if (n > by_size) {
    n = by_size;
  }
  return (n > 255u) ? 255u : n;
}

static uint32_t header_payload_len(const tlm_fields_t *fields, uint32_t mask)
{
  uint32_t n = TLM_HEADER_FIXED;
  for (uint32_t i = 0; i < fields->count; i++) {
    if ((mask >> i) & 1u) {
      n += 2u + (uint32_t)strlen(fields->row[i].name);
    }
  }
  return n;
}

uint32_t tlm_plan_bytes_per_s(const tlm_fields_t *fields, uint32_t fs_hz, uint32_t mask,
                              uint32_t decim, uint32_t rec_per_frame_)
{
  const uint32_t f = popcount32(mask);
  const uint32_t data_wire = tlm_wire_len_max(TLM_FRAME_OVERHEAD + TLM_DATA_FIXED +
                                              4u * rec_per_frame_ * f);
  const uint32_t hdr_wire = tlm_wire_len_max(TLM_FRAME_OVERHEAD +
                                             header_payload_len(fields, mask));
  /* frames/s = fs / (decim N), rounded up */
  const uint64_t num = (uint64_t)fs_hz * data_wire;
  const uint64_t den = (uint64_t)decim * rec_per_frame_;
  return (uint32_t)((num + den - 1u) / den) + hdr_wire;
}

tlm_status_t tlm_plan(const tlm_fields_t *fields, uint32_t fs_hz, uint32_t baud, uint32_t mask,
                      float rate_hz, tlm_plan_t *plan)
{
  if (mask == 0u || (mask & ~tlm_fields_mask_all(fields)) != 0u) {
    return TLM_ERR_FIELDS;
  }
  /* also rejects NaN: every comparison with it is false */
  if (!(rate_hz > 0.0f) || !(rate_hz <= (float)fs_hz)) {
    return TLM_ERR_RATE;
  }
  const float d = (float)fs_hz / rate_hz + 0.5f;
  if (!(d < (float)TLM_DECIM_MAX + 1.0f)) {
    return TLM_ERR_RATE;
  }
  uint32_t decim = (uint32_t)d;
  if (decim < 1u) {
    decim = 1u;
  }
  tlm_plan_t p;
  p.mask = mask;
  p.n_fields = popcount32(mask);
  p.decim = decim;
  p.rate_hz = (float)fs_hz / (float)decim;
  p.rec_per_frame = rec_per_frame(fs_hz, decim, p.n_fields);
  p.bytes_per_s = tlm_plan_bytes_per_s(fields, fs_hz, mask, decim, p.rec_per_frame);
  p.link_bytes_per_s = baud / 10u;
  *plan = p;
  if ((uint64_t)p.bytes_per_s * 100u > (uint64_t)p.link_bytes_per_s * TLM_LINK_MAX_PCT) {
    return TLM_ERR_BANDWIDTH;
  }
  return TLM_OK;
}

/* ---- ISR ---- */

GYRO_RAMFUNC void tlm_isr_record(tlm_t *t, const void *snapshot, uint32_t gen)
{
  if (gen != t->isr_seen) {
    t->isr_seen = gen; /* a new stream takes its first record at once */
    t->isr_count = 0u;
  }
  if (t->isr_count != 0u) {
    t->isr_count--;
    return;
  }
  /* the slot gen names, read after gen and in this activation (tlm.h: handoff) */
  atomic_signal_fence(memory_order_acquire);
  const tlm_isr_sel_t *sel = &t->isr_sel[gen & 1u];
  t->isr_count = sel->decim - 1u;
  const uint32_t mask = sel->mask;
  const uint32_t k = atomic_load_explicit(&t->isr_rec, memory_order_relaxed);
  atomic_store_explicit(&t->isr_rec, k + 1u, memory_order_relaxed);
  uint32_t rec[1u + TLM_FIELDS_MAX];
  uint32_t n = 0u;
  rec[n++] = k;
  const uint8_t *base = snapshot;
  /* set bits only, lowest first (table order): the cost follows the number of fields,
   * not the index of the highest one (count trailing zeros: RBIT + CLZ on the M4) */
  for (uint32_t m = mask; m != 0u; m &= m - 1u) {
    memcpy(&rec[n++], base + t->rows[__builtin_ctz(m)].offset, 4u);
  }
  (void)tlm_ring_push(&t->ring, rec, n);
}

/* ---- background: frames ---- */

static bool try_send(tlm_t *t)
{
  if (t->pending_len == 0u) {
    return true;
  }
  if (t->cfg.room(t->cfg.ctx) < t->pending_len) {
    return false;
  }
  t->cfg.write(t->cfg.ctx, t->wire, t->pending_len);
  t->pending_len = 0u;
  t->frames++;
  return true;
}

/* Seal the raw frame (payload already at raw + 4) into the pending wire buffer. */
static void queue_frame(tlm_t *t, uint8_t type, size_t payload_len)
{
  const size_t raw_len = tlm_frame_seal(t->raw, type, t->seq, payload_len);
  t->seq = (uint16_t)(t->seq + 1u);
  t->pending_len = tlm_frame_to_wire(t->raw, raw_len, t->wire, sizeof t->wire);
}

static void queue_header(tlm_t *t)
{
  uint8_t *p = &t->raw[TLM_FRAME_HEAD_BYTES];
  p[0] = (uint8_t)TLM_HEADER_VERSION;
  tlm_put_u32(&p[1], t->stream_id);
  tlm_put_u32(&p[5], t->cfg.fs_hz);
  tlm_put_u32(&p[9], t->plan.decim);
  tlm_put_u16(&p[13], (uint16_t)t->plan.rec_per_frame);
  tlm_put_u32(&p[15], tlm_ring_overruns(&t->ring) - t->lost_base);
  tlm_put_u32(&p[19], t->dropped);
  p[23] = (uint8_t)t->plan.n_fields;
  size_t n = TLM_HEADER_FIXED;
  for (uint32_t i = 0; i < t->cfg.fields->count; i++) {
    if (((t->plan.mask >> i) & 1u) != 0u) {
      const tlm_field_t *f = &t->rows[i];
      const size_t len = strlen(f->name);
      p[n++] = f->type;
      p[n++] = (uint8_t)len;
      memcpy(&p[n], f->name, len);
      n += len;
    }
  }
  queue_frame(t, (uint8_t)TLM_FRAME_HEADER, n);
}

static void queue_data(tlm_t *t)
{
  uint8_t *p = &t->raw[TLM_FRAME_HEAD_BYTES];
  tlm_put_u16(&p[0], (uint16_t)(t->stream_id & 0xFFFFu));
  tlm_put_u32(&p[2], t->acc_first);
  p[6] = (uint8_t)t->acc_n;
  queue_frame(t, (uint8_t)TLM_FRAME_DATA, TLM_DATA_FIXED + 4u * t->acc_n * t->plan.n_fields);
  t->acc_n = 0u;
}

/* Move records from the ring into frames while the link takes them. With flush, also
 * close a partial data frame, and drop (count) what the link cannot take. */
static void pump(tlm_t *t, bool flush)
{
  const uint32_t words = 1u + t->plan.n_fields;
  uint32_t rec[1u + TLM_FIELDS_MAX];
  for (;;) {
    if (!try_send(t)) {
      if (!flush) {
        return;
      }
      t->pending_len = 0u;
      t->dropped++;
    }
    if (t->acc_n == t->plan.rec_per_frame) {
      queue_data(t);
      continue;
    }
    if (!tlm_ring_peek(&t->ring, rec, words)) {
      break;
    }
    const uint32_t k = rec[0] - t->rec_base;
    if (t->acc_n > 0u && k != t->acc_first + t->acc_n) {
      queue_data(t); /* records were lost: a frame holds consecutive records only */
      continue;
    }
    if (t->acc_n == 0u && (t->header_due || (int32_t)(k - t->next_header) >= 0)) {
      t->header_due = false;
      t->next_header = k + t->rec_per_s;
      queue_header(t);
      continue;
    }
    if (t->acc_n == 0u) {
      t->acc_first = k;
    }
    uint8_t *dst = &t->raw[TLM_FRAME_HEAD_BYTES + TLM_DATA_FIXED + 4u * t->acc_n * t->plan.n_fields];
    for (uint32_t j = 0; j < t->plan.n_fields; j++) {
      tlm_put_u32(&dst[4u * j], rec[1u + j]);
    }
    t->acc_n++;
    t->records++;
    tlm_ring_consume(&t->ring, words);
  }
  if (t->header_due && t->acc_n == 0u) {
    /* a stream announces itself before its first record arrives */
    t->header_due = false;
    t->next_header = t->rec_per_s;
    queue_header(t);
    if (!try_send(t) && flush) {
      t->pending_len = 0u;
      t->dropped++;
    }
  }
  if (flush && t->acc_n > 0u) {
    queue_data(t);
    if (!try_send(t)) {
      t->pending_len = 0u;
      t->dropped++;
    }
  }
}

/* ---- background: selection handoff (tlm.h) ---- */

/* Counted from the last generation published, not the last written: writing twice
 * before a publication rewrites the same unnamed slot, never the named one. */
uint32_t tlm_sel_write(tlm_t *t, uint32_t mask, uint32_t decim)
{
  /* 0 means off: after 0xFFFFFFFF (slot 1) comes 2 (slot 0), the slots still alternate */
  const uint32_t gen = (t->sel_gen == 0xFFFFFFFFu) ? 2u : t->sel_gen + 1u;
  t->isr_sel[gen & 1u].mask = mask;
  t->isr_sel[gen & 1u].decim = decim;
  return gen;
}

void tlm_sel_publish(tlm_t *t, uint32_t gen)
{
  atomic_signal_fence(memory_order_release); /* the slot's stores before the name */
  atomic_store_explicit(&t->isr_gen, gen, memory_order_relaxed);
  t->sel_gen = gen;
}

void tlm_start(tlm_t *t, const tlm_plan_t *plan)
{
  tlm_stop(t);
  /* isr_gen is 0: the ISR takes no record, so the ring, the record counter and the overrun
   * counter hold still while the new stream's bases are taken */
  tlm_ring_discard(&t->ring);
  t->plan = *plan;
  t->stream_id++;
  t->rec_base = atomic_load_explicit(&t->isr_rec, memory_order_relaxed);
  t->lost_base = tlm_ring_overruns(&t->ring);
  t->rec_per_s = (t->cfg.fs_hz + plan->decim / 2u) / plan->decim;
  if (t->rec_per_s == 0u) {
    t->rec_per_s = 1u;
  }
  t->next_header = 0u;
  t->header_due = true;
  t->seq = 0u;
  t->acc_n = 0u;
  t->records = t->frames = t->dropped = 0u;
  t->pending_len = 0u;
  t->streaming = true;
  tlm_sel_publish(t, tlm_sel_write(t, plan->mask, plan->decim));
}

void tlm_stop(tlm_t *t)
{
  atomic_store_explicit(&t->isr_gen, 0u, memory_order_relaxed);
  atomic_signal_fence(memory_order_seq_cst);
  if (t->streaming) {
    pump(t, true);
    t->streaming = false;
  }
}

void tlm_poll(tlm_t *t)
{
  if (t->streaming) {
    pump(t, false);
  }
}

void tlm_stats(const tlm_t *t, tlm_stats_t *st)
{
  st->streaming = t->streaming;
  st->stream_id = t->stream_id;
  st->records = t->records;
  st->lost = tlm_ring_overruns(&t->ring) - t->lost_base;
  st->frames = t->frames;
  st->dropped = t->dropped;
}
