#include "tlm_decode.h"

enum { ST_TEXT = 0, ST_FRAME = 1, ST_SKIP = 2 };

void tlm_decode_init(tlm_decode_t *d, const tlm_decode_cfg_t *cfg)
{
  memset(d, 0, sizeof *d);
  if (cfg != NULL) {
    d->cfg = *cfg;
  }
  d->state = (uint8_t)ST_TEXT;
}

const tlm_layout_t *tlm_decode_layout(const tlm_decode_t *d)
{
  return d->have_layout ? &d->layout : NULL;
}

static void line_reset(tlm_decode_t *d)
{
  d->line_len = 0u;
  d->line_bad = false;
  d->line_cr = false;
}

/* A partial line cut by 0x00 or a frame start is garbage. */
static void line_abort(tlm_decode_t *d)
{
  if (d->line_len > 0u || d->line_bad || d->line_cr) {
    d->st.lines_bad++;
  }
  line_reset(d);
}

static void line_end(tlm_decode_t *d)
{
  if (d->line_bad) {
    d->st.lines_bad++;
  } else if (d->line_len > 0u) {
    d->line[d->line_len] = '\0';
    d->st.lines++;
    if (d->cfg.on_text != NULL) {
      d->cfg.on_text(d->cfg.ctx, d->line, d->line_len);
    }
  }
  line_reset(d);
}

static void text_byte(tlm_decode_t *d, uint8_t c)
{
  if (c == (uint8_t)'\n') {
    line_end(d);
  } else if (c == 0x00u) {
    line_abort(d);
  } else if (c == 0x01u) {
    line_abort(d);
    d->state = (uint8_t)ST_FRAME;
    d->buf[0] = c;
    d->buf_len = 1u;
  } else if (c == (uint8_t)'\r') {
    if (d->line_cr) {
      d->line_bad = true;
    }
    d->line_cr = true;
  } else if ((c >= 0x20u && c <= 0x7Eu) || c == (uint8_t)'\t') {
    if (d->line_cr || d->line_len >= TLM_DECODE_LINE_MAX) {
      d->line_bad = true;
    } else {
      d->line[d->line_len++] = (char)c;
    }
  } else {
    d->line_bad = true;
  }
}

static bool name_ok(const uint8_t *s, uint32_t len)
{
  if (len == 0u || len > TLM_NAME_MAX) {
    return false;
  }
  for (uint32_t i = 0; i < len; i++) {
    const uint8_t c = s[i];
    const bool ok = (c >= (uint8_t)'a' && c <= (uint8_t)'z') ||
                    (c >= (uint8_t)'A' && c <= (uint8_t)'Z') ||
                    (c >= (uint8_t)'0' && c <= (uint8_t)'9') || c == (uint8_t)'_' ||
                    c == (uint8_t)'.';
    if (!ok) {
      return false;
    }
  }
  return true;
}

/* Parse a header payload into *l; false if malformed. */
static bool parse_header(const uint8_t *p, size_t n, uint16_t seq, tlm_layout_t *l)
{
  if (n < TLM_HEADER_FIXED || p[0] != (uint8_t)TLM_HEADER_VERSION) {
    return false;
  }
  memset(l, 0, sizeof *l);
  l->stream_id = tlm_get_u32(&p[1]);
  l->fs_hz = tlm_get_u32(&p[5]);
  l->decim = tlm_get_u32(&p[9]);
  l->rec_per_frame = tlm_get_u16(&p[13]);
  l->lost = tlm_get_u32(&p[15]);
  l->dropped = tlm_get_u32(&p[19]);
  l->n_fields = p[23];
  l->seq = seq;
  if (l->fs_hz == 0u || l->decim == 0u || l->rec_per_frame == 0u || l->n_fields == 0u ||
      l->n_fields > TLM_FIELDS_MAX) {
    return false;
  }
  size_t off = TLM_HEADER_FIXED;
  for (uint32_t i = 0; i < l->n_fields; i++) {
    if (n - off < 2u) {
      return false;
    }
    const uint8_t type = p[off];
    const uint32_t len = p[off + 1u];
    off += 2u;
    if (type > 1u || len > n - off || !name_ok(&p[off], len)) {
      return false;
    }
    l->type[i] = type;
    memcpy(l->name[i], &p[off], len);
    l->name[i][len] = '\0';
    off += len;
    for (uint32_t j = 0; j < i; j++) {
      if (strcmp(l->name[j], l->name[i]) == 0) {
        return false;
      }
    }
  }
  return off == n;
}

static void track_seq(tlm_decode_t *d, uint16_t seq)
{
  d->st.seq_missing += (uint16_t)(seq - d->next_seq);
  d->next_seq = (uint16_t)(seq + 1u);
}

static void on_header(tlm_decode_t *d, const tlm_frame_view_t *v)
{
  tlm_layout_t l;
  if (!parse_header(v->payload, v->payload_len, v->seq, &l)) {
    d->st.bad_format++;
    return;
  }
  if (!d->have_layout || l.stream_id != d->layout.stream_id) {
    /* a new stream: its frames are counted from this header on */
    d->next_seq = v->seq;
    d->have_rec = false;
  }
  track_seq(d, v->seq);
  d->layout = l;
  d->have_layout = true;
  d->st.headers++;
  if (d->cfg.on_header != NULL) {
    d->cfg.on_header(d->cfg.ctx, &d->layout);
  }
}

static void on_data(tlm_decode_t *d, const tlm_frame_view_t *v)
{
  const uint8_t *p = v->payload;
  const size_t n = v->payload_len;
  if (n < TLM_DATA_FIXED) {
    d->st.bad_format++;
    return;
  }
  if (!d->have_layout || tlm_get_u16(&p[0]) != (uint16_t)(d->layout.stream_id & 0xFFFFu)) {
    d->st.no_layout++;
    return;
  }
  const uint32_t n_rec = p[6];
  if (n_rec == 0u || n != TLM_DATA_FIXED + 4u * n_rec * d->layout.n_fields) {
    d->st.bad_format++;
    return;
  }
  const uint32_t first = tlm_get_u32(&p[2]);
  track_seq(d, v->seq);
  if (d->have_rec && first != d->next_rec && (int32_t)(first - d->next_rec) > 0) {
    d->st.rec_missing += first - d->next_rec;
  }
  d->next_rec = first + n_rec;
  d->have_rec = true;
  d->st.data++;
  if (d->cfg.on_data != NULL) {
    const tlm_data_t data = {&d->layout, v->seq, first, n_rec, &p[TLM_DATA_FIXED]};
    d->cfg.on_data(d->cfg.ctx, &data);
  }
}

static void frame_end(tlm_decode_t *d)
{
  tlm_frame_view_t v;
  if (tlm_frame_open(d->buf, d->buf_len, d->raw, &v) != TLM_FRAME_OK) {
    d->st.corrupt++;
  } else if (v.type == (uint8_t)TLM_FRAME_HEADER) {
    on_header(d, &v);
  } else if (v.type == (uint8_t)TLM_FRAME_DATA) {
    on_data(d, &v);
  } else {
    d->st.bad_format++;
  }
  d->buf_len = 0u;
}

void tlm_decode_feed(tlm_decode_t *d, const uint8_t *data, size_t len)
{
  for (size_t i = 0; i < len; i++) {
    const uint8_t c = data[i];
    switch (d->state) {
    case ST_FRAME:
      if (c == 0x00u) {
        frame_end(d);
        d->state = (uint8_t)ST_TEXT;
      } else if (d->buf_len >= sizeof d->buf) {
        d->st.corrupt++; /* longer than any frame */
        d->buf_len = 0u;
        d->state = (uint8_t)ST_SKIP;
      } else {
        d->buf[d->buf_len++] = c;
      }
      break;
    case ST_SKIP:
      if (c == 0x00u) {
        d->state = (uint8_t)ST_TEXT;
      }
      break;
    default: text_byte(d, c); break;
    }
  }
}
